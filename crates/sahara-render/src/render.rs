//! The render loop: progressive passes of tiles rendered in parallel.
//!
//! Determinism: every random number is a function of (seed, pixel, pass,
//! sample, dimension), each pixel's samples are taken in a fixed order,
//! and samples are splatted with the filter into per-tile buffers (a tile
//! plus a margin of the filter's radius) that are merged into the image in
//! tile order after each pass. Floating-point sums therefore happen in the
//! same order whatever the number of threads or the order tiles finish in,
//! and the same seed gives the same image bit for bit.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use sahara_kd::BuildParams;

use crate::film::{heat_color, Film};
use crate::filter::Filter;
use crate::hash::hash2;
use crate::integrator::{Context, Integrator, TraceStats};
use crate::sampler::{dims, PixelSampler, SampleId, SamplerKind};
use crate::scene::Scene;
use crate::world::World;

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels (the camera's aspect should be width/height).
    pub height: u32,
    /// Samples per pixel in each pass.
    pub spp: u32,
    /// Most passes to render (total samples per pixel: `spp * passes`).
    pub passes: u32,
    /// Stop starting passes after this long; a pass under way when it runs
    /// out is abandoned (the first pass always completes).
    pub time_limit: Option<Duration>,
    /// Set to true (e.g. on Ctrl-C) to stop; the passes completed are kept.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Seed of every random decision.
    pub seed: u64,
    /// Sample generator.
    pub sampler: SamplerKind,
    /// Reconstruction filter.
    pub filter: Filter,
    /// Light transport.
    pub integrator: Integrator,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Kd-tree build parameters for the meshes.
    pub build: BuildParams,
    /// Full scale of the `cost` heat map in work units per camera ray
    /// (None: the image's maximum).
    pub cost_scale: Option<f32>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            spp: 16,
            passes: 1,
            time_limit: None,
            cancel: None,
            seed: 0,
            sampler: SamplerKind::Sobol,
            filter: Filter::default(),
            integrator: Integrator::default(),
            tile_size: 32,
            build: BuildParams::default(),
            cost_scale: None,
        }
    }
}

/// Progress report, sent after each tile and each pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Current pass (0-based).
    pub pass: u32,
    /// Most passes.
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
    /// Samples per pixel in the image.
    pub spp: u32,
    /// Work counted over the completed passes.
    pub trace: TraceStats,
    /// Samples whose radiance was NaN or infinite (set to zero). Should be 0.
    pub nan_samples: u64,
    /// Samples with a negative component (clamped). Should be 0.
    pub negative_samples: u64,
    /// Time to build the acceleration structures and lights.
    pub build_time: Duration,
    /// Time spent rendering passes.
    pub render_time: Duration,
    /// True if the render stopped on cancel or time limit before `passes`.
    pub stopped_early: bool,
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

/// The image and what it cost.
#[derive(Clone, Debug)]
pub struct RenderResult {
    /// The image (black if no pass completed).
    pub film: Film,
    /// Counts and times.
    pub stats: RenderStats,
    /// Raw per-pixel work of the `cost` view.
    pub cost: Option<CostMaps>,
}

/// A tile of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug)]
struct Tile {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

/// A tile's filtered samples over its pixels plus the filter margin.
struct TileOut {
    /// Buffer origin and size (clipped to the image).
    bx: u32,
    by: u32,
    bw: u32,
    bh: u32,
    sum: Vec<Vec3>,
    weight: Vec<f32>,
    stats: TraceStats,
    nan: u64,
    negative: u64,
}

/// Renders `scene`; `progress` is called from worker threads as tiles
/// finish (its calls may interleave; the image does not depend on them).
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(Progress) + Sync),
) -> RenderResult {
    let start = Instant::now();
    let world = World::new(scene, &settings.build);
    let build_time = start.elapsed();
    let (w, h) = (settings.width.max(1), settings.height.max(1));
    let ts = settings.tile_size.max(1);
    let tiles: Vec<Tile> = (0..h.div_ceil(ts))
        .flat_map(|ty| {
            (0..w.div_ceil(ts)).map(move |tx| Tile {
                x0: tx * ts,
                y0: ty * ts,
                x1: ((tx + 1) * ts).min(w),
                y1: ((ty + 1) * ts).min(h),
            })
        })
        .collect();
    let mut sum = vec![DVec3::ZERO; (w * h) as usize];
    let mut wsum = vec![0.0f64; (w * h) as usize];
    let mut stats = RenderStats {
        build_time,
        ..Default::default()
    };
    let render_start = Instant::now();
    let cancelled = || {
        settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    };
    let out_of_time = || settings.time_limit.is_some_and(|t| start.elapsed() >= t);
    let passes = settings.passes.max(1);
    let rays_so_far = std::sync::atomic::AtomicU64::new(0);
    for pass in 0..passes {
        if cancelled() || (pass > 0 && out_of_time()) {
            stats.stopped_early = true;
            break;
        }
        let done = AtomicU32::new(0);
        let abandon = AtomicBool::new(false);
        let outs: Vec<Option<TileOut>> = tiles
            .par_iter()
            // One job per tile: rayon otherwise hands out a few large runs
            // of tiles, and one costly run can leave the other cores idle.
            .with_max_len(1)
            .map(|tile| {
                if abandon.load(Ordering::Relaxed) || cancelled() || (pass > 0 && out_of_time()) {
                    abandon.store(true, Ordering::Relaxed);
                    return None;
                }
                let out = render_tile(&world, settings, *tile, pass, w, h);
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                let t = &out.stats;
                let rays = rays_so_far.fetch_add(
                    t.camera_rays + t.bounce_rays + t.shadow_rays,
                    Ordering::Relaxed,
                ) + t.camera_rays
                    + t.bounce_rays
                    + t.shadow_rays;
                progress(Progress {
                    pass,
                    passes,
                    tiles_done: d,
                    tiles: tiles.len() as u32,
                    elapsed: start.elapsed(),
                    rays,
                });
                Some(out)
            })
            .collect();
        if outs.iter().any(Option::is_none) {
            stats.stopped_early = true;
            break;
        }
        // Merge in tile order: the sums' order is fixed.
        for out in outs.into_iter().flatten() {
            for j in 0..out.bh {
                for i in 0..out.bw {
                    let k = (j * out.bw + i) as usize;
                    let p = ((out.by + j) * w + out.bx + i) as usize;
                    sum[p] += out.sum[k].as_dvec3();
                    wsum[p] += out.weight[k] as f64;
                }
            }
            stats.trace += out.stats;
            stats.nan_samples += out.nan;
            stats.negative_samples += out.negative;
        }
        stats.passes += 1;
    }
    stats.spp = stats.passes * settings.spp;
    stats.render_time = render_start.elapsed();
    let mut film = Film::new(w, h);
    for (p, (s, wt)) in film.pixels.iter_mut().zip(sum.iter().zip(&wsum)) {
        // Negative lobes (Mitchell) can make an estimate negative near
        // edges; the film holds radiance, which is not.
        *p = if *wt > 0.0 {
            (*s / *wt).as_vec3().max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        };
    }
    let cost =
        matches!(settings.integrator, Integrator::Cost).then(|| cost_maps(&mut film, settings));
    RenderResult { film, stats, cost }
}

/// Turns the raw cost film into a heat map, returning the raw values.
fn cost_maps(film: &mut Film, settings: &RenderSettings) -> CostMaps {
    let steps: Vec<f32> = film.pixels.iter().map(|p| p.x).collect();
    let tests: Vec<f32> = film.pixels.iter().map(|p| p.y).collect();
    let max = film.pixels.iter().map(|p| p.x + p.y).fold(0.0f32, f32::max);
    let scale = settings.cost_scale.unwrap_or(max).max(1e-6);
    for p in &mut film.pixels {
        *p = heat_color((p.x + p.y) / scale);
    }
    CostMaps {
        steps,
        tests,
        scale,
    }
}

/// Pixels beyond a pixel's own that its samples reach through the filter.
fn filter_margin(f: &Filter) -> u32 {
    (f.radius() - 0.5).ceil().max(0.0) as u32
}

/// Renders one pass of one tile.
fn render_tile(world: &World, s: &RenderSettings, t: Tile, pass: u32, w: u32, h: u32) -> TileOut {
    let m = filter_margin(&s.filter);
    let bx = t.x0.saturating_sub(m);
    let by = t.y0.saturating_sub(m);
    let bw = (t.x1 + m).min(w) - bx;
    let bh = (t.y1 + m).min(h) - by;
    let mut out = TileOut {
        bx,
        by,
        bw,
        bh,
        sum: vec![Vec3::ZERO; (bw * bh) as usize],
        weight: vec![0.0; (bw * bh) as usize],
        stats: TraceStats::default(),
        nan: 0,
        negative: 0,
    };
    let camera = &world.scene.camera;
    let inv = Vec2::new(1.0 / w as f32, 1.0 / h as f32);
    let r = s.filter.radius();
    for y in t.y0..t.y1 {
        for x in t.x0..t.x1 {
            let stream = hash2(s.seed, (y as u64) * w as u64 + x as u64);
            for index in 0..s.spp {
                let sampler = PixelSampler::new(
                    s.sampler,
                    SampleId {
                        stream,
                        pass,
                        index,
                        count: s.spp,
                    },
                );
                let pos = Vec2::new(x as f32, y as f32) + sampler.get_2d(dims::FILM);
                let (ray, time) = camera.generate_ray(
                    pos * inv,
                    sampler.get_2d(dims::LENS),
                    sampler.get_1d(dims::TIME),
                );
                let mut ctx = Context {
                    world,
                    sampler,
                    stats: &mut out.stats,
                };
                let mut l = s.integrator.li(&mut ctx, &ray, time);
                // Guard, count, never hide: a NaN or infinite sample is a
                // bug somewhere; it is zeroed so one cannot ruin a pixel,
                // and reported in the statistics.
                if !l.is_finite() {
                    out.nan += 1;
                    l = Vec3::ZERO;
                }
                if l.min_element() < 0.0 {
                    out.negative += 1;
                    l = l.max(Vec3::ZERO);
                }
                // Splat to every pixel centre within the filter radius.
                let px0 = x.saturating_sub(m).max(bx);
                let px1 = (x + m).min(w - 1);
                let py0 = y.saturating_sub(m).max(by);
                let py1 = (y + m).min(h - 1);
                for py in py0..=py1 {
                    let dy = pos.y - (py as f32 + 0.5);
                    if dy.abs() > r {
                        continue;
                    }
                    let wy = s.filter.eval_1d(dy);
                    for px in px0..=px1 {
                        let wt = wy * s.filter.eval_1d(pos.x - (px as f32 + 0.5));
                        if wt != 0.0 {
                            let k = ((py - by) * bw + (px - bx)) as usize;
                            out.sum[k] += l * wt;
                            out.weight[k] += wt;
                        }
                    }
                }
            }
        }
    }
    out
}
