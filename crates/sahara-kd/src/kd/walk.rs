//! The single-ray walk: Havran's sequential traversal with a stack of far
//! children (Havran 2000, "Heuristic Ray Shooting Algorithms", as used by
//! pbrt-v3's `KdTreeAccel::Intersect`): walk down to the near child, push
//! the far one with its parametric interval, test the leaf, pop. A cell
//! whose entry distance lies beyond the closest hit found so far cannot
//! hold a closer hit, so it is skipped. Shared by triangle and box trees.

use glam::Vec3;

use super::interval::{cut, may_hold_closer, widened_t0, widened_t1};
use super::{Counters, KdTree, LeafStorage};
use crate::build::MAX_DEPTH;
use crate::math::Ray;

#[derive(Clone, Copy)]
struct StackEntry {
    node: u32,
    t0: f32,
    t1: f32,
}

/// What a leaf visit asks of the traversal.
pub(crate) enum LeafResult {
    /// Go on to the next cell.
    Continue,
    /// End the walk.
    Stop,
}

/// What the walk does at a non-empty leaf: test it, lower `closest` (the
/// distance beyond which no cell can hold a closer hit) and say whether to
/// go on.
pub(crate) trait LeafVisit<C> {
    /// Visit the leaf whose index run starts at `offset` with `count` entries.
    fn visit(
        &mut self,
        offset: usize,
        count: usize,
        counters: &mut C,
        closest: &mut f32,
    ) -> LeafResult;

    /// Where the data of the leaf whose index run starts at `offset` lies,
    /// for a prefetch: its first block, and the other line its test reads
    /// (null where there is nothing to fetch).
    #[inline(always)]
    fn leaf_address(&self, offset: usize) -> (*const u8, *const u8) {
        let _ = offset;
        (std::ptr::null(), std::ptr::null())
    }
}

impl<C, F: FnMut(usize, usize, &mut C, &mut f32) -> LeafResult> LeafVisit<C> for F {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, closest: &mut f32) -> LeafResult {
        self(offset, count, c, closest)
    }
}

impl<P: LeafStorage> KdTree<P> {
    /// The traversal shared by both queries: visits the leaves the ray passes
    /// through, front to back, calling `leaf` with the offset and count of
    /// their primitive runs in `indices`.
    ///
    /// `leaf` reports the closest hit distance found so far through its last
    /// argument (infinity while there is none); cells entered beyond it are
    /// skipped.
    #[inline(always)]
    pub(crate) fn walk<C: Counters>(
        &self,
        ray: &Ray,
        counters: &mut C,
        leaf: &mut impl LeafVisit<C>,
    ) {
        // `is_valid` rules out NaN bounds, so `>` is the whole test.
        if self.nodes.is_empty() || !ray.is_valid() || ray.tmin > ray.tmax {
            return;
        }
        let inv_dir = Vec3::ONE / ray.dir;
        let Some((mut t0, mut t1)) = self
            .bounds
            .intersect_ray(ray.origin, inv_dir, ray.tmin, ray.tmax)
        else {
            return;
        };
        let origin = ray.origin.to_array();
        let dir = ray.dir.to_array();
        let inv = inv_dir.to_array();
        // Near and far by the direction's sign (Wald 2004): a ray moving
        // towards +axis meets the cell below the plane first. The sign bit
        // also orders rays with d = -0 consistently with `inv = -inf`.
        let neg = [
            dir[0].is_sign_negative(),
            dir[1].is_sign_negative(),
            dir[2].is_sign_negative(),
        ];
        // The stack is written before it is read (`sp` counts the valid
        // entries), so it need not be initialised: that saves clearing
        // 768 bytes per ray.
        let mut stack = [const { std::mem::MaybeUninit::<StackEntry>::uninit() }; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node = 0u32;
        let mut closest = f32::INFINITY;
        loop {
            debug_assert!((node as usize) < self.nodes.len());
            // SAFETY: node indices come from the builder, which writes only
            // indices of nodes it created (`validate` checks it in tests);
            // the bounds check cost ~7% of the random-ray profile (perf).
            let n = unsafe { *self.nodes.get_unchecked(node as usize) };
            if !n.is_leaf() {
                counters.inner();
                let axis = n.axis();
                let (near, far) = n.near_far(node, &neg);
                // NaN when the ray lies in the plane: both children get the
                // whole interval (see `interval`).
                let t_plane = (n.split() - origin[axis]) * inv[axis];
                if t_plane > widened_t1(t1) {
                    node = near; // the plane lies beyond the interval
                } else if t_plane < widened_t0(t0) {
                    node = far; // the plane lies before the interval
                } else {
                    debug_assert!(sp < MAX_DEPTH, "tree deeper than the traversal stack");
                    let (near_t1, far_t0) = cut(t_plane, t0, t1);
                    stack[sp] = std::mem::MaybeUninit::new(StackEntry {
                        node: far,
                        t0: far_t0,
                        t1,
                    });
                    sp += 1;
                    node = near;
                    t1 = near_t1;
                }
                continue;
            }
            counters.leaf();
            let count = n.leaf_count() as usize;
            if count != 0 {
                let offset = n.leaf_offset() as usize;
                if let LeafResult::Stop = leaf.visit(offset, count, counters, &mut closest) {
                    return;
                }
            }
            // Pop the next cell that may still hold a closer hit. Every
            // entry is checked: a ray lying in a split plane gives both
            // children its whole interval, so entries are not always front
            // to back and the first one beyond the hit does not end the walk
            // (the property tests found such a ray).
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push above.
                let e = unsafe { stack[sp].assume_init() };
                if may_hold_closer(e.t0, closest) {
                    node = e.node;
                    t0 = e.t0;
                    t1 = e.t1;
                    break;
                }
            }
        }
    }
}
