//! `decode_rgb_f32` on arbitrary bytes: no panic, no allocation beyond the
//! size limits; an image of the size it says, or a one-line error naming the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sahara_formats::image_in::decode_rgb_f32;
use sahara_fuzz::check_error;

fuzz_target!(|data: &[u8]| {
    match decode_rgb_f32(data, "fuzz.img") {
        Ok((w, h, rgb)) => assert_eq!(rgb.len(), w as usize * h as usize * 3),
        Err(e) => check_error(&e, "fuzz.img"),
    }
});
