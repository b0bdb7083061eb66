//! Directional albedo of a microfacet reflection lobe (GGX or Beckmann),
//! tabulated once per distribution.
//!
//! With Schlick's Fresnel `F = F0 (1 - s) + F90 s`, `s = (1 - cos)^5`, the
//! fraction of light a single GGX reflection sends back from direction
//! `mu = cos theta` is linear in `F0` and `F90`:
//! `E(mu) = F0 A(mu, r) + F90 B(mu, r)`. The layered BSDFs give the base
//! layer what the specular layer does not reflect (`1 - E`), and a
//! conductor the energy that single scattering loses (`1 - E` with
//! `F = 1`, after Kulla and Conty 2017, "Revisiting Physically Based
//! Shading at Imageworks"); both need `E` and its cosine-weighted
//! hemispherical average `E_avg = 2 \int E(mu) mu dmu`.
//!
//! The tables hold `A` and `B` on a grid of `mu` and perceptual roughness
//! `r`, each entry estimated from a stratified set of visible-normal
//! samples (the estimator `G2 / G1` per sample is smooth, so a few
//! thousand samples give three to four digits).

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

use super::fresnel::reflect;
use super::microfacet::{Distribution, Microfacet};

/// Grid points along `mu` (0 to 1) and along roughness (0 to 1).
const N: usize = 32;
/// Strata per axis of an entry's samples.
const STRATA: usize = 32;

/// The tables: `A` and `B` per `(roughness, mu)`, their averages per
/// roughness.
struct Tables {
    a: Vec<f32>,
    b: Vec<f32>,
    a_avg: Vec<f32>,
    b_avg: Vec<f32>,
}

/// The cosine of grid column `i` (the first one slightly above 0: at
/// exactly grazing incidence the lobe is undefined).
fn mu_at(i: usize) -> f32 {
    (i as f32 / (N - 1) as f32).max(1e-3)
}

/// `A` and `B` for one `(mu, roughness)` by visible-normal sampling.
///
/// The samples are GGX's visible normals for both distributions: its
/// sampling map is bounded and smooth on the unit square, so the midpoint
/// rule over the strata converges fast. Beckmann's map sends the outer
/// strata to unbounded slopes, and estimated with its own samples its
/// albedo came out up to 0.6 % low at rough normal incidence; with GGX's
/// (whose tails are heavier, so the ratio of densities stays bounded) and
/// that ratio as the weight it matches a quadrature of the BSDF.
fn entry(distribution: Distribution, mu: f32, roughness: f32) -> (f32, f32) {
    let mf = Microfacet::new(distribution, roughness);
    let ggx = Microfacet::ggx(roughness);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    if mf.is_smooth() {
        let s = (1.0 - mu).powi(5);
        return (1.0 - s, s);
    }
    let (mut a, mut b) = (0.0f64, 0.0f64);
    for i in 0..STRATA {
        for j in 0..STRATA {
            let u = Vec2::new(
                (i as f32 + 0.5) / STRATA as f32,
                (j as f32 + 0.5) / STRATA as f32,
            );
            let m = ggx.sample_visible(wo, u);
            let om = wo.dot(m);
            let wi = reflect(wo, m);
            if wi.z <= 0.0 || om <= 0.0 {
                continue;
            }
            let w = match distribution {
                Distribution::Ggx => (ggx.g(wo, wi) / ggx.g1(wo)) as f64,
                // G2 D_wo / G1 over GGX's D_wo ((wo.m) / wo.z cancels);
                // the ratio of the two D's is exp(-t) (1 + t)^2 with
                // t = tan^2 / alpha^2, taken from the slope in f64 (D
                // itself in f32 loses its digits when alpha is ~1e-3).
                _ => {
                    let (x, y, z) = (m.x as f64, m.y as f64, m.z as f64);
                    let t = (x * x + y * y) / (z * z) / (mf.alpha as f64).powi(2);
                    let ratio = (-t).exp() * (1.0 + t) * (1.0 + t);
                    mf.g(wo, wi) as f64 / ggx.g1(wo) as f64 * ratio
                }
            };
            let s = ((1.0 - om).max(0.0) as f64).powi(5);
            a += w * (1.0 - s);
            b += w * s;
        }
    }
    let mut n = (STRATA * STRATA) as f64;
    if distribution != Distribution::Ggx {
        // The weighted estimate can exceed 1 by a few parts in a thousand
        // where the lobe is a sliver (smooth and grazing); no single
        // scattering reflects more than comes in.
        n = n.max(a + b);
    }
    ((a / n) as f32, (b / n) as f32)
}

fn tables(distribution: Distribution) -> &'static Tables {
    static T: [OnceLock<Tables>; Distribution::ALL.len()] =
        [const { OnceLock::new() }; Distribution::ALL.len()];
    T[distribution as usize].get_or_init(|| {
        let mut a = vec![0.0; N * N];
        let mut b = vec![0.0; N * N];
        for r in 0..N {
            for m in 0..N {
                let (ea, eb) = entry(distribution, mu_at(m), r as f32 / (N - 1) as f32);
                a[r * N + m] = ea;
                b[r * N + m] = eb;
            }
        }
        // 2 \int E mu dmu by the trapezoid rule over the columns.
        let avg = |t: &[f32], r: usize| {
            let mut s = 0.0f64;
            for m in 0..N - 1 {
                let (m0, m1) = (mu_at(m) as f64, mu_at(m + 1) as f64);
                let (e0, e1) = (t[r * N + m] as f64, t[r * N + m + 1] as f64);
                s += 0.5 * (e0 * m0 + e1 * m1) * (m1 - m0);
            }
            (2.0 * s) as f32
        };
        let a_avg = (0..N).map(|r| avg(&a, r)).collect();
        let b_avg = (0..N).map(|r| avg(&b, r)).collect();
        Tables { a, b, a_avg, b_avg }
    })
}

/// Grid position of `x` in `[0, 1]`: the lower index and the fraction.
#[inline]
fn cell(x: f32) -> (usize, f32) {
    let x = x.clamp(0.0, 1.0) * (N - 1) as f32;
    let i = (x.floor() as usize).min(N - 2);
    (i, x - i as f32)
}

/// `(A, B)` at cosine `mu` and perceptual roughness `roughness`
/// (bilinear in the table).
#[inline]
pub fn ab(distribution: Distribution, mu: f32, roughness: f32) -> (f32, f32) {
    let t = tables(distribution);
    let (r, fr) = cell(roughness);
    let (m, fm) = cell(mu);
    let at = |v: &[f32]| {
        let lo = v[r * N + m] * (1.0 - fm) + v[r * N + m + 1] * fm;
        let hi = v[(r + 1) * N + m] * (1.0 - fm) + v[(r + 1) * N + m + 1] * fm;
        lo * (1.0 - fr) + hi * fr
    };
    (at(&t.a), at(&t.b))
}

/// The hemispherical averages `(A_avg, B_avg)` at `roughness`.
#[inline]
pub fn ab_avg(distribution: Distribution, roughness: f32) -> (f32, f32) {
    let t = tables(distribution);
    let (r, fr) = cell(roughness);
    let at = |v: &[f32]| v[r] * (1.0 - fr) + v[r + 1] * fr;
    (at(&t.a_avg), at(&t.b_avg))
}

/// Directional albedo of a microfacet reflection with Schlick's Fresnel
/// `(f0, f90)` at cosine `mu`.
#[inline]
pub fn schlick(distribution: Distribution, f0: Vec3, f90: Vec3, mu: f32, roughness: f32) -> Vec3 {
    let (a, b) = ab(distribution, mu, roughness);
    f0 * a + f90 * b
}

/// Its hemispherical average.
#[inline]
pub fn schlick_avg(distribution: Distribution, f0: Vec3, f90: Vec3, roughness: f32) -> Vec3 {
    let (a, b) = ab_avg(distribution, roughness);
    f0 * a + f90 * b
}

/// Hemispherical average of Schlick's Fresnel term itself:
/// `2 \int F mu dmu = f0 + (1 - f0) / 21`.
#[inline]
pub fn schlick_fresnel_avg(f0: Vec3) -> Vec3 {
    f0 + (Vec3::ONE - f0) / 21.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_and_perfect_limits() {
        for d in Distribution::ALL {
            // A smooth surface reflects exactly Schlick's F.
            for mu in [0.1f32, 0.5, 1.0] {
                let (a, b) = ab(d, mu, 0.0);
                let s = (1.0 - mu).powi(5);
                assert!(
                    (a - (1.0 - s)).abs() < 2e-2 && (b - s).abs() < 2e-2,
                    "{d:?} {mu}"
                );
            }
            // F = 1 loses energy to single scattering as roughness grows,
            // and never exceeds 1.
            let e = |mu, r| {
                let (a, b) = ab(d, mu, r);
                a + b
            };
            assert!(e(0.8, 0.05) > 0.99, "{d:?}");
            assert!(e(0.8, 1.0) < e(0.8, 0.5), "{d:?}");
            for r in 0..N {
                for m in 0..N {
                    let (a, b) = ab(d, mu_at(m), r as f32 / (N - 1) as f32);
                    assert!(
                        a >= 0.0 && b >= 0.0 && a + b <= 1.0 + 1e-4,
                        "{d:?} r {r} m {m}: {}",
                        a + b
                    );
                }
            }
            // The average of a smooth surface's F = 1 lobe is 1.
            let (a, b) = ab_avg(d, 0.0);
            assert!((a + b - 1.0).abs() < 1e-2, "{d:?} {}", a + b);
        }
    }

    #[test]
    fn beckmann_keeps_more_energy_than_ggx_when_rough() {
        // Beckmann's short tails mask less at grazing angles than GGX's
        // long ones at the same alpha (Heitz 2014, figure 8).
        let e = |d, mu, r| {
            let (a, b) = ab(d, mu, r);
            a + b
        };
        for mu in [0.2f32, 0.5] {
            assert!(e(Distribution::Beckmann, mu, 0.8) > e(Distribution::Ggx, mu, 0.8));
        }
    }
}
