//! The render loop of a guided render (`integrator::guiding`): iterations
//! of 1, 2, 4, ... samples per pixel, each sampling with the guide the
//! last one trained and training the next; the image is every
//! iteration's samples alike.
//!
//! Why every sample alike: an iteration's image is an unbiased estimate
//! whatever its guide, so any weights summing to one keep the image
//! unbiased. The paper keeps the last iteration alone, which throws away
//! about half the samples; weighting the iterations by the inverse of
//! their estimated variance (Müller's later practice) keeps the better
//! ones' share high, but needs each iteration's variance, and at a few
//! samples per pixel in a scene lit through a gap most pixels see no light
//! at all, so the estimate comes out far too low and the earliest, worst
//! iteration gets the most weight. Measured on the door-ajar kit scene
//! (64 spp, relative MSE): 3.0 with every sample alike, 5.7 with the last
//! iteration alone, 35 with inverse-variance weights estimated from each
//! iteration's two halves. Weighting by the samples is the inverse-variance
//! weighting of iterations whose samples are alike, and needs no estimate.
//!
//! The last iteration takes what is left of the render's samples once
//! another doubling would not fit (64 samples: 1, 2, 4, 8, 16 and 33).

use std::sync::atomic::AtomicU64;
use std::time::Instant;

use super::accumulate::Accumulated;
use super::pass::Run;
use super::plan::{Frame, PassPlan};
use super::samples::RoundSamples;
use super::settings::RenderSettings;
use super::stats::RenderStats;
use super::stop::Stop;
use super::watch::Progress;
use super::RenderResult;
use crate::cpu_time::process_cpu_time;
use crate::integrator::guiding::Guide;
use crate::world::World;

/// The samples per pixel of each iteration of a render of `spp`: 1, 2,
/// 4, ..., the last taking the rest once another doubling would not fit.
pub(super) fn iterations(spp: u32) -> Vec<u32> {
    let mut out = Vec::new();
    let (mut done, mut size) = (0u32, 1u32);
    while done < spp {
        let left = spp - done;
        let n = if left - size.min(left) < 2 * size {
            left
        } else {
            size
        };
        out.push(n);
        done += n;
        size = size.saturating_mul(2);
    }
    out
}

/// Renders `world` guided, as `render_world` renders unguided.
pub(super) fn render(
    world: &mut World,
    settings: &RenderSettings,
    progress: &(dyn Fn(Progress) + Sync),
    stats: RenderStats,
    start: Instant,
) -> RenderResult {
    let frame = Frame::plan(settings);
    let plan = PassPlan::new(settings);
    let mut acc = Accumulated::new(settings, &frame, stats);
    let stop = Stop { settings, start };
    let sizes = iterations(settings.spp.max(1));
    let mut guide = Guide::new(world.accel.bounds());
    let render_start = Instant::now();
    let cpu_start = process_cpu_time();
    let mut first_sample = 0u32;
    let passes = sizes.len() as u32;
    for (pass, &n) in (0u32..).zip(&sizes) {
        if stop.cancelled() || (pass > 0 && stop.out_of_time()) {
            acc.stats.stopped_early = true;
            break;
        }
        world.swap_guide(Some(guide));
        let range = first_sample..first_sample + n;
        let run = Run {
            world: &*world,
            settings,
            frame: Frame::plan(settings),
            stop: Stop { settings, start },
            progress,
            rays: AtomicU64::new(0),
        };
        let outs = run.pass(pass, passes, RoundSamples::every(range.clone()));
        let complete = outs
            .iter()
            .zip(&frame.tiles)
            .all(|(o, t)| o.as_ref().is_some_and(|o| o.pixels_done == t.pixels()));
        if !complete {
            // As unguided renders do: an interrupted first pass keeps the
            // pixels it finished, a later one is dropped whole.
            if pass == 0 {
                acc.keep_finished(&frame, &outs);
                acc.add(settings, outs);
            }
            acc.stats.stopped_early = true;
            world.swap_guide(None);
            break;
        }
        acc.add(settings, outs);
        acc.stats.passes += 1;
        acc.stats.spp += n;
        guide = world
            .swap_guide(None)
            .expect("the guide was set for the iteration")
            .next(n);
        first_sample += n;
    }
    acc.stats.render_time = render_start.elapsed();
    acc.stats.render_cpu_time = process_cpu_time().saturating_sub(cpu_start);
    acc.finish(world, settings, &frame, &plan)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iterations_double_and_the_last_takes_the_rest() {
        assert_eq!(iterations(1), vec![1]);
        assert_eq!(iterations(2), vec![2]);
        assert_eq!(iterations(3), vec![1, 2]);
        assert_eq!(iterations(64), vec![1, 2, 4, 8, 16, 33]);
        assert_eq!(iterations(100), vec![1, 2, 4, 8, 16, 69]);
        for spp in 1..300 {
            assert_eq!(iterations(spp).iter().sum::<u32>(), spp);
        }
    }
}
