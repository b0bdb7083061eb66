//! Front-to-back traversal: closest hit and any hit, single rays and batches.
//!
//! The scheme is Havran's sequential traversal with a stack of far children
//! (Havran 2000, "Heuristic Ray Shooting Algorithms", as used by pbrt-v3's
//! `KdTreeAccel::Intersect`): walk down to the near child, push the far one
//! with its parametric interval, test the leaf, pop. A cell whose entry
//! distance lies beyond the closest hit found so far cannot hold a closer hit,
//! so it is skipped.

use glam::Vec3;
use rayon::prelude::*;

use crate::geometry::leaf_layout::{Indexed, Layout, LeafBlock, Whole};
use crate::geometry::triangle::RayShear;
use crate::geometry::triangle_block::BLOCK_WIDTH;
use crate::geometry::{Aabb, Primitive, Ray, Triangle, TriangleHit, TriangleLeaves};
use crate::tree::KdTree;

/// The instruction sets a traversal is compiled for (the `SIMD` constant
/// of the leaf tests): each level has the ones below it.
pub(crate) mod level {
    /// Baseline: the lane loops, vectorised by the compiler.
    pub const PORTABLE: u8 = 0;
    /// AVX2 intrinsics in the leaf tests.
    pub const AVX2: u8 = 1;
    /// AVX2, and AVX-512 (F + VL) for the gathers from a block's vertex
    /// table (`vpermt2ps`).
    pub const AVX512: u8 = 2;
}

/// Run-time CPU feature selection: the release binary targets baseline
/// x86-64 (SSE2) and picks the AVX2 build of the traversal where it exists
/// (the AVX-512 one for compact leaves).
#[cfg(target_arch = "x86_64")]
pub(crate) mod simd {
    /// True when the CPU has AVX2 (std caches the CPUID query).
    #[inline(always)]
    pub fn avx2() -> bool {
        std::arch::is_x86_feature_detected!("avx2")
    }

    /// True when the CPU has AVX2 and AVX-512 F and VL.
    #[inline(always)]
    pub fn avx512() -> bool {
        avx2()
            && std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
    }
}

/// The closest hit of a ray: distance, triangle and barycentrics (hit point
/// `(1 - u - v) v0 + u v1 + v v2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the triangle, as given to the build.
    pub tri: u32,
    /// Barycentric weight of `v1`.
    pub u: f32,
    /// Barycentric weight of `v2`.
    pub v: f32,
}

/// Make `h`, a hit on triangle `i` with `h.t <= *best_t`, the best hit if
/// it is closer, or as close with a smaller index (the tie rule every query
/// and the brute-force oracle share).
#[inline(always)]
pub(crate) fn keep_closer(best_t: &mut f32, best: &mut Hit, h: TriangleHit, i: u32) {
    if h.t < *best_t || i < best.tri {
        *best_t = h.t;
        *best = Hit {
            t: h.t,
            tri: i,
            u: h.u,
            v: h.v,
        };
    }
}

/// Relative slack on the traversal's distance comparisons.
///
/// Cell distances and triangle distances are rounded separately, so a
/// triangle in the next cell may report a `t` a few ulps below the boundary
/// it lies behind. Skipping a cell or a child only when it is farther than
/// this margin keeps the result bit-identical to testing every triangle
/// (what the brute-force oracle does); the price is an occasional extra leaf
/// visit at a boundary. 2^-12 is ~500 ulps: far above the rounding of the
/// watertight test on the test suite's scales, far below any cell size.
pub(crate) const MARGIN: f32 = 1.0 / 4096.0;

/// Rays per work item of [`KdTree::closest_hits`] and [`KdTree::any_hits`].
const BATCH: usize = 256;

/// Depth bound of the traversal stack; builders never exceed it.
pub const MAX_DEPTH: usize = 64;

/// Per-ray work counters for `sahara bench --counters`.
pub trait Counters {
    /// An inner node was visited.
    fn inner(&mut self);
    /// A leaf was visited.
    fn leaf(&mut self);
    /// A ray/triangle test was made.
    fn triangle(&mut self);
}

/// Counting nothing: the production traversal compiles to no counter code.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCounters;

impl Counters for NoCounters {
    #[inline(always)]
    fn inner(&mut self) {}
    #[inline(always)]
    fn leaf(&mut self) {}
    #[inline(always)]
    fn triangle(&mut self) {}
}

/// Totals of traversal work over many rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounters {
    /// Inner nodes visited.
    pub inner: u64,
    /// Leaves visited (empty ones included).
    pub leaves: u64,
    /// Ray/triangle tests.
    pub triangles: u64,
}

impl Counters for TraversalCounters {
    fn inner(&mut self) {
        self.inner += 1;
    }
    fn leaf(&mut self) {
        self.leaves += 1;
    }
    fn triangle(&mut self) {
        self.triangles += 1;
    }
}

impl std::ops::AddAssign for TraversalCounters {
    fn add_assign(&mut self, o: Self) {
        self.inner += o.inner;
        self.leaves += o.leaves;
        self.triangles += o.triangles;
    }
}

#[derive(Clone, Copy)]
struct StackEntry {
    node: u32,
    t0: f32,
    t1: f32,
}

/// What a leaf visit asks of the traversal.
enum LeafResult {
    Continue,
    Stop,
}

/// What the walk does at a non-empty leaf: test it, lower `closest` (the
/// distance beyond which no cell can hold a closer hit) and say whether to
/// go on.
trait LeafVisit<C> {
    /// Visit the leaf whose index run starts at `offset` with `count` entries.
    fn visit(
        &mut self,
        offset: usize,
        count: usize,
        counters: &mut C,
        closest: &mut f32,
    ) -> LeafResult;
}

impl<C, F: FnMut(usize, usize, &mut C, &mut f32) -> LeafResult> LeafVisit<C> for F {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, closest: &mut f32) -> LeafResult {
        self(offset, count, c, closest)
    }
}

/// The closest-hit leaf visit of one ray, a named type rather than a
/// closure so that `#[inline(always)]` can put it into the walk's loop
/// (LLVM kept the closure out of line: a call per leaf).
struct ClosestLeaf<'a, L: Layout, const SIMD: u8> {
    tree: &'a KdTree<Triangle>,
    layout: L,
    shear: &'a RayShear,
    tmin: f32,
    best_t: f32,
    best: Hit,
}

impl<C: Counters, L: Layout, const SIMD: u8> LeafVisit<C> for ClosestLeaf<'_, L, SIMD> {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, closest: &mut f32) -> LeafResult {
        // SAFETY: the walk passes the `offset`, `count` of a non-empty leaf
        // of this tree, whose blocks `layout` holds.
        let blocks = unsafe { self.layout.blocks(offset, count) };
        self.tree.leaf_closest::<C, SIMD, _>(
            blocks,
            self.shear,
            self.tmin,
            count,
            &mut self.best_t,
            &mut self.best,
            c,
        );
        if self.best.tri != u32::MAX {
            *closest = self.best_t;
        }
        LeafResult::Continue
    }
}

/// The any-hit leaf visit of one ray (a named type for the reason given at
/// [`ClosestLeaf`]).
struct AnyLeaf<'a, L: Layout, const SIMD: u8> {
    layout: L,
    shear: &'a RayShear,
    tmin: f32,
    tmax: f32,
    found: bool,
}

impl<C: Counters, L: Layout, const SIMD: u8> LeafVisit<C> for AnyLeaf<'_, L, SIMD> {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, _: &mut f32) -> LeafResult {
        // SAFETY: as in `ClosestLeaf::visit`.
        let blocks = unsafe { self.layout.blocks(offset, count) };
        if self.any_in(blocks, count, c) {
            self.found = true;
            LeafResult::Stop
        } else {
            LeafResult::Continue
        }
    }
}

impl<L: Layout, const SIMD: u8> AnyLeaf<'_, L, SIMD> {
    /// True if a triangle of `blocks` (a leaf of `count`) is hit.
    #[inline(always)]
    fn any_in<C: Counters, B: LeafBlock>(
        &self,
        blocks: impl Iterator<Item = B>,
        count: usize,
        c: &mut C,
    ) -> bool {
        for (b, block) in blocks.enumerate() {
            let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
            (0..lanes).for_each(|_| c.triangle());
            // SAFETY: `SIMD` is the level the traversal is compiled for.
            let (mut m, e) = unsafe { block.edges::<SIMD>(self.shear, lanes) };
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                let uvw = [e[0][l], e[1][l], e[2][l]];
                let tri = block.triangle(l);
                if self.shear.decide(&tri, uvw, self.tmin, self.tmax).is_some() {
                    return true;
                }
            }
        }
        false
    }
}

impl KdTree<Triangle> {
    /// True if the leaf blocks are in the compact (indexed) layout.
    #[inline(always)]
    fn compact_leaves(&self) -> bool {
        matches!(self.leaf_data, TriangleLeaves::Indexed(_))
    }

    /// The closest hit with `t` in `(ray.tmin, ray.tmax]`; among hits at the
    /// same `t`, the one with the smallest triangle index.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_counted(ray, &mut NoCounters)
    }

    /// [`KdTree::closest_hit`], counting the work done.
    pub fn closest_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        // AVX-512 only speeds up the compact layout's gathers; the whole
        // layout keeps the AVX2 build.
        #[cfg(target_arch = "x86_64")]
        if self.compact_leaves() && simd::avx512() {
            // SAFETY: the CPU has AVX2 and AVX-512 F, VL (checked).
            return unsafe { self.closest_hit_avx512(ray, counters) };
        }
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: the CPU has AVX2 (checked at run time).
            return unsafe { self.closest_hit_avx2(ray, counters) };
        }
        self.closest_hit_portable::<C, { level::PORTABLE }>(ray, counters)
    }

    /// [`KdTree::closest_hit_portable`] compiled for AVX2 and AVX-512 (F,
    /// VL): the block test gathers its lanes from the vertex table with one
    /// two-register permute (`vpermt2ps`) instead of two permutes and a
    /// blend (see `indexed_block`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    unsafe fn closest_hit_avx512<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        self.closest_hit_portable::<C, { level::AVX512 }>(ray, counters)
    }

    /// [`KdTree::closest_hit_portable`] compiled for AVX2: the block test's
    /// eight lanes become one 256-bit operation instead of two SSE ones
    /// (and its intrinsics form, see `triangle_block`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn closest_hit_avx2<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        self.closest_hit_portable::<C, { level::AVX2 }>(ray, counters)
    }

    /// The closest-hit traversal, for whatever target features the caller
    /// is compiled with (inlined into each); `SIMD` selects the leaf test's
    /// intrinsics (a level the CPU has, see [`level`]).
    #[inline(always)]
    fn closest_hit_portable<C: Counters, const SIMD: u8>(
        &self,
        ray: &Ray,
        counters: &mut C,
    ) -> Option<Hit> {
        match &self.leaf_data {
            TriangleLeaves::Whole(v) => self.closest_hit_in::<C, SIMD, _>(Whole(v), ray, counters),
            TriangleLeaves::Indexed(p) => {
                self.closest_hit_in::<C, SIMD, _>(Indexed(p), ray, counters)
            }
        }
    }

    /// [`KdTree::closest_hit_portable`] for the tree's leaf layout.
    #[inline(always)]
    fn closest_hit_in<C: Counters, const SIMD: u8, L: Layout>(
        &self,
        layout: L,
        ray: &Ray,
        counters: &mut C,
    ) -> Option<Hit> {
        let shear = RayShear::from_ray(ray);
        let mut leaf = ClosestLeaf::<L, SIMD> {
            tree: self,
            layout,
            shear: &shear,
            tmin: ray.tmin,
            best_t: ray.tmax,
            best: Hit {
                t: f32::INFINITY,
                tri: u32::MAX,
                u: 0.0,
                v: 0.0,
            },
        };
        self.walk(ray, counters, &mut leaf);
        let best = leaf.best;
        (best.tri != u32::MAX).then_some(best)
    }

    /// True if any triangle is hit with `t` in `(ray.tmin, ray.tmax]`
    /// (occlusion; stops at the first hit found).
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.any_hit_counted(ray, &mut NoCounters)
    }

    /// [`KdTree::any_hit`], counting the work done.
    pub fn any_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        // AVX-512 only speeds up the compact layout's gathers; the whole
        // layout keeps the AVX2 build.
        #[cfg(target_arch = "x86_64")]
        if self.compact_leaves() && simd::avx512() {
            // SAFETY: the CPU has AVX2 and AVX-512 F, VL (checked).
            return unsafe { self.any_hit_avx512(ray, counters) };
        }
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: the CPU has AVX2 (checked at run time).
            return unsafe { self.any_hit_avx2(ray, counters) };
        }
        self.any_hit_portable::<C, { level::PORTABLE }>(ray, counters)
    }

    /// [`KdTree::any_hit_portable`] compiled for AVX2 and AVX-512 (F, VL).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    unsafe fn any_hit_avx512<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        self.any_hit_portable::<C, { level::AVX512 }>(ray, counters)
    }

    /// [`KdTree::any_hit_portable`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn any_hit_avx2<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        self.any_hit_portable::<C, { level::AVX2 }>(ray, counters)
    }

    /// The any-hit traversal (inlined into each target-feature variant).
    #[inline(always)]
    fn any_hit_portable<C: Counters, const SIMD: u8>(&self, ray: &Ray, counters: &mut C) -> bool {
        match &self.leaf_data {
            TriangleLeaves::Whole(v) => self.any_hit_in::<C, SIMD, _>(Whole(v), ray, counters),
            TriangleLeaves::Indexed(p) => self.any_hit_in::<C, SIMD, _>(Indexed(p), ray, counters),
        }
    }

    /// [`KdTree::any_hit_portable`] for the tree's leaf layout.
    #[inline(always)]
    fn any_hit_in<C: Counters, const SIMD: u8, L: Layout>(
        &self,
        layout: L,
        ray: &Ray,
        counters: &mut C,
    ) -> bool {
        let shear = RayShear::from_ray(ray);
        let mut leaf = AnyLeaf::<L, SIMD> {
            layout,
            shear: &shear,
            tmin: ray.tmin,
            tmax: ray.tmax,
            found: false,
        };
        self.walk(ray, counters, &mut leaf);
        leaf.found
    }

    /// The closest-hit test of one leaf, whose `count` triangles are in
    /// `blocks`: updates `best_t` and `best` (whose `tri` is `u32::MAX`
    /// while there is no hit) with them; among equally distant hits the
    /// smallest index wins. `SIMD` is the level the caller is compiled for.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn leaf_closest<C: Counters, const SIMD: u8, B: LeafBlock>(
        &self,
        blocks: impl Iterator<Item = B>,
        shear: &RayShear,
        tmin: f32,
        count: usize,
        best_t: &mut f32,
        best: &mut Hit,
        counters: &mut C,
    ) {
        for (b, block) in blocks.enumerate() {
            let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
            (0..lanes).for_each(|_| counters.triangle());
            // Eight edge tests at once; the scalar test decides the few
            // lanes left (see `triangle_block`).
            // SAFETY: `SIMD` is the level the traversal is compiled for.
            let (mut m, e) = unsafe { block.edges::<SIMD>(shear, lanes) };
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                let uvw = [e[0][l], e[1][l], e[2][l]];
                if let Some(h) = shear.decide(&block.triangle(l), uvw, tmin, *best_t) {
                    // The index only now: its load missed the cache on
                    // most kept lanes (perf, random rays), and most kept
                    // lanes are not hits within the interval.
                    let i = self.indices[block.run() + l];
                    keep_closer(best_t, best, h, i);
                }
            }
        }
    }

    /// Closest hits of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        // Work items of 256 rays, and every one its own job
        // (`with_max_len(1)`): rayon otherwise splits a range only a few
        // times unless a thief steals, so a costly quarter of an image can
        // hold one thread while the other idles (teapot_stadium's camera
        // rays scaled 1.30x on two threads that way).
        rays.par_chunks(BATCH)
            .zip(out.par_chunks_mut(BATCH))
            .with_max_len(1)
            .for_each(|(rs, os)| {
                for (r, o) in rs.iter().zip(os) {
                    *o = self.closest_hit(r);
                }
            });
    }

    /// Occlusion of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn any_hits(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        rays.par_chunks(BATCH)
            .zip(out.par_chunks_mut(BATCH))
            .with_max_len(1)
            .for_each(|(rs, os)| {
                for (r, o) in rs.iter().zip(os) {
                    *o = self.any_hit(r);
                }
            });
    }
}

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

impl<P: Primitive> KdTree<P> {
    /// The traversal shared by both queries: visits the leaves the ray passes
    /// through, front to back, calling `leaf` with the offset and count of
    /// their primitive runs in `indices`.
    ///
    /// `leaf` reports the closest hit distance found so far through its last
    /// argument (infinity while there is none); cells entered beyond it are
    /// skipped.
    #[inline(always)]
    fn walk<C: Counters>(&self, ray: &Ray, counters: &mut C, leaf: &mut impl LeafVisit<C>) {
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
                // NaN when the ray lies in the plane (o = split, d = 0): then
                // no comparison holds and both children get the whole
                // interval, as they must.
                let t_plane = (n.split() - origin[axis]) * inv[axis];
                if t_plane > t1 + t1.abs() * MARGIN {
                    node = near; // the plane lies beyond the interval
                } else if t_plane < t0 - t0.abs() * MARGIN {
                    node = far; // the plane lies before the interval
                } else {
                    debug_assert!(sp < MAX_DEPTH, "tree deeper than the traversal stack");
                    stack[sp] = std::mem::MaybeUninit::new(StackEntry {
                        node: far,
                        t0: t_plane.max(t0).min(t1),
                        t1,
                    });
                    sp += 1;
                    node = near;
                    t1 = t_plane.min(t1).max(t0);
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
                if e.t0 <= closest * (1.0 + MARGIN) {
                    node = e.node;
                    t0 = e.t0;
                    t1 = e.t1;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::build::BuildParams;
    use crate::test_support::{floats, soup};

    /// The portable build of the traversal (what a CPU without AVX2 runs)
    /// agrees with brute force bit for bit, like the dispatched one that the
    /// other tests exercise on this machine.
    #[test]
    fn portable_and_dispatched_traversals_agree_with_brute_force() {
        let mut f = floats(99);
        let tris = soup(&mut f, 3000, 0.4);
        for compact_leaves in [false, true] {
            let params = BuildParams {
                compact_leaves,
                ..BuildParams::default()
            };
            let tree = KdTree::build(tris.clone(), &params);
            for _ in 0..3000 {
                let ray = Ray::new(Vec3::new(f(), f(), f()) * 5.0, Vec3::new(f(), f(), f()));
                let want = brute::closest_hit(&tris, &ray);
                let mut nc = NoCounters;
                assert_eq!(
                    tree.closest_hit_portable::<_, { level::PORTABLE }>(&ray, &mut nc),
                    want
                );
                assert_eq!(tree.closest_hit(&ray), want);
                assert_eq!(
                    tree.any_hit_portable::<_, { level::PORTABLE }>(&ray, &mut nc),
                    want.is_some()
                );
                assert_eq!(tree.any_hit(&ray), want.is_some());
                // The AVX2 build too where the dispatch picks AVX-512.
                #[cfg(target_arch = "x86_64")]
                if simd::avx2() {
                    // SAFETY: the CPU has AVX2.
                    unsafe {
                        assert_eq!(tree.closest_hit_avx2(&ray, &mut nc), want);
                        assert_eq!(tree.any_hit_avx2(&ray, &mut nc), want.is_some());
                    }
                }
            }
        }
    }

    /// The batch queries put each ray's own answer in its own slot, across
    /// the parallel work items (more rays than one item holds, and a
    /// partial last item).
    #[test]
    fn batches_answer_each_ray_in_its_slot() {
        let mut f = floats(5);
        let tree = KdTree::build(soup(&mut f, 2000, 1.0), &BuildParams::default());
        let rays: Vec<Ray> = (0..3 * BATCH + 37)
            .map(|_| Ray::new(Vec3::new(f(), f(), f()) * 5.0, Vec3::new(f(), f(), f())))
            .collect();
        let mut hits = vec![None; rays.len()];
        tree.closest_hits(&rays, &mut hits);
        let mut occluded = vec![false; rays.len()];
        tree.any_hits(&rays, &mut occluded);
        assert!(hits.iter().filter(|h| h.is_some()).count() > rays.len() / 10);
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(hits[i], tree.closest_hit(r), "ray {i}");
            assert_eq!(occluded[i], tree.any_hit(r), "ray {i}");
        }
    }
}
