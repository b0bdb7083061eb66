//! Traversal work per ray, next to what the SAH predicts.

use rayon::prelude::*;
use sahara_kd::{Ray, TraversalCounters, TriangleAccel};

use super::trace::{Query, CHUNK};

/// Traversal work summed over a set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CountTotals {
    /// Rays traced.
    pub rays: u64,
    /// Rays whose interval meets the root cell (the others do no work).
    pub rays_meeting_root: u64,
    /// Nodes, leaves and triangle tests over all rays.
    pub work: TraversalCounters,
}

impl std::ops::Add for CountTotals {
    type Output = CountTotals;
    fn add(mut self, o: CountTotals) -> CountTotals {
        self.rays += o.rays;
        self.rays_meeting_root += o.rays_meeting_root;
        self.work += o.work;
        self
    }
}

/// True if the traversal enters the root cell for `ray` (it returns at once
/// otherwise).
fn meets_root(tree: &TriangleAccel, ray: &Ray) -> bool {
    ray.is_valid()
        && ray.tmin <= ray.tmax
        && !tree.bounds().is_empty()
        && tree
            .bounds()
            .intersect_ray(ray.origin, glam::Vec3::ONE / ray.dir, ray.tmin, ray.tmax)
            .is_some()
}

/// Count the traversal work of `rays` on the current rayon pool.
pub fn count_set(tree: &TriangleAccel, rays: &[Ray], query: Query) -> CountTotals {
    rays.par_chunks(CHUNK)
        .with_max_len(1) // one job per chunk, as in `trace_into`
        .map(|chunk| {
            let mut t = CountTotals {
                rays: chunk.len() as u64,
                ..Default::default()
            };
            for r in chunk {
                t.rays_meeting_root += meets_root(tree, r) as u64;
                match query {
                    Query::ClosestHit => {
                        tree.closest_hit_counted(r, &mut t.work);
                    }
                    Query::AnyHit => {
                        tree.any_hit_counted(r, &mut t.work);
                    }
                }
            }
            t
        })
        .reduce(CountTotals::default, |a, b| a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use sahara_kd::{AccelParams, Triangle};

    #[test]
    fn counts_add_up_and_misses_of_the_root_test_no_triangle() {
        let tris: Vec<Triangle> = (0..50)
            .map(|i| {
                let z = 2.0 + i as f32;
                Triangle::new(
                    Vec3::new(-1.0, -1.0, z),
                    Vec3::new(1.0, -1.0, z),
                    Vec3::new(0.0, 1.0, z),
                )
            })
            .collect();
        for params in [AccelParams::default(), AccelParams::kd(Default::default())] {
            let tree = TriangleAccel::build(tris.clone(), &params);
            let hit = Ray::new(Vec3::new(0.0, -0.5, 0.0), Vec3::Z);
            let away = Ray::new(Vec3::new(0.0, -0.5, 0.0), Vec3::NEG_Z);
            let t = count_set(&tree, &[hit, away], Query::ClosestHit);
            assert_eq!((t.rays, t.rays_meeting_root), (2, 1));
            let mut one = TraversalCounters::default();
            tree.closest_hit_counted(&hit, &mut one);
            // A ray missing the root cell: no leaf, no triangle; the kd-tree
            // does not start, the hierarchy tests the root's children once.
            let mut missed = TraversalCounters::default();
            tree.closest_hit_counted(&away, &mut missed);
            assert_eq!((missed.leaves, missed.triangles), (0, 0));
            assert!(missed.inner <= 1);
            assert_eq!(t.work.triangles, one.triangles);
            assert_eq!(t.work.leaves, one.leaves);
            assert_eq!(t.work.inner, one.inner + missed.inner);
            assert!(one.triangles >= 1 && one.leaves >= 1);
            let any = count_set(&tree, &[hit], Query::AnyHit);
            assert!(any.work.triangles <= one.triangles);
        }
    }
}
