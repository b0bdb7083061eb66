//! The GGX / Trowbridge-Reitz microfacet distribution with the
//! height-correlated Smith shadowing term and visible-normal sampling.
//!
//! Local frame: the macro normal is +z. Formulas: Walter et al. 2007,
//! "Microfacet Models for Refraction through Rough Surfaces"; Heitz 2014,
//! "Understanding the Masking-Shadowing Function"; Heitz 2018, "Sampling the
//! GGX Distribution of Visible Normals".

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Roughness below which a surface is treated as perfectly smooth (the GGX
/// terms lose all precision as alpha goes to 0).
pub const MIN_ALPHA: f32 = 1e-3;

/// An isotropic GGX distribution.
#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    /// Width parameter alpha.
    pub alpha: f32,
}

impl Ggx {
    /// The distribution for a perceptual roughness in `[0, 1]`
    /// (`alpha = roughness^2`, the Disney / glTF mapping).
    pub fn from_roughness(roughness: f32) -> Self {
        Self {
            alpha: roughness.clamp(0.0, 1.0).powi(2),
        }
    }

    /// True when the surface is too smooth for the microfacet terms.
    pub fn is_smooth(&self) -> bool {
        self.alpha < MIN_ALPHA
    }

    /// Normal distribution `D(m)`.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = m.z * m.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// Smith's auxiliary function Lambda(w).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        let tan2 = ((1.0 - c2) / c2).max(0.0);
        0.5 * (-1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
    }

    /// Masking of one direction, `G1(w)`.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing `G(wo, wi)`.
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of visible normals `D_wo(m) = G1(wo) max(0, wo.m) D(m) / wo.z`
    /// (`wo.z > 0`).
    #[inline]
    pub fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * wo.dot(m).max(0.0) * self.d(m) / wo.z
    }

    /// A microfacet normal drawn from the visible normals seen from `wo`
    /// (`wo.z > 0`): stretch to the unit-roughness configuration, sample the
    /// projected hemisphere there, unstretch.
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let a = self.alpha;
        let vh = Vec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        Vec3::new(a * nh.x, a * nh.y, nh.z.max(1e-7)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::hash::{hash2, unit_f32};

    #[test]
    fn projected_ndf_integrates_to_one() {
        // The integral of D(m) m.z over the hemisphere is 1 (uniform sphere
        // sampling estimate, many samples).
        for alpha in [0.1f32, 0.5, 1.0] {
            let g = Ggx { alpha };
            let n = 400_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let u = Vec2::new(unit_f32(hash2(1, i)), unit_f32(hash2(2, i)));
                // Cosine-weighted: pdf z/pi, so D z / (z / pi) = pi D.
                let m = crate::math::warp::cosine_hemisphere(u);
                sum += (PI * g.d(m)) as f64;
            }
            let est = sum / n as f64;
            assert!((est - 1.0).abs() < 0.03, "alpha {alpha}: {est}");
        }
    }

    #[test]
    fn visible_normal_samples_face_the_viewer() {
        let g = Ggx { alpha: 0.6 };
        let wo = Vec3::new(0.8, 0.0, 0.6);
        for i in 0..1000 {
            let u = Vec2::new(unit_f32(hash2(3, i)), unit_f32(hash2(4, i)));
            let m = g.sample_visible(wo, u);
            assert!(m.z > 0.0 && (m.length() - 1.0).abs() < 1e-4);
            assert!(wo.dot(m) >= -1e-4);
        }
    }
}
