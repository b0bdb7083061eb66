//! The spot light: a point light restricted to a cone with a smooth edge.

use glam::Vec3;
use std::f32::consts::PI;

use super::emission::Emission;
use super::{point, LightSample};
use crate::math::warp::{luminance, uniform_cone, Frame};

/// Angular falloff: 1 inside the inner cone, 0 outside the outer one, a
/// smoothstep in cosine between.
#[inline]
pub fn falloff(cos: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    if cos >= cos_inner {
        return 1.0;
    }
    if cos <= cos_outer {
        return 0.0;
    }
    let t = (cos - cos_outer) / (cos_inner - cos_outer);
    t * t * (3.0 - 2.0 * t)
}

/// Incident radiance at `p` from the spot light.
pub fn sample(
    position: Vec3,
    direction: Vec3,
    intensity: Vec3,
    cos_inner: f32,
    cos_outer: f32,
    p: Vec3,
) -> Option<LightSample> {
    let mut s = point::sample(position, intensity, p)?;
    let f = falloff((-s.wi).dot(direction), cos_inner, cos_outer);
    if f <= 0.0 {
        return None;
    }
    s.li *= f;
    Some(s)
}

/// Emitted power (luminance, the falloff band counted at half) for light
/// selection.
pub fn power(intensity: Vec3, cos_inner: f32, cos_outer: f32) -> f32 {
    2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * luminance(intensity)
}

/// Light leaving a spot light, its direction uniform in the outer cone
/// (`u_dir`).
pub(crate) fn emission(
    position: Vec3,
    direction: Vec3,
    intensity: Vec3,
    cos_inner: f32,
    cos_outer: f32,
    u_dir: glam::Vec2,
) -> Emission {
    let local = uniform_cone(u_dir, cos_outer);
    let dir = Frame::from_normal(direction).to_world(local);
    Emission {
        p: position,
        n: Vec3::ZERO,
        dir,
        le: intensity * falloff(local.z, cos_inner, cos_outer),
        pdf_pos: 1.0,
        pdf_dir: 1.0 / (2.0 * PI * (1.0 - cos_outer)),
        two_sided: false,
    }
}

/// Density of direction `dir` leaving a spot light: uniform in the outer
/// cone.
pub(crate) fn pdf_dir(direction: Vec3, cos_outer: f32, dir: Vec3) -> f32 {
    if dir.dot(direction) >= cos_outer {
        1.0 / (2.0 * PI * (1.0 - cos_outer))
    } else {
        0.0
    }
}
