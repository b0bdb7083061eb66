//! One tile of one pass: its strips' samples traced, guarded, and splatted
//! with the filter into the tile's sums.
//!
//! The sums are exact: each sample adds fixed-point values to the pixels
//! its filter reaches ([`crate::film::sums`], [`crate::film::splat`]),
//! and integer addition does not depend on order or grouping. So a tile's
//! sums are the same however its samples were cut into strips and traced,
//! and the image's (the tiles' sums added up, [`Accumulated::add`]) the
//! same however the frame was cut into tiles, threads and a render farm's
//! parts. The tile also keeps each pixel's own samples for adaptive
//! sampling, in floating point: those are added pixel by pixel, each
//! pixel's samples in the order of their numbers ([`TileOut::add_strip`]),
//! and a pixel belongs to one tile.
//!
//! [`Accumulated::add`]: super::accumulate::Accumulated::add

use std::time::Instant;

use glam::Vec3;

use super::adaptive::TileSums;
use super::aux::Aux;
use super::samples::RoundSamples;
use super::settings::RenderSettings;
use super::stats::TimeSplit;
use super::strip::{self, Slots, Strip, StripPixels};
use crate::film::splat::{Pixels, SplatSums, Splatter};
use crate::film::sums::SumBuffer;
use crate::film::window::PixelWindow;
use crate::integrator::bdpt::Splat;
use crate::integrator::laps::{Lap, Laps};
use crate::integrator::{Integrator, TraceStats};
use crate::world::World;

/// A tile of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tile {
    pub(super) x0: u32,
    pub(super) y0: u32,
    pub(super) x1: u32,
    pub(super) y1: u32,
}

impl Tile {
    /// Number of pixels.
    pub(super) fn pixels(&self) -> u32 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }

    /// The `k`-th pixel in render order (rows top to bottom).
    pub(super) fn pixel(&self, k: u32) -> (u32, u32) {
        let w = self.x1 - self.x0;
        (self.x0 + k % w, self.y0 + k / w)
    }
}

/// A tile's filtered samples over its pixels plus the filter margin.
pub(super) struct TileOut {
    /// Over the tile plus the margin, clipped to the window.
    pub(super) sums: SumBuffer,
    pub(super) stats: TraceStats,
    pub(super) split: TimeSplit,
    pub(super) aux: Option<Aux>,
    /// With adaptive sampling, the tile's pixels' own samples.
    pub(super) own: Option<TileSums>,
    pub(super) nan: u64,
    pub(super) negative: u64,
    /// Pixels rendered, in render order (all of them unless stopped).
    pub(super) pixels_done: u32,
    /// Light the tile's samples add elsewhere on the film (bidirectional
    /// integrators).
    pub(super) splats: Vec<Splat>,
}

/// Renders the round's `samples` of one tile, splatting them into the
/// window's pixels they reach; `stop` is asked before each strip of rows,
/// and once it says so, the rest of the tile is left out.
pub(super) fn render_tile(
    world: &World,
    s: &RenderSettings,
    t: Tile,
    window: &PixelWindow,
    samples: RoundSamples,
    stop: &dyn Fn() -> bool,
) -> TileOut {
    let convergence = samples.convergence();
    let (w, h) = (s.width.max(1), s.height.max(1));
    let splatter = Splatter::new(&s.filter).at_most(super::SAMPLE_LOOP_ISA);
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
    let depth_view = matches!(s.integrator, Integrator::Depth);
    let rows = strip::rows(&s.integrator);
    let mut laps = Laps::default();
    let mut film = SplatSums::new(reach.x0, reach.y0, reach.width(), reach.height());
    // The strip's buffers, kept by the thread from tile to tile.
    Strip::with(|strip| {
        for y0 in (t.y0..t.y1).step_by(rows as usize) {
            if stop() {
                break;
            }
            let y1 = (y0 + rows).min(t.y1);
            if convergence.is_some_and(|c| !c.any_active(t.x0, t.x1, y0, y1)) {
                out.pixels_done += (y1 - y0) * (t.x1 - t.x0);
                continue;
            }
            let pixels = StripPixels {
                x0: t.x0,
                x1: t.x1,
                y0,
                y1,
            };
            strip.render(world, s, pixels, samples, &mut out.stats);
            let clock = Instant::now();
            let slots = &mut strip.slots;
            out.add_strip(slots, pixels, samples, depth_view);
            let pixels = Pixels {
                x0: t.x0,
                x1: t.x1,
                y0,
                y1,
                first: &slots.first,
            };
            film.splat_each(&splatter, pixels, &slots.pos, &slots.radiance);
            laps.lap(clock, Lap::Film);
            out.pixels_done += (y1 - y0) * (t.x1 - t.x0);
        }
        laps += strip.take_times();
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

impl TileOut {
    /// Takes a traced strip's samples, ready for the film's splat: each
    /// guarded in place ([`guard`]) and given to the render passes' sums
    /// and to its pixel's own sums for adaptive sampling, pixel by pixel,
    /// rows top to bottom, each pixel's samples in the order of their
    /// numbers (the slots' order); the light they add elsewhere is
    /// guarded and kept for the pass.
    fn add_strip(
        &mut self,
        slots: &mut Slots,
        pixels: StripPixels,
        samples: RoundSamples,
        depth_view: bool,
    ) {
        for mut splat in slots.splats.drain(..) {
            splat.l = guard(splat.l, &mut self.nan, &mut self.negative);
            self.splats.push(splat);
        }
        let (nan, negative) = (&mut self.nan, &mut self.negative);
        let plain = samples.convergence().is_none() && self.aux.is_none();
        let mut k = 0;
        for y in pixels.y0..pixels.y1 {
            for x in pixels.x0..pixels.x1 {
                for _ in samples.of(x, y) {
                    let raw = slots.radiance[k];
                    let l = guard(raw, nan, negative);
                    if !plain {
                        if let Some(aux) = &mut self.aux {
                            aux.add_sample(x, y, &slots.aux[k], l);
                        }
                        if let Some(own) = &mut self.own {
                            own.at(x, y).add(l);
                        }
                    }
                    // The depth view averages the distances of the
                    // samples that hit (a miss is 0, never a hit): mixing
                    // misses in would draw a near halo at every
                    // silhouette. A pixel no sample hit stays 0. NaN tells
                    // the film to leave a sample out.
                    slots.radiance[k] = if depth_view && raw == Vec3::ZERO {
                        Vec3::NAN
                    } else {
                        l
                    };
                    k += 1;
                }
            }
        }
    }
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
