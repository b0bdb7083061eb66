//! Materials: a BSDF, an optional albedo texture, and emission.
//!
//! BSDFs work in a local shading frame whose +z is the shading normal (for
//! glass: the outward normal). Values are radiance-transport BSDFs; a
//! sample's `weight` is `f |cos| / pdf`.

pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod microfacet;

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::texture::Texture;
use microfacet::Ggx;

/// The scattering model of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian reflection with reflectance `albedo`.
    Diffuse {
        /// Reflectance in `[0, 1]` per channel.
        albedo: Vec3,
    },
    /// Rough metal: GGX microfacets, Schlick Fresnel tinted by `color`.
    Conductor {
        /// Reflectance at normal incidence.
        color: Vec3,
        /// Perceptual roughness in `[0, 1]` (`alpha = roughness^2`).
        roughness: f32,
    },
    /// A perfect mirror (Schlick Fresnel tinted by `color`).
    Mirror {
        /// Reflectance at normal incidence.
        color: Vec3,
    },
    /// Smooth glass: Fresnel-weighted reflection and refraction.
    Dielectric {
        /// Index of refraction of the inside (below the outward normal).
        ior: f32,
    },
    /// Rough glass (Walter et al. 2007): translucency.
    RoughDielectric {
        /// Index of refraction of the inside.
        ior: f32,
        /// Perceptual roughness in `[0, 1]`.
        roughness: f32,
    },
}

/// A BSDF value and the density with which [`Bsdf::sample`] picks `wi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfEval {
    /// The BSDF value (without the cosine).
    pub f: Vec3,
    /// Solid-angle density of sampling `wi` given `wo`.
    pub pdf: f32,
}

impl BsdfEval {
    /// No scattering.
    pub const ZERO: BsdfEval = BsdfEval {
        f: Vec3::ZERO,
        pdf: 0.0,
    };
}

/// A sampled incident direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Incident direction (unit, local frame).
    pub wi: Vec3,
    /// `f |cos| / pdf`.
    pub weight: Vec3,
    /// Solid-angle density (for delta lobes: the lobe's discrete probability).
    pub pdf: f32,
    /// True for a delta lobe (mirror, smooth glass).
    pub delta: bool,
}

impl Bsdf {
    /// True if every lobe is a delta: light sampling cannot help.
    pub fn is_delta(&self) -> bool {
        match *self {
            Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => true,
            Bsdf::Conductor { roughness, .. } | Bsdf::RoughDielectric { roughness, .. } => {
                Ggx::from_roughness(roughness).is_smooth()
            }
            Bsdf::Diffuse { .. } => false,
        }
    }

    /// True if the BSDF only reflects (such surfaces are two-sided).
    pub fn is_reflective_only(&self) -> bool {
        !matches!(self, Bsdf::Dielectric { .. } | Bsdf::RoughDielectric { .. })
    }

    /// True for the Lambertian BSDF.
    pub fn is_diffuse(&self) -> bool {
        matches!(self, Bsdf::Diffuse { .. })
    }

    /// Value and density for the pair `(wo, wi)`, with `tint` multiplying the
    /// base colour (texture lookup; 1 without a texture). Delta lobes give
    /// zero.
    pub fn eval(&self, tint: Vec3, wo: Vec3, wi: Vec3) -> BsdfEval {
        match *self {
            Bsdf::Diffuse { albedo } => diffuse::eval(albedo * tint, wo, wi),
            Bsdf::Conductor { color, roughness } => {
                let ggx = Ggx::from_roughness(roughness);
                if ggx.is_smooth() {
                    return BsdfEval::ZERO;
                }
                conductor::eval(color * tint, &ggx, wo, wi)
            }
            Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => BsdfEval::ZERO,
            Bsdf::RoughDielectric { ior, roughness } => {
                let ggx = Ggx::from_roughness(roughness);
                if ggx.is_smooth() {
                    return BsdfEval::ZERO;
                }
                dielectric::eval_rough(ior, &ggx, wo, wi)
            }
        }
    }

    /// An incident direction for `wo`, from a lobe chosen by `u_lobe` and a
    /// direction by `u`.
    pub fn sample(&self, tint: Vec3, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let s = match *self {
            Bsdf::Diffuse { albedo } => diffuse::sample(albedo * tint, wo, u),
            Bsdf::Conductor { color, roughness } => {
                let ggx = Ggx::from_roughness(roughness);
                if ggx.is_smooth() {
                    conductor::sample_mirror(color * tint, wo)
                } else {
                    conductor::sample(color * tint, &ggx, wo, u)
                }
            }
            Bsdf::Mirror { color } => conductor::sample_mirror(color * tint, wo),
            Bsdf::Dielectric { ior } => dielectric::sample_smooth(ior, wo, u_lobe),
            Bsdf::RoughDielectric { ior, roughness } => {
                let ggx = Ggx::from_roughness(roughness);
                if ggx.is_smooth() {
                    dielectric::sample_smooth(ior, wo, u_lobe)
                } else {
                    dielectric::sample_rough(ior, &ggx, wo, u_lobe, u)
                }
            }
        }?;
        // A sample that would poison the image is dropped here, at the one
        // place all BSDFs pass through; the tests make sure this never fires
        // for valid input.
        (s.weight.is_finite() && s.pdf.is_finite() && s.pdf > 0.0).then_some(s)
    }
}

/// A surface material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// How the surface scatters light.
    pub bsdf: Bsdf,
    /// Optional texture multiplying the albedo / colour (ignored by glass).
    pub texture: Option<Arc<Texture>>,
    /// Emitted radiance (zero for non-emitters).
    pub emission: Vec3,
    /// Emit from both faces (default: only the front face, the side of the
    /// winding-order normal `(v1 - v0) x (v2 - v0)`).
    pub two_sided_emission: bool,
}

impl Material {
    /// A material from a BSDF, without texture or emission.
    pub fn new(bsdf: Bsdf) -> Self {
        Self {
            bsdf,
            texture: None,
            emission: Vec3::ZERO,
            two_sided_emission: false,
        }
    }

    /// A Lambertian material.
    pub fn diffuse(albedo: Vec3) -> Self {
        Self::new(Bsdf::Diffuse { albedo })
    }

    /// A rough metal.
    pub fn conductor(color: Vec3, roughness: f32) -> Self {
        Self::new(Bsdf::Conductor { color, roughness })
    }

    /// A perfect mirror.
    pub fn mirror(color: Vec3) -> Self {
        Self::new(Bsdf::Mirror { color })
    }

    /// Smooth glass.
    pub fn glass(ior: f32) -> Self {
        Self::new(Bsdf::Dielectric { ior })
    }

    /// Rough glass.
    pub fn rough_glass(ior: f32, roughness: f32) -> Self {
        Self::new(Bsdf::RoughDielectric { ior, roughness })
    }

    /// A black emitter of radiance `radiance`.
    pub fn emitter(radiance: Vec3) -> Self {
        Self::diffuse(Vec3::ZERO).with_emission(radiance)
    }

    /// This material emitting `radiance`.
    pub fn with_emission(mut self, radiance: Vec3) -> Self {
        self.emission = radiance;
        self
    }

    /// This material with an albedo texture.
    pub fn with_texture(mut self, texture: Arc<Texture>) -> Self {
        self.texture = Some(texture);
        self
    }

    /// True if the material emits light.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// The texture tint at `uv` (1 without a texture).
    #[inline]
    pub fn tint(&self, uv: Vec2) -> Vec3 {
        match &self.texture {
            Some(t) => t.bilinear(uv),
            None => Vec3::ONE,
        }
    }

    /// Radiance emitted towards a direction with `cos_front` the cosine to
    /// the front face's normal.
    #[inline]
    pub fn emitted(&self, cos_front: f32) -> Vec3 {
        if cos_front > 0.0 || (self.two_sided_emission && cos_front < 0.0) {
            self.emission
        } else {
            Vec3::ZERO
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::{hash3, unit_f32};
    use crate::sampling::uniform_sphere;
    use std::f32::consts::PI;

    fn u2(a: u64, i: u64) -> Vec2 {
        Vec2::new(unit_f32(hash3(a, i, 0)), unit_f32(hash3(a, i, 1)))
    }

    fn non_delta() -> Vec<Bsdf> {
        vec![
            Bsdf::Diffuse { albedo: Vec3::ONE },
            Bsdf::Conductor {
                color: Vec3::ONE,
                roughness: 0.3,
            },
            Bsdf::Conductor {
                color: Vec3::new(0.9, 0.6, 0.3),
                roughness: 0.8,
            },
            Bsdf::RoughDielectric {
                ior: 1.5,
                roughness: 0.4,
            },
            Bsdf::RoughDielectric {
                ior: 1.33,
                roughness: 0.8,
            },
        ]
    }

    /// The sampled estimate of the directional albedo must match a
    /// quadrature of `eval` over the sphere (a jittered equal-area grid:
    /// accurate even for peaked lobes), and the sampling pdf must integrate
    /// to the fraction of samples not rejected. This fails if `weight`, `f`
    /// or `pdf` disagree anywhere.
    #[test]
    fn sampling_agrees_with_evaluation() {
        let wos = [
            Vec3::new(0.3, 0.1, 0.9).normalize(),
            Vec3::new(0.8, -0.2, 0.3).normalize(),
            Vec3::new(0.2, 0.3, -0.7).normalize(),
        ];
        let g = 600u64;
        let n = g * g;
        for bsdf in non_delta() {
            for (k, wo) in wos.iter().enumerate() {
                let mut sampled = 0.0f64;
                let mut accepted = 0u64;
                let mut quad = 0.0f64;
                let mut pdf_integral = 0.0f64;
                for i in 0..n {
                    if let Some(s) =
                        bsdf.sample(Vec3::ONE, *wo, unit_f32(hash3(9, i, 7)), u2(k as u64, i))
                    {
                        sampled += s.weight.x as f64;
                        accepted += 1;
                        let e = bsdf.eval(Vec3::ONE, *wo, s.wi);
                        let rel = (e.pdf - s.pdf).abs() / s.pdf.max(1e-3);
                        assert!(rel < 1e-2, "{bsdf:?}: pdf {} vs {}", s.pdf, e.pdf);
                    }
                    let j = u2(100 + k as u64, i);
                    let cell = Vec2::new((i % g) as f32 + j.x, (i / g) as f32 + j.y) / g as f32;
                    let wi = uniform_sphere(cell);
                    let e = bsdf.eval(Vec3::ONE, *wo, wi);
                    quad += (e.f.x * wi.z.abs() * 4.0 * PI) as f64;
                    pdf_integral += (e.pdf * 4.0 * PI) as f64;
                }
                let (a, b) = (sampled / n as f64, quad / n as f64);
                assert!(
                    (a - b).abs() < 0.005 + 0.01 * b,
                    "{bsdf:?} wo {wo}: sampled {a} quadrature {b}"
                );
                // Refraction out of a denser medium scales radiance up by
                // eta^2, so only reflectors are bounded by 1.
                if bsdf.is_reflective_only() {
                    assert!(a <= 1.0 + 1e-3, "{bsdf:?}: albedo {a} > 1");
                }
                let p = pdf_integral / n as f64;
                let kept = accepted as f64 / n as f64;
                assert!(
                    (p - kept).abs() < 0.01,
                    "{bsdf:?}: pdf integrates to {p}, kept {kept}"
                );
            }
        }
    }

    #[test]
    fn smooth_glass_conserves_energy() {
        // Reflection and refraction weights, averaged with the Fresnel
        // probabilities, carry all the energy (up to the 1/eta^2 radiance
        // scale of refraction, which cancels on exit).
        let wo = Vec3::new(0.5, 0.0, 0.5f32.sqrt() * 1.22).normalize();
        let b = Bsdf::Dielectric { ior: 1.5 };
        let f = fresnel::dielectric(wo.z, 1.5);
        let r = b.sample(Vec3::ONE, wo, 0.0, Vec2::ZERO).unwrap();
        let t = b.sample(Vec3::ONE, wo, 0.999, Vec2::ZERO).unwrap();
        assert!(r.wi.z > 0.0 && t.wi.z < 0.0);
        assert!((r.pdf - f).abs() < 1e-6 && (t.pdf - (1.0 - f)).abs() < 1e-6);
        assert!((t.weight.x * 1.5 * 1.5 - 1.0).abs() < 1e-5);
        // And back out (from inside, wo below the surface): the inverse
        // scale.
        let back = b.sample(Vec3::ONE, t.wi, 0.999, Vec2::ZERO).unwrap();
        assert!((back.weight.x - 1.5 * 1.5).abs() < 1e-4);
    }
}
