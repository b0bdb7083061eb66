//! Batch queries: many rays in parallel work items.

use rayon::prelude::*;

use super::query::{AnyLeaf, ClosestLeaf, LayoutQuery, OverLeaves};
use super::KdTree;
use crate::isect::Hit;
use crate::leaf::layout::Layout;
use crate::math::{Aabb, Ray, Triangle};
use crate::simd::dispatch;

/// Rays per work item of [`KdTree::closest_hits`] and [`KdTree::any_hits`].
pub(crate) const BATCH: usize = 256;

impl KdTree<Triangle> {
    /// Closest hits of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        in_parallel(rays, out, |rs, os| self.closest_hits_serial(rs, os));
    }

    /// Occlusion of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn any_hits(&self, rays: &[Ray], out: &mut [bool]) {
        in_parallel(rays, out, |rs, os| self.any_hits_serial(rs, os));
    }

    /// Closest hits of many rays on the calling thread (for callers that
    /// run their own threads, such as a renderer's tiles); `out[i]`
    /// answers `rays[i]`. Several rays are walked at once, interleaved, so
    /// that their memory loads overlap: faster than one ray at a time on
    /// incoherent rays (see `docs/performance.md`), the same answers.
    pub fn closest_hits_serial(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.closest_hits_walked(rays, out, BatchWalk::Auto);
    }

    /// [`KdTree::closest_hits_serial`] with the walk chosen by `walk`
    /// (for tests and measurements).
    #[doc(hidden)]
    pub fn closest_hits_walked(&self, rays: &[Ray], out: &mut [Option<Hit>], walk: BatchWalk) {
        self.batch(
            rays,
            out,
            walk,
            |out| ClosestBatch { rays, out },
            |r| self.closest_hit(r),
        );
    }

    /// Occlusion of many rays on the calling thread, as
    /// [`KdTree::closest_hits_serial`]; `out[i]` answers `rays[i]`.
    pub fn any_hits_serial(&self, rays: &[Ray], out: &mut [bool]) {
        self.any_hits_walked(rays, out, BatchWalk::Auto);
    }

    /// [`KdTree::any_hits_serial`] with the walk chosen by `walk` (for
    /// tests and measurements).
    #[doc(hidden)]
    pub fn any_hits_walked(&self, rays: &[Ray], out: &mut [bool], walk: BatchWalk) {
        self.batch(
            rays,
            out,
            walk,
            |out| AnyBatch { rays, out },
            |r| self.any_hit(r),
        );
    }

    /// Answers `rays` into `out`: by the interleaved wide walk of
    /// `kernel` if the batch takes it (see [`KdTree::interleaves`]), else
    /// ray by ray with `one`.
    fn batch<'a, T, Q: LayoutQuery<Output = ()>>(
        &self,
        rays: &[Ray],
        out: &'a mut [T],
        walk: BatchWalk,
        kernel: impl FnOnce(&'a mut [T]) -> Q,
        one: impl Fn(&Ray) -> T,
    ) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        if self.interleaves(rays, walk) {
            let query = kernel(out);
            dispatch(self.max_level, OverLeaves { tree: self, query });
        } else {
            for (r, o) in rays.iter().zip(out) {
                *o = one(r);
            }
        }
    }

    /// Whether a batch of `rays` takes the interleaved wide walk.
    fn interleaves(&self, rays: &[Ray], walk: BatchWalk) -> bool {
        !self.wide.is_empty()
            && match walk {
                BatchWalk::Auto => {
                    self.nodes.len() >= SMALL_TREE
                        && self.expected_inner >= SHALLOW
                        && !coherent(rays, self.bounds)
                }
                BatchWalk::Binary => false,
                BatchWalk::Wide => true,
            }
    }
}

/// How a batch query walks its rays.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BatchWalk {
    /// Ray by ray over the binary nodes when the rays are coherent, else
    /// interleaved over the wide nodes.
    Auto,
    /// Ray by ray over the binary nodes.
    Binary,
    /// Interleaved over the wide nodes (when the tree has them).
    Wide,
}

/// Rays sampled to judge a batch's coherence.
const SAMPLE: usize = 32;

/// Trees of fewer binary nodes take the binary walk: a walk of a few
/// nodes costs less than the wide walk's set-up.
const SMALL_TREE: usize = 64;

/// Trees whose SAH expects fewer inner nodes per ray than this take the
/// binary walk: most rays cross a few large cells (a small object in a
/// large empty room), where the binary walk's steps are few and
/// predictable and the wide walk's per-ray set-up is not repaid (figures
/// in `docs/performance.md`).
const SHALLOW: f64 = 8.0;

/// True when most neighbouring rays of the batch start close together
/// (within a hundredth of the tree's diagonal) and point within about 25
/// degrees of each other (camera rays, shadow rays from neighbouring
/// pixels towards one light): they walk the same cells, the binary
/// walk's branches are predictable, and one ray at a time over the binary
/// nodes beats the wide walk, whose every step computes all seven planes.
/// Incoherent rays (bounces off diffuse surfaces, shadow rays from
/// scattered points, random rays) take the interleaved wide walk (figures
/// in `docs/performance.md`).
fn coherent(rays: &[Ray], bounds: Aabb) -> bool {
    let near = (bounds.max - bounds.min).length_squared() * 1e-4;
    let step = (rays.len() / SAMPLE).max(1);
    let (mut pairs, mut close) = (0, 0);
    for i in (1..rays.len()).step_by(step).take(SAMPLE) {
        let (a, b) = (&rays[i - 1], &rays[i]);
        let d = a.dir.dot(b.dir);
        // cos > 0.9, without the square roots.
        let aligned = d > 0.0 && d * d > 0.81 * a.dir.length_squared() * b.dir.length_squared();
        close += (aligned && a.origin.distance_squared(b.origin) <= near) as usize;
        pairs += 1;
    }
    4 * close >= 3 * pairs
}

/// [`KdTree::closest_hits_serial`] as a [`LayoutQuery`].
struct ClosestBatch<'a> {
    rays: &'a [Ray],
    out: &'a mut [Option<Hit>],
}

impl LayoutQuery for ClosestBatch<'_> {
    type Output = ();
    #[inline(always)]
    fn over<L: Layout, const SIMD: u8>(self, tree: &KdTree<Triangle>, layout: L) {
        let Self { rays, out } = self;
        tree.walk_interleaved::<_, SIMD>(
            rays,
            |i| ClosestLeaf::<L, SIMD>::new(tree, layout, &rays[i]),
            |i, v| out[i] = v.hit(),
        );
    }
}

/// [`KdTree::any_hits_serial`] as a [`LayoutQuery`].
struct AnyBatch<'a> {
    rays: &'a [Ray],
    out: &'a mut [bool],
}

impl LayoutQuery for AnyBatch<'_> {
    type Output = ();
    #[inline(always)]
    fn over<L: Layout, const SIMD: u8>(self, tree: &KdTree<Triangle>, layout: L) {
        let Self { rays, out } = self;
        tree.walk_interleaved::<_, SIMD>(
            rays,
            |i| AnyLeaf::<L, SIMD>::new(layout, &rays[i]),
            |i, v| out[i] = v.found(),
        );
    }
}

/// `out[i] = query(&rays[i])` for every ray, in work items of [`BATCH`]
/// rays, every one its own job (`with_max_len(1)`): rayon otherwise splits
/// a range only a few times unless a thief steals, so a costly quarter of
/// an image could hold one thread while the other idles (see
/// `docs/performance.md`).
pub(crate) fn in_parallel<T: Send>(
    rays: &[Ray],
    out: &mut [T],
    query: impl Fn(&[Ray], &mut [T]) + Sync,
) {
    assert_eq!(rays.len(), out.len(), "one output slot per ray");
    rays.par_chunks(BATCH)
        .zip(out.par_chunks_mut(BATCH))
        .with_max_len(1)
        .for_each(|(rs, os)| query(rs, os));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::build::BuildParams;
    use crate::simd::level;
    use crate::test_support::{floats, soup};
    use glam::Vec3;

    /// Every level's build of the interleaved wide walk (the portable one
    /// is what a CPU without AVX2 runs) answers as brute force, in both
    /// leaf layouts, with rays that miss the root cell or are invalid
    /// among them.
    #[test]
    fn every_level_of_the_interleaved_walk_agrees_with_brute_force() {
        let mut f = floats(41);
        let tris = soup(&mut f, 3000, 0.4);
        let mut rays: Vec<Ray> = (0..2000)
            .map(|_| Ray::new(Vec3::new(f(), f(), f()) * 5.0, Vec3::new(f(), f(), f())))
            .collect();
        rays.push(Ray::new(Vec3::splat(100.0), Vec3::X));
        rays.push(Ray::new(Vec3::ZERO, Vec3::ZERO));
        rays.push(Ray::with_interval(Vec3::ZERO, Vec3::X, 2.0, 1.0));
        let want: Vec<Option<Hit>> = rays.iter().map(|r| brute::closest_hit(&tris, r)).collect();
        for compact_leaves in [false, true] {
            let params = BuildParams {
                compact_leaves,
                ..BuildParams::default()
            };
            let tree = KdTree::build(tris.clone(), &params);
            assert!(!tree.wide.is_empty());
            for top in [level::PORTABLE, level::AVX2, level::AVX512] {
                let mut out = vec![None; rays.len()];
                let query = ClosestBatch {
                    rays: &rays,
                    out: &mut out,
                };
                dispatch(top, OverLeaves { tree: &tree, query });
                assert_eq!(out, want, "level {top}, compact {compact_leaves}");
                let mut occluded = vec![false; rays.len()];
                let query = AnyBatch {
                    rays: &rays,
                    out: &mut occluded,
                };
                dispatch(top, OverLeaves { tree: &tree, query });
                let any: Vec<bool> = want.iter().map(|h| h.is_some()).collect();
                assert_eq!(occluded, any, "level {top}, compact {compact_leaves}");
            }
        }
    }

    /// Camera-like rays count as coherent; bounce-like, random ones and
    /// parallel rays from scattered points do not.
    #[test]
    fn coherence_is_judged_by_neighbouring_directions() {
        let camera: Vec<Ray> = (0..256)
            .map(|i| {
                let (x, y) = ((i % 16) as f32 / 16.0 - 0.5, (i / 16) as f32 / 16.0 - 0.5);
                Ray::new(Vec3::ZERO, Vec3::new(x, y, 1.0))
            })
            .collect();
        let bounds = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        assert!(coherent(&camera, bounds));
        let mut f = floats(3);
        let random: Vec<Ray> = (0..256)
            .map(|_| Ray::new(Vec3::ZERO, Vec3::new(f(), f(), f())))
            .collect();
        assert!(!coherent(&random, bounds));
        // Bounces off one plane: cosine-like directions about +z.
        let bounces: Vec<Ray> = (0..256)
            .map(|_| Ray::new(Vec3::ZERO, Vec3::new(f(), f(), f().abs() + 0.1)))
            .collect();
        assert!(!coherent(&bounces, bounds));
        assert!(coherent(&camera[..1], bounds));
        // One direction from scattered points (shadow rays towards the sun).
        let sun: Vec<Ray> = (0..256)
            .map(|_| Ray::new(Vec3::new(f(), f(), f()) * 10.0, Vec3::new(0.3, 1.0, 0.2)))
            .collect();
        assert!(!coherent(&sun, bounds));
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
