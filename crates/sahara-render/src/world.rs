//! The scene prepared for rendering: acceleration structure, the lights
//! the integrators sample and how one is chosen, and surface hits.

use glam::{Vec2, Vec3};
use sahara_kd::gamma;
use sahara_kd::{AccelParams, Counters, NoCounters, Ray};

use crate::accel::{Accel, BatchBuffers, RawHit};
use crate::integrator::guiding::Guide;
use crate::light::area::{sample_flat_lanes, FlatPiece};
use crate::light::choice::{Chosen, LightChoice};
use crate::light::gather::SceneLights;
use crate::light::{AreaLight, LightSample, LightSampler, LightSource};
use crate::material::Material;
use crate::math::lanes::{F, M, V};
use crate::math::piecewise::Distribution1D;
use crate::math::warp::Frame;
use crate::medium::{Medium, MediumInterface};
use crate::scene::mesh::SceneMesh;
use crate::scene::Scene;
use crate::texture::footprint::{CameraSpread, UvFootprint};

/// A ray's intersection with a surface, in world space.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Ray parameter (distance for unit directions).
    pub t: f32,
    /// Hit point.
    pub p: Vec3,
    /// Unit geometric normal of the front face (winding order).
    pub ng: Vec3,
    /// Unit shading normal, on the same side as `ng`.
    pub ns: Vec3,
    /// Texture coordinates (the mesh's first uv set; the barycentric
    /// coordinates without one).
    pub uv: Vec2,
    /// The mesh's second uv set (the first without one).
    pub uv1: Vec2,
    /// Barycentric coordinates of the hit (of the second and third
    /// corner).
    pub bary: Vec2,
    /// Shutter fraction of the ray's time (where moving instances were).
    pub shutter: f32,
    /// Material id.
    pub material: u32,
    /// Instance index.
    pub instance: u32,
    /// Triangle index in the instance's mesh.
    pub tri: u32,
    /// Bound on the rounding error of `p` along `ng`.
    pub err: f32,
}

impl SurfaceHit {
    /// The origin of a ray leaving the surface along `w`: the hit point
    /// pushed along the geometric normal, to `w`'s side, past the bound on
    /// its rounding error, so the new ray cannot hit this surface again.
    #[inline]
    pub fn spawn_origin(&self, w: Vec3) -> Vec3 {
        let off = self.ng * self.err;
        if w.dot(self.ng) >= 0.0 {
            self.p + off
        } else {
            self.p - off
        }
    }

    /// The shading frame.
    #[inline]
    pub fn frame(&self) -> Frame {
        Frame::from_normal(self.ns)
    }

    /// Both uv sets.
    #[inline]
    pub fn uvs(&self) -> [Vec2; 2] {
        [self.uv, self.uv1]
    }
}

/// An occlusion query: the segment of `ray` at `time`, which instance
/// `ignore` cannot block.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShadowQuery {
    /// The segment (its interval ends short of the light).
    pub ray: Ray,
    /// The sample's time.
    pub time: f32,
    /// An instance that cannot block (the light's own surface).
    pub ignore: Option<u32>,
}

/// The buffers of the world's batch queries, kept from one call to the
/// next.
#[derive(Debug, Default)]
pub struct WorldBuffers {
    s: Vec<f32>,
    raw: Vec<Option<RawHit>>,
    rays: Vec<Ray>,
    ignore: Vec<Option<u32>>,
    accel: BatchBuffers,
}

/// Safety factor on the pbrt-style error bound (it is a first-order bound;
/// doubling it costs nothing visible).
const ERR_SAFETY: f32 = 2.0;

/// Smallest ray-origin offset, in units of the hit point's largest
/// coordinate times the machine epsilon (about 8 ulps).
const MIN_OFFSET_ULPS: f32 = 16.0;

/// The prepared scene.
pub struct World<'a> {
    /// The description.
    pub scene: &'a Scene,
    /// Ray queries.
    pub accel: Accel,
    /// Every sampled light.
    pub lights: Vec<LightSource>,
    /// How light tracing picks the light a path starts from: by power.
    select: Distribution1D,
    /// How next-event estimation picks the light it samples from a
    /// shading point.
    nee: LightChoice,
    /// Each light's powers, by which the choice is made.
    powers: Vec<f32>,
    instance_light: Vec<Option<u32>>,
    /// Per light, the triangles of its instance's mesh a mesh light is
    /// made of (empty for other lights).
    mesh_triangles: Vec<Vec<u32>>,
    env: Option<u32>,
    default_material: Material,
    /// Whether any material has holes (alpha): shadow rays then look at
    /// what they meet.
    has_holes: bool,
    /// The camera as texture lookups see it (none: lookups read the
    /// finest MIP level).
    pub spread: Option<CameraSpread>,
    /// Centre of the scene's bounds.
    pub center: Vec3,
    /// Radius of the scene's bounding sphere.
    pub radius: f32,
    /// The media on the two sides of each instance's surface (empty when
    /// the scene has no media).
    interfaces: Vec<Option<MediumInterface>>,
    /// Whether light travels through media ([`Scene::has_media`]).
    has_media: bool,
    /// What a guided render has learned of where light comes from
    /// (`integrator::guiding`); None when the render is not guided.
    guide: Option<Guide>,
}

impl<'a> World<'a> {
    /// Builds trees and lights, the lights chosen by the default light
    /// sampler.
    pub fn new(scene: &'a Scene, params: &AccelParams) -> Self {
        Self::with_light_sampler(scene, params, LightSampler::default())
    }

    /// Builds trees and lights, the lights chosen by `light_sampler`.
    pub fn with_light_sampler(
        scene: &'a Scene,
        params: &AccelParams,
        light_sampler: LightSampler,
    ) -> Self {
        let SceneLights {
            lights,
            instance_light,
            env,
            mesh_triangles,
        } = SceneLights::gather(scene);
        // Shadow rays towards a sphere light ignore the sphere's own
        // instance, which therefore keeps a tree of its own.
        let ignorable: Vec<u32> = lights
            .iter()
            .filter_map(|l| match l {
                LightSource::Area(a) => a.shadow_ignore(),
                LightSource::Explicit(_) | LightSource::Environment(_) => None,
            })
            .collect();
        let accel = Accel::build(&scene.meshes, &scene.instances, params, &ignorable);
        let (center, radius) = bounding_sphere(&accel);
        let powers: Vec<f32> = lights.iter().map(|l| l.power(radius)).collect();
        let nee = LightChoice::new(light_sampler, &lights, &powers);
        let select = Distribution1D::new(powers.clone());
        Self {
            scene,
            accel,
            lights,
            select,
            nee,
            powers,
            instance_light,
            mesh_triangles,
            env,
            default_material: Material::default(),
            has_holes: scene.materials.iter().any(Material::has_holes),
            spread: None,
            center,
            radius,
            interfaces: if scene.has_media() {
                let mut v = vec![None; scene.instances.len()];
                for &(i, m) in &scene.medium_interfaces {
                    if let Some(slot) = v.get_mut(i as usize) {
                        *slot = Some(m);
                    }
                }
                v
            } else {
                Vec::new()
            },
            has_media: scene.has_media(),
            guide: None,
        }
    }

    /// The path guide of the iteration under way, if the render is guided.
    #[inline]
    pub(crate) fn guide(&self) -> Option<&Guide> {
        self.guide.as_ref()
    }

    /// Sets the path guide the next passes sample and train (None: none),
    /// returning the one before.
    pub(crate) fn swap_guide(&mut self, guide: Option<Guide>) -> Option<Guide> {
        std::mem::replace(&mut self.guide, guide)
    }

    /// True if light travels through media in this scene (see
    /// [`Scene::has_media`]).
    #[inline]
    pub fn has_media(&self) -> bool {
        self.has_media
    }

    /// The media on the two sides of `instance`'s surface, if it bounds
    /// any.
    #[inline]
    pub fn medium_interface(&self, instance: u32) -> Option<&MediumInterface> {
        self.interfaces.get(instance as usize)?.as_ref()
    }

    /// Medium `i` of the scene.
    #[inline]
    pub fn medium(&self, i: u32) -> &Medium {
        &self.scene.media[i as usize]
    }

    /// Chooses the lights next-event estimation samples by `kind` (a
    /// world is made with the default, [`LightSampler::Tree`]).
    pub fn set_light_sampler(&mut self, kind: LightSampler) {
        if self.nee.kind() != kind {
            self.nee = LightChoice::new(kind, &self.lights, &self.powers);
        }
    }

    /// Sets the footprint of texture lookups from the film: `height`
    /// pixels and `spp` samples per pixel in all (see
    /// [`crate::texture::footprint`]).
    pub fn set_film(&mut self, height: u32, spp: u64) {
        let c = &self.scene.camera;
        self.spread = Some(CameraSpread::new(c.eye, c.vfov_deg, height, spp));
    }

    /// The corners of the hit triangle in world space, and its mesh.
    fn corners(&self, hit: &SurfaceHit) -> ([Vec3; 3], &crate::scene::mesh::SceneMesh, [u32; 3]) {
        let inst = &self.scene.instances[hit.instance as usize];
        let mesh = &self.scene.meshes[inst.mesh as usize];
        let idx = mesh.mesh.indices[hit.tri as usize];
        let xf = self.accel.transform(hit.instance, hit.shutter);
        (
            idx.map(|k| xf.transform_point3(mesh.mesh.positions[k as usize])),
            mesh,
            idx,
        )
    }

    /// The footprint of texture lookups at `hit`.
    pub fn uv_footprint(&self, hit: &SurfaceHit) -> UvFootprint {
        let Some(offsets) = self.spread.and_then(|s| s.surface_offsets(hit.p, hit.ng)) else {
            return UvFootprint::POINT;
        };
        let (p, mesh, idx) = self.corners(hit);
        let set = |uvs: Option<&Vec<Vec2>>| match uvs {
            Some(t) => idx.map(|k| t[k as usize]),
            None => [Vec2::ZERO, Vec2::X, Vec2::Y],
        };
        let uv0 = set(mesh.uvs.as_ref());
        let uv1 = mesh
            .uvs1
            .as_ref()
            .map_or(uv0, |t| idx.map(|k| t[k as usize]));
        UvFootprint::on_triangle(p, [uv0, uv1], offsets)
    }

    /// The world-space tangent at `hit` for a normal map read from uv set
    /// `uv_set`, with its handedness: the mesh's tangents interpolated,
    /// else the direction of increasing `u` on the triangle.
    pub fn tangent(&self, hit: &SurfaceHit, uv_set: u8) -> (Vec3, f32) {
        let inst = &self.scene.instances[hit.instance as usize];
        let mesh = &self.scene.meshes[inst.mesh as usize];
        let xf = self.accel.transform(hit.instance, hit.shutter);
        let m = glam::Mat3::from(xf.matrix3);
        let mirror = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
        let idx = mesh.mesh.indices[hit.tri as usize];
        if let Some(t) = &mesh.tangents {
            let (b1, b2) = (hit.bary.x, hit.bary.y);
            let [t0, t1, t2] = idx.map(|k| t[k as usize]);
            let v = t0.truncate() * (1.0 - b1 - b2) + t1.truncate() * b1 + t2.truncate() * b2;
            return (m * v, t0.w.signum() * mirror);
        }
        let (p, mesh, idx) = self.corners(hit);
        let uvs = match uv_set {
            0 => mesh.uvs.as_ref(),
            _ => mesh.uvs1.as_ref().or(mesh.uvs.as_ref()),
        };
        let uv = uvs.map_or([Vec2::ZERO, Vec2::X, Vec2::Y], |t| {
            idx.map(|k| t[k as usize])
        });
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = d1.x * d2.y - d1.y * d2.x;
        if det == 0.0 || !det.is_finite() {
            return (e1, 1.0);
        }
        let dpdu = (e1 * d2.y - e2 * d1.y) / det;
        let dpdv = (e2 * d1.x - e1 * d2.x) / det;
        let sign = hit.ng.cross(dpdu).dot(dpdv).signum();
        (dpdu, sign)
    }

    /// The material with id `id` (a grey default when out of range).
    #[inline]
    pub fn material(&self, id: u32) -> &Material {
        self.scene
            .materials
            .get(id as usize)
            .unwrap_or(&self.default_material)
    }

    /// Shutter fraction of an absolute time.
    #[inline]
    pub fn shutter_fraction(&self, time: f32) -> f32 {
        self.scene.camera.shutter_fraction(time)
    }

    /// The closest surface along `ray` at `time`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, time: f32) -> Option<SurfaceHit> {
        self.intersect_counted(ray, time, &mut NoCounters)
    }

    /// [`World::intersect`], counting traversal work.
    pub fn intersect_counted<C: Counters>(
        &self,
        ray: &Ray,
        time: f32,
        counters: &mut C,
    ) -> Option<SurfaceHit> {
        let s = self.shutter_fraction(time);
        let h = self.accel.closest(ray, s, counters)?;
        Some(self.surface(&h, s))
    }

    /// The closest surfaces along up to [`sahara_kd::PACKET16`] rays,
    /// `rays[i]` at `times[i]`, traced as a packet (coherent rays, such as
    /// the camera rays of a 4x4 pixel block, trace faster that way); the
    /// same hits as [`World::intersect`] ray by ray.
    pub fn intersect_packet(&self, rays: &[Ray], times: &[f32], out: &mut [Option<SurfaceHit>]) {
        let n = rays.len();
        let mut s = [0.0f32; sahara_kd::PACKET16];
        for (s, &t) in s.iter_mut().zip(times) {
            *s = self.shutter_fraction(t);
        }
        let mut raw = [None; sahara_kd::PACKET16];
        self.accel.closest_packet(rays, &s[..n], &mut raw[..n]);
        for ((o, h), &s) in out.iter_mut().zip(&raw[..n]).zip(&s[..n]) {
            *o = h.map(|h| self.surface(&h, s));
        }
    }

    /// The closest surfaces along many rays, `rays[i]` at `times[i]`, in
    /// one batch (see [`Accel::closest_batch`]); the same hits as
    /// [`World::intersect`] ray by ray. `buf` holds buffers between calls.
    pub fn intersect_batch(
        &self,
        rays: &[Ray],
        times: &[f32],
        out: &mut [Option<SurfaceHit>],
        buf: &mut WorldBuffers,
    ) {
        buf.s.clear();
        buf.s
            .extend(times.iter().map(|&t| self.shutter_fraction(t)));
        buf.raw.clear();
        buf.raw.resize(rays.len(), None);
        self.accel
            .closest_batch(rays, &buf.s, &mut buf.raw, &mut buf.accel);
        // The hits' triangles lie anywhere in the meshes: their indices,
        // then their vertices, are asked of the cache a few hits ahead
        // of the one whose shading data is computed, so that the loads
        // overlap instead of each hit waiting for its own.
        let raw = &buf.raw;
        let ahead = |k: usize| raw.get(k).copied().flatten();
        for k in 0..raw.len().min(2 * PREFETCH_AHEAD) {
            if let Some(h) = ahead(k) {
                self.prefetch_indices(&h);
            }
        }
        for (k, ((o, h), &s)) in out.iter_mut().zip(raw).zip(&buf.s).enumerate() {
            if let Some(h) = ahead(k + 2 * PREFETCH_AHEAD) {
                self.prefetch_indices(&h);
            }
            if let Some(h) = ahead(k + PREFETCH_AHEAD) {
                self.prefetch_vertices(&h);
            }
            *o = h.map(|h| self.surface(&h, s));
        }
    }

    /// Asks the cache for the indices (and material id) of `h`'s triangle.
    #[inline(always)]
    fn prefetch_indices(&self, h: &RawHit) {
        let mesh = self.mesh_of(h);
        prefetch(mesh.mesh.indices.as_ptr().wrapping_add(h.tri as usize));
        if let Some(ids) = &mesh.material_ids {
            prefetch(ids.as_ptr().wrapping_add(h.tri as usize));
        }
    }

    /// Asks the cache for the vertices of `h`'s triangle: positions, and
    /// normals and texture coordinates where the mesh has them.
    #[inline(always)]
    fn prefetch_vertices(&self, h: &RawHit) {
        let mesh = self.mesh_of(h);
        let Some(idx) = mesh.mesh.indices.get(h.tri as usize) else {
            return;
        };
        for &i in idx {
            let i = i as usize;
            prefetch(mesh.mesh.positions.as_ptr().wrapping_add(i));
            if let Some(n) = &mesh.normals {
                prefetch(n.as_ptr().wrapping_add(i));
            }
            if let Some(t) = &mesh.uvs {
                prefetch(t.as_ptr().wrapping_add(i));
            }
        }
    }

    /// The mesh of `h`'s instance.
    #[inline(always)]
    fn mesh_of(&self, h: &RawHit) -> &SceneMesh {
        let inst = &self.scene.instances[h.instance as usize];
        &self.scene.meshes[inst.mesh as usize]
    }

    /// [`World::visible`] of many queries, into `out[i]`, in one batch
    /// (see [`Accel::occluded_batch`]).
    pub(crate) fn visible_batch(
        &self,
        queries: &[ShadowQuery],
        out: &mut [bool],
        buf: &mut WorldBuffers,
    ) {
        if self.has_holes {
            for (q, o) in queries.iter().zip(out) {
                *o = self.visible_through_holes(q);
            }
            return;
        }
        buf.rays.clear();
        buf.rays.extend(queries.iter().map(|q| q.ray));
        buf.s.clear();
        buf.s
            .extend(queries.iter().map(|q| self.shutter_fraction(q.time)));
        buf.ignore.clear();
        buf.ignore.extend(queries.iter().map(|q| q.ignore));
        self.accel
            .occluded_batch(&buf.rays, &buf.s, &buf.ignore, out, &mut buf.accel);
        for o in out.iter_mut() {
            *o = !*o;
        }
    }

    /// Shading data of a raw hit.
    fn surface(&self, h: &RawHit, s: f32) -> SurfaceHit {
        let inst = &self.scene.instances[h.instance as usize];
        let mesh = &self.scene.meshes[inst.mesh as usize];
        let idx = mesh.mesh.indices[h.tri as usize];
        let [p0, p1, p2] = idx.map(|k| mesh.mesh.positions[k as usize]);
        let (b1, b2) = (h.u, h.v);
        let b0 = 1.0 - b1 - b2;
        let xf = self.accel.transform(h.instance, s);
        let p_obj = p0 * b0 + p1 * b1 + p2 * b2;
        let p = xf.transform_point3(p_obj);
        // Error bounds after pbrt (Pharr, Jakob, Humphreys, section 3.9):
        // barycentric interpolation, then the affine transform.
        let err_obj = gamma(7) * ((p0 * b0).abs() + (p1 * b1).abs() + (p2 * b2).abs());
        let m = glam::Mat3::from(xf.matrix3);
        let m_abs = glam::Mat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let t_abs = Vec3::from(xf.translation).abs();
        let err = m_abs * err_obj * (1.0 + gamma(3)) + gamma(3) * (m_abs * p_obj.abs() + t_abs);
        // Normals transform by the inverse transpose.
        let nm = self.accel.normal_transform(h.instance, &xf);
        let ng = (nm * (p1 - p0).cross(p2 - p0)).normalize_or_zero();
        let ns = match &mesh.normals {
            Some(n) => {
                let [n0, n1, n2] = idx.map(|k| n[k as usize]);
                let ns = (nm * (n0 * b0 + n1 * b1 + n2 * b2)).normalize_or_zero();
                if ns == Vec3::ZERO || !ns.is_finite() {
                    ng
                } else if ns.dot(ng) < 0.0 {
                    -ns
                } else {
                    ns
                }
            }
            None => ng,
        };
        let lerp = |t: &Vec<Vec2>| {
            let [t0, t1, t2] = idx.map(|k| t[k as usize]);
            t0 * b0 + t1 * b1 + t2 * b2
        };
        let uv = mesh.uvs.as_ref().map_or(Vec2::new(b1, b2), lerp);
        let uv1 = mesh.uvs1.as_ref().map_or(uv, lerp);
        SurfaceHit {
            t: h.t,
            p,
            ng,
            ns,
            uv,
            uv1,
            bary: Vec2::new(b1, b2),
            shutter: s,
            material: self.scene.material_of(h.instance, h.tri),
            instance: h.instance,
            tri: h.tri,
            // The bound is zero for a point computed exactly (a triangle in
            // a coordinate plane), but the kd-tree's test accepts t = 0, and
            // an offset below an ulp of the coordinates would round away:
            // never offset by less than a few ulps of the point's magnitude.
            err: (ERR_SAFETY * err.dot(ng.abs()))
                .max(MIN_OFFSET_ULPS * f32::EPSILON * p.abs().max_element())
                .max(f32::MIN_POSITIVE),
        }
    }

    /// True if nothing blocks the segment from `origin` along unit `w` over
    /// `dist` (infinite for distant lights): [`World::shadow_query`]
    /// answered by [`World::visible`].
    /// `ignore` names an instance that cannot block (see [`LightSample`]).
    pub fn unoccluded(
        &self,
        origin: Vec3,
        w: Vec3,
        dist: f32,
        time: f32,
        ignore: Option<u32>,
    ) -> bool {
        self.visible(&self.shadow_query(origin, w, dist, time, ignore))
    }

    /// The occlusion query of the segment from `origin` along unit `w` over
    /// `dist`. The segment stops short of its end by [`SHADOW_EPS`] of its
    /// length, so the light's own surface does not block it.
    #[inline]
    pub(crate) fn shadow_query(
        &self,
        origin: Vec3,
        w: Vec3,
        dist: f32,
        time: f32,
        ignore: Option<u32>,
    ) -> ShadowQuery {
        let tmax = if dist.is_finite() {
            dist * (1.0 - SHADOW_EPS)
        } else {
            f32::INFINITY
        };
        ShadowQuery {
            ray: Ray::with_interval(origin, w, 0.0, tmax),
            time,
            ignore,
        }
    }

    /// True if nothing blocks the segment of `q`.
    #[inline]
    pub(crate) fn visible(&self, q: &ShadowQuery) -> bool {
        if self.has_holes {
            return self.visible_through_holes(q);
        }
        !self
            .accel
            .occluded(&q.ray, self.shutter_fraction(q.time), q.ignore)
    }

    /// [`World::visible`] in a scene with cut-out or stochastic surfaces:
    /// the closest surfaces along the segment in turn, until one is
    /// there (blocked) or none is left (visible). After
    /// [`MAX_PASS_THROUGHS`] surfaces the segment counts as blocked.
    fn visible_through_holes(&self, q: &ShadowQuery) -> bool {
        let s = self.shutter_fraction(q.time);
        let mut ray = q.ray;
        for k in 0..MAX_PASS_THROUGHS {
            let Some(h) = self.accel.closest(&ray, s, &mut NoCounters) else {
                return true;
            };
            let hit = self.surface(&h, s);
            if Some(h.instance) != q.ignore {
                let u = pass_through_draw(&ray, &hit, k);
                if !self.material(hit.material).passes(&hit.uvs(), u) {
                    return false;
                }
            }
            let origin = hit.spawn_origin(ray.dir);
            let travelled = (origin - ray.origin).dot(ray.dir) / ray.dir.length_squared();
            ray = Ray::with_interval(origin, ray.dir, 0.0, ray.tmax - travelled);
            if ray.tmax.is_nan() || ray.tmax <= 0.0 {
                return true;
            }
        }
        false
    }

    /// True if the scene has any light to sample.
    pub fn has_lights(&self) -> bool {
        !self.lights.is_empty()
    }

    /// One light chosen for next-event estimation (`u_pick`) from the
    /// point `p` with shading normal `n` (zero for a point in a medium),
    /// sampled from `p` (`u`), with the probability of the choice.
    pub fn sample_light(
        &self,
        p: Vec3,
        n: Vec3,
        u_pick: f32,
        u: Vec2,
    ) -> Option<(LightSample, f32)> {
        self.sample_light_as(p, n, u_pick, u, false)
    }

    /// [`World::sample_light`] for estimators that weigh the light's
    /// sample against BSDF sampling by MIS (with [`World::env_pdf_mis`]):
    /// the environment's sample is MIS-compensated
    /// ([`EnvLight::sample_mis`](crate::light::environment::EnvLight::sample_mis)).
    pub fn sample_light_mis(
        &self,
        p: Vec3,
        n: Vec3,
        u_pick: f32,
        u: Vec2,
    ) -> Option<(LightSample, f32)> {
        self.sample_light_as(p, n, u_pick, u, true)
    }

    /// [`World::sample_light_mis`] for the lanes `on` of a packet of
    /// paths (points `p`, shading normals `n`): the light chosen in the
    /// lanes, and flat pieces (untextured triangles of mesh lights, quads)
    /// sampled in the lanes; other lights lane by lane. Each lane's sample
    /// is the scalar one, bit for bit.
    #[inline(always)]
    pub(crate) fn sample_light_mis_lanes<const N: usize>(
        &self,
        on: M<N>,
        p: V<N>,
        n: V<N>,
        u_pick: F<N>,
        u: (F<N>, F<N>),
    ) -> LightLanes<N> {
        let mut out = LightLanes {
            has: M::splat(false),
            wi: V::default(),
            li: V::default(),
            pdf: F::splat(1.0),
            dist: F::splat(0.0),
            delta: M::splat(false),
            ignore: [None; N],
        };
        if self.lights.is_empty() || !on.any() {
            return out;
        }
        let chosen = self.nee.sample_lanes(on, p, n, u_pick);
        let mut pieces = [FlatPiece::default(); N];
        let mut flat = M::<N>::splat(false);
        let mut pmf = F::<N>::splat(1.0);
        for (i, c) in chosen.iter().enumerate() {
            let Some(c) = c else { continue };
            let light = &self.lights[c.light];
            let piece = match light {
                LightSource::Area(a) => a.flat_piece(c.tri),
                _ => None,
            };
            if let Some(f) = piece {
                pieces[i] = f;
                flat.0[i] = true;
                pmf.0[i] = c.pmf;
                continue;
            }
            let ui = Vec2::new(u.0 .0[i], u.1 .0[i]);
            if let Some(ls) = self.sample_chosen(c, p.get(i), ui, true) {
                out.has.0[i] = true;
                out.wi.set(i, ls.wi);
                out.li.set(i, ls.li);
                out.pdf.0[i] = c.pmf * ls.pdf;
                out.dist.0[i] = ls.dist;
                out.delta.0[i] = ls.delta;
                out.ignore[i] = ls.ignore;
            }
        }
        if flat.any() {
            let fs = sample_flat_lanes(&pieces, p, u);
            let ok = flat & fs.ok;
            out.has = out.has | ok;
            out.wi = ok.select_v(fs.wi, out.wi);
            out.li = ok.select_v(fs.li, out.li);
            out.pdf = ok.select(pmf * fs.pdf, out.pdf);
            out.dist = ok.select(fs.dist, out.dist);
        }
        out
    }

    /// [`World::sample_light`], or with `mis` its MIS-compensated form.
    #[inline]
    fn sample_light_as(
        &self,
        p: Vec3,
        n: Vec3,
        u_pick: f32,
        u: Vec2,
        mis: bool,
    ) -> Option<(LightSample, f32)> {
        if self.lights.is_empty() {
            return None;
        }
        let c = self.nee.sample(p, n, u_pick)?;
        Some((self.sample_chosen(&c, p, u, mis)?, c.pmf))
    }

    /// The chosen light `c` sampled from `p` with `u`: a mesh light's
    /// chosen triangle alone, or the whole light (with `mis`, its
    /// MIS-compensated form).
    #[inline]
    fn sample_chosen(&self, c: &Chosen, p: Vec3, u: Vec2, mis: bool) -> Option<LightSample> {
        match (&self.lights[c.light], c.tri) {
            (LightSource::Area(a), Some(tri)) => a.sample_triangle(p, tri, u),
            (l, _) if mis => l.sample_mis(p, u),
            (l, _) => l.sample(p, u),
        }
    }

    /// One light chosen by power (`u_pick`), as its index and the
    /// probability of the choice.
    pub(crate) fn pick_light(&self, u_pick: f32) -> Option<(usize, f32)> {
        if self.lights.is_empty() {
            return None;
        }
        let (i, pmf) = self.select.sample_discrete(u_pick);
        (pmf > 0.0).then_some((i, pmf))
    }

    /// The sampled light that instance `instance` is part of, if any.
    pub(crate) fn light_of(&self, instance: u32) -> Option<u32> {
        self.instance_light[instance as usize]
    }

    /// The environment's light, if the scene has an environment.
    pub(crate) fn env_light(&self) -> Option<u32> {
        self.env
    }

    /// Probability that [`World::pick_light`] picks light `i`.
    pub fn light_pmf(&self, i: usize) -> f32 {
        self.select.pmf(i)
    }

    /// Density (selection times solid angle) with which light sampling from
    /// `p_ref` (shading normal `n_ref`, zero in a medium) produces
    /// direction `wi` towards the emissive `hit`; 0 when the hit surface is
    /// not a sampled light.
    pub fn light_pdf(&self, p_ref: Vec3, n_ref: Vec3, hit: &SurfaceHit, wi: Vec3) -> f32 {
        let Some(l) = self.instance_light[hit.instance as usize] else {
            return 0.0;
        };
        let l = l as usize;
        let LightSource::Area(a) = &self.lights[l] else {
            return 0.0;
        };
        if self.nee.by_triangle() && a.is_mesh() {
            let Some(k) = AreaLight::triangle_of(&self.mesh_triangles[l], hit.tri) else {
                return 0.0;
            };
            let pmf = self.nee.pmf(p_ref, n_ref, l, Some(k));
            if pmf == 0.0 {
                return 0.0;
            }
            return pmf * a.pdf_triangle(k, p_ref, hit.p, hit.ng, wi);
        }
        self.nee.pmf(p_ref, n_ref, l, None) * a.pdf(p_ref, hit.p, hit.ng, wi)
    }

    /// Radiance of the environment along `w` (black without one).
    pub fn env_radiance(&self, w: Vec3) -> Vec3 {
        match self.env {
            Some(i) => match &self.lights[i as usize] {
                LightSource::Environment(e) => e.radiance(w),
                LightSource::Explicit(_) | LightSource::Area(_) => Vec3::ZERO,
            },
            None => Vec3::ZERO,
        }
    }

    /// Density (selection times solid angle) of light sampling choosing
    /// direction `w` on the environment.
    pub fn env_pdf(&self, w: Vec3) -> f32 {
        match self.env {
            Some(i) => match &self.lights[i as usize] {
                LightSource::Environment(e) => {
                    self.nee.pmf(Vec3::ZERO, Vec3::ZERO, i as usize, None) * e.pdf(w)
                }
                LightSource::Explicit(_) | LightSource::Area(_) => 0.0,
            },
            None => 0.0,
        }
    }

    /// [`World::env_pdf`] of [`World::sample_light_mis`].
    pub fn env_pdf_mis(&self, w: Vec3) -> f32 {
        match self.env {
            Some(i) => match &self.lights[i as usize] {
                LightSource::Environment(e) => {
                    self.nee.pmf(Vec3::ZERO, Vec3::ZERO, i as usize, None) * e.pdf_mis(w)
                }
                LightSource::Explicit(_) | LightSource::Area(_) => 0.0,
            },
            None => 0.0,
        }
    }

    /// True if the scene has an environment.
    pub fn has_environment(&self) -> bool {
        self.env.is_some()
    }
}

/// Relative shortening of shadow rays towards points on lights.
pub const SHADOW_EPS: f32 = 1.0 / 4096.0;

/// The centre and radius of a sphere around the scene's geometry (the unit
/// sphere when there is none).
fn bounding_sphere(accel: &Accel) -> (Vec3, f32) {
    let b = accel.bounds();
    if b.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (b.center(), (0.5 * b.extent().length()).max(1e-3))
    }
}

/// Most surfaces with holes a ray passes through before it stops there.
pub const MAX_PASS_THROUGHS: u32 = 64;

/// The uniform number deciding whether the `k`-th surface a shadow ray
/// meets lets it through (stochastic transparency): a hash of the ray and
/// the hit, so a render is the same every time.
#[inline]
pub(crate) fn pass_through_draw(ray: &Ray, hit: &SurfaceHit, k: u32) -> f32 {
    let o = ray.origin.to_array().map(f32::to_bits);
    let d = ray.dir.to_array().map(f32::to_bits);
    let a = (o[0] as u64) << 32 | o[1] as u64;
    let b = (o[2] as u64) << 32 | d[0] as u64;
    let c = (d[1] as u64) << 32 | d[2] as u64;
    let e = (hit.instance as u64) << 32 | hit.tri as u64;
    crate::math::hash::unit_f32(crate::math::hash::hash3(a ^ e, b, c.wrapping_add(k as u64)))
}

/// Hits ahead of the one being shaded whose vertices are asked of the
/// cache (their indices twice as far ahead).
const PREFETCH_AHEAD: usize = 8;

/// Asks the cache for the line holding `p` (a hint: it neither faults nor
/// reads).
#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch neither faults nor reads.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast())
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Light samples of a packet's lanes ([`World::sample_light_mis_lanes`]):
/// per lane whether it has one, and the direction, incident radiance,
/// density (the choice's probability times the sample's solid-angle
/// density), distance, whether the light is a delta light and the
/// instance its shadow ray must ignore.
pub(crate) struct LightLanes<const N: usize> {
    pub has: M<N>,
    pub wi: V<N>,
    pub li: V<N>,
    pub pdf: F<N>,
    pub dist: F<N>,
    pub delta: M<N>,
    pub ignore: [Option<u32>; N],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::Camera;
    use crate::scene::shape::Shape;

    /// A floor 100 wide under a 1x1 quad light facing it from a height of
    /// 1 and an emitting sphere beside it: the quad joins the world tree,
    /// the sphere keeps its own; and no shadow segment from the floor to
    /// a point sampled on the quad is blocked, the quad's own triangles
    /// now in the walk, down to a cosine of 1/50 at the light.
    #[test]
    fn a_flat_emitter_joins_the_world_tree_and_never_shadows_its_samples() {
        let cam = Camera::look_at(Vec3::new(0.0, 3.0, -3.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0);
        let mut scene = Scene::new(cam);
        let floor = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
        let lamp = scene.add_material(Material::emitter(Vec3::splat(4.0)).with_two_sided(false));
        // A square of side `a` at height `y`, facing down (the floor's
        // side does not matter to its shadows).
        let square = |y: f32, a: f32| Shape::Quad {
            corner: Vec3::new(-a / 2.0, y, -a / 2.0),
            edge_u: Vec3::new(a, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 0.0, a),
        };
        let f = scene.add_shape(square(0.0, 100.0), floor);
        let q = scene.add_shape(square(1.0, 1.0), lamp);
        let s = scene.add_shape(
            Shape::Sphere {
                center: Vec3::new(30.0, 2.0, 0.0),
                radius: 0.5,
            },
            lamp,
        );
        let world = World::new(&scene, &AccelParams::default());
        assert!(world.accel.is_merged(f) && world.accel.is_merged(q));
        assert!(!world.accel.is_merged(s));
        let quad = world
            .lights
            .iter()
            .find_map(|l| match l {
                LightSource::Area(a) if a.instance == Some(q) => Some(a),
                _ => None,
            })
            .expect("the quad's light");
        assert_eq!(quad.shadow_ignore(), None);
        let (mut tried, mut blocked) = (0, 0);
        for i in 0..=40 {
            for j in 0..=40 {
                let p = Vec3::new(-49.0 + 2.45 * i as f32, 0.0, -49.0 + 2.45 * j as f32);
                for k in 0..16 {
                    let u = Vec2::new((k % 4) as f32 / 4.0 + 0.1, (k / 4) as f32 / 4.0 + 0.1);
                    let Some(ls) = quad.sample(p, u) else {
                        continue;
                    };
                    let origin = p + Vec3::Y * 1e-4;
                    let q = world.shadow_query(origin, ls.wi, ls.dist, 0.0, ls.ignore);
                    tried += 1;
                    blocked += usize::from(!world.visible(&q));
                }
            }
        }
        assert!(tried > 20_000, "{tried}");
        assert_eq!(blocked, 0, "{blocked} of {tried} blocked");
    }
}
