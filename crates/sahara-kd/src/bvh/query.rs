//! Closest-hit, any-hit and all-hits queries of one ray, dispatched to
//! the walk compiled for the best instruction-set level the CPU has.

use super::node::{is_leaf, leaf_parts};
use super::walk::{portable_step, BoxRay, Stack};
use super::Bvh;
use crate::isect::{Hit, RayShear};
use crate::kd::{Counters, NoCounters};
use crate::math::Ray;
use crate::simd::{dispatch, Kernel};

impl Bvh {
    /// The closest hit with `t` in `(ray.tmin, ray.tmax]`; among hits at the
    /// same `t`, the one with the smallest triangle index.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_counted(ray, &mut NoCounters)
    }

    /// [`Bvh::closest_hit`], counting the work done (wide nodes as inner
    /// nodes).
    pub fn closest_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> Option<Hit> {
        dispatch(
            self.max_level,
            Closest {
                bvh: self,
                ray,
                counters,
            },
        )
    }

    /// True if any triangle is hit with `t` in `(ray.tmin, ray.tmax]`
    /// (occlusion; stops at the first hit found).
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.any_hit_counted(ray, &mut NoCounters)
    }

    /// [`Bvh::any_hit`], counting the work done.
    pub fn any_hit_counted<C: Counters>(&self, ray: &Ray, counters: &mut C) -> bool {
        dispatch(
            self.max_level,
            Any {
                bvh: self,
                ray,
                counters,
            },
        )
    }

    /// Every hit with `t` in `(ray.tmin, ray.tmax]`, into `hits` (cleared
    /// first): each triangle once, ordered by `t`, then by triangle index,
    /// as [`crate::KdTree::all_hits`].
    pub fn all_hits(&self, ray: &Ray, hits: &mut Vec<Hit>) {
        hits.clear();
        if self.nodes.is_empty() || !ray.is_valid() || ray.tmin > ray.tmax {
            return;
        }
        let r = BoxRay::new(ray, self.scale);
        let shear = RayShear::from_ray(ray);
        let mut stack = Stack::new();
        let mut next = Some(0u32);
        while let Some(c) = next.take().or_else(|| stack.pop().map(|e| e.0)) {
            if !is_leaf(c) {
                // SAFETY: inner references name nodes the build wrote.
                portable_step::<false>(unsafe { self.node(c) }, &r, ray.tmax, &mut stack);
                continue;
            }
            let (line, count) = leaf_parts(c);
            // SAFETY: leaf references name leaves the build wrote.
            let q = unsafe { self.quad(line) };
            for l in 0..count {
                if let Some(h) = shear.intersect(&q.triangle(l), ray.tmin, ray.tmax) {
                    hits.push(Hit {
                        t: h.t,
                        tri: q.tri[l],
                        u: h.u,
                        v: h.v,
                    });
                }
            }
        }
        // A triangle referenced by several leaves is found in each.
        hits.sort_unstable_by_key(|h| h.tri);
        hits.dedup_by_key(|h| h.tri);
        hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
    }
}

/// [`Bvh::closest_hit_counted`] as a kernel for [`dispatch`].
pub(crate) struct Closest<'a, C> {
    pub(crate) bvh: &'a Bvh,
    pub(crate) ray: &'a Ray,
    pub(crate) counters: &'a mut C,
}

impl<C: Counters> Kernel for Closest<'_, C> {
    type Output = Option<Hit>;
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) -> Option<Hit> {
        self.bvh.walk_closest::<C, LEVEL>(self.ray, self.counters)
    }
}

/// [`Bvh::any_hit_counted`] as a kernel for [`dispatch`].
pub(crate) struct Any<'a, C> {
    pub(crate) bvh: &'a Bvh,
    pub(crate) ray: &'a Ray,
    pub(crate) counters: &'a mut C,
}

impl<C: Counters> Kernel for Any<'_, C> {
    type Output = bool;
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) -> bool {
        self.bvh.walk_any::<C, LEVEL>(self.ray, self.counters)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::bvh::{BvhBuilder, BvhParams};
    use crate::simd::level;
    use crate::test_support::{floats, soup};
    use glam::Vec3;

    fn builders() -> [BvhParams; 3] {
        [
            BvhParams::new(BvhBuilder::Binned),
            BvhParams::new(BvhBuilder::Spatial),
            BvhParams::new(BvhBuilder::FromKd),
        ]
    }

    /// Every builder and every level's walk agrees with brute force bit
    /// for bit.
    #[test]
    fn every_builder_and_level_agrees_with_brute_force() {
        let mut f = floats(99);
        let tris = soup(&mut f, 3000, 0.6);
        for params in builders() {
            let bvh = Bvh::build(tris.clone(), &params);
            for k in 0..3000 {
                let o = Vec3::new(f(), f(), f()) * 5.0;
                let ray = match k % 3 {
                    0 => Ray::new(o, Vec3::new(f(), f(), f())),
                    1 => Ray::with_interval(o, Vec3::new(f(), f(), f()), 0.5, 3.0),
                    _ => Ray::new(o, Vec3::new(0.0, f(), 0.0)),
                };
                let want = brute::closest_hit(&tris, &ray);
                assert_eq!(bvh.closest_hit(&ray), want, "{:?} ray {k}", params.builder);
                assert_eq!(bvh.any_hit(&ray), want.is_some());
                for top in [level::PORTABLE, level::AVX2, level::AVX512] {
                    let c = &mut NoCounters;
                    let q = Closest {
                        bvh: &bvh,
                        ray: &ray,
                        counters: c,
                    };
                    assert_eq!(dispatch(top, q), want, "level {top} ray {k}");
                    let c = &mut NoCounters;
                    let q = Any {
                        bvh: &bvh,
                        ray: &ray,
                        counters: c,
                    };
                    assert_eq!(dispatch(top, q), want.is_some(), "level {top} ray {k}");
                }
            }
        }
    }

    #[test]
    fn all_hits_agree_with_brute_force() {
        let mut f = floats(7);
        let tris = soup(&mut f, 2000, 0.5);
        let mut hits = Vec::new();
        for params in builders() {
            let bvh = Bvh::build(tris.clone(), &params);
            for k in 0..1000 {
                let o = Vec3::new(f(), f(), f()) * 5.0;
                let ray = Ray::new(o, Vec3::new(f(), f(), f()));
                bvh.all_hits(&ray, &mut hits);
                assert_eq!(hits, brute::all_hits(&tris, &ray), "ray {k}");
            }
        }
    }

    #[test]
    fn empty_and_tiny_hierarchies() {
        let bvh = Bvh::build(Vec::new(), &BvhParams::default());
        assert_eq!(bvh.closest_hit(&Ray::new(Vec3::ZERO, Vec3::X)), None);
        let t = crate::Triangle::new(
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
        );
        let bvh = Bvh::build(vec![t], &BvhParams::default());
        let h = bvh.closest_hit(&Ray::new(Vec3::ZERO, Vec3::X)).unwrap();
        assert_eq!((h.t, h.tri), (1.0, 0));
    }
}
