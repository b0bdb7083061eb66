//! `decode_image` on arbitrary bytes, named as any image and as a TGA
//! file (which has no signature): no panic, no allocation beyond the size
//! limits; an image of the size it says, or a one-line error naming the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sahara_formats::image_in::decode_image;
use sahara_fuzz::check_error;

fuzz_target!(|data: &[u8]| {
    for name in ["fuzz.img", "fuzz.tga"] {
        match decode_image(data, name) {
            Ok(i) => {
                let pixels = i.width as usize * i.height as usize;
                assert_eq!(i.rgb.len(), pixels * 3);
                if let Some(a) = &i.alpha {
                    assert_eq!(a.len(), pixels);
                }
            }
            Err(e) => check_error(&e, name),
        }
    }
});
