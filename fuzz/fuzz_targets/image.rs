//! `decode_raw` on arbitrary bytes, named as any image and as a TGA
//! file (which has no signature): no panic, no allocation beyond the size
//! limits; an image of the size it says, or a one-line error naming the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sahara_fuzz::check_error;
use sahara_readers::image_in::{decode_raw, Pixels};

fuzz_target!(|data: &[u8]| {
    for name in ["fuzz.img", "fuzz.tga"] {
        match decode_raw(data, name) {
            Ok(i) => {
                let pixels = i.width as usize * i.height as usize;
                let (values, per_pixel) = match &i.pixels {
                    Pixels::Rgba8(v) => (v.len(), 4),
                    Pixels::EncodedRgbF32(v) => (v.len(), 3),
                    Pixels::LinearRgbF32(v) => (v.len(), 3),
                };
                assert_eq!(values, pixels * per_pixel);
            }
            Err(e) => check_error(&e, name),
        }
    }
});
