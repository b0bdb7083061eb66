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
    let mut kvd = ktx2("quad_uastc.ktx2");
    kvd[60..64].copy_from_slice(&35u32.to_le_bytes());
    let e = decode_raw(&kvd, "kvd.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "kvd.ktx2: cannot read the KTX2 texture: its key/value data is corrupt"
    );
    // Only the signature, and a KTX2 file whose payload is not Basis
    // Universal (vkFormat R8G8B8A8_UNORM, no supercompression).
    let e = decode_raw(&ktx2("quad_uastc.ktx2")[..12], "bad.ktx2")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("bad.ktx2: cannot read the KTX2 texture"),
        "{e}"
    );
    let mut raw = ktx2("quad_uastc.ktx2");
    raw[12..16].copy_from_slice(&37u32.to_le_bytes());
    let e = decode_raw(&raw, "raw.ktx2").unwrap_err().to_string();
    assert_eq!(
        e,
        "raw.ktx2: cannot read the KTX2 texture: it is not a Basis Universal texture or it is \
         corrupt (only KTX2 files with an ETC1S or UASTC payload are read; convert the texture \
         to PNG or JPEG)"
    );
}
