//! The scene's acceleration structure, organised as Mitsuba and Embree
//! organise theirs: the static geometry that is not instanced sits in one
//! world-space tree (an eight-wide bounding volume hierarchy by default, or
//! a kd-tree: `RenderSettings::build`), and real instances keep two levels.
//!
//! - Every instance that is static, whose mesh no other instance uses, and
//!   that no occlusion query may ignore (see [`Accel::build`]) is *merged*:
//!   its triangles are moved to world space at build time and go into one
//!   world tree with the others, traced without any transform.
//! - The others (meshes shared by several instances, moving instances,
//!   emitting spheres, whose shadow rays ignore them, and a ground plane
//!   that dwarfs the rest, see [`grounds`]) keep one tree per mesh in
//!   object space and a top level over their world (swept) bounds. Rays
//!   are moved into an instance's object space at their time; ray
//!   parameters are preserved by the affine map, so hits of different
//!   instances, and of the world tree, compare directly.
//!
//! Among equally distant hits the smallest instance index wins, then the
//! smallest triangle index: the world tree holds the merged instances'
//! triangles in instance order, and its own tie rule (the smallest
//! triangle index) is then this rule, so the result depends on nothing but
//! the scene.

pub mod top_level;

use glam::{Affine3A, Mat3};
use sahara_kd::{
    Aabb, AccelParams, Counters, Hit, Isa, NoCounters, Ray, Triangle, TriangleAccel, PACKET16,
};

use crate::scene::instance::{Instance, Placement};
use crate::scene::mesh::SceneMesh;
use top_level::InstanceList;

/// Most instances whose trees [`Accel::closest_packet`] traces a packet
/// through one after another, without the top level.
const PACKET_INSTANCES: usize = 8;

/// The buffers of [`Accel::closest_batch`] and [`Accel::occluded_batch`],
/// kept from one call to the next.
#[derive(Debug, Default)]
pub struct BatchBuffers {
    rays: Vec<Ray>,
    hits: Vec<Option<Hit>>,
    blocked: Vec<bool>,
    index: Vec<u32>,
}

/// A hit before shading: which instance and triangle, where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawHit {
    /// World ray parameter.
    pub t: f32,
    /// Instance index.
    pub instance: u32,
    /// Triangle index in the instance's mesh.
    pub tri: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the third vertex.
    pub v: f32,
}

impl RawHit {
    /// Tree hit `h` as a hit of instance `instance` (its triangle index
    /// counted in the tree the hit came from).
    #[inline]
    pub(crate) fn of(h: &Hit, instance: u32) -> Self {
        Self {
            t: h.t,
            instance,
            tri: h.tri,
            u: h.u,
            v: h.v,
        }
    }
}

/// How a scene's geometry was organised: how many trees were built for
/// how many instances, and how many of those went into the world tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AccelLayout {
    /// Trees built: the world tree (if any instance was merged) and one
    /// per mesh of the two-level instances.
    pub trees: usize,
    /// Instances in all.
    pub instances: usize,
    /// Instances merged into the world tree.
    pub merged: usize,
}

impl std::fmt::Display for AccelLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = |n: usize| if n == 1 { "" } else { "s" };
        write!(
            f,
            "{} tree{}, {} instance{} ({} in the world tree)",
            self.trees,
            s(self.trees),
            self.instances,
            s(self.instances),
            self.merged
        )
    }
}

/// An instance as traversal sees it.
#[derive(Clone, Copy, Debug)]
struct Placed {
    /// Its mesh's object-space tree (an index into `Accel::trees`), or
    /// [`MERGED`] when its triangles are in the world tree.
    tree: u32,
    placement: Placement,
    /// World-to-object map of a static instance (None when moving).
    to_object: Option<Affine3A>,
    /// The normals' object-to-world map of a static instance (the
    /// inverse transpose of its linear part), kept because every hit's
    /// shading needs it (None when moving).
    normals: Option<Mat3>,
}

/// [`Placed::tree`] of an instance merged into the world tree.
const MERGED: u32 = u32::MAX;

/// How far past the closest hit so far, at `t`, a two-level instance is
/// still traced: a little farther. A hit exactly as far can still win
/// (a lower instance index wins ties), but where it lies on the face of
/// its instance's box (a box, a quad in a wall) the box test's entry
/// distance, rounded differently from the triangle test's `t`, may
/// exceed `t` by an ulp or two and cull it; which instances were traced
/// would then decide the tie. Hits found beyond `t` lose to the one at
/// `t` ([`Accel::replaces`]), so this changes no answer, only makes
/// every path find the same one.
#[inline]
fn reach(t: f32) -> f32 {
    t + t.abs() * (64.0 * f32::EPSILON)
}

/// The scene's acceleration structure.
#[derive(Debug)]
pub struct Accel {
    /// The merged instances' triangles in world space (None when there
    /// are none).
    world: Option<TriangleAccel>,
    /// The merged instances, in increasing index order.
    merged: Vec<u32>,
    /// The world tree's index of each merged instance's first triangle.
    /// A hit's instance is found by binary search here: a table of one
    /// instance per world triangle would cost 4 bytes a triangle and a
    /// cache miss a hit, where these few offsets stay in cache; either is
    /// noise beside the walk.
    merged_first: Vec<u32>,
    /// One object-space tree per mesh of the instances that are not
    /// merged.
    trees: Vec<TriangleAccel>,
    /// Every instance.
    placed: Vec<Placed>,
    /// The instances that are not merged, in increasing index order; the
    /// top level's entry `k` is instance `apart[k]`.
    apart: Vec<u32>,
    top: InstanceList,
    bounds: Aabb,
}

/// Thickness, relative to its largest extent, at or below which an
/// instance is flat.
const FLAT: f32 = 1e-3;

/// How much larger than the rest a flat instance must be to stay out of
/// the world tree.
const GROUND_DWARFS: f32 = 4.0;

/// Which of the instances that could be merged (`candidate`) are grounds,
/// kept out of the world tree: flat ones (a ground plane, a sea) whose
/// largest extent is at least [`GROUND_DWARFS`] times the diagonal of the
/// other candidates that are not flat. Merged, such a plane's two
/// triangles span the world tree's whole root cell, and the tree over the
/// plane and the detailed model standing on it walked slower than the
/// model's tree and the plane apart: a rough gold dragon on a 4 m plane
/// (`dragon_glossy`) spent 1.5x the time in the kd-tree walks, and the
/// render 1.3-1.4x the CPU time, with the plane merged (the same rays, the
/// same image; docs/performance.md).
fn grounds(
    meshes: &[SceneMesh],
    instances: &[Instance],
    candidate: &dyn Fn(usize, &Instance) -> bool,
) -> Vec<bool> {
    let bounds: Vec<Option<Aabb>> = instances
        .iter()
        .enumerate()
        .map(|(i, inst)| {
            let Placement::Static(_) = inst.placement else {
                return None;
            };
            if !candidate(i, inst) {
                return None;
            }
            let object = meshes[inst.mesh as usize]
                .mesh
                .triangles()
                .iter()
                .filter(|t| t.is_hittable())
                .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
            let b = inst.placement.world_bounds(object);
            (!b.is_empty() && b.min.is_finite() && b.max.is_finite()).then_some(b)
        })
        .collect();
    let is_flat = |b: &Aabb| {
        let e = b.max - b.min;
        e.min_element() <= FLAT * e.max_element()
    };
    let subject = bounds
        .iter()
        .flatten()
        .filter(|b| !is_flat(b))
        .fold(Aabb::EMPTY, |a, b| a.union(*b));
    let diagonal = (subject.max - subject.min).length();
    bounds
        .iter()
        .map(|b| {
            b.is_some_and(|b| {
                !subject.is_empty()
                    && diagonal.is_finite()
                    && is_flat(&b)
                    && (b.max - b.min).max_element() >= GROUND_DWARFS * diagonal
            })
        })
        .collect()
}

impl Accel {
    /// Builds the world tree over the merged instances, one object-space
    /// tree per mesh of the others (instances share them) and the top
    /// level over those others.
    ///
    /// An instance is merged when it is static, its mesh is used by no
    /// other instance, it is not in `ignorable` (the instances that an
    /// occlusion query may name as the one to ignore, [`Accel::occluded`]),
    /// and it is not a ground ([`grounds`]). The ignorable ones keep their
    /// own tree because the world tree cannot skip one instance's
    /// triangles inside its walk (see [`Accel::occluded`]).
    pub fn build(
        meshes: &[SceneMesh],
        instances: &[Instance],
        params: &AccelParams,
        ignorable: &[u32],
    ) -> Self {
        let mut uses = vec![0u32; meshes.len()];
        for inst in instances {
            uses[inst.mesh as usize] += 1;
        }
        let mut must_stay = vec![false; instances.len()];
        for &i in ignorable {
            if let Some(k) = must_stay.get_mut(i as usize) {
                *k = true;
            }
        }
        let candidate = |i: usize, inst: &Instance| {
            !must_stay[i] && uses[inst.mesh as usize] == 1 && !inst.placement.is_moving()
        };
        let ground = grounds(meshes, instances, &candidate);
        let merges = |i: usize, inst: &Instance| candidate(i, inst) && !ground[i];

        // The world tree: the merged instances' triangles in instance order
        // (the tie rule needs it), each with its vertices in mesh order (so
        // the barycentrics weigh the same corners as in object space).
        let mut world_tris = Vec::new();
        let mut merged = Vec::new();
        let mut merged_first = Vec::new();
        let mut boxes = Vec::with_capacity(instances.len());
        for (i, inst) in instances.iter().enumerate() {
            let Placement::Static(xf) = inst.placement else {
                continue;
            };
            if !merges(i, inst) {
                continue;
            }
            let first = u32::try_from(world_tris.len())
                .expect("more than 2^32 triangles in the merged instances");
            merged.push(i as u32);
            merged_first.push(first);
            let tris = meshes[inst.mesh as usize].mesh.triangles();
            // The instance's bounds as a tree of its own mesh would give
            // them (the hittable triangles' box in object space, then
            // transformed), so that the scene's bounds, and with them the
            // lights' powers, do not depend on the layout.
            let object = tris
                .iter()
                .filter(|t| t.is_hittable())
                .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
            boxes.push((i, inst.placement.world_bounds(object)));
            world_tris.extend(tris.iter().map(|t| {
                Triangle::new(
                    xf.transform_point3(t.v[0]),
                    xf.transform_point3(t.v[1]),
                    xf.transform_point3(t.v[2]),
                )
            }));
        }
        let world = (!world_tris.is_empty()).then(|| TriangleAccel::build(world_tris, params));

        // The two-level rest: one tree per mesh used, in mesh order.
        let mut tree_of = vec![MERGED; meshes.len()];
        let mut trees = Vec::new();
        let mut apart = Vec::new();
        for (i, inst) in instances.iter().enumerate() {
            if merges(i, inst) {
                continue;
            }
            apart.push(i as u32);
            let m = inst.mesh as usize;
            if tree_of[m] == MERGED {
                tree_of[m] = trees.len() as u32;
                trees.push(TriangleAccel::build(meshes[m].mesh.triangles(), params));
            }
        }
        let placed: Vec<Placed> = instances
            .iter()
            .enumerate()
            .map(|(i, inst)| Placed {
                tree: if merges(i, inst) {
                    MERGED
                } else {
                    tree_of[inst.mesh as usize]
                },
                placement: inst.placement,
                to_object: match inst.placement {
                    Placement::Static(a) => Some(a.inverse()),
                    Placement::Moving { .. } => None,
                },
                normals: match inst.placement {
                    Placement::Static(a) => Some(normal_map(&a)),
                    Placement::Moving { .. } => None,
                },
            })
            .collect();
        let apart_boxes: Vec<Aabb> = apart
            .iter()
            .map(|&i| {
                let p = &placed[i as usize];
                p.placement.world_bounds(trees[p.tree as usize].bounds())
            })
            .collect();
        let bounds = boxes
            .iter()
            .map(|(_, b)| *b)
            .chain(apart_boxes.iter().copied())
            .fold(Aabb::EMPTY, |a, b| a.union(b));
        Self {
            world,
            merged,
            merged_first,
            trees,
            placed,
            apart,
            top: InstanceList::build(&apart_boxes),
            bounds,
        }
    }

    /// Hold every tree's queries to the instructions of `isa` at most
    /// (answers do not change; see [`Isa`]).
    pub fn set_isa(&mut self, isa: Isa) {
        for t in self.world.iter_mut().chain(&mut self.trees) {
            t.set_isa(isa);
        }
    }

    /// Number of trees: the world tree (if any instance was merged)
    /// and one per mesh of the other instances, however many instances
    /// share it.
    pub fn tree_count(&self) -> usize {
        usize::from(self.world.is_some()) + self.trees.len()
    }

    /// Number of instances, merged or not.
    pub fn instance_count(&self) -> usize {
        self.placed.len()
    }

    /// Number of instances whose triangles are in the world tree.
    pub fn merged_count(&self) -> usize {
        self.merged.len()
    }

    /// Number of instances traced in two levels (through the top level and
    /// their mesh's object-space tree).
    pub fn two_level_count(&self) -> usize {
        self.apart.len()
    }

    /// The trees and instances built.
    pub fn layout(&self) -> AccelLayout {
        AccelLayout {
            trees: self.tree_count(),
            instances: self.instance_count(),
            merged: self.merged_count(),
        }
    }

    /// Number of triangles in the world tree.
    pub fn world_triangles(&self) -> usize {
        self.world.as_ref().map_or(0, |w| w.primitive_count())
    }

    /// Whether instance `i` is merged into the world tree.
    pub fn is_merged(&self, i: u32) -> bool {
        self.placed[i as usize].tree == MERGED
    }

    /// Bytes held by the trees (nodes, leaf indices, triangles, leaf
    /// blocks).
    pub fn tree_bytes(&self) -> usize {
        self.world
            .iter()
            .chain(&self.trees)
            .map(|t| t.memory_bytes())
            .sum()
    }

    /// World bounds of everything.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The object-space ray of instance `p` at shutter fraction `s`.
    #[inline]
    fn object_ray(p: &Placed, ray: &Ray, s: f32, tmax: f32) -> Ray {
        let inv = match p.to_object {
            Some(a) => a,
            None => p.placement.at(s).inverse(),
        };
        Ray::with_interval(
            inv.transform_point3(ray.origin),
            inv.transform_vector3(ray.dir),
            ray.tmin,
            tmax,
        )
    }

    /// The hit of a world-tree hit: its instance and the triangle's index
    /// in that instance's mesh.
    #[inline]
    fn merged_hit(&self, h: &Hit) -> RawHit {
        // The last merged instance starting at or before the triangle
        // (an instance without triangles starts where the next one does).
        let k = self.merged_first.partition_point(|&f| f <= h.tri) - 1;
        RawHit {
            tri: h.tri - self.merged_first[k],
            ..RawHit::of(h, self.merged[k])
        }
    }

    /// Whether hit `h` of instance `i` takes the place of `best`: it is
    /// closer, or as close and of a lower instance index.
    #[inline]
    fn replaces(best: Option<RawHit>, h: &Hit, i: u32) -> bool {
        !best.is_some_and(|b| b.t < h.t || (b.t == h.t && b.instance <= i))
    }

    /// The closest hit along `ray` at shutter fraction `s`, counting the
    /// work (top-level box tests count as inner-node visits).
    pub fn closest<C: Counters>(&self, ray: &Ray, s: f32, counters: &mut C) -> Option<RawHit> {
        let best = self
            .world
            .as_ref()
            .and_then(|w| w.closest_hit_counted(ray, counters))
            .map(|h| self.merged_hit(&h));
        self.closest_apart(ray, s, best, counters)
    }

    /// The closest of `best` (a hit in the world tree) and the hits of the
    /// two-level instances along `ray` at `s`, through the top level.
    #[inline]
    fn closest_apart<C: Counters>(
        &self,
        ray: &Ray,
        s: f32,
        mut best: Option<RawHit>,
        counters: &mut C,
    ) -> Option<RawHit> {
        if self.apart.is_empty() {
            return best;
        }
        // Hits as far as the world tree's still count: a lower instance
        // index wins them.
        let ray = match best {
            Some(b) => Ray::with_interval(ray.origin, ray.dir, ray.tmin, reach(b.t)),
            None => *ray,
        };
        self.top.closest(&ray, counters, |k, tmax, counters| {
            let i = self.apart[k as usize];
            let p = &self.placed[i as usize];
            let r = Self::object_ray(p, &ray, s, tmax);
            let h = self.trees[p.tree as usize].closest_hit_counted(&r, counters)?;
            // Ties between instances go to the lower index, whatever order
            // the top level offers them in (an instance spanning several
            // cells may also be offered again).
            if !Self::replaces(best, &h, i) {
                return None;
            }
            best = Some(RawHit::of(&h, i));
            Some(reach(h.t))
        });
        best
    }

    /// Closest hits of up to [`PACKET16`] rays, `rays[i]` at shutter
    /// fraction `s[i]`, exactly as [`Accel::closest`] finds them: the
    /// world tree traces the rays as one packet (see
    /// [`TriangleAccel::closest_hit_packet16`]); then a scene of a few two-level
    /// instances traces the packet through each instance's tree in turn,
    /// each ray's interval cut at its closest hit so far, and a scene of
    /// more, ray by ray through the top level.
    pub fn closest_packet(&self, rays: &[Ray], s: &[f32], out: &mut [Option<RawHit>]) {
        let n = rays.len();
        assert!(n <= PACKET16 && s.len() == n && out.len() == n);
        let mut hits: [Option<Hit>; PACKET16] = [None; PACKET16];
        match &self.world {
            Some(w) => {
                w.closest_hit_packet16(rays, &mut hits[..n]);
                for (o, h) in out.iter_mut().zip(&hits) {
                    *o = h.as_ref().map(|h| self.merged_hit(h));
                }
            }
            None => out.fill(None),
        }
        if self.apart.len() > PACKET_INSTANCES {
            for ((r, &s), o) in rays.iter().zip(s).zip(out.iter_mut()) {
                *o = self.closest_apart(r, s, *o, &mut NoCounters);
            }
            return;
        }
        let mut obj = [Ray::new(glam::Vec3::ZERO, glam::Vec3::X); PACKET16];
        for &i in &self.apart {
            let p = &self.placed[i as usize];
            for k in 0..n {
                let tmax = out[k].map_or(rays[k].tmax, |b| reach(b.t));
                obj[k] = Self::object_ray(p, &rays[k], s[k], tmax);
            }
            self.trees[p.tree as usize].closest_hit_packet16(&obj[..n], &mut hits[..n]);
            for k in 0..n {
                let Some(h) = hits[k] else { continue };
                // The tie rule of `closest`: the lower instance index wins.
                if !Self::replaces(out[k], &h, i) {
                    continue;
                }
                out[k] = Some(RawHit::of(&h, i));
            }
        }
    }

    /// Closest hits of many rays, `rays[i]` at shutter fraction `s[i]`,
    /// exactly as [`Accel::closest`] finds them: the world tree traces all
    /// the rays as one batch ([`TriangleAccel::closest_hits_serial`], which walks
    /// incoherent rays interleaved over the wide nodes); then a scene of a
    /// few two-level instances traces them through each instance's tree
    /// in turn as one batch, each ray's interval cut at its closest hit so
    /// far, and a scene of more, ray by ray through the top level. `buf`
    /// holds the object-space rays between calls.
    pub fn closest_batch(
        &self,
        rays: &[Ray],
        s: &[f32],
        out: &mut [Option<RawHit>],
        buf: &mut BatchBuffers,
    ) {
        let n = rays.len();
        assert!(s.len() == n && out.len() == n);
        buf.hits.clear();
        buf.hits.resize(n, None);
        match &self.world {
            Some(w) => {
                w.closest_hits_serial(rays, &mut buf.hits);
                for (o, h) in out.iter_mut().zip(&buf.hits) {
                    *o = h.as_ref().map(|h| self.merged_hit(h));
                }
            }
            None => out.fill(None),
        }
        if self.apart.len() > PACKET_INSTANCES {
            for ((r, &s), o) in rays.iter().zip(s).zip(out.iter_mut()) {
                *o = self.closest_apart(r, s, *o, &mut NoCounters);
            }
            return;
        }
        for &i in &self.apart {
            let p = &self.placed[i as usize];
            buf.rays.clear();
            for k in 0..n {
                let tmax = out[k].map_or(rays[k].tmax, |b| reach(b.t));
                buf.rays.push(Self::object_ray(p, &rays[k], s[k], tmax));
            }
            self.trees[p.tree as usize].closest_hits_serial(&buf.rays, &mut buf.hits);
            for (o, h) in out.iter_mut().zip(&buf.hits) {
                let Some(h) = *h else { continue };
                // The tie rule of `closest`: the lower instance index wins.
                if !Self::replaces(*o, &h, i) {
                    continue;
                }
                *o = Some(RawHit::of(&h, i));
            }
        }
    }

    /// [`Accel::occluded`] of many rays, `rays[i]` at shutter fraction
    /// `s[i]` ignoring instance `ignore[i]`, into `out[i]`: through the
    /// world tree as one batch, then the rays not yet blocked through each
    /// two-level instance's tree in turn as one batch, or ray by ray
    /// through the top level (see [`Accel::closest_batch`]).
    pub fn occluded_batch(
        &self,
        rays: &[Ray],
        s: &[f32],
        ignore: &[Option<u32>],
        out: &mut [bool],
        buf: &mut BatchBuffers,
    ) {
        let n = rays.len();
        assert!(s.len() == n && ignore.len() == n && out.len() == n);
        debug_assert!(ignore.iter().flatten().all(|&i| !self.is_merged(i)));
        match &self.world {
            Some(w) => w.any_hits_serial(rays, out),
            None => out.fill(false),
        }
        if self.apart.len() > PACKET_INSTANCES {
            for (k, o) in out.iter_mut().enumerate() {
                *o = *o || self.occluded_apart(&rays[k], s[k], ignore[k]);
            }
            return;
        }
        for &i in &self.apart {
            let p = &self.placed[i as usize];
            buf.rays.clear();
            buf.index.clear();
            for k in 0..n {
                if !out[k] && ignore[k] != Some(i) {
                    buf.index.push(k as u32);
                    buf.rays
                        .push(Self::object_ray(p, &rays[k], s[k], rays[k].tmax));
                }
            }
            buf.blocked.clear();
            buf.blocked.resize(buf.rays.len(), false);
            self.trees[p.tree as usize].any_hits_serial(&buf.rays, &mut buf.blocked);
            for (&k, &b) in buf.index.iter().zip(&buf.blocked) {
                out[k as usize] |= b;
            }
        }
    }

    /// True if anything but instance `ignore` lies along `ray` within its
    /// interval.
    ///
    /// `ignore` must be one of the instances [`Accel::build`] was told are
    /// ignorable (checked in debug builds): it names the emitter a shadow
    /// ray aims at, whose tessellation may lie across the exact surface
    /// the light sampled (a point sampled on a sphere is outside its
    /// inscribed polyhedron; from inside, the polyhedron lies before it),
    /// so the segment's end cannot simply be trimmed by a fixed fraction.
    /// Such instances keep their own tree and are skipped here; a filter
    /// inside the world tree's walk would cost every other query.
    pub fn occluded(&self, ray: &Ray, s: f32, ignore: Option<u32>) -> bool {
        debug_assert!(ignore.is_none_or(|i| !self.is_merged(i)));
        self.world.as_ref().is_some_and(|w| w.any_hit(ray)) || self.occluded_apart(ray, s, ignore)
    }

    /// [`Accel::occluded`] among the two-level instances.
    #[inline]
    fn occluded_apart(&self, ray: &Ray, s: f32, ignore: Option<u32>) -> bool {
        !self.apart.is_empty()
            && self.top.any(ray, |k| {
                let i = self.apart[k as usize];
                if Some(i) == ignore {
                    return false;
                }
                let p = &self.placed[i as usize];
                let r = Self::object_ray(p, ray, s, ray.tmax);
                self.trees[p.tree as usize].any_hit(&r)
            })
    }

    /// Object-to-world transform of instance `i` at shutter fraction `s`.
    pub fn transform(&self, i: u32, s: f32) -> Affine3A {
        self.placed[i as usize].placement.at(s)
    }

    /// The map of instance `i`'s normals to world space when its
    /// transform is `xf` ([`Accel::transform`] at the same time): the
    /// inverse transpose of `xf`'s linear part.
    #[inline]
    pub fn normal_transform(&self, i: u32, xf: &Affine3A) -> Mat3 {
        self.placed[i as usize]
            .normals
            .unwrap_or_else(|| normal_map(xf))
    }
}

/// The inverse transpose of `xf`'s linear part, which maps normals.
#[inline]
fn normal_map(xf: &Affine3A) -> Mat3 {
    Mat3::from(xf.matrix3).inverse().transpose()
}

#[cfg(test)]
mod tests;
