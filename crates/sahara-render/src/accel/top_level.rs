//! The top level of the two-level acceleration structure: a structure over
//! instance bounds queried with closures.
//!
//! For now a plain loop over the boxes; the interface is that of the
//! coming `sahara_kd::BoxTree` (`build(&[Aabb])`, closure-based `closest`
//! and `any`), so it can be swapped in here without touching the callers.

use glam::Vec3;
use sahara_kd::{Aabb, Counters, Ray};

/// The instances' world bounds, traversed by testing each box.
#[derive(Clone, Debug, Default)]
pub struct InstanceList {
    bounds: Vec<Aabb>,
}

impl InstanceList {
    /// A top level over these boxes (index `i` is instance `i`).
    pub fn build(bounds: &[Aabb]) -> Self {
        Self {
            bounds: bounds.to_vec(),
        }
    }

    /// Calls `visit(i, tmax)` for every instance whose box the ray meets
    /// before `tmax`; `visit` returns the new `tmax` when it found a closer
    /// hit. Instances are visited in index order, so the result does not
    /// depend on anything but the scene.
    #[inline]
    pub fn closest<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut visit: impl FnMut(u32, f32, &mut C) -> Option<f32>,
    ) {
        let inv = Vec3::ONE / ray.dir;
        let mut tmax = ray.tmax;
        for (i, b) in self.bounds.iter().enumerate() {
            counters.inner();
            if b.intersect_ray(ray.origin, inv, ray.tmin, tmax).is_some() {
                if let Some(t) = visit(i as u32, tmax, counters) {
                    tmax = t;
                }
            }
        }
    }

    /// True as soon as `visit(i)` returns true for an instance whose box the
    /// ray meets.
    #[inline]
    pub fn any(&self, ray: &Ray, mut visit: impl FnMut(u32) -> bool) -> bool {
        let inv = Vec3::ONE / ray.dir;
        self.bounds.iter().enumerate().any(|(i, b)| {
            b.intersect_ray(ray.origin, inv, ray.tmin, ray.tmax)
                .is_some()
                && visit(i as u32)
        })
    }
}
