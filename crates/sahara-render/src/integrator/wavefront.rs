//! Many pixel samples' paths traced together, one step at a time.
//!
//! Each round finds the closest hits of every live path's ray in one batch
//! (the camera rays as 16-ray packets), takes every path's step
//! ([`super::state`]), then answers all the shadow rays the steps asked for
//! in one batch and applies their contributions. A sample's radiance is
//! summed in the order [`Integrator::li`] sums it, so the image is the same
//! bit for bit; what changes is that the tree sees rays in batches, which
//! lets coherent ones share a traversal.

use std::time::Instant;

use sahara_kd::{Ray, PACKET16};

use super::laps::{Lap, Laps};
use super::queries::RayQueries;
use super::state::{Deferred, PathState};
use super::{Context, Integrator, TraceStats};
use crate::world::{SurfaceHit, World};

/// The buffers of a batch, kept from one batch to the next.
#[derive(Default)]
pub(crate) struct Wavefront {
    /// Indices of the live paths.
    live: Vec<u32>,
    /// The live paths after this round's steps.
    next: Vec<u32>,
    rays: Vec<Ray>,
    times: Vec<f32>,
    hits: Vec<Option<SurfaceHit>>,
    /// The round's deferred contributions, and the path each belongs to.
    deferred: Vec<Deferred>,
    owner: Vec<u32>,
    /// Whether each deferred contribution's shadow ray is unblocked.
    visible: Vec<bool>,
    /// The batched closest-hit and shadow queries.
    queries: RayQueries,
    /// Time spent finding hits and answering shadow rays, and in the
    /// paths' steps, since the last [`Wavefront::take_times`].
    laps: Laps,
}

impl Wavefront {
    /// The time spent tracing and shading since the last call, and resets
    /// both.
    pub fn take_times(&mut self) -> Laps {
        self.laps.take()
    }

    /// Traces every path of `paths` to its end with `integrator` (one of
    /// the stepped ones), leaving each sample's radiance in its `l`.
    /// Consecutive runs of [`PACKET16`] paths start with one camera packet
    /// (order them so that a run's rays leave close together: one pixel's
    /// samples, or a small block of pixels).
    pub fn trace(
        &mut self,
        integrator: &Integrator,
        world: &World,
        stats: &mut TraceStats,
        paths: &mut [PathState],
    ) {
        debug_assert!(integrator.is_stepped());
        stats.camera_rays += paths.len() as u64;
        self.live.clear();
        self.live.extend(0..paths.len() as u32);
        let mut first = true;
        // Each stretch of the round is timed as tracing or shading: the
        // clock is read a few times per round of the whole batch.
        let mut clock = Instant::now();
        while !self.live.is_empty() {
            self.rays.clear();
            self.times.clear();
            for &i in &self.live {
                self.rays.push(paths[i as usize].ray);
                self.times.push(paths[i as usize].time);
            }
            self.hits.clear();
            self.hits.resize(self.live.len(), None);
            clock = self.laps.lap(clock, Lap::Shading);
            if first {
                for ((r, t), h) in self
                    .rays
                    .chunks(PACKET16)
                    .zip(self.times.chunks(PACKET16))
                    .zip(self.hits.chunks_mut(PACKET16))
                {
                    world.intersect_packet(r, t, h);
                }
                first = false;
            } else {
                self.queries
                    .closest(world, &self.rays, &self.times, &mut self.hits);
            }
            clock = self.laps.lap(clock, Lap::Tracing);
            // Every live path's step.
            self.deferred.clear();
            self.owner.clear();
            self.next.clear();
            for (&i, hit) in self.live.iter().zip(&self.hits) {
                let st = &mut paths[i as usize];
                let mut ctx = Context {
                    world,
                    sampler: st.sampler,
                    stats,
                };
                let more = integrator.step(&mut ctx, st, *hit, &mut self.deferred);
                self.owner.resize(self.deferred.len(), i);
                if more {
                    self.next.push(i);
                }
            }
            clock = self.laps.lap(clock, Lap::Shading);
            // The shadow rays in one batch, then their contributions in
            // the order made.
            let deferred = &self.deferred;
            self.queries.visible(
                world,
                deferred.len(),
                |j| deferred[j].shadow.as_ref(),
                &mut self.visible,
            );
            clock = self.laps.lap(clock, Lap::Tracing);
            for ((d, &i), &v) in self.deferred.iter().zip(&self.owner).zip(&self.visible) {
                paths[i as usize].apply(&d.op, v);
            }
            std::mem::swap(&mut self.live, &mut self.next);
        }
        self.laps.lap(clock, Lap::Shading);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::light::environment::Environment;
    use crate::light::Light;
    use crate::material::Material;
    use crate::sampler::{dims, PixelSampler, SampleId, SamplerKind};
    use crate::scene::camera::Camera;
    use crate::scene::instance::{Instance, Srt};
    use crate::scene::shape::Shape;
    use crate::scene::Scene;
    use glam::{Quat, Vec2, Vec3};
    use sahara_kd::AccelParams;

    /// A scene with every kind of light and lobe, a moving instance, a
    /// thin lens and a shutter, and `extra` more small spheres (past the
    /// packet path's instance count, the packets go ray by ray).
    pub(crate) fn scene(extra: usize) -> Scene {
        let cam = Camera::look_at(Vec3::new(0.0, 2.0, -6.0), Vec3::ZERO, Vec3::Y, 50.0, 1.0)
            .with_thin_lens(0.05, 6.0)
            .with_shutter(0.0, 1.0);
        let mut scene = Scene::new(cam);
        let floor = scene.add_material(Material::diffuse(Vec3::splat(0.6)));
        let glass = scene.add_material(Material::glass(1.5));
        let rough = scene.add_material(Material::conductor(Vec3::new(0.9, 0.6, 0.2), 0.3));
        let mirror = scene.add_material(Material::mirror(Vec3::splat(0.9)));
        let lamp = scene.add_material(Material::emitter(Vec3::new(5.0, 4.0, 3.0)));
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-5.0, -1.0, -5.0),
                edge_u: Vec3::new(0.0, 0.0, 10.0),
                edge_v: Vec3::new(10.0, 0.0, 0.0),
            },
            floor,
        );
        for (x, m) in [(-1.5, glass), (1.5, rough)] {
            scene.add_shape(
                Shape::Sphere {
                    center: Vec3::new(x, 0.0, 0.0),
                    radius: 1.0,
                },
                m,
            );
        }
        scene.add_shape(
            Shape::Disc {
                center: Vec3::new(0.0, 3.0, 0.0),
                normal: -Vec3::Y,
                radius: 0.5,
            },
            lamp,
        );
        let ball = scene.add_mesh(
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: 0.4,
            }
            .to_mesh(),
        );
        scene.add_instance(Instance::moving(
            ball,
            Srt::translation(Vec3::new(0.0, 1.0, -1.0)),
            Srt {
                scale: Vec3::splat(1.5),
                rotation: Quat::from_rotation_y(1.0),
                translation: Vec3::new(0.8, 1.2, -1.0),
            },
            Some(mirror),
        ));
        // Instances of one mesh, which stay two-level (a mesh of its own
        // each would go into the world tree).
        let small = scene.add_mesh(
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: 0.3,
            }
            .to_mesh(),
        );
        for k in 0..extra {
            let a = k as f32 * 0.7;
            scene.add_instance(Instance::new(
                small,
                glam::Affine3A::from_translation(Vec3::new(3.0 * a.cos(), -0.7, 3.0 * a.sin())),
                Some([floor, rough, glass][k % 3]),
            ));
        }
        scene.add_light(Light::point(Vec3::new(2.0, 3.0, -2.0), Vec3::splat(10.0)));
        scene.add_light(Light::directional(
            Vec3::new(-1.0, -2.0, 1.0),
            Vec3::splat(0.5),
        ));
        scene.environment = Some(Environment::Constant(Vec3::splat(0.2)));
        scene.validate().unwrap();
        scene
    }

    /// Batched paths give every sample the radiance `li` gives it, bit for
    /// bit, for both stepped integrators, in scenes traced with packets
    /// through the instances and ray by ray through the top level.
    #[test]
    fn batches_give_the_radiance_of_single_paths() {
        for extra in [0, 12] {
            let scene = scene(extra);
            let world = World::new(&scene, &AccelParams::default());
            assert_eq!(world.accel.two_level_count() > 8, extra > 0);
            assert!(world.accel.merged_count() > 0);
            for integrator in ["path", "distribution"] {
                let integrator = Integrator::named(integrator).unwrap();
                let (w, h, spp) = (12u32, 10u32, 3u32);
                let mut paths = Vec::new();
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
                            let film = (Vec2::new(x as f32, y as f32) + sampler.get_2d(dims::FILM))
                                / Vec2::new(w as f32, h as f32);
                            let (ray, time) = scene.camera.generate_ray(
                                film,
                                sampler.get_2d(dims::LENS),
                                sampler.get_1d(dims::TIME),
                            );
                            paths.push(PathState::new(ray, time, sampler));
                        }
                    }
                }
                let starts = paths.clone();
                let mut batch_stats = TraceStats::default();
                Wavefront::default().trace(&integrator, &world, &mut batch_stats, &mut paths);
                let mut single_stats = TraceStats::default();
                let mut lit = 0;
                for (p, s) in paths.iter().zip(&starts) {
                    let mut ctx = Context {
                        world: &world,
                        sampler: s.sampler,
                        stats: &mut single_stats,
                    };
                    let l = integrator.li(&mut ctx, &s.ray, s.time);
                    assert_eq!(
                        p.l.to_array().map(f32::to_bits),
                        l.to_array().map(f32::to_bits)
                    );
                    lit += (l.max_element() > 0.0) as u32;
                }
                assert!(lit as usize > paths.len() / 2, "{integrator:?}: {lit} lit");
                assert_eq!(batch_stats, single_stats, "{integrator:?}");
                assert!(batch_stats.shadow_rays > 0 && batch_stats.bounce_rays > 0);
            }
        }
    }
}
