//! Batch queries: many rays on the calling thread or in parallel work
//! items.

use super::packet::{Answer, SWITCH};
use super::Bvh;
use crate::isect::Hit;
use crate::kd::batch::in_parallel;
use crate::kd::NoCounters;
use crate::math::Ray;
use crate::simd::{dispatch, Kernel};

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
            self.max_level,
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
            self.max_level,
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
    /// Closest hits of up to [`crate::PACKET`] (eight) rays traced as one
    /// packet (e.g. a 4x2 pixel tile of camera rays); `out[i]` answers
    /// `rays[i]` exactly as [`Bvh::closest_hit`] would. See the `packet`
    /// module for the walk.
    ///
    /// # Panics
    /// If there are more than eight rays or `out` differs in length.
    pub fn closest_hit_packet(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET8, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        dispatch(
            self.max_level,
            PacketQuery {
                bvh: self,
                wide16: false,
                switch: SWITCH,
                rays,
                out,
            },
        );
    }

    /// Closest hits of up to [`crate::PACKET16`] (sixteen) rays traced as
    /// one packet (e.g. a 4x4 pixel tile); `out[i]` answers `rays[i]`
    /// exactly as [`Bvh::closest_hit`] would. With AVX-512 the sixteen rays
    /// share one walk in sixteen-lane registers; with AVX2 in two
    /// eight-lane halves.
    ///
    /// # Panics
    /// If there are more than sixteen rays or `out` differs in length.
    pub fn closest_hit_packet16(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET16, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        dispatch(
            self.max_level,
            PacketQuery {
                bvh: self,
                wide16: true,
                switch: SWITCH,
                rays,
                out,
            },
        );
    }

    /// Whether each of up to [`crate::PACKET16`] (sixteen) rays hits
    /// anything, the rays traced as one packet by the closest-hit packet
    /// walk with each lane ending at its first hit; `out[i]` answers
    /// `rays[i]` exactly as [`Bvh::any_hit`] would. Shadow rays from one
    /// pixel's samples towards one light share the packet's boxes.
    ///
    /// # Panics
    /// If there are more than sixteen rays or `out` differs in length.
    pub fn any_hit_packet16(&self, rays: &[Ray], out: &mut [bool]) {
        assert!(rays.len() <= PACKET16, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        dispatch(
            self.max_level,
            PacketQuery {
                bvh: self,
                wide16: true,
                switch: SWITCH,
                rays,
                out,
            },
        );
    }
}

/// Rays in an eight-ray packet.
const PACKET8: usize = 8;

/// Rays in a sixteen-ray packet.
const PACKET16: usize = super::packet::LANES;

/// A packet walk in one dispatch: closest hits (`A = Option<Hit>`) or
/// any hits (`A = bool`).
pub(super) struct PacketQuery<'a, A> {
    pub(super) bvh: &'a Bvh,
    /// Sixteen lanes (else eight).
    pub(super) wide16: bool,
    /// Nodes and leaves that at most this many rays reach are finished
    /// ray by ray.
    pub(super) switch: u32,
    pub(super) rays: &'a [Ray],
    pub(super) out: &'a mut [A],
}

impl<A: Answer> Kernel for PacketQuery<'_, A> {
    type Output = ();
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) {
        // SAFETY: the level's instructions (the caller's contract).
        unsafe {
            self.bvh
                .trace_packet::<LEVEL, A>(self.wide16, self.switch, self.rays, self.out)
        }
    }
}
