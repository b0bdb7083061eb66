//! Glass: the smooth dielectric (delta reflection and refraction weighted
//! by Fresnel) and the rough dielectric of Walter et al. 2007.
//!
//! Radiance transport: refraction from index n_o into n_i scales radiance
//! by `(n_o / n_i)^2` (the BTDF is not symmetric), so the weights below
//! carry `1 / eta^2` with `eta = n(wi side) / n(wo side)`.
//!
//! The local +z axis is the outward normal: `ior` lies below it.

use glam::{Vec2, Vec3};

use super::fresnel::{dielectric as fresnel, reflect, refract};
use super::microfacet::Microfacet;
use super::{BsdfEval, BsdfSample};

/// Mirror `w`'s z when `wo` is inside, and the relative index `eta` seen
/// from `wo`'s side: the code below always works with `wo.z > 0`.
#[inline]
fn orient(wo: Vec3, ior: f32) -> (bool, f32) {
    if wo.z < 0.0 {
        (true, 1.0 / ior)
    } else {
        (false, ior)
    }
}

#[inline]
fn flip_z(w: Vec3, flip: bool) -> Vec3 {
    if flip {
        Vec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}

/// Reflection (with probability F) or refraction of a smooth interface.
pub fn sample_smooth(ior: f32, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let (flip, eta) = orient(wo, ior);
    let wo = flip_z(wo, flip);
    let f = fresnel(wo.z, eta);
    if u_lobe < f {
        return Some(BsdfSample {
            wi: flip_z(Vec3::new(-wo.x, -wo.y, wo.z), flip),
            weight: Vec3::ONE,
            pdf: f,
            delta: true,
        });
    }
    let wi = refract(wo, Vec3::Z, eta)?;
    Some(BsdfSample {
        wi: flip_z(wi, flip),
        weight: Vec3::splat(1.0 / (eta * eta)),
        pdf: 1.0 - f,
        delta: true,
    })
}

/// A thin pane of index `ior` (both faces parallel, nothing in between
/// absorbs): light is reflected, with the reflectance `R' = 2R / (1 + R)`
/// of the two faces and every bounce between them, or passes straight
/// through, undeviated.
pub fn sample_thin(ior: f32, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let r = fresnel(wo.z.abs(), ior);
    let r = if r < 1.0 { 2.0 * r / (1.0 + r) } else { 1.0 };
    if u_lobe < r {
        return Some(BsdfSample {
            wi: Vec3::new(-wo.x, -wo.y, wo.z),
            weight: Vec3::ONE,
            pdf: r,
            delta: true,
        });
    }
    Some(BsdfSample {
        wi: -wo,
        weight: Vec3::ONE,
        pdf: 1.0 - r,
        delta: true,
    })
}

/// The generalised half vector of `wo` (z > 0) and `wi`, facing +z, and
/// whether the pair is a reflection.
#[inline]
fn half_vector(wo: Vec3, wi: Vec3, eta: f32) -> (Vec3, bool) {
    let reflection = wi.z > 0.0;
    let h = if reflection { wo + wi } else { wo + eta * wi };
    let h = h.normalize_or_zero();
    (if h.z < 0.0 { -h } else { h }, reflection)
}

/// Value and density of the rough dielectric.
pub fn eval_rough(ior: f32, mf: &Microfacet, wo: Vec3, wi: Vec3) -> BsdfEval {
    if wo.z == 0.0 || wi.z == 0.0 {
        return BsdfEval::ZERO;
    }
    let (flip, eta) = orient(wo, ior);
    let (wo, wi) = (flip_z(wo, flip), flip_z(wi, flip));
    let (h, reflection) = half_vector(wo, wi, eta);
    let (oh, ih) = (wo.dot(h), wi.dot(h));
    if h == Vec3::ZERO || oh <= 0.0 {
        return BsdfEval::ZERO;
    }
    let f = fresnel(oh, eta);
    let d = mf.d(h);
    let g = mf.g(wo, wi);
    let pdf_h = mf.pdf_visible(wo, h);
    if reflection {
        if ih <= 0.0 {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            f: Vec3::splat(f * d * g / (4.0 * wo.z * wi.z)),
            pdf: f * pdf_h / (4.0 * oh),
        }
    } else {
        // The pair must straddle the microsurface too.
        if ih >= 0.0 {
            return BsdfEval::ZERO;
        }
        let denom = (oh + eta * ih) * (oh + eta * ih);
        if denom <= 0.0 {
            return BsdfEval::ZERO;
        }
        let ft = (1.0 - f) * d * g * (ih * oh).abs() / (wo.z * wi.z.abs() * denom);
        BsdfEval {
            f: Vec3::splat(ft),
            pdf: (1.0 - f) * pdf_h * eta * eta * ih.abs() / denom,
        }
    }
}

/// Reflection or refraction about a visible microfacet normal.
pub fn sample_rough(
    ior: f32,
    mf: &Microfacet,
    wo: Vec3,
    u_lobe: f32,
    u: Vec2,
) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let (flip, eta) = orient(wo, ior);
    let wo = flip_z(wo, flip);
    let m = mf.sample_visible(wo, u);
    let om = wo.dot(m);
    if om <= 0.0 {
        return None;
    }
    let f = fresnel(om, eta);
    let (wi, weight) = if u_lobe < f {
        let wi = reflect(wo, m);
        if wi.z <= 0.0 {
            return None;
        }
        // F G / G1 divided by the lobe probability F.
        (wi, mf.g(wo, wi) / mf.g1(wo))
    } else {
        let wi = refract(wo, m, eta)?;
        if wi.z >= 0.0 {
            return None;
        }
        // (1 - F) G / (G1 eta^2) divided by the lobe probability 1 - F.
        (wi, mf.g(wo, wi) / (mf.g1(wo) * eta * eta))
    };
    let e = eval_rough(ior, mf, flip_z(wo, flip), flip_z(wi, flip));
    if e.pdf <= 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi: flip_z(wi, flip),
        weight: Vec3::splat(weight),
        pdf: e.pdf,
        delta: false,
    })
}
