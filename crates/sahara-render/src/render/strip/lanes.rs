//! The path tracer's lane loop (`path` with paths in SIMD lanes): the
//! strip's samples go to [`PathLanes`] as one queue in camera-packet
//! order, which its packets of 8 or 16 lanes take in turn.

use glam::Vec3;

use super::{Slots, StripRound};
use crate::integrator::lanes::{LaneSample, PathLanes};
use crate::integrator::laps::Laps;
use crate::integrator::{AuxSample, TraceStats};
use crate::world::World;

/// The lane loop's buffers, kept from strip to strip.
#[derive(Default)]
pub(super) struct Lanes {
    /// The strip's samples, in camera-packet order.
    samples: Vec<LaneSample>,
    /// Each sample's slot.
    slot: Vec<u32>,
    radiance: Vec<Vec3>,
    aux: Vec<AuxSample>,
    paths: PathLanes,
}

impl Lanes {
    /// Traces the round's samples in lanes, into their slots. The queue is
    /// in the stepped loop's camera-packet order: 4x4 pixel blocks, the
    /// pixels of a block in Morton order, each pixel's samples together;
    /// so a packet holds one pixel's samples, or those of a 2x2 block's
    /// pixels when each has few, whose rays leave close together. Lanes
    /// are refilled from the queue as their paths end if `refill`.
    pub(super) fn trace(
        &mut self,
        slots: &mut Slots,
        world: &World,
        round: &StripRound,
        stats: &mut TraceStats,
        refill: bool,
    ) {
        let aux = round.aux();
        self.samples.clear();
        let samples = &mut self.samples;
        slots.in_camera_packet_order(round, &mut self.slot, |sampler, ray, time| {
            samples.push(LaneSample { ray, time, sampler })
        });
        self.radiance.clear();
        self.radiance.resize(self.samples.len(), Vec3::ZERO);
        self.aux.clear();
        if aux {
            self.aux.resize(self.samples.len(), AuxSample::default());
        }
        self.paths.trace(
            &round.settings.integrator,
            world,
            &self.samples,
            &mut self.radiance,
            aux.then_some(&mut self.aux[..]),
            stats,
            refill,
        );
        for (&l, &k) in self.radiance.iter().zip(&self.slot) {
            slots.radiance[k as usize] = l;
        }
        if aux {
            for (a, &k) in self.aux.iter().zip(&self.slot) {
                slots.aux[k as usize] = *a;
            }
        }
    }

    /// The lanes' time tracing and shading since last asked.
    pub(super) fn take_times(&mut self) -> Laps {
        self.paths.take_times()
    }
}
