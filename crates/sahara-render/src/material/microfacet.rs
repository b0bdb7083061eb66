//! Microfacet distributions: GGX / Trowbridge-Reitz and Beckmann, each
//! with its Smith shadowing term (height-correlated) and visible-normal
//! sampling.
//!
//! Local frame: the macro normal is +z. Formulas: Walter et al. 2007,
//! "Microfacet Models for Refraction through Rough Surfaces"; Heitz 2014,
//! "Understanding the Masking-Shadowing Function"; Heitz and d'Eon 2014,
//! "Importance Sampling Microfacet-Based BSDFs using the Distribution of
//! Visible Normals" (the stretch to unit roughness, Beckmann's slopes);
//! Heitz 2018, "Sampling the GGX Distribution of Visible Normals".

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Roughness below which a surface is treated as perfectly smooth (the
/// microfacet terms lose all precision as alpha goes to 0).
pub const MIN_ALPHA: f32 = 1e-3;

/// The shape of a rough surface's distribution of microfacet normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Distribution {
    /// GGX (Trowbridge-Reitz): long tails, a highlight with a glow around
    /// it. glTF's and pbrt's, and Sahara's default.
    #[default]
    Ggx,
    /// Beckmann (a Gaussian of slopes): short tails, a highlight with a
    /// sharper edge. Mitsuba's default for its rough BSDFs.
    Beckmann,
}

impl Distribution {
    /// Every distribution, in a fixed order (tables are built per entry).
    pub const ALL: [Distribution; 2] = [Distribution::Ggx, Distribution::Beckmann];

    /// The names of [`Distribution::ALL`], in its order.
    pub const NAMES: [&'static str; 2] = [Distribution::Ggx.name(), Distribution::Beckmann.name()];

    /// The name scene files use (`ggx`, `beckmann`).
    pub const fn name(self) -> &'static str {
        match self {
            Distribution::Ggx => "ggx",
            Distribution::Beckmann => "beckmann",
        }
    }

    /// The distribution of a name (`ggx`, `beckmann`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|d| d.name() == name)
    }
}

/// Sahara's perceptual roughness (`alpha = roughness^2`, see
/// [`Microfacet::new`]) of a distribution's width `alpha` as pbrt and
/// Mitsuba give it, `alpha` clamped to `[0, 1]`.
pub fn roughness_from_alpha(alpha: f64) -> f32 {
    alpha.clamp(0.0, 1.0).sqrt() as f32
}

/// The one width Sahara's isotropic distributions render for an
/// anisotropic pair `(u, v)` of widths (or of roughnesses that map to
/// them): their mean, and whether the two differ (which a reader warns
/// about, naming its file).
pub fn isotropic_mean(u: f64, v: f64) -> (f64, bool) {
    (0.5 * (u + v), (u - v).abs() > 1e-6)
}

/// An isotropic microfacet distribution of width `alpha`.
#[derive(Clone, Copy, Debug)]
pub struct Microfacet {
    /// Width parameter alpha (GGX's alpha; Beckmann's RMS slope times
    /// sqrt 2).
    pub alpha: f32,
    /// The shape.
    pub distribution: Distribution,
}

impl Microfacet {
    /// The distribution for a perceptual roughness in `[0, 1]`
    /// (`alpha = roughness^2`, the Disney / glTF mapping).
    pub fn new(distribution: Distribution, roughness: f32) -> Self {
        Self {
            alpha: roughness.clamp(0.0, 1.0).powi(2),
            distribution,
        }
    }

    /// GGX for a perceptual roughness in `[0, 1]`.
    pub fn ggx(roughness: f32) -> Self {
        Self::new(Distribution::Ggx, roughness)
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
        match self.distribution {
            Distribution::Ggx => {
                let t = m.z * m.z * (a2 - 1.0) + 1.0;
                a2 / (PI * t * t)
            }
            Distribution::Beckmann => {
                // tan^2 from the tangential part: 1 - cos^2 would lose its
                // digits for the near-normal microfacets of a smooth
                // surface, where the exponent divides by alpha^2.
                let c2 = m.z * m.z;
                let tan2 = (m.x * m.x + m.y * m.y) / c2;
                (-tan2 / a2).exp() / (PI * a2 * c2 * c2)
            }
        }
    }

    /// Smith's auxiliary function Lambda(w).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        match self.distribution {
            Distribution::Ggx => {
                let tan2 = ((1.0 - c2) / c2).max(0.0);
                0.5 * (-1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
            }
            Distribution::Beckmann => beckmann_lambda(self.alpha, (w.x * w.x + w.y * w.y) / c2),
        }
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
    /// (`wo.z > 0`).
    #[inline]
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        match self.distribution {
            Distribution::Ggx => self.sample_visible_ggx(wo, u),
            Distribution::Beckmann => self.sample_visible_beckmann(wo, u),
        }
    }

    /// GGX: stretch to the unit-roughness configuration, sample the
    /// projected hemisphere there, unstretch.
    #[inline]
    fn sample_visible_ggx(&self, wo: Vec3, u: Vec2) -> Vec3 {
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

    /// Beckmann: stretch to unit roughness, where the visible slopes
    /// `(x, y)` of a direction at polar angle theta (azimuth along +x) have
    /// the density `(1 - x tan theta)+ exp(-x^2 - y^2)`: `x` by inverting
    /// its marginal distribution, `y` from its Gaussian; then rotate to
    /// the direction's azimuth and unstretch.
    fn sample_visible_beckmann(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let a = self.alpha;
        let s = Vec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let sin_t = (s.x * s.x + s.y * s.y).sqrt();
        let (cos_p, sin_p) = if sin_t > 0.0 {
            (s.x / sin_t, s.y / sin_t)
        } else {
            (1.0, 0.0)
        };
        let x = beckmann_visible_slope(s.z as f64, sin_t as f64, u.x as f64);
        let y = erfinv(2.0 * (u.y as f64).clamp(1e-7, 1.0 - 1e-7) - 1.0);
        let (x, y) = (x as f32, y as f32);
        // Rotate to the azimuth, unstretch; the normal of slope (x, y) is
        // (-x, -y, 1) normalised.
        let (xr, yr) = (cos_p * x - sin_p * y, sin_p * x + cos_p * y);
        Vec3::new(-a * xr, -a * yr, 1.0).normalize()
    }
}

/// Beckmann's Smith Lambda for a direction of `tan^2 theta` = `tan2`:
/// with `a = cot(theta) / alpha`, `(erf(a) - 1) / 2 + exp(-a^2) / (2 a
/// sqrt(pi))`, in f64 (the two terms cancel for large a). Kept out of line
/// so that GGX's Lambda, beside it, stays small enough to inline.
#[inline(never)]
fn beckmann_lambda(alpha: f32, tan2: f32) -> f32 {
    if tan2 == 0.0 {
        return 0.0;
    }
    let a = 1.0 / (alpha as f64 * (tan2 as f64).sqrt());
    let l = 0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt());
    l.max(0.0) as f32
}

/// The slope `x` along the incident azimuth of a visible microfacet of the
/// unit Beckmann distribution, seen from polar angle theta
/// (`cos_t = cos theta`, `sin_t = sin theta`), for a uniform `u`.
///
/// Its marginal density is `(1 - x tan theta) exp(-x^2)` for
/// `x < cot theta`, whose integral from `-inf` is
/// `F(x) = sqrt(pi) / 2 (1 + erf x) + tan theta / 2 exp(-x^2)`;
/// `F(x) = u F(cot theta)` is solved by Newton steps kept inside a
/// bisection bracket (F is increasing on the support, so the bracket
/// always holds the root).
fn beckmann_visible_slope(cos_t: f64, sin_t: f64, u: f64) -> f64 {
    let u = u.clamp(1e-7, 1.0 - 1e-7);
    if sin_t < 1e-6 * cos_t.max(1e-30) {
        // Normal incidence: the slopes are Gaussian.
        return erfinv(2.0 * u - 1.0);
    }
    let tan_t = sin_t / cos_t.max(1e-12);
    let cot_t = cos_t / sin_t;
    let half_sqrt_pi = 0.5 * std::f64::consts::PI.sqrt();
    let f = |x: f64| half_sqrt_pi * (1.0 + libm::erf(x)) + 0.5 * tan_t * (-x * x).exp();
    // Past 6 the slope's share is below 1e-16 (and cot may be huge).
    let hi0 = cot_t.min(6.0);
    let target = u * f(hi0);
    let (mut lo, mut hi) = (-6.0f64, hi0);
    // Start where the density without the visibility factor would put it.
    let mut x = erfinv(2.0 * u - 1.0).clamp(lo, hi);
    for _ in 0..40 {
        let v = f(x) - target;
        if v.abs() < 1e-10 {
            break;
        }
        if v > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let dv = (1.0 - x * tan_t) * (-x * x).exp();
        let next = if dv > 0.0 { x - v / dv } else { f64::NAN };
        x = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo < 1e-12 {
            break;
        }
    }
    x
}

/// The inverse error function on `(-1, 1)`: Winitzki's closed-form
/// approximation (relative error about 2e-3) refined by Newton steps on
/// `erf`.
fn erfinv(z: f64) -> f64 {
    if z <= -1.0 {
        return f64::NEG_INFINITY;
    }
    if z >= 1.0 {
        return f64::INFINITY;
    }
    const A: f64 = 0.147;
    let l = (1.0 - z * z).ln();
    let t = 2.0 / (std::f64::consts::PI * A) + 0.5 * l;
    let mut x = z.signum() * ((t * t - l / A).sqrt() - t).sqrt();
    let two_over_sqrt_pi = 2.0 / std::f64::consts::PI.sqrt();
    for _ in 0..3 {
        let d = two_over_sqrt_pi * (-x * x).exp();
        if d <= 0.0 {
            break;
        }
        x -= (libm::erf(x) - z) / d;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::hash::{hash2, unit_f32};

    fn u2(a: u64, i: u64) -> Vec2 {
        Vec2::new(unit_f32(hash2(a, i)), unit_f32(hash2(a + 1, i)))
    }

    #[test]
    fn a_files_alpha_is_the_square_of_saharas_roughness() {
        assert_eq!(roughness_from_alpha(0.25), 0.5);
        assert_eq!(roughness_from_alpha(-1.0), 0.0);
        assert_eq!(roughness_from_alpha(4.0), 1.0);
        // The roughness gives back the alpha it came from.
        let r = roughness_from_alpha(0.09);
        assert!((Microfacet::ggx(r).alpha - 0.09).abs() < 1e-7);
        assert_eq!(isotropic_mean(0.1, 0.3), (0.2, true));
        assert_eq!(isotropic_mean(0.2, 0.2), (0.2, false));
    }

    #[test]
    fn projected_ndf_integrates_to_one() {
        // The integral of D(m) m.z over the hemisphere is 1 (cosine-weighted
        // estimate, many samples).
        for d in Distribution::ALL {
            for alpha in [0.1f32, 0.5, 1.0] {
                let mf = Microfacet {
                    alpha,
                    distribution: d,
                };
                let n = 400_000;
                let mut sum = 0.0f64;
                for i in 0..n {
                    // Cosine-weighted: pdf z/pi, so D z / (z / pi) = pi D.
                    let m = crate::math::warp::cosine_hemisphere(u2(1, i));
                    sum += (PI * mf.d(m)) as f64;
                }
                let est = sum / n as f64;
                assert!((est - 1.0).abs() < 0.03, "{d:?} alpha {alpha}: {est}");
            }
        }
    }

    /// `\int g(m) D_wo(m) dm` by quadrature over the hemisphere (an
    /// equal-area grid in `cos theta` and `phi`, fine enough for lobes of
    /// alpha 0.2 and wider).
    fn visible_integral(mf: &Microfacet, wo: Vec3, g: impl Fn(Vec3) -> f64) -> f64 {
        let (nz, np) = (2000, 400);
        let mut sum = 0.0f64;
        for i in 0..nz {
            let z = (i as f64 + 0.5) / nz as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..np {
                let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
                let m = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                sum += g(m) * mf.pdf_visible(wo, m) as f64;
            }
        }
        sum * 2.0 * std::f64::consts::PI / (nz * np) as f64
    }

    #[test]
    fn visible_normals_are_a_density_and_sampling_follows_it() {
        // For each distribution, width and view: D_wo integrates to 1 (the
        // Smith Lambda matches D), and the mean of test functions over
        // sampled normals equals their integral against D_wo (the sampler
        // draws from the density that eval reports).
        type Moment = (&'static str, fn(Vec3) -> f64);
        let tests: [Moment; 3] = [
            ("m.x", |m| m.x as f64),
            ("m.z^2", |m| (m.z * m.z) as f64),
            ("m.y^2", |m| (m.y * m.y) as f64),
        ];
        for d in Distribution::ALL {
            for alpha in [0.2f32, 0.6] {
                for theta in [0.0f32, 0.7, 1.3, 1.5] {
                    let mf = Microfacet {
                        alpha,
                        distribution: d,
                    };
                    let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
                    let norm = visible_integral(&mf, wo, |_| 1.0);
                    assert!((norm - 1.0).abs() < 5e-3, "{d:?} {alpha} {theta}: {norm}");
                    let n = 200_000u64;
                    for (name, g) in tests {
                        let mean = (0..n)
                            .map(|i| g(mf.sample_visible(wo, u2(7, i))))
                            .sum::<f64>()
                            / n as f64;
                        let expect = visible_integral(&mf, wo, g);
                        assert!(
                            (mean - expect).abs() < 5e-3,
                            "{d:?} alpha {alpha} theta {theta} {name}: sampled {mean}, integral {expect}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn visible_normal_samples_face_the_viewer() {
        for d in Distribution::ALL {
            let mf = Microfacet {
                alpha: 0.6,
                distribution: d,
            };
            let wo = Vec3::new(0.8, 0.0, 0.6);
            for i in 0..1000 {
                let m = mf.sample_visible(wo, u2(3, i));
                assert!(m.z > 0.0 && (m.length() - 1.0).abs() < 1e-4, "{d:?}");
                assert!(wo.dot(m) >= -1e-4, "{d:?}");
            }
        }
    }

    #[test]
    fn beckmann_lambda_matches_its_closed_form_limits() {
        let mf = Microfacet {
            alpha: 0.3,
            distribution: Distribution::Beckmann,
        };
        // Normal incidence: no masking; grazing: Lambda grows without
        // bound; in between, Walter et al.'s rational fit of G1 (good to
        // a few parts in a thousand).
        assert_eq!(mf.lambda(Vec3::Z), 0.0);
        for cos in [0.05f32, 0.2, 0.5] {
            let w = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let a = cos / (mf.alpha * (1.0 - cos * cos).sqrt());
            let fit = if a < 1.6 {
                (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
            } else {
                1.0
            };
            assert!(
                (mf.g1(w) - fit).abs() < 4e-3,
                "cos {cos}: {} vs {fit}",
                mf.g1(w)
            );
        }
    }

    #[test]
    fn erfinv_inverts_erf() {
        for z in [-0.999999, -0.9, -0.3, 0.0, 1e-9, 0.5, 0.99, 0.999999] {
            assert!((libm::erf(erfinv(z)) - z).abs() < 1e-12, "{z}");
        }
    }
}
