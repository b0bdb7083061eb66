//! Debug views: normals, depth, ambient occlusion, traversal cost.

use glam::Vec3;
use sahara_kd::{Ray, TraversalCounters};

use super::Context;
use crate::math::warp::{cosine_hemisphere, Frame};
use crate::sampler::dims;

/// The shading normal at the first hit as `n / 2 + 1/2`.
pub fn normals(ctx: &mut Context, ray: &Ray, time: f32) -> Vec3 {
    match ctx.world.intersect(ray, time) {
        Some(h) => h.ns * 0.5 + Vec3::splat(0.5),
        None => Vec3::ZERO,
    }
}

/// Distance to the first hit.
pub fn depth(ctx: &mut Context, ray: &Ray, time: f32) -> Vec3 {
    match ctx.world.intersect(ray, time) {
        Some(h) => Vec3::splat(h.t * ray.dir.length()),
        None => Vec3::ZERO,
    }
}

/// Fraction of cosine-weighted directions about the visible side's normal
/// not blocked within `distance`.
pub fn ao(ctx: &mut Context, ray: &Ray, time: f32, samples: u32, distance: f32) -> Vec3 {
    let Some(h) = ctx.world.intersect(ray, time) else {
        return Vec3::ZERO;
    };
    let dist = if distance > 0.0 {
        distance
    } else {
        0.1 * ctx.world.radius
    };
    let n = if h.ns.dot(ray.dir) > 0.0 { -h.ns } else { h.ns };
    let frame = Frame::from_normal(n);
    let mut open = 0u32;
    for k in 0..samples {
        let w = frame.to_world(cosine_hemisphere(ctx.sampler.get_2d(dims::extra(0, 0, k))));
        ctx.stats.shadow_rays += 1;
        if ctx.world.unoccluded(h.spawn_origin(w), w, dist, time, None) {
            open += 1;
        }
    }
    Vec3::splat(open as f32 / samples as f32)
}

/// Raw work of the camera ray: traversal steps (inner nodes and leaves,
/// top-level box tests included) in x, triangle tests in y. The render
/// loop turns the averages into a heat map.
pub fn cost(ctx: &mut Context, ray: &Ray, time: f32) -> Vec3 {
    let mut c = TraversalCounters::default();
    ctx.world.intersect_counted(ray, time, &mut c);
    ctx.stats.traversal += c;
    Vec3::new((c.inner + c.leaves) as f32, c.triangles as f32, 0.0)
}
