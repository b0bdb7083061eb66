//! Stochastic progressive photon mapping (Hachisuka and Jensen 2009;
//! pbrt-v4's `sppm` is built the same way).
//!
//! Each iteration traces one camera path per pixel through mirrors and
//! glass to its first rough surface, the pixel's **visible point** (light
//! found on the way, and light sampled at the visible point, is added
//! directly), then traces photons from the lights. A photon that arrives
//! at a surface after at least one scattering gives its power, times the
//! visible point's BSDF, to every visible point within that pixel's
//! search radius. After the iteration each pixel shrinks its radius so
//! that a fraction `ALPHA` of the new photons is kept (Hachisuka and
//! Jensen's progressive radius reduction): the estimate's blur goes to
//! zero and its noise averages out, so the image converges, caustics seen
//! in mirrors and through glass included, which no other Sahara
//! integrator can find from a point light.
//!
//! Determinism: the visible points are found per pixel, the photons in
//! fixed chunks traced in parallel, and each chunk's deposits are applied
//! in chunk order, so the image does not depend on the number of threads.

use std::collections::HashMap;

use glam::{IVec3, Vec3};
use sahara_kd::Ray;

use super::{bdpt, Context, Shading};
use crate::math::hash::hash2;
use crate::math::warp::luminance;
use crate::sampler::{dims, PixelSampler, SampleId, SamplerKind};
use crate::world::{SurfaceHit, World};

/// The fraction of new photons each iteration keeps in the radius
/// reduction (Hachisuka and Jensen's alpha; pbrt uses 2/3).
pub(crate) const ALPHA: f32 = 2.0 / 3.0;

/// Photons traced together as one job; their deposits are applied in
/// this order whatever thread traced them.
const PHOTON_CHUNK: usize = 4096;

/// A pixel's visible point: where its camera path met its first surface
/// that is not a perfect mirror or smooth glass.
pub(crate) struct VisiblePoint {
    hit: SurfaceHit,
    sh: Shading,
    /// Throughput from the camera to here.
    beta: Vec3,
}

/// A pixel's photon statistics across iterations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelStats {
    /// Search radius.
    pub radius: f32,
    /// Photons counted so far (after the radius reductions).
    pub n: f32,
    /// Flux gathered so far, scaled with the radius.
    pub tau: Vec3,
    /// Light found directly (emission and light sampling), summed over
    /// iterations.
    pub direct: Vec3,
}

impl PixelStats {
    /// A pixel that has gathered nothing yet, with search radius `radius`.
    pub fn new(radius: f32) -> Self {
        Self {
            radius,
            n: 0.0,
            tau: Vec3::ZERO,
            direct: Vec3::ZERO,
        }
    }

    /// Folds one iteration's `m` photons of flux `phi` into the
    /// statistics, shrinking the radius.
    pub fn update(&mut self, phi: Vec3, m: u32) {
        if m == 0 {
            return;
        }
        let m = m as f32;
        let n = self.n + ALPHA * m;
        let r = self.radius * (n / (self.n + m)).sqrt();
        self.tau = (self.tau + phi) * (r * r) / (self.radius * self.radius);
        self.n = n;
        self.radius = r;
    }

    /// The pixel's radiance after `iterations` iterations of `photons`
    /// photons each.
    pub fn radiance(&self, iterations: u32, photons: u64) -> Vec3 {
        let it = iterations.max(1) as f32;
        let area = std::f32::consts::PI * self.radius * self.radius;
        let indirect = if photons > 0 && area > 0.0 {
            self.tau / (photons as f32 * it * area)
        } else {
            Vec3::ZERO
        };
        self.direct / it + indirect
    }
}

/// The camera path of one pixel sample along `ray` at `time`, at most
/// `max_depth` scatterings deep: the light it finds directly, and its
/// visible point if it reaches a rough surface.
pub(crate) fn camera_path(
    ctx: &mut Context,
    mut ray: Ray,
    time: f32,
    max_depth: u32,
) -> (Vec3, Option<VisiblePoint>) {
    ctx.stats.camera_rays += 1;
    let world = ctx.world;
    let mut beta = Vec3::ONE;
    let mut l = Vec3::ZERO;
    let mut holes = 0;
    let mut depth = 0u32;
    loop {
        let Some(hit) = world.intersect(&ray, time) else {
            // Only mirrors and glass lead here (a rough surface ends the
            // path): the environment counts in full.
            l += beta * world.env_radiance(ray.dir);
            return (l, None);
        };
        if super::through_hole(world, &mut ray, &hit, &mut holes) {
            continue;
        }
        let sh = Shading::new(world, &hit, ray.dir);
        l += beta * sh.emitted;
        if sh.blind {
            return (l, None);
        }
        if !sh.bsdf.is_delta() {
            l += beta * direct_light(ctx, &hit, &sh, depth, time);
            return (l, Some(VisiblePoint { hit, sh, beta }));
        }
        if depth >= max_depth {
            return (l, None);
        }
        let Some((s, next)) = sh.sample_bounce(ctx, &hit, depth) else {
            return (l, None);
        };
        beta *= s.weight;
        ray = next;
        depth += 1;
    }
}

/// Light arriving at the visible point from one light sample (chosen by
/// power), unweighted: emission at rough surfaces is never counted, so
/// light sampling is the one way to it.
fn direct_light(ctx: &mut Context, hit: &SurfaceHit, sh: &Shading, depth: u32, time: f32) -> Vec3 {
    let u_pick = ctx.sampler.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
    let u = ctx.sampler.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
    let Some((ls, pmf)) = ctx.world.sample_light(hit.p, hit.ns, u_pick, u) else {
        return Vec3::ZERO;
    };
    match super::light_contribution(ctx, hit, sh, &ls, time) {
        Some((c, _, shadow)) if ctx.world.visible(&shadow) => c / (pmf * ls.pdf),
        _ => Vec3::ZERO,
    }
}

/// The visible points of one iteration in a uniform grid of cells twice
/// the largest radius wide, so a photon looks in one cell only.
pub(crate) struct Grid {
    cell: f32,
    cells: HashMap<IVec3, Vec<u32>>,
}

impl Grid {
    /// The grid of `points` (pixel index and visible point) with the
    /// pixels' `radii`.
    pub fn new(points: &[(u32, &VisiblePoint)], radii: &[f32]) -> Self {
        let max_r = points
            .iter()
            .map(|(k, _)| radii[*k as usize])
            .fold(0.0f32, f32::max);
        let cell = (2.0 * max_r).max(f32::MIN_POSITIVE);
        let mut cells: HashMap<IVec3, Vec<u32>> = HashMap::new();
        for (k, vp) in points {
            let r = radii[*k as usize];
            let lo = ((vp.hit.p - Vec3::splat(r)) / cell).floor().as_ivec3();
            let hi = ((vp.hit.p + Vec3::splat(r)) / cell).floor().as_ivec3();
            for x in lo.x..=hi.x {
                for y in lo.y..=hi.y {
                    for z in lo.z..=hi.z {
                        cells.entry(IVec3::new(x, y, z)).or_default().push(*k);
                    }
                }
            }
        }
        Self { cell, cells }
    }

    /// The pixels whose visible points may lie within their radius of `p`.
    fn near(&self, p: Vec3) -> &[u32] {
        let c = (p / self.cell).floor().as_ivec3();
        self.cells.get(&c).map_or(&[], Vec::as_slice)
    }
}

/// One photon's deposit: flux for a pixel's visible point.
pub(crate) type Deposit = (u32, Vec3);

/// Traces photons `first..first + count` of iteration `iteration` (at
/// most `max_depth` scatterings), depositing into the visible points of
/// `grid` (`points[k]`: pixel `k`'s, `radii[k]`: its radius).
#[allow(clippy::too_many_arguments)]
pub(crate) fn trace_photons(
    world: &World,
    seed: u64,
    iteration: u32,
    first: u64,
    count: u64,
    max_depth: u32,
    time: f32,
    grid: &Grid,
    points: &[Option<VisiblePoint>],
    radii: &[f32],
    stats: &mut super::TraceStats,
) -> Vec<Deposit> {
    let mut out = Vec::new();
    for k in first..first + count {
        let sampler = PixelSampler::new(
            SamplerKind::Independent,
            SampleId {
                stream: hash2(seed ^ 0x5350_504d_5048_4f54, k),
                pass: iteration,
                index: 0,
                count: 1,
            },
        );
        let mut ctx = Context {
            world,
            sampler,
            stats,
        };
        trace_photon(&mut ctx, max_depth, time, grid, points, radii, &mut out);
    }
    out
}

/// One photon: from a light chosen by power, scattered by the adjoint
/// BSDFs, ended by Russian roulette on its throughput's change.
fn trace_photon(
    ctx: &mut Context,
    max_depth: u32,
    time: f32,
    grid: &Grid,
    points: &[Option<VisiblePoint>],
    radii: &[f32],
    out: &mut Vec<Deposit>,
) {
    let world = ctx.world;
    let dim = |depth: u32, k: u32| dims::extra(depth.min(63), 0xffc, k);
    let Some((_, _, _, mut beta, mut ray)) = super::leave_light(ctx, |k| dim(0, k)) else {
        return;
    };
    let mut holes = 0;
    let mut depth = 0u32;
    while depth < max_depth {
        ctx.stats.bounce_rays += 1;
        let Some(hit) = world.intersect(&ray, time) else {
            return;
        };
        if super::through_hole(world, &mut ray, &hit, &mut holes) {
            continue;
        }
        // Light arriving straight from a light is found by the visible
        // points' light sampling; only scattered photons are gathered.
        if depth > 0 {
            for &k in grid.near(hit.p) {
                let r = radii[k as usize];
                let Some(vp) = &points[k as usize] else {
                    continue;
                };
                if vp.hit.p.distance_squared(hit.p) > r * r {
                    continue;
                }
                let wi = -ray.dir;
                if !vp.sh.side_ok(&vp.hit, wi) {
                    continue;
                }
                let f = vp.sh.bsdf.eval(vp.sh.wo, vp.sh.frame.to_local(wi)).f;
                let phi = vp.beta * beta * f;
                if phi.max_element() > 0.0 {
                    out.push((k, phi));
                }
            }
        }
        let sh = Shading::new(world, &hit, ray.dir);
        if sh.blind {
            return;
        }
        let u_lobe = ctx.sampler.get_1d(dim(depth + 1, 0));
        let u = ctx.sampler.get_2d(dim(depth + 1, 1));
        let Some(s) = sh.bsdf.sample(sh.wo, u_lobe, u) else {
            return;
        };
        let Some(wi) = sh.scattered(&hit, s.wi, s.delta) else {
            return;
        };
        let next = beta * s.weight * bdpt::adjoint(&hit, &sh, wi);
        // Russian roulette: continue in proportion to the throughput's
        // change, so surviving photons keep about the power they had.
        let q = (1.0 - luminance(next) / luminance(beta).max(f32::MIN_POSITIVE)).max(0.0);
        if ctx.sampler.get_1d(dim(depth + 1, 2)) < q {
            return;
        }
        beta = next / (1.0 - q);
        if !beta.is_finite() || beta == Vec3::ZERO {
            return;
        }
        ray = Ray::new(hit.spawn_origin(wi), wi);
        depth += 1;
    }
}

/// Photons traced as one job (see [`PHOTON_CHUNK`]): the chunks of
/// `photons` photons.
pub(crate) fn chunks(photons: u64) -> impl Iterator<Item = (u64, u64)> {
    let c = PHOTON_CHUNK as u64;
    (0..photons.div_ceil(c)).map(move |i| (i * c, c.min(photons - i * c)))
}
