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
