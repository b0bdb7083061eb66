//! Metals: the rough GGX conductor and the perfect mirror, with any
//! Fresnel term (Schlick's tinted by a colour, or the exact one of a
//! complex index of refraction).

use glam::{Vec2, Vec3};

use super::fresnel::reflect;
use super::microfacet::Microfacet;
use super::{BsdfEval, BsdfSample};

/// Mirror `w` into the upper hemisphere (reflection-only BSDFs are
/// two-sided: they are evaluated as if seen from above).
#[inline]
fn upper(w: Vec3, flip: bool) -> Vec3 {
    if flip {
        Vec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}

/// Value and density of the rough conductor whose Fresnel reflectance at
/// the microfacet cosine `c` is `fresnel(c)`.
pub fn eval(fresnel: impl Fn(f32) -> Vec3, mf: &Microfacet, wo: Vec3, wi: Vec3) -> BsdfEval {
    if wo.z * wi.z <= 0.0 {
        return BsdfEval::ZERO;
    }
    let flip = wo.z < 0.0;
    let (wo, wi) = (upper(wo, flip), upper(wi, flip));
    let h = (wo + wi).normalize();
    let oh = wo.dot(h);
    if oh <= 0.0 {
        return BsdfEval::ZERO;
    }
    let f = fresnel(oh) * (mf.d(h) * mf.g(wo, wi) / (4.0 * wo.z * wi.z));
    BsdfEval {
        f,
        pdf: mf.pdf_visible(wo, h) / (4.0 * oh),
    }
}

/// A direction reflected about a visible microfacet normal.
pub fn sample(
    fresnel: impl Fn(f32) -> Vec3,
    mf: &Microfacet,
    wo: Vec3,
    u: Vec2,
) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let flip = wo.z < 0.0;
    let wo = upper(wo, flip);
    let m = mf.sample_visible(wo, u);
    let om = wo.dot(m);
    let wi = reflect(wo, m);
    if wi.z <= 0.0 || om <= 0.0 {
        return None;
    }
    let pdf = mf.pdf_visible(wo, m) / (4.0 * om);
    // f cos / pdf = F D G / (4 wo.z) / (G1 D (wo.m) / wo.z / (4 wo.m))
    //             = F G / G1: D and the Jacobian cancel.
    let weight = fresnel(om) * (mf.g(wo, wi) / mf.g1(wo));
    Some(BsdfSample {
        wi: upper(wi, flip),
        weight,
        pdf,
        delta: false,
    })
}

/// The perfect mirror direction (a delta lobe).
pub fn sample_mirror(fresnel: impl Fn(f32) -> Vec3, wo: Vec3) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi: Vec3::new(-wo.x, -wo.y, wo.z),
        weight: fresnel(wo.z.abs()),
        pdf: 1.0,
        delta: true,
    })
}
