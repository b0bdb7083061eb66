//! Unidirectional path tracing with next-event estimation, multiple
//! importance sampling (power heuristic) of light and BSDF sampling, and
//! Russian roulette.

use glam::Vec3;
use sahara_kd::Ray;

use super::{light_contribution, Context, Shading};
use crate::sampler::dims;
use crate::sampling::power_heuristic;

/// Radiance along `ray`. `max_depth` counts scattering events: emission seen
/// after `d` bounces is added at vertex `d`, light sampled at vertex `d`
/// arrives after `d + 1`, and nothing beyond `max_depth` bounces.
pub fn li(ctx: &mut Context, ray: &Ray, time: f32, max_depth: u32, rr_depth: u32) -> Vec3 {
    let world = ctx.world;
    let mut l = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    let mut ray = *ray;
    // The previous scattering: was it a delta lobe, its pdf, its point.
    let mut prev_delta = true;
    let mut prev_pdf = 0.0f32;
    let mut prev_p = ray.origin;
    let mut depth = 0u32;
    loop {
        let Some(hit) = world.intersect(&ray, time) else {
            if world.has_environment() {
                let le = world.env_radiance(ray.dir);
                let w = if prev_delta {
                    1.0
                } else {
                    power_heuristic(prev_pdf, world.env_pdf(ray.dir))
                };
                l += beta * le * w;
            }
            break;
        };
        let sh = Shading::new(world, &hit, ray.dir);
        let mat = sh.material;
        if mat.is_emissive() {
            let le = mat.emitted(hit.ng.dot(sh.wo_world));
            if le != Vec3::ZERO {
                let w = if prev_delta {
                    1.0
                } else {
                    let lp = world.light_pdf(prev_p, &hit, ray.dir);
                    // Emitters that light sampling never picks (moving
                    // ones) are found by BSDF sampling alone: weight 1.
                    if lp > 0.0 {
                        power_heuristic(prev_pdf, lp)
                    } else {
                        1.0
                    }
                };
                l += beta * le * w;
            }
        }
        if depth >= max_depth {
            break;
        }
        // Next-event estimation: one light, chosen by power.
        if !mat.bsdf.is_delta() {
            let u_pick = ctx.sampler.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
            let u = ctx.sampler.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
            if let Some((ls, pmf)) = world.sample_light(hit.p, u_pick, u) {
                if let Some((c, bsdf_pdf)) = light_contribution(ctx, &hit, &sh, &ls, time) {
                    let light_pdf = pmf * ls.pdf;
                    let w = if ls.delta {
                        1.0
                    } else {
                        power_heuristic(light_pdf, bsdf_pdf)
                    };
                    l += beta * c * (w / light_pdf);
                }
            }
        }
        // Continue the path by sampling the BSDF.
        let Some((s, next)) = sh.sample_bounce(ctx, &hit, depth) else {
            break;
        };
        beta *= s.weight;
        prev_delta = s.delta;
        prev_pdf = s.pdf;
        prev_p = hit.p;
        ray = next;
        depth += 1;
        // Russian roulette: continue with probability max(beta), so paths
        // carrying little keep a bounded weight.
        if depth >= rr_depth {
            let q = beta.max_element().min(1.0);
            if q <= 0.0 {
                break;
            }
            if q < 1.0 {
                let q = q.max(0.05);
                if ctx.sampler.get_1d(dims::bounce(depth, dims::ROULETTE)) >= q {
                    break;
                }
                beta /= q;
            }
        }
        if beta == Vec3::ZERO {
            break;
        }
    }
    l
}
