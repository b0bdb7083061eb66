//! The sample loop of the integrators traced one sample at a time: each
//! sample from its camera ray to its end ([`Integrator::li_splats`]), in
//! slot order.
//!
//! [`Integrator::li_splats`]: crate::integrator::Integrator::li_splats

use super::{Slots, StripRound};
use crate::integrator::{AuxSample, Context, TraceStats};
use crate::world::World;

/// Traces the round's samples one at a time into their slots.
pub(super) fn trace(slots: &mut Slots, world: &World, round: &StripRound, stats: &mut TraceStats) {
    let (integrator, aux_on, film) = (&round.settings.integrator, round.aux(), round.film());
    for (x, y) in round.pixels.iter() {
        for g in round.samples.of(x, y) {
            let (sampler, pos, ray, time) = round.cameras.at(x, y, g);
            let mut ctx = Context {
                world,
                sampler,
                stats,
            };
            let k = slots.slot(round, x, y, g);
            slots.pos[k] = pos;
            let mut aux = AuxSample {
                open: aux_on,
                ..AuxSample::default()
            };
            slots.radiance[k] =
                integrator.li_splats(&mut ctx, &ray, time, film, &mut slots.splats, &mut aux);
            if aux_on {
                slots.aux[k] = aux;
            }
        }
    }
}
