//! Light from infinitely far away: a constant colour or an
//! equirectangular map, importance sampled.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use super::LightSample;
use crate::math::piecewise::Distribution2D;
use crate::math::warp::{luminance, uniform_sphere};
use crate::texture::Texture;

/// The scene's surroundings.
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// The same radiance from every direction.
    Constant(Vec3),
    /// An equirectangular (latitude-longitude) radiance map times `scale`.
    ///
    /// Mapping (Y up): row 0 is the zenith +Y, the last row the nadir;
    /// `u = phi / 2 pi` with `phi = atan2(z, x)` in `[0, 2 pi)`, so the
    /// left edge looks towards +X and the quarter towards +Z. Looked up
    /// per texel (piecewise constant, which the importance sampling matches
    /// exactly).
    Map {
        /// The map.
        texture: Arc<Texture>,
        /// Radiance multiplier.
        scale: f32,
    },
}

/// Direction of equirectangular coordinates `(u, v)`, and `sin(theta)`.
#[inline]
pub fn direction(uv: Vec2) -> (Vec3, f32) {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * uv.x;
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    (Vec3::new(st * cp, ct, st * sp), st)
}

/// Equirectangular coordinates of a unit direction.
#[inline]
pub fn coordinates(w: Vec3) -> Vec2 {
    let theta = w.y.clamp(-1.0, 1.0).acos();
    let mut phi = w.z.atan2(w.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    Vec2::new(
        (phi / (2.0 * PI)).min(1.0 - f32::EPSILON),
        (theta / PI).min(1.0 - f32::EPSILON),
    )
}

/// `sin(theta)` at the centre of texel row `y` of `h`: the area of the
/// row's patch of sphere, relative.
fn row_sin(y: usize, h: usize) -> f32 {
    (PI * (y as f32 + 0.5) / h as f32).sin()
}

/// The MIS-compensated distribution of a map of luminances `lum` (`w` by
/// `h`, solid-angle mean `mean`): each texel's excess over the mean, by its
/// patch's area; `None` when no texel exceeds the mean (a constant map).
fn compensated(lum: &[f32], mean: f32, w: usize, h: usize) -> Option<Distribution2D> {
    let f: Vec<f32> = lum
        .iter()
        .enumerate()
        .map(|(i, &l)| (l - mean).max(0.0) * row_sin(i / w, h))
        .collect();
    f.iter()
        .any(|&v| v > 0.0)
        .then(|| Distribution2D::new(&f, w, h))
}

/// A direction drawn from `dist` over the map's (u, v) (uniform on the
/// sphere without one) and its solid-angle density.
fn sample_of(dist: Option<&Distribution2D>, u: Vec2) -> Option<(Vec3, f32)> {
    match dist {
        None => Some((uniform_sphere(u), 1.0 / (4.0 * PI))),
        Some(d) => {
            let (uv, pdf_uv) = d.sample(u);
            let (w, st) = direction(uv);
            if st <= 0.0 || pdf_uv <= 0.0 {
                return None;
            }
            // Jacobian of (u, v) -> sphere: 2 pi^2 sin(theta).
            Some((w, pdf_uv / (2.0 * PI * PI * st)))
        }
    }
}

/// Solid-angle density of [`sample_of`] for direction `w`.
fn pdf_of(dist: Option<&Distribution2D>, w: Vec3) -> f32 {
    match dist {
        None => 1.0 / (4.0 * PI),
        Some(d) => {
            let uv = coordinates(w);
            let st = (PI * uv.y).sin();
            if st <= 0.0 {
                return 0.0;
            }
            d.pdf(uv) / (2.0 * PI * PI * st)
        }
    }
}

/// The environment prepared for sampling.
#[derive(Clone, Debug)]
pub struct EnvLight {
    env: Environment,
    dist: Option<Distribution2D>,
    /// The distribution for light sampling that multiple importance
    /// sampling pairs with BSDF sampling: texels brighter than the mean,
    /// by how much (`None`: the map is constant, or none is brighter).
    compensated: Option<Distribution2D>,
    mean: f32,
}

impl EnvLight {
    /// Builds the sampling distribution: texel luminance times
    /// `sin(theta)` of the texel row's centre (the area of the row's patch
    /// of sphere).
    pub fn new(env: &Environment) -> Self {
        match env {
            Environment::Constant(c) => Self {
                env: env.clone(),
                dist: None,
                compensated: None,
                mean: luminance(*c),
            },
            Environment::Map { texture, scale } => {
                let (w, h) = (texture.width as usize, texture.height as usize);
                let mut lum = Vec::with_capacity(w * h);
                let mut f = Vec::with_capacity(w * h);
                let mut total = 0.0f64;
                let mut weight = 0.0f64;
                for y in 0..h {
                    let st = row_sin(y, h);
                    for x in 0..w {
                        let l = luminance(texture.texel(x as i64, y as i64) * *scale).max(0.0);
                        lum.push(l);
                        f.push(l * st);
                        total += (l * st) as f64;
                        weight += st as f64;
                    }
                }
                let mean = (total / weight.max(1e-30)) as f32;
                Self {
                    env: env.clone(),
                    dist: Some(Distribution2D::new(&f, w, h)),
                    compensated: compensated(&lum, mean, w, h),
                    mean,
                }
            }
        }
    }

    /// Radiance arriving from direction `w` (unit; the direction a ray
    /// travels to meet the environment).
    #[inline]
    pub fn radiance(&self, w: Vec3) -> Vec3 {
        match &self.env {
            Environment::Constant(c) => *c,
            Environment::Map { texture, scale } => {
                let uv = coordinates(w);
                let x = (uv.x * texture.width as f32) as i64;
                let y = (uv.y * texture.height as f32) as i64;
                texture.texel(x, y) * *scale
            }
        }
    }

    /// A direction and the radiance from it.
    pub fn sample(&self, u: Vec2) -> Option<LightSample> {
        sample_of(self.dist.as_ref(), u).map(|(wi, pdf)| self.light_sample(wi, pdf))
    }

    /// The sample of direction `wi` drawn with solid-angle density `pdf`.
    fn light_sample(&self, wi: Vec3, pdf: f32) -> LightSample {
        LightSample {
            wi,
            dist: f32::INFINITY,
            li: self.radiance(wi),
            pdf,
            delta: false,
            ignore: None,
            n: Vec3::ZERO,
            two_sided: false,
        }
    }

    /// Solid-angle density of [`EnvLight::sample`] for direction `w`.
    pub fn pdf(&self, w: Vec3) -> f32 {
        pdf_of(self.dist.as_ref(), w)
    }

    /// A direction and the radiance from it, for light sampling that
    /// multiple importance sampling pairs with BSDF sampling: MIS
    /// compensation (Karlik et al. 2019) samples only the texels brighter
    /// than the map's mean, in proportion to the excess, and leaves the
    /// rest of the sphere to the BSDF's samples, which find the dim, broad
    /// part of the sky well; both estimators stay unbiased together, as
    /// every direction has one technique of non-zero density. Only for
    /// estimators that also trace BSDF samples to the environment and
    /// weigh both with [`EnvLight::pdf_mis`].
    pub fn sample_mis(&self, u: Vec2) -> Option<LightSample> {
        match &self.compensated {
            Some(d) => sample_of(Some(d), u).map(|(wi, pdf)| self.light_sample(wi, pdf)),
            None => self.sample(u),
        }
    }

    /// Solid-angle density of [`EnvLight::sample_mis`] for direction `w`.
    pub fn pdf_mis(&self, w: Vec3) -> f32 {
        match &self.compensated {
            Some(d) => pdf_of(Some(d), w),
            None => self.pdf(w),
        }
    }

    /// Power through a disc of the scene's radius: pi r^2 times the
    /// irradiance of the mean radiance, pi L.
    pub fn power(&self, scene_radius: f32) -> f32 {
        PI * scene_radius * scene_radius * PI * self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::hash::{hash3, unit_f32};

    #[test]
    fn coordinates_invert_direction() {
        for uv in [
            Vec2::new(0.1, 0.2),
            Vec2::new(0.7, 0.9),
            Vec2::new(0.5, 0.5),
        ] {
            let (w, _) = direction(uv);
            assert!((coordinates(w) - uv).length() < 1e-4);
        }
        assert!(direction(Vec2::new(0.3, 0.0)).0.y > 0.999);
    }

    /// The integral over the sphere of a piecewise-constant map's red
    /// channel (`w` by `h` texels), by quadrature: each texel's value times
    /// its patch's solid angle, the integral of sin(theta) over its row.
    fn integral(texels: &[Vec3], w: u32, h: u32) -> f64 {
        let mut sum = 0.0f64;
        for y in 0..h {
            let (t0, t1) = (PI * y as f32 / h as f32, PI * (y + 1) as f32 / h as f32);
            let band = (t0.cos() - t1.cos()) as f64;
            for x in 0..w {
                sum += texels[(y * w + x) as usize].x as f64 * band * (2.0 * PI / w as f32) as f64;
            }
        }
        sum
    }

    #[test]
    fn map_sampling_is_unbiased() {
        // A map with a bright patch: the mean of L / pdf over samples must
        // equal the integral of L over the sphere, computed here by
        // quadrature over the texels (exact for a piecewise-constant map up
        // to the sin(theta) integral, done finely).
        let (w, h) = (16u32, 8u32);
        let texels: Vec<Vec3> = (0..w * h)
            .map(|i| {
                if i % w < 3 && i / w == 2 {
                    Vec3::splat(50.0)
                } else {
                    Vec3::splat(0.2)
                }
            })
            .collect();
        let env = Environment::Map {
            texture: Arc::new(Texture::new(w, h, texels.clone())),
            scale: 1.0,
        };
        let light = EnvLight::new(&env);
        let exact = integral(&texels, w, h);
        let n = 200_000u64;
        let mut est = 0.0f64;
        let mut mismatches = 0;
        for i in 0..n {
            let u = Vec2::new(unit_f32(hash3(1, i, 0)), unit_f32(hash3(1, i, 1)));
            if let Some(s) = light.sample(u) {
                // The round trip through the direction may land in the
                // neighbouring texel when the sample lies on a border.
                if (light.pdf(s.wi) - s.pdf).abs() > 1e-3 * s.pdf {
                    mismatches += 1;
                }
                est += (s.li.x / s.pdf) as f64;
            }
        }
        assert!(mismatches < n / 1000, "{mismatches} pdf mismatches");
        est /= n as f64;
        assert!((est / exact - 1.0).abs() < 0.01, "{est} vs {exact}");
    }

    /// MIS compensation: one light sample from the compensated map and one
    /// uniform sample of the sphere (standing in for a BSDF's), weighted by
    /// the power heuristic, estimate the map's integral without bias; the
    /// compensated samples land only on texels brighter than the mean, and
    /// their density is what `pdf_mis` says.
    #[test]
    fn compensated_sampling_with_mis_is_unbiased() {
        let (w, h) = (32u32, 16u32);
        let texels: Vec<Vec3> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (5..7).contains(&x) && y == 4 {
                    Vec3::splat(80.0)
                } else {
                    Vec3::splat(0.1 + 0.4 * y as f32 / h as f32)
                }
            })
            .collect();
        let env = Environment::Map {
            texture: Arc::new(Texture::new(w, h, texels.clone())),
            scale: 1.0,
        };
        let light = EnvLight::new(&env);
        assert!(light.compensated.is_some());
        let exact = integral(&texels, w, h);
        let power = |a: f32, b: f32| a * a / (a * a + b * b);
        let n = 400_000u64;
        let (mut est, mut mismatches, mut dim) = (0.0f64, 0, 0);
        for i in 0..n {
            let u = Vec2::new(unit_f32(hash3(2, i, 0)), unit_f32(hash3(2, i, 1)));
            if let Some(s) = light.sample_mis(u) {
                if (light.pdf_mis(s.wi) - s.pdf).abs() > 1e-3 * s.pdf {
                    mismatches += 1;
                }
                if s.li.x < light.mean {
                    dim += 1;
                }
                let other = 1.0 / (4.0 * PI);
                est += (s.li.x * power(s.pdf, other) / s.pdf) as f64;
            }
            let v = Vec2::new(unit_f32(hash3(3, i, 0)), unit_f32(hash3(3, i, 1)));
            let wi = uniform_sphere(v);
            let pdf = 1.0 / (4.0 * PI);
            est += (light.radiance(wi).x * power(pdf, light.pdf_mis(wi)) / pdf) as f64;
        }
        assert!(mismatches < n / 1000, "{mismatches} pdf mismatches");
        assert!(dim < n / 1000, "{dim} samples on texels below the mean");
        est /= n as f64;
        assert!((est / exact - 1.0).abs() < 0.01, "{est} vs {exact}");
    }
}
