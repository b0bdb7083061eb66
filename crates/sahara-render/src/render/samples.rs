//! Which samples a round draws, and what each of them is.
//!
//! A pixel's samples are numbered over all passes: sample `g` is index
//! `g % pass_size` of pass `g / pass_size` ([`RenderSettings::pass_size`]).
//! A round gives each pixel a run of those numbers ([`RoundSamples`]): a
//! pass's (the indices of the sample range within it,
//! [`PassPlan::numbered`]), or with adaptive sampling the ones after those
//! the pixel has ([`Convergence::round`]). Every random number of sample
//! `g` of pixel `(x, y)` is drawn from the seed, the pixel, `g`'s pass and
//! index and the dimension ([`CameraSamples::at`]), and from nothing else:
//! not the tile, the strip, the thread, nor where in a batch or in what
//! order the sample is traced. So any sample can be rendered alone, and a
//! frame cut into windows or sample ranges (a render farm's parts) draws
//! the same samples as the whole.
//!
//! [`PassPlan::numbered`]: super::plan::PassPlan::numbered

use glam::Vec2;

use super::adaptive::Convergence;
use super::settings::RenderSettings;
use crate::math::hash::hash2;
use crate::sampler::{dims, PixelSampler, SampleId};
use crate::scene::camera::Camera;

/// The samples one round gives each pixel, numbered over all passes:
/// sample `g` is index `g % pass_size` of pass `g / pass_size`.
#[derive(Clone, Copy)]
pub(super) enum RoundSamples<'a> {
    /// Every pixel samples `start..end`.
    Every { start: u32, end: u32 },
    /// Each pixel those adaptive sampling gives it.
    Adaptive(&'a Convergence),
}

impl RoundSamples<'_> {
    /// Every pixel samples `numbers`.
    pub(super) fn every(numbers: std::ops::Range<u32>) -> Self {
        Self::Every {
            start: numbers.start,
            end: numbers.end,
        }
    }

    /// The samples of pixel `(x, y)`.
    #[inline]
    pub(super) fn of(&self, x: u32, y: u32) -> std::ops::Range<u32> {
        match self {
            Self::Every { start, end } => *start..*end,
            Self::Adaptive(c) => c.round(x, y),
        }
    }

    /// The convergence state, with adaptive sampling.
    pub(super) fn convergence(&self) -> Option<&Convergence> {
        match self {
            Self::Every { .. } => None,
            Self::Adaptive(c) => Some(c),
        }
    }
}

/// Where the samples of a render's camera come from: sample `g` of pixel
/// `(x, y)` has its sampler, film position and camera ray.
pub(super) struct CameraSamples<'a> {
    s: &'a RenderSettings,
    camera: &'a Camera,
    w: u32,
    inv: Vec2,
    /// Samples per pixel of a pass.
    spp: u32,
}

impl<'a> CameraSamples<'a> {
    /// The samples of `camera` under `settings`.
    pub(super) fn new(settings: &'a RenderSettings, camera: &'a Camera) -> Self {
        let (w, h) = (settings.width.max(1), settings.height.max(1));
        Self {
            s: settings,
            camera,
            w,
            inv: Vec2::new(1.0 / w as f32, 1.0 / h as f32),
            spp: settings.pass_size(),
        }
    }

    /// Sample `g` of pixel `(x, y)`: its sampler (the stream of the seed
    /// and the pixel, at index `g % spp` of pass `g / spp`), its film
    /// position, its camera ray and its time. The one place a sample's
    /// random numbers are chosen: a function of the seed, the pixel and
    /// `g`, whoever asks and in whatever order.
    #[inline]
    pub(super) fn at(&self, x: u32, y: u32, g: u32) -> (PixelSampler, Vec2, sahara_kd::Ray, f32) {
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
