//! Images as stored: 8-bit codes, encoded 16-bit fractions, linear floats.

use std::io::Cursor;

use sahara_readers::image_in::{decode_raw, ImageFormat, Pixels};

fn encode(img: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut out = Vec::new();
    img.write_to(&mut Cursor::new(&mut out), format).unwrap();
    out
}

#[test]
fn eight_bit_pngs_are_their_codes_with_alpha_as_fractions() {
    let rgba = image::RgbaImage::from_raw(2, 1, vec![255, 128, 0, 255, 0, 10, 255, 51]).unwrap();
    let i = decode_raw(&encode(rgba.into(), image::ImageFormat::Png), "a.png").unwrap();
    assert_eq!((i.width, i.height, i.format), (2, 1, ImageFormat::Png));
    assert_eq!(
        i.pixels,
        Pixels::Rgba8(vec![255, 128, 0, 255, 0, 10, 255, 51])
    );
    assert_eq!(i.alpha, Some(vec![1.0, 0.2]));
    // Grey is expanded to RGB; no alpha channel, no alpha.
    let grey = image::GrayImage::from_raw(1, 1, vec![7]).unwrap();
    let i = decode_raw(&encode(grey.into(), image::ImageFormat::Png), "g.png").unwrap();
    assert_eq!(i.pixels, Pixels::Rgba8(vec![7, 7, 7, 255]));
    assert_eq!(i.alpha, None);
}

#[test]
fn sixteen_bit_pngs_are_encoded_fractions_and_hdr_is_linear() {
    let deep =
        image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(1, 1, vec![65535u16, 0, 32896]).unwrap();
    let i = decode_raw(&encode(deep.into(), image::ImageFormat::Png), "d.png").unwrap();
    // Not decoded from sRGB: 32896 / 65535 = 128 / 255.
    assert_eq!(
        i.pixels,
        Pixels::EncodedRgbF32(vec![1.0, 0.0, 32896.0 / 65535.0])
    );
    assert_eq!(i.alpha, None);
    let hdr = image::Rgb32FImage::from_raw(1, 1, vec![2.0, 0.5, 0.25]).unwrap();
    let i = decode_raw(&encode(hdr.into(), image::ImageFormat::Hdr), "e.hdr").unwrap();
    assert_eq!(i.format, ImageFormat::Hdr);
    assert_eq!(i.pixels, Pixels::LinearRgbF32(vec![2.0, 0.5, 0.25]));
}

/// The KTX2 textures of `tests/data/` (written by its `make_ktx2.py` with
/// Basis Universal's encoder): an 8 x 8 image of four 4 x 4 quadrants, red
/// and green above, blue and white below, each quadrant one 4 x 4 block.
fn ktx2(name: &str) -> Vec<u8> {
    std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

/// The colour each texel of the 8 x 8 test image was encoded from.
fn quadrant_colour(x: usize, y: usize) -> [u8; 3] {
    [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]][x / 4 + 2 * (y / 4)]
}

#[test]
fn ktx2_textures_decode_to_their_colours_within_the_codecs_error() {
    // Tolerances per channel, from what each codec can store for a block of
    // one colour:
    // - UASTC has a solid-colour block mode holding the colour's 8-bit
    //   codes: exact, 0.
    // - ETC1S stores a block as one colour of 5 bits a channel (expanded to
    //   8 bits: codes 0, 8, 16, 24, 33, ... 255, never more than 9 apart)
    //   plus an intensity offset shared by the three channels (the smallest
    //   table's are -8, -2, +2, +8), clamped to 0..255. Whichever offset the
    //   encoder picks, each channel's 5-bit value can be chosen within half
    //   a step, 4.5, of the colour less the offset: at most 4 codes off.
    // Basis Universal's own transcoder (make_ktx2.py) gives the same texels
    // as the values held here: the colours exactly from UASTC, and red
    // (253, 0, 0), green (2, 255, 2), blue (0, 0, 253), white from ETC1S.
    let etc1s_reference = [[253, 0, 0], [2, 255, 2], [0, 0, 253], [255, 255, 255]];
    for (file, tolerance) in [("quad_uastc.ktx2", 0), ("quad_etc1s.ktx2", 4)] {
        let i = decode_raw(&ktx2(file), file).unwrap();
        assert_eq!(
            (i.width, i.height, i.format),
            (8, 8, ImageFormat::Ktx2),
            "{file}"
        );
        let Pixels::Rgba8(rgba) = &i.pixels else {
            panic!("{file}: {:?}", i.format)
        };
        assert_eq!(i.alpha, None, "{file}: opaque");
        for y in 0..8 {
            for x in 0..8 {
                let texel = &rgba[4 * (8 * y + x)..4 * (8 * y + x) + 4];
                let want = quadrant_colour(x, y);
                assert!(
                    (0..3).all(|c| texel[c].abs_diff(want[c]) <= tolerance) && texel[3] == 255,
                    "{file} ({x}, {y}): {texel:?} for {want:?}"
                );
                if file == "quad_etc1s.ktx2" {
                    assert_eq!(
                        texel[..3],
                        etc1s_reference[x / 4 + 2 * (y / 4)],
                        "({x}, {y})"
                    );
                }
            }
        }
    }
}

/// Texel `i` of the plain KTX2 test image (`tests/data/make_ktx2_plain.py`)
/// as 8-bit codes (R, G, B, A).
fn plain_codes(i: usize) -> [u8; 4] {
    let i = i as u32;
    [32 * i + 3, 255 - 30 * i, (7 * i * i) % 256, 255 - 20 * i].map(|c| c as u8)
}

/// Texel `i` of the plain KTX2 test image as 16-bit values over 65535.
fn plain_unorm16(i: usize) -> [f32; 4] {
    plain_codes(i).map(|c| (257 * u32::from(c) + i as u32) as f32 / 65535.0)
}

/// Texel `i` of the plain KTX2 test image as floats.
fn plain_floats(i: usize) -> [f32; 4] {
    let i = i as f32;
    [i / 2.0 + 0.25, 2.0 - i / 8.0, 16.0 * i, i / 8.0]
}

#[test]
fn plain_ktx2_textures_read_to_their_texels() {
    // Each file holds the 4 x 2 test image in its base level's first layer
    // (and other values in a second level or layer, which must not be
    // read). Values are exact: 8-bit codes as stored, 16-bit over 65535,
    // floats as stored (the test image's fit every float format exactly).
    let rgb = |rgba: [f32; 4], channels: usize| {
        let mut v = [rgba[0], rgba[1], rgba[2]];
        v[channels.min(3)..].fill(0.0);
        v
    };
    for (file, channels) in [
        ("plain_rgb8_zstd.ktx2", 3),
        ("plain_rgba8_srgb_zlib.ktx2", 4),
        ("plain_bgra8_none.ktx2", 4),
        ("plain_rg8_zstd.ktx2", 2),
    ] {
        let i = decode_raw(&ktx2(file), file).unwrap();
        assert_eq!(
            (i.width, i.height, i.format),
            (4, 2, ImageFormat::Ktx2),
            "{file}"
        );
        let want: Vec<u8> = (0..8)
            .flat_map(|k| {
                let c = plain_codes(k);
                match channels {
                    2 => [c[0], c[1], 0, 255],
                    3 => [c[0], c[1], c[2], 255],
                    _ => c,
                }
            })
            .collect();
        assert_eq!(i.pixels, Pixels::Rgba8(want), "{file}");
        let alpha = (channels == 4).then(|| {
            (0..8)
                .map(|k| f32::from(plain_codes(k)[3]) / 255.0)
                .collect::<Vec<_>>()
        });
        assert_eq!(i.alpha, alpha, "{file}");
    }
    // One channel, shown as grey by its KTXswizzle (rrr1).
    let i = decode_raw(&ktx2("plain_r8_rrr1.ktx2"), "r8").unwrap();
    let want: Vec<u8> = (0..8)
        .flat_map(|k| {
            let r = plain_codes(k)[0];
            [r, r, r, 255]
        })
        .collect();
    assert_eq!((i.pixels, i.alpha), (Pixels::Rgba8(want), None));
    for (file, channels) in [("plain_rgba16_zstd.ktx2", 4), ("plain_rgb16_none.ktx2", 3)] {
        let i = decode_raw(&ktx2(file), file).unwrap();
        let want = (0..8)
            .flat_map(|k| rgb(plain_unorm16(k), channels))
            .collect();
        assert_eq!(i.pixels, Pixels::EncodedRgbF32(want), "{file}");
        let alpha = (channels == 4).then(|| (0..8).map(|k| plain_unorm16(k)[3]).collect());
        assert_eq!(i.alpha, alpha, "{file}");
    }
    for (file, channels) in [
        ("plain_rgba16f_zlib.ktx2", 4),
        ("plain_rgb32f_zstd.ktx2", 3),
        ("plain_r32f_none.ktx2", 1),
        ("plain_e5b9g9r9_none.ktx2", 3),
        ("plain_b10g11r11_zstd.ktx2", 3),
    ] {
        let i = decode_raw(&ktx2(file), file).unwrap();
        assert_eq!((i.width, i.height), (4, 2), "{file}");
        let want: Vec<f32> = (0..8)
            .flat_map(|k| rgb(plain_floats(k), channels))
            .collect();
        let Pixels::LinearRgbF32(got) = &i.pixels else {
            panic!("{file}: {:?}", i.pixels)
        };
        assert_eq!(got.len(), want.len(), "{file}");
        for (k, (g, w)) in got.chunks(3).zip(want.chunks(3)).enumerate() {
            // E5B9G9R9 keeps 9 bits under the texel's largest channel's
            // exponent: within half a step of 2^(e + 1 - 9). The other
            // formats hold the test image's values exactly.
            let step = if file.contains("e5b9g9r9") {
                2f32.powi(w[2].max(w[0]).log2().floor() as i32 + 1 - 9)
            } else {
                0.0
            };
            for c in 0..3 {
                assert!(
                    (g[c] - w[c]).abs() <= step / 2.0,
                    "{file} texel {k}: {g:?} for {w:?}"
                );
            }
        }
        let alpha = (channels == 4).then(|| (0..8).map(|k| plain_floats(k)[3]).collect());
        assert_eq!(i.alpha, alpha, "{file}");
    }
}

#[test]
fn ktx2_formats_sahara_does_not_read_are_said_to_be_not_supported() {
    // vkFormat 146 (BC7_SRGB_BLOCK), 38 (R8G8B8A8_SNORM), 124 (D16_UNORM),
    // and a scheme that does not exist: "not supported", naming what, and
    // never "corrupt".
    let with = |at: usize, value: u32| {
        let mut bytes = ktx2("plain_rgba8_srgb_zlib.ktx2");
        bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
        decode_raw(&bytes, "t.ktx2").unwrap_err().to_string()
    };
    for (vk, kind) in [
        (146, "BC1 to BC7 block-compressed"),
        (38, "8-bit signed, scaled or integer"),
        (124, "depth or stencil"),
        (1_000_054_000, "PVRTC"),
    ] {
        let e = with(12, vk);
        assert!(
            e.starts_with(&format!(
                "t.ktx2: cannot read the KTX2 texture: its format, vkFormat {vk} (a"
            )) && e.contains(kind)
                && e.contains("is not supported")
                && !e.contains("corrupt"),
            "{e}"
        );
    }
    let e = with(44, 7);
    assert!(
        e.contains("supercompression scheme 7 is not supported") && !e.contains("corrupt"),
        "{e}"
    );
    // vkFormat 0 whose data format is not Basis Universal's.
    let mut bytes = ktx2("plain_rgba8_srgb_zlib.ktx2");
    bytes[12..16].copy_from_slice(&0u32.to_le_bytes());
    let e = decode_raw(&bytes, "t.ktx2").unwrap_err().to_string();
    assert!(
        e.contains("vkFormat 0 with data format model 1, is not supported")
            && !e.contains("corrupt"),
        "{e}"
    );
}

#[test]
fn plain_ktx2_files_whose_sizes_disagree_are_corrupt_and_never_read_past_their_end() {
    let good = ktx2("plain_rgb8_zstd.ktx2");
    // Level 0 stated to unpack to more or less than a 4 x 2 RGB8 image.
    for unpacked in [23u64, 25, 1 << 40] {
        let mut bytes = good.clone();
        bytes[96..104].copy_from_slice(&unpacked.to_le_bytes());
        let e = decode_raw(&bytes, "t.ktx2").unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "t.ktx2: cannot read the KTX2 texture: it is corrupt: its level 0 says it unpacks \
                 to {unpacked} bytes, where one 4x2 R8G8B8_UNORM image takes 24"
            )
        );
    }
    // Cut anywhere, or any byte changed: an image or a one-line error,
    // never a panic.
    for file in [
        "plain_rgb8_zstd.ktx2",
        "plain_rgba16f_zlib.ktx2",
        "plain_bgra8_none.ktx2",
    ] {
        let good = ktx2(file);
        for len in 12..good.len() {
            let e = decode_raw(&good[..len], "t.ktx2").unwrap_err().to_string();
            assert!(
                e.starts_with("t.ktx2: cannot read the KTX2 texture: "),
                "{e}"
            );
        }
        for at in 12..good.len() {
            for flip in [0x01, 0x80, 0xFF] {
                let mut bytes = good.clone();
                bytes[at] ^= flip;
                if let Err(e) = decode_raw(&bytes, "t.ktx2") {
                    assert!(!e.to_string().contains('\n'), "{e}");
                }
            }
        }
    }
}

#[test]
fn bad_ktx2_data_is_a_one_line_error_naming_the_file() {
    let check = |bytes: &[u8], what: &str| match decode_raw(bytes, "bad.ktx2") {
        Ok(_) => {}
        Err(e) => {
            let e = e.to_string();
            assert!(
                e.starts_with("bad.ktx2: cannot read the KTX2 texture: ")
                    || e.starts_with("bad.ktx2: the image is "),
                "{what}: {e}"
            );
            assert!(!e.contains('\n'), "{what}: {e}");
        }
    };
    for file in ["quad_uastc.ktx2", "quad_etc1s.ktx2"] {
        let good = ktx2(file);
        // Cut anywhere after the signature: an error, never a panic.
        for len in 12..good.len() {
            let e = decode_raw(&good[..len], "bad.ktx2").err();
            assert!(e.is_some(), "{file} cut at {len} bytes was read");
            check(&good[..len], &format!("{file} cut at {len}"));
        }
        // Any one byte changed: an image or an error, never a panic.
        for at in 12..good.len() {
            for flip in [0x01, 0x80, 0xFF] {
                let mut bytes = good.clone();
                bytes[at] ^= flip;
                check(&bytes, &format!("{file} byte {at} ^ {flip:#x}"));
            }
        }
    }
    // What the transcoder would trust: a Zstandard level stated to unpack
    // to 512 GiB (it would allocate that and abort), and key/value data
    // that ends inside an entry's padding (it would read past it and
    // panic).
    let mut huge = ktx2("quad_uastc.ktx2");
    huge[96..104].copy_from_slice(&(64u64 + (1 << 39)).to_le_bytes());
    let e = decode_raw(&huge, "huge.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "huge.ktx2: cannot read the KTX2 texture: its level index is corrupt"
    );
    // A level whose offset plus length passes 2^64 (the transcoder adds
    // them unchecked: a panic where overflow is checked).
    let mut wraps = ktx2("quad_uastc.ktx2");
    wraps[80..88].copy_from_slice(&u64::MAX.to_le_bytes());
    let e = decode_raw(&wraps, "wraps.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "wraps.ktx2: cannot read the KTX2 texture: its level index is corrupt"
    );
    // A height of 0 (as a 1D texture has) beside 2^32 - 1 layers and
    // faces: the stack is still counted against the pixel limit (a 0 once
    // hid it, and the level check's product overflowed).
    let mut flat = ktx2("quad_uastc.ktx2");
    flat[24..28].copy_from_slice(&0u32.to_le_bytes());
    flat[32..40].copy_from_slice(&[0xFF; 8]);
    let e = decode_raw(&flat, "flat.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "flat.ktx2: cannot read the KTX2 texture: its size is corrupt"
    );
    let mut kvd = ktx2("quad_uastc.ktx2");
    kvd[60..64].copy_from_slice(&35u32.to_le_bytes());
    let e = decode_raw(&kvd, "kvd.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "kvd.ktx2: cannot read the KTX2 texture: its key/value data is corrupt"
    );
    // Only the signature.
    let e = decode_raw(&ktx2("quad_uastc.ktx2")[..12], "bad.ktx2")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("bad.ktx2: cannot read the KTX2 texture"),
        "{e}"
    );
    // The UASTC file's data taken for R8G8B8A8_UNORM: its level's size
    // disagrees.
    let mut raw = ktx2("quad_uastc.ktx2");
    raw[12..16].copy_from_slice(&37u32.to_le_bytes());
    let e = decode_raw(&raw, "raw.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "raw.ktx2: cannot read the KTX2 texture: it is corrupt: its level 0 says it unpacks to \
         64 bytes, where one 8x8 R8G8B8A8_UNORM image takes 256"
    );
}
