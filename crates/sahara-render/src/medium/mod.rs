//! Participating media: what fills the space between surfaces (fog, smoke,
//! the inside of a translucent object).
//!
//! A medium is bounded by surfaces: an instance may carry a
//! [`MediumInterface`] naming the medium on each side of its surface, and
//! the camera may sit in one. Light travelling a distance `d` through a
//! medium keeps `exp(-σt d)` of itself per colour channel (σt = σa + σs,
//! the extinction: absorption plus out-scattering) and gains what the
//! medium scatters in from elsewhere, distributed by its phase function.
//!
//! Distances are sampled in proportion to the average of the channels'
//! densities `σt,c exp(-σt,c t)` (one channel chosen at random, then the
//! distance drawn from its exponential; the estimate divided by the
//! average density): spectral multiple importance sampling with the
//! balance heuristic over the three channels, so a coloured medium is
//! unbiased in every channel and no channel's noise explodes where
//! another's extinction dominates.
//!
//! A medium may also emit: at a point of absorption σa and emitted
//! radiance Le it adds `σa Le` per unit length (pbrt-v4's convention: a
//! medium glows as strongly as it absorbs, so a thick one approaches Le
//! and a thin one adds `σa Le d`). The free-flight sample estimates what a
//! segment emits towards its start along with where the path goes on.

mod cloud;
mod grid;
mod phase;

use glam::Vec3;

pub use cloud::CloudMedium;
pub use grid::{ColourGrid, ColourVolume, DensityGrid, GridCoefficients, GridMedium};
pub use phase::HenyeyGreenstein;

/// A participating medium.
#[derive(Clone, Debug, PartialEq)]
pub enum Medium {
    /// The same coefficients everywhere.
    Homogeneous(Homogeneous),
    /// Coefficients that vary over a grid: a density scaling fixed
    /// coefficients, or colours per voxel.
    Grid(Box<GridMedium>),
    /// Coefficients scaled by pbrt-v4's procedural noise cloud.
    Cloud(Box<CloudMedium>),
}

/// A medium whose coefficients are the same everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homogeneous {
    /// Absorption coefficient per unit length, per channel.
    pub sigma_a: Vec3,
    /// Scattering coefficient per unit length, per channel.
    pub sigma_s: Vec3,
    /// How scattered light leaves.
    pub phase: HenyeyGreenstein,
    /// Radiance emitted per unit of absorption, per channel (the medium
    /// adds `sigma_a * emission` per unit length); zero for most media.
    pub emission: Vec3,
}

/// The media on the two sides of a surface, by index into
/// [`crate::Scene::media`] (`None`: vacuum).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumInterface {
    /// The medium behind the surface (against its winding-order normal
    /// `(v1 - v0) x (v2 - v0)`: inside a closed mesh wound outwards).
    pub inside: Option<u32>,
    /// The medium in front of the surface.
    pub outside: Option<u32>,
    /// The surface only bounds the media: light passes it unbent and
    /// unscattered, whatever its material (an index-matched boundary,
    /// pbrt's `interface` material, a Mitsuba shape without a BSDF).
    pub index_matched: bool,
}

impl MediumInterface {
    /// The medium a ray leaving the surface along `dir` travels in, for a
    /// surface of geometric normal `ng`.
    #[inline]
    pub fn medium_along(&self, ng: Vec3, dir: Vec3) -> Option<u32> {
        if dir.dot(ng) < 0.0 {
            self.inside
        } else {
            self.outside
        }
    }
}

/// Where a distance sampled along a ray through a medium falls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FreeFlight {
    /// The distance to the scattering event, or the segment's end.
    pub t: f32,
    /// True if the ray scatters at `t` (inside the segment).
    pub scattered: bool,
    /// The throughput's factor: transmittance times `σs` over the
    /// sampling density for a scattering event, transmittance over the
    /// probability of passing for the segment's end.
    pub weight: Vec3,
    /// The light the medium emits along the segment towards its start,
    /// estimated with the same samples (zero in a medium that does not
    /// emit): to be added with the throughput before `weight`.
    pub emitted: Vec3,
}

/// Spectral tracking's choice at a tentative collision of a walk at
/// majorant `m` (Kutz et al. 2017): real (the path scatters) or null,
/// with probabilities in proportion to the channels' summed scattering
/// `sigma_s` and null coefficients `sigma_n` (negative parts left out of
/// the choice), the throughput `weight` multiplied by each channel's
/// coefficient over `m` times the probability. True if the collision is
/// null and the walk goes on; false if it scattered, or was absorbed for
/// certain (the weight then zero).
#[inline]
pub(crate) fn null_collision(
    weight: &mut Vec3,
    sigma_s: Vec3,
    sigma_n: Vec3,
    m: f32,
    draw: &mut dyn FnMut() -> f32,
) -> bool {
    let (ps, pn) = (sigma_s.element_sum(), sigma_n.max(Vec3::ZERO).element_sum());
    if ps + pn <= 0.0 {
        *weight = Vec3::ZERO;
        return false;
    }
    let p_scatter = ps / (ps + pn);
    if draw() < p_scatter {
        *weight *= sigma_s / (m * p_scatter);
        return false;
    }
    *weight *= sigma_n / (m * (1.0 - p_scatter));
    true
}

impl Medium {
    /// A homogeneous medium of absorption `sigma_a` and scattering
    /// `sigma_s` (per unit length) with a Henyey-Greenstein phase function
    /// of asymmetry `g`.
    pub fn homogeneous(sigma_a: Vec3, sigma_s: Vec3, g: f32) -> Self {
        Medium::Homogeneous(Homogeneous {
            sigma_a,
            sigma_s,
            phase: HenyeyGreenstein::new(g),
            emission: Vec3::ZERO,
        })
    }

    /// The medium emitting radiance `le` per unit of absorption (it adds
    /// `σa le` per unit length, where σa is the local absorption); for a
    /// grid, times its emission scale at each point. A noise cloud does not
    /// emit (pbrt-v4's has no emission either) and stays as it is.
    pub fn with_emission(mut self, le: Vec3) -> Self {
        match &mut self {
            Medium::Homogeneous(h) => h.emission = le,
            Medium::Grid(m) => m.emission = le,
            Medium::Cloud(_) => debug_assert_eq!(le, Vec3::ZERO, "a noise cloud does not emit"),
        }
        self
    }

    /// The radiance the medium emits per unit of absorption, before any
    /// per-point scale (zero if it does not emit).
    pub fn emission(&self) -> Vec3 {
        match self {
            Medium::Homogeneous(h) => h.emission,
            Medium::Grid(m) => m.emission,
            Medium::Cloud(_) => Vec3::ZERO,
        }
    }

    /// Why the medium cannot be rendered (negative or non-finite
    /// coefficients, an asymmetry outside (-1, 1), a cloud's non-finite
    /// shape parameters), in one line; `None` if it can.
    pub fn problem(&self) -> Option<String> {
        if let Medium::Cloud(c) = self {
            let shape = [c.density, c.wispiness, c.frequency];
            if shape.iter().any(|v| !v.is_finite()) {
                return Some(format!(
                    "cloud density {}, wispiness {} and frequency {} must be finite",
                    c.density, c.wispiness, c.frequency
                ));
            }
        }
        let (sigma_a, sigma_s, g) = match self {
            Medium::Homogeneous(h) => (h.sigma_a, h.sigma_s, h.phase.g),
            Medium::Grid(m) => {
                if let Some(problem) = m.problem() {
                    return Some(problem);
                }
                (Vec3::ZERO, Vec3::ZERO, m.phase.g)
            }
            Medium::Cloud(m) => (m.sigma_a, m.sigma_s, m.phase.g),
        };
        let emission = self.emission();
        let bad = |v: Vec3| !v.is_finite() || v.min_element() < 0.0;
        if bad(sigma_a) {
            Some(format!(
                "absorption {sigma_a} must be finite and not negative"
            ))
        } else if bad(sigma_s) {
            Some(format!(
                "scattering {sigma_s} must be finite and not negative"
            ))
        } else if bad(emission) {
            Some(format!(
                "emission {emission} must be finite and not negative"
            ))
        } else if !(g > -1.0 && g < 1.0) {
            Some(format!("phase asymmetry g = {g} must lie in (-1, 1)"))
        } else {
            None
        }
    }

    /// The single-scattering albedo at world point `p`: the fraction of
    /// the light a collision takes that it scatters, σs / (σa + σs), per
    /// channel (0 where the medium neither absorbs nor scatters).
    pub fn albedo(&self, p: Vec3) -> Vec3 {
        let (sigma_a, sigma_s) = match self {
            Medium::Homogeneous(h) => (h.sigma_a, h.sigma_s),
            Medium::Grid(m) => return m.albedo(p),
            // A density scales σa and σs alike.
            Medium::Cloud(m) => (m.sigma_a, m.sigma_s),
        };
        let sigma_t = sigma_a + sigma_s;
        Vec3::select(sigma_t.cmpgt(Vec3::ZERO), sigma_s / sigma_t, Vec3::ZERO)
    }

    /// The phase function.
    #[inline]
    pub fn phase(&self) -> HenyeyGreenstein {
        match self {
            Medium::Homogeneous(h) => h.phase,
            Medium::Grid(m) => m.phase,
            Medium::Cloud(m) => m.phase,
        }
    }

    /// The fraction of light that crosses the segment `origin + t dir`,
    /// `t` in `[0, d]` (`dir` a unit vector; `d` infinite for a ray that
    /// meets nothing): exact in a homogeneous medium, estimated by ratio
    /// tracking with numbers from `draw` in a grid.
    #[inline]
    pub fn transmittance(
        &self,
        origin: Vec3,
        dir: Vec3,
        d: f32,
        draw: &mut dyn FnMut() -> f32,
    ) -> Vec3 {
        match self {
            Medium::Homogeneous(h) => exp_neg(h.sigma_a + h.sigma_s, d),
            Medium::Grid(m) => m.transmittance(origin, dir, d, draw),
            Medium::Cloud(m) => m.transmittance(origin, dir, d, draw),
        }
    }

    /// Where the medium scatters a ray `origin + t dir` that would reach
    /// a surface at `t_max` (infinite if none), with numbers from `draw`.
    #[inline]
    pub(crate) fn free_flight(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        draw: &mut dyn FnMut() -> f32,
    ) -> FreeFlight {
        match self {
            Medium::Homogeneous(h) => {
                let u_channel = draw();
                h.free_flight(u_channel, draw(), t_max)
            }
            Medium::Grid(m) => m.free_flight(origin, dir, t_max, draw),
            Medium::Cloud(m) => m.free_flight(origin, dir, t_max, draw),
        }
    }
}

impl Homogeneous {
    /// A scattering distance along a segment of length `t_max`, from
    /// `u_channel` (which channel's density to draw from) and `u` (the
    /// distance).
    #[inline]
    fn free_flight(&self, u_channel: f32, u: f32, t_max: f32) -> FreeFlight {
        let h = self;
        let sigma_t = h.sigma_a + h.sigma_s;
        let c = ((u_channel * 3.0) as usize).min(2);
        let s = sigma_t[c];
        let t = if s > 0.0 {
            -(1.0 - u).ln() / s
        } else {
            f32::INFINITY
        };
        if t < t_max {
            let tr = exp_neg(sigma_t, t);
            let density = (sigma_t * tr).element_sum() / 3.0;
            if density > 0.0 {
                // The emission's integral `∫ Tr σa Le` over the segment,
                // estimated at the same sampled distance: where this
                // density is zero, so is σa.
                FreeFlight {
                    t,
                    scattered: true,
                    weight: h.sigma_s * tr / density,
                    emitted: h.sigma_a * h.emission * tr / density,
                }
            } else {
                FreeFlight {
                    t,
                    scattered: true,
                    weight: Vec3::ZERO,
                    emitted: Vec3::ZERO,
                }
            }
        } else {
            let tr = exp_neg(sigma_t, t_max);
            let pass = tr.element_sum() / 3.0;
            FreeFlight {
                t: t_max,
                scattered: false,
                weight: if pass > 0.0 { tr / pass } else { Vec3::ZERO },
                emitted: Vec3::ZERO,
            }
        }
    }
}

/// `exp(-sigma d)` per channel, with a channel of zero extinction keeping
/// everything even over an infinite distance.
#[inline]
fn exp_neg(sigma: Vec3, d: f32) -> Vec3 {
    Vec3::from_array(
        sigma
            .to_array()
            .map(|s| if s > 0.0 { (-s * d).exp() } else { 1.0 }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fog() -> Medium {
        Medium::homogeneous(Vec3::new(0.1, 0.5, 1.0), Vec3::new(0.9, 0.5, 0.2), 0.3)
    }

    #[test]
    fn transmittance_is_exponential_per_channel() {
        let m = fog();
        let tr = |m: &Medium, d: f32| m.transmittance(Vec3::ZERO, Vec3::X, d, &mut || 0.5);
        let tr_2 = tr(&m, 2.0);
        let want = Vec3::new((-2.0f32).exp(), (-2.0f32).exp(), (-2.4f32).exp());
        assert!((tr_2 - want).abs().max_element() < 1e-6, "{tr_2} {want}");
        assert_eq!(tr(&m, f32::INFINITY), Vec3::ZERO);
        let clear = Medium::homogeneous(Vec3::new(0.0, 1.0, 1.0), Vec3::ZERO, 0.0);
        assert_eq!(tr(&clear, f32::INFINITY), Vec3::new(1.0, 0.0, 0.0));
    }

    /// The free-flight estimator's mean over a segment is what reaches its
    /// end (the pass branch) plus what scatters inside (the scatter branch,
    /// whose weights average the single-scattering integral
    /// `σs (1 - exp(-σt d)) / σt`), per channel.
    #[test]
    fn free_flight_is_unbiased_per_channel() {
        let m = fog();
        let Medium::Homogeneous(h) = m else {
            unreachable!()
        };
        let sigma_t = h.sigma_a + h.sigma_s;
        let d = 1.7;
        let n = 400_000;
        let (mut pass, mut scatter) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            // Stratified in the distance, every channel in turn.
            let f = h.free_flight((i % 3) as f32 / 3.0 + 0.1, u, d);
            if f.scattered {
                assert!(f.t < d);
                scatter += f.weight;
            } else {
                assert_eq!(f.t, d);
                pass += f.weight;
            }
        }
        let (pass, scatter) = (pass / n as f32, scatter / n as f32);
        let want_pass = m.transmittance(Vec3::ZERO, Vec3::X, d, &mut || 0.5);
        let want_scatter = h.sigma_s * (Vec3::ONE - want_pass) / sigma_t;
        assert!(
            (pass - want_pass).abs().max_element() < 2e-3,
            "{pass} {want_pass}"
        );
        assert!(
            (scatter - want_scatter).abs().max_element() < 2e-3,
            "{scatter} {want_scatter}"
        );
    }

    #[test]
    fn bad_coefficients_are_named() {
        let m = Medium::homogeneous(Vec3::new(-1.0, 0.0, 0.0), Vec3::ONE, 0.0);
        assert!(m.problem().unwrap().contains("absorption"));
        let m = Medium::homogeneous(Vec3::ONE, Vec3::splat(f32::NAN), 0.0);
        assert!(m.problem().unwrap().contains("scattering"));
        let m = Medium::homogeneous(Vec3::ONE, Vec3::ONE, 1.0);
        assert!(m.problem().unwrap().contains("asymmetry"));
        assert_eq!(fog().problem(), None);
    }

    #[test]
    fn the_side_decides_the_medium() {
        let mi = MediumInterface {
            inside: Some(0),
            outside: None,
            index_matched: true,
        };
        assert_eq!(mi.medium_along(Vec3::Z, -Vec3::Z), Some(0));
        assert_eq!(mi.medium_along(Vec3::Z, Vec3::Z), None);
    }
}
