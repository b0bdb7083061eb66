//! The Henyey-Greenstein phase function: how a medium redistributes the
//! light it scatters, by the angle between the directions of travel
//! before and after.

use glam::{Vec2, Vec3};

use crate::math::warp::Frame;

/// Henyey and Greenstein's phase function (1941) of asymmetry `g`: the
/// mean cosine of the scattering angle; 0 scatters alike in every
/// direction (isotropic), towards 1 forwards, towards -1 backwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    /// The asymmetry, in (-1, 1).
    pub g: f32,
}

/// Below this |g| the function is sampled as isotropic (the inversion
/// divides by g).
const ISOTROPIC: f32 = 1e-3;

impl HenyeyGreenstein {
    /// The phase function of asymmetry `g`.
    pub fn new(g: f32) -> Self {
        Self { g }
    }

    /// The density (per steradian, integrating to 1) of leaving along
    /// `w_out` for light travelling along `w_in` (both unit directions of
    /// travel): a function of their cosine alone.
    #[inline]
    pub fn eval(&self, w_in: Vec3, w_out: Vec3) -> f32 {
        hg(w_in.dot(w_out), self.g)
    }

    /// A direction of travel after scattering light travelling along
    /// `w_in`, drawn in proportion to [`HenyeyGreenstein::eval`] from `u`,
    /// and its density.
    #[inline]
    pub fn sample(&self, w_in: Vec3, u: Vec2) -> (Vec3, f32) {
        let g = self.g;
        let cos = if g.abs() < ISOTROPIC {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
            ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * u.y;
        let local = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
        let w = Frame::from_normal(w_in).to_world(local).normalize();
        (w, hg(cos, g))
    }
}

/// Henyey-Greenstein of the cosine between the directions of travel.
#[inline]
fn hg(cos: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * std::f32::consts::PI * denom * denom.max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density integrates to one, its mean cosine is g, and sampling
    /// draws in proportion to it (the sampled directions' mean cosine is g
    /// and each sample's density is the function's value).
    #[test]
    fn densities_integrate_to_one_and_samples_follow_them() {
        let w_in = Vec3::new(0.3, -0.5, 0.8).normalize();
        for g in [-0.7, -0.2, 0.0, 0.0005, 0.4, 0.9] {
            let p = HenyeyGreenstein::new(g);
            // The integral over the sphere by the cosine (the function has
            // rotational symmetry about w_in).
            let n = 200_000;
            let (mut total, mut mean_cos) = (0.0f64, 0.0f64);
            for i in 0..n {
                let cos = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let v = hg(cos as f32, g) as f64 * 2.0 * std::f64::consts::PI * (2.0 / n as f64);
                total += v;
                mean_cos += v * cos;
            }
            assert!((total - 1.0).abs() < 2e-3, "g {g}: {total}");
            assert!((mean_cos - g as f64).abs() < 2e-3, "g {g}: {mean_cos}");
            let m = 256;
            let mut sampled_cos = 0.0f64;
            for i in 0..m {
                for j in 0..m {
                    let u = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                    let (w, pdf) = p.sample(w_in, u);
                    assert!((w.length() - 1.0).abs() < 1e-4);
                    let want = p.eval(w_in, w);
                    assert!(
                        (pdf - want).abs() <= 1e-3 * want.max(1.0),
                        "g {g}: {pdf} {want}"
                    );
                    sampled_cos += w_in.dot(w) as f64;
                }
            }
            sampled_cos /= (m * m) as f64;
            assert!(
                (sampled_cos - g as f64).abs() < 5e-3,
                "g {g}: {sampled_cos}"
            );
        }
    }
}
