//! The Lambertian reflector.

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

use super::{BsdfEval, BsdfSample};
use crate::math::warp::cosine_hemisphere;

/// Value and density of the Lambertian BRDF of reflectance `albedo`
/// (two-sided: `wo` may be on either side, `wi` must be on the same one).
#[inline]
pub fn eval(albedo: Vec3, wo: Vec3, wi: Vec3) -> BsdfEval {
    if wo.z * wi.z <= 0.0 {
        return BsdfEval::ZERO;
    }
    BsdfEval {
        f: albedo * FRAC_1_PI,
        pdf: wi.z.abs() * FRAC_1_PI,
    }
}

/// A cosine-weighted direction on `wo`'s side.
#[inline]
pub fn sample(albedo: Vec3, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
    let mut wi = cosine_hemisphere(u);
    if wi.z <= 0.0 {
        return None;
    }
    let pdf = wi.z * FRAC_1_PI;
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    Some(BsdfSample {
        wi,
        weight: albedo,
        pdf,
        delta: false,
    })
}
