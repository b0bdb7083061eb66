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
//! eight lanes at a time: [`avx2`] with AVX2 intrinsics where the CPU has
//! them (chosen at run time), the portable walk here otherwise. A leaf's
//! triangles are first culled eight at a time against the packet's frustum
//! when its rays share an origin ([`crate::leaf::frustum`]); each block's
//! survivors are then tested triangle by triangle for all rays at once
//! ([`crate::leaf::packet_shear`]) or ray by ray with the block test,
//! whichever takes fewer tests. Results are bit-identical to
//! [`KdTree::closest_hit`].
//!
//! A packet whose rays' direction signs differ is traced ray by ray.
//!
//! Sixteen-ray packets ([`KdTree::closest_hit_packet16`]) walk two such
//! packets together with AVX-512 where the CPU has it ([`avx512`]).

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod setup;

use crate::build::MAX_DEPTH;
use crate::isect::TriangleHit;
use crate::isect::TrianglePlane;
use crate::isect::{keep_closer, Hit};
use crate::kd::KdTree;
use crate::leaf::layout::{Indexed, Layout, LeafBlock, Whole};
use crate::leaf::Frustum;
use crate::leaf::PacketShear;
use crate::leaf::TriangleLeaves;
use crate::leaf::BLOCK_WIDTH;
use crate::math::slack::MARGIN;
use crate::math::{Ray, Triangle};
use crate::simd::level;

/// Rays per packet.
pub const PACKET: usize = 8;

/// Rays per sixteen-ray packet (two [`PACKET`] halves walked together).
pub const PACKET16: usize = 2 * PACKET;

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

#[cfg(target_arch = "x86_64")]
thread_local! {
    /// This thread's packets, reused from call to call: the two halves of
    /// a sixteen-ray packet, the first also an eight-ray packet. A fresh
    /// packet was a copy of `Packet::EMPTY` (1 KB, `memmove`: ~7% of the
    /// sixteen-ray path's samples on the teapot in its stadium) whose
    /// fields the set-up then overwrote; reused, the set-up resets the
    /// mailbox and writes the rest as before. 1 thread, best of 3
    /// interleaved rounds, five meshes: 16-ray packets 1.01-1.05x, then
    /// 8-ray packets 1.02-1.05x.
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
        #[cfg(target_arch = "x86_64")]
        if crate::simd::has_avx2() {
            // SAFETY: the CPU has AVX2 (checked at run time).
            return unsafe { self.closest_hit_packet_avx2(rays, out) };
        }
        self.packet_portable(rays, out);
    }

    /// [`KdTree::closest_hit_packet`] with the portable walk whatever the
    /// CPU (the fallback, and the reference the AVX2 path is tested
    /// against).
    fn packet_portable(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        let mut p = Packet::EMPTY;
        if self.packet(rays, &mut p) {
            match &self.leaf_data {
                TriangleLeaves::Whole(v) => self.walk_packet_portable(Whole(v), &mut p),
                TriangleLeaves::Indexed(b) => self.walk_packet_portable(Indexed(b), &mut p),
            }
            finish(&p, out);
        } else {
            self.closest_hits_one_by_one(rays, out);
        }
    }

    /// [`KdTree::closest_hit_packet`] with the set-up and the walk compiled
    /// for AVX2.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn closest_hit_packet_avx2(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        // SAFETY: as this function (the caller's contract).
        PACKETS.with_borrow_mut(|h| unsafe { self.packet8_in(&mut h[0], rays, out) })
    }

    /// [`KdTree::closest_hit_packet_avx2`] in the packet `p` (whatever it
    /// held: the set-up writes every field the walk reads).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn packet8_in(&self, p: &mut Packet, rays: &[Ray], out: &mut [Option<Hit>]) {
        // SAFETY: the CPU has AVX2 (the caller's contract).
        if !self.nodes.is_empty() && unsafe { p.setup_avx2(rays, &self.bounds) } {
            // SAFETY (both arms): as above.
            match &self.leaf_data {
                TriangleLeaves::Whole(v) => unsafe { self.walk_packet_avx2(Whole(v), p) },
                TriangleLeaves::Indexed(b) => unsafe { self.walk_packet_avx2(Indexed(b), p) },
            }
            finish(p, out);
        } else {
            self.closest_hits_one_by_one(rays, out);
        }
    }

    /// Closest hits of up to [`PACKET16`] rays traced as one packet (e.g. a
    /// 4x4 pixel tile: rays `0..8` and `8..16` should each be a coherent
    /// 4x2 half); `out[i]` answers `rays[i]` exactly as
    /// [`KdTree::closest_hit`] would.
    ///
    /// With AVX-512 the sixteen rays share one walk (`avx512`); without
    /// it, or when the two halves' direction signs differ, each half is
    /// traced as a [`PACKET`]-ray packet.
    ///
    /// # Panics
    /// If there are more than [`PACKET16`] rays or `out` differs in length.
    pub fn closest_hit_packet16(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET16, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        #[cfg(target_arch = "x86_64")]
        if rays.len() > PACKET && crate::simd::has_avx512() {
            // SAFETY: the CPU has AVX2 and AVX-512 F (checked at run time).
            if unsafe { self.closest_hit_packet16_avx512(rays, out) } {
                return;
            }
        }
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            self.closest_hit_packet(r, o);
        }
    }

    /// [`KdTree::closest_hit_packet16`] with the sixteen-lane walk; false
    /// (and `out` untouched) when the rays cannot share it: an empty tree,
    /// or halves whose direction signs differ.
    ///
    /// # Safety
    /// The CPU must have AVX2 and AVX-512 F; `rays` must hold more than
    /// [`PACKET`] and at most [`PACKET16`] rays.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f")]
    unsafe fn closest_hit_packet16_avx512(&self, rays: &[Ray], out: &mut [Option<Hit>]) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        // SAFETY: as this function (the caller's contract).
        PACKETS.with_borrow_mut(|h| unsafe { self.packet16_in(h, rays, out) })
    }

    /// [`KdTree::closest_hit_packet16_avx512`] in the halves `h` (whatever
    /// they held: the set-up writes every field the walk reads).
    ///
    /// # Safety
    /// As [`KdTree::closest_hit_packet16_avx512`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f")]
    unsafe fn packet16_in(
        &self,
        h: &mut [Packet; 2],
        rays: &[Ray],
        out: &mut [Option<Hit>],
    ) -> bool {
        let (a, b) = rays.split_at(PACKET);
        // SAFETY (both): the CPU has AVX2 (the caller's contract).
        if !unsafe { h[0].setup_avx2(a, &self.bounds) }
            || !unsafe { h[1].setup_avx2(b, &self.bounds) }
            || h[0].neg != h[1].neg
        {
            return false;
        }
        // SAFETY (both arms): AVX2 and AVX-512 F (the caller's contract).
        match &self.leaf_data {
            TriangleLeaves::Whole(v) => unsafe { self.walk_packet16_avx512(Whole(v), h) },
            TriangleLeaves::Indexed(v) => unsafe { self.walk_packet16_avx512(Indexed(v), h) },
        }
        let (oa, ob) = out.split_at_mut(PACKET);
        finish(&h[0], oa);
        finish(&h[1], ob);
        true
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

    /// Closest hits of many rays in packets of [`PACKET`] consecutive rays
    /// (order them so that neighbours are coherent, e.g. 4x2 pixel tiles).
    pub fn closest_hits_packets(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one output slot per ray");
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            self.closest_hit_packet(r, o);
        }
    }

    /// Make `p` the packet of `rays`; false when they must be traced one
    /// by one (no rays, an empty tree, or direction signs that differ).
    #[inline(always)]
    fn packet(&self, rays: &[Ray], p: &mut Packet) -> bool {
        !self.nodes.is_empty() && p.setup(rays, &self.bounds)
    }

    /// The portable packet walk (for CPUs without AVX2; the reference the
    /// AVX2 walk is tested against).
    fn walk_packet_portable<L: Layout>(&self, layout: L, p: &mut Packet) {
        let (mut t0, mut t1) = (p.t0, p.t1);
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
                let (near, far) = nd.near_far(node, &p.neg);
                // Each lane decides as `walk` does (same expressions, so the
                // same rounding): near only, far only, or both with the
                // interval cut at the plane.
                let (o, iv) = (&p.org[axis], &p.inv[axis]);
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
            let mut live_rays = 0u32;
            for l in 0..PACKET {
                live_rays |= ((t0[l] <= t1[l]) as u32) << l;
            }
            // SAFETY: `nd` is a leaf of this tree.
            unsafe {
                self.packet_leaf::<{ level::PORTABLE }, _>(
                    layout,
                    p,
                    nd.leaf_offset() as usize,
                    nd.leaf_count() as usize,
                    live_rays,
                )
            };
            // Pop the next cell some ray may still find a closer hit in.
            live = false;
            while sp > 0 {
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push above.
                let e = unsafe { stack[sp].assume_init() };
                for l in 0..PACKET {
                    let keep = e.t0[l] <= e.t1[l] && e.t0[l] <= p.closest[l] * (1.0 + MARGIN);
                    (t0[l], t1[l]) = if keep { (e.t0[l], e.t1[l]) } else { OFF };
                    live |= keep;
                }
                if live {
                    node = e.node;
                    break;
                }
            }
        }
    }

    /// Test the leaf at `offset` with `count` triangles for the rays in
    /// `live` (bit `l` = ray `l`) and update their closest hits exactly as
    /// [`KdTree::leaf_closest`] does ray by ray (the smallest `t`, then the
    /// smallest index, wins).
    ///
    /// # Safety
    /// `offset` and `count` must be those of a leaf of this tree, whose
    /// blocks `layout` holds; the CPU must have the instructions of level
    /// `SIMD`.
    #[inline(always)]
    unsafe fn packet_leaf<const SIMD: u8, L: Layout>(
        &self,
        layout: L,
        p: &mut Packet,
        offset: usize,
        count: usize,
        live: u32,
    ) {
        if count == 0 || live == 0 {
            return;
        }
        // SAFETY: passed on from the caller.
        let blocks = unsafe { layout.blocks(offset, count) };
        let rays = live.count_ones();
        for (b, block) in blocks.enumerate() {
            let lanes = (count - b * BLOCK_WIDTH).min(BLOCK_WIDTH);
            let tris = match &p.frustum {
                // SAFETY: `SIMD` is the level the walk is compiled for.
                Some(f) => unsafe { block.survivors::<SIMD>(f, lanes) },
                None => (1u32 << lanes) - 1,
            };
            if tris == 0 {
                continue;
            }
            let indices = &self.indices[block.run()..block.run() + BLOCK_WIDTH];
            // Triangle-parallel when it takes fewer tests: one 8-ray test
            // per triangle left against one 8-triangle test per ray.
            match p.packet_shear {
                Some(ps) if rays >= tris.count_ones() => {
                    block_closest_packet::<SIMD>(&ps, p, block, indices, tris, live)
                }
                _ => block_closest_rays::<SIMD>(p, block, indices, lanes, tris, live),
            }
        }
        for l in 0..PACKET {
            if p.best[l].tri != u32::MAX {
                p.closest[l] = p.best_t[l];
            }
        }
    }
}

/// The indices of the set bits of `mask`, lowest first.
#[inline(always)]
fn set_bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// The triangles `tris` of `block` (indices `indices`) against the rays in
/// `live`, one triangle at a time for all rays.
///
/// The CPU must have the instructions of level `SIMD` (the packet leaf's
/// contract).
#[inline(always)]
fn block_closest_packet<const SIMD: u8>(
    ps: &PacketShear,
    p: &mut Packet,
    block: impl LeafBlock,
    indices: &[u32],
    tris: u32,
    live: u32,
) {
    for j in set_bits(tris) {
        let i = indices[j];
        // Tested before for all of these rays (a triangle that spans many
        // cells, e.g. a large floor): a second test could only offer the
        // same hits again (with `tmax` lowered since), which change
        // nothing.
        if p.mailbox
            .iter()
            .any(|&(t, rays)| t == i && rays & live == live)
        {
            continue;
        }
        p.mailbox[p.mailbox_next] = (i, live);
        p.mailbox_next = (p.mailbox_next + 1) % MAILBOX;
        // SAFETY: `SIMD` is the level the walk is compiled for.
        let (m, e) = unsafe { block.packet_edges::<SIMD>(ps, j) };
        let m = m & live;
        if m == 0 {
            continue;
        }
        let tri = block.triangle(j);
        // The plane once for all the rays that need it.
        let plane = TrianglePlane::new(&tri);
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: `SIMD` is the level the walk is compiled for.
            unsafe { decide_lanes_avx2(p, &tri, &plane, &e, m, i) };
            continue;
        }
        for l in set_bits(m) {
            let uvw = [e[0][l], e[1][l], e[2][l]];
            let (tmin, tmax) = (p.tmin[l], p.best_t[l]);
            if let Some(h) = p.shear(l).decide_in_plane(&tri, || plane, uvw, tmin, tmax) {
                keep_closer(&mut p.best_t[l], &mut p.best[l], h, i);
            }
        }
    }
}

/// The rays `m` that passed the packet's edge test against `tri` (edge
/// functions `e`, plane `plane`, index `i`), decided as
/// [`RayShear::decide_in_plane`] decides each, with the plane distances of
/// the eight lanes computed at once; lanes on an edge or with a non-finite
/// determinant take the scalar test, as there.
///
/// Why: the scalar f64 division and conversions per ray were the largest
/// part of the packet test's tail (`perf annotate`).
///
/// Always inlined, without a target feature of its own: compiled as an
/// AVX2 function, LLVM left it out of line once the packet walk existed
/// for two leaf layouts, and the call per triangle cost the packets 4-5%
/// (`perf`, the bunny's camera rays).
///
/// # Safety
/// The CPU must have AVX2, and the caller must be compiled for it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn decide_lanes_avx2(
    p: &mut Packet,
    tri: &Triangle,
    plane: &TrianglePlane,
    e: &[Lanes; 3],
    m: u32,
    i: u32,
) {
    // SAFETY: AVX2 (the caller's contract).
    let t = unsafe {
        plane.distances_avx2(
            [&p.org[0], &p.org[1], &p.org[2]],
            [&p.dir[0], &p.dir[1], &p.dir[2]],
        )
    };
    for l in set_bits(m) {
        let [u, v, w] = [e[0][l], e[1][l], e[2][l]];
        let (tmin, tmax) = (p.tmin[l], p.best_t[l]);
        let det = u + v + w;
        let h = if u != 0.0 && v != 0.0 && w != 0.0 && det.is_finite() {
            // The edge test kept the lane, so its signs agree (see
            // `edge_lanes`); as `decide_in_plane` from here on.
            debug_assert!(!((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)));
            let rcp = 1.0 / det;
            (t[l] > tmin && t[l] <= tmax).then(|| TriangleHit {
                t: t[l] + 0.0,
                u: v * rcp,
                v: w * rcp,
            })
        } else {
            p.shear(l)
                .decide_in_plane(tri, || *plane, [u, v, w], tmin, tmax)
        };
        if let Some(h) = h {
            keep_closer(&mut p.best_t[l], &mut p.best[l], h, i);
        }
    }
}

/// The triangles `tris` among the first `lanes` of `block` against the rays
/// in `live`, one ray at a time with the block test (as
/// [`KdTree::leaf_closest`] does).
///
/// The CPU must have the instructions of level `SIMD` (the packet leaf's
/// contract).
#[inline(always)]
fn block_closest_rays<const SIMD: u8>(
    p: &mut Packet,
    block: impl LeafBlock,
    indices: &[u32],
    lanes: usize,
    tris: u32,
    live: u32,
) {
    for l in set_bits(live) {
        let shear = p.shear(l);
        // SAFETY: `SIMD` is the level the walk is compiled for.
        let (m, e) = unsafe { block.edges::<SIMD>(&shear, lanes) };
        for j in set_bits(m & tris) {
            let uvw = [e[0][j], e[1][j], e[2][j]];
            let (tmin, tmax) = (p.tmin[l], p.best_t[l]);
            if let Some(h) = shear.decide(&block.triangle(j), uvw, tmin, tmax) {
                keep_closer(&mut p.best_t[l], &mut p.best[l], h, indices[j]);
            }
        }
    }
}

/// Write the packet's closest hits to `out`.
fn finish(p: &Packet, out: &mut [Option<Hit>]) {
    for (l, o) in out.iter_mut().enumerate() {
        *o = (p.best[l].tri != u32::MAX).then_some(p.best[l]);
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
                got.fill(None);
                tree.packet_portable(&rays, &mut got);
                assert_eq!(got, want, "packet {p} (portable)");
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
