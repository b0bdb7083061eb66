//! Unidirectional path tracing with next-event estimation, multiple
//! importance sampling (power heuristic) of light and BSDF sampling, and
//! Russian roulette.

use super::guiding::{self, AtVertex};
use super::state::{Deferred, Op, PathState};
use super::{escaped, light_contribution, Context, Shading};
use crate::math::warp::power_heuristic;
use crate::sampler::dims;
use crate::world::SurfaceHit;
use glam::Vec3;

/// One step of the path in `st`, whose ray found `hit`: emission seen there,
/// next-event estimation (its contribution deferred to `out`, waiting on
/// the shadow ray) and the next ray. Returns whether the path goes on.
///
/// `max_depth` counts scattering events: emission seen after `d` bounces is
/// added at vertex `d`, light sampled at vertex `d` arrives after `d + 1`,
/// and nothing beyond `max_depth` bounces.
pub(crate) fn step(
    ctx: &mut Context,
    st: &mut PathState,
    hit: Option<SurfaceHit>,
    max_depth: u32,
    rr_depth: u32,
    out: &mut Vec<Deferred>,
) -> bool {
    let world = ctx.world;
    let ray = st.ray;
    guiding::close(st);
    let Some(hit) = hit else {
        if let Some(l) = escaped(
            world,
            &mut st.aux,
            ray.dir,
            st.beta,
            st.prev_delta,
            st.prev_pdf,
        ) {
            st.l += l;
        }
        return false;
    };
    if super::pass_through(ctx, st, &hit) {
        return true;
    }
    let sh = Shading::new(world, &hit, ray.dir);
    st.aux.surface(&sh, &hit, ray.dir, st.depth);
    {
        let le = sh.emitted;
        if le != Vec3::ZERO {
            let w = if st.prev_delta {
                1.0
            } else {
                let lp = world.light_pdf(st.prev_p, st.prev_n, &hit, ray.dir);
                // Emitters that light sampling never picks (moving ones)
                // are found by BSDF sampling alone: weight 1.
                if lp > 0.0 {
                    power_heuristic(st.prev_pdf, lp)
                } else {
                    1.0
                }
            };
            st.l += st.beta * le * w;
        }
    }
    // What reaches the last vertex by more than one scattering passes
    // its painted occlusion.
    st.beta *= std::mem::replace(&mut st.occlusion, 1.0);
    let depth = st.depth;
    if depth >= max_depth {
        return false;
    }
    // Where the render learns where light comes from, the bounce is
    // guided by it (`guiding`); the scattering density is then the
    // balance of the BSDF's and the guide's.
    let guide = AtVertex::of(world.guide(), &sh, &hit);
    // Next-event estimation: one light, chosen as the world chooses.
    if !sh.bsdf.is_delta() {
        let u_pick = ctx.sampler.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
        let u = ctx.sampler.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
        if let Some((ls, pmf)) = world.sample_light_mis(hit.p, hit.ns, u_pick, u) {
            if let Some((c, bsdf_pdf, shadow)) = light_contribution(ctx, &hit, &sh, &ls, st.time) {
                let bsdf_pdf = guide.map_or(bsdf_pdf, |g| g.pdf(ls.wi, bsdf_pdf));
                let light_pdf = pmf * ls.pdf;
                let w = if ls.delta {
                    1.0
                } else {
                    power_heuristic(light_pdf, bsdf_pdf)
                };
                out.push(Deferred {
                    shadow: Some(shadow),
                    op: Op::Add(st.beta * c * (w / light_pdf)),
                });
            }
        }
    }
    // Continue the path by sampling the BSDF.
    let bounce = match &guide {
        Some(g) => g.sample_bounce(ctx, &sh, &hit, depth),
        None => sh.sample_bounce(ctx, &hit, depth),
    };
    let Some((s, next)) = bounce else {
        return false;
    };
    st.beta *= s.weight;
    st.occlusion = sh.occlusion;
    st.prev_delta = s.delta;
    st.prev_pdf = s.pdf;
    st.prev_p = hit.p;
    st.prev_n = hit.ns;
    st.ray = next;
    st.depth += 1;
    let beta = st.beta;
    let more = roulette(ctx, &mut st.beta, st.depth, rr_depth);
    if let Some(g) = guide.filter(|_| more && !s.delta) {
        // Before roulette's division: what survives stands for what did
        // not, which trains nothing.
        g.record(st, next.dir, beta, s.pdf);
    }
    more
}

/// Russian roulette after `depth` bounces: the path goes on with
/// probability max(beta) (at least 5 %) from bounce `rr_depth` on, so
/// paths carrying little keep a bounded weight, its throughput divided by
/// that probability; false if it ends (or carries nothing).
pub(crate) fn roulette(ctx: &mut Context, beta: &mut Vec3, depth: u32, rr_depth: u32) -> bool {
    if depth >= rr_depth {
        let q = beta.max_element().min(1.0);
        if q <= 0.0 {
            return false;
        }
        if q < 1.0 {
            let q = q.max(0.05);
            if ctx.sampler.get_1d(dims::bounce(depth, dims::ROULETTE)) >= q {
                return false;
            }
            *beta /= q;
        }
    }
    *beta != Vec3::ZERO
}
