//! `parse_obj` on arbitrary bytes: no panic, no hang; a mesh with indices in
//! range, or a one-line error naming the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sahara_fuzz::{check_error, check_mesh};
use sahara_readers::obj::parse_obj;

fuzz_target!(|data: &[u8]| {
    match parse_obj(data, "fuzz.obj") {
        Ok(mesh) => check_mesh(&mesh.positions, &mesh.indices),
        Err(e) => check_error(&e, "fuzz.obj"),
    }
});
