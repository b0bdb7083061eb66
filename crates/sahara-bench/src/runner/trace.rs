//! Tracing a set of rays into hit records, in chunks handed out to the
//! threads of the current rayon pool.

use rayon::prelude::*;
use sahara_kd::{Ray, TriangleAccel};

use crate::record::HitRecord;

/// Rays per work item in multi-threaded tracing.
pub const CHUNK: usize = 4096;

/// What a set asks of the tracer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Query {
    /// The nearest hit (`t`, triangle).
    ClosestHit,
    /// Occlusion: is anything hit in `(tmin, tmax]`?
    AnyHit,
}

/// The record of one ray.
#[inline]
pub fn trace_one(tree: &TriangleAccel, ray: &Ray, query: Query) -> HitRecord {
    match query {
        Query::ClosestHit => HitRecord::from_closest(tree.closest_hit(ray)),
        Query::AnyHit => HitRecord::from_occluded(tree.any_hit(ray)),
    }
}

/// Trace `rays` into `out` (`out[i]` answers `rays[i]`) on the current rayon
/// pool, in chunks of [`CHUNK`] rays.
///
/// # Panics
/// If `out` and `rays` differ in length.
pub fn trace_into(tree: &TriangleAccel, rays: &[Ray], query: Query, out: &mut [HitRecord]) {
    assert_eq!(rays.len(), out.len(), "one record per ray");
    // Every chunk its own job (`with_max_len(1)`): rayon otherwise splits
    // the range only a few times unless a thief steals, and a costly
    // quarter of the image held one thread while the other idled (see
    // docs/performance.md, "Measured and kept").
    rays.par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .with_max_len(1)
        .for_each(|(rs, os)| match query {
            Query::ClosestHit => {
                for (r, o) in rs.iter().zip(os) {
                    *o = HitRecord::from_closest(tree.closest_hit(r));
                }
            }
            Query::AnyHit => {
                for (r, o) in rs.iter().zip(os) {
                    *o = HitRecord::from_occluded(tree.any_hit(r));
                }
            }
        });
}

/// The answers of one batch call, kept between timed runs so that a
/// measurement times the query alone, not the allocation of its output.
#[derive(Default)]
pub struct BatchAnswers {
    hits: Vec<Option<sahara_kd::Hit>>,
    occluded: Vec<bool>,
}

impl BatchAnswers {
    /// Answers `rays` with one call of the tree's batch query
    /// (`KdTree::closest_hits` or `KdTree::any_hits`), which splits the
    /// rays over the current rayon pool itself.
    pub fn trace(&mut self, tree: &TriangleAccel, rays: &[Ray], query: Query) {
        match query {
            Query::ClosestHit => {
                self.hits.resize(rays.len(), None);
                tree.closest_hits(rays, &mut self.hits);
            }
            Query::AnyHit => {
                self.occluded.resize(rays.len(), false);
                tree.any_hits(rays, &mut self.occluded);
            }
        }
    }

    /// The records of the last [`BatchAnswers::trace`] with `query`.
    ///
    /// # Panics
    /// If `out` differs in length from the rays traced last.
    pub fn records(&self, query: Query, out: &mut [HitRecord]) {
        match query {
            Query::ClosestHit => {
                assert_eq!(self.hits.len(), out.len(), "one record per ray");
                for (h, o) in self.hits.iter().zip(out) {
                    *o = HitRecord::from_closest(*h);
                }
            }
            Query::AnyHit => {
                assert_eq!(self.occluded.len(), out.len(), "one record per ray");
                for (h, o) in self.occluded.iter().zip(out) {
                    *o = HitRecord::from_occluded(*h);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use sahara_kd::{AccelParams, Triangle};

    #[test]
    fn records_match_single_ray_queries() {
        let tris = vec![
            Triangle::new(
                Vec3::new(-1.0, -1.0, 2.0),
                Vec3::new(1.0, -1.0, 2.0),
                Vec3::new(0.0, 1.0, 2.0),
            ),
            Triangle::new(
                Vec3::new(-1.0, -1.0, 4.0),
                Vec3::new(1.0, -1.0, 4.0),
                Vec3::new(0.0, 1.0, 4.0),
            ),
        ];
        let tree = TriangleAccel::build(tris, &AccelParams::default());
        // More than one chunk, alternating hits and misses.
        let rays: Vec<Ray> = (0..CHUNK + 100)
            .map(|i| {
                let x = if i % 2 == 0 { 0.0 } else { 5.0 };
                Ray::new(Vec3::new(x, -0.5, 0.0), Vec3::Z)
            })
            .collect();
        let mut out = vec![HitRecord::MISS; rays.len()];
        trace_into(&tree, &rays, Query::ClosestHit, &mut out);
        for (i, (r, o)) in rays.iter().zip(&out).enumerate() {
            assert_eq!(*o, trace_one(&tree, r, Query::ClosestHit));
            assert_eq!(o.is_hit(), i % 2 == 0);
        }
        assert_eq!(out[0], HitRecord { t: 2.0, tri: 0 });
        trace_into(&tree, &rays, Query::AnyHit, &mut out);
        assert_eq!(out[0], HitRecord::OCCLUDED);
        assert_eq!(out[1], HitRecord::MISS);
    }
}
