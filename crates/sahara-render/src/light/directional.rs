//! The directional (distant) light.

use glam::Vec3;
use std::f32::consts::PI;

use super::emission::Emission;
use super::LightSample;
use crate::math::warp::luminance;

/// Incident light from a distant source travelling along `direction`
/// (unit), delivering `irradiance` on a surface facing it.
pub fn sample(direction: Vec3, irradiance: Vec3) -> Option<LightSample> {
    Some(LightSample {
        wi: -direction,
        dist: f32::INFINITY,
        li: irradiance,
        pdf: 1.0,
        delta: true,
        ignore: None,
        n: Vec3::ZERO,
        two_sided: false,
    })
}

/// Power through a disc of the scene's radius, for light selection.
pub fn power(irradiance: Vec3, scene_radius: f32) -> f32 {
    PI * scene_radius * scene_radius * luminance(irradiance)
}

/// Light leaving a directional light through `origin`, a point of the
/// disc of the scene's `radius` facing it.
pub(crate) fn emission(direction: Vec3, irradiance: Vec3, origin: Vec3, radius: f32) -> Emission {
    Emission {
        p: origin,
        n: Vec3::ZERO,
        dir: direction,
        le: irradiance,
        pdf_pos: 1.0 / (PI * radius * radius),
        pdf_dir: 1.0,
        two_sided: false,
    }
}
