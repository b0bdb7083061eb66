//! End-to-end tests of `sahara render`: every example scene, mesh files,
//! and the errors a user meets first.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use sahara_formats::load_rgb_f32;

use crate::common::{denoiser_missing, sahara, temp_dir};

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The workspace's example scenes.
fn example_scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut scenes: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    scenes
}

/// Mean of the image's linear RGB values, after checking they are finite.
fn checked_mean(path: &Path, width: u32, height: u32) -> f32 {
    let (w, h, rgb) = load_rgb_f32(path).unwrap();
    assert_eq!((w, h), (width, height), "{}", path.display());
    assert!(rgb.iter().all(|v| v.is_finite()), "{}", path.display());
    rgb.iter().sum::<f32>() / rgb.len() as f32
}

#[test]
fn every_example_scene_renders() {
    let scenes = example_scenes();
    assert!(scenes.len() >= 3, "{scenes:?}");
    // The scenes' meshes ship in scenes/assets: nothing outside the
    // repository is needed, so there is nothing to skip.
    let dir = temp_dir("examples");
    for scene in scenes {
        let stem = scene.file_stem().unwrap().to_string_lossy().into_owned();
        let png = dir.join(format!("{stem}.png"));
        let out = sahara(&[
            "render",
            scene.to_str().unwrap(),
            "--width",
            "48",
            "--height",
            "48",
            "--spp",
            "2",
            "-o",
            png.to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert!(out.status.success(), "{stem}: {err}");
        assert!(!err.contains("NaN"), "{stem}: {err}");
        assert!(!err.contains("warning"), "{stem}: {err}");
        let mean = checked_mean(&png, 48, 48);
        assert!(
            (0.02..0.9).contains(&mean),
            "{stem}: implausible mean {mean}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A one-quad OBJ facing +z with an MTL naming a missing texture, and a
/// sidecar camera looking at it.
fn write_quad(dir: &Path, mtl: &str) -> PathBuf {
    fs::write(dir.join("quad.mtl"), format!("newmtl m\n{mtl}\n")).unwrap();
    fs::write(
        dir.join("quad.camera.json"),
        r#"{"eye":[0,0,3],"target":[0,0,0],"vfov_deg":60}"#,
    )
    .unwrap();
    let obj = dir.join("quad.obj");
    fs::write(
        &obj,
        "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nusemtl m\nf 1 2 3 4\n",
    )
    .unwrap();
    obj
}

#[test]
fn a_mesh_renders_with_its_mtl_and_warnings_are_counted() {
    let dir = temp_dir("mesh");
    let obj = write_quad(&dir, "Kd 0.2 0.9 0.2\nmap_Kd missing.png");
    let exr = dir.join("quad.exr");
    let out = sahara(&[
        "render",
        obj.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "2",
        "-o",
        exr.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("missing.png") && err.contains("1 warning"),
        "{err}"
    );
    assert!(err.contains("quad.camera.json"), "{err}");
    // The quad fills the centre: lit by the default sun and sky, green.
    let (w, _, rgb) = load_rgb_f32(&exr).unwrap();
    let c = ((8 * w + 8) * 3) as usize;
    let (r, g, b) = (rgb[c], rgb[c + 1], rgb[c + 2]);
    assert!(g > 2.0 * r && g > 2.0 * b && g > 0.1, "{r} {g} {b}");
    let _ = fs::remove_dir_all(&dir);
}

/// Renders `obj` at 16x16, 1 spp, with `extra` options; the EXR's pixels.
fn render_exr(dir: &Path, obj: &Path, extra: &[&str]) -> (u32, Vec<f32>) {
    let exr = dir.join("quad.exr");
    let mut args = vec![
        "render",
        obj.to_str().unwrap(),
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "1",
        "-o",
        exr.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = sahara(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let (w, _, rgb) = load_rgb_f32(&exr).unwrap();
    (w, rgb)
}

#[test]
fn weak_emitters_get_the_default_sky_unless_told_otherwise() {
    let dir = temp_dir("emitter");
    let sky = [0.55f32, 0.6, 0.7];
    // A dim emitter: the default sky and sun keep the mesh lit.
    let obj = write_quad(&dir, "Kd 0 0 0\nKe 0.2 0.1 0.05");
    let (w, rgb) = render_exr(&dir, &obj, &[]);
    let c = ((8 * w + 8) * 3) as usize;
    assert!((rgb[c] - 0.2).abs() < 1e-3 && (rgb[c + 2] - 0.05).abs() < 1e-3);
    assert_eq!(&rgb[..3], &sky);
    // --sky none: its own light only, a black background.
    let (_, rgb) = render_exr(&dir, &obj, &["--sky", "none"]);
    assert!((rgb[c] - 0.2).abs() < 1e-3 && (rgb[c + 2] - 0.05).abs() < 1e-3);
    assert_eq!(&rgb[..3], &[0.0, 0.0, 0.0]);
    // A strong emitter lights the scene by itself: no sky.
    let obj = write_quad(&dir, "Kd 0 0 0\nKe 500 250 125");
    let (_, rgb) = render_exr(&dir, &obj, &[]);
    assert!((rgb[c] - 500.0).abs() < 1e-1);
    assert_eq!(&rgb[..3], &[0.0, 0.0, 0.0]);
    // ... unless told otherwise.
    let (_, rgb) = render_exr(&dir, &obj, &["--sky", "default"]);
    assert_eq!(&rgb[..3], &sky);
    // An environment map from a file, and a clear error for a missing one.
    let map = dir.join("sky.hdr");
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
    hdr.extend_from_slice(&[128, 64, 32, 129, 128, 64, 32, 129]);
    fs::write(&map, hdr).unwrap();
    let (_, rgb) = render_exr(&dir, &obj, &["--sky", map.to_str().unwrap()]);
    for (got, want) in rgb[..3].iter().zip([1.0, 0.5, 0.25]) {
        assert!((got - want).abs() < 0.01, "{:?}", &rgb[..3]);
    }
    let png = dir.join("x.png");
    let out = sahara(&[
        "render",
        obj.to_str().unwrap(),
        "--sky",
        "nowhere.exr",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("nowhere.exr"), "{}", stderr(&out));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn command_line_options_override_the_scene_file() {
    let dir = temp_dir("override");
    write_quad(&dir, "Kd 0.5 0.5 0.5");
    let scene = dir.join("s.toml");
    fs::write(
        &scene,
        "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n\n[[object]]\ntype = \"mesh\"\nfile = \"quad.obj\"\n\n\
         [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n\n\
         [film]\nwidth = 12\nheight = 6\noutput = \"from_file.png\"\n",
    )
    .unwrap();
    let out = std::process::Command::new(crate::common::SAHARA)
        .args(["render", scene.to_str().unwrap(), "--spp", "1"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    // The file's size and output (in the working folder) hold...
    let (w, h, _) = load_rgb_f32(&dir.join("from_file.png")).unwrap();
    assert_eq!((w, h), (12, 6));
    // ...unless given on the command line.
    let png = dir.join("cli.png");
    let out = sahara(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "1",
        "--width",
        "5",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (w, h, _) = load_rgb_f32(&png).unwrap();
    assert_eq!((w, h), (5, 6));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn an_unknown_integrator_is_a_clear_error() {
    let out = sahara(&["render", "--integrator", "whitted", "--width", "4"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("unknown integrator 'whitted'") && err.contains("path, distribution"),
        "{err}"
    );
}

#[test]
fn a_scene_with_a_missing_mesh_names_the_line_and_the_path() {
    let dir = temp_dir("missing");
    let scene = dir.join("s.toml");
    fs::write(
        &scene,
        "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n\n[film]\nwidth = 4\nheight = 4\n\n\
         [[object]]\ntype = \"mesh\"\nfile = \"gone/bunny.obj\"\n",
    )
    .unwrap();
    let out = sahara(&["render", scene.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("s.toml: line 11"), "{err}");
    assert!(err.contains("gone/bunny.obj"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_zero_size_image_is_refused() {
    for (w, h) in [("0", "16"), ("16", "0")] {
        let out = sahara(&["render", "--width", w, "--height", h, "-o", "never.png"]);
        assert!(!out.status.success());
        let err = stderr(&out);
        assert!(err.contains("--width") || err.contains("--height"), "{err}");
        assert!(!Path::new("never.png").exists());
    }
}

#[test]
fn an_unwritable_output_is_refused_before_rendering() {
    let dir = temp_dir("unwritable");
    let target = dir.join("no-such-folder").join("out.png");
    let start = std::time::Instant::now();
    // 4096 spp would take minutes: the refusal must come first.
    let out = sahara(&["render", "--spp", "4096", "-o", target.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("cannot write the output image"), "{err}");
    assert!(err.contains("no-such-folder"), "{err}");
    assert!(!err.contains("rendering "), "refused after starting: {err}");
    assert!(start.elapsed().as_secs() < 30);
}

#[test]
fn every_output_is_checked_before_the_scene_is_loaded() {
    let dir = temp_dir("outputs-first");
    // The scene does not exist: an error about the output proves the
    // output was checked first.
    let missing = dir.join("missing.toml");
    let readonly = dir.join("kept.png");
    fs::write(&readonly, b"an earlier image").unwrap();
    let mut perms = fs::metadata(&readonly).unwrap().permissions();
    perms.set_readonly(true);
    fs::set_permissions(&readonly, perms).unwrap();
    let jpg = dir.join("out.jpg");
    let bare = dir.join("out");
    let tiff = dir.join("x.tiff");
    let png_part = dir.join("part.png");
    for (output, extra, what) in [
        (&jpg, &[][..], "unsupported image file extension \"jpg\""),
        (&bare, &[], "unsupported image file extension \"\""),
        (&tiff, &[], "unsupported image file extension \"tiff\""),
        (&readonly, &[], "read-only"),
        (&png_part, &["--part", "0/2"], "name a .exr file"),
    ] {
        let out = sahara(
            &[
                &[
                    "render",
                    missing.to_str().unwrap(),
                    "-o",
                    output.to_str().unwrap(),
                ],
                extra,
            ]
            .concat(),
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.contains(output.to_str().unwrap()) && err.contains(what),
            "{err}"
        );
    }
    assert_eq!(fs::read(&readonly).unwrap(), b"an earlier image");
    let mut perms = fs::metadata(&readonly).unwrap().permissions();
    #[allow(clippy::permissions_set_readonly_false)]
    perms.set_readonly(false);
    fs::set_permissions(&readonly, perms).unwrap();
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_log_that_is_not_a_terminal_gets_plain_progress_lines() {
    let dir = temp_dir("plain-progress");
    let out = dir.join("p.png");
    let o = std::process::Command::new(crate::common::SAHARA)
        .args(["render", "--width", "40", "--height", "40", "--spp", "4"])
        .args(["--pass-spp", "2", "-o", out.to_str().unwrap()])
        .env("SAHARA_PROGRESS_EVERY", "0")
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    // Each line gives the whole render's share, the time elapsed and left,
    // and the speed; the tiles are said to be the pass's.
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("progress: "))
        .collect();
    assert!(lines.len() > 1, "{err}");
    for line in &lines[..lines.len() - 1] {
        assert!(
            line.contains("% done, ")
                && line.contains(" elapsed, eta ")
                && line.contains(" Mrays/s (pass ")
                && line.contains(" of this pass)"),
            "{line}"
        );
    }
    assert!(err.contains("(pass 1/2, tile "), "{err}");
    assert!(err.contains("(pass 2/2, tile "), "{err}");
    // The last line says the render is finished, whatever the last tile's
    // line said.
    assert!(
        lines.last().unwrap().starts_with("progress: 100.0% done, ")
            && lines
                .last()
                .unwrap()
                .ends_with(" elapsed, finished (2 passes)"),
        "{err}"
    );
    // A line every hour: none is printed, nor the closing one.
    let o = std::process::Command::new(crate::common::SAHARA)
        .args(["render", "--width", "40", "--height", "40", "--spp", "4"])
        .args(["-o", out.to_str().unwrap()])
        .env("SAHARA_PROGRESS_EVERY", "3600")
        .output()
        .unwrap();
    assert!(!stderr(&o).contains("progress: "), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn steps_that_take_a_while_say_what_they_are_doing() {
    // With SAHARA_STATUS_AFTER=0 every step is said, however short; in a
    // log, a line when it is said and one with its time when it ends.
    let dir = temp_dir("status-lines");
    let out = dir.join("s.png");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bunny_dof.toml");
    let o = std::process::Command::new(crate::common::SAHARA)
        .args([
            "render",
            scene.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "16",
        ])
        .args(["--spp", "1", "-o", out.to_str().unwrap()])
        .env("SAHARA_STATUS_AFTER", "0")
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    for step in [
        format!("loading {}", scene.display()),
        "building the trees and light tables".to_owned(),
    ] {
        assert!(err.contains(&format!("{step}...\n")), "{step}: {err}");
        assert!(err.contains(&format!("{step}: done in ")), "{step}: {err}");
    }
    // By default a step of less than a second says nothing.
    let o = sahara(&[
        "render",
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!stderr(&o).contains("..."), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn the_bare_command_takes_renders_options() {
    // `sahara -o out.png --spp 1 ...` renders the built-in scene as
    // `sahara render` does with them.
    let dir = temp_dir("bare");
    let (bare, render) = (dir.join("bare.png"), dir.join("render.png"));
    let size = ["--width", "24", "--height", "16", "--spp", "1"];
    let out = sahara(&[&["-o", bare.to_str().unwrap()][..], &size].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = sahara(&[&["render", "-o", render.to_str().unwrap()][..], &size].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(fs::read(&bare).unwrap(), fs::read(&render).unwrap());
    // A mistake in them is said as render says it.
    let out = sahara(&["--spp", "0"]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("0 is not in 1..="),
        "{}",
        stderr(&out)
    );
    // Help and version stay the tool's.
    let out = sahara(&["--version"]);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("sahara "));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn argument_errors_are_one_line_with_exit_code_1() {
    for (args, what) in [
        (&["render", "--spp", "0"][..], "0 is not in 1..="),
        (
            &["render", "--width", "100000"],
            "100000 is not in 1..=65536",
        ),
        (&["render", "--threads", "-1"], "-1 is not in 1..=1024"),
        (
            &["render", "--sampler", "halton"],
            "unknown sampler 'halton'",
        ),
        (
            &["render", "--filter", "lanczos"],
            "expected box, tent, gaussian or mitchell",
        ),
        (
            &["render", "--tonemap", "reinhard"],
            "unknown tone map 'reinhard'",
        ),
        (&["render", "--no-such-option"], "--no-such-option"),
    ] {
        let out = sahara(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(what),
            "{args:?}: {err}"
        );
    }
    // A scene given without `render`, as pbrt and Mitsuba take one.
    let dir = temp_dir("no-subcommand");
    let scene = dir.join("scene.toml");
    fs::write(&scene, "").unwrap();
    let out = sahara(&[scene.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("did you mean: sahara render {}", scene.display())),
        "{err}"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_render_that_cannot_fit_in_memory_is_refused_with_an_estimate() {
    let dir = temp_dir("huge");
    let out_png = dir.join("huge.png");
    let out = sahara(&[
        "render",
        "--width",
        "65536",
        "--height",
        "65536",
        "-o",
        out_png.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("needs about") && err.contains("available"),
        "{err}"
    );
    assert!(!out_png.exists());
}

#[test]
fn a_misspelt_command_or_option_gets_the_nearest_one() {
    for (args, what) in [
        (&["rendr"][..], "did you mean: sahara render"),
        (&["render", "--sp", "16"], "did you mean: --spp"),
        (
            &["render", "--integrater", "path"],
            "did you mean: --integrator",
        ),
    ] {
        let out = sahara(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(what), "{args:?}: {err}");
    }
}

#[test]
fn an_output_that_is_a_folder_is_refused_as_a_folder() {
    let dir = temp_dir("output-folder");
    let out = sahara(&["render", "--spp", "1", "-o", dir.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("{}: is a folder", dir.display())),
        "{err}"
    );
    assert!(!err.contains("extension"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn adaptive_sampling_at_its_minimum_says_no_pixel_can_stop_early() {
    let dir = temp_dir("adaptive-min");
    let png = dir.join("a.png");
    let run = |spp: &str| {
        let out = sahara(&[
            "render",
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            spp,
            "--noise-threshold",
            "0.5",
            "-o",
            png.to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert!(out.status.success(), "{err}");
        err
    };
    // The cap equals the default minimum of 16: every pixel takes 16
    // samples, and the log neither claims pixels stopped early nor hides why.
    let err = run("16");
    assert!(err.contains("every pixel takes all 16 samples"), "{err}");
    assert!(err.contains("100.0% of the 16 spp budget"), "{err}");
    assert!(
        err.contains("0 of 1024 pixels (0.0%) stopped early"),
        "{err}"
    );
    // With room above the minimum, pixels stop early and no warning is given.
    let err = run("256");
    assert!(!err.contains("every pixel takes all"), "{err}");
    assert!(!err.contains(" 0 of 1024 pixels"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn two_identical_exr_renders_are_byte_identical() {
    let dir = temp_dir("exr-repeat");
    let mut files = Vec::new();
    for k in 0..4 {
        let out = dir.join(format!("r{k}.exr"));
        let threads = if k % 2 == 0 { "1" } else { "2" };
        let o = out.to_str().unwrap();
        let args = ["render", "--width", "16", "--height", "12", "--spp", "2"];
        let run = sahara(&[&args[..], &["--threads", threads, "-o", o]].concat());
        assert!(run.status.success(), "{}", stderr(&run));
        files.push(fs::read(&out).unwrap());
    }
    for (k, f) in files.iter().enumerate() {
        assert!(*f == files[0], "render {k} differs from render 0");
    }
    fs::remove_dir_all(dir).unwrap();
}

/// A floor quad lit by a disc area light, with `extra` appended.
fn write_lit_floor(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let scene = dir.join(name);
    fs::write(
        &scene,
        format!(
            "[camera]\neye = [0, 2, 3]\ntarget = [0, 0, 0]\n\n\
             [[object]]\ntype = \"quad\"\ncorner = [-2, 0, 2]\nedge_u = [4, 0, 0]\nedge_v = [0, 0, -4]\n\n\
             [[light]]\ntype = \"area\"\nshape = \"disc\"\ncenter = [0, 1.5, 0]\nnormal = [0, -1, 0]\n\
             radius = 0.5\nradiance = [4, 4, 4]\n\n\
             [film]\nwidth = 8\nheight = 6\n{extra}"
        ),
    )
    .unwrap();
    scene
}

#[test]
fn the_command_line_and_scene_files_share_their_defaults() {
    let dir = temp_dir("defaults");
    // The distribution integrator named on the command line, and named
    // without parameters in a file, render the same image.
    let plain = write_lit_floor(&dir, "plain.toml", "");
    let named = write_lit_floor(
        &dir,
        "named.toml",
        "\n[integrator]\nname = \"distribution\"\n",
    );
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    let run = |args: &[&str]| {
        let out = sahara(args);
        assert!(out.status.success(), "{}", stderr(&out));
        stderr(&out)
    };
    let log_a = run(&[
        "render",
        plain.to_str().unwrap(),
        "--integrator",
        "distribution",
        "-o",
        a.to_str().unwrap(),
    ]);
    let log_b = run(&["render", named.to_str().unwrap(), "-o", b.to_str().unwrap()]);
    assert!(
        fs::read(&a).unwrap() == fs::read(&b).unwrap(),
        "{log_a}\n{log_b}"
    );
    // Samples per pixel: the same default with and without a scene file.
    let c = dir.join("c.png");
    let log_c = run(&[
        "render",
        "--width",
        "8",
        "--height",
        "6",
        "-o",
        c.to_str().unwrap(),
    ]);
    for log in [&log_a, &log_b, &log_c] {
        assert!(log.contains(", 64 spp in passes of 8,"), "{log}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn spp_is_the_samples_per_pixel_rendered_whatever_the_pass_size() {
    let dir = temp_dir("exact-spp");
    for (spp, pass, passes) in [("10", "8", 2), ("10", "4", 3), ("5", "8", 1)] {
        let out = dir.join(format!("s{spp}-{pass}.exr"));
        let o = sahara(&[
            "render",
            "--width",
            "8",
            "--height",
            "6",
            "--spp",
            spp,
            "--pass-spp",
            pass,
            "-o",
            out.to_str().unwrap(),
        ]);
        let log = stderr(&o);
        assert!(o.status.success(), "{log}");
        let pass_size = pass.parse::<u32>().unwrap().min(spp.parse().unwrap());
        assert!(
            log.contains(&format!(", {spp} spp in passes of {pass_size},")),
            "{log}"
        );
        let passes = if passes == 1 {
            "1 pass".to_string()
        } else {
            format!("{passes} passes")
        };
        assert!(log.contains(&format!(": {passes}, {spp} spp,")), "{log}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_scene_files_output_goes_to_the_working_folder() {
    let dir = temp_dir("output-folder");
    let scenes = dir.join("scenes");
    let work = dir.join("work");
    fs::create_dir_all(&scenes).unwrap();
    fs::create_dir_all(&work).unwrap();
    let scene = scenes.join("s.toml");
    fs::write(
        &scene,
        "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n\
         output = \"out.png\"\n[sampler]\nspp = 1\n",
    )
    .unwrap();
    let o = std::process::Command::new(crate::common::SAHARA)
        .args(["render", scene.to_str().unwrap()])
        .current_dir(&work)
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(work.join("out.png").is_file(), "{err}");
    assert!(!scenes.join("out.png").exists(), "{err}");
    let shown = work.canonicalize().unwrap().join("out.png");
    assert!(err.contains(&format!("wrote {}", shown.display())), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn files_that_are_not_scenes_are_refused_saying_what_they_are() {
    let dir = temp_dir("not-scenes");
    let png =
        fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/images/bunny_dof.png"))
            .unwrap();
    let fake_glb = dir.join("model.glb");
    let fake_obj = dir.join("model.obj");
    fs::write(&fake_glb, &png).unwrap();
    fs::write(&fake_obj, &png).unwrap();
    let empty = dir.join("empty.obj");
    fs::write(&empty, "# only a comment\n").unwrap();
    let two = dir.join("two.obj");
    fs::write(&two, "v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap();
    let cargo = dir.join("Cargo.toml");
    fs::write(
        &cargo,
        "[package]\nname = \"x\"\n[profile.release]\ndebug = 1\n",
    )
    .unwrap();
    let missing = dir.join("scene");
    for (path, what) in [
        (&fake_glb, "is a PNG image, not a scene or mesh file"),
        (&fake_obj, "is a PNG image, not a scene or mesh file"),
        (&empty, "the mesh has no triangles"),
        (&two, "the mesh has no triangles"),
        (&cargo, "not a Sahara scene file"),
        (&missing, "not found"),
    ] {
        let out = dir.join("out.png");
        let o = sahara(&[
            "render",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.contains(path.to_str().unwrap()) && err.contains(what),
            "{err}"
        );
        assert!(!out.exists(), "an image was written for {}", path.display());
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_path_without_a_usable_extension_says_what_it_is() {
    let dir = temp_dir("no-ext");
    let bare = dir.join("scene");
    fs::write(&bare, "[camera]\n").unwrap();
    for (path, what) in [(dir.clone(), "is a folder"), (bare, "has no extension")] {
        let out = sahara(&["render", path.to_str().unwrap()]);
        assert!(!out.status.success());
        let err = stderr(&out);
        assert!(
            err.contains(what) && err.contains(path.to_str().unwrap()),
            "{err}"
        );
        assert!(!err.contains("cannot render . files"), "{err}");
        assert!(
            err.contains("expected a scene file (.toml, .pbrt, .pbrt.gz, .xml) or a mesh"),
            "{err}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_mesh_too_large_to_frame_names_the_file() {
    let dir = temp_dir("huge");
    let obj = dir.join("huge.obj");
    fs::write(&obj, "v -3e38 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n").unwrap();
    let out = sahara(&[
        "render",
        obj.to_str().unwrap(),
        "--width",
        "4",
        "--height",
        "4",
    ]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("huge.obj") && err.contains("too large to frame"),
        "{err}"
    );
    assert!(!err.contains("invalid scene: camera"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

/// `sahara render SCENE --spp 1 -o OUTPUT`, and its log.
fn render_one_sample(scene: &Path, output: &Path) -> (Output, String) {
    let out = sahara(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "1",
        "-o",
        output.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    (out, err)
}

#[test]
fn the_no_light_warning_is_printed_once() {
    let dir = temp_dir("unlit");
    let scene = dir.join("dark.toml");
    fs::write(
        &scene,
        "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n\n\
         [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\n\
         [film]\nwidth = 4\nheight = 4\n",
    )
    .unwrap();
    let (out, err) = render_one_sample(&scene, &dir.join("dark.png"));
    assert!(out.status.success(), "{err}");
    assert_eq!(err.matches("has no light").count(), 1, "{err}");
    assert!(
        err.contains("dark.toml"),
        "the warning names the file: {err}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// An area light whose emitting face looks away from everything renders
/// black: the log says so, and a light turned towards the scene is not
/// warned about.
#[test]
fn a_light_that_faces_away_from_the_scene_is_warned_about() {
    let dir = temp_dir("away");
    let scene = |name: &str, edges: &str| {
        let path = dir.join(name);
        fs::write(
            &path,
            format!(
                "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n\n\
                 [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\n\
                 [[light]]\ntype = \"area\"\nshape = \"quad\"\ncorner = [-1, 3, -1]\n{edges}\n\
                 radiance = [5, 5, 5]\n\n[film]\nwidth = 8\nheight = 8\n"
            ),
        )
        .unwrap();
        path
    };
    for (name, edges, warned) in [
        ("up.toml", "edge_u = [0, 0, 2]\nedge_v = [2, 0, 0]", true),
        ("down.toml", "edge_u = [2, 0, 0]\nedge_v = [0, 0, 2]", false),
    ] {
        let (out, err) = render_one_sample(&scene(name, edges), &dir.join("x.png"));
        assert!(out.status.success(), "{err}");
        assert_eq!(
            err.contains("no light reaches the scene"),
            warned,
            "{name}: {err}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A glTF file's JSON errors give the position once and say what was
/// expected in words, not Rust's type names.
#[test]
fn gltf_json_errors_say_what_was_expected_in_words() {
    let dir = temp_dir("gltf-words");
    for (json, says) in [
        (
            r#"{"asset":{"version":"2.0"},"nodes":[{"translation":[1,"x",2]}]}"#,
            "expected a number",
        ),
        (
            r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[-1]}]}"#,
            "expected an index (a whole number)",
        ),
    ] {
        let path = dir.join("bad.gltf");
        fs::write(&path, json).unwrap();
        let out = sahara(&[
            "render",
            path.to_str().unwrap(),
            "-o",
            dir.join("x.png").to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert!(!out.status.success());
        assert!(err.contains(says), "{err}");
        assert_eq!(err.matches("line 1").count(), 1, "the position once: {err}");
        assert!(
            !err.contains("f32") && !err.contains("child of root"),
            "{err}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_short_ascii_ply_line_is_reported_at_its_line() {
    let dir = temp_dir("short-ply");
    let ply = dir.join("short.ply");
    fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
    )
    .unwrap();
    for cmd in ["render", "stats", "bench"] {
        let out = sahara(&[cmd, ply.to_str().unwrap()]);
        assert!(!out.status.success(), "{cmd}");
        let err = stderr(&out);
        assert!(
            err.contains("short.ply: line 11:") && err.contains("expected 3 values, found 2"),
            "{cmd}: {err}"
        );
        assert!(!err.contains("nothing to frame"), "{cmd}: {err}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn the_depth_view_spans_the_visible_range_in_png_and_stays_raw_in_exr() {
    let dir = temp_dir("depth");
    let (png, exr) = (dir.join("depth.png"), dir.join("depth.exr"));
    let mut logs = String::new();
    for out in [&png, &exr] {
        let o = sahara(&[
            "render",
            "--integrator",
            "depth",
            "--width",
            "24",
            "--height",
            "24",
            "--spp",
            "1",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        logs += &stderr(&o);
    }
    assert!(
        logs.contains("nearest hit") && logs.contains("farthest"),
        "{logs}"
    );
    // PNG: the box's near and far walls are far apart in grey.
    let (_, _, shown) = load_rgb_f32(&png).unwrap();
    let (lo, hi) = shown
        .iter()
        .fold((f32::INFINITY, 0.0f32), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(hi > 0.9 && hi - lo > 0.5, "PNG range {lo}..{hi}");
    // EXR: raw distances (the Cornell box is hundreds of units deep).
    let (_, _, raw) = load_rgb_f32(&exr).unwrap();
    let far = raw.iter().fold(0.0f32, |a, &b| a.max(b));
    assert!(far > 100.0, "EXR holds distances, max {far}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn render_takes_a_camera_sidecar_and_a_builder() {
    let dir = temp_dir("camera-builder");
    let obj = write_quad(&dir, "Kd 0.8 0.8 0.8");
    let far = dir.join("far.json");
    fs::write(&far, r#"{"eye":[0,0,30],"target":[0,0,0],"vfov_deg":60}"#).unwrap();
    let render = |extra: &[&str], out: &Path| {
        let args = [
            "render",
            obj.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "16",
        ];
        let o = sahara(
            &[
                &args[..],
                &["--spp", "2", "-o", out.to_str().unwrap()],
                extra,
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let (near_img, far_img) = (dir.join("near.exr"), dir.join("far.exr"));
    let log = render(&[], &near_img);
    assert!(log.contains("quad.camera.json"), "{log}");
    let log = render(&["--camera", far.to_str().unwrap()], &far_img);
    assert!(
        log.contains("camera: ") && log.contains("far.json"),
        "{log}"
    );
    // From ten times as far the view differs.
    assert!(fs::read(&far_img).unwrap() != fs::read(&near_img).unwrap());

    // The builder changes the speed, never the image.
    for builder in ["median", "binned16", "rr-middle"] {
        let out = dir.join(format!("{builder}.exr"));
        render(&["--builder", builder], &out);
        assert!(
            fs::read(&out).unwrap() == fs::read(&near_img).unwrap(),
            "--builder {builder} changed the image"
        );
    }
    let o = sahara(&["render", obj.to_str().unwrap(), "--builder", "octree"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("unknown builder 'octree'"),
        "{}",
        stderr(&o)
    );
    // A missing sidecar names the file.
    let missing = dir.join("missing.json");
    let o = sahara(&[
        "render",
        obj.to_str().unwrap(),
        "--camera",
        missing.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("missing.json"), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn an_area_light_with_a_material_also_reflects() {
    let dir = temp_dir("reflecting-light");
    // The camera sees the back of a one-sided light panel (which emits
    // nothing that way) under a white sky.
    let write = |name: &str, extra: &str| {
        let scene = dir.join(name);
        fs::write(
            &scene,
            format!(
                "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nvfov = 20\n\n\
                 [[material]]\nname = \"diffuser\"\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\n\
                 [[light]]\ntype = \"area\"\nshape = \"quad\"\ncorner = [-2, -2, 0]\n\
                 edge_u = [0, 4, 0]\nedge_v = [4, 0, 0]\nradiance = [5, 5, 5]\n{extra}\n\
                 [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n\n\
                 [film]\nwidth = 8\nheight = 8\n"
            ),
        )
        .unwrap();
        render_mean_8x8(&scene, &dir.join(format!("{name}.exr")))
    };
    let black = write("black.toml", "");
    let white = write("white.toml", "material = \"diffuser\"\n");
    assert_eq!(
        black, 0.0,
        "without a material the back of the panel is black"
    );
    // A white diffuser under a uniform white sky reflects about its albedo.
    assert!((white - 0.8).abs() < 0.05, "mean {white}");

    // An emitting object: an emission material with an albedo reflects too.
    let object = |name: &str, albedo: &str| {
        let scene = dir.join(name);
        fs::write(
            &scene,
            format!(
                "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nvfov = 20\n\n\
                 [[material]]\nname = \"panel\"\ntype = \"emission\"\nradiance = [5, 5, 5]\n{albedo}\n\
                 [[object]]\ntype = \"quad\"\ncorner = [-2, -2, 0]\nedge_u = [0, 4, 0]\n\
                 edge_v = [4, 0, 0]\nmaterial = \"panel\"\n\n\
                 [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n\n\
                 [film]\nwidth = 8\nheight = 8\n"
            ),
        )
        .unwrap();
        render_mean_8x8(&scene, &dir.join(format!("{name}.exr")))
    };
    assert_eq!(object("dark_object.toml", ""), 0.0);
    let white = object("white_object.toml", "albedo = [0.8, 0.8, 0.8]");
    assert!((white - 0.8).abs() < 0.05, "mean {white}");
    let _ = fs::remove_dir_all(&dir);
}

/// Render `scene` (an 8x8 film) at 16 spp to the EXR `out`; its mean.
fn render_mean_8x8(scene: &Path, out: &Path) -> f32 {
    let o = sahara(&[
        "render",
        scene.to_str().unwrap(),
        "--spp",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    checked_mean(out, 8, 8)
}

#[test]
fn a_pbrt_scene_renders_with_its_film_and_its_warnings_counted() {
    let dir = temp_dir("pbrt");
    let scene = dir.join("s.pbrt");
    fs::write(
        &scene,
        "LookAt 0 0 3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
         Film \"rgb\" \"integer xresolution\" 12 \"integer yresolution\" 6 \"string filename\" \"from_file.png\"\n\
         Sampler \"halton\" \"integer pixelsamples\" 2\nWorldBegin\n\
         LightSource \"infinite\" \"rgb L\" [1 1 1]\n\
         Material \"coateddiffuse\" Shape \"sphere\"\nShape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n\
         Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n",
    )
    .unwrap();
    let out = sahara(&["render", scene.to_str().unwrap()]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("shape 'curve' is not supported; skipped (2 times"),
        "{err}"
    );
    let mean = checked_mean(&dir.join("from_file.png"), 12, 6);
    assert!(mean > 0.1, "a lit sphere on a white sky: {mean}");
    // Compressed, and with the size overridden.
    let text = fs::read(&scene).unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut gz, &text).unwrap();
    fs::write(dir.join("z.pbrt.gz"), gz.finish().unwrap()).unwrap();
    let png = dir.join("cli.png");
    let out = sahara(&[
        "render",
        dir.join("z.pbrt.gz").to_str().unwrap(),
        "--width",
        "5",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    checked_mean(&png, 5, 6);
    // An error names the file, line and column.
    fs::write(dir.join("bad.pbrt"), "WorldBegin\n  Shapee \"sphere\"\n").unwrap();
    let out = sahara(&["render", dir.join("bad.pbrt").to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("bad.pbrt: line 2: column 3: unknown directive 'Shapee'"),
        "{}",
        stderr(&out)
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_pbrt_crop_window_renders_those_pixels_of_the_whole_frame() {
    let dir = temp_dir("pbrt-crop");
    let frame = "LookAt 0 0 3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
                 Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 12 CROP\n\
                 Sampler \"independent\" \"integer pixelsamples\" 4\nWorldBegin\n\
                 LightSource \"infinite\" \"rgb L\" [1 1 1]\n\
                 Material \"diffuse\" \"rgb reflectance\" [0.7 0.3 0.2] Shape \"sphere\"\n";
    let render = |name: &str, crop: &str| {
        let scene = dir.join(format!("{name}.pbrt"));
        fs::write(&scene, frame.replace("CROP", crop)).unwrap();
        let exr = dir.join(format!("{name}.exr"));
        let out = sahara(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        (load_rgb_f32(&exr).unwrap(), stderr(&out))
    };
    let ((w, h, whole), _) = render("whole", "");
    assert_eq!((w, h), (16, 12));
    // pbrt-v4's rule: x from ceil(0.3 * 16) = 5 to ceil(0.8 * 16) = 13,
    // y from ceil(0.25 * 12) = 3 to ceil(0.6 * 12) = 8.
    for (name, crop) in [
        ("crop", "\"float cropwindow\" [0.3 0.8 0.25 0.6]"),
        ("bounds", "\"integer pixelbounds\" [5 13 3 8]"),
    ] {
        let ((cw, ch, part), err) = render(name, crop);
        assert_eq!((cw, ch), (8, 5), "{name}");
        assert!(
            err.contains(
                "crop window of the scene file: pixels x 5..13, y 3..8, written as a 8x5 image"
            ),
            "{err}"
        );
        for y in 0..5usize {
            for x in 0..8usize {
                let (i, j) = (3 * (y * 8 + x), 3 * ((y + 3) * 16 + x + 5));
                assert_eq!(part[i..i + 3], whole[j..j + 3], "{name}: pixel {x}, {y}");
            }
        }
    }
    let _ = fs::remove_dir_all(&dir);
}

/// The channels of an EXR file by name, as floats.
fn exr_channels(path: &Path) -> std::collections::BTreeMap<String, Vec<f32>> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    let mut out = std::collections::BTreeMap::new();
    for layer in &image.layer_data {
        for ch in &layer.channel_data.list {
            out.insert(
                ch.name.to_string(),
                ch.sample_data.values_as_f32().collect(),
            );
        }
    }
    out
}

/// `--aov` writes the passes as named layers beside the beauty, which stays
/// as it is without them; the albedo of the built-in Cornell box's walls is
/// their reflectance, its normals are unit vectors, its depths positive.
#[test]
fn render_passes_are_layers_of_the_exr() {
    let dir = temp_dir("aov");
    let (with, without) = (dir.join("with.exr"), dir.join("without.exr"));
    let args = ["render", "--width", "24", "--height", "24", "--spp", "4"];
    let out = sahara(
        &[
            &args[..],
            &["--aov", "albedo,normal,depth", "-o", with.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = sahara(&[&args[..], &["-o", without.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let a = exr_channels(&with);
    let b = exr_channels(&without);
    let names: Vec<&str> = a.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "normal.X", "normal.Y",
            "normal.Z"
        ]
    );
    for c in ["R", "G", "B"] {
        assert_eq!(a[c], b[c], "the beauty's {c} changed");
    }
    let n = 24 * 24;
    assert!(a["albedo.R"].iter().all(|v| (0.0..=1.0).contains(v)));
    assert!(
        a["depth.Z"].iter().all(|&d| d > 0.0),
        "the box is closed around the camera's view"
    );
    let length = |k: usize| {
        (a["normal.X"][k].powi(2) + a["normal.Y"][k].powi(2) + a["normal.Z"][k].powi(2)).sqrt()
    };
    assert!((0..n).all(|k| length(k) <= 1.0 + 1e-4));
    // Pixels on an edge average two normals, and those at the open front of
    // the box average a wall's with the zero of samples that escape; the
    // others are whole.
    let unit = (0..n).filter(|&k| (length(k) - 1.0).abs() < 1e-3).count();
    assert!(unit > n / 2, "{unit} of {n} unit normals");
    // The middle of the back wall (below the ceiling, above the boxes)
    // faces the camera.
    let k = 6 * 24 + 12;
    let normal = [a["normal.X"][k], a["normal.Y"][k], a["normal.Z"][k]];
    assert!((normal[2] + 1.0).abs() < 1e-3, "{normal:?}");
}

/// The `object` and `material` passes hold, per pixel, the ids of what its
/// centre shows, and the list beside the image names them as the scene
/// file does: a named sphere in front of a wall that does not fill the
/// frame.
#[test]
fn id_passes_say_what_each_pixel_shows() {
    let dir = temp_dir("aov-ids");
    let scene = dir.join("ids.toml");
    fs::write(
        &scene,
        r#"
sky = "none"
[film]
width = 32
height = 32
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
vfov = 40
[[material]]
name = "blue"
type = "diffuse"
albedo = [0.2, 0.3, 0.6]
[[material]]
name = "grey"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[light]]
type = "point"
position = [0, 3, 4]
intensity = [10, 10, 10]
[[object]]
type = "quad"
name = "wall"
corner = [-3, -1, -2]
edge_u = [6, 0, 0]
edge_v = [0, 2, 0]
material = "grey"
[[object]]
type = "sphere"
name = "ball"
center = [0, 0, 0]
radius = 1
material = "blue"
"#,
    )
    .unwrap();
    let exr = dir.join("ids.exr");
    let out = sahara(&[
        "render",
        scene.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "32",
        "--spp",
        "2",
        "--aov",
        "object,material",
        "-o",
        exr.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let a = exr_channels(&exr);
    let names: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("ids.names.json")).unwrap()).unwrap();
    let at = |pass: &str, x: usize, y: usize| {
        let id = a[&format!("{pass}.id")][y * 32 + x];
        assert_eq!(id.fract(), 0.0, "an id is a whole number");
        if id == 0.0 {
            return "nothing".to_string();
        }
        names[pass][format!("{id}")].as_str().unwrap().to_string()
    };
    // The centre shows the ball, the left edge the wall, the top row
    // (above the wall) nothing.
    assert_eq!(
        (at("object", 16, 16), at("material", 16, 16)),
        ("ball".into(), "blue".into())
    );
    assert_eq!(
        (at("object", 2, 16), at("material", 2, 16)),
        ("wall".into(), "grey".into())
    );
    assert_eq!(
        (at("object", 16, 0), at("material", 16, 0)),
        ("nothing".into(), "nothing".into())
    );
    // The ball is a disc of angular radius asin(1/5) in a 40 degree view:
    // about 0.56 of the half-height, 9 pixels of 16.
    let ball = (0..32 * 32)
        .filter(|&k| at("object", k % 32, k / 32) == "ball")
        .count() as f64;
    let expected = std::f64::consts::PI * (0.559 * 16.0f64).powi(2);
    assert!(
        (ball / expected - 1.0).abs() < 0.1,
        "{ball} ball pixels, expected {expected:.0}"
    );
}

#[test]
fn render_passes_need_an_exr_and_a_path_tracer() {
    let dir = temp_dir("aov-errors");
    let png = dir.join("x.png");
    let out = sahara(&["render", "--aov", "albedo", "-o", png.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("is not one (name a .exr file)"),
        "{}",
        stderr(&out)
    );
    let exr = dir.join("x.exr");
    let out = sahara(&[
        "render",
        "--aov",
        "depth",
        "--integrator",
        "ao",
        "--spp",
        "1",
        "-o",
        exr.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("--aov: the ao integrator cannot make render passes"),
        "{}",
        stderr(&out)
    );
    let out = sahara(&["render", "--aov", "objects", "-o", exr.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("albedo, normal, depth, position, uv, variance, object or material"),
        "{}",
        stderr(&out)
    );
    assert!(!exr.exists() && !png.exists());
}

/// `--noise-threshold`: the log says what adaptive sampling did, and the
/// EXR holds the samples each pixel took, between the minimum and the cap
/// in whole passes, adding up to the logged count.
#[test]
fn adaptive_sampling_logs_its_samples_and_writes_them_as_a_layer() {
    let dir = temp_dir("adaptive");
    let exr = dir.join("a.exr");
    let out = sahara(&[
        "render",
        "--width",
        "24",
        "--height",
        "24",
        "--spp",
        "48",
        "--noise-threshold",
        "0.05",
        "--min-spp",
        "8",
        "-o",
        exr.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let log = stderr(&out);
    assert!(
        log.contains("(adaptive: noise threshold 0.05, at least 8 spp)"),
        "{log}"
    );
    let line = log
        .lines()
        .find(|l| l.starts_with("adaptive: "))
        .unwrap_or_else(|| panic!("no adaptive line in {log}"));
    let logged: u64 = line["adaptive: ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let layers = exr_channels(&exr);
    let samples = &layers["samples.Y"];
    assert_eq!(samples.len(), 24 * 24);
    assert!(samples
        .iter()
        .all(|&n| (8.0..=48.0).contains(&n) && n % 8.0 == 0.0));
    assert!(samples.iter().any(|&n| n < 48.0), "no pixel stopped");
    assert_eq!(samples.iter().map(|&n| n as u64).sum::<u64>(), logged);
}

/// A scene file asks for adaptive sampling in `[sampler]` and for
/// denoising in `[film]`; the command line's threshold wins, and what
/// cannot be split over a farm is refused for the file's keys too.
#[test]
fn a_scene_file_asks_for_adaptive_sampling_and_denoising() {
    let dir = temp_dir("file-adaptive");
    let scene = dir.join("s.toml");
    let write = |sampler: &str, film: &str| {
        fs::write(
            &scene,
            format!(
                "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n\n\
                 [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\n\
                 [[light]]\ntype = \"point\"\nposition = [0, 4, 2]\nintensity = [20, 20, 20]\n\n\
                 [sampler]\nspp = 32\n{sampler}\n[film]\nwidth = 16\nheight = 16\n{film}\n"
            ),
        )
        .unwrap();
    };
    let exr = dir.join("x.exr");
    let run = |extra: &[&str]| {
        let args = [
            &[
                "render",
                scene.to_str().unwrap(),
                "-o",
                exr.to_str().unwrap(),
            ][..],
            extra,
        ]
        .concat();
        let out = sahara(&args);
        let err = stderr(&out);
        (out.status.success(), err)
    };
    write("noise_threshold = 0.05\nmin_spp = 8", "");
    let (ok, err) = run(&[]);
    assert!(ok, "{err}");
    assert!(
        err.contains("(adaptive: noise threshold 0.05, at least 8 spp)"),
        "{err}"
    );
    let (ok, err) = run(&["--noise-threshold", "0.1"]);
    assert!(
        ok && err.contains("noise threshold 0.1, at least 8 spp"),
        "{err}"
    );
    let (ok, err) = run(&["--samples", "0..8"]);
    assert!(
        !ok && err.contains(
            "the scene file's noise_threshold: adaptive sampling cannot be used with sample ranges"
        ),
        "{err}"
    );
    write("min_spp = 8", "");
    let (ok, err) = run(&[]);
    assert!(
        !ok && err.contains("`min_spp` needs `noise_threshold`"),
        "{err}"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn adaptive_sampling_refuses_sample_ranges_and_bad_thresholds() {
    let dir = temp_dir("adaptive-errors");
    let exr = dir.join("part.exr");
    for (args, says) in [
        (
            &["--noise-threshold", "0.01", "--samples", "0..8"][..],
            "cannot be used with sample ranges",
        ),
        (
            &[
                "--noise-threshold",
                "0.01",
                "--part",
                "1/2",
                "--split",
                "samples",
            ][..],
            "cannot be used with sample ranges",
        ),
        (&["--noise-threshold", "0"][..], "must be a positive number"),
        (
            &["--noise-threshold", "nan"][..],
            "must be a positive number",
        ),
        (&["--min-spp", "4"][..], "--noise-threshold"),
    ] {
        let out = sahara(&[&["render", "-o", exr.to_str().unwrap()][..], args].concat());
        assert!(!out.status.success(), "{args:?}");
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
    }
    assert!(!exr.exists());
}

/// Root-mean-square difference over the pixels the reference shows below
/// 1 (the light's own pixels, far brighter, would decide it alone).
fn rmse_below_one(a: &[f32], reference: &[f32]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (p, r) in a.chunks(3).zip(reference.chunks(3)) {
        if r.iter().all(|&v| v < 1.0) {
            sum += p
                .iter()
                .zip(r)
                .map(|(x, y)| f64::from(x - y).powi(2))
                .sum::<f64>();
            n += 3;
        }
    }
    (sum / n.max(1) as f64).sqrt()
}

/// `--denoise` brings a noisy render much closer to a converged one, keeps
/// the noisy image as a layer, and is refused where it cannot work. Skipped
/// (said so) where Open Image Denoise is not installed, unless
/// `SAHARA_REQUIRE_OIDN` is set, as CI sets it.
#[test]
fn denoising_lowers_the_error_of_a_noisy_render() {
    let dir = temp_dir("denoise");
    let (noisy, reference) = (dir.join("noisy.exr"), dir.join("reference.exr"));
    let args = [
        "render", "--width", "64", "--height", "64", "--filter", "box",
    ];
    let out = sahara(
        &[
            &args[..],
            &["--spp", "8", "--denoise", "-o", noisy.to_str().unwrap()],
        ]
        .concat(),
    );
    if denoiser_missing(&out) {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("denoised with Open Image Denoise"),
        "{}",
        stderr(&out)
    );
    let out = sahara(
        &[
            &args[..],
            &["--spp", "512", "-o", reference.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let a = exr_channels(&noisy);
    let r = exr_channels(&reference);
    let rgb = |m: &std::collections::BTreeMap<String, Vec<f32>>, prefix: &str| -> Vec<f32> {
        let c = |n: &str| &m[&format!("{prefix}{n}")];
        let (r, g, b) = (c("R"), c("G"), c("B"));
        (0..r.len()).flat_map(|k| [r[k], g[k], b[k]]).collect()
    };
    let reference = rgb(&r, "");
    let before = rmse_below_one(&rgb(&a, "noisy."), &reference);
    let after = rmse_below_one(&rgb(&a, ""), &reference);
    assert!(after < 0.6 * before, "denoised {after} vs noisy {before}");
    // Refused where it cannot work, before any rendering.
    let out = sahara(&[
        "render",
        "--denoise",
        "--integrator",
        "normals",
        "-o",
        noisy.to_str().unwrap(),
    ]);
    assert!(
        stderr(&out).contains("--denoise: the normals integrator cannot be denoised"),
        "{}",
        stderr(&out)
    );
}

/// A mesh lit by `auto` says in its log which way the rule went and by
/// what measure: an unlit triangle gets the default sky (own lights at 0).
#[test]
fn the_log_says_why_the_default_sky_was_added() {
    let dir = temp_dir("sky-rule");
    let obj = dir.join("tri.obj");
    fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    // 512x512 at 1 sample: a few milliseconds for one triangle.
    let (out, log) = render_one_sample(&obj, &dir.join("tri.png"));
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("light: default sky and sun (auto: own lights at 0.000 of the default sky and sun's power, below 0.05)"),
        "{log}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// The glTF scenes of `tests/assets/` (written by its
/// `make_framing_scenes.py`).
fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/assets")
        .join(name)
}

/// Renders `model` with its object ids at `width` x `height`; returns the
/// log and the name of the object each pixel shows (`nothing` for the sky).
fn render_objects(model: &Path, dir: &Path, width: u32, height: u32) -> (String, Vec<String>) {
    let exr = dir.join("objects.exr");
    let out = sahara(&[
        "render",
        model.to_str().unwrap(),
        "--width",
        &width.to_string(),
        "--height",
        &height.to_string(),
        "--spp",
        "4",
        "--aov",
        "object",
        "-o",
        exr.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let ids = &exr_channels(&exr)["object.id"];
    let names: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("objects.names.json")).unwrap()).unwrap();
    let objects = ids
        .iter()
        .map(|&id| match id {
            0.0 => "nothing".to_string(),
            // `FILE/NODE`: the node's name.
            id => names["object"][format!("{id}")]
                .as_str()
                .unwrap()
                .rsplit('/')
                .next()
                .unwrap()
                .to_string(),
        })
        .collect();
    (err, objects)
}

/// A small island with a palm in a huge, glowing, gently waved sea: the
/// automatic camera frames the island, not the sea, and the sea's glow does
/// not switch the default sky off.
#[test]
fn a_subject_in_a_huge_glowing_sea_fills_the_frame_under_the_sky() {
    let dir = temp_dir("island-sea");
    let (err, objects) = render_objects(&asset("island_sea.gltf"), &dir, 80, 60);
    assert!(
        err.contains("framing 9 objects; 1 flat or emissive object"),
        "{err}"
    );
    assert!(err.contains("light: default sky and sun"), "{err}");
    let share = |what: &dyn Fn(&str) -> bool| {
        objects.iter().filter(|o| what(o)).count() as f64 / objects.len() as f64
    };
    // The island (20 units across, 7 with the palm) and what stands on it
    // are framed, seen from above: their bounding sphere fills the frame's
    // height, the island about 8 % of the frame and the palm 0.6 %. Framed
    // with the 392-unit sea (seen from 724 units) they would take under
    // 0.1 % and 0.01 %.
    let subject = share(&|o| o != "Sea" && o != "nothing");
    assert!(subject > 0.03, "the island fills {subject} of the frame");
    let palm = share(&|o| o == "Trunk" || o.starts_with("Leaf"));
    assert!(palm > 0.002, "the palm fills {palm} of the frame");
    let _ = fs::remove_dir_all(&dir);
}

/// A Cornell box (five one-sided walls, open at +z) without a camera is
/// looked into through its open side: every wall is seen from inside.
#[test]
fn a_room_open_on_one_side_is_looked_into_through_it() {
    let dir = temp_dir("open-room");
    let (err, objects) = render_objects(&asset("open_room.gltf"), &dir, 40, 30);
    assert!(err.contains("a room open on its +z side"), "{err}");
    // Where each wall is seen: the mean column and row of its pixels.
    let centre = |name: &str| {
        let at: Vec<(usize, usize)> = (0..40 * 30)
            .filter(|&k| objects[k] == name)
            .map(|k| (k % 40, k / 40))
            .collect();
        assert!(at.len() > 20, "{name}: {} pixels", at.len());
        let n = at.len() as f64;
        (
            at.iter().map(|p| p.0 as f64).sum::<f64>() / n,
            at.iter().map(|p| p.1 as f64).sum::<f64>() / n,
        )
    };
    let (left, right, back) = (centre("Left"), centre("Right"), centre("Back"));
    let (floor, ceiling) = (centre("Floor"), centre("Ceiling"));
    // From inside the opening: the left wall on the left, the right wall on
    // the right, the ceiling above, the floor below, the back wall between.
    assert!(
        left.0 < back.0 && back.0 < right.0,
        "{left:?} {back:?} {right:?}"
    );
    assert!(
        ceiling.1 < back.1 && back.1 < floor.1,
        "{ceiling:?} {back:?} {floor:?}"
    );
    // The opening fills the frame's height: the sky only beside the box.
    assert_eq!(objects[15 * 40 + 1], "nothing");
    assert_eq!(objects[15 * 40 + 20], "Block");
    let _ = fs::remove_dir_all(&dir);
}

/// A glTF whose only texture is a KTX2 image (`KHR_texture_basisu`, no PNG
/// fallback; `crates/sahara-readers/tests/data/`, written by its
/// `make_ktx2.py`) renders with it: the square's four quadrants, red and
/// green above, blue and white below, seen where they are.
#[test]
fn a_gltf_with_ktx2_textures_renders_with_them() {
    let dir = temp_dir("ktx2");
    let model =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../sahara-readers/tests/data/quad_basisu.gltf");
    let exr = dir.join("quad.exr");
    let out = sahara(&[
        "render",
        model.to_str().unwrap(),
        "--width",
        "48",
        "--height",
        "36",
        "--spp",
        "4",
        "--aov",
        "albedo",
        "-o",
        exr.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let c = exr_channels(&exr);
    let n = 48 * 36;
    let albedo = |k: usize| [c["albedo.R"][k], c["albedo.G"][k], c["albedo.B"][k]];
    let beauty = |k: usize| [c["R"][k], c["G"][k], c["B"][k]];
    // The pixels whose albedo is each quadrant's colour (linear, as the
    // sRGB codes 255 and 0 decode), their mean position and beauty.
    let quadrant = |want: [f32; 3]| {
        let at: Vec<usize> = (0..n)
            .filter(|&k| (0..3).all(|i| (albedo(k)[i] - want[i]).abs() < 0.01))
            .collect();
        assert!(at.len() > 20, "{want:?}: {} pixels", at.len());
        let mean =
            |f: &dyn Fn(usize) -> f32| at.iter().map(|&k| f(k)).sum::<f32>() / at.len() as f32;
        (
            [mean(&|k| (k % 48) as f32), mean(&|k| (k / 48) as f32)],
            [0, 1, 2].map(|i| mean(&|k| beauty(k)[i])),
        )
    };
    let (red, red_light) = quadrant([1.0, 0.0, 0.0]);
    let (green, green_light) = quadrant([0.0, 1.0, 0.0]);
    let (blue, blue_light) = quadrant([0.0, 0.0, 1.0]);
    let (white, _) = quadrant([1.0, 1.0, 1.0]);
    // Red left of green and above blue; white right of blue, below green.
    assert!(
        red[0] < green[0] && blue[0] < white[0],
        "{red:?} {green:?} {blue:?} {white:?}"
    );
    assert!(
        red[1] < blue[1] && green[1] < white[1],
        "{red:?} {green:?} {blue:?} {white:?}"
    );
    // And the light they reflect is theirs.
    assert!(
        red_light[0] > 10.0 * red_light[1].max(red_light[2]),
        "{red_light:?}"
    );
    assert!(
        green_light[1] > 10.0 * green_light[0].max(green_light[2]),
        "{green_light:?}"
    );
    assert!(
        blue_light[2] > 10.0 * blue_light[0].max(blue_light[1]),
        "{blue_light:?}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// What an integrator does not support (its declaration in the renderer)
/// is refused by the renderer before anything renders, and printed in one
/// line that names the option or scene-file key that asked for it.
#[test]
fn unsupported_settings_are_refused_in_one_line_naming_what_asked() {
    const ADAPTIVE_SPHERE: &str = "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n\
        [[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\
        [[light]]\ntype = \"point\"\nposition = [0, 4, 2]\nintensity = [20, 20, 20]\n\
        [sampler]\nspp = 8\nnoise_threshold = 0.05\n[film]\nwidth = 16\nheight = 16\n";
    let dir = temp_dir("unsupported");
    let scene = dir.join("s.toml");
    fs::write(&scene, ADAPTIVE_SPHERE).unwrap();
    let exr = dir.join("x.exr");
    let o = exr.to_str().unwrap();
    for (args, says) in [
        (
            &[
                "render",
                "--integrator",
                "sppm",
                "--noise-threshold",
                "0.05",
                "-o",
                o,
            ][..],
            "--noise-threshold: the sppm integrator cannot sample adaptively",
        ),
        (
            &[
                "render",
                scene.to_str().unwrap(),
                "--integrator",
                "bdpt",
                "-o",
                o,
            ][..],
            "the scene file's noise_threshold: the bdpt integrator cannot sample adaptively",
        ),
        (
            &[
                "render",
                "--integrator",
                "lightpath",
                "--aov",
                "albedo",
                "-o",
                o,
            ][..],
            "--aov: the lightpath integrator cannot make render passes",
        ),
        (
            &[
                "render",
                "--integrator",
                "sppm",
                "--samples",
                "0..4",
                "-o",
                o,
            ][..],
            "--samples: the sppm integrator cannot render a range of each pixel's samples",
        ),
    ] {
        let out = sahara(args);
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?} was rendered");
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{args:?}: one line: {err}"
        );
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!exr.exists(), "{args:?}: an output was written");
    }
    let _ = fs::remove_dir_all(&dir);
}
