//! The block test: one ray against the eight triangles of a leaf block, in
//! either layout.
//!
//! A leaf's triangles are copied, in leaf order, into blocks of
//! [`BLOCK_WIDTH`] so that one leaf visit reads contiguous memory instead of
//! an index and then a triangle per reference, and so that the edge functions
//! of the watertight test are computed for eight triangles at once (plain
//! loops over `[f32; 8]`, which the compiler turns into SIMD: two SSE or one
//! AVX2 operation per line; see `crate::simd`).
//!
//! The block test is a filter, never a decision: it evaluates exactly the
//! floating-point operations of [`RayShear::intersect`] (same order, no fused
//! multiply-add, which Rust never contracts on its own), so a lane it rejects
//! is one the scalar test rejects; every other lane (rare: only triangles
//! whose projection holds the ray) is decided by the scalar test itself. Hits
//! are therefore bit-identical to the reference test and the brute-force
//! oracle.

use super::edges::edge_lanes;
#[cfg(target_arch = "x86_64")]
use super::edges::{edge_lanes_avx2, sheared_avx2};
use super::{IndexedBlock, TriangleBlock, BLOCK_WIDTH};
use crate::isect::RayShear;
#[cfg(target_arch = "x86_64")]
use crate::simd::lanes::Lanes8;
use crate::simd::level;

impl RayShear {
    /// One vertex of eight triangles moved to the ray origin and sheared, as
    /// in `intersect`: `(p[kx] - o[kx]) - sx (p[kz] - o[kz])`, and the same
    /// with `ky`, `sy`.
    #[inline(always)]
    fn sheared(&self, p: &[[f32; BLOCK_WIDTH]; 3]) -> ([f32; BLOCK_WIDTH], [f32; BLOCK_WIDTH]) {
        let [kx, ky, kz] = self.k;
        let (ox, oy, oz) = (self.origin[kx], self.origin[ky], self.origin[kz]);
        let (sx, sy) = (self.s.x, self.s.y);
        let (px, py, pz) = (&p[kx], &p[ky], &p[kz]);
        let mut x = [0.0f32; BLOCK_WIDTH];
        let mut y = [0.0f32; BLOCK_WIDTH];
        for l in 0..BLOCK_WIDTH {
            let z = pz[l] - oz;
            x[l] = (px[l] - ox) - sx * z;
            y[l] = (py[l] - oy) - sy * z;
        }
        (x, y)
    }

    /// The lanes among the first `lanes` of `block` that the watertight test
    /// may accept, as a bit mask (bit `i` = lane `i`).
    ///
    /// A lane is left out only when its three edge functions are non-zero
    /// with mixed signs and their sum is finite: precisely the scalar test's
    /// early rejection, computed with the same operations.
    #[inline(always)]
    pub fn block_candidates(&self, block: &TriangleBlock, lanes: usize) -> u32 {
        self.block_edges(block, lanes).0
    }

    /// [`RayShear::block_candidates`] and the lanes' edge functions
    /// `[u, v, w]`, for [`RayShear::decide`].
    #[inline(always)]
    pub fn block_edges(
        &self,
        block: &TriangleBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        let v = &block.v;
        let (mask, e) = edge_lanes(
            self.sheared(&v[0]),
            self.sheared(&v[1]),
            self.sheared(&v[2]),
        );
        (mask & ((1u32 << lanes) - 1), e)
    }
}

impl RayShear {
    /// [`RayShear::block_edges`] of a block as a tree stores it: each
    /// distinct vertex sheared once (the same operations, so the same
    /// lanes), then gathered into the lanes.
    #[inline(always)]
    pub fn indexed_edges(
        &self,
        block: IndexedBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        let [kx, ky, kz] = self.k;
        let (ox, oy, oz) = (self.origin[kx], self.origin[ky], self.origin[kz]);
        let (sx, sy) = (self.s.x, self.s.y);
        let mut x = [0.0f32; 3 * BLOCK_WIDTH];
        let mut y = [0.0f32; 3 * BLOCK_WIDTH];
        for n in 0..block.table_len() {
            let p = block.table_vertex(n);
            let z = p[kz] - oz;
            x[n] = (p[kx] - ox) - sx * z;
            y[n] = (p[ky] - oy) - sy * z;
        }
        let vertex = |k: usize| {
            let n: [usize; BLOCK_WIDTH] = std::array::from_fn(|l| block.number(k, l));
            (n.map(|n| x[n]), n.map(|n| y[n]))
        };
        let (mask, e) = edge_lanes(vertex(0), vertex(1), vertex(2));
        (mask & ((1u32 << lanes) - 1), e)
    }

    /// [`RayShear::indexed_edges`], in intrinsics at level `SIMD` (AVX2 or
    /// above; see `crate::simd::level`).
    ///
    /// # Safety
    /// The CPU must have the level's instructions, and the caller must be
    /// compiled for them.
    #[inline(always)]
    pub(crate) unsafe fn indexed_block_edges<const SIMD: u8>(
        &self,
        block: IndexedBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract (and it is compiled for AVX2:
            // `AVX2` is only set inside the AVX2 traversals).
            return unsafe { self.indexed_edges_intrinsics::<SIMD>(block, lanes) };
        }
        self.indexed_edges(block, lanes)
    }
}

#[cfg(target_arch = "x86_64")]
impl RayShear {
    /// [`RayShear::block_edges`] in AVX2 intrinsics (the same results).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn block_edges_avx2(
        &self,
        block: &TriangleBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        use std::arch::x86_64::*;
        let [kx, ky, kz] = self.k;
        let set = |x: f32| _mm256_set1_ps(x);
        let (ox, oy, oz) = (
            set(self.origin[kx]),
            set(self.origin[ky]),
            set(self.origin[kz]),
        );
        let (sx, sy) = (set(self.s.x), set(self.s.y));
        let sheared = |p: &[[f32; BLOCK_WIDTH]; 3]| {
            // SAFETY: eight f32 per row.
            let load = |a: &[f32; BLOCK_WIDTH]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
            sheared_avx2(
                [load(&p[kx]), load(&p[ky]), load(&p[kz])],
                [ox, oy, oz],
                sx,
                sy,
            )
        };
        let v = &block.v;
        let (mask, e) = edge_lanes_avx2(sheared(&v[0]), sheared(&v[1]), sheared(&v[2]));
        (mask & ((1u32 << lanes) - 1), e)
    }

    /// [`RayShear::indexed_edges`] in AVX2 intrinsics (the same results):
    /// the (at most 16) distinct vertices sheared in two registers, the
    /// lanes gathered from them with permutes; a verbatim block's lanes
    /// are loaded as they are.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn indexed_edges_avx2(
        &self,
        block: IndexedBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        // SAFETY: AVX2 (this function's target feature).
        unsafe { self.indexed_edges_intrinsics::<{ level::AVX2 }>(block, lanes) }
    }

    /// The body of [`RayShear::indexed_edges_avx2`], always inlined (a
    /// function with a target feature cannot be): LLVM kept the function
    /// out of line, and the call per block, with the walk's registers
    /// spilled around it, cost up to 10% (`perf`).
    ///
    /// With `SIMD` at [`level::AVX512`], the gathers are AVX-512 (VL)
    /// two-register permutes.
    ///
    /// # Safety
    /// The CPU must have AVX2 (and AVX-512 F, VL at that level), and the
    /// caller must be compiled for it.
    #[inline(always)]
    pub(crate) unsafe fn indexed_edges_intrinsics<const SIMD: u8>(
        &self,
        block: IndexedBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        use std::arch::x86_64::*;
        let [kx, ky, kz] = self.k;
        let o = [
            _mm256_set1_ps(self.origin[kx]),
            _mm256_set1_ps(self.origin[ky]),
            _mm256_set1_ps(self.origin[kz]),
        ];
        let (sx, sy) = (_mm256_set1_ps(self.s.x), _mm256_set1_ps(self.s.y));
        if block.is_verbatim() {
            // SAFETY: AVX2 (the caller's contract).
            return unsafe { self.verbatim_edges_avx2(block, lanes) };
        }
        // SAFETY: not verbatim; AVX2 (the caller's contract). No closures
        // or `array::from_fn` here: this body has no target feature of its
        // own, and LLVM left such helpers as calls.
        unsafe {
            let (xl, xh) = block.row_avx2(kx);
            let (yl, yh) = block.row_avx2(ky);
            let (zl, zh) = block.row_avx2(kz);
            let (lx, ly) = sheared_avx2([xl, yl, zl], o, sx, sy);
            let (hx, hy) = sheared_avx2([xh, yh, zh], o, sx, sy);
            let n0 = block.numbers_avx2(0);
            let n1 = block.numbers_avx2(1);
            let n2 = block.numbers_avx2(2);
            let (mask, e) = edge_lanes_avx2(
                (
                    IndexedBlock::gather::<SIMD>((lx, hx), n0),
                    IndexedBlock::gather::<SIMD>((ly, hy), n0),
                ),
                (
                    IndexedBlock::gather::<SIMD>((lx, hx), n1),
                    IndexedBlock::gather::<SIMD>((ly, hy), n1),
                ),
                (
                    IndexedBlock::gather::<SIMD>((lx, hx), n2),
                    IndexedBlock::gather::<SIMD>((ly, hy), n2),
                ),
            );
            (mask & ((1u32 << lanes) - 1), e)
        }
    }

    /// [`RayShear::indexed_edges_avx2`] of a verbatim block (its lanes
    /// loaded as they are); out of line, so that the common path stays
    /// small enough to be inlined into the traversal (a call per block, with
    /// the walk's registers spilled around it, cost up to 10%).
    ///
    /// # Safety
    /// The CPU must have AVX2; the block must be verbatim.
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    #[cold]
    unsafe fn verbatim_edges_avx2(
        &self,
        block: IndexedBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        use std::arch::x86_64::*;
        let [kx, ky, kz] = self.k;
        let set = |x: f32| _mm256_set1_ps(x);
        let o = [
            set(self.origin[kx]),
            set(self.origin[ky]),
            set(self.origin[kz]),
        ];
        let (sx, sy) = (set(self.s.x), set(self.s.y));
        let v: [(Lanes8, Lanes8); 3] = std::array::from_fn(|k| {
            // SAFETY: a verbatim block; AVX2 (the caller's contract).
            let p = |a: usize| unsafe { block.slot_avx2(k, a) };
            sheared_avx2([p(kx), p(ky), p(kz)], o, sx, sy)
        });
        let (mask, e) = edge_lanes_avx2(v[0], v[1], v[2]);
        (mask & ((1u32 << lanes) - 1), e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Ray, Triangle};
    use crate::test_support::floats;
    use glam::Vec3;

    /// The filter never drops a lane the scalar test accepts, and it drops
    /// every lane the scalar test rejects by its signs (so it filters).
    #[test]
    fn candidates_keep_every_hit_and_drop_clear_misses() {
        let mut f = floats(12345);
        let (mut hits, mut dropped) = (0, 0);
        for _ in 0..2000 {
            let tris: Vec<Triangle> = (0..BLOCK_WIDTH)
                .map(|_| {
                    Triangle::new(
                        Vec3::new(f(), f(), f() + 3.0),
                        Vec3::new(f(), f(), f() + 3.0),
                        Vec3::new(f(), f(), f() + 3.0),
                    )
                })
                .collect();
            let block = TriangleBlock::pack(&tris);
            let ray = Ray::new(
                Vec3::new(f() * 0.2, f() * 0.2, 0.0),
                Vec3::new(f() * 0.3, f() * 0.3, 1.0),
            );
            let shear = RayShear::from_ray(&ray);
            for lanes in [1, 5, BLOCK_WIDTH] {
                let (m, e) = shear.block_edges(&block, lanes);
                assert_eq!(m, shear.block_candidates(&block, lanes));
                assert_eq!(m >> lanes, 0, "lanes past the count are masked");
                for (l, t) in tris.iter().enumerate().take(lanes) {
                    let hit = shear.intersect(t, ray.tmin, ray.tmax);
                    if m & (1 << l) != 0 {
                        // Finishing from the block's edge functions gives
                        // the scalar test's answer, bit for bit.
                        let uvw = [e[0][l], e[1][l], e[2][l]];
                        assert_eq!(shear.decide(t, uvw, ray.tmin, ray.tmax), hit);
                    }
                    if hit.is_some() {
                        hits += 1;
                        assert!(m & (1 << l) != 0, "lane {l} hit but was dropped");
                    } else if m & (1 << l) == 0 {
                        dropped += 1;
                    }
                }
            }
        }
        assert!(hits > 1000, "{hits}");
        assert!(dropped > 5 * hits, "{dropped} dropped, {hits} hits");
    }

    /// The AVX2 block test gives the portable one's mask and edge functions
    /// bit for bit: rays along every axis and sign, triangles with shared,
    /// repeated or zero coordinates, rays through vertices and edges.
    #[test]
    fn avx2_block_edges_equal_the_portable_ones() {
        #[cfg(target_arch = "x86_64")]
        if crate::simd::has_avx2() {
            let mut f = floats(4242);
            let mut kept = 0;
            for round in 0..4000 {
                let pick = |f: &mut dyn FnMut() -> f32| match round % 5 {
                    0 => f().round(),
                    1 => 0.0,
                    _ => f(),
                };
                let mut tris: Vec<Triangle> = (0..BLOCK_WIDTH)
                    .map(|_| {
                        let mut p = || Vec3::new(pick(&mut f), f(), pick(&mut f));
                        Triangle::new(p(), p(), p())
                    })
                    .collect();
                tris[3].v[2] = tris[3].v[0]; // degenerate
                let block = TriangleBlock::pack(&tris);
                let mut dir = Vec3::new(f(), f(), f());
                dir[round % 3] = if round % 2 == 0 { 2.0 } else { -2.0 };
                let origin = match round % 4 {
                    // Through a vertex or along an edge of triangle 1.
                    0 => tris[1].v[0] - dir,
                    1 => (tris[1].v[0] + tris[1].v[1]) * 0.5 - dir * 0.5,
                    _ => Vec3::new(f(), f(), f()) * 2.0,
                };
                let shear = RayShear::from_ray(&Ray::new(origin, dir));
                for lanes in [1, 6, BLOCK_WIDTH] {
                    let (m, e) = shear.block_edges(&block, lanes);
                    // SAFETY: the CPU has AVX2.
                    let (m2, e2) = unsafe { shear.block_edges_avx2(&block, lanes) };
                    assert_eq!(m, m2, "round {round}");
                    let bits = |e: [[f32; BLOCK_WIDTH]; 3]| e.map(|r| r.map(f32::to_bits));
                    assert_eq!(bits(e), bits(e2), "round {round}");
                    kept += m.count_ones();
                }
            }
            assert!(kept > 2000, "{kept} lanes kept");
        }
    }
}
