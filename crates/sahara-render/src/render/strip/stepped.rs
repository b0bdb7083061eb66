//! The stepped integrators' sample loop (`path`, `distribution`): the
//! wavefront ([`Wavefront`]) traces every path of the strip a step at a
//! time, each step's rays as one batch.

use super::{Slots, StripRound};
use crate::integrator::guiding;
use crate::integrator::laps::Laps;
use crate::integrator::wavefront::Wavefront;
use crate::integrator::{PathState, TraceStats};
use crate::world::World;

/// The stepped loop's buffers, kept from strip to strip.
#[derive(Default)]
pub(super) struct Stepped {
    /// The strip's paths, in camera-packet order.
    paths: Vec<PathState>,
    /// Each path's slot.
    slot: Vec<u32>,
    wavefront: Wavefront,
}

impl Stepped {
    /// Traces the round's paths as batches, in camera-packet order: 4x4
    /// pixel blocks, the pixels of a block in Morton order (2x2 blocks of
    /// 2x2), each pixel's samples together. A run of 16 paths is then 16
    /// samples of one pixel, or the samples of a 2x2 block's pixels when a
    /// pixel takes 4: their camera rays, shadow rays and bounces start close
    /// together and share the tree's cells (figures in
    /// docs/performance.md, "What a packet of one pixel's samples would
    /// share"). The order changes no path's arithmetic; each path's
    /// radiance goes to its slot.
    pub(super) fn trace(
        &mut self,
        slots: &mut Slots,
        world: &World,
        round: &StripRound,
        stats: &mut TraceStats,
    ) {
        let aux = round.aux();
        self.paths.clear();
        let paths = &mut self.paths;
        slots.in_camera_packet_order(round, &mut self.slot, |sampler, ray, time| {
            paths.push(PathState::new(ray, time, sampler).with_aux(aux))
        });
        let guide = world.guide();
        if guide.is_some() {
            guiding::begin(&mut self.paths);
        }
        self.wavefront
            .trace(&round.settings.integrator, world, stats, &mut self.paths);
        if let Some(g) = guide {
            guiding::finish(g, &self.paths);
        }
        for (p, &k) in self.paths.iter().zip(&self.slot) {
            slots.radiance[k as usize] = p.l;
        }
        if aux {
            for (p, &k) in self.paths.iter().zip(&self.slot) {
                slots.aux[k as usize] = p.aux;
            }
        }
    }

    /// The wavefront's time tracing and shading since last asked.
    pub(super) fn take_times(&mut self) -> Laps {
        self.wavefront.take_times()
    }
}
