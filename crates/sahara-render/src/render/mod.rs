//! The render loop: progressive passes of tiles rendered in parallel.
//!
//! [`render_world`] plans the frame's tiles and the passes its sample
//! range meets (`plan`); each pass, until the render stops (`stop`),
//! renders every tile on the thread pool (`pass`), a tile a strip of rows
//! at a time (`tile`), each strip's samples traced by the integrator's
//! sample loop (`strip`); the tiles' sums are added up (`accumulate`),
//! adaptive sampling chooses the next round's samples (`adaptive`), the
//! caller sees progress and previews (`watch`), and the sums become the
//! image (`result`). The settings (`settings`), the counts (`stats`), the
//! render passes (`aux`, `ids`), the photon mapper's own loop (`sppm`) and
//! the frame digest of a render farm's parts (`digest`) sit beside them.
//!
//! Determinism: the same seed gives the same image bit for bit whatever
//! the number of threads, the order tiles finish in, or the split of the
//! frame into windows and sample ranges rendered separately and added up.
//! Three rules make it so, each stated where it is kept:
//! - every random number of a sample is a function of the seed, the pixel,
//!   the sample's number over all passes and the dimension (`samples`: which
//!   samples a pass draws);
//! - a sample loop may trace a strip's samples in any order and grouping,
//!   but a sample's result depends on it alone and goes to its slot
//!   (`strip`);
//! - samples are splatted with the filter into per-tile buffers (a tile
//!   plus a margin of the filter's radius) of exact fixed-point sums
//!   ([`crate::film::sums`]) that are added into the image after each
//!   pass: integer sums do not depend on how samples are grouped (`tile`,
//!   `accumulate`).

mod accumulate;
pub mod adaptive;
pub mod aux;
pub mod digest;
mod guided;
mod ids;
mod pass;
mod plan;
mod result;
mod samples;
mod settings;
mod sppm;
mod stats;
mod stop;
mod strip;
mod tile;
mod watch;

use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use crate::cpu_time::process_cpu_time;
use crate::integrator::{Integrator, SettingsError};
use crate::scene::Scene;
use crate::world::World;
use accumulate::Accumulated;
pub use adaptive::AdaptiveStats;
pub use aux::{Aov, Aux, AuxImages, AuxSums};
use pass::Run;
use plan::{Frame, PassPlan};
use result::develop;
pub use result::{cost_maps, CostMaps, RenderResult};
use sahara_kd::Isa;
use samples::RoundSamples;
pub use settings::{PathLoop, RenderSettings, UNLIMITED_SPP};
pub use stats::{RenderStats, TimeShares, TimeSplit};
use stop::Stop;
use watch::Previews;
pub use watch::{Preview, Progress};

/// Renders `scene`; `progress` is called from worker threads as tiles
/// finish (its calls may interleave; the image does not depend on them).
/// Settings the integrator cannot honour are refused before anything is
/// built ([`RenderSettings::check`]).
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RenderResult, SettingsError> {
    render_watched(scene, settings, progress, None)
}

/// Renders `scene` as [`render`] does, also handing the image of the passes
/// completed so far to `preview` between passes, at most once per
/// `preview.every` (a preview does not change the final image).
pub fn render_watched(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(Progress) + Sync),
    preview: Option<Preview<'_>>,
) -> Result<RenderResult, SettingsError> {
    settings.check_for(scene)?;
    let start = Instant::now();
    let mut world = World::with_light_sampler(scene, &settings.build, settings.light_sampler);
    let build_time = start.elapsed();
    render_world(&mut world, settings, progress, preview, start, build_time)
}

/// Renders a scene already prepared for tracing (`world`, built with
/// `settings.build`), as [`render_watched`] does after its build; `start`
/// is when the render began (its time limit counts from there) and
/// `build_time` what the build took. The criterion benchmarks render this
/// way to time the render loop without the tree builds.
///
/// The steps: plan the frame's tiles ([`Frame`]) and passes
/// ([`PassPlan`]); per pass, stop on cancel or time limit ([`Stop`]),
/// render the tiles ([`Run::pass`]), keep what an interrupted first pass
/// finished, add the tiles' sums ([`Accumulated::add`]), run the adaptive
/// round ([`Accumulated::adaptive_round`]) and show a preview
/// ([`Previews`]); then develop the image ([`Accumulated::finish`]).
/// The widest instructions the sample loop's ray queries and film splats
/// use. The loop is scalar code (shading, sampling, light choice) with
/// walks and splats in it; on Intel's server cores a 512-bit instruction
/// lowers the core's clock for about a millisecond after it, so a few of
/// them slow all of that code. Measured on an Ice Lake Xeon, whole renders
/// at 256 bits were 1.07-1.22x as fast as with AVX-512 walks and splats
/// (`docs/performance.md`); images are the same bit for bit.
pub(crate) const SAMPLE_LOOP_ISA: Isa = Isa::Avx2;

#[doc(hidden)]
pub fn render_world(
    world: &mut World,
    settings: &RenderSettings,
    progress: &(dyn Fn(Progress) + Sync),
    preview: Option<Preview<'_>>,
    start: Instant,
    build_time: Duration,
) -> Result<RenderResult, SettingsError> {
    settings.check_for(world.scene)?;
    world.set_film(settings.height.max(1), u64::from(settings.spp.max(1)));
    world.accel.set_isa(SAMPLE_LOOP_ISA);
    world.set_light_sampler(settings.light_sampler);
    let stats = RenderStats {
        build_time,
        layout: world.accel.layout(),
        ..Default::default()
    };
    if settings.guided(world.has_media()) {
        return Ok(guided::render(world, settings, progress, stats, start));
    }
    let world = &*world;
    let mut previews = Previews::new(preview);
    if let Integrator::Sppm {
        max_depth,
        radius,
        photons,
    } = settings.integrator
    {
        let params = sppm::Params {
            max_depth,
            radius,
            photons: photons as u64,
        };
        return Ok(sppm::render(
            world,
            settings,
            params,
            progress,
            &mut previews,
            stats,
            start,
        ));
    }
    let run = Run {
        world,
        settings,
        frame: Frame::plan(settings),
        stop: Stop { settings, start },
        progress,
        rays: AtomicU64::new(0),
    };
    let plan = PassPlan::new(settings);
    let mut acc = Accumulated::new(settings, &run.frame, stats);
    let render_start = Instant::now();
    let cpu_start = process_cpu_time();
    for n in 0..plan.passes {
        if run.stop.cancelled() || (n > 0 && run.stop.out_of_time()) {
            acc.stats.stopped_early = true;
            break;
        }
        let pass = plan.first_pass + n;
        let indices = plan.indices(pass);
        let samples = match &acc.convergence {
            Some(c) => RoundSamples::Adaptive(c),
            None => RoundSamples::every(plan.numbered(pass)),
        };
        let outs = run.pass(n, plan.passes, samples);
        let complete = outs
            .iter()
            .zip(&run.frame.tiles)
            .all(|(o, t)| o.as_ref().is_some_and(|o| o.pixels_done == t.pixels()));
        if !complete && n > 0 {
            // A later pass is dropped whole: every pixel keeps the same
            // number of samples.
            acc.stats.stopped_early = true;
            break;
        }
        if !complete {
            // The first pass, interrupted: keep the window's pixels it finished.
            acc.keep_finished(&run.frame, &outs);
        }
        acc.add(settings, outs);
        if !complete {
            acc.stats.stopped_early = true;
            break;
        }
        acc.stats.passes += 1;
        acc.stats.spp += indices.len() as u32;
        let all_converged = acc.adaptive_round();
        if n + 1 < plan.passes {
            previews.offer(|| {
                let mut snapshot = acc.stats;
                snapshot.render_time = render_start.elapsed();
                snapshot.stopped_early = true;
                develop(
                    acc.sums.clone(),
                    acc.aux.clone(),
                    None,
                    snapshot,
                    settings,
                    None,
                )
            });
        }
        if all_converged {
            break;
        }
    }
    acc.stats.render_time = render_start.elapsed();
    acc.stats.render_cpu_time = process_cpu_time().saturating_sub(cpu_start);
    Ok(acc.finish(world, settings, &run.frame, &plan))
}
