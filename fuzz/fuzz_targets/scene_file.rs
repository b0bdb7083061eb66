//! `parse_scene` on arbitrary UTF-8: no panic; a scene or a one-line
//! error naming the file. Paths resolve against a folder that does not exist,
//! so file references are errors, never reads.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use sahara_formats::parse_scene;
use sahara_fuzz::check_error;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let folder = Path::new("/nonexistent-sahara-fuzz");
    if let Err(e) = parse_scene(text, "fuzz.toml", folder) {
        check_error(&e, "fuzz.toml");
    }
});
