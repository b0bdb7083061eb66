//! The render loop of stochastic progressive photon mapping
//! ([`crate::integrator::sppm`]): one iteration per sample per pixel, each
//! a camera pass over the window's pixels and a photon pass over the
//! whole scene, then every pixel's radius reduction.
//!
//! A pixel's estimate depends on its own visible points and on the
//! photons, never on other pixels: a window of the frame rendered alone
//! gives the same bits as the whole frame's render over it, so a frame
//! splits by tiles exactly. It does not split by sample ranges: each
//! iteration's radius depends on the ones before.

use std::sync::atomic::Ordering;
use std::time::Instant;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::result::{develop, RenderResult};
use super::settings::RenderSettings;
use super::stats::RenderStats;
use super::watch::{Previews, Progress};
use crate::cpu_time::process_cpu_time;
use crate::film::sums::SumBuffer;
use crate::film::window::PixelWindow;
use crate::integrator::sppm::{self, Grid, PixelStats, VisiblePoint};
use crate::integrator::{Context, TraceStats};
use crate::math::hash::hash2;
use crate::sampler::{dims, PixelSampler, SampleId};
use crate::world::World;

/// A pixel's camera path: the light it found directly, and its visible
/// point.
type CameraSample = (Vec3, Option<VisiblePoint>);

/// SPPM's parameters.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Params {
    pub max_depth: u32,
    /// Initial search radius (0: twice a pixel's width at the distance
    /// from the camera to the scene's centre).
    pub radius: f32,
    /// Photons per iteration (0: one per pixel of the image).
    pub photons: u64,
}

/// Renders `world` with SPPM under `settings`; `start` is when the render
/// began (the time limit counts from it). Each iteration is a camera pass
/// ([`Iterations::camera_pass`]) and a photon pass
/// ([`Iterations::photon_pass`]); a preview may follow it.
pub(crate) fn render(
    world: &World,
    settings: &RenderSettings,
    params: Params,
    progress: &(dyn Fn(Progress) + Sync),
    previews: &mut Previews,
    mut stats: RenderStats,
    start: Instant,
) -> RenderResult {
    let sppm = Iterations::new(world, settings, params);
    let mut pixels = vec![PixelStats::new(sppm.r0); sppm.window.pixels() as usize];
    let render_start = Instant::now();
    let cpu_start = process_cpu_time();
    let cancelled = || {
        settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    };
    let out_of_time = || settings.time_limit.is_some_and(|t| start.elapsed() >= t);
    let mut done = 0;
    for it in 0..sppm.iterations {
        if it > 0 && (cancelled() || out_of_time()) {
            stats.stopped_early = true;
            break;
        }
        let points = sppm.camera_pass(it, &mut pixels, &mut stats);
        sppm.photon_pass(it, &points, &mut pixels, &mut stats);
        done += 1;
        let t = &stats.trace;
        progress(Progress {
            pass: it,
            passes: sppm.iterations,
            tiles_done: 1,
            tiles: 1,
            elapsed: start.elapsed(),
            rays: t.camera_rays + t.bounce_rays + t.shadow_rays,
        });
        if it + 1 < sppm.iterations {
            previews.offer(|| {
                let mut snapshot = stats;
                snapshot.passes = done;
                snapshot.spp = done;
                snapshot.render_time = render_start.elapsed();
                snapshot.stopped_early = true;
                develop(
                    sppm.sums(&pixels, done),
                    None,
                    None,
                    snapshot,
                    settings,
                    None,
                )
            });
        }
    }
    stats.passes = done;
    stats.spp = done;
    stats.render_time = render_start.elapsed();
    stats.render_cpu_time = process_cpu_time().saturating_sub(cpu_start);
    develop(sppm.sums(&pixels, done), None, None, stats, settings, None)
}

/// What every iteration of an SPPM render uses.
struct Iterations<'a, 'w> {
    world: &'a World<'w>,
    settings: &'a RenderSettings,
    params: Params,
    /// The image's size, and its inverse.
    w: u32,
    inv: Vec2,
    /// The pixels rendered.
    window: PixelWindow,
    /// Iterations: one per sample per pixel.
    iterations: u32,
    /// Photons per iteration.
    photons: u64,
    /// The initial search radius.
    r0: f32,
}

impl<'a, 'w> Iterations<'a, 'w> {
    fn new(world: &'a World<'w>, settings: &'a RenderSettings, params: Params) -> Self {
        let (w, h) = (settings.width.max(1), settings.height.max(1));
        let window = settings
            .window
            .unwrap_or(PixelWindow::full(w, h))
            .intersect(&PixelWindow::full(w, h));
        let photons = if params.photons > 0 {
            params.photons
        } else {
            u64::from(w) * u64::from(h)
        };
        let camera = &world.scene.camera;
        let r0 = if params.radius > 0.0 {
            params.radius
        } else {
            let pixel = 2.0 * camera.tan_half_fov() / h as f32;
            (2.0 * pixel * camera.eye.distance(world.center)).max(1e-6 * world.radius)
        };
        Self {
            world,
            settings,
            params,
            w,
            inv: Vec2::new(1.0 / w as f32, 1.0 / h as f32),
            window,
            iterations: settings.spp.max(1),
            photons,
            r0,
        }
    }

    /// Iteration `it`'s camera pass: every pixel's camera path, row by row;
    /// the light found directly is added to `pixels`, the visible points
    /// (in the window's pixel order) returned.
    fn camera_pass(
        &self,
        it: u32,
        pixels: &mut [PixelStats],
        stats: &mut RenderStats,
    ) -> Vec<Option<VisiblePoint>> {
        let (world, settings, window, w) = (self.world, self.settings, &self.window, self.w);
        let camera = &world.scene.camera;
        let rows: Vec<(Vec<CameraSample>, TraceStats)> = (window.y0..window.y1)
            .into_par_iter()
            .map(|y| {
                let mut ts = TraceStats::default();
                let row = (window.x0..window.x1)
                    .map(|x| {
                        let sampler = PixelSampler::new(
                            settings.sampler,
                            SampleId {
                                stream: hash2(
                                    settings.seed,
                                    u64::from(y) * u64::from(w) + u64::from(x),
                                ),
                                pass: 0,
                                index: it,
                                count: self.iterations,
                            },
                        );
                        let pos = Vec2::new(x as f32, y as f32) + sampler.get_2d(dims::FILM);
                        let (ray, time) = camera.generate_ray(
                            pos * self.inv,
                            sampler.get_2d(dims::LENS),
                            sampler.get_1d(dims::TIME),
                        );
                        let mut ctx = Context {
                            world,
                            sampler,
                            stats: &mut ts,
                        };
                        sppm::camera_path(&mut ctx, ray, time, self.params.max_depth)
                    })
                    .collect();
                (row, ts)
            })
            .collect();
        let mut points: Vec<Option<VisiblePoint>> = Vec::with_capacity(pixels.len());
        for (k, (row, ts)) in rows.into_iter().enumerate() {
            stats.trace += ts;
            for (j, (direct, vp)) in row.into_iter().enumerate() {
                let p = &mut pixels[k * window.width() as usize + j];
                p.direct += guard(direct, stats);
                points.push(vp);
            }
        }
        points
    }

    /// Iteration `it`'s photon pass, in chunks whose deposits apply in
    /// order, then every pixel's radius reduction.
    fn photon_pass(
        &self,
        it: u32,
        points: &[Option<VisiblePoint>],
        pixels: &mut [PixelStats],
        stats: &mut RenderStats,
    ) {
        let n = pixels.len();
        let radii: Vec<f32> = pixels.iter().map(|p| p.radius).collect();
        let listed: Vec<(u32, &VisiblePoint)> = points
            .iter()
            .enumerate()
            .filter_map(|(k, vp)| vp.as_ref().map(|vp| (k as u32, vp)))
            .collect();
        let grid = Grid::new(&listed, &radii);
        let camera = &self.world.scene.camera;
        let shutter = (camera.shutter_open, camera.shutter_close);
        let time = 0.5 * (shutter.0 + shutter.1);
        let chunks: Vec<(Vec<sppm::Deposit>, TraceStats)> = sppm::chunks(self.photons)
            .collect::<Vec<_>>()
            .into_par_iter()
            .with_max_len(1)
            .map(|(first, count)| {
                let mut ts = TraceStats::default();
                let d = sppm::trace_photons(
                    self.world,
                    self.settings.seed,
                    it,
                    first,
                    count,
                    self.params.max_depth,
                    time,
                    &grid,
                    points,
                    &radii,
                    &mut ts,
                );
                (d, ts)
            })
            .collect();
        let mut phi = vec![Vec3::ZERO; n];
        let mut m = vec![0u32; n];
        for (deposits, ts) in chunks {
            stats.trace += ts;
            for (k, f) in deposits {
                phi[k as usize] += f;
                m[k as usize] += 1;
            }
        }
        for (k, p) in pixels.iter_mut().enumerate() {
            let f = guard(phi[k], stats);
            p.update(f, m[k]);
        }
    }

    /// The window's sums after `done` iterations.
    fn sums(&self, pixels: &[PixelStats], done: u32) -> SumBuffer {
        let window = &self.window;
        let mut sums = SumBuffer::new(window.x0, window.y0, window.width(), window.height());
        for (s, p) in sums.sums.iter_mut().zip(pixels) {
            s.add_sample(p.radiance(done, self.photons), 1.0);
        }
        sums
    }
}

/// A NaN or infinite value is zeroed and counted, a negative component
/// clamped and counted (as the render loop does for samples).
fn guard(v: Vec3, stats: &mut RenderStats) -> Vec3 {
    super::tile::guard(v, &mut stats.nan_samples, &mut stats.negative_samples)
}
