//! Packets: eight coherent rays (e.g. a 4x2 pixel tile of camera rays)
//! traced down the tree together.
//!
//! Wald's coherent kd-tree traversal (Wald 2004, "Realtime Ray Tracing and
//! Interactive Global Illumination", PhD thesis): rays whose directions
//! share their signs meet the two children of every node in the same order,
//! so the packet walks one path, fetching each node once for all its rays.
//! Each ray keeps its own parametric interval; a child is entered when at
//! least one ray's interval reaches it, and rays that do not are masked off
//! there. The per-ray interval arithmetic is the single-ray traversal's,
//! eight lanes at a time (plain loops over `[f32; 8]` that compile to SIMD,
//! with an AVX2 build chosen at run time), and so is the leaf test, ray by
//! ray: results are bit-identical to [`KdTree::closest_hit`].
//!
//! A packet whose rays' direction signs differ is traced ray by ray.

use glam::Vec3;

use crate::geometry::triangle::RayShear;
use crate::geometry::{Ray, Triangle};
use crate::traverse::{Hit, NoCounters, MARGIN, MAX_DEPTH};
use crate::tree::KdTree;

/// Rays per packet.
pub const PACKET: usize = 8;

type Lanes = [f32; PACKET];

/// A far child and the rays' intervals in it (`t0 > t1`: ray masked off).
#[derive(Clone, Copy)]
struct Entry {
    node: u32,
    t0: Lanes,
    t1: Lanes,
}

/// The empty interval that masks a lane off.
const OFF: (f32, f32) = (f32::INFINITY, f32::NEG_INFINITY);

impl KdTree<Triangle> {
    /// Closest hits of up to [`PACKET`] rays traced as one packet; `out[i]`
    /// answers `rays[i]` exactly as [`KdTree::closest_hit`] would.
    ///
    /// # Panics
    /// If there are more than [`PACKET`] rays or `out` differs in length.
    pub fn closest_hit_packet(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        #[cfg(target_arch = "x86_64")]
        if crate::traverse::simd::avx2() {
            // SAFETY: the CPU has AVX2 (checked at run time).
            return unsafe { self.packet_avx2(rays, out) };
        }
        self.packet_portable(rays, out)
    }

    /// Closest hits of many rays in packets of [`PACKET`] consecutive rays
    /// (order them so that neighbours are coherent, e.g. 4x2 pixel tiles).
    pub fn closest_hits_packets(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            self.closest_hit_packet(r, o);
        }
    }

    /// [`KdTree::packet_portable`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn packet_avx2(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.packet_portable(rays, out)
    }

    /// The packet traversal (inlined into each target-feature variant).
    #[inline(always)]
    fn packet_portable(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        let n = rays.len();
        if n == 0 {
            return;
        }
        let signs = |r: &Ray| {
            [
                r.dir.x.is_sign_negative(),
                r.dir.y.is_sign_negative(),
                r.dir.z.is_sign_negative(),
            ]
        };
        let neg = signs(&rays[0]);
        if self.nodes.is_empty() || rays.iter().any(|r| signs(r) != neg) {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = self.closest_hit(r);
            }
            return;
        }

        // Per-lane ray data; lanes past `n`, invalid rays and rays missing
        // the root cell start masked off.
        let mut org = [[0.0f32; PACKET]; 3];
        let mut inv = [[0.0f32; PACKET]; 3];
        let (mut t0, mut t1) = ([OFF.0; PACKET], [OFF.1; PACKET]);
        let mut shear = [RayShear::new(Vec3::ZERO, Vec3::Z); PACKET];
        let mut best_t = [0.0f32; PACKET];
        let none = Hit {
            t: f32::INFINITY,
            tri: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut best = [none; PACKET];
        // Closest hit so far per lane, infinity while there is none: cells
        // entered beyond it are skipped, as in `walk`.
        let mut closest = [f32::INFINITY; PACKET];
        for (l, r) in rays.iter().enumerate() {
            best_t[l] = r.tmax;
            if !r.is_valid() || r.tmin > r.tmax {
                continue;
            }
            let inv_dir = Vec3::ONE / r.dir;
            if let Some((a, b)) = self.bounds.intersect_ray(r.origin, inv_dir, r.tmin, r.tmax) {
                (t0[l], t1[l]) = (a, b);
                for k in 0..3 {
                    org[k][l] = r.origin[k];
                    inv[k][l] = inv_dir[k];
                }
                shear[l] = RayShear::from_ray(r);
            }
        }

        let mut stack = [const { std::mem::MaybeUninit::<Entry>::uninit() }; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node = 0u32;
        let mut live = (0..PACKET).any(|l| t0[l] <= t1[l]);
        while live {
            debug_assert!((node as usize) < self.nodes.len());
            // SAFETY: node indices come from the builder (see `walk`).
            let nd = unsafe { *self.nodes.get_unchecked(node as usize) };
            if !nd.is_leaf() {
                let axis = nd.axis();
                let split = nd.split();
                let below = node + 1;
                let above = nd.above_child();
                let (near, far) = if neg[axis] {
                    (above, below)
                } else {
                    (below, above)
                };
                // Each lane decides as `walk` does (same expressions, so the
                // same rounding): near only, far only, or both with the
                // interval cut at the plane.
                let (o, iv) = (&org[axis], &inv[axis]);
                let (mut n0, mut n1) = ([0.0f32; PACKET], [0.0f32; PACKET]);
                let (mut f0, mut f1) = ([0.0f32; PACKET], [0.0f32; PACKET]);
                let (mut any_near, mut any_far) = (false, false);
                for l in 0..PACKET {
                    let active = t0[l] <= t1[l];
                    let tp = (split - o[l]) * iv[l];
                    let near_only = tp > t1[l] + t1[l].abs() * MARGIN;
                    let far_only = !near_only && tp < t0[l] - t0[l].abs() * MARGIN;
                    let to_near = active && !far_only;
                    let to_far = active && !near_only;
                    (n0[l], n1[l]) = if !to_near {
                        OFF
                    } else if near_only {
                        (t0[l], t1[l])
                    } else {
                        (t0[l], tp.min(t1[l]).max(t0[l]))
                    };
                    (f0[l], f1[l]) = if !to_far {
                        OFF
                    } else if far_only {
                        (t0[l], t1[l])
                    } else {
                        (tp.max(t0[l]).min(t1[l]), t1[l])
                    };
                    any_near |= to_near;
                    any_far |= to_far;
                }
                if any_near {
                    if any_far {
                        debug_assert!(sp < MAX_DEPTH, "tree deeper than the traversal stack");
                        stack[sp] = std::mem::MaybeUninit::new(Entry {
                            node: far,
                            t0: f0,
                            t1: f1,
                        });
                        sp += 1;
                    }
                    (node, t0, t1) = (near, n0, n1);
                } else {
                    (node, t0, t1) = (far, f0, f1);
                }
                continue;
            }
            let count = nd.leaf_count() as usize;
            if count != 0 {
                let offset = nd.leaf_offset() as usize;
                for l in 0..PACKET {
                    if t0[l] <= t1[l] {
                        // SAFETY: `offset`, `count` are those of a leaf.
                        unsafe {
                            self.leaf_closest(
                                &shear[l],
                                rays[l].tmin,
                                offset,
                                count,
                                &mut best_t[l],
                                &mut best[l],
                                &mut NoCounters,
                            )
                        };
                        if best[l].tri != u32::MAX {
                            closest[l] = best_t[l];
                        }
                    }
                }
            }
            // Pop the next cell some ray may still find a closer hit in.
            live = false;
            while sp > 0 {
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push above.
                let e = unsafe { stack[sp].assume_init() };
                for l in 0..PACKET {
                    let keep = e.t0[l] <= e.t1[l] && e.t0[l] <= closest[l] * (1.0 + MARGIN);
                    (t0[l], t1[l]) = if keep { (e.t0[l], e.t1[l]) } else { OFF };
                    live |= keep;
                }
                if live {
                    node = e.node;
                    break;
                }
            }
        }
        for (l, o) in out.iter_mut().enumerate() {
            *o = (best[l].tri != u32::MAX).then_some(best[l]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::build::{BuildParams, Builder};
    use crate::test_support::{floats, soup};

    /// Camera-like packets (a common origin, nearby directions), packets
    /// with mixed direction signs, short ones and invalid rays: every
    /// answer equals brute force, bit for bit, in both builds.
    #[test]
    fn packets_agree_with_brute_force() {
        let mut f = floats(2024);
        let tris = soup(&mut f, 2000, 0.5);
        for builder in [Builder::Sah, Builder::Binned { bins: 16 }] {
            let tree = KdTree::build(tris.clone(), &BuildParams::new(builder));
            for p in 0..400 {
                let eye = Vec3::new(f(), f(), -6.0);
                let spread = if p % 4 == 0 { 1.0 } else { 0.05 };
                let aim = Vec3::new(f(), f(), 1.0);
                let n = if p % 7 == 0 { 1 + p % PACKET } else { PACKET };
                let mut rays: Vec<Ray> = (0..n)
                    .map(|_| Ray::new(eye, aim + Vec3::new(f(), f(), f()) * spread))
                    .collect();
                if p % 11 == 0 {
                    rays[0] = Ray::new(eye, Vec3::ZERO); // invalid: never hits
                }
                if p % 13 == 0 {
                    rays[n - 1].tmax = 6.0; // a shorter segment
                }
                let want: Vec<_> = rays.iter().map(|r| brute::closest_hit(&tris, r)).collect();
                let mut got = vec![None; n];
                tree.closest_hit_packet(&rays, &mut got);
                assert_eq!(got, want, "packet {p}");
                got.fill(None);
                tree.packet_portable(&rays, &mut got);
                assert_eq!(got, want, "packet {p} (portable)");
            }
        }
    }

    #[test]
    fn batches_answer_every_ray() {
        let mut f = floats(5);
        let tris = soup(&mut f, 500, 0.5);
        let tree = KdTree::build(tris.clone(), &BuildParams::default());
        let rays: Vec<Ray> = (0..1003)
            .map(|_| {
                Ray::new(
                    Vec3::new(0.0, 0.0, -6.0),
                    Vec3::new(f() * 0.6, f() * 0.6, 1.0),
                )
            })
            .collect();
        let mut out = vec![None; rays.len()];
        tree.closest_hits_packets(&rays, &mut out);
        let hits = out.iter().filter(|h| h.is_some()).count();
        assert!(hits > 100, "{hits}");
        for (r, o) in rays.iter().zip(&out) {
            assert_eq!(*o, tree.closest_hit(r));
        }
    }
}
