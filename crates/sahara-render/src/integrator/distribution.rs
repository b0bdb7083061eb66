//! Distribution ray tracing (Cook, Porter, Carpenter 1984) in the Whitted
//! style: at every hit, direct light from every light with its samples
//! spread over the light; recursion only through mirror, glossy and
//! refractive lobes, one lobe-sampled ray per pixel sample.
//!
//! Emission and the environment are counted on camera rays and after
//! delta bounces only; after a glossy bounce the direct-lighting estimate
//! already holds them.

use glam::Vec3;
use sahara_kd::Ray;

use super::{light_contribution, Context, Shading};
use crate::sampler::dims;

/// Radiance along `ray` with up to `max_depth` specular/glossy bounces.
pub fn li(ctx: &mut Context, ray: &Ray, time: f32, max_depth: u32, light_samples: u32) -> Vec3 {
    let world = ctx.world;
    let mut l = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    let mut ray = *ray;
    let mut count_emission = true;
    let mut depth = 0u32;
    loop {
        let Some(hit) = world.intersect(&ray, time) else {
            if count_emission {
                l += beta * world.env_radiance(ray.dir);
            }
            break;
        };
        let sh = Shading::new(world, &hit, ray.dir);
        let mat = sh.material;
        if count_emission {
            l += beta * mat.emitted(hit.ng.dot(sh.wo_world));
        }
        if !mat.bsdf.is_delta() {
            for (j, light) in world.lights.iter().enumerate() {
                let n = if light.is_delta() { 1 } else { light_samples };
                let mut sum = Vec3::ZERO;
                for k in 0..n {
                    let u = ctx.sampler.get_2d(dims::extra(depth, j as u32, k));
                    let Some(ls) = light.sample(hit.p, u) else {
                        continue;
                    };
                    if let Some((c, _)) = light_contribution(ctx, &hit, &sh, &ls, time) {
                        sum += c / ls.pdf;
                    }
                }
                l += beta * sum / n as f32;
            }
        }
        if depth >= max_depth || mat.bsdf.is_diffuse() {
            break;
        }
        let Some((s, next)) = sh.sample_bounce(ctx, &hit, depth) else {
            break;
        };
        beta *= s.weight;
        count_emission = s.delta;
        ray = next;
        depth += 1;
        if beta == Vec3::ZERO {
            break;
        }
    }
    l
}
