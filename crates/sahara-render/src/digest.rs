//! The identity of a frame: a digest of the scene and of every setting
//! that changes its pixels, so that pieces of one frame rendered apart can
//! be recognised as such before they are added up.

use std::fmt::Write;

use sha2::{Digest, Sha256};

use crate::render::RenderSettings;
use crate::scene::Scene;

/// Feeds formatted text to the hash without building the whole string.
struct HashWriter(Sha256);

impl Write for HashWriter {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

/// SHA-256, in hex, of the scene and of the settings that change pixels:
/// size, samples per pixel and per pass, seed, sampler, filter, integrator
/// with its parameters, and the cost view's scale. The tree builder, tile
/// size, threads, time limit, window and sample range are left out: they
/// do not change a pixel of the frame.
///
/// The scene enters through its `Debug` form, which prints every float so
/// that it reads back to the same bits.
pub fn frame_digest(scene: &Scene, s: &RenderSettings) -> String {
    let mut h = HashWriter(Sha256::new());
    // Writing to a hash cannot fail.
    let _ = write!(
        h,
        "sahara frame 1\nsize {}x{}\nspp {} in passes of {}\nseed {}\nsampler {:?}\nfilter {:?}\n\
         integrator {:?}\ncost scale {:?}\nscene {:?}",
        s.width,
        s.height,
        u64::from(s.spp) * u64::from(s.passes),
        s.spp,
        s.seed,
        s.sampler,
        s.filter,
        s.integrator,
        s.cost_scale,
        scene
    );
    h.0.finalize()
        .iter()
        .fold(String::with_capacity(64), |mut out, b| {
            let _ = write!(out, "{b:02x}");
            out
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use sahara_kd::{BuildParams, Builder};

    #[test]
    fn pixel_settings_change_it_and_speed_settings_do_not() {
        let scene = builtin::cornell_box();
        let base = RenderSettings::default();
        let d = frame_digest(&scene, &base);
        assert_eq!(d.len(), 64);
        let same = RenderSettings {
            build: BuildParams::new(Builder::Binned { bins: 16 }),
            tile_size: 7,
            window: Some(crate::split::PixelWindow::full(3, 3)),
            samples: Some(1..2),
            ..base.clone()
        };
        assert_eq!(frame_digest(&scene, &same), d);
        for other in [
            RenderSettings {
                seed: 1,
                ..base.clone()
            },
            RenderSettings {
                width: 511,
                ..base.clone()
            },
            RenderSettings {
                spp: 8,
                passes: 2,
                ..base.clone()
            },
            RenderSettings {
                filter: crate::Filter::tent(),
                ..base.clone()
            },
        ] {
            assert_ne!(frame_digest(&scene, &other), d);
        }
        let mut moved = scene.clone();
        moved.camera.aspect *= 1.0 + f32::EPSILON;
        assert_ne!(frame_digest(&moved, &base), d);
    }
}
