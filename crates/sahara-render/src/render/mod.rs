//! The render loop: progressive passes of tiles rendered in parallel.
//!
//! Determinism: every random number is a function of (seed, pixel, pass,
//! sample, dimension), and samples are splatted with the filter into
//! per-tile buffers (a tile plus a margin of the filter's radius) of exact
//! fixed-point sums ([`crate::film::sums`]) that are added into the image after
//! each pass. The sums do not depend on how samples are grouped, so the
//! same seed gives the same image bit for bit whatever the number of
//! threads, the order tiles finish in, or the split of the frame into
//! windows and sample ranges rendered separately and added up.

mod accumulate;
pub mod adaptive;
pub mod aux;
pub mod digest;
mod ids;
mod pass;
mod plan;
mod result;
mod settings;
mod sppm;
mod stats;
mod stop;
mod watch;

use std::sync::atomic::AtomicU64;
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};

use crate::cpu_time::process_cpu_time;
use crate::film::splat::{Pixels, SplatSums, Splatter};
use crate::film::sums::SumBuffer;
use crate::film::window::PixelWindow;
use crate::integrator::bdpt::batch::{BdptBatch, CameraSample};
use crate::integrator::bdpt::Splat;
use crate::integrator::laps::{Lap, Laps};
use crate::integrator::wavefront::Wavefront;
use crate::integrator::{AuxSample, Context, Integrator, PathState, SettingsError, TraceStats};
use crate::math::hash::hash2;
use crate::sampler::{dims, PixelSampler, SampleId};
use crate::scene::Scene;
use crate::world::World;
use accumulate::Accumulated;
pub use adaptive::{Adaptive, AdaptiveStats};
use adaptive::{Convergence, TileSums};
pub use aux::{Aov, Aux, AuxImages, AuxSums};
use pass::Run;
use plan::{Frame, PassPlan};
use result::develop;
pub use result::{cost_maps, CostMaps, RenderResult};
pub use settings::{RenderSettings, UNLIMITED_SPP};
pub use stats::{RenderStats, TimeShares, TimeSplit};
use stop::Stop;
use watch::Previews;
pub use watch::{Preview, Progress};

/// A tile of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug)]
struct Tile {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

impl Tile {
    /// Number of pixels.
    fn pixels(&self) -> u32 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }

    /// The `k`-th pixel in render order (rows top to bottom).
    fn pixel(&self, k: u32) -> (u32, u32) {
        let w = self.x1 - self.x0;
        (self.x0 + k % w, self.y0 + k / w)
    }
}

/// A tile's filtered samples over its pixels plus the filter margin.
struct TileOut {
    /// Over the tile plus the margin, clipped to the window.
    sums: SumBuffer,
    stats: TraceStats,
    split: TimeSplit,
    aux: Option<Aux>,
    /// With adaptive sampling, the tile's pixels' own samples.
    own: Option<TileSums>,
    nan: u64,
    negative: u64,
    /// Pixels rendered, in render order (all of them unless stopped).
    pixels_done: u32,
    /// Light the tile's samples add elsewhere on the film (bidirectional
    /// integrators).
    splats: Vec<Splat>,
}

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
    let mut world = World::new(scene, &settings.build);
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
    let world = &*world;
    let stats = RenderStats {
        build_time,
        layout: world.accel.layout(),
        ..Default::default()
    };
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
            None => RoundSamples::Every {
                start: pass * plan.spp + indices.start,
                end: pass * plan.spp + indices.end,
            },
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

/// Rows of a tile whose samples are traced as one batch by the stepped
/// and the bidirectional integrators: 4x4 pixel blocks make the camera
/// packets.
const STRIP_ROWS: u32 = 4;

/// The samples one round gives each pixel, numbered over all passes:
/// sample `g` is index `g % pass_size` of pass `g / pass_size`.
#[derive(Clone, Copy)]
enum RoundSamples<'a> {
    /// Every pixel samples `start..end`.
    Every { start: u32, end: u32 },
    /// Each pixel those adaptive sampling gives it.
    Adaptive(&'a Convergence),
}

impl RoundSamples<'_> {
    /// The samples of pixel `(x, y)`.
    #[inline]
    fn of(&self, x: u32, y: u32) -> std::ops::Range<u32> {
        match self {
            Self::Every { start, end } => *start..*end,
            Self::Adaptive(c) => c.round(x, y),
        }
    }

    /// The convergence state, with adaptive sampling.
    fn convergence(&self) -> Option<&Convergence> {
        match self {
            Self::Every { .. } => None,
            Self::Adaptive(c) => Some(c),
        }
    }
}

/// Renders the round's `samples` of one tile, splatting them into the
/// window's pixels they reach; `stop` is asked before each strip of rows,
/// and once it says so, the rest of the tile is left out.
fn render_tile(
    world: &World,
    s: &RenderSettings,
    t: Tile,
    window: &PixelWindow,
    samples: RoundSamples,
    stop: &dyn Fn() -> bool,
) -> TileOut {
    let convergence = samples.convergence();
    let (w, h) = (s.width.max(1), s.height.max(1));
    let splatter = Splatter::new(&s.filter);
    let reach = PixelWindow {
        x0: t.x0,
        x1: t.x1,
        y0: t.y0,
        y1: t.y1,
    }
    .grow(splatter.margin(), w, h)
    .intersect(window);
    let tile_start = Instant::now();
    let mut out = TileOut {
        sums: SumBuffer::new(0, 0, 0, 0),
        stats: TraceStats::default(),
        split: TimeSplit::default(),
        aux: (!s.aovs.is_empty()).then(|| {
            let own = PixelWindow {
                x0: t.x0,
                x1: t.x1,
                y0: t.y0,
                y1: t.y1,
            }
            .intersect(window);
            Aux::new(&s.aovs, own.x0, own.y0, own.width(), own.height())
        }),
        own: convergence.map(|_| TileSums::new(t.x0, t.x1, t.y0, t.y1)),
        nan: 0,
        negative: 0,
        pixels_done: 0,
        splats: Vec::new(),
    };
    let batched = s.integrator.is_stepped() || s.integrator.bidirectional().is_some();
    let depth_view = matches!(s.integrator, Integrator::Depth);
    let rows = if batched { STRIP_ROWS } else { 1 };
    let mut laps = Laps::default();
    let mut film = SplatSums::new(reach.x0, reach.y0, reach.width(), reach.height());
    // The strip's buffers, kept by the thread from tile to tile.
    STRIP.with_borrow_mut(|strip| {
        for y0 in (t.y0..t.y1).step_by(rows as usize) {
            if stop() {
                break;
            }
            let y1 = (y0 + rows).min(t.y1);
            if convergence.is_some_and(|c| !c.any_active(t.x0, t.x1, y0, y1)) {
                out.pixels_done += (y1 - y0) * (t.x1 - t.x0);
                continue;
            }
            strip.render(world, s, t.x0, t.x1, y0, y1, samples, &mut out.stats);
            let clock = Instant::now();
            for mut splat in strip.splats.drain(..) {
                splat.l = guard(splat.l, &mut out.nan, &mut out.negative);
                out.splats.push(splat);
            }
            // Each sample guarded in place (and given to the other sums),
            // pixel by pixel, rows top to bottom, as the strip holds them.
            let (nan, negative) = (&mut out.nan, &mut out.negative);
            let plain = convergence.is_none() && out.aux.is_none();
            let mut k = 0;
            for y in y0..y1 {
                for x in t.x0..t.x1 {
                    for _ in samples.of(x, y) {
                        let raw = strip.radiance[k];
                        let l = guard(raw, nan, negative);
                        if !plain {
                            if let Some(aux) = &mut out.aux {
                                aux.add_sample(x, y, &strip.aux[k], l);
                            }
                            if let Some(own) = &mut out.own {
                                own.at(x, y).add(l);
                            }
                        }
                        // The depth view averages the distances of the
                        // samples that hit (a miss is 0, never a hit):
                        // mixing misses in would draw a near halo at every
                        // silhouette. A pixel no sample hit stays 0. NaN
                        // tells the film to leave a sample out.
                        strip.radiance[k] = if depth_view && raw == Vec3::ZERO {
                            Vec3::NAN
                        } else {
                            l
                        };
                        k += 1;
                    }
                }
            }
            let pixels = Pixels {
                x0: t.x0,
                x1: t.x1,
                y0,
                y1,
                first: &strip.first,
            };
            film.splat_each(&splatter, pixels, &strip.pos, &strip.radiance);
            laps.lap(clock, Lap::Film);
            out.pixels_done += (y1 - y0) * (t.x1 - t.x0);
        }
        // One of the two traced the strip's samples.
        laps += strip.wavefront.take_times();
        laps += strip.bdpt.take_times();
    });
    // The parts of the splats folded into the tile's exact sums.
    let clock = Instant::now();
    out.sums = film.into_sums();
    laps.lap(clock, Lap::Film);
    (out.split.tracing, out.split.shading, out.split.film) =
        (laps.tracing, laps.shading, laps.film);
    out.split.total = tile_start.elapsed();
    out
}

/// Guard, count, never hide: a NaN or infinite sample is a bug somewhere;
/// it is zeroed so one cannot ruin a pixel, and counted in `nan` for the
/// statistics; a negative component is clamped and counted in `negative`.
#[inline(always)]
pub(super) fn guard(mut l: Vec3, nan: &mut u64, negative: &mut u64) -> Vec3 {
    if !l.is_finite() {
        *nan += 1;
        l = Vec3::ZERO;
    }
    if l.min_element() < 0.0 {
        *negative += 1;
        l = l.max(Vec3::ZERO);
    }
    l
}

thread_local! {
    /// This thread's strip buffers, reused by every tile it renders (fresh
    /// ones per tile cost page faults of their own).
    static STRIP: std::cell::RefCell<Strip> = std::cell::RefCell::new(Strip::default());
}

/// The samples of a strip of a tile's rows: film positions and radiance,
/// pixel by pixel (rows top to bottom) and sample by sample.
#[derive(Default)]
struct Strip {
    pos: Vec<Vec2>,
    radiance: Vec<Vec3>,
    paths: Vec<PathState>,
    /// Where each path's radiance goes in `radiance`.
    slot: Vec<u32>,
    /// Where each pixel's samples start in `pos` and `radiance`.
    first: Vec<u32>,
    /// Each sample's auxiliary values (when the settings ask for them).
    aux: Vec<AuxSample>,
    /// Light the samples add elsewhere on the film.
    splats: Vec<Splat>,
    wavefront: Wavefront,
    /// The bidirectional integrators' samples, in pixel order, and their
    /// radiance.
    cameras: Vec<CameraSample>,
    samples: Vec<Vec3>,
    bdpt: BdptBatch,
}

/// The pixels `[x0, x1) x [y0, y1)` of a strip.
#[derive(Clone, Copy)]
struct StripPixels {
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
}

impl StripPixels {
    /// The pixels, rows top to bottom.
    fn iter(self) -> impl Iterator<Item = (u32, u32)> {
        (self.y0..self.y1).flat_map(move |y| (self.x0..self.x1).map(move |x| (x, y)))
    }
}

/// Where the samples of a strip's camera come from: sample `g` of pixel
/// `(x, y)` has its sampler, film position and camera ray.
struct CameraSamples<'a> {
    s: &'a RenderSettings,
    camera: &'a crate::scene::camera::Camera,
    w: u32,
    inv: Vec2,
    /// Samples per pixel of a pass.
    spp: u32,
}

impl CameraSamples<'_> {
    #[inline]
    fn at(&self, x: u32, y: u32, g: u32) -> (PixelSampler, Vec2, sahara_kd::Ray, f32) {
        let stream = hash2(self.s.seed, (y as u64) * self.w as u64 + x as u64);
        let sampler = PixelSampler::new(
            self.s.sampler,
            SampleId {
                stream,
                pass: g / self.spp,
                index: g % self.spp,
                count: self.spp,
            },
        );
        let pos = Vec2::new(x as f32, y as f32) + sampler.get_2d(dims::FILM);
        let (ray, time) = self.camera.generate_ray(
            pos * self.inv,
            sampler.get_2d(dims::LENS),
            sampler.get_1d(dims::TIME),
        );
        (sampler, pos, ray, time)
    }
}

/// Where sample `g` of pixel `(x, y)` of a strip goes in its buffers.
#[inline]
fn slot(first: &[u32], samples: RoundSamples, p: StripPixels, x: u32, y: u32, g: u32) -> usize {
    let start = samples.of(x, y).start;
    (first[((y - p.y0) * (p.x1 - p.x0) + (x - p.x0)) as usize] + g - start) as usize
}

impl Strip {
    /// Renders the round's `samples` of pixels `[x0, x1) x [y0, y1)`: lays
    /// out the strip's buffers, then traces the samples as the integrator
    /// does (bidirectional, stepped in batches, or one at a time).
    #[allow(clippy::too_many_arguments)]
    fn render(
        &mut self,
        world: &World,
        s: &RenderSettings,
        x0: u32,
        x1: u32,
        y0: u32,
        y1: u32,
        samples: RoundSamples,
        stats: &mut TraceStats,
    ) {
        let (w, h) = (s.width.max(1), s.height.max(1));
        let pixels = StripPixels { x0, x1, y0, y1 };
        let aux_on = !s.aovs.is_empty();
        self.lay_out(pixels, samples, aux_on);
        let cameras = CameraSamples {
            s,
            camera: &world.scene.camera,
            w,
            inv: Vec2::new(1.0 / w as f32, 1.0 / h as f32),
            spp: s.pass_size(),
        };
        let film = Vec2::new(w as f32, h as f32);
        if let Some((max_depth, strategies)) = s.integrator.bidirectional() {
            self.cameras_in_pixel_order(&cameras, pixels, samples);
            self.samples.clear();
            self.samples.resize(self.cameras.len(), Vec3::ZERO);
            self.bdpt.trace(
                world,
                max_depth,
                strategies,
                film,
                &self.cameras,
                &mut self.samples,
                stats,
                &mut self.splats,
            );
            for (&l, &k) in self.samples.iter().zip(&self.slot) {
                self.radiance[k as usize] = l;
            }
        } else if s.integrator.is_stepped() && !world.has_media() {
            // A scene with media takes the volumetric path tracer below,
            // one path at a time.
            self.trace_stepped(world, &cameras, pixels, samples, stats);
        } else {
            for (x, y) in pixels.iter() {
                for g in samples.of(x, y) {
                    let (sampler, pos, ray, time) = cameras.at(x, y, g);
                    let mut ctx = Context {
                        world,
                        sampler,
                        stats,
                    };
                    let k = slot(&self.first, samples, pixels, x, y, g);
                    self.pos[k] = pos;
                    let mut aux = AuxSample {
                        open: aux_on,
                        ..AuxSample::default()
                    };
                    self.radiance[k] = s.integrator.li_splats(
                        &mut ctx,
                        &ray,
                        time,
                        film,
                        &mut self.splats,
                        &mut aux,
                    );
                    if aux_on {
                        self.aux[k] = aux;
                    }
                }
            }
        }
    }

    /// Sizes the strip's buffers for the round's samples of `pixels`, and
    /// notes where each pixel's samples start.
    fn lay_out(&mut self, pixels: StripPixels, samples: RoundSamples, aux: bool) {
        self.first.clear();
        let mut n = 0usize;
        for (x, y) in pixels.iter() {
            self.first.push(n as u32);
            n += samples.of(x, y).len();
        }
        self.pos.clear();
        self.pos.resize(n, Vec2::ZERO);
        self.radiance.clear();
        self.radiance.resize(n, Vec3::ZERO);
        self.aux.clear();
        if aux {
            self.aux.resize(n, AuxSample::default());
        }
    }

    /// The bidirectional integrators' camera samples, pixel by pixel, rows
    /// top to bottom, with the slot of each.
    fn cameras_in_pixel_order(
        &mut self,
        cameras: &CameraSamples,
        pixels: StripPixels,
        samples: RoundSamples,
    ) {
        self.cameras.clear();
        self.slot.clear();
        for (x, y) in pixels.iter() {
            for g in samples.of(x, y) {
                let (sampler, pos, ray, time) = cameras.at(x, y, g);
                let k = slot(&self.first, samples, pixels, x, y, g);
                self.pos[k] = pos;
                self.slot.push(k as u32);
                self.cameras.push(CameraSample { ray, time, sampler });
            }
        }
    }

    /// Traces the stepped integrators' paths as batches, in camera-packet
    /// order: 4x4 pixel blocks, the pixels of a block in Morton order (2x2
    /// blocks of 2x2), each pixel's samples together. A run of 16 paths is
    /// then 16 samples of one pixel, or the samples of a 2x2 block's pixels
    /// when a pixel takes 4: their camera rays, shadow rays and bounces
    /// start close together and share the tree's cells (figures in
    /// docs/performance.md, "What a packet of one pixel's samples would
    /// share"). The order changes no path's arithmetic.
    fn trace_stepped(
        &mut self,
        world: &World,
        cameras: &CameraSamples,
        pixels: StripPixels,
        samples: RoundSamples,
        stats: &mut TraceStats,
    ) {
        let aux = !cameras.s.aovs.is_empty();
        let StripPixels { x0, x1, y0, y1 } = pixels;
        self.paths.clear();
        self.slot.clear();
        for (bx, by) in (y0..y1)
            .step_by(4)
            .flat_map(|by| (x0..x1).step_by(4).map(move |bx| (bx, by)))
        {
            for m in 0..16u32 {
                // De-interleave the Morton index's bits.
                let dx = (m & 1) | (m >> 1 & 2);
                let dy = (m >> 1 & 1) | (m >> 2 & 2);
                let (x, y) = (bx + dx, by + dy);
                if x >= x1 || y >= y1 {
                    continue;
                }
                for g in samples.of(x, y) {
                    let (sampler, pos, ray, time) = cameras.at(x, y, g);
                    let k = slot(&self.first, samples, pixels, x, y, g);
                    self.pos[k] = pos;
                    self.slot.push(k as u32);
                    self.paths
                        .push(PathState::new(ray, time, sampler).with_aux(aux));
                }
            }
        }
        self.wavefront
            .trace(&cameras.s.integrator, world, stats, &mut self.paths);
        for (p, &k) in self.paths.iter().zip(&self.slot) {
            self.radiance[k as usize] = p.l;
        }
        if aux {
            for (p, &k) in self.paths.iter().zip(&self.slot) {
                self.aux[k as usize] = p.aux;
            }
        }
    }
}
