//! `sahara render` stopped by a signal: the passes completed so far are
//! written, marked partial, and the file they replace is never left broken.

#![cfg(unix)]

use std::fs;
use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{temp_dir, SAHARA};

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
    let args = ["--width", "24", "--height", "16", "--pass-spp", "1"];
    interrupt_render(
        &[&args[..], &["--time-limit", "600"]].concat(),
        out,
        signal,
        after,
    )
}

/// Starts `sahara render ARGS --threads 1 -o OUT`, waits until it has
/// rendered for `after`, sends `signal` and returns (exit code, stderr).
fn interrupt_render(
    args: &[&str],
    out: &std::path::Path,
    signal: &str,
    after: Duration,
) -> (Option<i32>, String) {
    let mut child = Command::new(SAHARA)
        .arg("render")
        .args(args)
        .args(["--threads", "1", "-o"])
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
    let (code, log) = interrupt(&out, "-TERM", Duration::from_millis(1500));
    assert_eq!(code, Some(130), "{log}");
    assert!(
        log.contains("stopping: finishing the tiles under way"),
        "{log}"
    );
    assert!(log.contains("wrote PARTIAL image"), "{log}");
    assert_eq!(exr_text(&out, "sahara:partial").as_deref(), Some("true"));
    let spp: u32 = exr_text(&out, "sahara:spp").unwrap().parse().unwrap();
    assert!(spp >= 1, "{spp}");
    let (w, h, rgb) = sahara_formats::load_rgb_f32(&out).unwrap();
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
fn an_interrupted_render_never_replaces_an_earlier_image() {
    let dir = temp_dir("keep-earlier");
    let out = dir.join("image.exr");
    let complete = |spp: &str| {
        let o = Command::new(SAHARA)
            .args([
                "render", "--width", "24", "--height", "16", "--spp", spp, "-o",
            ])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    // A complete image of the same name, from an earlier run.
    complete("2");
    let before = fs::read(&out).unwrap();
    let (code, log) = interrupt(&out, "-INT", Duration::from_millis(1500));
    assert_eq!(code, Some(130), "{log}");
    assert_eq!(fs::read(&out).unwrap(), before, "the earlier image changed");
    let beside = dir.join("image.partial.exr");
    assert!(log.contains("image.partial.exr"), "{log}");
    assert!(log.contains("left as it was"), "{log}");
    assert_eq!(exr_text(&beside, "sahara:partial").as_deref(), Some("true"));
    // A complete render replaces the image and removes the partial one.
    complete("3");
    assert_eq!(exr_text(&out, "sahara:spp").as_deref(), Some("3"));
    assert!(!beside.exists(), "a stale partial image was left");
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

#[test]
fn sigint_in_the_first_pass_keeps_the_finished_pixels_marked_partial() {
    let dir = temp_dir("first-pass");
    let out = dir.join("image.exr");
    // One pass of 4096 samples per pixel: many seconds on one thread.
    let args = [
        "--width",
        "48",
        "--height",
        "32",
        "--spp",
        "4096",
        "--pass-spp",
        "4096",
    ];
    let (code, log) = interrupt_render(&args, &out, "-INT", Duration::from_millis(1500));
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("wrote PARTIAL image"), "{log}");
    assert!(log.contains("first pass interrupted"), "{log}");
    assert_eq!(exr_text(&out, "sahara:partial").as_deref(), Some("true"));
    assert_eq!(exr_text(&out, "sahara:spp").as_deref(), Some("4096"));
    let finished: usize = exr_text(&out, "sahara:finished_pixels")
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        finished > 0 && finished < 48 * 32,
        "{finished} pixels: {log}"
    );
    let (w, h, rgb) = sahara_formats::load_rgb_f32(&out).unwrap();
    assert_eq!((w, h), (48, 32));
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    // The finished pixels are lit; the unfinished ones are black.
    let lit = rgb.chunks(3).filter(|p| p.iter().any(|v| *v > 0.0)).count();
    assert!(lit > 0 && lit <= finished, "{lit} lit, {finished} finished");
}

#[test]
fn previews_are_rewritten_while_rendering_and_marked_partial() {
    let dir = temp_dir("preview");
    let out = dir.join("preview.exr");
    let mut child = Command::new(SAHARA)
        .args([
            "render", "--width", "16", "--height", "16", "--spp", "1000000",
        ])
        .args([
            "--pass-spp",
            "1",
            "--preview-every",
            "0.2",
            "--threads",
            "1",
            "-o",
        ])
        .arg(&out)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("run sahara");
    let start = Instant::now();
    let mut seen_spp = Vec::new();
    while seen_spp.len() < 2 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no previews: {seen_spp:?}"
        );
        assert!(child.try_wait().unwrap().is_none(), "sahara stopped");
        if out.exists() {
            assert_eq!(exr_text(&out, "sahara:partial").as_deref(), Some("true"));
            let spp: u32 = exr_text(&out, "sahara:spp").unwrap().parse().unwrap();
            if seen_spp.last() != Some(&spp) {
                seen_spp.push(spp);
            }
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(seen_spp[1] > seen_spp[0], "{seen_spp:?}");
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let mut log = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut log)
        .unwrap();
    assert_eq!(child.wait().unwrap().code(), Some(130), "{log}");

    // A render that completes: the final image replaces the previews.
    let done = dir.join("done.exr");
    let o = Command::new(SAHARA)
        .args(["render", "--width", "8", "--height", "8", "--spp", "6"])
        .args(["--pass-spp", "1", "--preview-every", "0", "-o"])
        .arg(&done)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(exr_text(&done, "sahara:partial").as_deref(), Some("false"));
    assert_eq!(exr_text(&done, "sahara:spp").as_deref(), Some("6"));
    let mut names: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names, ["done.exr", "preview.exr"], "{names:?}");
}

#[test]
fn sigterm_leaves_a_part_marked_partial_that_merge_refuses() {
    let dir = temp_dir("part-sigterm");
    let out = dir.join("part.exr");
    // Many passes of one sample: far more than the wait.
    let args = [
        "--width",
        "24",
        "--height",
        "16",
        "--spp",
        "200000",
        "--pass-spp",
        "1",
        "--part",
        "1/2",
    ];
    let (code, log) = interrupt_render(&args, &out, "-TERM", Duration::from_millis(1500));
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("wrote PARTIAL part"), "{log}");
    assert_eq!(exr_text(&out, "sahara:complete").as_deref(), Some("false"));
    let done = exr_text(&out, "sahara:samples_done").unwrap();
    assert!(done.starts_with("0..") && done != "0..200000", "{done}");
    let merged = dir.join("merged.exr");
    let m = Command::new(SAHARA)
        .args([
            "merge",
            out.to_str().unwrap(),
            "-o",
            merged.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&m.stderr);
    assert!(!m.status.success() && e.contains("a partial part"), "{e}");
}

/// A binary PLY of `n` small triangles scattered through a unit cube: a
/// tree build of a second or more on one thread.
fn write_soup_ply(path: &std::path::Path, n: u32) {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut data = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n\
         element face {n}\nproperty list uchar int vertex_indices\nend_header\n",
        3 * n
    )
    .into_bytes();
    for _ in 0..n {
        let c = [next(), next(), next()];
        for _ in 0..3 {
            for a in c {
                data.extend_from_slice(&(a + 0.02 * next()).to_le_bytes());
            }
        }
    }
    for i in 0..n {
        data.push(3);
        for k in 0..3 {
            data.extend_from_slice(&((3 * i + k) as i32).to_le_bytes());
        }
    }
    fs::write(path, data).unwrap();
}

#[test]
fn a_render_stopped_before_its_first_pixel_exits_130_and_writes_nothing() {
    let dir = temp_dir("before-first-pixel");
    let mesh = dir.join("soup.ply");
    write_soup_ply(&mesh, 600_000);
    let out = dir.join("image.png");
    // The signal comes as the render starts, while the tree is being built.
    let args = [mesh.to_str().unwrap(), "--width", "8", "--height", "8"];
    let (code, log) = interrupt_render(&args, &out, "-INT", Duration::ZERO);
    assert_eq!(code, Some(130), "{log}");
    assert!(
        log.contains("interrupted before the first pixel was finished: no image written"),
        "{log}"
    );
    assert!(!log.contains("error:"), "{log}");
    assert!(!out.exists());
    let _ = fs::remove_dir_all(&dir);
}
