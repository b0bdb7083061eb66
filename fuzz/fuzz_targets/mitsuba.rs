//! `parse_mitsuba` on arbitrary bytes: no panic; a scene or a one-line error
//! naming the file. Relative names resolve against a folder that does not
//! exist, so `<include>`, meshes and images are errors or warnings, never reads.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use sahara_formats::parse_mitsuba;
use sahara_fuzz::check_error;

fuzz_target!(|data: &[u8]| {
    let folder = Path::new("/nonexistent-sahara-fuzz");
    match parse_mitsuba(data, "fuzz.xml", folder) {
        Ok(s) => {
            for m in &s.scene.meshes {
                sahara_fuzz::check_mesh(&m.mesh.positions, &m.mesh.indices);
            }
        }
        Err(e) => check_error(&e, "fuzz.xml"),
    }
});
