//! Atomic file replacement: write beside the target, fsync, rename over it.
//!
//! A reader of the target sees either the old file or the complete new one,
//! never a half-written file, and a failed write leaves the old file as it
//! was. The temporary file is `.<name>.tmp-<pid>-<n>` in the target's own
//! folder (a rename is only atomic within one file system) and is removed
//! on every error path.

use std::fs::{self, File, OpenOptions};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use sahara_readers::FormatError;

/// Writes `path` atomically: `fill` writes the contents into a temporary file,
/// which is flushed, fsynced and renamed over `path`.
///
/// If `fill` or any later step fails, the temporary file is removed and an
/// existing `path` is left untouched.
pub fn write_atomically<F>(path: &Path, fill: F) -> Result<(), FormatError>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), FormatError>,
{
    let (temp, file) = create_temp(path)?;
    let guard = RemoveOnDrop(Some(temp.clone()));
    let temp = temp.as_path();
    let mut writer = BufWriter::new(file);
    fill(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|e| FormatError::write(temp, e.into_error()))?;
    file.sync_all().map_err(|e| FormatError::write(temp, e))?;
    drop(file);
    if path.is_dir() {
        return Err(FormatError::in_file(
            &path.display().to_string(),
            "cannot write the file: it is a directory",
        ));
    }
    fs::rename(temp, path).map_err(|e| FormatError::write(path, e))?;
    guard.disarm();
    // Make the rename itself durable; not every platform lets a folder be
    // opened and synced, and the data is already safe, so failures are ignored.
    if let Ok(dir) = File::open(folder_of(path)) {
        let _ = dir.sync_all();
    }
    Ok(())
}

/// Checks, before a long render, that `path` can be written: its folder
/// exists, `path` is not a folder, and a temporary file can be created and
/// removed there.
pub fn check_writable(path: &Path) -> Result<(), FormatError> {
    let name = path.display().to_string();
    if path.file_name().is_none() {
        return Err(FormatError::in_file(
            &name,
            "cannot write here: the path does not end in a file name",
        ));
    }
    let folder = folder_of(path);
    if !folder.is_dir() {
        return Err(FormatError::in_file(
            &name,
            format!(
                "cannot write here: the folder {} does not exist",
                folder.display()
            ),
        ));
    }
    if path.is_dir() {
        return Err(FormatError::in_file(
            &name,
            "cannot write here: it is a folder",
        ));
    }
    let (temp, file) = create_temp(path)?;
    drop(file);
    fs::remove_file(&temp).map_err(|e| FormatError::write(&temp, e))
}

/// The folder a file called `path` lives in (`.` for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Creates a new, unique temporary file beside `path`.
fn create_temp(path: &Path) -> Result<(PathBuf, File), FormatError> {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        FormatError::in_file(
            &path.display().to_string(),
            "cannot write here: the path does not end in a file name",
        )
    })?;
    loop {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let mut temp_name = std::ffi::OsString::from(".");
        temp_name.push(name);
        temp_name.push(format!(".tmp-{}-{n}", std::process::id()));
        let temp = folder_of(path).join(temp_name);
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => return Ok((temp, file)),
            // Left over from a crashed process with a recycled id: try the next number.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => {
                return Err(FormatError::in_file(
                    &path.display().to_string(),
                    format!(
                        "cannot create a temporary file in {}: {e}",
                        folder_of(path).display()
                    ),
                ))
            }
        }
    }
}

/// Removes the temporary file when dropped, unless disarmed after the rename.
struct RemoveOnDrop(Option<PathBuf>);

impl RemoveOnDrop {
    fn disarm(mut self) {
        self.0 = None;
    }
}

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        if let Some(path) = self.0.take() {
            let _ = fs::remove_file(path);
        }
    }
}
