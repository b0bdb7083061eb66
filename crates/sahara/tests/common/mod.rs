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
    eprintln!("skipped: Open Image Denoise is not installed here (pip install pyoidn)");
    true
}
