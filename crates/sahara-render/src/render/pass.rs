//! One pass: every tile of the frame rendered on the thread pool, with
//! progress reports and early stops.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};

use rayon::prelude::*;

use super::plan::Frame;
use super::samples::RoundSamples;
use super::settings::RenderSettings;
use super::stop::Stop;
use super::tile::{render_tile, TileOut};
use super::watch::Progress;
use crate::world::World;

/// What a render's passes render with: the scene, the settings, the
/// frame's tiles and when to stop.
pub(super) struct Run<'a, 'w> {
    pub(super) world: &'a World<'w>,
    pub(super) settings: &'a RenderSettings,
    pub(super) frame: Frame,
    pub(super) stop: Stop<'a>,
    pub(super) progress: &'a (dyn Fn(Progress) + Sync),
    /// Rays traced so far, for the progress reports.
    pub(super) rays: AtomicU64,
}

impl Run<'_, '_> {
    /// Renders pass `n` (of `passes`) of every tile in parallel, reporting
    /// progress after each; a tile not started once the render stops
    /// (cancel, or the time limit after the first pass) is `None`, and in
    /// the first pass a cancel stops tiles pixel by pixel, so that a long
    /// first pass still leaves the pixels it finished.
    pub(super) fn pass(&self, n: u32, passes: u32, samples: RoundSamples) -> Vec<Option<TileOut>> {
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
