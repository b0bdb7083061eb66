//! Batch queries: many rays on the calling thread or in parallel work
//! items.

use super::Bvh;
use crate::isect::Hit;
use crate::kd::batch::in_parallel;
use crate::kd::NoCounters;
use crate::math::Ray;
use crate::simd::{dispatch, level, Kernel};

impl Bvh {
    /// Closest hits of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        in_parallel(rays, out, |rs, os| self.closest_hits_serial(rs, os));
    }

    /// Occlusion of many rays, in parallel; `out[i]` answers `rays[i]`.
    pub fn any_hits(&self, rays: &[Ray], out: &mut [bool]) {
        in_parallel(rays, out, |rs, os| self.any_hits_serial(rs, os));
    }

    /// Closest hits of many rays on the calling thread (for callers that
    /// run their own threads); `out[i]` answers `rays[i]`.
    pub fn closest_hits_serial(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        dispatch(
            level::AVX512,
            ClosestBatch {
                bvh: self,
                rays,
                out,
            },
        );
    }

    /// Occlusion of many rays on the calling thread; `out[i]` answers
    /// `rays[i]`.
    pub fn any_hits_serial(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        dispatch(
            level::AVX512,
            AnyBatch {
                bvh: self,
                rays,
                out,
            },
        );
    }
}

/// A batch of closest-hit walks in one dispatch.
struct ClosestBatch<'a> {
    bvh: &'a Bvh,
    rays: &'a [Ray],
    out: &'a mut [Option<Hit>],
}

impl Kernel for ClosestBatch<'_> {
    type Output = ();
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) {
        for (r, o) in self.rays.iter().zip(self.out.iter_mut()) {
            *o = self.bvh.walk_closest::<_, LEVEL>(r, &mut NoCounters);
        }
    }
}

/// A batch of any-hit walks in one dispatch.
struct AnyBatch<'a> {
    bvh: &'a Bvh,
    rays: &'a [Ray],
    out: &'a mut [bool],
}

impl Kernel for AnyBatch<'_> {
    type Output = ();
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) {
        for (r, o) in self.rays.iter().zip(self.out.iter_mut()) {
            *o = self.bvh.walk_any::<_, LEVEL>(r, &mut NoCounters);
        }
    }
}

impl Bvh {
    /// Closest hits of up to 8 rays (a packet's worth).
    pub fn closest_hit_packet(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.closest_hits_serial(rays, out);
    }

    /// Closest hits of up to 16 rays (a packet's worth).
    pub fn closest_hit_packet16(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.closest_hits_serial(rays, out);
    }
}
