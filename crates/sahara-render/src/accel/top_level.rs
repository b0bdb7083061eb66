//! The top level of the two-level acceleration structure: a kd-tree over the
//! instances' world bounds (`sahara_kd::BoxTree`), queried with closures that
//! trace the instance's own mesh tree.

use sahara_kd::{Aabb, BoxTree, BuildParams, Builder, Counters, Ray};

/// The instances' world bounds in a kd-tree.
#[derive(Clone, Debug)]
pub struct InstanceList {
    tree: BoxTree,
}

impl Default for InstanceList {
    fn default() -> Self {
        Self::build(&[])
    }
}

impl InstanceList {
    /// A top level over these boxes (index `i` is instance `i`).
    pub fn build(bounds: &[Aabb]) -> Self {
        Self {
            tree: BoxTree::build(bounds.to_vec(), &{
                // Instances are tested one at a time: the classic SAH.
                let mut p = BuildParams::new(Builder::Sah);
                p.leaf_width = 1;
                p
            }),
        }
    }

    /// Calls `visit(i, tmax)` for the instances whose cells the ray passes
    /// through, front to back; `visit` returns the hit distance when it found
    /// a hit no farther than `tmax`. The traversal stops once no cell ahead
    /// can hold a closer hit; among equally distant hits the smallest
    /// instance index wins, so the result depends on nothing but the scene.
    #[inline]
    pub fn closest<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        mut visit: impl FnMut(u32, f32, &mut C) -> Option<f32>,
    ) {
        self.tree.closest_with(ray, |i, tmax| {
            counters.inner();
            visit(i, tmax, counters)
        });
    }

    /// True as soon as `visit(i)` returns true for an instance whose cell
    /// the ray passes through.
    #[inline]
    pub fn any(&self, ray: &Ray, visit: impl FnMut(u32) -> bool) -> bool {
        self.tree.any_with(ray, visit)
    }
}
