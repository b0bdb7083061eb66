//! Many pixel samples of bidirectional path tracing traced together.
//!
//! Each round extends every sample's camera and light subpaths by one
//! vertex, the closest hits of all their rays found in one batch
//! ([`RayQueries::closest`]). Once every subpath has ended, each sample's
//! strategies are evaluated ([`super::connect`]) with their shadow rays
//! left open, all of those are answered in one batch
//! ([`RayQueries::visible`]), and each sample sums its contributions in
//! the order [`super::sample`] sums them: the image is the same bit for
//! bit, the tree sees rays in batches.

use std::time::Instant;

use glam::{Vec2, Vec3};
use sahara_kd::Ray;

use super::{
    camera_start, connect, light_start, subpath_lengths, Connection, Splat, Strategies, Vertex,
    Walk,
};
use crate::integrator::laps::{Lap, Laps};
use crate::integrator::queries::RayQueries;
use crate::integrator::{Context, TraceStats};
use crate::sampler::PixelSampler;
use crate::world::{SurfaceHit, World};

/// The index of a sample's camera subpath in its [`Sample::paths`].
const CAMERA: usize = 0;
/// The index of a sample's light subpath in its [`Sample::paths`].
const LIGHT: usize = 1;

/// Most samples traced together. A sample's subpaths take up to 19
/// vertices of 304 bytes at the default depth: 128 samples keep them
/// within a core's L2 cache between rounds. On the built-in Cornell box
/// and `scenes/bunny_dof.toml`, batches of 1024 (a strip of four rows at
/// 8 samples per pixel) took 3-5 % more time than batches of 128
/// (docs/performance.md).
const BATCH: usize = 128;

/// The start of a pixel sample: its camera ray, time and random numbers.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraSample {
    /// The camera ray.
    pub ray: Ray,
    /// The sample's time.
    pub time: f32,
    /// The sample's random numbers.
    pub sampler: PixelSampler,
}

/// One pixel sample in flight.
#[derive(Default)]
struct Sample {
    /// The camera subpath and the light subpath.
    paths: [Vec<Vertex>; 2],
    /// The walks extending them (none: the light subpath did not start).
    walks: [Option<Walk>; 2],
}

/// The buffers of the batches, kept from one batch to the next.
#[derive(Default)]
pub(crate) struct BdptBatch {
    /// The samples of a batch (they keep their subpaths' buffers).
    samples: Vec<Sample>,
    /// The subpaths in flight, `(sample, CAMERA or LIGHT)`.
    live: Vec<(u32, usize)>,
    /// Those still in flight after this round.
    next: Vec<(u32, usize)>,
    rays: Vec<Ray>,
    times: Vec<f32>,
    hits: Vec<Option<SurfaceHit>>,
    /// Every sample's contributions, sample after sample.
    connections: Vec<Connection>,
    /// Where each sample's contributions end in `connections`.
    ends: Vec<u32>,
    /// Whether each contribution's shadow ray is unblocked.
    visible: Vec<bool>,
    queries: RayQueries,
    /// Time spent in the batched queries and between them, since the
    /// last [`BdptBatch::take_times`].
    laps: Laps,
}

impl BdptBatch {
    /// The time spent tracing and shading since the last call, and resets
    /// both.
    pub fn take_times(&mut self) -> Laps {
        self.laps.take()
    }

    /// Traces the pixel samples `cameras`, paths of at most `max_depth`
    /// scattering events with `strategies`, in batches of at most
    /// [`BATCH`]: each sample's radiance for its pixel goes to the same
    /// index of `radiance`, and the light tracing contributions to
    /// `splats` (sample by sample, in the order of `cameras`). `film` is
    /// the image's size in pixels.
    #[allow(clippy::too_many_arguments)]
    pub fn trace(
        &mut self,
        world: &World,
        max_depth: u32,
        strategies: Strategies,
        film: Vec2,
        cameras: &[CameraSample],
        radiance: &mut [Vec3],
        stats: &mut TraceStats,
        splats: &mut Vec<Splat>,
    ) {
        assert_eq!(cameras.len(), radiance.len());
        stats.camera_rays += cameras.len() as u64;
        for (c, l) in cameras.chunks(BATCH).zip(radiance.chunks_mut(BATCH)) {
            self.trace_batch(world, max_depth, strategies, film, c, l, stats, splats);
        }
    }

    /// [`BdptBatch::trace`] of one batch.
    #[allow(clippy::too_many_arguments)]
    fn trace_batch(
        &mut self,
        world: &World,
        max_depth: u32,
        strategies: Strategies,
        film: Vec2,
        cameras: &[CameraSample],
        radiance: &mut [Vec3],
        stats: &mut TraceStats,
        splats: &mut Vec<Splat>,
    ) {
        let mut clock = Instant::now();
        let (camera_len, light_len) = subpath_lengths(max_depth, strategies);
        if self.samples.len() < cameras.len() {
            self.samples.resize_with(cameras.len(), Sample::default);
        }
        let samples = &mut self.samples[..cameras.len()];
        self.live.clear();
        for (i, (s, c)) in samples.iter_mut().zip(cameras).enumerate() {
            let mut ctx = Context {
                world,
                sampler: c.sampler,
                stats,
            };
            for path in &mut s.paths {
                path.clear();
            }
            let camera = camera_start(world, &c.ray, camera_len, &mut s.paths[CAMERA]);
            let light = light_start(&mut ctx, light_len, &mut s.paths[LIGHT]);
            s.walks = [Some(camera), light];
            for end in [CAMERA, LIGHT] {
                if s.walks[end].is_some_and(|w| w.open(&s.paths[end])) {
                    self.live.push((i as u32, end));
                }
            }
        }
        // One vertex more on every subpath in flight per round.
        while !self.live.is_empty() {
            self.rays.clear();
            self.times.clear();
            for &(i, end) in &self.live {
                let walk = samples[i as usize].walks[end].expect("in flight");
                self.rays.push(walk.ray);
                self.times.push(cameras[i as usize].time);
            }
            self.hits.clear();
            self.hits.resize(self.live.len(), None);
            clock = self.laps.lap(clock, Lap::Shading);
            self.queries
                .closest(world, &self.rays, &self.times, &mut self.hits);
            clock = self.laps.lap(clock, Lap::Tracing);
            self.next.clear();
            for (&(i, end), hit) in self.live.iter().zip(&self.hits) {
                let s = &mut samples[i as usize];
                let mut ctx = Context {
                    world,
                    sampler: cameras[i as usize].sampler,
                    stats,
                };
                let walk = s.walks[end].as_mut().expect("in flight");
                if walk.extend(&mut ctx, &mut s.paths[end], *hit) {
                    self.next.push((i, end));
                }
            }
            std::mem::swap(&mut self.live, &mut self.next);
        }
        // Every sample's strategies, their shadow rays in one batch.
        self.connections.clear();
        self.ends.clear();
        for (s, c) in samples.iter().zip(cameras) {
            let mut ctx = Context {
                world,
                sampler: c.sampler,
                stats,
            };
            connect(
                &mut ctx,
                &s.paths[CAMERA],
                &s.paths[LIGHT],
                c.time,
                max_depth,
                strategies,
                film,
                &mut self.connections,
            );
            self.ends.push(self.connections.len() as u32);
        }
        let connections = &self.connections;
        clock = self.laps.lap(clock, Lap::Shading);
        self.queries.visible(
            world,
            connections.len(),
            |j| connections[j].shadow.as_ref(),
            &mut self.visible,
        );
        clock = self.laps.lap(clock, Lap::Tracing);
        let mut start = 0;
        for (l, &end) in radiance.iter_mut().zip(&self.ends) {
            let end = end as usize;
            *l = Vec3::ZERO;
            for (c, &v) in connections[start..end]
                .iter()
                .zip(&self.visible[start..end])
            {
                c.apply(v, l, splats);
            }
            start = end;
        }
        self.laps.lap(clock, Lap::Shading);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::wavefront::tests::scene;
    use crate::sampler::{dims, SampleId, SamplerKind};
    use sahara_kd::AccelParams;

    /// Samples traced in batches give each sample the radiance and the
    /// splats [`super::super::sample`] gives it alone, bit for bit and in
    /// the same order, with the same counts, for both strategies, in
    /// scenes traced through the instances' trees in batches and ray by
    /// ray through the top level, over more samples than one batch holds.
    #[test]
    fn batches_give_the_radiance_and_splats_of_single_samples() {
        for extra in [0, 12] {
            let scene = scene(extra);
            let world = World::new(&scene, &AccelParams::default());
            let (w, h, spp) = (12u32, 10u32, 3u32);
            let film = Vec2::new(w as f32, h as f32);
            let mut cameras = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    for index in 0..spp {
                        let sampler = PixelSampler::new(
                            SamplerKind::Sobol,
                            SampleId {
                                stream: (y * w + x) as u64,
                                pass: 0,
                                index,
                                count: spp,
                            },
                        );
                        let pos =
                            (Vec2::new(x as f32, y as f32) + sampler.get_2d(dims::FILM)) / film;
                        let (ray, time) = scene.camera.generate_ray(
                            pos,
                            sampler.get_2d(dims::LENS),
                            sampler.get_1d(dims::TIME),
                        );
                        cameras.push(CameraSample { ray, time, sampler });
                    }
                }
            }
            assert!(cameras.len() > 2 * BATCH);
            for strategies in [Strategies::All, Strategies::LightTracing] {
                let mut batch_stats = TraceStats::default();
                let mut radiance = vec![Vec3::ZERO; cameras.len()];
                let mut batch_splats = Vec::new();
                BdptBatch::default().trace(
                    &world,
                    5,
                    strategies,
                    film,
                    &cameras,
                    &mut radiance,
                    &mut batch_stats,
                    &mut batch_splats,
                );
                let mut single_stats = TraceStats::default();
                let mut single_splats = Vec::new();
                let mut lit = 0;
                for (c, l) in cameras.iter().zip(&radiance) {
                    let mut ctx = Context {
                        world: &world,
                        sampler: c.sampler,
                        stats: &mut single_stats,
                    };
                    ctx.stats.camera_rays += 1;
                    let single = super::super::sample(
                        &mut ctx,
                        &c.ray,
                        c.time,
                        5,
                        strategies,
                        film,
                        &mut single_splats,
                    );
                    assert_eq!(
                        l.to_array().map(f32::to_bits),
                        single.to_array().map(f32::to_bits)
                    );
                    lit += (single.max_element() > 0.0) as usize;
                }
                let bits = |s: &[Splat]| -> Vec<[u32; 5]> {
                    s.iter()
                        .map(|s| {
                            let [a, b] = s.pos.to_array().map(f32::to_bits);
                            let [c, d, e] = s.l.to_array().map(f32::to_bits);
                            [a, b, c, d, e]
                        })
                        .collect()
                };
                assert_eq!(bits(&batch_splats), bits(&single_splats));
                assert!(
                    lit > cameras.len() / 4 && batch_splats.len() > 10,
                    "{strategies:?}: {lit} lit, {} splats",
                    batch_splats.len()
                );
                assert_eq!(batch_stats, single_stats, "{strategies:?}");
                assert!(batch_stats.shadow_rays > 0 && batch_stats.bounce_rays > 0);
            }
        }
    }
}
