//! What a render counts and times: [`RenderStats`], and where the render
//! threads' time went ([`TimeSplit`]).

use std::time::Duration;

use super::adaptive::AdaptiveStats;
use crate::accel::AccelLayout;
use crate::integrator::TraceStats;

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
