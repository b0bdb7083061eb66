//! Batch queries: many rays in parallel work items.

use rayon::prelude::*;

use super::KdTree;
use crate::isect::Hit;
use crate::math::{Ray, Triangle};

/// Rays per work item of [`KdTree::closest_hits`] and [`KdTree::any_hits`].
pub(crate) const BATCH: usize = 256;

impl KdTree<Triangle> {
    /// Closest hits of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        in_parallel(rays, out, |r| self.closest_hit(r));
    }

    /// Occlusion of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn any_hits(&self, rays: &[Ray], out: &mut [bool]) {
        in_parallel(rays, out, |r| self.any_hit(r));
    }
}

/// `out[i] = query(&rays[i])` for every ray, in work items of [`BATCH`]
/// rays, every one its own job (`with_max_len(1)`): rayon otherwise splits
/// a range only a few times unless a thief steals, so a costly quarter of
/// an image could hold one thread while the other idles (see
/// `docs/performance.md`).
fn in_parallel<T: Send>(rays: &[Ray], out: &mut [T], query: impl Fn(&Ray) -> T + Sync) {
    assert_eq!(rays.len(), out.len(), "one output slot per ray");
    rays.par_chunks(BATCH)
        .zip(out.par_chunks_mut(BATCH))
        .with_max_len(1)
        .for_each(|(rs, os)| {
            for (r, o) in rs.iter().zip(os) {
                *o = query(r);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::BuildParams;
    use crate::test_support::{floats, soup};
    use glam::Vec3;

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
