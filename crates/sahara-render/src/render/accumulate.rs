//! What the completed passes add up to: the window's exact sums, the
//! render passes, the adaptive sampling state and the counts.

use super::adaptive::Convergence;
use super::aux::{Aov, Aux};
use super::ids;
use super::plan::{Frame, PassPlan};
use super::result::{develop, RenderResult};
use super::settings::RenderSettings;
use super::stats::RenderStats;
use super::tile::TileOut;
use crate::film::sums::SumBuffer;
use crate::integrator::bdpt::Splat;
use crate::world::World;

/// What the completed passes add up to.
pub(super) struct Accumulated {
    /// The window's exact sums.
    pub(super) sums: SumBuffer,
    /// The render passes' sums, when asked for.
    pub(super) aux: Option<Aux>,
    /// The adaptive sampling state, when it is on.
    pub(super) convergence: Option<Convergence>,
    pub(super) stats: RenderStats,
    /// Pixels finished in an interrupted first pass (None: not interrupted).
    finished: Option<Vec<bool>>,
    /// How much each light tracing splat counts: a window renders the
    /// light subpaths of its region's samples only, which then stand for
    /// every pixel's of the image.
    splat_scale: f32,
}

impl Accumulated {
    /// Nothing yet: empty sums over `frame`'s window, and `stats` of the
    /// build.
    pub(super) fn new(settings: &RenderSettings, frame: &Frame, stats: RenderStats) -> Self {
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
    pub(super) fn keep_finished(&mut self, frame: &Frame, outs: &[Option<TileOut>]) {
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
    pub(super) fn add(&mut self, settings: &RenderSettings, outs: Vec<Option<TileOut>>) {
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
    pub(super) fn adaptive_round(&mut self) -> bool {
        self.convergence.as_mut().is_some_and(|c| c.update() == 0)
    }

    /// The image of the completed passes, with the counts of samples
    /// taken, and the object and material ids when asked for.
    pub(super) fn finish(
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
        let mut result = develop(
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
