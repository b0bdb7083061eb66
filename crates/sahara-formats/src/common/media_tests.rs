//! What the readers' media tests share: a scene read from another format
//! holds the same media and interfaces as its twin in Sahara's own format.

use sahara_render::{Medium, Scene};

/// `read` (a pbrt or Mitsuba file) and `twin` (its TOML twin) hold the
/// same camera medium, `media` media (grids alike up to 1e-6 in their
/// placement) and `interfaces` medium interfaces.
pub(crate) fn assert_same_media(read: &Scene, twin: &Scene, media: usize, interfaces: usize) {
    assert_eq!(read.camera_medium, Some(0));
    assert_eq!(read.camera_medium, twin.camera_medium);
    assert_eq!(read.media.len(), media);
    for (i, (a, b)) in read.media.iter().zip(&twin.media).enumerate() {
        match (a, b) {
            (Medium::Grid(a), Medium::Grid(b)) => {
                assert_eq!(a.density, b.density);
                assert_eq!(
                    (a.sigma_a, a.sigma_s, a.phase),
                    (b.sigma_a, b.sigma_s, b.phase)
                );
                assert!(a.to_medium.abs_diff_eq(b.to_medium, 1e-6), "{a:?} {b:?}");
            }
            (a, b) => assert_eq!(a, b, "medium {i}"),
        }
    }
    assert_eq!(read.medium_interfaces, twin.medium_interfaces);
    assert_eq!(read.medium_interfaces.len(), interfaces);
}
