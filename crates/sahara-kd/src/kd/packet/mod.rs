//! Packets: eight coherent rays (e.g. a 4x2 pixel tile of camera rays), or
//! sixteen (a 4x4 tile) as two such halves, traced down the tree together.
//!
//! Wald's coherent kd-tree traversal (Wald 2004, "Realtime Ray Tracing and
//! Interactive Global Illumination", PhD thesis): rays whose directions
//! share their signs meet the two children of every node in the same order,
//! so the packet walks one path, fetching each node once for all its rays.
//! Each ray keeps its own parametric interval; a child is entered when at
//! least one ray's interval reaches it, and rays that do not are masked off
//! there. The walk (`walk`) is written once over the lane forms of
//! `simd::lanes` — eight lanes portable or in AVX2 registers, sixteen in
//! AVX-512 registers — with the single-ray walk's interval rules
//! (`kd::interval`). A leaf's triangles are first culled eight at a time
//! against the packet's frustum when its rays share an origin
//! ([`crate::leaf::frustum`]); each block's survivors are then tested
//! triangle by triangle for all rays at once ([`crate::leaf::packet_shear`])
//! or ray by ray with the block test, whichever takes fewer tests (`leaf`).
//! Results are bit-identical to [`KdTree::closest_hit`].
//!
//! A packet whose rays' direction signs differ is traced ray by ray; a
//! sixteen-ray packet whose halves differ, half by half.

mod leaf;
mod setup;
mod walk;

use crate::isect::Hit;
use crate::kd::KdTree;
use crate::leaf::layout::{Indexed, Whole};
use crate::leaf::{Frustum, PacketShear, TriangleLeaves};
use crate::math::{Ray, Triangle};
use crate::simd::lanes::Lanes;
use crate::simd::{dispatch, level, Kernel};
use walk::{Leaf16, Leaf8};

/// Rays per packet.
pub const PACKET: usize = 8;

/// Rays per sixteen-ray packet (two [`PACKET`] halves walked together).
pub const PACKET16: usize = 2 * PACKET;

const _: () = assert!(PACKET == crate::simd::lanes::WIDTH);

/// The empty interval that masks a lane off.
const OFF: (f32, f32) = (f32::INFINITY, f32::NEG_INFINITY);

/// The best hit of a ray that has none yet.
const NO_HIT: Hit = Hit {
    t: f32::INFINITY,
    tri: u32::MAX,
    u: 0.0,
    v: 0.0,
};

/// A packet's rays, lane by lane, and what the traversal has found so far.
struct Packet {
    /// Signs of the shared direction (the near/far order of every node).
    neg: [bool; 3],
    /// Origins by axis.
    org: [Lanes; 3],
    /// Reciprocal directions by axis.
    inv: [Lanes; 3],
    /// Intervals in the root cell (`OFF` for lanes past the rays given,
    /// invalid rays and rays that miss the root cell).
    t0: Lanes,
    t1: Lanes,
    /// The rays' `tmin`.
    tmin: Lanes,
    /// Directions by axis.
    dir: [Lanes; 3],
    /// The watertight test's permutation, when the live rays share it.
    k: Option<[usize; 3]>,
    /// With `k`: the rays' shear constants `sx`, `sy`, `sz` by lane (see
    /// [`Packet::shear`]).
    s: [Lanes; 3],
    /// The packet form of the watertight test, with `k`.
    packet_shear: Option<PacketShear>,
    /// The live rays' frustum, when they also share their origin.
    frustum: Option<Frustum>,
    /// The closest hit's `t` so far (the ray's `tmax` while there is none).
    best_t: Lanes,
    /// The closest hit so far (`tri == u32::MAX`: none).
    best: [Hit; PACKET],
    /// `best_t` where there is a hit, infinity elsewhere: cells entered
    /// beyond it are skipped, as in `walk`.
    closest: Lanes,
    /// The triangles last tested against the packet with the packet test
    /// (a ring of [`MAILBOX`] indices) and the rays each was tested for.
    mailbox: [(u32, u32); MAILBOX],
    /// The slot of `mailbox` to overwrite next.
    mailbox_next: usize,
}

/// Triangles a packet remembers having tested (its mailbox; Amanatides and
/// Woo 1987 for grids, Havran 2000 for kd-trees): a triangle referenced by
/// several leaves is met again in each, and testing it again for the same
/// rays cannot change their closest hits.
const MAILBOX: usize = 8;

thread_local! {
    /// This thread's packets, reused from call to call: the two halves of
    /// a sixteen-ray packet, the first also an eight-ray packet. A fresh
    /// packet would be a 1 KB copy of `Packet::EMPTY` per call whose fields
    /// the set-up overwrites anyway; reused, the set-up resets the mailbox
    /// and writes every other field the walk reads (figures in
    /// `docs/performance.md`).
    static PACKETS: std::cell::RefCell<[Packet; 2]> =
        const { std::cell::RefCell::new([Packet::EMPTY, Packet::EMPTY]) };
}

impl KdTree<Triangle> {
    /// Closest hits of up to [`PACKET`] rays traced as one packet; `out[i]`
    /// answers `rays[i]` exactly as [`KdTree::closest_hit`] would.
    ///
    /// # Panics
    /// If there are more than [`PACKET`] rays or `out` differs in length.
    pub fn closest_hit_packet(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        // The thread's packet is borrowed here, outside the kernel: a
        // closure is compiled without its caller's target features, so the
        // walk must not sit in one.
        PACKETS.with_borrow_mut(|h| {
            let k = Packet8Query {
                tree: self,
                rays,
                out,
                p: &mut h[0],
            };
            dispatch(level::AVX2.min(self.max_level), k)
        });
    }

    /// Closest hits of up to [`PACKET16`] rays traced as one packet (e.g. a
    /// 4x4 pixel tile: rays `0..8` and `8..16` should each be a coherent
    /// 4x2 half); `out[i]` answers `rays[i]` exactly as
    /// [`KdTree::closest_hit`] would.
    ///
    /// With AVX-512 the sixteen rays share one walk; without it, or when
    /// the two halves' direction signs differ, each half is traced as a
    /// [`PACKET`]-ray packet.
    ///
    /// # Panics
    /// If there are more than [`PACKET16`] rays or `out` differs in length.
    pub fn closest_hit_packet16(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET16, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        // Borrowed outside the kernel, as in `closest_hit_packet`; false
        // below the AVX-512 level or when the halves cannot share a walk.
        let traced = rays.len() > PACKET
            && PACKETS.with_borrow_mut(|h| {
                let k = Packet16Query {
                    tree: self,
                    rays,
                    out,
                    h,
                };
                dispatch(self.max_level, k)
            });
        if traced {
            return;
        }
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            self.closest_hit_packet(r, o);
        }
    }

    /// Closest hits of many rays in packets of [`PACKET`] consecutive rays
    /// (order them so that neighbours are coherent, e.g. 4x2 pixel tiles).
    pub fn closest_hits_packets(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            self.closest_hit_packet(r, o);
        }
    }

    /// Closest hits of many rays in packets of [`PACKET16`] consecutive
    /// rays (see [`KdTree::closest_hit_packet16`]).
    pub fn closest_hits_packets16(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        for (r, o) in rays.chunks(PACKET16).zip(out.chunks_mut(PACKET16)) {
            self.closest_hit_packet16(r, o);
        }
    }

    /// The rays of a packet that cannot be traced together, one by one.
    fn closest_hits_one_by_one(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = self.closest_hit(r);
        }
    }

    /// The eight-ray packet of `rays` in `p` (whatever it held: the set-up
    /// writes every field the walk reads), walked at level `SIMD`.
    ///
    /// # Safety
    /// The CPU must have the level's instructions, and the caller must be
    /// compiled for them.
    #[inline(always)]
    unsafe fn trace_packet8<const SIMD: u8>(
        &self,
        p: &mut Packet,
        rays: &[Ray],
        out: &mut [Option<Hit>],
    ) {
        // SAFETY: the level's instructions (the caller's contract).
        if self.nodes.is_empty() || !unsafe { p.setup_at::<SIMD>(rays, &self.bounds) } {
            self.closest_hits_one_by_one(rays, out);
            return;
        }
        // SAFETY (all arms): as above.
        match &self.leaf_data {
            #[cfg(target_arch = "x86_64")]
            TriangleLeaves::Whole(v) if SIMD >= level::AVX2 => unsafe {
                self.walk_packet::<std::arch::x86_64::__m256, _>(Leaf8::<SIMD, _>::new(
                    self,
                    Whole(v),
                    p,
                ))
            },
            #[cfg(target_arch = "x86_64")]
            TriangleLeaves::Indexed(v) if SIMD >= level::AVX2 => unsafe {
                self.walk_packet::<std::arch::x86_64::__m256, _>(Leaf8::<SIMD, _>::new(
                    self,
                    Indexed(v),
                    p,
                ))
            },
            TriangleLeaves::Whole(v) => unsafe {
                self.walk_packet::<Lanes, _>(Leaf8::<SIMD, _>::new(self, Whole(v), p))
            },
            TriangleLeaves::Indexed(v) => unsafe {
                self.walk_packet::<Lanes, _>(Leaf8::<SIMD, _>::new(self, Indexed(v), p))
            },
        }
        leaf::finish(p, out);
    }

    /// The sixteen-ray packet of `rays` in the halves `h` (set up as for
    /// [`KdTree::trace_packet8`]), walked with AVX-512; false (and `out`
    /// untouched) when the rays cannot share the walk: an empty tree, or
    /// halves whose direction signs differ.
    ///
    /// # Safety
    /// The CPU must have AVX2 and AVX-512 F, and the caller must be
    /// compiled for them; `rays` must hold more than [`PACKET`] and at most
    /// [`PACKET16`] rays.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn trace_packet16(
        &self,
        h: &mut [Packet; 2],
        rays: &[Ray],
        out: &mut [Option<Hit>],
    ) -> bool {
        const AVX2: u8 = level::AVX2;
        let (a, b) = rays.split_at(PACKET);
        // SAFETY (both): AVX2 (the caller's contract).
        if self.nodes.is_empty()
            || !unsafe { h[0].setup_at::<AVX2>(a, &self.bounds) }
            || !unsafe { h[1].setup_at::<AVX2>(b, &self.bounds) }
            || h[0].neg != h[1].neg
        {
            return false;
        }
        // SAFETY (both arms): AVX-512 F (the caller's contract). The leaf
        // tests of each half stay at the AVX2 level.
        match &self.leaf_data {
            TriangleLeaves::Whole(v) => unsafe {
                self.walk_packet::<std::arch::x86_64::__m512, _>(Leaf16::<AVX2, _>::new(
                    self,
                    Whole(v),
                    h,
                ))
            },
            TriangleLeaves::Indexed(v) => unsafe {
                self.walk_packet::<std::arch::x86_64::__m512, _>(Leaf16::<AVX2, _>::new(
                    self,
                    Indexed(v),
                    h,
                ))
            },
        }
        let (oa, ob) = out.split_at_mut(PACKET);
        leaf::finish(&h[0], oa);
        leaf::finish(&h[1], ob);
        true
    }
}

/// [`KdTree::closest_hit_packet`] as a kernel for [`dispatch`].
struct Packet8Query<'a> {
    tree: &'a KdTree<Triangle>,
    rays: &'a [Ray],
    out: &'a mut [Option<Hit>],
    /// The packet to set up and walk in (this thread's, or a fresh one).
    p: &'a mut Packet,
}

impl Kernel for Packet8Query<'_> {
    type Output = ();
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) {
        let Self { tree, rays, out, p } = self;
        // SAFETY: the level's instructions (the caller's contract).
        unsafe { tree.trace_packet8::<LEVEL>(p, rays, out) };
    }
}

/// The sixteen-lane walk of [`KdTree::closest_hit_packet16`] as a kernel
/// for [`dispatch`]: true when it traced the rays.
struct Packet16Query<'a> {
    tree: &'a KdTree<Triangle>,
    rays: &'a [Ray],
    out: &'a mut [Option<Hit>],
    /// The two halves to set up and walk in (this thread's).
    h: &'a mut [Packet; 2],
}

impl Kernel for Packet16Query<'_> {
    type Output = bool;
    #[inline(always)]
    unsafe fn run<const LEVEL: u8>(self) -> bool {
        let Self { tree, rays, out, h } = self;
        #[cfg(target_arch = "x86_64")]
        if LEVEL >= level::AVX512 {
            // SAFETY: AVX2 and AVX-512 F (the caller's contract); 9 to 16
            // rays (the caller's check).
            return unsafe { tree.trace_packet16(h, rays, out) };
        }
        let _ = (tree, rays, out, h);
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::build::{BuildParams, Builder};
    use crate::test_support::{floats, soup};
    use glam::Vec3;

    /// Camera-like packets (a common origin, nearby directions), packets
    /// with mixed direction signs, short ones and invalid rays: every
    /// answer equals brute force, bit for bit, in both builds.
    #[test]
    fn packets_agree_with_brute_force() {
        let mut f = floats(2024);
        let tris = soup(&mut f, 2000, 0.5);
        let compact = BuildParams {
            compact_leaves: true,
            ..BuildParams::new(Builder::Sah)
        };
        for params in [
            BuildParams::new(Builder::Sah),
            BuildParams::new(Builder::Binned { bins: 16 }),
            compact,
        ] {
            let tree = KdTree::build(tris.clone(), &params);
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
                if p % 5 == 3 {
                    // From the eye exactly at the vertices and edge
                    // midpoints of one triangle: the packet's frustum
                    // planes pass through the vertices its rays aim at.
                    let t = &tris[(p * 17) % tris.len()];
                    for (k, r) in rays.iter_mut().enumerate() {
                        let target = if k % 2 == 0 {
                            t.v[k % 3]
                        } else {
                            (t.v[k % 3] + t.v[(k + 1) % 3]) * 0.5
                        };
                        r.dir = target - eye;
                    }
                }
                if p % 5 == 1 {
                    // Axis-parallel rays whose origins lie in split planes
                    // (vertex coordinates): `tp` is NaN or a cell face.
                    for (k, r) in rays.iter_mut().enumerate() {
                        let v = tris[(p * 31 + k * 7) % tris.len()].v[k % 3];
                        r.origin = Vec3::new(v.x, v.y, -6.0);
                        r.dir = Vec3::new(0.0, if p % 10 == 1 { 0.0 } else { -0.0 }, 1.0);
                    }
                }
                let want: Vec<_> = rays.iter().map(|r| brute::closest_hit(&tris, r)).collect();
                let mut got = vec![None; n];
                tree.closest_hit_packet(&rays, &mut got);
                assert_eq!(got, want, "packet {p}");
                for top in [level::PORTABLE, level::AVX2] {
                    got.fill(None);
                    let mut packet = Packet::EMPTY;
                    let k = Packet8Query {
                        tree: &tree,
                        rays: &rays,
                        out: &mut got,
                        p: &mut packet,
                    };
                    dispatch(top, k);
                    assert_eq!(got, want, "packet {p} (level {top})");
                }
            }
        }
    }

    /// Sixteen-ray packets: 4x4 tiles of camera rays, tiles whose halves
    /// (or whose rays within a half) differ in direction signs, 9 to 15
    /// rays, invalid rays and short segments: every answer equals brute
    /// force, bit for bit, in both leaf layouts (with AVX-512 through the
    /// sixteen-lane walk, elsewhere through two eight-ray packets).
    #[test]
    fn sixteen_ray_packets_agree_with_brute_force() {
        let mut f = floats(1604);
        let tris = soup(&mut f, 2000, 0.5);
        let compact = BuildParams {
            compact_leaves: true,
            ..BuildParams::new(Builder::Sah)
        };
        for params in [BuildParams::new(Builder::Sah), compact] {
            let tree = KdTree::build(tris.clone(), &params);
            for p in 0..300 {
                let eye = Vec3::new(f(), f(), -6.0);
                let aim = Vec3::new(f(), f(), 1.0);
                let n = if p % 7 == 0 { 9 + p % 7 } else { PACKET16 };
                // A 4x4 tile of directions around `aim`.
                let step = if p % 3 == 0 { 0.2 } else { 0.01 };
                let mut rays: Vec<Ray> = (0..n)
                    .map(|k| {
                        let (x, y) = ((k % 4) as f32, (k / 4) as f32);
                        Ray::new(eye, aim + Vec3::new(x, y, 0.0) * step)
                    })
                    .collect();
                if p % 5 == 1 {
                    // The second half looks the other way along x.
                    for r in &mut rays[PACKET..] {
                        r.dir.x = -r.dir.x - 0.01;
                    }
                }
                if p % 5 == 2 {
                    // One ray of the first half looks back.
                    rays[3].dir = -rays[3].dir;
                }
                if p % 11 == 0 {
                    rays[n - 1] = Ray::new(eye, Vec3::ZERO); // invalid
                }
                if p % 13 == 0 {
                    rays[n - 2].tmax = 6.0;
                }
                let want: Vec<_> = rays.iter().map(|r| brute::closest_hit(&tris, r)).collect();
                let mut got = vec![None; n];
                tree.closest_hit_packet16(&rays, &mut got);
                assert_eq!(got, want, "packet {p}");
            }
            let rays: Vec<Ray> = (0..PACKET16 * 20 + 5)
                .map(|_| Ray::new(Vec3::new(0.0, 0.0, -6.0), Vec3::new(f(), f(), 1.0)))
                .collect();
            let mut got = vec![None; rays.len()];
            tree.closest_hits_packets16(&rays, &mut got);
            for (r, g) in rays.iter().zip(&got) {
                assert_eq!(*g, brute::closest_hit(&tris, r));
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
