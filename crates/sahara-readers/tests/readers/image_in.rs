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
