//! Distribution ray tracing (Cook, Porter, Carpenter 1984) in the Whitted
//! style: at every hit, direct light from every light with its samples
//! spread over the light; recursion only through mirror, glossy and
//! refractive lobes, one lobe-sampled ray per pixel sample.
//!
//! Emission and the environment are counted on camera rays and after
//! delta bounces only; after a glossy bounce the direct-lighting estimate
//! already holds them.

use super::state::{Deferred, Op, PathState};
use super::{light_contribution, Context, Shading};
use crate::sampler::dims;
use crate::world::SurfaceHit;
use glam::Vec3;

/// One step of the path in `st`, whose ray found `hit`: emission seen
/// there, every light's samples (deferred to `out`, waiting on their
/// shadow rays) and the next ray, with up to `max_depth` specular/glossy
/// bounces. Returns whether the path goes on.
pub(crate) fn step(
    ctx: &mut Context,
    st: &mut PathState,
    hit: Option<SurfaceHit>,
    max_depth: u32,
    light_samples: u32,
    out: &mut Vec<Deferred>,
) -> bool {
    let world = ctx.world;
    let ray = st.ray;
    let Some(hit) = hit else {
        if st.prev_delta || st.aux.open {
            let le = world.env_radiance(ray.dir);
            st.aux.escape(le);
            if st.prev_delta {
                st.l += st.beta * le;
            }
        }
        return false;
    };
    if super::pass_through(ctx, st, &hit) {
        return true;
    }
    let sh = Shading::new(world, &hit, ray.dir);
    st.aux.surface(&sh, &hit, ray.dir, st.depth);
    if st.prev_delta {
        st.l += st.beta * sh.emitted;
    }
    let depth = st.depth;
    if !sh.bsdf.is_delta() {
        for (j, light) in world.lights.iter().enumerate() {
            let n = if light.is_delta() { 1 } else { light_samples };
            for k in 0..n {
                let u = ctx.sampler.get_2d(dims::extra(depth, j as u32, k));
                let Some(ls) = light.sample(hit.p, u) else {
                    continue;
                };
                if let Some((c, _, shadow)) = light_contribution(ctx, &hit, &sh, &ls, st.time) {
                    out.push(Deferred {
                        shadow: Some(shadow),
                        op: Op::Sum(c / ls.pdf),
                    });
                }
            }
            out.push(Deferred {
                shadow: None,
                op: Op::Flush { beta: st.beta, n },
            });
        }
    }
    if depth >= max_depth || sh.bsdf.is_diffuse() {
        return false;
    }
    let Some((s, next)) = sh.sample_bounce(ctx, &hit, depth) else {
        return false;
    };
    st.beta *= s.weight;
    st.prev_delta = s.delta;
    st.ray = next;
    st.depth += 1;
    st.beta != Vec3::ZERO
}
