//! Queries of a box tree: the caller's closures intersect the objects.

use super::walk::LeafResult;
use super::{KdTree, NoCounters};
use crate::math::{Aabb, Ray};

impl KdTree<Aabb> {
    /// Closest hit over the boxes' contents: `hit(i, tmax)` intersects
    /// object `i` and returns its hit distance if it is at most `tmax`.
    /// Objects are offered front to back, cell by cell; the traversal stops
    /// once no cell ahead can hold a closer hit. Returns the closest object
    /// and its distance. An object that spans several cells may be offered
    /// more than once.
    pub fn closest_with(
        &self,
        ray: &Ray,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        let mut best_t = ray.tmax;
        self.walk(
            ray,
            &mut NoCounters,
            &mut |offset, count, _: &mut NoCounters, closest: &mut f32| {
                // SAFETY: `offset`, `count` describe a leaf of this tree.
                let items = unsafe { self.indices.get_unchecked(offset..offset + count) };
                for &i in items {
                    if let Some(t) = hit(i, best_t) {
                        if t <= best_t && best.is_none_or(|(bi, bt)| t < bt || (t == bt && i < bi))
                        {
                            best_t = t;
                            best = Some((i, t));
                        }
                    }
                }
                *closest = if best.is_some() {
                    best_t
                } else {
                    f32::INFINITY
                };
                LeafResult::Continue
            },
        );
        best
    }

    /// True if `hit(i)` is true for an object whose box the ray passes
    /// through; stops at the first.
    pub fn any_with(&self, ray: &Ray, mut hit: impl FnMut(u32) -> bool) -> bool {
        let mut found = false;
        self.walk(
            ray,
            &mut NoCounters,
            &mut |offset, count, _: &mut NoCounters, _: &mut f32| {
                // SAFETY: `offset`, `count` describe a leaf of this tree.
                let items = unsafe { self.indices.get_unchecked(offset..offset + count) };
                if items.iter().any(|&i| hit(i)) {
                    found = true;
                    LeafResult::Stop
                } else {
                    LeafResult::Continue
                }
            },
        );
        found
    }
}
