//! A frame rendered in parts (tiles, sample ranges, crop windows, or both)
//! and merged is the whole frame's file byte for byte; `merge` refuses what
//! would not make that frame, naming the file.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{denoiser_missing, sahara, temp_dir};
use sahara_formats::{read_part, write_part};

/// The frame of every test: small, a few passes (the last one shorter), a
/// filter wider than a pixel.
const FRAME: &[&str] = &[
    "--width",
    "23",
    "--height",
    "17",
    "--spp",
    "10",
    "--pass-spp",
    "4",
    "--filter",
    "mitchell",
];

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `sahara render FRAME EXTRA -o OUT`, which must succeed.
fn render(extra: &[&str], out: &Path) {
    let o = out.to_str().unwrap();
    let r = sahara(&[&["render"], FRAME, extra, &["--threads", "2", "-o", o]].concat());
    assert!(r.status.success(), "{extra:?}: {}", stderr(&r));
}

/// `sahara merge PARTS -o OUT` and its result.
fn merge(parts: &[PathBuf], out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["merge".to_string()];
    args.extend(parts.iter().map(|p| p.display().to_string()));
    args.extend(["-o".to_string(), out.display().to_string()]);
    args.extend(extra.iter().map(|s| s.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    sahara(&args)
}

/// Renders the parts given by `pieces` (extra options each) into `dir`.
fn parts(dir: &Path, tag: &str, pieces: &[Vec<String>]) -> Vec<PathBuf> {
    pieces
        .iter()
        .enumerate()
        .map(|(k, extra)| {
            let p = dir.join(format!("{tag}-{k}.exr"));
            let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
            render(&extra, &p);
            p
        })
        .collect()
}

fn split(n: u32, how: &str) -> Vec<Vec<String>> {
    (0..n)
        .map(|i| {
            vec![
                "--part".into(),
                format!("{i}/{n}"),
                "--split".into(),
                how.into(),
            ]
        })
        .collect()
}

#[test]
fn tiles_sample_ranges_and_crops_merge_to_the_whole_frame_byte_for_byte() {
    let dir = temp_dir("farm-merge");
    let (whole_exr, whole_png) = (dir.join("whole.exr"), dir.join("whole.png"));
    render(&[], &whole_exr);
    render(&[], &whole_png);
    // 5 tiles, one rendered with another tree builder (not part of the frame).
    let mut tiles = split(5, "tiles");
    tiles[2].extend(["--builder".into(), "binned".into()]);
    // Tiles x sample ranges, with an empty range and a range across passes.
    let mut both = Vec::new();
    for i in 0..3 {
        for r in ["0..0", "0..3", "3..9", "9..10"] {
            both.push(vec![
                "--part".into(),
                format!("{i}/3"),
                "--samples".into(),
                r.into(),
            ]);
        }
    }
    // Hand-made crop windows, one of them split by samples.
    let crops = vec![
        vec!["--crop".into(), "0,0.4,0,1".into()],
        vec!["--crop".into(), "0.4,1,0,0.5".into()],
        vec![
            "--crop".into(),
            "0.4,1,0.5,1".into(),
            "--part".into(),
            "0/2".into(),
            "--split".into(),
            "samples".into(),
        ],
        vec![
            "--crop".into(),
            "0.4,1,0.5,1".into(),
            "--part".into(),
            "1/2".into(),
            "--split".into(),
            "samples".into(),
        ],
    ];
    for (tag, pieces) in [
        ("tiles", tiles),
        ("samples", split(4, "samples")),
        ("both", both),
        ("crops", crops),
    ] {
        let files = parts(&dir, tag, &pieces);
        for whole in [&whole_exr, &whole_png] {
            let ext = whole.extension().unwrap().to_str().unwrap();
            let out = dir.join(format!("merged-{tag}.{ext}"));
            let m = merge(&files, &out, &[]);
            assert!(m.status.success(), "{tag}: {}", stderr(&m));
            assert!(
                fs::read(&out).unwrap() == fs::read(whole).unwrap(),
                "{tag}: the merged {ext} differs from the whole frame's"
            );
        }
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn merge_refuses_what_would_not_make_the_frame() {
    let dir = temp_dir("farm-refusals");
    let files = parts(&dir, "t", &split(2, "tiles"));
    let out = dir.join("out.exr");
    let refused = |parts: &[PathBuf], extra: &[&str], what: &[&str]| {
        let m = merge(parts, &out, extra);
        let e = stderr(&m);
        assert!(!m.status.success(), "{what:?} was merged");
        assert_eq!(e.trim_end().lines().count(), 1, "one line: {e}");
        for w in what {
            assert!(e.contains(w), "{w:?} not in: {e}");
        }
        assert!(!out.exists(), "an output was written");
    };
    // Missing: tile 1 of 2, every sample of it.
    refused(
        &files[..1],
        &[],
        &["missing samples 0..10 of tile 1 of 2 (pixels x 11..23, y 0..17)"],
    );
    // Missing samples of a tile.
    let half = dir.join("half.exr");
    render(&["--part", "1/2", "--samples", "0..8"], &half);
    refused(
        &[files[0].clone(), half.clone()],
        &[],
        &["missing samples 8..10 of tile 1 of 2"],
    );
    // Overlap: a part given twice, and a sample range inside another.
    refused(
        &[files[0].clone(), files[1].clone(), files[1].clone()],
        &[],
        &["overlap", "t-1.exr", "samples 0..10"],
    );
    refused(
        &[files[0].clone(), files[1].clone(), half.clone()],
        &[],
        &["overlap", "half.exr", "samples 0..8"],
    );
    // Another frame: another seed.
    let other = dir.join("other.exr");
    render(&["--part", "1/2", "--seed", "7"], &other);
    refused(
        &[files[0].clone(), other.clone()],
        &[],
        &["other.exr: a part of another frame"],
    );
    // Not EXR, truncated, or an EXR image that is not a part.
    let text = dir.join("text.exr");
    fs::write(&text, "not an image\n").unwrap();
    refused(
        &[files[0].clone(), text.clone()],
        &[],
        &["text.exr: not an OpenEXR file"],
    );
    let bytes = fs::read(&files[1]).unwrap();
    let cut = dir.join("cut.exr");
    fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    refused(
        &[files[0].clone(), cut.clone()],
        &[],
        &["cut.exr: truncated or damaged"],
    );
    fs::write(&cut, &bytes[..100]).unwrap();
    refused(&[files[0].clone(), cut.clone()], &[], &["cut.exr:"]);
    let image = dir.join("image.exr");
    render(&[], &image);
    refused(
        &[files[0].clone(), image.clone()],
        &[],
        &["image.exr: not a Sahara render part"],
    );
    // Partial: refused unless allowed, and then said.
    let (info, sums) = read_part(&files[1]).unwrap();
    let partial = dir.join("partial.exr");
    let mut cut_info = info.clone();
    cut_info.complete = false;
    cut_info.samples_done = 0..4;
    write_part(&partial, &cut_info, &sums).unwrap();
    refused(
        &[files[0].clone(), partial.clone()],
        &[],
        &["partial.exr: a partial part", "samples 0..4 of 0..10"],
    );
    let m = merge(
        &[files[0].clone(), partial.clone()],
        &out,
        &["--allow-partial"],
    );
    assert!(m.status.success(), "{}", stderr(&m));
    assert!(
        stderr(&m).contains("merging partial part"),
        "{}",
        stderr(&m)
    );
    let meta = exr::meta::MetaData::read_from_file(&out, false).unwrap();
    let partial_flag = meta.headers[0]
        .own_attributes
        .other
        .get(&exr::meta::attribute::Text::from("sahara:partial"))
        .cloned();
    assert_eq!(
        partial_flag,
        Some(exr::meta::attribute::AttributeValue::Text(
            exr::meta::attribute::Text::from("true")
        ))
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn skip_existing_keeps_a_complete_part_and_renders_any_other() {
    let dir = temp_dir("farm-skip");
    let p = dir.join("p.exr");
    let args = |extra: &[&str]| {
        let o = p.to_str().unwrap().to_string();
        let mut a: Vec<String> = ["render"].iter().map(|s| s.to_string()).collect();
        a.extend(FRAME.iter().map(|s| s.to_string()));
        a.extend(["--part", "1/3", "--skip-existing", "-o"].map(String::from));
        a.push(o);
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |extra: &[&str]| {
        let a = args(extra);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let r = sahara(&a);
        assert!(r.status.success(), "{}", stderr(&r));
        stderr(&r)
    };
    assert!(run(&[]).contains("does not exist"));
    let first = fs::read(&p).unwrap();
    assert!(run(&[]).contains("not rendered again"));
    // The tree builder is not part of the frame: still the same part.
    assert!(run(&["--builder", "binned"]).contains("not rendered again"));
    assert_eq!(fs::read(&p).unwrap(), first);
    // Another seed is another frame; a partial part is rendered again.
    assert!(run(&["--seed", "5"]).contains("another frame"));
    let (mut info, sums) = read_part(&p).unwrap();
    info.complete = false;
    info.samples_done = info.samples.start..info.samples.start;
    write_part(&p, &info, &sums).unwrap();
    assert!(run(&["--seed", "5"]).contains("it is partial"));
    assert!(read_part(&p).unwrap().0.complete);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn part_options_are_checked() {
    for (args, what) in [
        (
            &["render", "--part", "3/3", "-o", "x.exr"][..],
            "is not a part I/N",
        ),
        (
            &["render", "--crop", "0,2,0,1", "-o", "x.exr"],
            "is not a crop window",
        ),
        (
            &["render", "--samples", "5..2", "-o", "x.exr"],
            "is not a sample range",
        ),
        (
            &[
                "render",
                "--spp",
                "4",
                "--pass-spp",
                "4",
                "--samples",
                "0..5",
                "-o",
                "x.exr",
            ],
            "reaches past the frame's 4 samples",
        ),
        (
            &["render", "--part", "0/2", "-o", "x.png"],
            "name a .exr file",
        ),
        (
            &[
                "render",
                "--part",
                "0/2",
                "--time-limit",
                "1",
                "-o",
                "x.exr",
            ],
            "--time-limit: cannot make a part",
        ),
        (
            &["render", "--skip-existing", "-o", "x.exr"],
            "applies to parts",
        ),
    ] {
        let r = sahara(args);
        assert!(!r.status.success(), "{args:?}");
        assert!(stderr(&r).contains(what), "{args:?}: {}", stderr(&r));
    }
}

mod random_splits {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

        /// Random frames and random splits (1-7 tiles x 1-5 sample ranges,
        /// some without pixels or samples): the merged EXR and PNG are the
        /// whole frame's bytes.
        #[test]
        fn random_splits_merge_to_the_whole_frame(
            (w, h, spp, pass) in (1u32..=20, 1u32..=14, 1u32..=9, 1u32..=4),
            (sampler, filter, integrator, seed) in (0usize..3, 0usize..4, 0usize..4, 0u64..100),
            tiles in 1u32..=7,
            cuts in proptest::collection::vec(0.0f64..=1.0, 0..=4),
        ) {
            let dir = temp_dir(&format!("farm-random-{w}-{h}-{spp}-{seed}-{tiles}"));
            let pass = pass.min(spp);
            let total = spp;
            let frame: Vec<String> = [
                "render", "--width", &w.to_string(), "--height", &h.to_string(),
                "--spp", &spp.to_string(), "--pass-spp", &pass.to_string(),
                "--sampler", ["independent", "stratified", "sobol"][sampler],
                "--filter", ["box", "tent", "gaussian", "mitchell"][filter],
                "--integrator", ["path", "distribution", "ao", "normals"][integrator],
                "--seed", &seed.to_string(), "--threads", "2",
            ].iter().map(|s| s.to_string()).collect();
            let run = |extra: &[String], out: &Path| {
                let mut a = frame.clone();
                a.extend(extra.iter().cloned());
                a.extend(["-o".to_string(), out.display().to_string()]);
                let a: Vec<&str> = a.iter().map(String::as_str).collect();
                let r = sahara(&a);
                assert!(r.status.success(), "{a:?}: {}", stderr(&r));
            };
            let mut bounds: Vec<u32> = cuts.iter().map(|c| (c * total as f64) as u32).collect();
            bounds.extend([0, total]);
            bounds.sort_unstable();
            let mut files = Vec::new();
            for i in 0..tiles {
                for r in bounds.windows(2) {
                    let p = dir.join(format!("p{i}-{}-{}.exr", r[0], r[1]));
                    run(&[
                        "--part".into(), format!("{i}/{tiles}"),
                        "--samples".into(), format!("{}..{}", r[0], r[1]),
                    ], &p);
                    files.push(p);
                }
            }
            for ext in ["exr", "png"] {
                let whole = dir.join(format!("whole.{ext}"));
                run(&[], &whole);
                let merged = dir.join(format!("merged.{ext}"));
                let m = merge(&files, &merged, &[]);
                prop_assert!(m.status.success(), "{}", stderr(&m));
                prop_assert!(fs::read(&merged).unwrap() == fs::read(&whole).unwrap(),
                    "the merged {} differs", ext);
            }
            fs::remove_dir_all(&dir).unwrap();
        }
    }
}

/// Bidirectional path tracing splits by samples exactly (its light
/// tracing lands anywhere in the frame, from every pixel's samples, and
/// the sums do not depend on the order it arrives in); a split by pixels,
/// or adaptive sampling, is refused in one line before anything renders.
#[test]
fn bdpt_splits_by_samples_exactly_and_refuses_splits_by_pixels() {
    let dir = temp_dir("farm-bdpt");
    let bdpt = ["--integrator", "bdpt"];
    let whole = dir.join("whole.exr");
    render(&bdpt, &whole);
    let pieces: Vec<Vec<String>> = split(3, "samples")
        .into_iter()
        .map(|mut p| {
            p.extend(bdpt.iter().map(|s| s.to_string()));
            p
        })
        .collect();
    let files = parts(&dir, "bdpt", &pieces);
    let out = dir.join("merged.exr");
    let m = merge(&files, &out, &[]);
    assert!(m.status.success(), "{}", stderr(&m));
    assert!(
        fs::read(&out).unwrap() == fs::read(&whole).unwrap(),
        "the merged bdpt frame differs from the whole one"
    );
    let o = dir.join("refused.exr");
    for extra in [
        &["--part", "0/2", "--split", "tiles"][..],
        &["--crop", "0,0.5,0,1"][..],
        &["--noise-threshold", "0.05"][..],
    ] {
        let r = sahara(
            &[
                &["render"],
                FRAME,
                &bdpt,
                extra,
                &["-o", o.to_str().unwrap()],
            ]
            .concat(),
        );
        let e = stderr(&r);
        assert!(!r.status.success(), "{extra:?} was rendered");
        assert_eq!(e.trim_end().lines().count(), 1, "{extra:?}: one line: {e}");
        assert!(e.contains("bdpt"), "{extra:?}: {e}");
        assert!(!o.exists(), "{extra:?}: an output was written");
    }
    fs::remove_dir_all(&dir).unwrap();
}

/// SPPM splits by tiles exactly (a pixel's estimate depends on its own
/// visible points and the photons only); a split by samples, whose
/// iterations depend on the ones before, is refused in one line.
#[test]
fn sppm_splits_by_tiles_exactly_and_refuses_sample_ranges() {
    let dir = temp_dir("farm-sppm");
    let sppm = ["--integrator", "sppm"];
    let whole = dir.join("whole.exr");
    render(&sppm, &whole);
    let pieces: Vec<Vec<String>> = split(3, "tiles")
        .into_iter()
        .map(|mut p| {
            p.extend(sppm.iter().map(|s| s.to_string()));
            p
        })
        .collect();
    let files = parts(&dir, "sppm", &pieces);
    let out = dir.join("merged.exr");
    let m = merge(&files, &out, &[]);
    assert!(m.status.success(), "{}", stderr(&m));
    assert!(
        fs::read(&out).unwrap() == fs::read(&whole).unwrap(),
        "the merged sppm frame differs from the whole one"
    );
    let o = dir.join("refused.exr");
    for extra in [
        &["--part", "0/2", "--split", "samples"][..],
        &["--samples", "0..5"][..],
        &["--noise-threshold", "0.05"][..],
    ] {
        let r = sahara(
            &[
                &["render"],
                FRAME,
                &sppm,
                extra,
                &["-o", o.to_str().unwrap()],
            ]
            .concat(),
        );
        let e = stderr(&r);
        assert!(!r.status.success(), "{extra:?} was rendered");
        assert_eq!(e.trim_end().lines().count(), 1, "{extra:?}: one line: {e}");
        assert!(e.contains("sppm"), "{extra:?}: {e}");
        assert!(!o.exists(), "{extra:?}: an output was written");
    }
    fs::remove_dir_all(&dir).unwrap();
}

/// Each option list of `pieces` with `extra` added.
fn with(pieces: Vec<Vec<String>>, extra: &[&str]) -> Vec<Vec<String>> {
    pieces
        .into_iter()
        .map(|mut p| {
            p.extend(extra.iter().map(|s| s.to_string()));
            p
        })
        .collect()
}

/// The names of an EXR file's channels.
fn channel_names(path: &Path) -> Vec<String> {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    image
        .layer_data
        .iter()
        .flat_map(|l| l.channel_data.list.iter().map(|c| c.name.to_string()))
        .collect()
}

/// Render passes are merged like the beauty: the merged frame's layers
/// (and, with adaptive sampling, its sample counts) are the whole frame's
/// byte for byte; parts rendered with other passes are refused.
#[test]
fn render_passes_merge_to_the_whole_frames_byte_for_byte() {
    let dir = temp_dir("farm-passes");
    let aov = [
        "--aov",
        "albedo,normal,depth,position,uv,variance,object,material",
    ];
    let adaptive = ["--noise-threshold", "0.05", "--aov", "depth"];
    for (tag, extra, pieces) in [
        ("tiles", &aov[..], split(3, "tiles")),
        ("samples", &aov[..], split(3, "samples")),
        ("adaptive", &adaptive[..], split(2, "tiles")),
    ] {
        let whole = dir.join(format!("whole-{tag}.exr"));
        render(extra, &whole);
        let names = channel_names(&whole);
        for layer in ["depth.Z", "R"] {
            assert!(names.iter().any(|n| n == layer), "{tag}: {names:?}");
        }
        if tag == "adaptive" {
            assert!(names.iter().any(|n| n == "samples.Y"), "{names:?}");
        }
        let files = parts(&dir, tag, &with(pieces, extra));
        let out = dir.join(format!("merged-{tag}.exr"));
        let m = merge(&files, &out, &[]);
        assert!(m.status.success(), "{tag}: {}", stderr(&m));
        assert!(
            fs::read(&out).unwrap() == fs::read(&whole).unwrap(),
            "{tag}: the merged passes differ from the whole frame's"
        );
        // The list of names of the id passes comes along.
        let names = |image: &Path| fs::read_to_string(image.with_extension("names.json")).ok();
        assert_eq!(names(&out), names(&whole), "{tag}");
        assert_eq!(names(&out).is_some(), tag != "adaptive", "{tag}");
    }
    // One tile rendered without the passes: refused in one line.
    let mut files = parts(&dir, "mixed", &with(split(3, "tiles"), &aov));
    files[0] = parts(&dir, "plain", &split(3, "tiles")[..1])[0].clone();
    let out = dir.join("mixed.exr");
    let m = merge(&files, &out, &[]);
    let e = stderr(&m);
    assert!(!m.status.success());
    assert_eq!(e.trim_end().lines().count(), 1, "one line: {e}");
    assert!(e.contains("other render passes"), "{e}");
    assert!(!out.exists());
    fs::remove_dir_all(&dir).unwrap();
}

/// Parts of a denoised frame carry the albedo and normal and are not
/// denoised alone; `merge` denoises the merged frame, which is then the
/// whole frame's denoised image. Skipped (said so) where Open Image Denoise
/// is not installed, unless `SAHARA_REQUIRE_OIDN` is set, as CI sets it.
#[test]
fn a_denoised_frame_is_denoised_once_merged() {
    let dir = temp_dir("farm-denoise");
    let whole = dir.join("whole.exr");
    let o = whole.to_str().unwrap();
    let r = sahara(&[&["render"], FRAME, &["--denoise", "-o", o]].concat());
    if denoiser_missing(&r) {
        return;
    }
    assert!(r.status.success(), "{}", stderr(&r));
    let files = parts(&dir, "tile", &with(split(2, "tiles"), &["--denoise"]));
    for f in &files {
        let (info, sums) = read_part(f).unwrap();
        assert!(
            info.output.denoise && info.output.aovs.is_empty(),
            "{info:?}"
        );
        assert!(sums.passes.albedo.is_some() && sums.passes.normal.is_some());
    }
    let out = dir.join("merged.exr");
    let m = merge(&files, &out, &[]);
    assert!(m.status.success(), "{}", stderr(&m));
    assert!(
        stderr(&m).contains("denoised with Open Image Denoise"),
        "{}",
        stderr(&m)
    );
    let read = |p: &Path| {
        let image = exr::prelude::read_all_flat_layers_from_file(p).unwrap();
        let mut out = std::collections::BTreeMap::new();
        for l in &image.layer_data {
            for c in &l.channel_data.list {
                let v: Vec<f32> = c.sample_data.values_as_f32().collect();
                out.insert(c.name.to_string(), v);
            }
        }
        out
    };
    let (a, b) = (read(&out), read(&whole));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "the same layers"
    );
    for (name, va) in &a {
        let vb = &b[name];
        if name.starts_with("noisy.") {
            assert_eq!(va, vb, "{name}: the noisy image is the whole frame's");
        } else {
            // The same network on the same input; allow for a library
            // that is not bit-reproducible across runs.
            let worst = va
                .iter()
                .zip(vb)
                .map(|(x, y)| (x - y).abs() / y.abs().max(1e-3))
                .fold(0.0f32, f32::max);
            assert!(worst < 1e-3, "{name}: off by {worst}");
        }
    }
    // Parts without albedo and normal cannot be denoised.
    let plain = parts(&dir, "plain", &split(2, "tiles"));
    let m = merge(&plain, &dir.join("plain.exr"), &["--denoise"]);
    let e = stderr(&m);
    assert!(
        !m.status.success() && e.contains("no albedo and normal"),
        "{e}"
    );
    fs::remove_dir_all(&dir).unwrap();
}

/// A scene with participating media (the volumetric path tracer, one path
/// at a time) splits by tiles and by samples, and its render passes with
/// it, into parts that merge to the whole frame byte for byte; the whole
/// frame is the same on one thread as on two.
#[test]
fn media_split_and_merge_byte_for_byte() {
    let dir = temp_dir("farm-media");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/fog_cornell.toml");
    let scene = scene.to_str().unwrap();
    let with_scene = |pieces: Vec<Vec<String>>| -> Vec<Vec<String>> {
        pieces
            .into_iter()
            .map(|mut p| {
                p.extend([scene.to_string(), "--aov".into(), "albedo,normal".into()]);
                p
            })
            .collect()
    };
    let whole = dir.join("whole.exr");
    render(&[scene, "--aov", "albedo,normal"], &whole);
    let one = dir.join("one-thread.exr");
    let o = one.to_str().unwrap();
    let r = sahara(
        &[
            &["render"],
            FRAME,
            &[scene, "--aov", "albedo,normal", "--threads", "1", "-o", o],
        ]
        .concat(),
    );
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(
        fs::read(&one).unwrap() == fs::read(&whole).unwrap(),
        "one thread and two render different frames"
    );
    for (tag, how) in [("tiles", "tiles"), ("samples", "samples")] {
        let files = parts(&dir, tag, &with_scene(split(3, how)));
        let out = dir.join(format!("merged-{tag}.exr"));
        let m = merge(&files, &out, &[]);
        assert!(m.status.success(), "{tag}: {}", stderr(&m));
        assert!(
            fs::read(&out).unwrap() == fs::read(&whole).unwrap(),
            "{tag}: the merged frame differs from the whole one"
        );
    }
    fs::remove_dir_all(&dir).unwrap();
}
