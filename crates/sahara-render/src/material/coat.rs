//! A clear dielectric coat over a reflector.
//!
//! `f = c f_coat(wo, wi) + f_base(wo, wi) (1 - c E(wo)) (1 - c E(wi))`:
//! the coat's GGX reflection (Schlick's Fresnel from the coat's index,
//! `f90 = 1`) with strength `c`, and the base seen through the coat, dimmed
//! by the coat's directional albedo `E` on the way in and on the way out.
//! The sum is reciprocal, and its albedo stays at most 1: from `wo` the
//! coat reflects `c E(wo)` and the base gets `1 - c E(wo)` to reflect at
//! most all of (glTF's `KHR_materials_clearcoat` writes the same layering
//! with the Fresnel term of the view direction alone, which is not
//! reciprocal).
//!
//! Sampling picks the coat with probability `c E(wo) / (c E(wo) +
//! (1 - c E(wo)) / 2)` (the base taken to reflect half of what reaches it)
//! and the base's own sampling otherwise; densities are the mixture.
//!
//! The coat has a normal of its own (glTF's `clearcoatNormalTexture`, else
//! the surface's normal without the base's normal map): its lobe and its
//! albedo are taken in that frame, and the lobe is scaled by the ratio of
//! the cosines to the coat's and to the shading normal, so that the
//! light it reflects is what a surface facing that way would reflect.

use glam::{Vec2, Vec3};

use super::albedo;
use super::fresnel::{reflect, schlick_f90};
use super::layered::{to_side, upper};
use super::microfacet::{Distribution, Microfacet};
use super::{Bsdf, BsdfEval, BsdfSample};
use crate::math::warp::Frame;

/// The coat lobe at one shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat {
    /// Strength in `[0, 1]`.
    pub factor: f32,
    /// Perceptual roughness.
    pub roughness: f32,
    /// Reflectance at normal incidence (from the coat's index).
    pub f0: f32,
    /// The coat's normal in the shading frame (+z: the shading normal).
    pub normal: Vec3,
}

impl Coat {
    /// A coat of strength `factor`, `roughness` and index `ior`.
    pub fn new(factor: f32, roughness: f32, ior: f32) -> Self {
        let unit = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        let eta = if ior.is_finite() && ior >= 1.0 {
            ior
        } else {
            1.5
        };
        Self {
            factor: unit(factor),
            roughness: unit(roughness),
            f0: ((eta - 1.0) / (eta + 1.0)).powi(2),
            normal: Vec3::Z,
        }
    }

    /// This coat with its normal `n` (unit, in the shading frame; one
    /// below the surface is ignored).
    pub fn with_normal(mut self, n: Vec3) -> Self {
        self.normal = if n.z > 1e-4 && n.is_finite() {
            n
        } else {
            Vec3::Z
        };
        self
    }

    /// The coat's frame, if its normal is not the shading normal.
    #[inline]
    fn frame(&self) -> Option<Frame> {
        (self.normal != Vec3::Z).then(|| Frame::from_normal(self.normal))
    }

    /// `w` (upper hemisphere of the shading frame) in the coat's frame.
    #[inline]
    fn local(&self, frame: &Option<Frame>, w: Vec3) -> Vec3 {
        frame.as_ref().map_or(w, |f| f.to_local(w))
    }

    /// The coat's reflected fraction from `mu`, times its strength.
    #[inline]
    fn albedo(&self, mu: f32) -> f32 {
        let ggx = Distribution::Ggx;
        self.factor
            * albedo::schlick(
                ggx,
                Vec3::splat(self.f0),
                Vec3::ONE,
                mu.abs(),
                self.roughness,
            )
            .x
    }

    #[inline]
    fn fresnel(&self, c: f32) -> f32 {
        self.factor * schlick_f90(Vec3::splat(self.f0), Vec3::ONE, c).x
    }

    /// Probability of sampling the coat from `wo`.
    #[inline]
    fn probability(&self, wo: Vec3) -> f32 {
        let e = self.albedo(wo.z);
        if e <= 0.0 {
            0.0
        } else {
            e / (e + 0.5 * (1.0 - e))
        }
    }

    /// True if the coat's lobe is a delta.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        Microfacet::ggx(self.roughness).is_smooth()
    }

    /// The coat lobe alone for `wo` and `wi` in the coat's frame, its
    /// value scaled to the shading frame, where `wi` has cosine `cos_i`.
    fn lobe(&self, wo: Vec3, wi: Vec3, cos_i: f32) -> BsdfEval {
        let ggx = Microfacet::ggx(self.roughness);
        if ggx.is_smooth() || wo.z <= 0.0 || wi.z <= 0.0 || cos_i <= 0.0 {
            return BsdfEval::ZERO;
        }
        let h = (wo + wi).normalize();
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            f: Vec3::splat(self.fresnel(oh) * ggx.d(h) * ggx.g(wo, wi) / (4.0 * wo.z * cos_i)),
            pdf: ggx.pdf_visible(wo, h) / (4.0 * oh),
        }
    }

    /// Value and density of the coat over `base` (tinted by `tint`).
    pub fn eval(&self, base: &Bsdf, tint: Vec3, wo: Vec3, wi: Vec3) -> BsdfEval {
        let b = base.eval(tint, wo, wi);
        if wo.z * wi.z <= 0.0 {
            return b;
        }
        let (uo, ui) = (upper(wo), upper(wi));
        let frame = self.frame();
        let (co, ci) = (self.local(&frame, uo), self.local(&frame, ui));
        let p = self.probability(co);
        let c = self.lobe(co, ci, ui.z);
        let dim = (1.0 - self.albedo(co.z)) * (1.0 - self.albedo(ci.z));
        BsdfEval {
            f: c.f + b.f * dim,
            pdf: p * c.pdf + (1.0 - p) * b.pdf,
        }
    }

    /// A direction from the coat or the base.
    pub fn sample(
        &self,
        base: &Bsdf,
        tint: Vec3,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let flip = wo.z < 0.0;
        let uo = upper(wo);
        let frame = self.frame();
        let co = self.local(&frame, uo);
        let p = self.probability(co);
        if u_lobe < p {
            if co.z <= 0.0 {
                return None;
            }
            let to_shading = |w: Vec3| frame.as_ref().map_or(w, |f| f.to_world(w));
            let ggx = Microfacet::ggx(self.roughness);
            if ggx.is_smooth() {
                let wi = to_shading(Vec3::new(-co.x, -co.y, co.z));
                if wi.z <= 0.0 {
                    return None;
                }
                return Some(BsdfSample {
                    wi: to_side(wi, flip),
                    weight: Vec3::splat(self.fresnel(co.z) / p),
                    pdf: p,
                    delta: true,
                });
            }
            let m = ggx.sample_visible(co, u);
            if co.dot(m) <= 0.0 {
                return None;
            }
            let wi = to_shading(reflect(co, m));
            if wi.z <= 0.0 {
                return None;
            }
            let e = self.eval(base, tint, uo, wi);
            if e.pdf <= 0.0 {
                return None;
            }
            return Some(BsdfSample {
                wi: to_side(wi, flip),
                weight: e.f * (wi.z / e.pdf),
                pdf: e.pdf,
                delta: false,
            });
        }
        // The base's lobe, chosen by the rest of `u_lobe` rescaled.
        let s = base.sample(tint, wo, ((u_lobe - p) / (1.0 - p)).clamp(0.0, 1.0), u)?;
        let wi = s.wi;
        if wi.z * wo.z <= 0.0 {
            // Transmission through the base: the coat only reflects.
            return Some(s);
        }
        let (co, ci) = (self.local(&frame, upper(wo)), self.local(&frame, upper(wi)));
        let dim = (1.0 - self.albedo(co.z)) * (1.0 - self.albedo(ci.z));
        if s.delta {
            return Some(BsdfSample {
                weight: s.weight * dim / (1.0 - p),
                pdf: s.pdf * (1.0 - p),
                ..s
            });
        }
        let e = self.eval(base, tint, wo, wi);
        if e.pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: e.f * (wi.z.abs() / e.pdf),
            pdf: e.pdf,
            delta: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::tests::{albedo_two_ways, u2};
    use crate::material::PointBsdf;
    use crate::math::hash::{hash3, unit_f32};
    use crate::math::warp::uniform_sphere;

    fn bases() -> Vec<Bsdf> {
        vec![
            Bsdf::Diffuse { albedo: Vec3::ONE },
            Bsdf::MetallicRoughness {
                base_color: Vec3::new(0.9, 0.5, 0.2),
                metallic: 1.0,
                roughness: 0.4,
                ior: 1.5,
                specular: 1.0,
                specular_color: Vec3::ONE,
            },
            Bsdf::MetallicRoughness {
                base_color: Vec3::ONE,
                metallic: 0.0,
                roughness: 0.7,
                ior: 1.5,
                specular: 1.0,
                specular_color: Vec3::ONE,
            },
        ]
    }

    /// Albedo at most 1 at every roughness and angle; a coat over a white
    /// diffuse base keeps most of the light (only what the coat sends back
    /// down is lost).
    #[test]
    fn white_furnace() {
        let n = 100_000u64;
        for roughness in [0.0f32, 0.05, 0.3, 0.8] {
            let coat = Coat::new(1.0, roughness, 1.5);
            for base in bases() {
                for (k, cos) in [1.0f32, 0.5, 0.1].into_iter().enumerate() {
                    let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
                    let mut sum = 0.0f64;
                    for i in 0..n {
                        let u = unit_f32(hash3(5, i, k as u64));
                        if let Some(s) = coat.sample(&base, Vec3::ONE, wo, u, u2(6, i)) {
                            sum += s.weight.max_element() as f64;
                        }
                    }
                    let a = sum / n as f64;
                    assert!(a <= 1.0 + 5e-3, "{base:?} r {roughness} cos {cos}: {a}");
                    if matches!(base, Bsdf::Diffuse { .. }) {
                        assert!(a >= 0.85, "{base:?} r {roughness} cos {cos}: {a}");
                    }
                }
            }
        }
    }

    /// Sampled weights and densities agree with `eval`, the density
    /// integrates to the fraction of samples kept, and the sampled albedo
    /// matches a quadrature of `eval` over the sphere.
    #[test]
    fn sampling_agrees_with_evaluation() {
        let tilted = Vec3::new(0.3, -0.2, 0.9).normalize();
        for (roughness, normal) in [(0.1f32, Vec3::Z), (0.5, Vec3::Z), (0.3, tilted)] {
            let coat = Coat::new(0.8, roughness, 1.5).with_normal(normal);
            for base in bases() {
                let wo = Vec3::new(0.5, 0.2, 0.7).normalize();
                let b = PointBsdf {
                    bsdf: base,
                    tint: Vec3::ONE,
                    coat: Some(coat),
                };
                let (a, q, p, kept) = albedo_two_ways(&b, wo, 400, 8);
                assert!(
                    (a - q).abs() < 0.005 + 0.01 * q,
                    "{base:?} coat normal {normal}: {a} vs {q}"
                );
                assert!((p - kept).abs() < 0.01, "{base:?}: pdf {p}, kept {kept}");
            }
        }
    }

    #[test]
    fn the_coat_is_reciprocal() {
        let coat = Coat::new(0.7, 0.3, 1.5);
        for base in bases() {
            for i in 0..500u64 {
                let a = uniform_sphere(u2(10, i));
                let mut b = uniform_sphere(u2(11, i));
                b.z = b.z.abs() * a.z.signum();
                let f = coat.eval(&base, Vec3::ONE, a, b).f;
                let r = coat.eval(&base, Vec3::ONE, b, a).f;
                let scale = f.max_element().max(r.max_element()).max(1e-3);
                assert!((f - r).abs().max_element() <= 1e-3 * scale, "{f} {r}");
            }
        }
    }
}
