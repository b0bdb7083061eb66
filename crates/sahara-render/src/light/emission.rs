//! Light leaving the lights: a point and a direction drawn from each kind
//! of light, with the densities of both, for the light subpaths of
//! bidirectional path tracing (and the densities alone, for its multiple
//! importance sampling weights).
//!
//! Positions are densities per unit area (1 for point and spot lights,
//! which have one position); directions are densities per unit solid
//! angle. Lights at infinity (the environment and directional lights)
//! send their light through a disc of the scene's bounding radius facing
//! the direction, as pbrt does: the position density is then per unit area
//! of that disc.
//!
//! Here are the surfaces (their points drawn by `AreaLight::surface_point`,
//! as next-event estimation draws them) and the environment; a point, spot
//! or directional light's own emission is in its module, through
//! `Light::emission`.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

use super::LightSource;
use crate::math::warp::{concentric_disc, cosine_hemisphere, Frame};

/// Light leaving a light: where, where to, how much, and how likely.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Emission {
    /// The origin: a point on the light, or on the disc in front of a
    /// light at infinity.
    pub p: Vec3,
    /// Unit normal of an emitting surface at `p`, on the side the light
    /// leaves (zero for point and spot lights and lights at infinity).
    pub n: Vec3,
    /// Unit direction the light travels.
    pub dir: Vec3,
    /// Radiance (surfaces, the environment), intensity (point and spot
    /// lights) or irradiance (directional lights) along `dir`.
    pub le: Vec3,
    /// Density of `p` (per unit area; 1 for point and spot lights).
    pub pdf_pos: f32,
    /// Density of `dir` (per unit solid angle; 1 for directional lights).
    pub pdf_dir: f32,
    /// Whether the surface emits from both faces.
    pub two_sided: bool,
}

/// Direction density of a surface emitting by the cosine towards `dir`,
/// `cos` being the cosine to its front normal.
#[inline]
pub(crate) fn surface_pdf_dir(cos: f32, two_sided: bool) -> f32 {
    if two_sided {
        cos.abs() / (2.0 * PI)
    } else {
        cos.max(0.0) / PI
    }
}

/// The uniform number `u` split in two: which face (false: the front) and
/// a fresh uniform number for the direction.
#[inline]
fn face(u: f32, two_sided: bool) -> (bool, f32) {
    if !two_sided {
        return (false, u);
    }
    if u < 0.5 {
        (false, 2.0 * u)
    } else {
        (true, (2.0 * u - 1.0).min(1.0 - f32::EPSILON))
    }
}

impl LightSource {
    /// True for the lights at infinity (environment, directional).
    pub(crate) fn is_infinite(&self) -> bool {
        match self {
            LightSource::Environment(_) => true,
            LightSource::Explicit(light) => light.is_infinite(),
            LightSource::Area(_) => false,
        }
    }

    /// Light leaving this light: position from `u_pos`, direction from
    /// `u_dir`; lights at infinity aim at the sphere of `center` and
    /// `radius` around the scene. `None` when nothing leaves.
    pub(crate) fn sample_emission(
        &self,
        u_pos: Vec2,
        u_dir: Vec2,
        center: Vec3,
        radius: f32,
    ) -> Option<Emission> {
        // A point on the disc of the scene's radius facing `dir`, one
        // radius upstream of the centre.
        let disc = |dir: Vec3| {
            let f = Frame::from_normal(dir);
            let d = concentric_disc(u_pos) * radius;
            center + f.s * d.x + f.t * d.y - dir * radius
        };
        let e = match self {
            LightSource::Explicit(light) => light.emission(u_dir, disc, radius),
            LightSource::Environment(env) => {
                let s = env.sample(u_dir)?;
                let dir = -s.wi;
                Emission {
                    p: disc(dir),
                    n: Vec3::ZERO,
                    dir,
                    le: s.li,
                    pdf_pos: 1.0 / (PI * radius * radius),
                    pdf_dir: s.pdf,
                    two_sided: false,
                }
            }
            LightSource::Area(a) => {
                let s = a.surface_point(u_pos);
                let (p, n, le, two_sided) = (s.p, s.n, a.radiance_at(&s), s.two_sided);
                let (back, ux) = face(u_dir.x, two_sided);
                let local = cosine_hemisphere(Vec2::new(ux, u_dir.y));
                let front = if back { -n } else { n };
                let dir = Frame::from_normal(front).to_world(local);
                Emission {
                    p,
                    n: front,
                    dir,
                    le,
                    pdf_pos: 1.0 / a.area,
                    pdf_dir: surface_pdf_dir(local.z, two_sided),
                    two_sided,
                }
            }
        };
        (e.le.max_element() > 0.0 && e.pdf_dir > 0.0 && e.pdf_pos > 0.0 && e.pdf_pos.is_finite())
            .then_some(e)
    }

    /// Density of a finite light's direction `dir` leaving its point of
    /// front normal `n` (zero for point and spot lights), `two_sided` for
    /// surfaces.
    pub(crate) fn pdf_dir(&self, n: Vec3, dir: Vec3, two_sided: bool) -> f32 {
        match self {
            LightSource::Explicit(light) => light.pdf_dir(dir),
            LightSource::Area(_) => surface_pdf_dir(n.dot(dir), two_sided),
            // Lights at infinity: see `pdf_disc`.
            LightSource::Environment(_) => 0.0,
        }
    }

    /// Density of the light's origin (without the light's choice): per
    /// unit area on a surface, 1 for point, spot and directional lights,
    /// and for the environment the solid-angle density of the direction
    /// `towards` it.
    pub(crate) fn pdf_origin(&self, towards: Vec3) -> f32 {
        match self {
            LightSource::Area(a) => 1.0 / a.area,
            LightSource::Environment(e) => e.pdf(towards),
            LightSource::Explicit(_) => 1.0,
        }
    }
}

/// Density per unit area of the disc through which a light at infinity
/// sends its light into the scene of bounding `radius`.
#[inline]
pub(crate) fn pdf_disc(radius: f32) -> f32 {
    1.0 / (PI * radius * radius)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::area::Emitter;
    use crate::light::{AreaLight, Light};
    use crate::math::warp::uniform_sphere;

    /// Every light's sampled directions have the density `pdf_dir` gives,
    /// and integrate to one over the sphere (estimated by the sample mean
    /// of `1 / pdf` over a uniform sphere, i.e. the support's solid angle).
    #[test]
    fn emission_densities_match_the_sampling() {
        let quad = LightSource::Area(AreaLight::analytic(
            Emitter::Quad {
                corner: Vec3::ZERO,
                u: Vec3::X,
                v: Vec3::Z,
                n: Vec3::X.cross(Vec3::Z),
            },
            Vec3::ONE,
            true,
            0,
        ));
        let spot = LightSource::Explicit(Light::spot(Vec3::ZERO, Vec3::Y, Vec3::ONE, 20.0, 30.0));
        let point = LightSource::Explicit(Light::point(Vec3::ZERO, Vec3::ONE));
        for light in [quad, spot, point] {
            let n = 64;
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    let e = light
                        .sample_emission(u, Vec2::new(u.y, u.x), Vec3::ZERO, 1.0)
                        .unwrap();
                    let pdf = light.pdf_dir(e.n, e.dir, true);
                    assert!(
                        (pdf - e.pdf_dir).abs() <= 1e-4 * e.pdf_dir,
                        "{light:?}: {pdf} vs {}",
                        e.pdf_dir
                    );
                }
            }
            // Integral of the density over the sphere, by uniform sphere
            // samples: 4 pi mean(pdf).
            let mut sum = 0.0f64;
            let m = 512;
            for i in 0..m {
                for j in 0..m {
                    let u = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                    let w = uniform_sphere(u);
                    sum += light.pdf_dir(Vec3::new(0.0, -1.0, 0.0), w, true) as f64;
                }
            }
            let integral = 4.0 * std::f64::consts::PI * sum / (m * m) as f64;
            assert!((integral - 1.0).abs() < 0.01, "{light:?}: {integral}");
        }
    }
}
