//! The isotropic point light.

use glam::Vec3;
use std::f32::consts::PI;

use super::emission::Emission;
use super::LightSample;
use crate::math::warp::{luminance, uniform_sphere};

/// Incident radiance at `p` from a point light of `intensity` (W/sr) at
/// `position`: `I / d^2` along the connecting direction.
pub fn sample(position: Vec3, intensity: Vec3, p: Vec3) -> Option<LightSample> {
    let d = position - p;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let dist = d2.sqrt();
    Some(LightSample {
        wi: d / dist,
        dist,
        li: intensity / d2,
        pdf: 1.0,
        delta: true,
        ignore: None,
        n: Vec3::ZERO,
        two_sided: false,
    })
}

/// Emitted power (luminance) for light selection.
pub fn power(intensity: Vec3) -> f32 {
    4.0 * PI * luminance(intensity)
}

/// Light leaving a point light, its direction uniform on the sphere
/// (`u_dir`).
pub(crate) fn emission(position: Vec3, intensity: Vec3, u_dir: glam::Vec2) -> Emission {
    Emission {
        p: position,
        n: Vec3::ZERO,
        dir: uniform_sphere(u_dir),
        le: intensity,
        pdf_pos: 1.0,
        pdf_dir: PDF_DIR,
        two_sided: false,
    }
}

/// Density of any direction leaving a point light.
pub(crate) const PDF_DIR: f32 = 1.0 / (4.0 * PI);
