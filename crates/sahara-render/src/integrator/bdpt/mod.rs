//! Bidirectional path tracing (Veach 1997, chapter 10; pbrt-v4's `bdpt`
//! follows the same construction) and light tracing, its strategy of
//! connecting light subpaths to the camera alone.
//!
//! Every pixel sample traces a camera subpath and a light subpath and
//! joins every prefix of one to every prefix of the other: `s` light
//! vertices and `t` camera vertices make a path of `s + t` vertices. `s =
//! 0` is the camera path finding an emitter; `s = 1` samples a point on a
//! light from the camera path's last vertex (next-event estimation);
//! `t = 1` joins a light subpath vertex to the lens, and what it carries
//! lands on the film wherever that vertex is seen ([`Splat`]), not
//! necessarily in the sample's pixel. Each contribution is weighted by
//! the power heuristic over all the strategies that could have made the
//! same path, computed from the densities of each vertex as sampled from
//! either end (per unit area; per unit solid angle for vertices at
//! infinity).
//!
//! What is left out, and why: `s = 1, t = 1` (a light's point joined
//! straight to the lens; the camera ray finding the light, `s = 0`, covers
//! those paths alone) and `t = 0` (light paths hitting the lens, which a
//! pinhole has no area for). Painted occlusion maps, which are not
//! physical, do not darken bidirectional paths. Light subpaths do not use
//! Russian roulette: every path is cut at `max_depth` scattering events.
//!
//! The work is written as steps that leave the ray queries to their
//! caller: a subpath grows by one vertex per closest hit ([`Walk`]), and
//! the strategies of a sample are evaluated with their shadow rays left
//! open ([`Connection`]), then summed in a fixed order. [`sample`] answers
//! the queries one at a time; the render loop traces many samples
//! together and answers them in batches ([`batch`]), with the same result
//! bit for bit.

use glam::{Vec2, Vec3};
use sahara_kd::Ray;

use super::{Context, Shading};
use crate::light::emission::pdf_disc;
use crate::light::LightSource;
use crate::sampler::dims;
use crate::scene::camera::Camera;
use crate::world::{ShadowQuery, SurfaceHit, World};

pub(crate) use crate::film::sums::Splat;

pub(crate) mod batch;

/// Which of the strategies a render uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Strategies {
    /// All of them, weighted by multiple importance sampling.
    All,
    /// Light tracing: light subpath vertices joined to the lens, and the
    /// emitters the camera sees directly.
    LightTracing,
}

/// The `light` field of [`dims::extra`] for a light subpath's decisions
/// (`depth` 0: the light, its point and direction; `depth` d: the d-th
/// scattering).
const LIGHT_DIMS: u32 = 0xffe;
/// The `light` field of [`dims::extra`] for the lens point joined to the
/// d-th light subpath vertex.
const LENS_DIMS: u32 = 0xffd;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Camera,
    /// A point on a light at a finite distance.
    Light,
    /// A light at infinity (the environment, a directional light).
    Infinite,
    Surface,
}

/// A vertex of a subpath.
struct Vertex {
    kind: Kind,
    p: Vec3,
    /// Surfaces and surface lights: the unit geometric normal (front
    /// face). Point lights and the camera: zero. Lights at infinity: the
    /// unit direction from the scene towards the light.
    n: Vec3,
    /// Throughput from the subpath's start up to here.
    beta: Vec3,
    /// The subpath scattered here through a delta lobe.
    delta: bool,
    /// Density of this vertex as its own subpath sampled it.
    pdf_fwd: f32,
    /// Density of this vertex as the other end would sample it.
    pdf_rev: f32,
    /// Lights: the light's index.
    light: usize,
    /// Surface lights: emission from both faces.
    two_sided: bool,
    /// Surfaces: the hit and its shading.
    surface: Option<(SurfaceHit, Shading)>,
}

impl Vertex {
    fn endpoint(kind: Kind, p: Vec3, n: Vec3, beta: Vec3) -> Self {
        Self {
            kind,
            p,
            n,
            beta,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            light: 0,
            two_sided: false,
            surface: None,
        }
    }

    fn on_surface(&self) -> bool {
        matches!(self.kind, Kind::Surface | Kind::Light) && self.n != Vec3::ZERO
    }

    fn infinite(&self) -> bool {
        self.kind == Kind::Infinite
    }

    /// A surface vertex a connection can end at (its BSDF is not all
    /// delta, and it faces the side it is seen from).
    fn connectible(&self) -> Option<&(SurfaceHit, Shading)> {
        self.surface
            .as_ref()
            .filter(|(_, sh)| !sh.blind && !sh.bsdf.is_delta())
    }
}

/// The unit direction from `a` to `b` and their squared distance (1 when
/// one is at infinity).
fn towards(a: &Vertex, b: &Vertex) -> (Vec3, f32) {
    if b.infinite() {
        return (b.n, 1.0);
    }
    if a.infinite() {
        return (-a.n, 1.0);
    }
    let d = b.p - a.p;
    let d2 = d.length_squared();
    (d / d2.sqrt(), d2)
}

/// A solid-angle density at `from` of the direction to `to`, as a density
/// of `to` per unit area (unchanged when `to` is at infinity).
fn to_area(pdf: f32, from: &Vertex, to: &Vertex) -> f32 {
    if to.infinite() {
        return pdf;
    }
    let (w, d2) = towards(from, to);
    let p = pdf / d2;
    if to.on_surface() {
        p * to.n.dot(w).abs()
    } else {
        p
    }
}

/// Density with which light vertex `v` emits towards `next`, per unit
/// area of `next`.
fn pdf_emit(world: &World, v: &Vertex, next: &Vertex) -> f32 {
    if v.infinite() {
        let p = pdf_disc(world.radius);
        return if next.on_surface() {
            p * next.n.dot(v.n).abs()
        } else {
            p
        };
    }
    let (w, _) = towards(v, next);
    to_area(world.lights[v.light].pdf_dir(v.n, w, v.two_sided), v, next)
}

/// Density of light vertex `v` as the start of a light subpath (the
/// light's choice times its origin's density).
fn pdf_origin(world: &World, v: &Vertex) -> f32 {
    world.light_pmf(v.light) * world.lights[v.light].pdf_origin(v.n)
}

/// Density with which `cur`, reached from `prev`, samples `next` (per
/// unit area of `next`).
fn pdf_next(world: &World, cur: &Vertex, prev: Option<&Vertex>, next: &Vertex) -> f32 {
    match cur.kind {
        Kind::Surface => {
            let (Some((_, sh)), Some(prev)) = (&cur.surface, prev) else {
                return 0.0;
            };
            let (wp, _) = towards(cur, prev);
            let (wn, _) = towards(cur, next);
            let pdf = sh
                .bsdf
                .eval(sh.frame.to_local(wp), sh.frame.to_local(wn))
                .pdf;
            to_area(pdf, cur, next)
        }
        Kind::Camera => {
            let (w, _) = towards(cur, next);
            to_area(world.scene.camera.pdf_dir(cur.p, w), cur, next)
        }
        Kind::Light | Kind::Infinite => pdf_emit(world, cur, next),
    }
}

/// The BSDF of surface vertex `v` for light leaving towards unit `w`,
/// arriving from its subpath's previous vertex; `importance` for light
/// subpaths (the adjoint BSDF, with the correction for shading normals
/// of Veach 1997, section 5.3).
fn f_towards(v: &Vertex, w: Vec3, importance: bool) -> Vec3 {
    let Some((hit, sh)) = &v.surface else {
        return Vec3::ZERO;
    };
    if !sh.side_ok(hit, w) {
        return Vec3::ZERO;
    }
    let wi = sh.frame.to_local(w);
    let f = sh.bsdf.eval(sh.wo, wi).f;
    if importance {
        f * adjoint(hit, sh, w)
    } else {
        f
    }
}

/// The adjoint factors of a light subpath's scattering at `hit` towards
/// `w`: refraction's radiance scaling undone, and the shading normal's
/// correction `|wo.ns| |w.ng| / (|wo.ng| |w.ns|)`.
pub(super) fn adjoint(hit: &SurfaceHit, sh: &Shading, w: Vec3) -> f32 {
    let ns = sh.frame.n;
    let den = sh.wo_world.dot(hit.ng) * w.dot(ns);
    if den == 0.0 {
        return 0.0;
    }
    let num = sh.wo_world.dot(ns) * w.dot(hit.ng);
    (num / den).abs() * sh.bsdf.adjoint_scale(sh.wo, sh.frame.to_local(w))
}

/// The dimension of a light subpath's decision `k` at `depth`.
fn light_dim(depth: usize, k: u32) -> u32 {
    dims::extra((depth as u32).min(63), LIGHT_DIMS, k)
}

/// A subpath being extended: the ray that finds its next vertex and what
/// that ray carries.
#[derive(Clone, Copy, Debug)]
struct Walk {
    /// The ray whose closest hit is the subpath's next vertex.
    ray: Ray,
    /// The throughput the ray carries.
    beta: Vec3,
    /// The density of the ray's direction (for a ray from a light at
    /// infinity: the density of its origin on the disc).
    pdf: f32,
    /// Surfaces with holes the subpath has passed through.
    holes: u32,
    /// Most vertices of the subpath.
    max_len: usize,
    /// A light subpath (it carries importance the other way).
    importance: bool,
}

impl Walk {
    /// Whether `path` has room for the vertex this walk's ray finds.
    fn open(&self, path: &[Vertex]) -> bool {
        path.len() < self.max_len
    }

    /// Extends `path` by the closest hit `hit` of the walk's ray; returns
    /// whether the subpath goes on (along the walk's new ray).
    fn extend(
        &mut self,
        ctx: &mut Context,
        path: &mut Vec<Vertex>,
        hit: Option<SurfaceHit>,
    ) -> bool {
        let world = ctx.world;
        let importance = self.importance;
        let Some(hit) = hit else {
            if let (false, Some(env)) = (importance, world.env_light()) {
                let mut v = Vertex::endpoint(Kind::Infinite, Vec3::ZERO, self.ray.dir, self.beta);
                v.light = env as usize;
                v.pdf_fwd = self.pdf;
                path.push(v);
            }
            return false;
        };
        if super::through_hole(world, &mut self.ray, &hit, &mut self.holes) {
            return true;
        }
        let ray = self.ray;
        let sh = Shading::new(world, &hit, ray.dir);
        let mut v = Vertex::endpoint(Kind::Surface, hit.p, hit.ng, self.beta);
        let prev = path.last().expect("a walk starts from an endpoint");
        v.pdf_fwd = if prev.infinite() {
            self.pdf * hit.ng.dot(ray.dir).abs()
        } else {
            to_area(self.pdf, prev, &v)
        };
        v.surface = Some((hit, sh));
        path.push(v);
        if path.len() >= self.max_len {
            return false;
        }
        let depth = path.len() - 2;
        let (u_lobe, u) = if importance {
            (
                ctx.sampler.get_1d(light_dim(depth + 1, 0)),
                ctx.sampler.get_2d(light_dim(depth + 1, 1)),
            )
        } else {
            (
                ctx.sampler
                    .get_1d(dims::bounce(depth as u32, dims::BSDF_LOBE)),
                ctx.sampler
                    .get_2d(dims::bounce(depth as u32, dims::BSDF_DIR)),
            )
        };
        let n = path.len();
        let (hit, sh) = path[n - 1].surface.as_ref().expect("just pushed");
        if sh.blind {
            return false;
        }
        let Some(s) = sh.bsdf.sample(sh.wo, u_lobe, u) else {
            return false;
        };
        let Some(wi) = sh.scattered(hit, s.wi, s.delta) else {
            return false;
        };
        ctx.stats.bounce_rays += 1;
        let mut weight = s.weight;
        if importance {
            weight *= adjoint(hit, sh, wi);
        }
        let (pdf_fwd, pdf_rev) = if s.delta {
            (0.0, 0.0)
        } else {
            (s.pdf, sh.bsdf.eval(sh.frame.to_local(wi), sh.wo).pdf)
        };
        let next = Ray::new(hit.spawn_origin(wi), wi);
        self.beta *= weight;
        path[n - 1].delta = s.delta;
        path[n - 2].pdf_rev = to_area(pdf_rev, &path[n - 1], &path[n - 2]);
        self.pdf = pdf_fwd;
        self.ray = next;
        self.beta != Vec3::ZERO && self.beta.is_finite()
    }
}

/// The start of a camera subpath of at most `max_len` vertices along
/// camera ray `ray`: its first vertex, pushed to `path`, and the walk that
/// finds the next.
fn camera_start(world: &World, ray: &Ray, max_len: usize, path: &mut Vec<Vertex>) -> Walk {
    path.push(Vertex::endpoint(
        Kind::Camera,
        ray.origin,
        Vec3::ZERO,
        Vec3::ONE,
    ));
    Walk {
        ray: *ray,
        beta: Vec3::ONE,
        pdf: world.scene.camera.pdf_dir(ray.origin, ray.dir),
        holes: 0,
        max_len,
        importance: false,
    }
}

/// The start of a sample's light subpath of at most `max_len` vertices:
/// the point on a light, pushed to `path`, and the walk that finds the
/// next vertex; `None` if no light emits.
fn light_start(ctx: &mut Context, max_len: usize, path: &mut Vec<Vertex>) -> Option<Walk> {
    let world = ctx.world;
    if !world.has_lights() {
        return None;
    }
    let (i, pmf, e, beta, ray) = super::leave_light(ctx, |k| light_dim(0, k))?;
    let light: &LightSource = &world.lights[i];
    let infinite = light.is_infinite();
    let mut v = if infinite {
        Vertex::endpoint(Kind::Infinite, Vec3::ZERO, -e.dir, e.le)
    } else {
        Vertex::endpoint(Kind::Light, e.p, e.n, e.le)
    };
    v.light = i;
    v.two_sided = e.two_sided;
    v.pdf_fwd = pmf * light.pdf_origin(-e.dir);
    path.push(v);
    Some(Walk {
        ray,
        beta,
        pdf: if infinite { e.pdf_pos } else { e.pdf_dir },
        holes: 0,
        max_len,
        importance: true,
    })
}

/// The densities of one vertex of a complete path, as sampled from the
/// light's end (`pl`) and from the camera's (`pc`).
#[derive(Clone, Copy, Debug)]
struct Densities {
    pl: f32,
    pc: f32,
    delta: bool,
}

/// Changes to the densities of the vertices around a connection, for
/// the path the connection makes: `(index from the light's end, pl, pc)`.
type Overrides = [(usize, Option<f32>, Option<f32>); 4];

/// The power-heuristic weight of strategy `s` for the path of `s` light
/// vertices (`light(i)`, from the light) and `t` camera vertices
/// (`camera(j)`, from the camera), with the connection's `overrides`.
/// `delta_light`: the path's light is a point, spot or directional light,
/// which no camera path can find.
fn mis_weight<'a>(
    s: usize,
    t: usize,
    light: &dyn Fn(usize) -> &'a Vertex,
    camera: &dyn Fn(usize) -> &'a Vertex,
    overrides: &Overrides,
    delta_light: bool,
) -> f32 {
    let n = s + t;
    // Vertex `i` of the whole path, counted from the light.
    let d = |i: usize| {
        let mut d = if i < s {
            let v = light(i);
            Densities {
                pl: v.pdf_fwd,
                pc: v.pdf_rev,
                delta: v.delta,
            }
        } else {
            let v = camera(n - 1 - i);
            Densities {
                pl: v.pdf_rev,
                pc: v.pdf_fwd,
                delta: v.delta,
            }
        };
        for &(j, pl, pc) in overrides {
            if j == i {
                if let Some(pl) = pl {
                    d.pl = pl;
                }
                if let Some(pc) = pc {
                    d.pc = pc;
                }
            }
        }
        // The connection's own ends scatter through their non-delta lobes.
        if i == s || (s > 0 && i == s - 1) {
            d.delta = false;
        }
        d
    };
    let possible = |sp: usize| {
        let tp = n - sp;
        if tp == 0 || (sp == 1 && tp == 1) {
            return false;
        }
        if sp == 0 {
            return !delta_light && !d(0).delta;
        }
        !d(sp - 1).delta && !d(sp).delta
    };
    let remap = |f: f32| if f != 0.0 { f } else { 1.0 };
    let mut sum = 1.0f32;
    let mut r = 1.0f32;
    for i in (0..s).rev() {
        let di = d(i);
        r *= remap(di.pc) / remap(di.pl);
        if possible(i) {
            sum += r * r;
        }
    }
    r = 1.0;
    for i in s..n - 1 {
        let di = d(i);
        r *= remap(di.pl) / remap(di.pc);
        if possible(i + 1) {
            sum += r * r;
        }
    }
    if sum.is_finite() {
        1.0 / sum
    } else {
        0.0
    }
}

/// Most vertices of a subpath (the camera or light and 62 scatterings).
const MAX_VERTICES: usize = 64;

/// A strategy's contribution to one sample, waiting on its shadow ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Connection {
    /// The segment that must be unblocked for the light to arrive (none:
    /// it arrives).
    shadow: Option<ShadowQuery>,
    /// The weighted contribution.
    l: Vec3,
    /// Light tracing's contributions: where on the film (in pixels) the
    /// light lands; none: in the sample's pixel.
    film: Option<Vec2>,
}

impl Connection {
    /// A contribution to the sample's pixel.
    fn pixel(l: Vec3, shadow: Option<ShadowQuery>) -> Self {
        Self {
            shadow,
            l,
            film: None,
        }
    }

    /// Adds the contribution, if `visible` says its shadow ray (if any) is
    /// unblocked, to the sample's radiance `l` or as a splat to `splats`.
    fn apply(&self, visible: bool, l: &mut Vec3, splats: &mut Vec<Splat>) {
        if !visible {
            return;
        }
        match self.film {
            Some(pos) => splats.push(Splat { pos, l: self.l }),
            None => *l += self.l,
        }
    }
}

/// The lengths of a sample's subpaths: the camera's, and the light's.
fn subpath_lengths(max_depth: u32, strategies: Strategies) -> (usize, usize) {
    let depth = (max_depth as usize).min(MAX_VERTICES - 2);
    let camera = match strategies {
        Strategies::All => depth + 2,
        Strategies::LightTracing => 2,
    };
    (camera, depth + 1)
}

/// Every strategy's contribution for the sample whose subpaths are `cv`
/// (from the camera) and `lv` (from a light), at `time`, paths of at most
/// `max_depth` scattering events; pushed to `out` in the order the sample
/// sums them (`t` camera vertices outer, `s` light vertices inner), each
/// with the shadow ray that decides whether it arrives. `film` is the
/// image's size in pixels.
#[allow(clippy::too_many_arguments)]
fn connect(
    ctx: &mut Context,
    cv: &[Vertex],
    lv: &[Vertex],
    time: f32,
    max_depth: u32,
    strategies: Strategies,
    film: Vec2,
    out: &mut Vec<Connection>,
) {
    let world = ctx.world;
    let camera = &world.scene.camera;
    let depth = (max_depth as usize).min(MAX_VERTICES - 2);
    for t in 1..=cv.len() {
        for s in 0..=lv.len() {
            if s + t < 2 || (s == 1 && t == 1) || s + t - 2 > depth {
                continue;
            }
            if strategies == Strategies::LightTracing && !(t == 1 || (s == 0 && t == 2)) {
                continue;
            }
            let c = match (t, s) {
                (1, _) => to_lens(ctx, camera, &lv[..s], time, strategies, film),
                (_, 0) => {
                    let l = emitter_found(world, &cv[..t], strategies);
                    // Adding zero to the radiance changes nothing.
                    (l != Vec3::ZERO).then(|| Connection::pixel(l, None))
                }
                (_, 1) => light_sampled(ctx, &cv[..t], time),
                _ => joined(ctx, &lv[..s], &cv[..t], time),
            };
            out.extend(c);
        }
    }
}

/// One pixel sample of bidirectional path tracing (or of light tracing
/// alone) along camera ray `ray` at `time`, paths of at most `max_depth`
/// scattering events, its ray queries answered one at a time; returns the
/// radiance for the sample's pixel and pushes the light tracing
/// contributions to `splats`. `film` is the image's size in pixels. The
/// render loop traces many samples together ([`batch::BdptBatch`]) with
/// the same result bit for bit.
pub(crate) fn sample(
    ctx: &mut Context,
    ray: &Ray,
    time: f32,
    max_depth: u32,
    strategies: Strategies,
    film: Vec2,
    splats: &mut Vec<Splat>,
) -> Vec3 {
    let world = ctx.world;
    let (camera_len, light_len) = subpath_lengths(max_depth, strategies);
    let walk_to_end = |ctx: &mut Context, mut w: Walk, path: &mut Vec<Vertex>| {
        if !w.open(path) {
            return;
        }
        while w.extend(ctx, path, world.intersect(&w.ray, time)) {}
    };
    let mut cv = Vec::with_capacity(camera_len);
    let w = camera_start(world, ray, camera_len, &mut cv);
    walk_to_end(ctx, w, &mut cv);
    let mut lv = Vec::with_capacity(light_len);
    if let Some(w) = light_start(ctx, light_len, &mut lv) {
        walk_to_end(ctx, w, &mut lv);
    }
    let mut connections = Vec::new();
    connect(
        ctx,
        &cv,
        &lv,
        time,
        max_depth,
        strategies,
        film,
        &mut connections,
    );
    let mut l = Vec3::ZERO;
    for c in &connections {
        let visible = c.shadow.is_none_or(|q| world.visible(&q));
        c.apply(visible, &mut l, splats);
    }
    l
}

/// Strategy `s = 0`: the camera subpath's last vertex is on an emitter
/// (or at infinity, in the environment).
fn emitter_found(world: &World, cv: &[Vertex], strategies: Strategies) -> Vec3 {
    let t = cv.len();
    let pt = &cv[t - 1];
    let (le, as_light) = match pt.kind {
        Kind::Infinite => (world.env_radiance(pt.n), {
            let mut v = Vertex::endpoint(Kind::Infinite, Vec3::ZERO, pt.n, pt.beta);
            v.light = pt.light;
            Some(v)
        }),
        Kind::Surface => {
            let Some((hit, sh)) = &pt.surface else {
                return Vec3::ZERO;
            };
            let light = world.light_of(hit.instance).map(|i| {
                let mut v = Vertex::endpoint(Kind::Light, hit.p, hit.ng, pt.beta);
                v.light = i as usize;
                v.two_sided = world.material(hit.material).two_sided_emission;
                v
            });
            (sh.emitted, light)
        }
        _ => return Vec3::ZERO,
    };
    if le == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let c = pt.beta * le;
    // Emitters no light subpath starts from (moving ones) are found this
    // way alone; so are all of them in light tracing.
    let Some(x0) = as_light else {
        return c;
    };
    if strategies == Strategies::LightTracing {
        return c;
    }
    let overrides: Overrides = [
        (0, Some(pdf_origin(world, &x0)), None),
        (1, Some(pdf_emit(world, &x0, &cv[t - 2])), None),
        (usize::MAX, None, None),
        (usize::MAX, None, None),
    ];
    c * mis_weight(0, t, &|i| &cv[i], &|j| &cv[j], &overrides, false)
}

/// Strategy `s = 1`: a point on a light sampled from the camera
/// subpath's last vertex.
fn light_sampled(ctx: &mut Context, cv: &[Vertex], time: f32) -> Option<Connection> {
    let world = ctx.world;
    let t = cv.len();
    let pt = &cv[t - 1];
    let (hit, sh) = pt.connectible()?;
    let depth = (t - 2) as u32;
    let u_pick = ctx.sampler.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
    let u = ctx.sampler.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
    let (i, pmf) = world.pick_light(u_pick)?;
    let light = &world.lights[i];
    let ls = light.sample(hit.p, u)?;
    let f = f_towards(pt, ls.wi, false);
    let c = pt.beta * f * sh.frame.n.dot(ls.wi).abs() * ls.li / (pmf * ls.pdf);
    if c.max_element() <= 0.0 {
        return None;
    }
    let mut x0 = if light.is_infinite() {
        Vertex::endpoint(Kind::Infinite, Vec3::ZERO, ls.wi, ls.li)
    } else {
        Vertex::endpoint(Kind::Light, hit.p + ls.wi * ls.dist, ls.n, ls.li)
    };
    x0.light = i;
    x0.two_sided = ls.two_sided;
    x0.pdf_fwd = pmf * light.pdf_origin(ls.wi);
    let prev = &cv[t - 2];
    let overrides: Overrides = [
        (0, None, Some(pdf_next(world, pt, Some(prev), &x0))),
        (1, Some(pdf_emit(world, &x0, pt)), None),
        (2, Some(pdf_next(world, pt, Some(&x0), prev)), None),
        (usize::MAX, None, None),
    ];
    let w = mis_weight(1, t, &|_| &x0, &|j| &cv[j], &overrides, light.is_delta());
    if w <= 0.0 {
        return None;
    }
    ctx.stats.shadow_rays += 1;
    let q = world.shadow_query(hit.spawn_origin(ls.wi), ls.wi, ls.dist, time, ls.ignore);
    Some(Connection::pixel(c * w, Some(q)))
}

/// Strategy `t = 1`: the light subpath's last vertex joined to a point on
/// the lens; what it carries lands where the vertex is seen.
fn to_lens(
    ctx: &mut Context,
    camera: &Camera,
    lv: &[Vertex],
    time: f32,
    strategies: Strategies,
    film: Vec2,
) -> Option<Connection> {
    let world = ctx.world;
    let s = lv.len();
    let qs = &lv[s - 1];
    let (hit, sh) = qs.connectible()?;
    let u = ctx
        .sampler
        .get_2d(dims::extra((s as u32).min(63), LENS_DIMS, 0));
    let cs = camera.sample_toward(hit.p, u)?;
    let f = f_towards(qs, cs.wi, true);
    let c = qs.beta * f * sh.frame.n.dot(cs.wi).abs() * (cs.importance / cs.pdf);
    if c.max_element() <= 0.0 {
        return None;
    }
    let w = match strategies {
        Strategies::LightTracing => 1.0,
        Strategies::All => {
            let lens = Vertex::endpoint(Kind::Camera, cs.lens, Vec3::ZERO, Vec3::ONE);
            let overrides: Overrides = [
                (s - 1, None, Some(pdf_next(world, &lens, None, qs))),
                (
                    s - 2,
                    None,
                    Some(pdf_next(world, qs, Some(&lens), &lv[s - 2])),
                ),
                (usize::MAX, None, None),
                (usize::MAX, None, None),
            ];
            let delta_light = world.lights[lv[0].light].is_delta();
            mis_weight(s, 1, &|i| &lv[i], &|_| &lens, &overrides, delta_light)
        }
    };
    if w <= 0.0 {
        return None;
    }
    ctx.stats.shadow_rays += 1;
    let q = world.shadow_query(hit.spawn_origin(cs.wi), cs.wi, cs.dist, time, None);
    Some(Connection {
        shadow: Some(q),
        l: c * w,
        film: Some(cs.film * film),
    })
}

/// Strategies `s, t >= 2`: the two subpaths' last vertices joined.
fn joined(ctx: &mut Context, lv: &[Vertex], cv: &[Vertex], time: f32) -> Option<Connection> {
    let world = ctx.world;
    let (s, t) = (lv.len(), cv.len());
    let (qs, pt) = (&lv[s - 1], &cv[t - 1]);
    let (Some((qhit, qsh)), Some((phit, psh))) = (qs.connectible(), pt.connectible()) else {
        return None;
    };
    let d = qhit.p - phit.p;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let dist = d2.sqrt();
    let w = d / dist;
    let g = qsh.frame.n.dot(w).abs() * psh.frame.n.dot(w).abs() / d2;
    let c = qs.beta * f_towards(qs, -w, true) * f_towards(pt, w, false) * pt.beta * g;
    if c.max_element() <= 0.0 {
        return None;
    }
    let overrides: Overrides = [
        (s - 1, None, Some(pdf_next(world, pt, Some(&cv[t - 2]), qs))),
        (s - 2, None, Some(pdf_next(world, qs, Some(pt), &lv[s - 2]))),
        (s, Some(pdf_next(world, qs, Some(&lv[s - 2]), pt)), None),
        (s + 1, Some(pdf_next(world, pt, Some(qs), &cv[t - 2])), None),
    ];
    let delta_light = world.lights[lv[0].light].is_delta();
    let weight = mis_weight(s, t, &|i| &lv[i], &|j| &cv[j], &overrides, delta_light);
    if weight <= 0.0 {
        return None;
    }
    ctx.stats.shadow_rays += 1;
    let q = world.shadow_query(phit.spawn_origin(w), w, dist, time, None);
    Some(Connection::pixel(c * weight, Some(q)))
}
