//! The render loop of a guided render (`integrator::guiding`): iterations
//! of 1, 2, 4, ... samples per pixel, each sampling with the guide the
//! last one trained and training the next, and the image made of all of
//! them weighted by the inverse of their variance.
//!
//! Why that combination: an iteration's image is an unbiased estimate
//! whatever its guide, so any weights that sum to one keep the image
//! unbiased, and those inverse to each image's variance make the sum's
//! variance smallest. The paper keeps the last iteration alone, which
//! throws away about half the samples; Müller's later practice weights the
//! iterations by their variance, which keeps what the early iterations
//! paid for where their guides were already good. An iteration's variance
//! is estimated from its two halves (the same guide, disjoint samples):
//! the squared difference of the halves' images over four, relative to
//! the pixel's value, averaged over the image. An iteration of a single
//! sample per pixel has no halves and weighs nothing, unless it is the
//! only one.
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
use crate::film::sums::SumBuffer;
use crate::integrator::guiding::Guide;
use crate::math::warp::luminance;
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

/// One iteration's image and its estimated variance (None: no halves).
struct Iteration {
    sums: SumBuffer,
    variance: Option<f64>,
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
    let window = frame.window;
    let stop = Stop { settings, start };
    let sizes = iterations(settings.spp.max(1));
    let mut guide = Guide::new(world.accel.bounds());
    let mut done: Vec<Iteration> = Vec::new();
    let render_start = Instant::now();
    let cpu_start = process_cpu_time();
    let mut first_sample = 0u32;
    let passes: u32 = sizes.iter().map(|&n| if n > 1 { 2 } else { 1 }).sum();
    let mut pass = 0u32;
    'iterations: for &n in &sizes {
        world.swap_guide(Some(guide));
        let halves = if n > 1 {
            let mid = first_sample + n / 2;
            vec![first_sample..mid, mid..first_sample + n]
        } else {
            vec![first_sample..first_sample + n]
        };
        let mut images = Vec::new();
        for range in halves {
            if stop.cancelled() || (pass > 0 && stop.out_of_time()) {
                acc.stats.stopped_early = true;
                break 'iterations;
            }
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
                if pass == 0 {
                    acc.keep_finished(&frame, &outs);
                    acc.add(settings, outs);
                }
                acc.stats.stopped_early = true;
                break 'iterations;
            }
            let mut half = SumBuffer::new(window.x0, window.y0, window.width(), window.height());
            for o in outs.iter().flatten() {
                half.add(&o.sums);
            }
            images.push(half);
            acc.add(settings, outs);
            acc.stats.passes += 1;
            acc.stats.spp += range.len() as u32;
            pass += 1;
        }
        let variance = (images.len() == 2).then(|| relative_variance(&images[0], &images[1]));
        let mut sums = images.swap_remove(0);
        if let Some(other) = images.first() {
            sums.add(other);
        }
        done.push(Iteration { sums, variance });
        guide = world
            .swap_guide(None)
            .expect("the guide was set for the iteration")
            .next(n);
        first_sample += n;
    }
    world.swap_guide(None);
    if !done.is_empty() {
        combine(&mut acc.sums, &done);
    }
    acc.stats.render_time = render_start.elapsed();
    acc.stats.render_cpu_time = process_cpu_time().saturating_sub(cpu_start);
    acc.finish(world, settings, &frame, &plan)
}

/// The variance of the mean of two halves' images relative to the
/// pixel's value, averaged over the image: per pixel `(a − b)² / 4`
/// over `m² + 0.01` (luminance; `m` their mean).
fn relative_variance(a: &SumBuffer, b: &SumBuffer) -> f64 {
    let mut sum = 0.0f64;
    for (pa, pb) in a.sums.iter().zip(&b.sums) {
        let (la, lb) = (luminance(pa.value()) as f64, luminance(pb.value()) as f64);
        let m = 0.5 * (la + lb);
        sum += 0.25 * (la - lb).powi(2) / (m * m + 0.01);
    }
    sum / a.sums.len().max(1) as f64
}

/// Replaces the image's sums by the iterations' images weighted by the
/// inverse of their variance (each pixel keeps its total filter weight,
/// its radiance sums set to that weight times the combined value).
fn combine(sums: &mut SumBuffer, done: &[Iteration]) {
    let mut weights: Vec<f64> = done
        .iter()
        .map(|it| match it.variance {
            Some(v) if v > 0.0 => 1.0 / v,
            _ => 0.0,
        })
        .collect();
    let total: f64 = weights.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        // No estimate (a render of one iteration, or an image without
        // noise): every sample alike.
        return;
    }
    for w in &mut weights {
        *w /= total;
    }
    for (k, px) in sums.sums.iter_mut().enumerate() {
        if px.weight <= 0 {
            continue;
        }
        let mut value = [0.0f64; 3];
        for (it, &w) in done.iter().zip(&weights) {
            let p = &it.sums.sums[k];
            if w == 0.0 || p.weight <= 0 {
                continue;
            }
            for (c, v) in value.iter_mut().enumerate() {
                *v += w * p.rgb[c] as f64 / p.weight as f64;
            }
        }
        let weight = px.weight as f64;
        for (c, v) in value.iter().enumerate() {
            px.rgb[c] = (v * weight) as i128;
        }
    }
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
