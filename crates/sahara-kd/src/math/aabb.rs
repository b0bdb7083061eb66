//! Axis-aligned bounding boxes.

use glam::Vec3;

use super::slack::FAR_GROW;

/// An axis-aligned box `[min, max]` (closed). An empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// A box from two corners, in any order.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box around the given points.
    pub fn from_points<I: IntoIterator<Item = Vec3>>(points: I) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grow(p))
    }

    /// True if the box contains no point.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// The box grown to contain `p`.
    pub fn grow(self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box containing both.
    pub fn union(self, o: Aabb) -> Self {
        Self {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The intersection of both boxes (possibly empty).
    pub fn intersection(self, o: Aabb) -> Self {
        Self {
            min: self.min.max(o.min),
            max: self.max.min(o.max),
        }
    }

    /// Edge lengths.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// The centre point.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Surface area (0 for an empty box), computed in f64 so that the SAH of
    /// very flat or very large cells does not lose its digits.
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent().as_dvec3();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The axis (0, 1, 2) of the largest extent.
    pub fn largest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// True if `p` lies in the closed box.
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The two halves of the box cut by the plane `axis = pos`.
    pub fn split(&self, axis: usize, pos: f32) -> (Aabb, Aabb) {
        let mut left = *self;
        let mut right = *self;
        left.max[axis] = pos;
        right.min[axis] = pos;
        (left, right)
    }

    /// The parametric interval `[t0, t1]` in which the ray `o + t d` lies in
    /// the box, clipped to `[tmin, tmax]`, or `None`.
    ///
    /// Robust in the sense of pbrt-v3 (Pharr, Jakob, Humphreys, section 3.9.2):
    /// the far distance is enlarged by `1 + 2 gamma(3)` so that rounding never
    /// rejects a ray that grazes the box; a ray parallel to a slab is tested
    /// against it by its origin alone.
    pub fn intersect_ray(
        &self,
        origin: Vec3,
        inv_dir: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32)> {
        let mut t0 = tmin;
        let mut t1 = tmax;
        for a in 0..3 {
            if inv_dir[a].is_infinite() {
                // Parallel to the slab (d = +-0): inside it for every t, or
                // never. Computed instead, 0 * inf on the slab's face would be
                // NaN on one side and -inf on the other, and cut the interval.
                if origin[a] < self.min[a] || origin[a] > self.max[a] {
                    return None;
                }
                continue;
            }
            let mut near = (self.min[a] - origin[a]) * inv_dir[a];
            let mut far = (self.max[a] - origin[a]) * inv_dir[a];
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= FAR_GROW;
            // Written so that a NaN `near`/`far` leaves the interval unchanged.
            t0 = if near > t0 { near } else { t0 };
            t1 = if far < t1 { far } else { t1 };
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}
