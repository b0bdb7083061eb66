//! `parse_ply` on arbitrary bytes: no panic, no hang, no allocation beyond
//! what the file can hold; a mesh with indices in range, or a one-line error
//! naming the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sahara_fuzz::{check_error, check_mesh};
use sahara_readers::ply::parse_ply;

fuzz_target!(|data: &[u8]| {
    match parse_ply(data, "fuzz.ply") {
        Ok(mesh) => check_mesh(&mesh.positions, &mesh.indices),
        Err(e) => check_error(&e, "fuzz.ply"),
    }
});
