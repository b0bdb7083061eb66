//! Texture loading: sRGB decoding of PNG/JPEG, linear HDR/EXR, size limits, errors.

use std::fs;

use sahara_formats::{decode_rgb_f32, load_image, load_rgb_f32};
use sahara_formats::{write_exr, write_png};

use crate::common::TempDir;

fn close(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance
}

#[test]
fn png_is_decoded_from_srgb_to_linear() {
    let dir = TempDir::new("tex-png");
    let path = dir.0.join("t.png");
    // sRGB 128 is linear 0.21586 (((128/255 + 0.055) / 1.055)^2.4); 10 is on the
    // linear segment: 10 / 255 / 12.92 = 0.0030353.
    write_png(&path, 2, 1, &[0, 128, 255, 10, 255, 0]).unwrap();
    let (w, h, rgb) = load_rgb_f32(&path).unwrap();
    assert_eq!((w, h), (2, 1));
    assert_eq!(rgb.len(), 6);
    let expected = [0.0, 0.215_86, 1.0, 0.003_035_3, 1.0, 0.0];
    for (got, want) in rgb.iter().zip(expected) {
        assert!(close(*got, want, 2e-5), "{rgb:?}");
    }
}

#[test]
fn png_alpha_is_the_fraction_the_image_crate_gives() {
    // Every code, grey-and-alpha and RGBA: the image crate's fractions for
    // the two differ in the last bit for some codes, and loading keeps them.
    let dir = TempDir::new("tex-alpha");
    let grey = image::GrayAlphaImage::from_fn(256, 1, |x, _| image::LumaA([7, x as u8]));
    let rgba = image::RgbaImage::from_fn(256, 1, |x, _| image::Rgba([7, 8, 9, x as u8]));
    for (name, img) in [
        ("ga.png", image::DynamicImage::ImageLumaA8(grey)),
        ("rgba.png", image::DynamicImage::ImageRgba8(rgba)),
    ] {
        let path = dir.0.join(name);
        img.save(&path).unwrap();
        let want: Vec<f32> = img.to_rgba32f().pixels().map(|p| p.0[3]).collect();
        let got = load_image(&path).unwrap().alpha.unwrap();
        let bits = |v: &[f32]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&want), "{name}");
    }
}

#[test]
fn grey_and_sixteen_bit_pngs_become_rgb() {
    let dir = TempDir::new("tex-grey");
    let path = dir.0.join("grey.png");
    image::GrayImage::from_raw(1, 2, vec![255, 128])
        .unwrap()
        .save(&path)
        .unwrap();
    let (w, h, rgb) = load_rgb_f32(&path).unwrap();
    assert_eq!((w, h), (1, 2));
    assert_eq!(&rgb[..3], &[1.0, 1.0, 1.0]);
    assert!(
        rgb[3..].iter().all(|&v| close(v, 0.215_86, 2e-5)),
        "{rgb:?}"
    );

    let path = dir.0.join("deep.png");
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(1, 1, vec![65535u16, 0, 32896])
        .unwrap()
        .save(&path)
        .unwrap();
    let (_, _, rgb) = load_rgb_f32(&path).unwrap();
    // 32896 / 65535 = 128 / 255.
    assert!(close(rgb[0], 1.0, 1e-6) && rgb[1] == 0.0 && close(rgb[2], 0.215_86, 2e-5));
}

#[test]
fn jpeg_is_decoded_from_srgb() {
    let dir = TempDir::new("tex-jpg");
    let path = dir.0.join("t.jpg");
    // A flat grey survives JPEG compression (up to rounding).
    image::RgbImage::from_pixel(16, 8, image::Rgb([128, 128, 128]))
        .save(&path)
        .unwrap();
    let (w, h, rgb) = load_rgb_f32(&path).unwrap();
    assert_eq!((w, h), (16, 8));
    assert_eq!(rgb.len(), 16 * 8 * 3);
    // sRGB 127..129 is linear 0.2122..0.2195.
    assert!(
        rgb.iter().all(|&v| (0.211..0.221).contains(&v)),
        "{:?}",
        &rgb[..6]
    );
}

#[test]
fn exr_and_hdr_are_linear() {
    let dir = TempDir::new("tex-exr");
    let path = dir.0.join("env.exr");
    let values = [0.1f32, 2.5, 1000.0, 0.0, 1e-3, 7.25];
    write_exr(&path, 1, 2, &values, &[]).unwrap();
    let (w, h, rgb) = load_rgb_f32(&path).unwrap();
    assert_eq!((w, h), (1, 2));
    assert_eq!(rgb, values.to_vec());

    // Radiance RGBE stores powers of two exactly.
    let path = dir.0.join("env.hdr");
    let pixels = vec![image::Rgb([1.0f32, 0.5, 0.25]), image::Rgb([8.0, 4.0, 2.0])];
    let file = fs::File::create(&path).unwrap();
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&pixels, 2, 1)
        .unwrap();
    let (w, h, rgb) = load_rgb_f32(&path).unwrap();
    assert_eq!((w, h), (2, 1));
    assert_eq!(rgb, vec![1.0, 0.5, 0.25, 8.0, 4.0, 2.0]);
}

#[test]
fn bad_images_are_clear_errors() {
    let err = |bytes: &[u8]| {
        let message = decode_rgb_f32(bytes, "tex.img").unwrap_err().to_string();
        assert!(message.starts_with("tex.img: "), "{message}");
        assert!(!message.contains('\n'), "{message}");
        message
    };
    assert!(err(b"hello, not an image").contains("not a PNG, JPEG"));
    assert!(err(b"").contains("not a PNG"));
    // A Radiance header claiming 100000 x 100000 pixels, and no pixel data.
    let huge = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n";
    let message = err(huge);
    assert!(
        message.contains("100000x100000") && message.contains("limit"),
        "{message}"
    );
    // A truncated PNG.
    let dir = TempDir::new("tex-bad");
    let path = dir.0.join("t.png");
    write_png(&path, 64, 64, &[7u8; 64 * 64 * 3]).unwrap();
    let bytes = fs::read(&path).unwrap();
    assert!(err(&bytes[..bytes.len() / 2]).contains("Png"));
    // A truncated EXR.
    let path = dir.0.join("t.exr");
    write_exr(&path, 4, 4, &[1.0; 48], &[]).unwrap();
    let bytes = fs::read(&path).unwrap();
    assert!(err(&bytes[..20]).contains("EXR"));

    let missing = load_rgb_f32(&dir.0.join("missing.png"))
        .unwrap_err()
        .to_string();
    assert!(
        missing.contains("missing.png") && missing.contains("cannot read"),
        "{missing}"
    );
}
