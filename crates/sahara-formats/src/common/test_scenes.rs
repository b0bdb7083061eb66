//! What the readers' tests share: a small render of a scene, and the
//! checks that a scene read from another format is its twin in Sahara's
//! own format (the same media and interfaces, the same image).

use glam::Vec3;
use sahara_render::{render, FrameSettings, Medium, RenderSettings, Scene};

/// A 24 x 24 render of `scene` at `spp` samples, in one pass.
pub(crate) fn image(scene: &Scene, spp: u32) -> Vec<Vec3> {
    let settings = RenderSettings::from(FrameSettings {
        width: 24,
        height: 24,
        spp,
        pass_spp: spp,
        ..Default::default()
    });
    let mut scene = scene.clone();
    scene.camera.aspect = 1.0;
    render(&scene, &settings, &|_| {}).unwrap().film.pixels
}

/// `read` and `twin` render (4 samples) to images that are not black and
/// differ by less than 1e-3 in every pixel and channel.
pub(crate) fn assert_same_render(read: &Scene, twin: &Scene) {
    let (a, b) = (image(read, 4), image(twin, 4));
    assert!(b.iter().any(|v| v.max_element() > 0.0), "black");
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (*x - *y).abs().max_element())
        .fold(0.0, f32::max);
    assert!(worst < 1e-3, "the images differ by up to {worst}");
}

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
                assert_eq!(a.coefficients, b.coefficients);
                assert_eq!(a.phase, b.phase);
                assert!(a.to_medium.abs_diff_eq(b.to_medium, 1e-6), "{a:?} {b:?}");
            }
            (a, b) => assert_eq!(a, b, "medium {i}"),
        }
    }
    assert_eq!(read.medium_interfaces, twin.medium_interfaces);
    assert_eq!(read.medium_interfaces.len(), interfaces);
}
