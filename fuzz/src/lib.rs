//! Checks shared by the fuzz targets.

use sahara_readers::FormatError;

/// Asserts the promise of `sahara_readers::error`: every error is one line
/// that starts with the file's name.
pub fn check_error(error: &FormatError, name: &str) {
    let message = error.to_string();
    assert!(
        message.starts_with(&format!("{name}: ")),
        "error does not start with the file name: {message:?}"
    );
    assert!(
        !message.contains('\n'),
        "error is not one line: {message:?}"
    );
}

/// Asserts a loaded mesh is usable: one triangle per index triple, every
/// index in range.
pub fn check_mesh(positions: &[glam::Vec3], indices: &[[u32; 3]]) {
    for (t, tri) in indices.iter().enumerate() {
        for &i in tri {
            assert!(
                (i as usize) < positions.len(),
                "triangle {t} has index {i} but there are {} positions",
                positions.len()
            );
        }
    }
}
