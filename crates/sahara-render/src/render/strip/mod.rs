//! A strip of a tile's rows, and the sample loops that trace its samples.
//!
//! A tile is rendered a strip of rows at a time ([`rows`]). A strip's
//! samples have fixed places, their slots ([`Slots`]): pixel by pixel,
//! rows top to bottom, each pixel's samples of the round in the order of
//! their numbers. A sample loop traces the samples in whatever order and
//! grouping suits it, and leaves each one's film position, radiance and
//! auxiliary values in its slot ([`Slots::slot`]); the tile then reads the
//! slots in order (`super::tile`).
//!
//! The loops, chosen by the integrator ([`SampleLoop::of`]):
//! - `single`: one sample at a time, from camera ray to end
//!   ([`Integrator::li_splats`]): the debug views, ambient occlusion, and
//!   the path tracers in a scene with media;
//! - `stepped`: the wavefront, every path of the strip a step at a time,
//!   in camera-packet order (`path` and `distribution`);
//! - `bidirectional`: camera and light subpaths in batches (`bdpt`,
//!   `lightpath`);
//! - `lanes`: paths in SIMD lanes, every step of 8 or 16 paths at once
//!   (`path`, as [`RenderSettings::path_loop`] asks).
//!
//! What every loop keeps, and with it the image's bits for a seed:
//! - a sample's random numbers come from [`CameraSamples::at`] for its
//!   pixel and number;
//! - a sample's result depends on that sample alone, never on which
//!   samples share its batch (or its packet, or its vector lanes), how
//!   many there are, or the order they are traced in;
//! - the result goes to the sample's slot, and the light it adds to other
//!   pixels to [`Slots::splats`] (added to exact sums, so in any order).
//!
//! A new way of tracing a strip is a module beside these and a variant of
//! [`SampleLoop`], held to the same.

mod bidirectional;
mod lanes;
mod single;
mod stepped;

use glam::{Vec2, Vec3};

use super::samples::{CameraSamples, RoundSamples};
use super::settings::RenderSettings;
use crate::integrator::bdpt::{Splat, Strategies};
use crate::integrator::laps::Laps;
use crate::integrator::{AuxSample, Integrator, TraceStats};
use crate::sampler::PixelSampler;
use crate::world::World;

/// Rows of a tile whose samples are traced as one batch by the stepped
/// and the bidirectional integrators: 4x4 pixel blocks make the camera
/// packets.
const STRIP_ROWS: u32 = 4;

/// The rows of a strip for `integrator`: [`STRIP_ROWS`] for those that
/// trace their samples in batches, one for the others.
pub(super) fn rows(integrator: &Integrator) -> u32 {
    let batched = integrator.is_stepped() || integrator.bidirectional().is_some();
    if batched {
        STRIP_ROWS
    } else {
        1
    }
}

thread_local! {
    /// This thread's strip buffers, reused by every tile it renders (fresh
    /// ones per tile cost page faults of their own).
    static STRIP: std::cell::RefCell<Strip> = std::cell::RefCell::new(Strip::default());
}

/// A strip's buffers: the slots of its samples, and each sample loop's
/// own.
#[derive(Default)]
pub(super) struct Strip {
    /// The samples of the strip last rendered.
    pub(super) slots: Slots,
    stepped: stepped::Stepped,
    bidirectional: bidirectional::Bidirectional,
    lanes: lanes::Lanes,
}

/// The pixels `[x0, x1) x [y0, y1)` of a strip.
#[derive(Clone, Copy)]
pub(super) struct StripPixels {
    pub(super) x0: u32,
    pub(super) x1: u32,
    pub(super) y0: u32,
    pub(super) y1: u32,
}

impl StripPixels {
    /// The pixels, rows top to bottom.
    fn iter(self) -> impl Iterator<Item = (u32, u32)> {
        (self.y0..self.y1).flat_map(move |y| (self.x0..self.x1).map(move |x| (x, y)))
    }
}

/// What a sample loop traces: the round's samples of a strip's pixels.
#[derive(Clone, Copy)]
struct StripRound<'a> {
    settings: &'a RenderSettings,
    pixels: StripPixels,
    samples: RoundSamples<'a>,
    cameras: &'a CameraSamples<'a>,
}

impl StripRound<'_> {
    /// The image's size in pixels.
    fn film(&self) -> Vec2 {
        Vec2::new(
            self.settings.width.max(1) as f32,
            self.settings.height.max(1) as f32,
        )
    }

    /// True when the settings ask for render passes.
    fn aux(&self) -> bool {
        !self.settings.aovs.is_empty()
    }
}

/// A strip's samples in their slots: pixel by pixel (rows top to bottom),
/// each pixel's samples in the order of their numbers.
#[derive(Default)]
pub(super) struct Slots {
    /// Where each pixel's samples start; a pixel has the slots up to the
    /// next pixel's start.
    pub(super) first: Vec<u32>,
    /// Each sample's film position.
    pub(super) pos: Vec<Vec2>,
    /// Each sample's radiance.
    pub(super) radiance: Vec<Vec3>,
    /// Each sample's auxiliary values (when the settings ask for them).
    pub(super) aux: Vec<AuxSample>,
    /// Light the samples add elsewhere on the film.
    pub(super) splats: Vec<Splat>,
}

impl Slots {
    /// Sizes the slots for the round's samples of its pixels, and notes
    /// where each pixel's samples start.
    fn lay_out(&mut self, round: &StripRound) {
        self.first.clear();
        let mut n = 0usize;
        for (x, y) in round.pixels.iter() {
            self.first.push(n as u32);
            n += round.samples.of(x, y).len();
        }
        self.pos.clear();
        self.pos.resize(n, Vec2::ZERO);
        self.radiance.clear();
        self.radiance.resize(n, Vec3::ZERO);
        self.aux.clear();
        if round.aux() {
            self.aux.resize(n, AuxSample::default());
        }
    }

    /// The slot of sample `g` of pixel `(x, y)`.
    #[inline]
    fn slot(&self, round: &StripRound, x: u32, y: u32, g: u32) -> usize {
        let p = round.pixels;
        let start = round.samples.of(x, y).start;
        (self.first[((y - p.y0) * (p.x1 - p.x0) + (x - p.x0)) as usize] + g - start) as usize
    }

    /// Calls `each` with every sample of the round's pixels in
    /// camera-packet order, noting each sample's film position in its slot
    /// and its slot in `slot` (cleared first): 4x4 pixel blocks, the pixels
    /// of a block in Morton order (2x2 blocks of 2x2), each pixel's samples
    /// together. A run of 16 samples is then one pixel's, or a 2x2 block's
    /// when a pixel takes 4, whose rays leave close together.
    fn in_camera_packet_order(
        &mut self,
        round: &StripRound,
        slot: &mut Vec<u32>,
        mut each: impl FnMut(PixelSampler, sahara_kd::Ray, f32),
    ) {
        let StripPixels { x0, x1, y0, y1 } = round.pixels;
        slot.clear();
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
                for g in round.samples.of(x, y) {
                    let (sampler, pos, ray, time) = round.cameras.at(x, y, g);
                    let k = self.slot(round, x, y, g);
                    self.pos[k] = pos;
                    slot.push(k as u32);
                    each(sampler, ray, time);
                }
            }
        }
    }
}

/// How a strip's samples are traced, by integrator.
#[derive(Clone, Copy)]
enum SampleLoop {
    /// Camera and light subpaths in batches ([`bidirectional`]).
    Bidirectional {
        max_depth: u32,
        strategies: Strategies,
    },
    /// The wavefront, a step of every path at a time ([`stepped`]).
    Stepped,
    /// Paths in SIMD lanes ([`lanes`]), lanes refilled as paths end if
    /// `refill`.
    Lanes { refill: bool },
    /// One sample at a time ([`single`]).
    Single,
}

impl SampleLoop {
    /// The loop of the settings' integrator in `world`.
    fn of(s: &RenderSettings, world: &World) -> Self {
        let integrator = &s.integrator;
        // A guided render takes the scalar loop: the guide is sampled and
        // trained by the scalar path step, and the lanes have no guided
        // sampling.
        let lanes = s.path_loop.lanes(integrator, world.scene);
        if let Some(refill) = lanes.filter(|_| world.guide().is_none()) {
            Self::Lanes { refill }
        } else if let Some((max_depth, strategies)) = integrator.bidirectional() {
            Self::Bidirectional {
                max_depth,
                strategies,
            }
        } else if integrator.is_stepped() && !world.has_media() {
            // A scene with media takes the volumetric path tracer, one
            // path at a time.
            Self::Stepped
        } else {
            Self::Single
        }
    }
}

impl Strip {
    /// Runs `f` with this thread's strip.
    pub(super) fn with<R>(f: impl FnOnce(&mut Strip) -> R) -> R {
        STRIP.with_borrow_mut(f)
    }

    /// Renders the round's `samples` of `pixels`: lays out the slots, then
    /// traces the samples with the integrator's loop, leaving each in its
    /// slot.
    pub(super) fn render(
        &mut self,
        world: &World,
        s: &RenderSettings,
        pixels: StripPixels,
        samples: RoundSamples,
        stats: &mut TraceStats,
    ) {
        let cameras = CameraSamples::new(s, &world.scene.camera);
        let round = StripRound {
            settings: s,
            pixels,
            samples,
            cameras: &cameras,
        };
        let slots = &mut self.slots;
        slots.lay_out(&round);
        match SampleLoop::of(s, world) {
            SampleLoop::Bidirectional {
                max_depth,
                strategies,
            } => self
                .bidirectional
                .trace(slots, world, &round, max_depth, strategies, stats),
            SampleLoop::Stepped => self.stepped.trace(slots, world, &round, stats),
            SampleLoop::Lanes { refill } => self.lanes.trace(slots, world, &round, stats, refill),
            SampleLoop::Single => single::trace(slots, world, &round, stats),
        }
    }

    /// The time the batched loops spent tracing and shading since last
    /// asked.
    pub(super) fn take_times(&mut self) -> Laps {
        let mut laps = self.stepped.take_times();
        laps += self.bidirectional.take_times();
        laps += self.lanes.take_times();
        laps
    }
}
