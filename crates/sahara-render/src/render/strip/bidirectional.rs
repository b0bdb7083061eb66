//! The bidirectional integrators' sample loop (`bdpt`, `lightpath`): the
//! strip's camera samples go to [`BdptBatch`], which traces their camera
//! and light subpaths in batches.

use glam::Vec3;

use super::{Slots, StripRound};
use crate::integrator::bdpt::batch::{BdptBatch, CameraSample};
use crate::integrator::bdpt::Strategies;
use crate::integrator::laps::Laps;
use crate::integrator::TraceStats;
use crate::world::World;

/// The bidirectional loop's buffers, kept from strip to strip.
#[derive(Default)]
pub(super) struct Bidirectional {
    /// The strip's camera samples, pixel by pixel (rows top to bottom).
    cameras: Vec<CameraSample>,
    /// Each camera sample's slot.
    slot: Vec<u32>,
    /// Each camera sample's radiance.
    samples: Vec<Vec3>,
    bdpt: BdptBatch,
}

impl Bidirectional {
    /// Traces the round's samples, paths of at most `max_depth`
    /// scattering events with `strategies`, into their slots; the light
    /// tracing contributions go to the slots' splats, sample by sample.
    pub(super) fn trace(
        &mut self,
        slots: &mut Slots,
        world: &World,
        round: &StripRound,
        max_depth: u32,
        strategies: Strategies,
        stats: &mut TraceStats,
    ) {
        self.cameras_in_pixel_order(slots, round);
        self.samples.clear();
        self.samples.resize(self.cameras.len(), Vec3::ZERO);
        self.bdpt.trace(
            world,
            max_depth,
            strategies,
            round.film(),
            &self.cameras,
            &mut self.samples,
            stats,
            &mut slots.splats,
        );
        for (&l, &k) in self.samples.iter().zip(&self.slot) {
            slots.radiance[k as usize] = l;
        }
    }

    /// The round's camera samples, pixel by pixel, rows top to bottom,
    /// with the slot of each.
    fn cameras_in_pixel_order(&mut self, slots: &mut Slots, round: &StripRound) {
        self.cameras.clear();
        self.slot.clear();
        for (x, y) in round.pixels.iter() {
            for g in round.samples.of(x, y) {
                let (sampler, pos, ray, time) = round.cameras.at(x, y, g);
                let k = slots.slot(round, x, y, g);
                slots.pos[k] = pos;
                self.slot.push(k as u32);
                self.cameras.push(CameraSample { ray, time, sampler });
            }
        }
    }

    /// The batch's time tracing and shading since last asked.
    pub(super) fn take_times(&mut self) -> Laps {
        self.bdpt.take_times()
    }
}
