//! `sahara render` stopped by a signal: the passes completed so far are
//! written, marked partial, and the file they replace is never left broken.

#![cfg(unix)]

use std::fs;
use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use common::{temp_dir, SAHARA};

/// The `sahara:*` text attributes of an EXR file.
fn exr_text(path: &std::path::Path, key: &str) -> Option<String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    match meta.headers[0]
        .own_attributes
        .other
        .get(&exr::meta::attribute::Text::from(key))
    {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => Some(t.to_string()),
        _ => None,
    }
}

/// Starts an open-ended render of the built-in scene into `out`, waits until
/// it has rendered for `after`, sends `signal` and returns (exit code, stderr).
fn interrupt(out: &std::path::Path, signal: &str, after: Duration) -> (Option<i32>, String) {
    let mut child = Command::new(SAHARA)
        .args(["render", "--width", "24", "--height", "16", "--spp", "1"])
        .args(["--time-limit", "600", "--threads", "1", "-o"])
        .arg(out)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("run sahara");
    let mut err = BufReader::new(child.stderr.take().unwrap());
    // The "rendering ..." line is printed just before the first pass.
    let mut log = String::new();
    while !log.contains("rendering ") {
        assert!(err.read_line(&mut log).unwrap() > 0, "no start line: {log}");
    }
    std::thread::sleep(after);
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("run kill");
    assert!(status.success());
    let start = Instant::now();
    err.read_to_string(&mut log).unwrap();
    let code = child.wait().unwrap().code();
    assert!(
        start.elapsed() < Duration::from_secs(60),
        "took too long to stop"
    );
    (code, log)
}

#[test]
fn sigterm_writes_the_completed_passes_marked_partial() {
    let dir = temp_dir("sigterm");
    let out = dir.join("image.exr");
    // An existing file is replaced whole, never truncated in place.
    fs::write(&out, b"the previous image").unwrap();
    let (code, log) = interrupt(&out, "-TERM", Duration::from_millis(1500));
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("wrote PARTIAL image"), "{log}");
    assert_eq!(exr_text(&out, "sahara:partial").as_deref(), Some("true"));
    let spp: u32 = exr_text(&out, "sahara:spp").unwrap().parse().unwrap();
    assert!(spp >= 1, "{spp}");
    let (w, h, rgb) = sahara_formats::image_in::load_rgb_f32(&out).unwrap();
    assert_eq!((w, h), (24, 16));
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(rgb.iter().any(|v| *v > 0.0), "the Cornell box is lit");
    // No temporary file is left beside the output.
    let names: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["image.exr"], "{names:?}");
}

#[test]
fn sigint_writes_the_completed_passes_marked_partial() {
    let dir = temp_dir("sigint");
    let out = dir.join("image.exr");
    let (code, log) = interrupt(&out, "-INT", Duration::from_millis(1500));
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("wrote PARTIAL image"), "{log}");
    assert_eq!(exr_text(&out, "sahara:partial").as_deref(), Some("true"));
}
