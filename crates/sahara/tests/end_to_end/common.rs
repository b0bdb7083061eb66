//! Helpers shared by the end-to-end tests of the `sahara` binary.

#![allow(dead_code)]

use std::fs;
use std::path::PathBuf;
use std::process::{Command, Output};

/// The binary under test.
pub const SAHARA: &str = env!("CARGO_BIN_EXE_sahara");

/// A fresh directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sahara-test-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// Run `sahara` with `args`.
pub fn sahara(args: &[&str]) -> Output {
    Command::new(SAHARA)
        .args(args)
        .output()
        .expect("run sahara")
}

/// True if `out` failed for want of Open Image Denoise, which a test then
/// skips (said so), unless `SAHARA_REQUIRE_OIDN` is set, as CI sets it:
/// then it fails.
pub fn denoiser_missing(out: &Output) -> bool {
    let err = String::from_utf8_lossy(&out.stderr);
    if out.status.success() || !err.contains("Open Image Denoise not found") {
        return false;
    }
    assert!(
        std::env::var_os("SAHARA_REQUIRE_OIDN").is_none(),
        "SAHARA_REQUIRE_OIDN is set: {err}"
    );
    skip_note("the denoiser's end-to-end tests (Open Image Denoise is not installed here: pip install pyoidn)");
    true
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
