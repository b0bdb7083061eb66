//! Helpers shared by the tests: temporary folders, triangle corners and the
//! shared scene folder. `sahara-formats`' tests include this file by path.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::Vec3;
use sahara_readers::Mesh;

/// A fresh, empty folder under the system temp dir, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("sahara-test-{}-{tag}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    /// Writes `contents` to `name` in the folder and returns its path.
    pub fn write(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The corner coordinates of every triangle, in triangle order.
pub fn corners(mesh: &Mesh) -> Vec<[Vec3; 3]> {
    mesh.indices
        .iter()
        .map(|t| t.map(|i| mesh.positions[i as usize]))
        .collect()
}

/// The shared scene folder: `$SAHARA_SCENES` if set, else `shared/scenes`
/// beside the workspace.
pub fn scenes_dir() -> PathBuf {
    match std::env::var_os("SAHARA_SCENES") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    }
}

/// Says that a group of tests is skipped and why, once per reason, on the
/// test binary's own stderr: `cargo test` shows it without `--nocapture`
/// (the harness captures only `print!` and `eprint!`).
pub fn skip_note(reason: &str) {
    use std::io::Write;
    static SAID: std::sync::Mutex<std::collections::BTreeSet<String>> =
        std::sync::Mutex::new(std::collections::BTreeSet::new());
    let first = SAID
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(reason.to_string());
    if first {
        // One write, so that lines of tests running in parallel stay whole.
        let _ = std::io::stderr().write_all(format!("SKIPPED: {reason}\n").as_bytes());
    }
}
