//! A packet's leaf test: the frustum cull, then each block's survivors
//! tested triangle by triangle for all rays at once or ray by ray with the
//! block test, whichever takes fewer tests; a mailbox skips triangles
//! already tested for the same rays.

use super::{Lanes, Packet, MAILBOX, PACKET};
use crate::isect::{keep_closer, Hit, TriangleHit, TrianglePlane};
use crate::kd::KdTree;
use crate::leaf::layout::{Layout, LeafBlock};
use crate::leaf::{PacketShear, BLOCK_WIDTH};
use crate::math::Triangle;
#[cfg(target_arch = "x86_64")]
use crate::simd::level;

impl KdTree<Triangle> {
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
    pub(super) unsafe fn packet_leaf<const SIMD: u8, L: Layout>(
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
pub(super) fn finish(p: &Packet, out: &mut [Option<Hit>]) {
    for (l, o) in out.iter_mut().enumerate() {
        *o = (p.best[l].tri != u32::MAX).then_some(p.best[l]);
    }
}
