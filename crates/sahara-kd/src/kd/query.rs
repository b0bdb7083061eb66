//! Closest-hit and any-hit queries of one ray, over either leaf layout,
//! for each instruction-set level.

use super::walk::{LeafResult, LeafVisit};
use super::{Counters, KdTree, NoCounters};
use crate::isect::{keep_closer, Hit, RayShear};
use crate::leaf::layout::{Indexed, Layout, LeafBlock, Whole};
use crate::leaf::{TriangleLeaves, BLOCK_WIDTH};
use crate::math::{Ray, Triangle};
use crate::simd::{dispatch, Kernel};

/// The closest-hit leaf visit of one ray, a named type rather than a
/// closure so that `#[inline(always)]` can put it into the walk's loop
/// (LLVM kept the closure out of line: a call per leaf).
pub(crate) struct ClosestLeaf<'a, L: Layout, const SIMD: u8> {
    tree: &'a KdTree<Triangle>,
    layout: L,
    shear: RayShear,
    tmin: f32,
    best_t: f32,
    best: Hit,
}

impl<'a, L: Layout, const SIMD: u8> ClosestLeaf<'a, L, SIMD> {
    /// The leaf visit of `ray` before any hit.
    #[inline(always)]
    pub(crate) fn new(tree: &'a KdTree<Triangle>, layout: L, ray: &Ray) -> Self {
        Self {
            tree,
            layout,
            shear: RayShear::from_ray(ray),
            tmin: ray.tmin,
            best_t: ray.tmax,
            best: Hit {
                t: f32::INFINITY,
                tri: u32::MAX,
                u: 0.0,
                v: 0.0,
            },
        }
    }

    /// The closest hit found.
    #[inline(always)]
    pub(crate) fn hit(&self) -> Option<Hit> {
        (self.best.tri != u32::MAX).then_some(self.best)
    }
}

impl<C: Counters, L: Layout, const SIMD: u8> LeafVisit<C> for ClosestLeaf<'_, L, SIMD> {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, closest: &mut f32) -> LeafResult {
        // SAFETY: the walk passes the `offset`, `count` of a non-empty leaf
        // of this tree, whose blocks `layout` holds.
        let blocks = unsafe { self.layout.blocks(offset, count) };
        self.tree.leaf_closest::<C, SIMD, _>(
            blocks,
            &self.shear,
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

    #[inline(always)]
    fn leaf_address(&self, offset: usize) -> (*const u8, *const u8) {
        // The hit's triangle index is read from the index array.
        let run = self.tree.indices.as_ptr().wrapping_add(offset);
        (self.layout.address(offset), run.cast())
    }
}

/// The any-hit leaf visit of one ray (a named type for the reason given at
/// [`ClosestLeaf`]).
pub(crate) struct AnyLeaf<L: Layout, const SIMD: u8> {
    layout: L,
    shear: RayShear,
    tmin: f32,
    tmax: f32,
    found: bool,
}

impl<L: Layout, const SIMD: u8> AnyLeaf<L, SIMD> {
    /// The leaf visit of `ray` before any hit.
    #[inline(always)]
    pub(crate) fn new(layout: L, ray: &Ray) -> Self {
        Self {
            layout,
            shear: RayShear::from_ray(ray),
            tmin: ray.tmin,
            tmax: ray.tmax,
            found: false,
        }
    }

    /// Whether a hit was found.
    #[inline(always)]
    pub(crate) fn found(&self) -> bool {
        self.found
    }
}

impl<C: Counters, L: Layout, const SIMD: u8> LeafVisit<C> for AnyLeaf<L, SIMD> {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, _: &mut f32) -> LeafResult {
        // SAFETY: as in `ClosestLeaf::visit`.
        let blocks = unsafe { self.layout.blocks(offset, count) };
        if self.any_hit_among(blocks, count, c) {
            self.found = true;
            LeafResult::Stop
        } else {
            LeafResult::Continue
        }
    }

    #[inline(always)]
    fn leaf_address(&self, offset: usize) -> (*const u8, *const u8) {
        let a = self.layout.address(offset);
        (a, a)
    }
}

impl<L: Layout, const SIMD: u8> AnyLeaf<L, SIMD> {
    /// True if a triangle of `blocks` (a leaf of `count`) is hit.
    #[inline(always)]
    fn any_hit_among<C: Counters, B: LeafBlock>(
        &self,
        blocks: impl Iterator<Item = B>,
        count: usize,
        c: &mut C,
    ) -> bool {
        for (b, block) in blocks.enumerate() {
            let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
            (0..lanes).for_each(|_| c.triangle());
            // SAFETY: `SIMD` is the level the traversal is compiled for.
            let (mut m, e) = unsafe { block.edges::<SIMD>(&self.shear, lanes) };
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

/// The all-hits leaf visit of one ray: every hit within the ray's
/// interval, whatever the others (a named type for the reason given at
/// [`ClosestLeaf`]).
pub(crate) struct AllLeaf<'a, L: Layout, const SIMD: u8> {
    tree: &'a KdTree<Triangle>,
    layout: L,
    shear: RayShear,
    tmin: f32,
    tmax: f32,
    hits: &'a mut Vec<Hit>,
}

impl<C: Counters, L: Layout, const SIMD: u8> LeafVisit<C> for AllLeaf<'_, L, SIMD> {
    #[inline(always)]
    fn visit(&mut self, offset: usize, count: usize, c: &mut C, _: &mut f32) -> LeafResult {
        // SAFETY: as in `ClosestLeaf::visit`.
        let blocks = unsafe { self.layout.blocks(offset, count) };
        for (b, block) in blocks.enumerate() {
            let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
            (0..lanes).for_each(|_| c.triangle());
            // SAFETY: `SIMD` is the level the traversal is compiled for.
            let (mut m, e) = unsafe { block.edges::<SIMD>(&self.shear, lanes) };
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                let uvw = [e[0][l], e[1][l], e[2][l]];
                let tri = block.triangle(l);
                if let Some(h) = self.shear.decide(&tri, uvw, self.tmin, self.tmax) {
                    self.hits.push(Hit {
                        t: h.t,
                        tri: self.tree.indices[block.run() + l],
                        u: h.u,
                        v: h.v,
                    });
                }
            }
        }
        // The closest distance is left at `tmax`: every cell is visited.
        LeafResult::Continue
    }
}

impl KdTree<Triangle> {
    /// The level its single-ray queries are dispatched at.
    #[inline(always)]
    fn single_ray_level(&self) -> u8 {
        self.max_level
    }

    /// The closest hit with `t` in `(ray.tmin, ray.tmax]`; among hits at the
    /// same `t`, the one with the smallest triangle index.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_counted(ray, &mut NoCounters)
    }

    /// [`KdTree::closest_hit`], counting the work done.
    pub fn closest_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        let query = ClosestQuery { ray, counters };
        dispatch(self.single_ray_level(), OverLeaves { tree: self, query })
    }

    /// True if any triangle is hit with `t` in `(ray.tmin, ray.tmax]`
    /// (occlusion; stops at the first hit found).
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.any_hit_counted(ray, &mut NoCounters)
    }

    /// [`KdTree::any_hit`], counting the work done.
    pub fn any_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        let query = AnyQuery { ray, counters };
        dispatch(self.single_ray_level(), OverLeaves { tree: self, query })
    }

    /// Every hit with `t` in `(ray.tmin, ray.tmax]`, into `hits` (cleared
    /// first): each triangle hit once, ordered by `t`, then by triangle
    /// index. A ray through an edge or a vertex shared by several
    /// triangles hits each of those the watertight test accepts (at least
    /// one). For counting surfaces crossed (inside tests by parity) and
    /// for every hit along a ray.
    pub fn all_hits(&self, ray: &Ray, hits: &mut Vec<Hit>) {
        hits.clear();
        let query = AllQuery { ray, hits };
        dispatch(self.single_ray_level(), OverLeaves { tree: self, query });
        // A triangle referenced by several leaves is found in each.
        hits.sort_unstable_by_key(|h| h.tri);
        hits.dedup_by_key(|h| h.tri);
        hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
    }

    /// The closest-hit walk over the leaf layout `layout`, at level `SIMD`.
    #[inline(always)]
    fn closest_hit_over<C: Counters, const SIMD: u8, L: Layout>(
        &self,
        layout: L,
        ray: &Ray,
        counters: &mut C,
    ) -> Option<Hit> {
        let mut leaf = ClosestLeaf::<L, SIMD>::new(self, layout, ray);
        self.walk(ray, counters, &mut leaf);
        leaf.hit()
    }

    /// The any-hit walk over the leaf layout `layout`, at level `SIMD`.
    #[inline(always)]
    fn any_hit_over<C: Counters, const SIMD: u8, L: Layout>(
        &self,
        layout: L,
        ray: &Ray,
        counters: &mut C,
    ) -> bool {
        let mut leaf = AnyLeaf::<L, SIMD>::new(layout, ray);
        self.walk(ray, counters, &mut leaf);
        leaf.found()
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
}

/// A query written once for both leaf layouts and every instruction-set
/// level; [`OverLeaves`] runs it over a tree's own layout.
pub(crate) trait LayoutQuery {
    /// What the query returns.
    type Output;

    /// The query on `tree`, whose leaf blocks are `layout`, with level
    /// `SIMD`'s instructions. Implementations are `#[inline(always)]`, as
    /// [`Kernel::run`] is.
    fn over<L: Layout, const SIMD: u8>(self, tree: &KdTree<Triangle>, layout: L) -> Self::Output;
}

/// `query` on `tree` as a kernel for [`dispatch`]. The layout is matched
/// here, once per query, so that the walk's loop holds one leaf test (see
/// `Layout`).
pub(crate) struct OverLeaves<'t, Q> {
    pub(crate) tree: &'t KdTree<Triangle>,
    pub(crate) query: Q,
}

impl<Q: LayoutQuery> Kernel for OverLeaves<'_, Q> {
    type Output = Q::Output;
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) -> Q::Output {
        let Self { tree, query } = self;
        match &tree.leaf_data {
            TriangleLeaves::Whole(v) => query.over::<_, LEVEL>(tree, Whole(v)),
            TriangleLeaves::Indexed(p) => query.over::<_, LEVEL>(tree, Indexed(p)),
        }
    }
}

/// [`KdTree::closest_hit_counted`] as a [`LayoutQuery`].
pub(crate) struct ClosestQuery<'a, C> {
    pub(crate) ray: &'a Ray,
    pub(crate) counters: &'a mut C,
}

impl<C: Counters> LayoutQuery for ClosestQuery<'_, C> {
    type Output = Option<Hit>;
    #[inline(always)]
    fn over<L: Layout, const SIMD: u8>(self, tree: &KdTree<Triangle>, layout: L) -> Option<Hit> {
        tree.closest_hit_over::<C, SIMD, _>(layout, self.ray, self.counters)
    }
}

/// [`KdTree::any_hit_counted`] as a [`LayoutQuery`].
pub(crate) struct AnyQuery<'a, C> {
    pub(crate) ray: &'a Ray,
    pub(crate) counters: &'a mut C,
}

impl<C: Counters> LayoutQuery for AnyQuery<'_, C> {
    type Output = bool;
    #[inline(always)]
    fn over<L: Layout, const SIMD: u8>(self, tree: &KdTree<Triangle>, layout: L) -> bool {
        tree.any_hit_over::<C, SIMD, _>(layout, self.ray, self.counters)
    }
}

/// [`KdTree::all_hits`] as a [`LayoutQuery`].
struct AllQuery<'a> {
    ray: &'a Ray,
    hits: &'a mut Vec<Hit>,
}

impl LayoutQuery for AllQuery<'_> {
    type Output = ();
    #[inline(always)]
    fn over<L: Layout, const SIMD: u8>(self, tree: &KdTree<Triangle>, layout: L) {
        let Self { ray, hits } = self;
        let mut leaf = AllLeaf::<L, SIMD> {
            tree,
            layout,
            shear: RayShear::from_ray(ray),
            tmin: ray.tmin,
            tmax: ray.tmax,
            hits,
        };
        tree.walk(ray, &mut NoCounters, &mut leaf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::build::BuildParams;
    use crate::simd::level;
    use crate::test_support::{floats, soup};
    use glam::Vec3;

    /// Every level's build of the walk (the portable one is what a CPU
    /// without AVX2 runs) agrees with brute force bit for bit, in both leaf
    /// layouts.
    #[test]
    fn every_level_agrees_with_brute_force() {
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
                assert_eq!(tree.closest_hit(&ray), want);
                assert_eq!(tree.any_hit(&ray), want.is_some());
                for top in [level::PORTABLE, level::AVX2, level::AVX512] {
                    let counters = &mut NoCounters;
                    let query = ClosestQuery {
                        ray: &ray,
                        counters,
                    };
                    let q = OverLeaves { tree: &tree, query };
                    assert_eq!(dispatch(top, q), want, "level {top}");
                    let counters = &mut NoCounters;
                    let query = AnyQuery {
                        ray: &ray,
                        counters,
                    };
                    let q = OverLeaves { tree: &tree, query };
                    assert_eq!(dispatch(top, q), want.is_some(), "level {top}");
                }
            }
        }
    }

    /// Every hit along a ray, as brute force finds them, in both leaf
    /// layouts; the first of them is the closest hit.
    #[test]
    fn all_hits_agree_with_brute_force() {
        let mut f = floats(7);
        let tris = soup(&mut f, 2000, 0.5);
        let mut hits = Vec::new();
        let (mut found, mut several) = (0, 0);
        for compact_leaves in [false, true] {
            let params = BuildParams {
                compact_leaves,
                ..BuildParams::default()
            };
            let tree = KdTree::build(tris.clone(), &params);
            for k in 0..2000 {
                let o = Vec3::new(f(), f(), f()) * 5.0;
                let ray = match k % 3 {
                    0 => Ray::new(o, Vec3::new(f(), f(), f())),
                    1 => Ray::with_interval(o, Vec3::new(f(), f(), f()), 0.5, 3.0),
                    _ => Ray::new(o, Vec3::X),
                };
                tree.all_hits(&ray, &mut hits);
                assert_eq!(hits, brute::all_hits(&tris, &ray), "ray {k}");
                assert_eq!(hits.first().copied(), tree.closest_hit(&ray), "ray {k}");
                found += hits.len();
                several += (hits.len() > 1) as usize;
            }
        }
        assert!(
            found > 1000 && several > 100,
            "{found} hits, {several} rays with several"
        );
        tree_without_triangles_has_no_hits();
    }

    fn tree_without_triangles_has_no_hits() {
        let tree = KdTree::build(Vec::new(), &BuildParams::default());
        let mut hits = vec![Hit {
            t: 1.0,
            tri: 0,
            u: 0.0,
            v: 0.0,
        }];
        tree.all_hits(&Ray::new(Vec3::ZERO, Vec3::X), &mut hits);
        assert!(hits.is_empty());
    }
}
