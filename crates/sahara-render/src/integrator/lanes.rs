//! The path tracer with paths in SIMD lanes: a packet of `N` lanes (16
//! under AVX-512, 8 under AVX2: [`crate::math::lanes::dispatch`]), each
//! lane one pixel sample's path, every step of the path done for all the
//! lanes at once.
//!
//! A packet takes its samples from a queue in the order given (the render
//! loop gives one pixel's samples together, or a 2x2 block's when a pixel
//! has few). Per bounce:
//!
//! 1. the closest hits of the lanes' rays, as one packet query
//!    ([`World::intersect_packet`]);
//! 2. each lane's hit, looked up lane by lane: its material and textures
//!    ([`Material::at`]), emission and its MIS weight; a lane the lanes
//!    cannot shade takes its whole step in the scalar code instead
//!    ([`Integrator::step`], counted in [`LaneCounts`]): a surface with
//!    holes or a normal map, a clear coat; a miss ends its path with the
//!    environment's light, added lane by lane;
//! 3. in the lanes: the shading frame, the light sample's draws, the
//!    BSDF's value for the light's direction (lane by lane for BSDFs
//!    without lane formulas, [`BsdfLanes`]), the MIS weights, the shadow
//!    rays' origins; the light's choice (the light tree walked by all
//!    lanes together) and its sample where the light is a flat piece (an
//!    untextured triangle of a mesh light, a quad), other lights lane by
//!    lane ([`World::sample_light_mis_lanes`]), each lane's sample the
//!    scalar one bit for bit;
//! 4. the shadow rays as one batch ([`World::visible_batch`]);
//! 5. in the lanes: the BSDF sample, the next ray, Russian roulette.
//!
//! A lane whose path ends is refilled with the queue's next sample before
//! the next bounce (or, without refilling, once all lanes have ended).
//!
//! The estimator is the scalar path tracer's ([`super::path`]): the same
//! decisions from the same sample dimensions, the same MIS and roulette.
//! The arithmetic is the lanes' (polynomial sines and cosines), so a
//! sample's radiance matches the scalar loop's to rounding, not bit for
//! bit; it depends on that sample alone: which lanes it shares, when it
//! was refilled and how wide the vector unit is change none of its bits.

use std::time::Instant;

use glam::Vec3;
use sahara_kd::Ray;

use super::laps::{Lap, Laps};
use super::queries::RayQueries;
use super::state::{Deferred, PathState};
use super::{AuxSample, Context, Integrator, TraceStats};
use crate::material::lanes::BsdfLanes;
use crate::math::lanes::{dispatch, Kernel, F, M, U, V};
use crate::sampler::lanes::SamplerLanes;
use crate::sampler::{dims, PixelSampler, SamplerKind};
use crate::texture::footprint::UvFootprint;
use crate::world::{ShadowQuery, SurfaceHit, World, WorldBuffers};

/// One sample for the lanes: its camera ray, time and sampler.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneSample {
    /// The camera ray.
    pub ray: Ray,
    /// The sample's time.
    pub time: f32,
    /// The sample's random numbers.
    pub sampler: PixelSampler,
}

/// How the lanes' bounces were shaded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LaneCounts {
    /// Path vertices shaded in the lanes.
    pub lane_bounces: u64,
    /// Paths ended by a miss, the environment's light added lane by lane.
    pub misses: u64,
    /// Path vertices shaded by the scalar code because their BSDF is
    /// under a clear coat.
    pub scalar_material: u64,
    /// Path vertices shaded by the scalar code for another reason: a
    /// surface with holes or a normal map.
    pub scalar_other: u64,
    /// Rounds of a packet (one closest-hit query each).
    pub rounds: u64,
    /// Lanes busy over those rounds (`lane_slots`: their lanes in all).
    pub busy_lanes: u64,
    /// Lanes of the packets over the rounds.
    pub lane_slots: u64,
}

impl std::ops::AddAssign for LaneCounts {
    fn add_assign(&mut self, o: Self) {
        self.lane_bounces += o.lane_bounces;
        self.misses += o.misses;
        self.scalar_material += o.scalar_material;
        self.scalar_other += o.scalar_other;
        self.rounds += o.rounds;
        self.busy_lanes += o.busy_lanes;
        self.lane_slots += o.lane_slots;
    }
}

/// The lane loop's buffers, kept from one call to the next.
#[derive(Default)]
pub(crate) struct PathLanes {
    /// Shadow queries of a round and their answers.
    queries: Vec<ShadowQuery>,
    visible: Vec<bool>,
    /// Each shadow query's packet and lane (`packet * N + lane`).
    query_owner: Vec<u32>,
    /// A round's rays other than camera rays, their times, hits, and
    /// each one's packet and lane.
    rays: Vec<Ray>,
    times: Vec<f32>,
    hits: Vec<Option<SurfaceHit>>,
    ray_owner: Vec<u32>,
    /// Each packet's hits (of its first `N` lanes: at most 16).
    packet_hits: Vec<[Option<SurfaceHit>; 16]>,
    /// The scalar steps' contributions.
    deferred: Vec<Deferred>,
    world: WorldBuffers,
    /// The batched closest-hit queries.
    closest: RayQueries,
    laps: Laps,
}

/// What the lanes trace: the samples, where their results go, and how.
struct Run<'a, 'w> {
    lanes: &'a mut PathLanes,
    integrator: &'a Integrator,
    world: &'a World<'w>,
    max_depth: u32,
    rr_depth: u32,
    samples: &'a [LaneSample],
    radiance: &'a mut [Vec3],
    aux: Option<&'a mut [AuxSample]>,
    stats: &'a mut TraceStats,
    refill: bool,
}

impl PathLanes {
    /// Traces every sample of `samples` with `integrator` (`path`), each
    /// sample's radiance into `radiance` (and, if given, what the denoiser
    /// is told into `aux`), lanes refilled as their paths end if
    /// `refill`.
    #[allow(clippy::too_many_arguments)]
    pub fn trace(
        &mut self,
        integrator: &Integrator,
        world: &World,
        samples: &[LaneSample],
        radiance: &mut [Vec3],
        aux: Option<&mut [AuxSample]>,
        stats: &mut TraceStats,
        refill: bool,
    ) {
        let Integrator::Path {
            max_depth,
            rr_depth,
        } = *integrator
        else {
            unreachable!("the lane loop traces the path integrator");
        };
        stats.camera_rays += samples.len() as u64;
        dispatch(
            LANE_ISA,
            Run {
                lanes: self,
                integrator,
                world,
                max_depth,
                rr_depth,
                samples,
                radiance,
                aux,
                stats,
                refill,
            },
        );
    }

    /// The time spent tracing and shading since the last call, and
    /// resets both.
    pub fn take_times(&mut self) -> Laps {
        self.laps.take()
    }
}

/// The paths of `N` lanes, coordinates in lanes.
struct Paths<const N: usize> {
    /// The lanes with a path in flight.
    alive: M<N>,
    /// The sample each lane traces (an index into the queue).
    owner: [usize; N],
    ray: [Ray; N],
    time: [f32; N],
    sampler: SamplerLanes<N>,
    l: V<N>,
    beta: V<N>,
    depth: U<N>,
    prev_delta: M<N>,
    prev_pdf: F<N>,
    prev_p: V<N>,
    prev_n: V<N>,
    occlusion: F<N>,
    pass_throughs: [u32; N],
    aux: [AuxSample; N],
}

impl<const N: usize> Paths<N> {
    fn new(kind: SamplerKind) -> Self {
        Self {
            alive: M::splat(false),
            owner: [0; N],
            ray: [Ray::new(Vec3::ZERO, Vec3::Z); N],
            time: [0.0; N],
            sampler: SamplerLanes::new(kind),
            l: V::default(),
            beta: V::default(),
            depth: U([0; N]),
            prev_delta: M::splat(false),
            prev_pdf: F::splat(0.0),
            prev_p: V::default(),
            prev_n: V::default(),
            occlusion: F::splat(1.0),
            pass_throughs: [0; N],
            aux: [AuxSample::default(); N],
        }
    }

    /// Lane `i` starts sample `k`, `s`.
    #[inline]
    fn start(&mut self, i: usize, k: usize, s: &LaneSample, aux: bool) {
        self.put(i, &PathState::new(s.ray, s.time, s.sampler).with_aux(aux));
        self.owner[i] = k;
        self.alive.0[i] = true;
    }

    /// Lane `i`'s path as the scalar code holds it.
    #[inline]
    fn get(&self, i: usize) -> PathState {
        let mut st = PathState::new(self.ray[i], self.time[i], self.sampler.get(i));
        st.l = self.l.get(i);
        st.beta = self.beta.get(i);
        st.depth = self.depth.0[i];
        st.prev_delta = self.prev_delta.0[i];
        st.prev_pdf = self.prev_pdf.0[i];
        st.prev_p = self.prev_p.get(i);
        st.prev_n = self.prev_n.get(i);
        st.occlusion = self.occlusion.0[i];
        st.pass_throughs = self.pass_throughs[i];
        st.aux = self.aux[i];
        st
    }

    /// Lane `i` holds the path `st`.
    #[inline]
    fn put(&mut self, i: usize, st: &PathState) {
        self.ray[i] = st.ray;
        self.time[i] = st.time;
        self.sampler.set(i, &st.sampler);
        self.l.set(i, st.l);
        self.beta.set(i, st.beta);
        self.depth.0[i] = st.depth;
        self.prev_delta.0[i] = st.prev_delta;
        self.prev_pdf.0[i] = st.prev_pdf;
        self.prev_p.set(i, st.prev_p);
        self.prev_n.set(i, st.prev_n);
        self.occlusion.0[i] = st.occlusion;
        self.pass_throughs[i] = st.pass_throughs;
        self.aux[i] = st.aux;
    }
}

/// A round's shading points in lanes.
struct Points<const N: usize> {
    /// The lanes shaded in the lanes this round.
    on: M<N>,
    p: V<N>,
    ng: V<N>,
    ns: V<N>,
    err: F<N>,
    bsdf: BsdfLanes<N>,
    /// The point's painted occlusion.
    occlusion: F<N>,
    /// The back of a one-sided material.
    blind: M<N>,
    ignore: [Option<u32>; N],
}

/// The origins of rays leaving the points along `w`, as
/// [`SurfaceHit::spawn_origin`].
#[inline(always)]
fn spawn_origin<const N: usize>(pt: &Points<N>, w: V<N>) -> V<N> {
    let off = pt.ng * pt.err;
    w.dot(pt.ng)
        .ge(F::splat(0.0))
        .select_v(pt.p + off, pt.p - off)
}

/// The shading frames of unit normals `n`, as
/// [`crate::math::warp::Frame::from_normal`]: (s, t, n).
#[inline(always)]
fn frames<const N: usize>(n: V<N>) -> (V<N>, V<N>) {
    let sign = n.z.sign();
    let a = F::splat(-1.0) / (sign + n.z);
    let b = n.x * n.y * a;
    let s = V::new(sign * n.x * n.x * a + 1.0, sign * b, -(sign * n.x));
    let t = V::new(b, sign + n.y * n.y * a, -n.y);
    (s, t)
}

/// The power heuristic of densities `f` and `g` (one sample each), as
/// [`crate::math::warp::power_heuristic`].
#[inline(always)]
fn power_heuristic<const N: usize>(f: F<N>, g: F<N>) -> F<N> {
    let zero = F::splat(0.0);
    let (f2, g2) = (f * f, g * g);
    let sum = f2 + g2;
    let w = f2 / sum;
    let w = sum.eq(zero).select(zero, w);
    f2.eq(F::splat(f32::INFINITY)).select(F::splat(1.0), w)
}

/// Packets in flight at once: their rays go to the accelerator as one
/// batch per bounce.
const PACKETS: usize = 64;

/// What a packet's round leaves for the next steps.
struct Round<const N: usize> {
    /// Lanes whose path ended this round.
    ended: M<N>,
    /// Light waiting on a shadow ray, per lane (`waiting`).
    pending: V<N>,
    waiting: M<N>,
}

/// The scene and the estimator's parameters, shared by a round's
/// packets.
struct Shared<'a, 'w> {
    integrator: &'a Integrator,
    world: &'a World<'w>,
    max_depth: u32,
    rr_depth: u32,
}

impl<'a, 'w> Shared<'a, 'w> {
    /// Lane `i`'s whole step in the scalar code (its shadow rays answered
    /// at once); true if its path goes on.
    #[inline(never)]
    fn scalar_step<const N: usize>(
        &self,
        paths: &mut Paths<N>,
        i: usize,
        hit: Option<SurfaceHit>,
        deferred: &mut Vec<Deferred>,
        stats: &mut TraceStats,
    ) -> bool {
        let world = self.world;
        let mut st = paths.get(i);
        let mut ctx = Context {
            world,
            sampler: st.sampler,
            stats,
        };
        deferred.clear();
        let more = self.integrator.step(&mut ctx, &mut st, hit, deferred);
        for d in deferred.drain(..) {
            st.apply(&d.op, d.shadow.is_none_or(|q| world.visible(&q)));
        }
        paths.put(i, &st);
        more
    }

    /// One step of every live lane of `paths`, whose rays found `hits`:
    /// emission, the light sample (its shadow rays pushed to `queries`,
    /// `owner` the lane of each), the BSDF sample and the next ray,
    /// Russian roulette.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn shade<const N: usize>(
        &self,
        paths: &mut Paths<N>,
        hits: &[Option<SurfaceHit>; N],
        queries: &mut Vec<ShadowQuery>,
        owner: &mut Vec<u32>,
        packet: u32,
        deferred: &mut Vec<Deferred>,
        stats: &mut TraceStats,
    ) -> Round<N> {
        let world = self.world;
        let zero = F::<N>::splat(0.0);
        let one = F::<N>::splat(1.0);
        let mut round = Round {
            ended: M::splat(false),
            pending: V::default(),
            waiting: M::splat(false),
        };
        // Each lane's surface, lane by lane.
        let mut pt = Points::<N> {
            on: M::splat(false),
            p: V::default(),
            ng: V::default(),
            ns: V::default(),
            err: zero,
            bsdf: BsdfLanes::default(),
            occlusion: one,
            blind: M::splat(false),
            ignore: [None; N],
        };
        for (i, hit) in hits.iter().enumerate() {
            if !paths.alive.0[i] {
                continue;
            }
            let Some(hit) = hit else {
                // The environment's light, as `path::step` adds it at a
                // miss, without the scalar step's round trip through a
                // whole path state.
                if let Some(le) = super::escaped(
                    world,
                    &mut paths.aux[i],
                    paths.ray[i].dir,
                    paths.beta.get(i),
                    paths.prev_delta.0[i],
                    paths.prev_pdf.0[i],
                ) {
                    paths.l.set(i, paths.l.get(i) + le);
                }
                stats.lanes.misses += 1;
                round.ended.0[i] = true;
                continue;
            };
            // The surface, if the lanes can shade it; else the whole step
            // in the scalar code, counted by why.
            let m = world.material(hit.material);
            let lane = 'shade: {
                if m.has_holes() || m.textures.normal.is_some() {
                    stats.lanes.scalar_other += 1;
                    break 'shade None;
                }
                let uvs = hit.uvs();
                let fp = if m.has_textures() {
                    world.uv_footprint(hit)
                } else {
                    UvFootprint::POINT
                };
                let point = m.at(&uvs, &fp);
                if !pt.bsdf.set(i, &point.bsdf) {
                    // Under a clear coat.
                    stats.lanes.scalar_material += 1;
                    break 'shade None;
                }
                Some((point.occlusion, uvs, fp))
            };
            let Some((occlusion, uvs, fp)) = lane else {
                if !self.scalar_step(paths, i, Some(*hit), deferred, stats) {
                    round.ended.0[i] = true;
                }
                continue;
            };
            stats.lanes.lane_bounces += 1;
            let dir = paths.ray[i].dir;
            let wo_world = -dir;
            // The render passes take the scalar code's view of the first
            // surface; the path itself is shaded in the lanes, so asking
            // for passes changes no bit of the beauty.
            if paths.aux[i].open {
                let sh = super::Shading::new(world, hit, dir);
                paths.aux[i].surface(&sh, hit, dir, paths.depth.0[i]);
            }
            // Emission seen here, weighted against light sampling.
            if m.is_emissive() {
                let le = m.emitted(hit.ng.dot(wo_world), &uvs, &fp);
                if le != Vec3::ZERO {
                    let w = if paths.prev_delta.0[i] {
                        1.0
                    } else {
                        let lp =
                            world.light_pdf(paths.prev_p.get(i), paths.prev_n.get(i), hit, dir);
                        // Emitters that light sampling never picks are
                        // found by BSDF sampling alone.
                        if lp > 0.0 {
                            crate::math::warp::power_heuristic(paths.prev_pdf.0[i], lp)
                        } else {
                            1.0
                        }
                    };
                    let l = paths.l.get(i) + paths.beta.get(i) * le * w;
                    paths.l.set(i, l);
                }
            }
            pt.on.0[i] = true;
            pt.p.set(i, hit.p);
            pt.ng.set(i, hit.ng);
            pt.ns.set(i, hit.ns);
            pt.err.0[i] = hit.err;
            pt.occlusion.0[i] = occlusion;
            pt.blind.0[i] = m.is_blind_side(wo_world.dot(hit.ng));
        }
        let on = pt.on;
        if !on.any() {
            return round;
        }
        // In the lanes from here. What reaches the last vertex by more
        // than one scattering passes its painted occlusion.
        paths.beta = on.select_v(paths.beta * paths.occlusion, paths.beta);
        paths.occlusion = on.select(one, paths.occlusion);
        let depth = paths.depth;
        let deep = depth.ge(self.max_depth);
        round.ended = round.ended | (on & deep);
        let on = on & !deep;
        let dir = V::<N>::from_fn(|i| paths.ray[i].dir);
        let wo_world = -dir;
        let (s, t) = frames(pt.ns);
        let n = pt.ns;
        let to_local = |v: V<N>| V::new(v.dot(s), v.dot(t), v.dot(n));
        let wo = to_local(wo_world);
        let wo_ng = wo_world.dot(pt.ng);
        let reflective = pt.bsdf.is_reflective_only();
        // A direction leaving on a side the BSDF may scatter to (shading
        // normals can suggest the other).
        let side_ok = |w: V<N>| !reflective | (w.dot(pt.ng) * wo_ng).gt(zero);
        // Next-event estimation: one light, chosen as `light_sampler` says.
        let nee = on & !pt.bsdf.is_delta() & !pt.blind;
        if nee.any() {
            let u_pick = paths
                .sampler
                .get_1d(depth.map(|d| dims::bounce(d, dims::LIGHT_PICK)));
            let u = paths
                .sampler
                .get_2d(depth.map(|d| dims::bounce(d, dims::LIGHT_POINT)));
            let ls = world.sample_light_mis_lanes(nee, pt.p, pt.ns, u_pick, u);
            let (wi, li, light_pdf, dist, delta) = (ls.wi, ls.li, ls.pdf, ls.dist, ls.delta);
            pt.ignore = ls.ignore;
            let wi_local = to_local(wi);
            let (f, bsdf_pdf) = pt.bsdf.eval(wo, wi_local);
            let c = f * wi_local.z.abs() * li;
            let has = ls.has & side_ok(wi) & c.max_element().gt(zero);
            if has.any() {
                let w = delta.select(one, power_heuristic(light_pdf, bsdf_pdf));
                round.pending = paths.beta * c * (w / light_pdf);
                round.waiting = has;
                let origin = spawn_origin(&pt, wi);
                for i in 0..N {
                    if has.0[i] {
                        owner.push(packet * N as u32 + i as u32);
                        queries.push(world.shadow_query(
                            origin.get(i),
                            wi.get(i),
                            dist.0[i],
                            paths.time[i],
                            pt.ignore[i],
                        ));
                        stats.shadow_rays += 1;
                    }
                }
            }
        }
        // The BSDF sample and the next ray.
        let u_lobe = paths
            .sampler
            .get_1d(depth.map(|d| dims::bounce(d, dims::BSDF_LOBE)));
        let u = paths
            .sampler
            .get_2d(depth.map(|d| dims::bounce(d, dims::BSDF_DIR)));
        let smp = pt.bsdf.sample(wo, u_lobe, u);
        let go = on & !pt.blind & smp.ok;
        let wi = s * smp.wi.x + t * smp.wi.y + n * smp.wi.z;
        // A reflection the shading normal sends below the geometric
        // surface: a delta lobe's is folded back across it, other lobes
        // end there.
        let folded = (wi - pt.ng * (wi.dot(pt.ng) * 2.0)).normalize();
        let ok_direct = side_ok(wi);
        let ok_folded = smp.delta & side_ok(folded);
        let wi = ok_direct.select_v(wi, folded);
        let go = go & (ok_direct | ok_folded);
        let origin = spawn_origin(&pt, wi);
        paths.beta = go.select_v(paths.beta * smp.weight, paths.beta);
        paths.occlusion = go.select(pt.occlusion, paths.occlusion);
        paths.prev_delta = go.select_m(smp.delta, paths.prev_delta);
        paths.prev_pdf = go.select(smp.pdf, paths.prev_pdf);
        paths.prev_p = go.select_v(pt.p, paths.prev_p);
        paths.prev_n = go.select_v(pt.ns, paths.prev_n);
        let depth = go.select_u(depth.map(|d| d + 1), depth);
        paths.depth = depth;
        for i in 0..N {
            if go.0[i] {
                paths.ray[i] = Ray::new(origin.get(i), wi.get(i));
                stats.bounce_rays += 1;
            }
        }
        // Russian roulette, as `path::roulette`.
        let q = paths.beta.max_element().min(one);
        let rr = go & depth.ge(self.rr_depth);
        let dead = rr & q.le(zero);
        let chance = rr & q.gt(zero) & q.lt(one);
        let mut lost = M::<N>::splat(false);
        if chance.any() {
            let qq = q.max(F::splat(0.05));
            let u = paths
                .sampler
                .get_1d(depth.map(|d| dims::bounce(d, dims::ROULETTE)));
            lost = chance & u.ge(qq);
            let win = chance & !lost;
            paths.beta = win.select_v(paths.beta / qq, paths.beta);
        }
        let black = paths.beta.x.eq(zero) & paths.beta.y.eq(zero) & paths.beta.z.eq(zero);
        round.ended = round.ended | (on & !go) | (go & (dead | lost | black));
        round
    }
}

impl<'a, 'w> Kernel for Run<'a, 'w> {
    type Output = ();

    #[inline(always)]
    fn run<const N: usize>(self) {
        let Run {
            lanes,
            integrator,
            world,
            max_depth,
            rr_depth,
            samples,
            radiance,
            mut aux,
            stats,
            refill,
        } = self;
        let Some(first) = samples.first() else {
            return;
        };
        let shared = Shared {
            integrator,
            world,
            max_depth,
            rr_depth,
        };
        let aux_on = aux.is_some();
        let count = samples.len().div_ceil(N).min(PACKETS);
        let mut packets: Vec<Paths<N>> = (0..count)
            .map(|_| Paths::new(first.sampler.kind()))
            .collect();
        let mut next = 0usize;
        let mut clock = Instant::now();
        let PathLanes {
            queries,
            visible,
            deferred,
            world: world_buffers,
            laps,
            rays,
            times,
            hits,
            ray_owner,
            query_owner,
            closest,
            packet_hits,
            ..
        } = lanes;
        // Lanes not alive keep stale hits, never read.
        packet_hits.resize(packets.len(), [None; 16]);
        loop {
            // Refill the lanes whose paths ended: every such lane, or a
            // packet's lanes once all have ended.
            for paths in packets.iter_mut() {
                if refill || !paths.alive.any() {
                    for i in 0..N {
                        if !paths.alive.0[i] && next < samples.len() {
                            paths.start(i, next, &samples[next], aux_on);
                            next += 1;
                        }
                    }
                }
            }
            // The closest hits: each packet's camera rays as a packet
            // (one pixel's samples leave together), the other rays in one
            // batch.
            rays.clear();
            times.clear();
            ray_owner.clear();
            let mut busy = 0u64;
            clock = laps.lap(clock, Lap::Shading);
            for (p, paths) in packets.iter().enumerate() {
                let mut cam_idx = [0usize; N];
                let mut cam_rays = [Ray::new(Vec3::ZERO, Vec3::Z); N];
                let mut cam_times = [0.0f32; N];
                let mut c = 0;
                for i in 0..N {
                    if !paths.alive.0[i] {
                        continue;
                    }
                    busy += 1;
                    if paths.depth.0[i] == 0 && paths.pass_throughs[i] == 0 {
                        cam_idx[c] = i;
                        cam_rays[c] = paths.ray[i];
                        cam_times[c] = paths.time[i];
                        c += 1;
                    } else {
                        rays.push(paths.ray[i]);
                        times.push(paths.time[i]);
                        ray_owner.push((p * N + i) as u32);
                    }
                }
                if c > 0 {
                    let mut h = [None::<SurfaceHit>; N];
                    world.intersect_packet(&cam_rays[..c], &cam_times[..c], &mut h[..c]);
                    for k in 0..c {
                        packet_hits[p][cam_idx[k]] = h[k];
                    }
                }
            }
            if busy == 0 {
                break;
            }
            stats.lanes.rounds += 1;
            stats.lanes.busy_lanes += busy;
            stats.lanes.lane_slots += (packets.len() * N) as u64;
            hits.clear();
            hits.resize(rays.len(), None);
            if !rays.is_empty() {
                closest.closest(world, rays, times, hits);
            }
            for (&o, h) in ray_owner.iter().zip(hits.iter()) {
                packet_hits[o as usize / N][o as usize % N] = *h;
            }
            clock = laps.lap(clock, Lap::Tracing);
            // Every packet's step, in the lanes.
            queries.clear();
            query_owner.clear();
            let mut round_of: Vec<Round<N>> = Vec::with_capacity(packets.len());
            for (p, paths) in packets.iter_mut().enumerate() {
                let hits: &[Option<SurfaceHit>; N] = (&packet_hits[p][..N]).try_into().unwrap();
                round_of.push(shared.shade(
                    paths,
                    hits,
                    queries,
                    query_owner,
                    p as u32,
                    deferred,
                    stats,
                ));
            }
            clock = laps.lap(clock, Lap::Shading);
            // The shadow rays in one batch, then the light that arrives.
            visible.clear();
            visible.resize(queries.len(), true);
            world.visible_batch(queries, visible, world_buffers);
            clock = laps.lap(clock, Lap::Tracing);
            let mut seen = vec![M::<N>::splat(false); packets.len()];
            for (&o, &v) in query_owner.iter().zip(visible.iter()) {
                seen[o as usize / N].0[o as usize % N] = v;
            }
            for ((paths, r), seen) in packets.iter_mut().zip(&round_of).zip(&seen) {
                let arrive = r.waiting & *seen;
                paths.l = arrive.select_v(paths.l + r.pending, paths.l);
                // The lanes whose paths ended give their samples' results.
                for i in 0..N {
                    if r.ended.0[i] {
                        paths.alive.0[i] = false;
                        let k = paths.owner[i];
                        radiance[k] = paths.l.get(i);
                        if let Some(aux) = aux.as_deref_mut() {
                            aux[k] = paths.aux[i];
                        }
                    }
                }
            }
        }
        laps.lap(clock, Lap::Shading);
    }
}

/// The widest vectors the lane loop may use: AVX-512's sixteen lanes
/// where the CPU has them. Unlike the scalar loop (held to AVX2 because a
/// few 512-bit instructions lower the clock of all its scalar code), the
/// lane loop does its shading in 512-bit vectors; measured on a box of
/// quads, 16 lanes were 1.20x the scalar loop's speed and 8 lanes 0.89x.
const LANE_ISA: sahara_kd::Isa = sahara_kd::Isa::Avx512;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::wavefront::tests::scene;
    use crate::sampler::SampleId;
    use glam::Vec2;
    use sahara_kd::AccelParams;

    /// The samples of a `w x h` image at `spp`, pixel by pixel.
    fn samples(scene: &crate::scene::Scene, kind: SamplerKind, spp: u32) -> Vec<LaneSample> {
        let (w, h) = (12u32, 10u32);
        let mut v = Vec::new();
        for y in 0..h {
            for x in 0..w {
                for index in 0..spp {
                    let sampler = PixelSampler::new(
                        kind,
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
                    v.push(LaneSample { ray, time, sampler });
                }
            }
        }
        v
    }

    /// Each sample's radiance from the lanes, and from the scalar path
    /// tracer driven by the same random numbers: nearly every sample
    /// takes the same path and agrees to rounding (a few part ways where
    /// rounding sends a ray across an edge); refilling the lanes or not
    /// changes no bit; every kind of light and lobe, a moving instance, a
    /// thin lens, the environment.
    #[test]
    fn lanes_follow_the_scalar_paths() {
        for extra in [0, 12] {
            let scene = scene(extra);
            let world = World::new(&scene, &AccelParams::default());
            let integrator = Integrator::named("path").unwrap();
            for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
                let samples = samples(&scene, kind, 5);
                let mut stats = TraceStats::default();
                let mut refilled = vec![Vec3::ZERO; samples.len()];
                let mut lanes = PathLanes::default();
                lanes.trace(
                    &integrator,
                    &world,
                    &samples,
                    &mut refilled,
                    None,
                    &mut stats,
                    true,
                );
                let mut packets = vec![Vec3::ZERO; samples.len()];
                let mut stats2 = TraceStats::default();
                lanes.trace(
                    &integrator,
                    &world,
                    &samples,
                    &mut packets,
                    None,
                    &mut stats2,
                    false,
                );
                let bits = |v: &[Vec3]| -> Vec<[u32; 3]> {
                    v.iter().map(|l| l.to_array().map(f32::to_bits)).collect()
                };
                assert_eq!(bits(&refilled), bits(&packets));
                assert_eq!(stats.lanes.lane_bounces, stats2.lanes.lane_bounces);
                let mut agree = 0;
                let (mut sum_lanes, mut sum_scalar) = (Vec3::ZERO, Vec3::ZERO);
                for (s, l) in samples.iter().zip(&refilled) {
                    let mut st = TraceStats::default();
                    let mut ctx = Context {
                        world: &world,
                        sampler: s.sampler,
                        stats: &mut st,
                    };
                    let r = integrator.li(&mut ctx, &s.ray, s.time);
                    let tol = 1e-3 * r.max_element().max(1e-2);
                    agree += ((*l - r).abs().max_element() <= tol) as usize;
                    sum_lanes += *l;
                    sum_scalar += r;
                }
                let share = agree as f64 / samples.len() as f64;
                assert!(
                    share > 0.97,
                    "{extra} {kind:?}: {share} of the samples agree"
                );
                assert!(stats.lanes.lane_bounces > 0 && stats.shadow_rays > 0);
                eprintln!(
                    "{extra} {kind:?}: {share:.4} agree; sums {sum_lanes} vs {sum_scalar}; {:?}",
                    stats.lanes
                );
            }
        }
    }
}
