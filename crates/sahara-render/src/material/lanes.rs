//! BSDFs in SIMD lanes: each lane a shading point with its own BSDF, the
//! lane loop's version of [`PointBsdf::eval`] and [`PointBsdf::sample`]
//! for the BSDFs real scenes use most: the Lambertian reflector, the
//! conductor (smooth, and rough with GGX or Beckmann microfacets; the
//! mirror), smooth and rough glass.
//!
//! Every kind present among the lanes is computed on all lanes and the
//! results are blended by the lanes' kinds, so the arithmetic of a lane
//! is its BSDF's whatever its neighbours hold. The formulas are those of
//! the scalar BSDFs ([`super::diffuse`], [`super::conductor`],
//! [`super::dielectric`], [`super::microfacet`]); sines and cosines come
//! from a polynomial ([`crate::math::lanes::sin_cos`]), so the values agree
//! with the scalar ones to a few ulps, not bit for bit. Beckmann's
//! Smith term and visible-normal sampling (the error function, a Newton
//! search in double precision) are computed lane by lane by the scalar
//! code, the rest of the Beckmann lobe in the lanes.
//!
//! The other BSDFs (the layered ones of [`super::layered`]: glTF's
//! metallic-roughness, coated diffuse, measured conductors; thin glass)
//! have no formulas here: their lanes are evaluated and sampled lane by
//! lane by the scalar BSDF itself, so the path stays in the lanes (its
//! light sample, shadow ray in the round's batch, MIS and roulette) and
//! those lanes' values are the scalar ones bit for bit. A point under a
//! clear coat is shaded by the scalar code ([`BsdfLanes::set`] says so):
//! the coat's normal is set in the scalar shading frame.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

use glam::Vec3;

use super::microfacet::{Distribution, Microfacet};
use super::{Bsdf, Material, PointBsdf};
use crate::math::lanes::{F, M, V};

/// The BSDFs of `N` lanes: each lane's kind, and its parameters.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BsdfLanes<const N: usize> {
    /// Lambertian lanes (`color` their albedo).
    pub diffuse: M<N>,
    /// Rough conductor lanes (`color` their normal reflectance).
    pub conductor: M<N>,
    /// Perfect mirror lanes (smooth conductors too).
    pub mirror: M<N>,
    /// Smooth glass lanes.
    pub glass: M<N>,
    /// Rough glass lanes.
    pub rough_glass: M<N>,
    /// Lanes whose microfacets are Beckmann's (else GGX).
    pub beckmann: M<N>,
    /// The scalar BSDF of each lane evaluated and sampled by its scalar
    /// code (none for the lanes with lane formulas).
    pub scalar: [Option<PointBsdf>; N],
    /// Of the `scalar` lanes, those whose every lobe is a delta, and those
    /// that may transmit.
    pub by_lane_delta: M<N>,
    pub by_lane_transmits: M<N>,
    /// Albedo, or reflectance at normal incidence, tint applied.
    pub color: V<N>,
    /// Microfacet width.
    pub alpha: F<N>,
    /// Index of refraction of glass.
    pub ior: F<N>,
}

/// A sampled direction per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SampleLanes<const N: usize> {
    /// Lanes with a sample (the others have none: the path ends).
    pub ok: M<N>,
    /// Incident direction (unit, local frame).
    pub wi: V<N>,
    /// `f |cos| / pdf`.
    pub weight: V<N>,
    /// Density (a delta lobe's discrete probability).
    pub pdf: F<N>,
    /// Lanes whose lobe is a delta.
    pub delta: M<N>,
}

impl<const N: usize> Default for BsdfLanes<N> {
    fn default() -> Self {
        let no = M::splat(false);
        Self {
            diffuse: no,
            conductor: no,
            mirror: no,
            glass: no,
            rough_glass: no,
            beckmann: no,
            by_lane_delta: no,
            by_lane_transmits: no,
            scalar: [None; N],
            color: V::default(),
            alpha: F::splat(0.0),
            ior: F::splat(1.5),
        }
    }
}

/// True if every material of `materials` is shaded in the lanes wherever
/// it is hit: no clear coat, no normal map, no holes (each of those sends
/// a lane to the scalar code).
pub(crate) fn all_in_lanes(materials: &[Material]) -> bool {
    materials
        .iter()
        .all(|m| m.clearcoat.is_none() && m.textures.normal.is_none() && !m.has_holes())
}

impl<const N: usize> BsdfLanes<N> {
    /// Makes lane `i` the BSDF `p`; false (the lane untouched) if it is
    /// under a clear coat, which the lanes leave to the scalar code.
    #[inline]
    pub fn set(&mut self, i: usize, p: &PointBsdf) -> bool {
        if p.coat.is_some() {
            return false;
        }
        let rough = |distribution: Distribution, roughness: f32| {
            let mf = Microfacet::new(distribution, roughness);
            (
                mf.alpha,
                distribution == Distribution::Beckmann,
                mf.is_smooth(),
            )
        };
        let (mut color, mut alpha, mut ior, mut beckmann) = (Vec3::ZERO, 0.0, 1.5, false);
        let kind = match p.bsdf {
            Bsdf::Diffuse { albedo } => {
                color = albedo * p.tint;
                0
            }
            Bsdf::Conductor {
                color: c,
                roughness,
                distribution,
            } => {
                let (a, b, smooth) = rough(distribution, roughness);
                color = c * p.tint;
                (alpha, beckmann) = (a, b);
                if smooth {
                    2
                } else {
                    1
                }
            }
            Bsdf::Mirror { color: c } => {
                color = c * p.tint;
                2
            }
            Bsdf::Dielectric { ior: eta } => {
                ior = eta;
                3
            }
            Bsdf::RoughDielectric {
                ior: eta,
                roughness,
                distribution,
            } => {
                let (a, b, smooth) = rough(distribution, roughness);
                (alpha, beckmann, ior) = (a, b, eta);
                if smooth {
                    3
                } else {
                    4
                }
            }
            Bsdf::ComplexConductor { .. }
            | Bsdf::MetallicRoughness { .. }
            | Bsdf::CoatedDiffuse { .. }
            | Bsdf::ThinDielectric { .. } => 5,
        };
        self.by_lane_delta.0[i] = kind == 5 && p.is_delta();
        self.by_lane_transmits.0[i] = kind == 5 && !p.is_reflective_only();
        self.scalar[i] = (kind == 5).then_some(*p);
        self.diffuse.0[i] = kind == 0;
        self.conductor.0[i] = kind == 1;
        self.mirror.0[i] = kind == 2;
        self.glass.0[i] = kind == 3;
        self.rough_glass.0[i] = kind == 4;
        self.beckmann.0[i] = beckmann;
        self.color.set(i, color);
        self.alpha.0[i] = alpha;
        self.ior.0[i] = ior;
        true
    }

    /// Lanes whose every lobe is a delta (light sampling cannot help).
    #[inline(always)]
    pub fn is_delta(&self) -> M<N> {
        self.mirror | self.glass | self.by_lane_delta
    }

    /// Lanes that only reflect.
    #[inline(always)]
    pub fn is_reflective_only(&self) -> M<N> {
        !(self.glass | self.rough_glass | self.by_lane_transmits)
    }

    /// The lanes' scalar BSDFs (of those that have one), with their lane
    /// numbers.
    #[inline(always)]
    fn scalar_lanes(&self) -> impl Iterator<Item = (usize, &PointBsdf)> {
        self.scalar
            .iter()
            .enumerate()
            .filter_map(|(i, p)| Some((i, p.as_ref()?)))
    }

    /// The microfacets of the lanes.
    #[inline(always)]
    fn microfacets(&self) -> Microfacets<N> {
        Microfacets {
            alpha: self.alpha,
            beckmann: self.beckmann,
        }
    }

    /// Value and density of each lane's BSDF for `(wo, wi)` (zero for
    /// delta lobes), as [`PointBsdf::eval`].
    #[inline(always)]
    pub fn eval(&self, wo: V<N>, wi: V<N>) -> (V<N>, F<N>) {
        let zero = F::splat(0.0);
        let mut f = V::default();
        let mut pdf = zero;
        if self.diffuse.any() {
            let same = (wo.z * wi.z).gt(zero) & self.diffuse;
            f = same.select_v(self.color * FRAC_1_PI, f);
            pdf = same.select(wi.z.abs() * FRAC_1_PI, pdf);
        }
        if self.conductor.any() {
            let mf = self.microfacets();
            let ok = (wo.z * wi.z).gt(zero) & self.conductor;
            let flip = wo.z.lt(zero);
            let (wo, wi) = (upper(wo, flip), upper(wi, flip));
            let h = (wo + wi).normalize();
            let oh = wo.dot(h);
            let ok = ok & oh.gt(zero);
            let fr = schlick(self.color, oh);
            let v = mf.d(h) * mf.g(wo, wi) / (wo.z * wi.z * 4.0);
            f = ok.select_v(fr * v, f);
            pdf = ok.select(mf.pdf_visible(wo, h) / (oh * 4.0), pdf);
        }
        if self.rough_glass.any() {
            let (rf, rpdf) = self.eval_rough_glass(wo, wi);
            f = self.rough_glass.select_v(V::new(rf, rf, rf), f);
            pdf = self.rough_glass.select(rpdf, pdf);
        }
        for (i, p) in self.scalar_lanes() {
            let e = p.eval(wo.get(i), wi.get(i));
            f.set(i, e.f);
            pdf.0[i] = e.pdf;
        }
        (f, pdf)
    }

    /// The rough dielectric's value (grey) and density, as
    /// [`super::dielectric::eval_rough`].
    #[inline(always)]
    fn eval_rough_glass(&self, wo: V<N>, wi: V<N>) -> (F<N>, F<N>) {
        let zero = F::splat(0.0);
        let mf = self.microfacets();
        let ok = !(wo.z.eq(zero) | wi.z.eq(zero));
        let flip = wo.z.lt(zero);
        let eta = flip.select(F::splat(1.0) / self.ior, self.ior);
        let (wo, wi) = (upper(wo, flip), upper(wi, flip));
        let reflection = wi.z.gt(zero);
        let h = reflection.select_v(wo + wi, wo + wi * eta);
        let len2 = h.length_squared();
        let nonzero = len2.gt(zero);
        let h = h * (F::splat(1.0) / len2.sqrt());
        let h = h.z.lt(zero).select_v(-h, h);
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let ok = ok & nonzero & oh.gt(zero);
        let fr = fresnel_dielectric(oh, eta);
        let d = mf.d(h);
        let g = mf.g(wo, wi);
        let pdf_h = mf.pdf_visible(wo, h);
        // Reflection.
        let ok_r = ok & reflection & ih.gt(zero);
        let f_r = fr * d * g / (wo.z * wi.z * 4.0);
        let p_r = fr * pdf_h / (oh * 4.0);
        // Transmission: the pair straddles the microsurface too.
        let s = oh + eta * ih;
        let denom = s * s;
        let ok_t = ok & !reflection & ih.lt(zero) & denom.gt(zero);
        let one_f = 1.0 - fr;
        let f_t = one_f * d * g * (ih * oh).abs() / (wo.z * wi.z.abs() * denom);
        let p_t = one_f * pdf_h * eta * eta * ih.abs() / denom;
        (
            ok_r.select(f_r, ok_t.select(f_t, zero)),
            ok_r.select(p_r, ok_t.select(p_t, zero)),
        )
    }

    /// A direction for each lane from its BSDF, the lobe chosen by
    /// `u_lobe` and the direction by `u`, as [`PointBsdf::sample`].
    #[inline(always)]
    pub fn sample(&self, wo: V<N>, u_lobe: F<N>, u: (F<N>, F<N>)) -> SampleLanes<N> {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let mut s = SampleLanes {
            ok: M::splat(false),
            wi: V::default(),
            weight: V::default(),
            pdf: zero,
            delta: self.is_delta(),
        };
        if self.diffuse.any() {
            let mut wi = cosine_hemisphere(u);
            let ok = wi.z.gt(zero) & self.diffuse;
            let pdf = wi.z * FRAC_1_PI;
            wi.z = wo.z.lt(zero).select(-wi.z, wi.z);
            s.ok = s.ok | ok;
            s.wi = ok.select_v(wi, s.wi);
            s.weight = ok.select_v(self.color, s.weight);
            s.pdf = ok.select(pdf, s.pdf);
        }
        if self.conductor.any() {
            let mf = self.microfacets();
            let flip = wo.z.lt(zero);
            let wo_u = upper(wo, flip);
            let m = mf.sample_visible(wo_u, u, self.conductor);
            let om = wo_u.dot(m);
            let wi = m * (om * 2.0) - wo_u;
            let ok = self.conductor & !wo.z.eq(zero) & wi.z.gt(zero) & om.gt(zero);
            let pdf = mf.pdf_visible(wo_u, m) / (om * 4.0);
            let w = mf.g(wo_u, wi) / mf.g1(wo_u);
            let weight = schlick(self.color, om) * w;
            s.ok = s.ok | ok;
            s.wi = ok.select_v(upper(wi, flip), s.wi);
            s.weight = ok.select_v(weight, s.weight);
            s.pdf = ok.select(pdf, s.pdf);
        }
        if self.mirror.any() {
            let ok = self.mirror & !wo.z.eq(zero);
            let wi = V::new(-wo.x, -wo.y, wo.z);
            s.ok = s.ok | ok;
            s.wi = ok.select_v(wi, s.wi);
            s.weight = ok.select_v(schlick(self.color, wo.z.abs()), s.weight);
            s.pdf = ok.select(one, s.pdf);
        }
        if self.glass.any() {
            let flip = wo.z.lt(zero);
            let eta = flip.select(one / self.ior, self.ior);
            let wo_u = upper(wo, flip);
            let fr = fresnel_dielectric(wo_u.z, eta);
            let reflect = u_lobe.lt(fr);
            let (wt, tir) = refract_z(wo_u, eta);
            let ok = self.glass & !wo.z.eq(zero) & (reflect | !tir);
            let wi = reflect.select_v(V::new(-wo_u.x, -wo_u.y, wo_u.z), wt);
            let w = reflect.select(one, one / (eta * eta));
            s.ok = s.ok | ok;
            s.wi = ok.select_v(upper(wi, flip), s.wi);
            s.weight = ok.select_v(V::new(w, w, w), s.weight);
            s.pdf = ok.select(reflect.select(fr, one - fr), s.pdf);
        }
        if self.rough_glass.any() {
            let mf = self.microfacets();
            let flip = wo.z.lt(zero);
            let eta = flip.select(one / self.ior, self.ior);
            let wo_u = upper(wo, flip);
            let m = mf.sample_visible(wo_u, u, self.rough_glass);
            let om = wo_u.dot(m);
            let fr = fresnel_dielectric(om, eta);
            let reflect = u_lobe.lt(fr);
            let wr = m * (om * 2.0) - wo_u;
            let (wt, tir) = refract(wo_u, m, eta);
            let wi = reflect.select_v(wr, wt);
            let ok = self.rough_glass
                & !wo.z.eq(zero)
                & om.gt(zero)
                & reflect.select_m(wr.z.gt(zero), !tir & wt.z.lt(zero));
            let g = mf.g(wo_u, wi) / mf.g1(wo_u);
            let w = reflect.select(g, g / (eta * eta));
            let wi_w = upper(wi, flip);
            let (_, pdf) = self.eval_rough_glass(wo, wi_w);
            let ok = ok & pdf.gt(zero);
            s.ok = s.ok | ok;
            s.wi = ok.select_v(wi_w, s.wi);
            s.weight = ok.select_v(V::new(w, w, w), s.weight);
            s.pdf = ok.select(pdf, s.pdf);
        }
        for (i, p) in self.scalar_lanes() {
            let u = glam::Vec2::new(u.0 .0[i], u.1 .0[i]);
            let Some(r) = p.sample(wo.get(i), u_lobe.0[i], u) else {
                continue;
            };
            s.ok.0[i] = true;
            s.wi.set(i, r.wi);
            s.weight.set(i, r.weight);
            s.pdf.0[i] = r.pdf;
            // A layered BSDF's smooth specular lobe is a delta, its
            // other lobes are not: the lobe sampled says.
            s.delta.0[i] = r.delta;
        }
        // As the scalar BSDFs: a sample that would poison the image is
        // dropped.
        let finite = s.weight.x.is_finite() & s.weight.y.is_finite() & s.weight.z.is_finite();
        s.ok = s.ok & finite & s.pdf.is_finite() & s.pdf.gt(zero);
        s
    }
}

/// `w` with its z mirrored where `flip`.
#[inline(always)]
fn upper<const N: usize>(w: V<N>, flip: M<N>) -> V<N> {
    V::new(w.x, w.y, flip.select(-w.z, w.z))
}

/// Schlick's Fresnel term of normal reflectance `f0` at cosine `c`.
#[inline(always)]
fn schlick<const N: usize>(f0: V<N>, c: F<N>) -> V<N> {
    let m = 1.0 - c.max(F::splat(0.0)).min(F::splat(1.0));
    let m2 = m * m;
    let m5 = m2 * m2 * m;
    V::new(
        f0.x + (1.0 - f0.x) * m5,
        f0.y + (1.0 - f0.y) * m5,
        f0.z + (1.0 - f0.z) * m5,
    )
}

/// The Fresnel reflectance of a dielectric interface of relative index
/// `eta` at cosine `cos_i`, as [`super::fresnel::dielectric`].
#[inline(always)]
fn fresnel_dielectric<const N: usize>(cos_i: F<N>, eta: F<N>) -> F<N> {
    let one = F::splat(1.0);
    let c = cos_i.max(F::splat(0.0)).min(one);
    let sin2_t = (one - c * c) / (eta * eta);
    let tir = sin2_t.ge(one);
    let cos_t = (one - sin2_t.min(one)).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    tir.select(one, (rs * rs + rp * rp) * 0.5)
}

/// `w` refracted through the plane of normal +z into relative index
/// `eta`, and the lanes where it is reflected totally instead.
#[inline(always)]
fn refract_z<const N: usize>(w: V<N>, eta: F<N>) -> (V<N>, M<N>) {
    let zero = F::splat(0.0);
    refract(w, V::new(zero, zero, F::splat(1.0)), eta)
}

/// `w` refracted through the surface of normal `n` into relative index
/// `eta`, as [`super::fresnel::refract`], and the lanes of total internal
/// reflection.
#[inline(always)]
fn refract<const N: usize>(w: V<N>, n: V<N>, eta: F<N>) -> (V<N>, M<N>) {
    let one = F::splat(1.0);
    let cos_i = n.dot(w);
    let sin2_i = (one - cos_i * cos_i).max(F::splat(0.0));
    let sin2_t = sin2_i / (eta * eta);
    let tir = sin2_t.ge(one);
    let cos_t = (one - sin2_t.min(one)).sqrt();
    (-w / eta + n * (cos_i / eta - cos_t), tir)
}

/// A cosine-weighted direction about +z from `u` (Shirley and Chiu's
/// concentric map of the square to the disc, lifted to the hemisphere),
/// as [`crate::math::warp::cosine_hemisphere`].
#[inline(always)]
pub(crate) fn cosine_hemisphere<const N: usize>(u: (F<N>, F<N>)) -> V<N> {
    let zero = F::splat(0.0);
    let ox = u.0 * 2.0 - 1.0;
    let oy = u.1 * 2.0 - 1.0;
    let centre = ox.eq(zero) & oy.eq(zero);
    let along_x = ox.abs().gt(oy.abs());
    let r = along_x.select(ox, oy);
    let theta = along_x.select((oy / ox) * FRAC_PI_4, FRAC_PI_2 - (ox / oy) * FRAC_PI_4);
    let (s, c) = theta.sin_cos();
    let dx = centre.select(zero, r * c);
    let dy = centre.select(zero, r * s);
    let z = (1.0 - (dx * dx + dy * dy)).max(zero).sqrt();
    V::new(dx, dy, z)
}

/// The microfacet distributions of `N` lanes.
#[derive(Clone, Copy)]
struct Microfacets<const N: usize> {
    alpha: F<N>,
    beckmann: M<N>,
}

impl<const N: usize> Microfacets<N> {
    /// The scalar distribution of lane `i`.
    #[inline(always)]
    fn lane(&self, i: usize) -> Microfacet {
        Microfacet {
            alpha: self.alpha.0[i],
            distribution: if self.beckmann.0[i] {
                Distribution::Beckmann
            } else {
                Distribution::Ggx
            },
        }
    }

    /// `D(m)`, as [`Microfacet::d`].
    #[inline(always)]
    fn d(&self, m: V<N>) -> F<N> {
        let zero = F::splat(0.0);
        let a2 = self.alpha * self.alpha;
        let c2 = m.z * m.z;
        let t = c2 * (a2 - 1.0) + 1.0;
        let ggx = a2 / (t * t * PI);
        let d = if self.beckmann.any() {
            let tan2 = (m.x * m.x + m.y * m.y) / c2;
            let b = (-(tan2 / a2)).exp() / (a2 * c2 * c2 * PI);
            self.beckmann.select(b, ggx)
        } else {
            ggx
        };
        m.z.le(zero).select(zero, d)
    }

    /// Smith's `Lambda(w)`, as [`Microfacet::lambda`]: GGX's in the lanes,
    /// Beckmann's (an error function in double precision) lane by lane.
    #[inline(always)]
    fn lambda(&self, w: V<N>) -> F<N> {
        let zero = F::splat(0.0);
        let c2 = w.z * w.z;
        let tan2 = ((1.0 - c2) / c2).max(zero);
        let ggx = ((self.alpha * self.alpha * tan2 + 1.0).sqrt() - 1.0) * 0.5;
        let mut l = c2.le(zero).select(F::splat(f32::INFINITY), ggx);
        if self.beckmann.any() {
            for i in 0..N {
                if self.beckmann.0[i] {
                    l.0[i] = self.lane(i).lambda(w.get(i));
                }
            }
        }
        l
    }

    #[inline(always)]
    fn g1(&self, w: V<N>) -> F<N> {
        F::splat(1.0) / (self.lambda(w) + 1.0)
    }

    #[inline(always)]
    fn g(&self, wo: V<N>, wi: V<N>) -> F<N> {
        F::splat(1.0) / (self.lambda(wo) + self.lambda(wi) + 1.0)
    }

    /// The density of visible normals, as [`Microfacet::pdf_visible`].
    #[inline(always)]
    fn pdf_visible(&self, wo: V<N>, m: V<N>) -> F<N> {
        let zero = F::splat(0.0);
        let v = self.g1(wo) * wo.dot(m).max(zero) * self.d(m) / wo.z;
        wo.z.le(zero).select(zero, v)
    }

    /// A visible normal seen from `wo` (z > 0) for the lanes of `on`, as
    /// [`Microfacet::sample_visible`]: GGX's in the lanes, Beckmann's lane
    /// by lane.
    #[inline(always)]
    fn sample_visible(&self, wo: V<N>, u: (F<N>, F<N>), on: M<N>) -> V<N> {
        let zero = F::splat(0.0);
        let one = F::splat(1.0);
        let a = self.alpha;
        let vh = V::new(a * wo.x, a * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let has = len2.gt(zero);
        let inv = one / len2.sqrt();
        let t1 = has.select_v(
            V::new(-vh.y * inv, vh.x * inv, zero),
            V::new(one, zero, zero),
        );
        let t2 = vh.cross(t1);
        let r = u.0.sqrt();
        let phi = u.1 * (2.0 * PI);
        let (sp, cp) = phi.sin_cos();
        let p1 = r * cp;
        let s = (vh.z + 1.0) * 0.5;
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(zero).sqrt() + s * r * sp;
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(zero).sqrt();
        let mut m = V::new(a * nh.x, a * nh.y, nh.z.max(F::splat(1e-7))).normalize();
        if (self.beckmann & on).any() {
            for i in 0..N {
                if self.beckmann.0[i] && on.0[i] {
                    let v = self
                        .lane(i)
                        .sample_visible(wo.get(i), glam::Vec2::new(u.0 .0[i], u.1 .0[i]));
                    m.set(i, v);
                }
            }
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::math::hash::{hash2, unit_f32};
    use glam::Vec2;

    /// Every kind of BSDF, textured (tint) and not: those with lane
    /// formulas, and those evaluated lane by lane by their scalar code.
    fn bsdfs() -> Vec<PointBsdf> {
        let mut v = Vec::new();
        for (i, m) in [
            Material::diffuse(Vec3::new(0.8, 0.5, 0.2)),
            Material::conductor(Vec3::new(0.9, 0.6, 0.3), 0.4),
            Material::conductor(Vec3::new(0.9, 0.6, 0.3), 0.0),
            Material::mirror(Vec3::splat(0.9)),
            Material::glass(1.5),
            Material::rough_glass(1.5, 0.3),
            Material::new(Bsdf::Conductor {
                color: Vec3::new(0.7, 0.7, 0.9),
                roughness: 0.5,
                distribution: Distribution::Beckmann,
            }),
            Material::new(Bsdf::RoughDielectric {
                ior: 1.33,
                roughness: 0.6,
                distribution: Distribution::Beckmann,
            }),
            Material::new(Bsdf::MetallicRoughness {
                base_color: Vec3::new(0.8, 0.3, 0.2),
                metallic: 0.4,
                roughness: 0.35,
                ior: 1.5,
                specular: 1.0,
                specular_color: Vec3::ONE,
            }),
            // Smooth: a delta specular lobe over a diffuse one.
            Material::new(Bsdf::MetallicRoughness {
                base_color: Vec3::new(0.2, 0.4, 0.8),
                metallic: 0.0,
                roughness: 0.0,
                ior: 1.5,
                specular: 1.0,
                specular_color: Vec3::ONE,
            }),
            Material::new(Bsdf::CoatedDiffuse {
                albedo: Vec3::new(0.7, 0.1, 0.1),
                ior: 1.5,
                roughness: 0.2,
                distribution: Distribution::Ggx,
            }),
            Material::new(Bsdf::ThinDielectric { ior: 1.5 }),
            Material::new(Bsdf::ComplexConductor {
                eta: Vec3::new(0.143, 0.374, 1.442),
                k: Vec3::new(3.983, 2.385, 1.603),
                roughness: 0.3,
                distribution: Distribution::Ggx,
                multiple_scattering: true,
            }),
        ]
        .into_iter()
        .enumerate()
        {
            let mut p = PointBsdf::new(m.bsdf);
            if i % 2 == 1 {
                p.tint = Vec3::new(0.5, 0.9, 0.7);
            }
            v.push(p);
        }
        v
    }

    fn dir(a: u64, i: u64) -> Vec3 {
        crate::math::warp::uniform_sphere(Vec2::new(
            unit_f32(hash2(a, i)),
            unit_f32(hash2(a + 7, i)),
        ))
    }

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 2e-4 * a.abs().max(b.abs()).max(1.0)
    }

    /// Each lane evaluates and samples as its scalar BSDF does, to
    /// rounding, whatever the other lanes hold.
    #[test]
    fn lanes_match_the_scalar_bsdfs() {
        let all = bsdfs();
        let mut checked = 0;
        for round in 0..400u64 {
            let mut lanes = BsdfLanes::<8>::default();
            let points: Vec<PointBsdf> = (0..8)
                .map(|i| all[((round * 3 + i * 5) % all.len() as u64) as usize])
                .collect();
            for (i, p) in points.iter().enumerate() {
                assert!(lanes.set(i, p));
            }
            let mut wo = V::<8>::default();
            let mut wi = V::<8>::default();
            for i in 0..8 {
                wo.set(i, dir(round, i as u64));
                wi.set(i, dir(round + 1000, i as u64));
            }
            let u_lobe = F::from_fn(|i| unit_f32(hash2(round + 2000, i as u64)));
            let u = (
                F::from_fn(|i| unit_f32(hash2(round + 3000, i as u64))),
                F::from_fn(|i| unit_f32(hash2(round + 4000, i as u64))),
            );
            let (f, pdf) = lanes.eval(wo, wi);
            let s = lanes.sample(wo, u_lobe, u);
            for (i, p) in points.iter().enumerate() {
                let e = p.eval(wo.get(i), wi.get(i));
                for (a, b) in f.get(i).to_array().into_iter().zip(e.f.to_array()) {
                    assert!(close(a, b), "{p:?} eval {a} vs {b}");
                }
                assert!(
                    close(pdf.0[i], e.pdf),
                    "{p:?} pdf {} vs {}",
                    pdf.0[i],
                    e.pdf
                );
                let r = p.sample(wo.get(i), u_lobe.0[i], Vec2::new(u.0 .0[i], u.1 .0[i]));
                assert_eq!(s.ok.0[i], r.is_some(), "{p:?} {:?}", r);
                if let Some(r) = r {
                    assert_eq!(s.delta.0[i], r.delta);
                    assert!(
                        (s.wi.get(i) - r.wi).length() < 1e-3,
                        "{p:?} {} vs {}",
                        s.wi.get(i),
                        r.wi
                    );
                    for (a, b) in s
                        .weight
                        .get(i)
                        .to_array()
                        .into_iter()
                        .zip(r.weight.to_array())
                    {
                        assert!(close(a, b), "{p:?} weight {a} vs {b}");
                    }
                    assert!(
                        close(s.pdf.0[i], r.pdf),
                        "{p:?} pdf {} vs {}",
                        s.pdf.0[i],
                        r.pdf
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 1500, "{checked}");
    }

    #[test]
    fn a_clear_coat_has_no_lane_version() {
        let mut lanes = BsdfLanes::<8>::default();
        let mut coated = PointBsdf::new(Bsdf::Diffuse { albedo: Vec3::ONE });
        coated.coat = Some(super::super::Coat::new(1.0, 0.1, 1.5));
        assert!(!lanes.set(0, &coated));
    }
}
