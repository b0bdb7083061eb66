//! The progress bar as a terminal shows it: `sahara render` with its stderr
//! on a pseudo-terminal 80 columns wide.

#![cfg(unix)]

use std::fs::File;
use std::io::Read;
use std::os::fd::{FromRawFd, OwnedFd};
use std::process::{Command, Stdio};

use crate::common::{temp_dir, SAHARA};

/// A pseudo-terminal of `cols` columns: (controller, terminal).
fn pty(cols: u16) -> (OwnedFd, OwnedFd) {
    let (mut controller, mut terminal) = (0, 0);
    let size = libc::winsize {
        ws_row: 24,
        ws_col: cols,
        ws_xpixel: 0,
        ws_ypixel: 0,
    };
    // SAFETY: openpty writes two descriptors it opened into the pointers.
    let r = unsafe {
        libc::openpty(
            &mut controller,
            &mut terminal,
            std::ptr::null_mut(),
            std::ptr::null(),
            &size,
        )
    };
    assert_eq!(r, 0, "openpty failed");
    // SAFETY: both descriptors are open and owned by nobody else.
    unsafe {
        (
            OwnedFd::from_raw_fd(controller),
            OwnedFd::from_raw_fd(terminal),
        )
    }
}

/// The text of a terminal stream with escape sequences removed, split
/// where the cursor returns to the line start.
fn frames(raw: &[u8]) -> Vec<String> {
    let text = String::from_utf8_lossy(raw);
    let mut out = Vec::new();
    let mut line = String::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\u{1b}' => {
                // CSI: ESC [ parameters final-byte.
                if chars.peek() == Some(&'[') {
                    chars.next();
                    for d in chars.by_ref() {
                        if ('@'..='~').contains(&d) {
                            break;
                        }
                    }
                }
            }
            '\r' | '\n' => {
                if !line.trim().is_empty() {
                    out.push(std::mem::take(&mut line));
                }
                line.clear();
            }
            c => line.push(c),
        }
    }
    if !line.trim().is_empty() {
        out.push(line);
    }
    out
}

#[test]
fn the_bar_fits_an_80_column_terminal_and_starts_at_0_percent() {
    let dir = temp_dir("progress");
    let out = dir.join("p.png");
    let (controller, terminal) = pty(80);
    let mut child = Command::new(SAHARA)
        .args(["render", "--width", "64", "--height", "64", "--spp", "256"])
        .args(["--pass-spp", "16", "--threads", "1", "-o"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::from(terminal))
        .spawn()
        .expect("run sahara");
    let mut reader = File::from(controller);
    let mut raw = Vec::new();
    let mut buf = [0u8; 4096];
    // Read until the child closes the terminal (EIO on Linux once it exits).
    loop {
        match reader.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => raw.extend_from_slice(&buf[..n]),
        }
    }
    assert!(child.wait().unwrap().success());
    let frames = frames(&raw);
    // The bar's frames (the closing lines, which give shares of time and
    // of the lanes' work in per cent too, are not).
    let bars: Vec<&String> = frames
        .iter()
        .filter(|f| f.contains('%') && !f.starts_with("wrote") && !f.starts_with("path loop"))
        .collect();
    assert!(!bars.is_empty(), "no progress bar drawn: {frames:#?}");
    assert!(
        bars[0].contains("  0%"),
        "the first frame is not at 0%: {:?}",
        bars[0]
    );
    for f in &bars {
        assert!(
            f.chars().count() <= 80,
            "a frame wider than the terminal ({} columns): {f:?}",
            f.chars().count()
        );
    }
}
