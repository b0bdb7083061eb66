//! Rays with a parametric interval.

use glam::Vec3;

/// A ray `o + t d` restricted to `t` in `(tmin, tmax]` (`tmin` exclusive, as Embree's `tnear`).
///
/// The direction need not be normalised; `t` is measured in units of `d`.
///
/// Laid out as eight `f32` (origin, direction, `tmin`, `tmax`), so that the
/// packet set-up can load eight rays as an 8x8 matrix and transpose it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (not necessarily unit length, must not be zero).
    pub dir: Vec3,
    /// Hits must lie beyond this distance (exclusive).
    pub tmin: f32,
    /// Largest accepted hit distance (may be `f32::INFINITY`).
    pub tmax: f32,
}

impl Ray {
    /// A ray over `(0, inf)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            tmin: 0.0,
            tmax: f32::INFINITY,
        }
    }

    /// A ray over `(tmin, tmax]`.
    pub fn with_interval(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Self {
        Self {
            origin,
            dir,
            tmin,
            tmax,
        }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// True when the ray can be traced: finite origin, finite non-zero
    /// direction, `tmin >= 0` and a `tmax` that is not NaN.
    ///
    /// As in Embree, a segment starting behind the origin is not a ray:
    /// traversal clips to the root box by slab distances measured from the
    /// origin, and a hit behind it (found by fuzzing: t = -0.5 at an edge of a
    /// ray with two zero direction components) would need the cells behind
    /// the origin ordered the other way round.
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.dir.is_finite()
            && self.dir != Vec3::ZERO
            && self.tmin >= 0.0
            && !self.tmax.is_nan()
    }
}
