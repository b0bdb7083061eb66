//! PNG/EXR writers: read-back by independent decoders, atomic replacement, checks.

use std::fs;
use std::path::Path;

use sahara_formats::FormatError;
use sahara_formats::{check_writable, write_atomically};
use sahara_formats::{write_exr, write_image, write_png, ImageFormat, Pixels};

use crate::common::TempDir;

/// Names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn png_reads_back_byte_for_byte() {
    let dir = TempDir::new("png");
    let path = dir.0.join("out.png");
    // 3 x 2: red, green, blue / black, white, grey.
    let rgb = [
        255, 0, 0, 0, 255, 0, 0, 0, 255, //
        0, 0, 0, 255, 255, 255, 128, 64, 32,
    ];
    write_png(&path, 3, 2, &rgb).unwrap();
    let decoded = image::open(&path).unwrap().into_rgb8();
    assert_eq!(decoded.dimensions(), (3, 2));
    assert_eq!(decoded.get_pixel(2, 0).0, [0, 0, 255]);
    assert_eq!(decoded.get_pixel(2, 1).0, [128, 64, 32]);
    assert_eq!(decoded.into_raw(), rgb.to_vec());
    assert_eq!(
        listing(&dir.0),
        vec!["out.png"],
        "no temporary file is left"
    );
}

#[test]
fn png_from_linear_floats_is_clamped_and_srgb_encoded_with_text_metadata() {
    let dir = TempDir::new("png-linear");
    let path = dir.0.join("out.PNG");
    // Linear 0.5 is sRGB 0.7354 -> 188; 0.0031308 is the curve's knee (12.92 * it = 0.04045 -> 10).
    let rgb = [0.5, -1.0, 7.0, 0.0031308, 1.0, f32::NAN];
    let meta = vec![
        ("partial".to_owned(), "true".to_owned()),
        ("spp".to_owned(), "16".to_owned()),
    ];
    write_image(&path, 2, 1, Pixels::LinearRgbF32(&rgb), &meta).unwrap();
    let decoded = image::open(&path).unwrap().into_rgb8().into_raw();
    assert_eq!(decoded, vec![188, 0, 255, 10, 255, 0]);

    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(&path).unwrap()));
    let reader = decoder.read_info().unwrap();
    let texts: Vec<(String, String)> = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect();
    assert_eq!(texts, meta);
}

#[test]
fn exr_values_and_metadata_round_trip_exactly() {
    let dir = TempDir::new("exr");
    let path = dir.0.join("out.exr");
    let rgb: Vec<f32> = vec![
        0.0,
        1.0,
        0.1, //
        12345.678,
        1.0e-7,
        0.333_333_34, //
        -2.5,
        65504.0,
        3.0e9, //
        0.5,
        0.25,
        0.125,
    ];
    let meta = vec![
        ("partial".to_owned(), "true".to_owned()),
        ("sahara.spp".to_owned(), "64".to_owned()),
    ];
    write_exr(&path, 2, 2, &rgb, &meta).unwrap();

    let image = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |size, _| vec![[0f32; 3]; size.width() * size.height()],
        |pixels: &mut Vec<[f32; 3]>, p, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[p.y() * 2 + p.x()] = [r, g, b];
        },
    )
    .unwrap();
    assert_eq!(image.layer_data.size.width(), 2);
    assert_eq!(image.layer_data.size.height(), 2);
    let flat: Vec<f32> = image.layer_data.channel_data.pixels.concat();
    assert_eq!(flat, rgb, "pixel values must round-trip bit for bit");
    // Pixel (1, 0) is the second triple.
    assert_eq!(
        image.layer_data.channel_data.pixels[1],
        [12345.678, 1.0e-7, 0.333_333_34]
    );

    let header = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    let other = &header.headers[0].own_attributes.other;
    let text = |key: &str| match other.get(&exr::meta::attribute::Text::from(key)) {
        Some(exr::meta::attribute::AttributeValue::Text(t)) => t.to_string(),
        v => panic!("{key}: {v:?}"),
    };
    assert_eq!(text("partial"), "true");
    assert_eq!(text("sahara.spp"), "64");
}

#[test]
fn the_same_exr_is_written_byte_for_byte_every_time() {
    let dir = TempDir::new("exr-bytes");
    let rgb: Vec<f32> = (0..4 * 3 * 3).map(|i| i as f32 * 0.25).collect();
    let meta: Vec<(String, String)> = (0..8)
        .map(|i| (format!("sahara:key{i}"), format!("value {i}")))
        .collect();
    let first = dir.0.join("first.exr");
    write_exr(&first, 4, 3, &rgb, &meta).unwrap();
    let expected = fs::read(&first).unwrap();
    for k in 0..6 {
        let again = dir.0.join(format!("again{k}.exr"));
        write_exr(&again, 4, 3, &rgb, &meta).unwrap();
        assert!(fs::read(&again).unwrap() == expected, "write {k} differs");
    }
    // Still a valid file with every attribute.
    let header = exr::meta::MetaData::read_from_file(&first, false).unwrap();
    let other = &header.headers[0].own_attributes.other;
    for (key, value) in &meta {
        match other.get(&exr::meta::attribute::Text::from(key.as_str())) {
            Some(exr::meta::attribute::AttributeValue::Text(t)) => {
                assert_eq!(&t.to_string(), value)
            }
            v => panic!("{key}: {v:?}"),
        }
    }
    let (w, h, back) = sahara_formats::load_rgb_f32(&first).unwrap();
    assert_eq!((w, h), (4, 3));
    assert_eq!(back, rgb);
}

#[test]
fn write_image_picks_the_format_by_extension_in_any_case() {
    let dir = TempDir::new("ext");
    let rgb = [0.25f32; 3];
    for (name, magic) in [
        ("a.png", &b"\x89PNG"[..]),
        ("b.PnG", &b"\x89PNG"[..]),
        ("c.EXR", &[0x76, 0x2f, 0x31, 0x01][..]),
    ] {
        let path = dir.0.join(name);
        write_image(&path, 1, 1, Pixels::LinearRgbF32(&rgb), &[]).unwrap();
        assert!(fs::read(&path).unwrap().starts_with(magic), "{name}");
    }
    // 8-bit input to an EXR is sRGB-decoded: code 255 is 1.0 exactly.
    let path = dir.0.join("d.exr");
    write_image(&path, 1, 1, Pixels::Rgb8(&[255, 0, 255]), &[]).unwrap();
    let (_, _, back) = sahara_formats::load_rgb_f32(&path).unwrap();
    assert_eq!(back, vec![1.0, 0.0, 1.0]);

    assert_eq!(
        ImageFormat::from_path(Path::new("x.Exr")).unwrap(),
        ImageFormat::Exr
    );
    for bad in ["out.jpg", "out", "out.png.bak"] {
        let path = dir.0.join(bad);
        let err = write_image(&path, 1, 1, Pixels::LinearRgbF32(&rgb), &[])
            .unwrap_err()
            .to_string();
        assert!(err.contains(bad) && err.contains(".png or .exr"), "{err}");
        assert!(!path.exists());
    }
}

#[test]
fn a_failed_write_leaves_the_existing_file_untouched() {
    let dir = TempDir::new("atomic");
    let path = dir.0.join("render.png");
    fs::write(&path, b"previous render").unwrap();

    // Wrong buffer length (2x2 RGB needs 12 bytes).
    let err = write_png(&path, 2, 2, &[0u8; 11]).unwrap_err().to_string();
    assert!(err.contains("12") && err.contains("11"), "{err}");
    let err = write_exr(&path.with_extension("exr"), 2, 2, &[0.0; 13], &[])
        .unwrap_err()
        .to_string();
    assert!(err.contains("12") && err.contains("13"), "{err}");
    // No pixels.
    assert!(write_png(&path, 0, 4, &[]).is_err());
    // A metadata key PNG cannot store.
    let bad_key = vec![(" spaced".to_owned(), "x".to_owned())];
    assert!(write_image(&path, 1, 1, Pixels::Rgb8(&[1, 2, 3]), &bad_key).is_err());

    // A failure half-way through writing the contents.
    let result = write_atomically(&path, |out| {
        use std::io::Write;
        out.write_all(b"half a new ren").unwrap();
        out.flush().unwrap();
        Err(FormatError::in_file("render.png", "simulated failure"))
    });
    assert!(result.is_err());

    assert_eq!(fs::read(&path).unwrap(), b"previous render");
    assert_eq!(
        listing(&dir.0),
        vec!["render.png"],
        "temporary files removed"
    );

    // And a successful write replaces it.
    write_png(&path, 1, 1, &[9, 8, 7]).unwrap();
    assert_eq!(
        image::open(&path).unwrap().into_rgb8().into_raw(),
        vec![9, 8, 7]
    );
    assert_eq!(listing(&dir.0), vec!["render.png"]);
}

#[test]
fn writing_over_a_folder_fails_cleanly() {
    let dir = TempDir::new("over-dir");
    let target = dir.0.join("out.png");
    fs::create_dir(&target).unwrap();
    fs::write(target.join("keep"), b"k").unwrap();
    let err = write_png(&target, 1, 1, &[1, 2, 3])
        .unwrap_err()
        .to_string();
    assert!(err.contains("out.png"), "{err}");
    assert_eq!(listing(&dir.0), vec!["out.png"]);
    assert_eq!(fs::read(target.join("keep")).unwrap(), b"k");
}

#[test]
fn check_writable_reports_missing_folders_and_leaves_nothing_behind() {
    let dir = TempDir::new("writable");
    check_writable(&dir.0.join("render.exr")).unwrap();
    assert!(listing(&dir.0).is_empty());

    let missing = dir.0.join("no-such-folder").join("render.exr");
    let err = check_writable(&missing).unwrap_err().to_string();
    assert!(
        err.contains("no-such-folder") && err.contains("does not exist"),
        "{err}"
    );
    assert!(!err.contains('\n'));

    let err = check_writable(&dir.0).unwrap_err().to_string();
    assert!(err.contains("folder"), "{err}");

    // A read-only folder (skipped when running as root, which may write anywhere).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.0.join("locked");
        fs::create_dir(&locked).unwrap();
        fs::set_permissions(&locked, fs::Permissions::from_mode(0o555)).unwrap();
        let probe = locked.join("probe");
        let root = fs::write(&probe, b"").is_ok();
        let _ = fs::remove_file(&probe);
        if !root {
            let err = check_writable(&locked.join("x.png"))
                .unwrap_err()
                .to_string();
            assert!(err.contains("temporary file"), "{err}");
        }
        fs::set_permissions(&locked, fs::Permissions::from_mode(0o755)).unwrap();
    }
}
