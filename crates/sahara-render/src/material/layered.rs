//! Reflectors made of a GGX specular lobe over terms that scatter like a
//! diffuse surface: the glTF metallic-roughness model, the coated diffuse
//! surface, and the energy-compensated conductor.
//!
//! Every such BSDF is
//! `f(wo, wi) = F(wo.h) D G / (4 |wo.z| |wi.z|) + sum_j c_j (1 - E_j(wo)) (1 - E_j(wi))`
//! where `E_j` is the directional albedo of a GGX lobe with Schlick's
//! Fresnel (see [`super::albedo`]). A term of that form is reciprocal, and
//! its albedo from `wo` is `c_j (1 - E_j(wo)) pi (1 - E_j,avg)`, which the
//! coefficients below choose so that nothing is created:
//!
//! - a dielectric specular layer of albedo `E_s` over a diffuse base of
//!   colour `rho` (glTF's "fresnel mix", albedo scaling):
//!   `c = rho / (pi (1 - E_s,avg))`, total albedo `E_s(wo) + rho (1 - E_s(wo))`;
//! - a dielectric coat of index `eta` over a diffuse base, with the light
//!   the coat reflects back down scattered again (as in Mitsuba's
//!   `plastic`): the coat transmits `(1 - E_avg) / eta^2` of the diffuse
//!   light leaving the base, reflecting `F_i = 1 - (1 - E_avg) / eta^2`,
//!   so `c = rho / (pi eta^2 (1 - rho F_i))`;
//! - the multiple scattering a single GGX bounce leaves out
//!   (Kulla and Conty 2017): with `E_1` the albedo of the lobe for
//!   `F = 1`, `c = F_ms / (pi (1 - E_1,avg))`,
//!   `F_ms = F_avg^2 E_1,avg / (1 - F_avg (1 - E_1,avg))`, so that a white
//!   conductor reflects everything at every roughness.
//!
//! Sampling picks the specular lobe (visible normals) or a cosine-weighted
//! direction with probabilities proportional to their albedos from `wo`;
//! the density is the mixture of both. A smooth specular lobe is a delta.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

use super::albedo;
use super::fresnel::{conductor, reflect, schlick_f90};
use super::microfacet::{Distribution, Microfacet};
use super::{BsdfEval, BsdfSample};
use crate::math::warp::{cosine_hemisphere, luminance};

/// The Fresnel term of the specular lobe.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Fresnel {
    /// `w_d Schlick(f0, f90) + w_m Schlick(metal_f0, 1)`: glTF's blend of
    /// a dielectric and a metal by `metallic`.
    Blend {
        w_d: f32,
        f0: Vec3,
        f90: Vec3,
        w_m: f32,
        metal_f0: Vec3,
    },
    /// The exact conductor term of `eta + i k`, times `tint`.
    Conductor { eta: Vec3, k: Vec3, tint: Vec3 },
}

impl Fresnel {
    #[inline]
    fn eval(&self, c: f32) -> Vec3 {
        match *self {
            Fresnel::Blend {
                w_d,
                f0,
                f90,
                w_m,
                metal_f0,
            } => w_d * schlick_f90(f0, f90, c) + w_m * schlick_f90(metal_f0, Vec3::ONE, c),
            Fresnel::Conductor { eta, k, tint } => conductor(c, eta, k) * tint,
        }
    }

    /// Reflectance at normal incidence.
    #[inline]
    fn f0(&self) -> Vec3 {
        self.eval(1.0)
    }

    /// The lobe's albedo from `mu` (for a conductor, that of Schlick's
    /// form through its normal-incidence value: only the choice of lobe
    /// and the multiple-scattering colour use it).
    #[inline]
    fn albedo(&self, mf: &Microfacet, mu: f32, roughness: f32) -> Vec3 {
        let d = mf.distribution;
        match *self {
            Fresnel::Blend {
                w_d,
                f0,
                f90,
                w_m,
                metal_f0,
            } => {
                w_d * albedo::schlick(d, f0, f90, mu, roughness)
                    + w_m * albedo::schlick(d, metal_f0, Vec3::ONE, mu, roughness)
            }
            Fresnel::Conductor { .. } => albedo::schlick(d, self.f0(), Vec3::ONE, mu, roughness),
        }
    }
}

/// A diffuse-like term `c (1 - E(wo)) (1 - E(wi))`, `E` the albedo of a
/// microfacet lobe (of the BSDF's distribution) with Schlick's
/// `(f0, f90)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Term {
    c: Vec3,
    f0: Vec3,
    f90: Vec3,
}

/// One layered BSDF at one shading point.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layered {
    roughness: f32,
    mf: Microfacet,
    fresnel: Fresnel,
    terms: [Option<Term>; 2],
}

/// `1 - x`, kept away from zero (a lobe that reflects everything on
/// average leaves nothing to the term anyway).
#[inline]
fn complement(x: Vec3) -> Vec3 {
    (Vec3::ONE - x).max(Vec3::splat(1e-4))
}

impl Layered {
    /// The glTF 2.0 metallic-roughness BSDF: a blend by `metallic` of a
    /// dielectric specular layer (Schlick, `f0 = ((ior - 1) / (ior + 1))^2`
    /// times `specular_color`, both times `specular`, as
    /// `KHR_materials_specular` defines) over a diffuse base of
    /// `base_color`, and a metal of reflectance `base_color`.
    pub fn metallic_roughness(
        base_color: Vec3,
        metallic: f32,
        roughness: f32,
        ior: f32,
        specular: f32,
        specular_color: Vec3,
    ) -> Self {
        let m = metallic.clamp(0.0, 1.0);
        let r0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let f0 = (Vec3::splat(r0) * specular_color).min(Vec3::ONE) * specular;
        let f90 = Vec3::splat(specular);
        let mf = Microfacet::ggx(roughness);
        let e_avg = albedo::schlick_avg(mf.distribution, f0, f90, roughness);
        let diffuse = Term {
            c: (1.0 - m) * base_color * FRAC_1_PI / complement(e_avg),
            f0,
            f90,
        };
        let mut l = Self {
            roughness,
            mf,
            fresnel: Fresnel::Blend {
                w_d: 1.0 - m,
                f0,
                f90,
                w_m: m,
                metal_f0: base_color,
            },
            terms: [(m < 1.0).then_some(diffuse), None],
        };
        if m > 0.0 {
            let f_avg = albedo::schlick_fresnel_avg(base_color);
            l.terms[1] = Some(l.multiple_scattering(f_avg, m));
        }
        l
    }

    /// A dielectric coat of index `ior`, microfacet `distribution` and
    /// `roughness` over a diffuse base of reflectance `albedo`.
    pub fn coated_diffuse(
        albedo: Vec3,
        ior: f32,
        distribution: Distribution,
        roughness: f32,
    ) -> Self {
        let mf = Microfacet::new(distribution, roughness);
        let eta = ior.max(1.0 + 1e-4);
        let f0 = Vec3::splat(((eta - 1.0) / (eta + 1.0)).powi(2));
        let e_avg = albedo::schlick_avg(mf.distribution, f0, Vec3::ONE, roughness);
        let f_inside = Vec3::ONE - complement(e_avg) / (eta * eta);
        let base = Term {
            c: albedo * FRAC_1_PI / (eta * eta * (Vec3::ONE - albedo * f_inside)),
            f0,
            f90: Vec3::ONE,
        };
        Self {
            roughness,
            mf,
            fresnel: Fresnel::Blend {
                w_d: 1.0,
                f0,
                f90: Vec3::ONE,
                w_m: 0.0,
                metal_f0: Vec3::ZERO,
            },
            terms: [Some(base), None],
        }
    }

    /// A conductor of complex index `eta + i k` (Fresnel times `tint`)
    /// with microfacet `distribution` and `roughness`, with the energy of
    /// multiple scattering between microfacets added if
    /// `multiple_scattering`.
    pub fn conductor(
        eta: Vec3,
        k: Vec3,
        tint: Vec3,
        (distribution, roughness): (Distribution, f32),
        multiple_scattering: bool,
    ) -> Self {
        let fresnel = Fresnel::Conductor { eta, k, tint };
        let mut l = Self {
            roughness,
            mf: Microfacet::new(distribution, roughness),
            fresnel,
            terms: [None, None],
        };
        if multiple_scattering {
            let f_avg = albedo::schlick_fresnel_avg(fresnel.f0());
            l.terms[0] = Some(l.multiple_scattering(f_avg, 1.0));
        }
        l
    }

    /// The Kulla-Conty term of a conductor of average Fresnel `f_avg`,
    /// weighted by `w`.
    fn multiple_scattering(&self, f_avg: Vec3, w: f32) -> Term {
        let e1_avg =
            albedo::schlick_avg(self.mf.distribution, Vec3::ONE, Vec3::ONE, self.roughness);
        let loss = complement(e1_avg);
        let f_ms = f_avg * f_avg * e1_avg / (Vec3::ONE - f_avg * (Vec3::ONE - e1_avg));
        Term {
            c: w * f_ms * FRAC_1_PI / loss,
            f0: Vec3::ONE,
            f90: Vec3::ONE,
        }
    }

    /// True if the specular lobe is a delta.
    #[inline]
    pub fn smooth_specular(&self) -> bool {
        self.mf.is_smooth()
    }

    /// True if every lobe is a delta (a smooth specular lobe and no term
    /// that scatters).
    pub fn is_delta(&self) -> bool {
        self.smooth_specular()
            && self
                .terms
                .iter()
                .flatten()
                .all(|t| t.c == Vec3::ZERO || (t.f0 == Vec3::ONE && t.f90 == Vec3::ONE))
    }

    /// `1 - E` of term `t` at `mu`.
    #[inline]
    fn one_minus_e(&self, t: &Term, mu: f32) -> Vec3 {
        let d = self.mf.distribution;
        (Vec3::ONE - albedo::schlick(d, t.f0, t.f90, mu, self.roughness)).max(Vec3::ZERO)
    }

    /// The terms' value for `(wo, wi)` (both above the surface).
    #[inline]
    fn terms_f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let mut f = Vec3::ZERO;
        for t in self.terms.iter().flatten() {
            f += t.c * self.one_minus_e(t, wo.z) * self.one_minus_e(t, wi.z);
        }
        f
    }

    /// Probability of sampling the specular lobe from `wo`.
    fn spec_probability(&self, wo: Vec3) -> f32 {
        if self.terms.iter().all(Option::is_none) {
            // A lone specular lobe (a conductor without the multiple
            // scattering term): no albedo tables needed to choose it.
            return 1.0;
        }
        let spec = luminance(self.fresnel.albedo(&self.mf, wo.z, self.roughness)).max(0.0);
        let mut rest = 0.0;
        for t in self.terms.iter().flatten() {
            let avg = albedo::schlick_avg(self.mf.distribution, t.f0, t.f90, self.roughness);
            rest += luminance(t.c * self.one_minus_e(t, wo.z) * PI * complement(avg)).max(0.0);
        }
        if spec + rest <= 0.0 {
            1.0
        } else {
            spec / (spec + rest)
        }
    }

    /// Value and density (`wo`, `wi` in the upper hemisphere).
    fn eval_upper(&self, wo: Vec3, wi: Vec3, p_spec: f32) -> BsdfEval {
        let mut f = self.terms_f(wo, wi);
        let mut pdf = (1.0 - p_spec) * wi.z * FRAC_1_PI;
        if !self.smooth_specular() {
            let h = (wo + wi).normalize();
            let oh = wo.dot(h);
            if oh > 0.0 {
                let g = &self.mf;
                f += self.fresnel.eval(oh) * (g.d(h) * g.g(wo, wi) / (4.0 * wo.z * wi.z));
                pdf += p_spec * g.pdf_visible(wo, h) / (4.0 * oh);
            }
        }
        BsdfEval { f, pdf }
    }

    /// Value and density for the pair (reflection on either side: the
    /// surface is evaluated as seen from `wo`'s side).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> BsdfEval {
        if wo.z * wi.z <= 0.0 {
            return BsdfEval::ZERO;
        }
        let (wo, wi) = (upper(wo), upper(wi));
        self.eval_upper(wo, wi, self.spec_probability(wo))
    }

    /// A direction from the specular lobe (with probability by albedo) or
    /// the cosine-weighted hemisphere.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let flip = wo.z < 0.0;
        let wo = upper(wo);
        let p_spec = self.spec_probability(wo);
        let wi = if u_lobe < p_spec {
            if self.smooth_specular() {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                return Some(BsdfSample {
                    wi: to_side(wi, flip),
                    weight: self.fresnel.eval(wo.z) / p_spec,
                    pdf: p_spec,
                    delta: true,
                });
            }
            let m = self.mf.sample_visible(wo, u);
            if wo.dot(m) <= 0.0 {
                return None;
            }
            reflect(wo, m)
        } else {
            cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let e = self.eval_upper(wo, wi, p_spec);
        if e.pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi: to_side(wi, flip),
            weight: e.f * (wi.z / e.pdf),
            pdf: e.pdf,
            delta: false,
        })
    }
}

/// `w` mirrored into the upper hemisphere.
#[inline]
pub(super) fn upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

/// `w` (upper hemisphere) mirrored below the surface if `below`.
#[inline]
pub(super) fn to_side(w: Vec3, below: bool) -> Vec3 {
    if below {
        Vec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}
