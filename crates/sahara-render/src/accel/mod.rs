//! Two-level acceleration: one kd-tree per distinct mesh, in object space,
//! and a top level over the instances' world (swept) bounds. Rays are
//! moved into an instance's object space at their time; ray parameters are
//! preserved by the affine map, so hits of different instances compare
//! directly.

pub mod top_level;

use glam::Affine3A;
use sahara_kd::{Aabb, BuildParams, Counters, Hit, KdTree, NoCounters, Ray, PACKET16};

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

/// An instance ready for traversal.
#[derive(Clone, Copy, Debug)]
struct Placed {
    mesh: u32,
    placement: Placement,
    /// World-to-object map of a static instance (None when moving).
    to_object: Option<Affine3A>,
}

/// The scene's acceleration structure.
#[derive(Debug)]
pub struct Accel {
    trees: Vec<KdTree>,
    placed: Vec<Placed>,
    top: InstanceList,
    bounds: Aabb,
}

impl Accel {
    /// Builds one tree per mesh (instances share them) and the top level.
    pub fn build(meshes: &[SceneMesh], instances: &[Instance], params: &BuildParams) -> Self {
        let trees: Vec<KdTree> = meshes
            .iter()
            .map(|m| KdTree::build(m.mesh.triangles(), params))
            .collect();
        let placed: Vec<Placed> = instances
            .iter()
            .map(|inst| Placed {
                mesh: inst.mesh,
                placement: inst.placement,
                to_object: match inst.placement {
                    Placement::Static(a) => Some(a.inverse()),
                    Placement::Moving { .. } => None,
                },
            })
            .collect();
        let boxes: Vec<Aabb> = placed
            .iter()
            .map(|p| p.placement.world_bounds(trees[p.mesh as usize].bounds()))
            .collect();
        let bounds = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        Self {
            trees,
            placed,
            top: InstanceList::build(&boxes),
            bounds,
        }
    }

    /// Number of kd-trees (one per distinct mesh, however many instances).
    pub fn tree_count(&self) -> usize {
        self.trees.len()
    }

    /// Number of instances.
    pub fn instance_count(&self) -> usize {
        self.placed.len()
    }

    /// Bytes held by the kd-trees (nodes, leaf indices, triangles, leaf
    /// blocks).
    pub fn tree_bytes(&self) -> usize {
        self.trees.iter().map(|t| t.stats().memory_bytes).sum()
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

    /// The closest hit along `ray` at shutter fraction `s`, counting the
    /// work (top-level box tests count as inner-node visits).
    pub fn closest<C: Counters>(&self, ray: &Ray, s: f32, counters: &mut C) -> Option<RawHit> {
        let mut best: Option<RawHit> = None;
        self.top.closest(ray, counters, |i, tmax, counters| {
            let p = &self.placed[i as usize];
            let r = Self::object_ray(p, ray, s, tmax);
            let h = self.trees[p.mesh as usize].closest_hit_counted(&r, counters)?;
            // Ties between instances go to the lower index, whatever order
            // the top level offers them in (an instance spanning several
            // cells may also be offered again).
            if best.is_some_and(|b| b.t < h.t || (b.t == h.t && b.instance <= i)) {
                return None;
            }
            best = Some(RawHit {
                t: h.t,
                instance: i,
                tri: h.tri,
                u: h.u,
                v: h.v,
            });
            Some(h.t)
        });
        best
    }

    /// Closest hits of up to [`PACKET16`] rays, `rays[i]` at shutter
    /// fraction `s[i]`, exactly as [`Accel::closest`] finds them: a scene
    /// of a few instances traces the rays as one packet through each
    /// instance's tree in turn (see [`KdTree::closest_hit_packet16`]),
    /// each ray's interval cut at its closest hit so far; a scene of more
    /// instances, ray by ray through the top level.
    pub fn closest_packet(&self, rays: &[Ray], s: &[f32], out: &mut [Option<RawHit>]) {
        let n = rays.len();
        assert!(n <= PACKET16 && s.len() == n && out.len() == n);
        if self.placed.len() > PACKET_INSTANCES {
            for ((r, &s), o) in rays.iter().zip(s).zip(out.iter_mut()) {
                *o = self.closest(r, s, &mut NoCounters);
            }
            return;
        }
        out.fill(None);
        let mut obj = [Ray::new(glam::Vec3::ZERO, glam::Vec3::X); PACKET16];
        let mut hits: [Option<Hit>; PACKET16] = [None; PACKET16];
        for (i, p) in self.placed.iter().enumerate() {
            let i = i as u32;
            for k in 0..n {
                let tmax = out[k].map_or(rays[k].tmax, |b| b.t);
                obj[k] = Self::object_ray(p, &rays[k], s[k], tmax);
            }
            self.trees[p.mesh as usize].closest_hit_packet16(&obj[..n], &mut hits[..n]);
            for k in 0..n {
                let Some(h) = hits[k] else { continue };
                // The tie rule of `closest`: the lower instance index wins.
                if out[k].is_some_and(|b| b.t < h.t || (b.t == h.t && b.instance <= i)) {
                    continue;
                }
                out[k] = Some(RawHit {
                    t: h.t,
                    instance: i,
                    tri: h.tri,
                    u: h.u,
                    v: h.v,
                });
            }
        }
    }

    /// Closest hits of many rays, `rays[i]` at shutter fraction `s[i]`,
    /// exactly as [`Accel::closest`] finds them: a scene of a few instances
    /// traces all the rays through each instance's tree in turn as one
    /// batch ([`KdTree::closest_hits_serial`], which walks incoherent rays
    /// interleaved over the wide nodes), each ray's interval cut at its
    /// closest hit so far; a scene of more instances, ray by ray through
    /// the top level. `buf` holds the object-space rays between calls.
    pub fn closest_batch(
        &self,
        rays: &[Ray],
        s: &[f32],
        out: &mut [Option<RawHit>],
        buf: &mut BatchBuffers,
    ) {
        let n = rays.len();
        assert!(s.len() == n && out.len() == n);
        if self.placed.len() > PACKET_INSTANCES {
            for ((r, &s), o) in rays.iter().zip(s).zip(out.iter_mut()) {
                *o = self.closest(r, s, &mut NoCounters);
            }
            return;
        }
        out.fill(None);
        for (i, p) in self.placed.iter().enumerate() {
            let i = i as u32;
            buf.rays.clear();
            for k in 0..n {
                let tmax = out[k].map_or(rays[k].tmax, |b| b.t);
                buf.rays.push(Self::object_ray(p, &rays[k], s[k], tmax));
            }
            buf.hits.clear();
            buf.hits.resize(n, None);
            self.trees[p.mesh as usize].closest_hits_serial(&buf.rays, &mut buf.hits);
            for (o, h) in out.iter_mut().zip(&buf.hits) {
                let Some(h) = *h else { continue };
                // The tie rule of `closest`: the lower instance index wins.
                if o.is_some_and(|b| b.t < h.t || (b.t == h.t && b.instance <= i)) {
                    continue;
                }
                *o = Some(RawHit {
                    t: h.t,
                    instance: i,
                    tri: h.tri,
                    u: h.u,
                    v: h.v,
                });
            }
        }
    }

    /// [`Accel::occluded`] of many rays, `rays[i]` at shutter fraction
    /// `s[i]` ignoring instance `ignore[i]`, into `out[i]`: through each
    /// instance's tree in turn as one batch of the rays not yet blocked
    /// (see [`Accel::closest_batch`]).
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
        if self.placed.len() > PACKET_INSTANCES {
            for (k, o) in out.iter_mut().enumerate() {
                *o = self.occluded(&rays[k], s[k], ignore[k]);
            }
            return;
        }
        out.fill(false);
        for (i, p) in self.placed.iter().enumerate() {
            let i = i as u32;
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
            self.trees[p.mesh as usize].any_hits_serial(&buf.rays, &mut buf.blocked);
            for (&k, &b) in buf.index.iter().zip(&buf.blocked) {
                out[k as usize] |= b;
            }
        }
    }

    /// True if anything but instance `ignore` lies along `ray` within its
    /// interval.
    pub fn occluded(&self, ray: &Ray, s: f32, ignore: Option<u32>) -> bool {
        self.top.any(ray, |i| {
            if Some(i) == ignore {
                return false;
            }
            let p = &self.placed[i as usize];
            let r = Self::object_ray(p, ray, s, ray.tmax);
            self.trees[p.mesh as usize].any_hit(&r)
        })
    }

    /// Object-to-world transform of instance `i` at shutter fraction `s`.
    pub fn transform(&self, i: u32, s: f32) -> Affine3A {
        self.placed[i as usize].placement.at(s)
    }
}
