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

pub mod adaptive;
pub mod aux;
pub mod digest;
mod ids;
mod sppm;

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use sahara_kd::BuildParams;

use crate::accel::AccelLayout;
use crate::cpu_time::process_cpu_time;
use crate::film::splat::{Pixels, SplatSums, Splatter};
use crate::film::sums::{filter_margin, SumBuffer};
use crate::film::window::PixelWindow;
use crate::film::{heat_color, Film};
use crate::integrator::bdpt::batch::{BdptBatch, CameraSample};
use crate::integrator::bdpt::Splat;
use crate::integrator::laps::{Lap, Laps};
use crate::integrator::wavefront::Wavefront;
#[cfg(doc)]
use crate::integrator::Supports;
use crate::integrator::{
    AuxSample, Context, Feature, Integrator, PathState, SettingsError, TraceStats,
};
use crate::math::hash::hash2;
use crate::sampler::{dims, PixelSampler, SampleId};
use crate::scene::Scene;
use crate::settings::FrameSettings;
use crate::world::World;
pub use adaptive::AdaptiveStats;
use adaptive::{Convergence, TileSums};
pub use aux::{Aov, Aux, AuxImages, AuxSums};

/// How to render: what the frame is ([`FrameSettings`], read as these
/// settings' own fields) and how this render goes about it.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// What the frame is: size, samples per pixel and per pass, seed,
    /// sampler, filter, integrator, adaptive sampling. With a time limit,
    /// `spp` can be [`UNLIMITED_SPP`].
    pub frame: FrameSettings,
    /// Stop starting passes after this long, even before `spp` samples; a
    /// pass under way when it runs out is abandoned (the first pass always
    /// completes). With a time limit, `spp` can be [`UNLIMITED_SPP`].
    pub time_limit: Option<Duration>,
    /// Set to true (e.g. on Ctrl-C) to stop; the passes completed are kept,
    /// and if the first pass is under way, the pixels it has finished.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Kd-tree build parameters for the meshes.
    pub build: BuildParams,
    /// Full scale of the `cost` heat map in work units per camera ray
    /// (None: the image's maximum).
    pub cost_scale: Option<f32>,
    /// The pixels whose sums the render produces (None: the whole image).
    /// Every sample whose filter footprint reaches them is rendered, so a
    /// window's sums are those of the whole frame's render over it, where
    /// the integrator splits by pixels ([`Supports::pixel_parts`]); the
    /// light-tracing integrators render a window as a crop, whose own
    /// pixels' light subpaths stand for the whole frame's.
    pub window: Option<PixelWindow>,
    /// The sample indices of every pixel to render, counted over all
    /// passes: sample `k` is index `k % pass_spp` of pass `k / pass_spp`
    /// (None: `0..spp`). The passes rendered are those the range meets.
    /// A range other than `0..spp` needs an integrator that splits by
    /// samples ([`Supports::sample_ranges`]).
    pub samples: Option<std::ops::Range<u32>>,
    /// True when the render is a part of a frame whose parts' sums are
    /// added up afterwards (a render farm's): its `window` must then be a
    /// part by pixels the integrator supports ([`Supports::pixel_parts`]).
    /// False: the window is a crop, an image of those pixels.
    pub part: bool,
    /// The render passes to make beside the beauty, the images a denoiser
    /// and compositing use ([`AuxImages`]; the integrators whose
    /// [`Supports::aovs`] says so); empty: none. Adaptive sampling
    /// ([`FrameSettings::adaptive`]) needs an integrator that supports it
    /// ([`Supports::adaptive`]), and not with `samples` other than
    /// `0..spp` (a pixel's decisions need all its samples).
    pub aovs: Vec<Aov>,
}

/// The renderer reads the frame's settings as its own (`settings.spp`):
/// they are the settings of every render, kept in one struct so that a
/// scene file, a part file and a caller describe them once.
impl std::ops::Deref for RenderSettings {
    type Target = FrameSettings;

    fn deref(&self) -> &FrameSettings {
        &self.frame
    }
}

impl std::ops::DerefMut for RenderSettings {
    fn deref_mut(&mut self) -> &mut FrameSettings {
        &mut self.frame
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            frame: FrameSettings::default(),
            time_limit: None,
            cancel: None,
            tile_size: 32,
            build: BuildParams::default(),
            cost_scale: None,
            window: None,
            samples: None,
            part: false,
            aovs: Vec::new(),
        }
    }
}

impl From<FrameSettings> for RenderSettings {
    /// A render of the whole frame `frame` with the defaults for the rest.
    fn from(frame: FrameSettings) -> Self {
        Self {
            frame,
            ..Default::default()
        }
    }
}

/// The `spp` of a render bounded by its time limit only.
pub const UNLIMITED_SPP: u32 = u32::MAX;

impl RenderSettings {
    /// Samples per pixel of each pass: `pass_spp`, at least 1, at most `spp`.
    pub fn pass_size(&self) -> u32 {
        self.pass_spp.clamp(1, self.spp.max(1))
    }

    /// The most passes the render takes: `spp` in passes of [`Self::pass_size`].
    pub fn passes(&self) -> u32 {
        self.spp.max(1).div_ceil(self.pass_size())
    }

    /// Refuses what the integrator cannot honour, as its kind declares
    /// ([`IntegratorKind::supports`]): a sample range, a part by pixels,
    /// adaptive sampling (and adaptive sampling with a sample range, which
    /// no integrator takes), render passes. Every render runs this first.
    ///
    /// [`IntegratorKind::supports`]: crate::IntegratorKind::supports
    pub fn check(&self) -> Result<(), SettingsError> {
        let kind = self.integrator.kind();
        let sample_range = self.samples.as_ref().filter(|r| **r != (0..self.spp));
        if sample_range.is_some() {
            kind.require(Feature::SampleRanges)?;
        }
        let (w, h) = (self.width.max(1), self.height.max(1));
        let full = PixelWindow::full(w, h);
        if self.part && self.window.is_some_and(|win| win.intersect(&full) != full) {
            kind.require(Feature::PixelParts)?;
        }
        if self.adaptive.is_some() {
            kind.require(Feature::Adaptive)?;
            if let Some(r) = sample_range {
                return Err(SettingsError::AdaptiveSampleRange {
                    samples: r.clone(),
                    spp: self.spp,
                });
            }
        }
        if !self.aovs.is_empty() {
            kind.require(Feature::Aovs)?;
        }
        Ok(())
    }

    /// [`RenderSettings::check`], and refuses what the integrator cannot
    /// honour in this scene: participating media.
    pub fn check_for(&self, scene: &Scene) -> Result<(), SettingsError> {
        self.check()?;
        if scene.has_media() {
            self.integrator.kind().require(Feature::Media)?;
        }
        Ok(())
    }
}

/// Progress report, sent after each tile and each pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Current pass (0-based).
    pub pass: u32,
    /// Most passes (when only a time limit bounds the render, those of
    /// [`UNLIMITED_SPP`]).
    pub passes: u32,
    /// Tiles finished in this pass.
    pub tiles_done: u32,
    /// Tiles per pass.
    pub tiles: u32,
    /// Time since the render began.
    pub elapsed: Duration,
    /// Rays traced so far (camera, bounce and shadow rays), for a live
    /// Mrays/s figure.
    pub rays: u64,
}

/// Counts and times of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Passes completed (and in the image).
    pub passes: u32,
    /// Samples per pixel in the image (of a sample range: those of the
    /// range in the completed passes, the first of them at the range's start).
    pub spp: u32,
    /// Work counted over the completed passes.
    pub trace: TraceStats,
    /// Samples whose radiance was NaN or infinite (set to zero). Should be 0.
    pub nan_samples: u64,
    /// Samples with a negative component (clamped). Should be 0.
    pub negative_samples: u64,
    /// Time to build the acceleration structures and lights.
    pub build_time: Duration,
    /// The trees built for the scene's instances.
    pub layout: AccelLayout,
    /// Time spent rendering passes.
    pub render_time: Duration,
    /// CPU time of all threads spent rendering passes (zero where the
    /// platform does not report it).
    pub render_cpu_time: Duration,
    /// Where the render threads' time went (path-tracing integrators).
    pub time_split: TimeSplit,
    /// True if the render stopped on cancel or time limit before `passes`.
    pub stopped_early: bool,
    /// Pixels finished (with all `spp` samples of the pass) in a first pass
    /// stopped by cancel; 0 otherwise. The image holds these pixels and is
    /// black elsewhere.
    pub first_pass_pixels: u64,
    /// What adaptive sampling did, when it was on.
    pub adaptive: Option<AdaptiveStats>,
}

/// Where the render threads' time went, summed over the threads: finding
/// hits and answering shadow rays (the kd-tree walks and the instance
/// layer), the paths' steps between them (surface interaction, textures,
/// BSDF and light sampling, MIS), adding the samples into the film's sums,
/// and the rest of each tile (camera rays, the sampler's set-up, the
/// strip's buffers). Measured for the integrators that trace their samples
/// in batches (`path`, `distribution`, `bdpt`, `lightpath`); zero for the
/// others.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TimeSplit {
    /// Time in the batch traversals.
    pub tracing: Duration,
    /// Time in the paths' steps.
    pub shading: Duration,
    /// Time splatting the samples into the tiles' sums.
    pub film: Duration,
    /// Time in tiles altogether (tracing, shading and film included).
    pub total: Duration,
}

/// [`TimeSplit`] as shares of its total, each in `[0, 1]`, adding up to 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeShares {
    /// The batch traversals.
    pub tracing: f64,
    /// The paths' steps.
    pub shading: f64,
    /// Splatting into the film.
    pub film: f64,
    /// Everything else in the tiles.
    pub rest: f64,
}

impl TimeSplit {
    /// The shares of tracing, shading, the film and the rest of the total;
    /// `None` when nothing was measured.
    pub fn shares(&self) -> Option<TimeShares> {
        let total = self.total.as_secs_f64();
        if self.tracing.is_zero() || total <= 0.0 {
            return None;
        }
        let share = |d: Duration| d.as_secs_f64() / total;
        let (tracing, shading, film) = (share(self.tracing), share(self.shading), share(self.film));
        Some(TimeShares {
            tracing,
            shading,
            film,
            rest: (1.0 - tracing - shading - film).max(0.0),
        })
    }
}

impl std::ops::AddAssign for TimeSplit {
    fn add_assign(&mut self, o: Self) {
        self.tracing += o.tracing;
        self.shading += o.shading;
        self.film += o.film;
        self.total += o.total;
    }
}

impl RenderStats {
    /// All rays traced.
    pub fn rays(&self) -> u64 {
        self.trace.camera_rays + self.trace.bounce_rays + self.trace.shadow_rays
    }
}

/// Per-pixel averages of the `cost` view.
#[derive(Clone, Debug, PartialEq)]
pub struct CostMaps {
    /// Traversal steps (inner nodes, leaves, top-level box tests) per ray.
    pub steps: Vec<f32>,
    /// Ray/triangle tests per ray.
    pub tests: Vec<f32>,
    /// The value shown as full heat.
    pub scale: f32,
}

/// What [`render_watched`] calls between passes, at most once per `every`.
pub struct Preview<'a> {
    /// Shortest time between two calls.
    pub every: Duration,
    /// Called with the image of the passes completed so far (not after the
    /// last pass: that image is the render's result).
    pub show: &'a mut (dyn FnMut(&RenderResult) + Send),
}

/// The image and what it cost.
#[derive(Clone, Debug)]
pub struct RenderResult {
    /// The image of the window (black if no pass completed).
    pub film: Film,
    /// The window's exact sums over the completed passes (and, in an
    /// interrupted first pass, over the tiles it finished).
    pub sums: SumBuffer,
    /// Counts and times.
    pub stats: RenderStats,
    /// Raw per-pixel work of the `cost` view.
    pub cost: Option<CostMaps>,
    /// The albedo, normal and depth images and their sums, when
    /// [`RenderSettings::aovs`] asks for them.
    pub aux: Option<Aux>,
    /// With adaptive sampling, the samples each pixel of the window took
    /// (rows top to bottom).
    pub samples: Option<Vec<u32>>,
}

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
                finish(
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

/// The pixels a render covers, cut into tiles.
struct Frame {
    /// The image's size.
    w: u32,
    h: u32,
    /// The pixels whose sums the render produces.
    window: PixelWindow,
    /// The pixels whose samples reach the window; with adaptive sampling,
    /// whole blocks of them, so that a piece of the frame judges its pixels
    /// as the whole frame does.
    region: PixelWindow,
    /// The region's tiles, rows top to bottom.
    tiles: Vec<Tile>,
}

impl Frame {
    fn plan(settings: &RenderSettings) -> Self {
        let (w, h) = (settings.width.max(1), settings.height.max(1));
        let window = settings
            .window
            .unwrap_or(PixelWindow::full(w, h))
            .intersect(&PixelWindow::full(w, h));
        let region = window.grow(filter_margin(&settings.filter), w, h);
        let region = match settings.adaptive {
            Some(_) => region.align(adaptive::BLOCK, w, h),
            None => region,
        };
        let ts = settings.tile_size.max(1);
        let tiles: Vec<Tile> = (0..region.height().div_ceil(ts))
            .flat_map(|ty| {
                (0..region.width().div_ceil(ts)).map(move |tx| Tile {
                    x0: region.x0 + tx * ts,
                    y0: region.y0 + ty * ts,
                    x1: (region.x0 + (tx + 1) * ts).min(region.x1),
                    y1: (region.y0 + (ty + 1) * ts).min(region.y1),
                })
            })
            .collect();
        Self {
            w,
            h,
            window,
            region,
            tiles,
        }
    }
}

/// The passes a render's sample range meets, and the range within each.
struct PassPlan {
    /// Samples per pixel of a whole pass.
    spp: u32,
    /// The first pass rendered.
    first_pass: u32,
    /// Passes rendered, at most.
    passes: u32,
    /// The sample range, counted over all passes.
    first: u64,
    last: u64,
}

impl PassPlan {
    fn new(settings: &RenderSettings) -> Self {
        let spp = settings.pass_size();
        let (first_pass, passes, first, last) = match &settings.samples {
            None => (0, settings.passes(), 0u64, u64::from(settings.spp.max(1))),
            Some(r) if r.start >= r.end => (0, 0, 0, 0),
            Some(r) => (
                r.start / spp,
                r.end.div_ceil(spp) - r.start / spp,
                u64::from(r.start),
                u64::from(r.end),
            ),
        };
        Self {
            spp,
            first_pass,
            passes,
            first,
            last,
        }
    }

    /// The sample indices of `pass` within the range.
    fn indices(&self, pass: u32) -> std::ops::Range<u32> {
        let (spp, base) = (u64::from(self.spp), u64::from(pass) * u64::from(self.spp));
        let i0 = self.first.saturating_sub(base).min(spp) as u32;
        let i1 = self.last.saturating_sub(base).min(spp) as u32;
        i0..i1
    }
}

/// When a render stops early: on cancel, and (after the first pass) at
/// the time limit.
struct Stop<'a> {
    settings: &'a RenderSettings,
    /// When the render began; the time limit counts from it.
    start: Instant,
}

impl Stop<'_> {
    fn cancelled(&self) -> bool {
        self.settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    fn out_of_time(&self) -> bool {
        self.settings
            .time_limit
            .is_some_and(|t| self.start.elapsed() >= t)
    }
}

/// Hands images to the caller's [`Preview`] at most once per its `every`.
pub(super) struct Previews<'a> {
    preview: Option<Preview<'a>>,
    last: Instant,
}

impl<'a> Previews<'a> {
    fn new(preview: Option<Preview<'a>>) -> Self {
        Self {
            preview,
            last: Instant::now(),
        }
    }

    /// Shows the image `image` makes, if a preview is due.
    pub(super) fn offer(&mut self, image: impl FnOnce() -> RenderResult) {
        if let Some(p) = self.preview.as_mut() {
            if self.last.elapsed() >= p.every {
                (p.show)(&image());
                self.last = Instant::now();
            }
        }
    }
}

/// What a render's passes render with: the scene, the settings, the
/// frame's tiles and when to stop.
struct Run<'a, 'w> {
    world: &'a World<'w>,
    settings: &'a RenderSettings,
    frame: Frame,
    stop: Stop<'a>,
    progress: &'a (dyn Fn(Progress) + Sync),
    /// Rays traced so far, for the progress reports.
    rays: AtomicU64,
}

impl Run<'_, '_> {
    /// Renders pass `n` (of `passes`) of every tile in parallel, reporting
    /// progress after each; a tile not started once the render stops
    /// (cancel, or the time limit after the first pass) is `None`, and in
    /// the first pass a cancel stops tiles pixel by pixel, so that a long
    /// first pass still leaves the pixels it finished.
    fn pass(&self, n: u32, passes: u32, samples: RoundSamples) -> Vec<Option<TileOut>> {
        let (settings, frame, stop) = (self.settings, &self.frame, &self.stop);
        let done = AtomicU32::new(0);
        let abandon = AtomicBool::new(false);
        let stop_pixel = || n == 0 && stop.cancelled();
        frame
            .tiles
            .par_iter()
            // One job per tile: rayon otherwise hands out a few large runs
            // of tiles, and one costly run can leave the other cores idle.
            .with_max_len(1)
            .map(|tile| {
                if abandon.load(Ordering::Relaxed)
                    || stop.cancelled()
                    || (n > 0 && stop.out_of_time())
                {
                    abandon.store(true, Ordering::Relaxed);
                    return None;
                }
                let out = render_tile(
                    self.world,
                    settings,
                    *tile,
                    &frame.window,
                    samples,
                    &stop_pixel,
                );
                if out.pixels_done < tile.pixels() {
                    abandon.store(true, Ordering::Relaxed);
                }
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                let t = &out.stats;
                let traced = t.camera_rays + t.bounce_rays + t.shadow_rays;
                let rays = self.rays.fetch_add(traced, Ordering::Relaxed) + traced;
                (self.progress)(Progress {
                    pass: n,
                    passes,
                    tiles_done: d,
                    tiles: frame.tiles.len() as u32,
                    elapsed: stop.start.elapsed(),
                    rays,
                });
                Some(out)
            })
            .collect()
    }
}

/// What the completed passes add up to.
struct Accumulated {
    /// The window's exact sums.
    sums: SumBuffer,
    /// The render passes' sums, when asked for.
    aux: Option<Aux>,
    /// The adaptive sampling state, when it is on.
    convergence: Option<Convergence>,
    stats: RenderStats,
    /// Pixels finished in an interrupted first pass (None: not interrupted).
    finished: Option<Vec<bool>>,
    /// How much each light tracing splat counts: a window renders the
    /// light subpaths of its region's samples only, which then stand for
    /// every pixel's of the image.
    splat_scale: f32,
}

impl Accumulated {
    fn new(settings: &RenderSettings, frame: &Frame, stats: RenderStats) -> Self {
        let window = &frame.window;
        Self {
            sums: SumBuffer::new(window.x0, window.y0, window.width(), window.height()),
            aux: (!settings.aovs.is_empty()).then(|| {
                Aux::new(
                    &settings.aovs,
                    window.x0,
                    window.y0,
                    window.width(),
                    window.height(),
                )
            }),
            convergence: settings.adaptive.map(|a| {
                let grow = settings.time_limit.is_none();
                Convergence::new(
                    frame.region,
                    a,
                    settings.pass_size(),
                    settings.spp.max(1),
                    grow,
                )
            }),
            stats,
            finished: None,
            splat_scale: (frame.w as f64 * frame.h as f64 / frame.region.pixels() as f64) as f32,
        }
    }

    /// Marks the window's pixels an interrupted first pass finished.
    fn keep_finished(&mut self, frame: &Frame, outs: &[Option<TileOut>]) {
        let window = &frame.window;
        let mut mask = vec![false; window.pixels() as usize];
        for (out, tile) in outs.iter().zip(&frame.tiles) {
            if let Some(out) = out {
                for k in 0..out.pixels_done {
                    let (x, y) = tile.pixel(k);
                    if (window.x0..window.x1).contains(&x) && (window.y0..window.y1).contains(&y) {
                        let i = (y - window.y0) * window.width() + (x - window.x0);
                        mask[i as usize] = true;
                    }
                }
            }
        }
        self.stats.first_pass_pixels = mask.iter().filter(|&&m| m).count() as u64;
        self.finished = Some(mask);
    }

    /// Adds a pass's tiles: their light tracing splats, sums, counts and
    /// render passes, and each pixel's own samples for adaptive sampling.
    fn add(&mut self, settings: &RenderSettings, outs: Vec<Option<TileOut>>) {
        let splats: Vec<&[Splat]> = outs.iter().flatten().map(|o| &o.splats[..]).collect();
        self.sums
            .add_splats(&settings.filter, &splats, self.splat_scale);
        for out in outs.into_iter().flatten() {
            self.sums.add(&out.sums);
            self.stats.trace += out.stats;
            self.stats.time_split += out.split;
            if let (Some(a), Some(o)) = (&mut self.aux, &out.aux) {
                a.add(o);
            }
            self.stats.nan_samples += out.nan;
            self.stats.negative_samples += out.negative;
            if let (Some(c), Some(o)) = (&mut self.convergence, &out.own) {
                c.add(o);
            }
        }
    }

    /// The adaptive round after a pass: which pixels go on. True when every
    /// pixel is below the threshold, and the render is complete.
    fn adaptive_round(&mut self) -> bool {
        self.convergence.as_mut().is_some_and(|c| c.update() == 0)
    }

    /// The image of the completed passes, with the counts of samples
    /// taken, and the object and material ids when asked for.
    fn finish(
        mut self,
        world: &World,
        settings: &RenderSettings,
        frame: &Frame,
        plan: &PassPlan,
    ) -> RenderResult {
        let window = &frame.window;
        if self.finished.is_some() {
            self.stats.spp = plan.indices(plan.first_pass).len() as u32;
        } else if let Some(c) = &self.convergence {
            self.stats.spp = c.most_samples(window);
        }
        let stats = &mut self.stats;
        stats.adaptive = self
            .convergence
            .as_ref()
            .map(|c| c.stats(window, stats.spp));
        let samples = self.convergence.as_ref().map(|c| c.samples(window));
        let mut result = finish(
            self.sums,
            self.aux,
            self.finished.as_deref(),
            self.stats,
            settings,
            samples,
        );
        let wants = |a: Aov| settings.aovs.contains(&a);
        if let Some(aux) = result
            .aux
            .as_mut()
            .filter(|_| wants(Aov::Object) || wants(Aov::Material))
        {
            let ids = ids::pixel_centres(world, window, frame.w, frame.h);
            if wants(Aov::Object) {
                aux.images.object = ids.objects;
            }
            if wants(Aov::Material) {
                aux.images.material = ids.materials;
            }
        }
        result
    }
}

/// The image of the sums so far (black where `finished` says a pixel was not).
fn finish(
    sums: SumBuffer,
    mut aux: Option<Aux>,
    finished: Option<&[bool]>,
    stats: RenderStats,
    settings: &RenderSettings,
    samples: Option<Vec<u32>>,
) -> RenderResult {
    if let Some(a) = &mut aux {
        a.develop(finished);
    }
    let mut film = Film::new(sums.width, sums.height);
    for (k, (p, s)) in film.pixels.iter_mut().zip(&sums.sums).enumerate() {
        let keep = finished.is_none_or(|f| f[k]);
        *p = if keep { s.value() } else { Vec3::ZERO };
    }
    let cost = matches!(settings.integrator, Integrator::Cost)
        .then(|| cost_maps(&mut film, settings.cost_scale));
    RenderResult {
        film,
        sums,
        stats,
        cost,
        aux,
        samples,
    }
}

/// Turns the raw film of the `cost` view into its heat map (full heat at
/// `scale` work units per camera ray, or at the image's maximum if None),
/// returning the raw values.
pub fn cost_maps(film: &mut Film, scale: Option<f32>) -> CostMaps {
    let steps: Vec<f32> = film.pixels.iter().map(|p| p.x).collect();
    let tests: Vec<f32> = film.pixels.iter().map(|p| p.y).collect();
    let max = film.pixels.iter().map(|p| p.x + p.y).fold(0.0f32, f32::max);
    let scale = scale.unwrap_or(max).max(1e-6);
    for p in &mut film.pixels {
        *p = heat_color((p.x + p.y) / scale);
    }
    CostMaps {
        steps,
        tests,
        scale,
    }
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
