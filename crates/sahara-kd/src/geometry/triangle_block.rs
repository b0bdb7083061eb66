//! Leaf triangles packed eight to a block (structure of arrays) and the
//! eight-wide edge test that filters them.
//!
//! A leaf's triangles are copied, in leaf order, into blocks of
//! [`BLOCK_WIDTH`] so that one leaf visit reads contiguous memory instead of
//! an index and then a triangle per reference, and so that the edge functions
//! of the watertight test are computed for eight triangles at once (plain
//! loops over `[f32; 8]`, which the compiler turns into SIMD: two SSE or one
//! AVX2 operation per line; see `crate::traverse::simd`).
//!
//! The block test is a filter, never a decision: it evaluates exactly the
//! floating-point operations of [`RayShear::intersect`] (same order, no fused
//! multiply-add, which Rust never contracts on its own), so a lane it rejects
//! is one the scalar test rejects; every other lane (rare: only triangles
//! whose projection holds the ray) is decided by the scalar test itself. Hits
//! are therefore bit-identical to the reference test and the brute-force
//! oracle.

use crate::traverse::level;
use glam::Vec3;

use super::indexed_block::IndexedBlock;
use super::triangle::RayShear;
use super::Triangle;

/// Triangles per block.
pub const BLOCK_WIDTH: usize = 8;

/// Up to eight triangles, coordinates by vertex, axis and lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct TriangleBlock {
    /// `v[vertex][axis][lane]`.
    pub v: [[[f32; BLOCK_WIDTH]; 3]; 3],
}

/// The triangles a run of a padded index array names (`u32::MAX` marks
/// padding), in order: what one leaf block holds, in either layout.
pub(crate) fn run_triangles(prims: &[Triangle], run: &[u32]) -> Vec<Triangle> {
    run.iter()
        .filter(|&&i| i != u32::MAX)
        .map(|&i| prims[i as usize])
        .collect()
}

impl TriangleBlock {
    /// A block of `tris` (at most eight); unused lanes are zero (and masked
    /// out by the lane count at test time).
    pub fn pack(tris: &[Triangle]) -> Self {
        assert!(tris.len() <= BLOCK_WIDTH, "{} triangles", tris.len());
        let mut v = [[[0.0; BLOCK_WIDTH]; 3]; 3];
        for (lane, t) in tris.iter().enumerate() {
            for (k, p) in t.v.iter().enumerate() {
                for axis in 0..3 {
                    v[k][axis][lane] = p[axis];
                }
            }
        }
        Self { v }
    }

    /// The triangle in `lane`, as it was packed.
    #[inline(always)]
    pub fn triangle(&self, lane: usize) -> Triangle {
        let p = |k: usize| Vec3::new(self.v[k][0][lane], self.v[k][1][lane], self.v[k][2][lane]);
        Triangle::new(p(0), p(1), p(2))
    }
}

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

/// Eight lanes of the watertight test's edge step: from the sheared
/// vertices `a`, `b`, `c` (x and y lanes), the edge functions `[u, v, w]`
/// and the mask of lanes the test may accept (bit `l` = lane `l`).
///
/// The expressions and their order are `RayShear::intersect`'s, so a lane
/// left out is one the scalar test rejects early: its edge functions are
/// non-zero with mixed signs and their sum is finite. Shared by the block
/// test (lanes = triangles) and the packet test (lanes = rays).
#[inline(always)]
pub(crate) fn edge_lanes(
    (ax, ay): ([f32; BLOCK_WIDTH], [f32; BLOCK_WIDTH]),
    (bx, by): ([f32; BLOCK_WIDTH], [f32; BLOCK_WIDTH]),
    (cx, cy): ([f32; BLOCK_WIDTH], [f32; BLOCK_WIDTH]),
) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
    let mut keep = [false; BLOCK_WIDTH];
    let mut e = [[0.0f32; BLOCK_WIDTH]; 3];
    for l in 0..BLOCK_WIDTH {
        let u = cx[l] * by[l] - cy[l] * bx[l];
        let v = ax[l] * cy[l] - ay[l] * cx[l];
        let w = bx[l] * ay[l] - by[l] * ax[l];
        (e[0][l], e[1][l], e[2][l]) = (u, v, w);
        let det = u + v + w;
        let nonzero = u != 0.0 && v != 0.0 && w != 0.0;
        let mixed = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
        keep[l] = !(nonzero && det.is_finite() && mixed);
    }
    let mut mask = 0u32;
    for (l, &k) in keep.iter().enumerate() {
        mask |= (k as u32) << l;
    }
    (mask, e)
}

/// [`edge_lanes`] in AVX2 intrinsics: the same operations lane for lane
/// (no fused multiply-add; ordered comparisons as Rust's `<`, `>`,
/// unordered `!=`), so the same edge functions and mask, with the mask from
/// one `movemask` where the compiled lane loop packed eight bools with a
/// dozen shuffles (`objdump` of the AVX2 paths).
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) fn edge_lanes_avx2(
    (ax, ay): (Lanes8, Lanes8),
    (bx, by): (Lanes8, Lanes8),
    (cx, cy): (Lanes8, Lanes8),
) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
    use std::arch::x86_64::*;
    let cross = |p: __m256, q: __m256, r: __m256, s: __m256| {
        _mm256_sub_ps(_mm256_mul_ps(p, q), _mm256_mul_ps(r, s))
    };
    let u = cross(cx, by, cy, bx);
    let v = cross(ax, cy, ay, cx);
    let w = cross(bx, ay, by, ax);
    let mut e = [[0.0f32; BLOCK_WIDTH]; 3];
    for (out, x) in e.iter_mut().zip([u, v, w]) {
        // SAFETY: eight f32.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), x) };
    }
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let zero = _mm256_setzero_ps();
    let ne = |x: __m256| _mm256_cmp_ps::<_CMP_NEQ_UQ>(x, zero);
    let lt = |x: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(x, zero);
    let gt = |x: __m256| _mm256_cmp_ps::<_CMP_GT_OQ>(x, zero);
    let nonzero = _mm256_and_ps(_mm256_and_ps(ne(u), ne(v)), ne(w));
    let some_neg = _mm256_or_ps(_mm256_or_ps(lt(u), lt(v)), lt(w));
    let some_pos = _mm256_or_ps(_mm256_or_ps(gt(u), gt(v)), gt(w));
    let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
    let finite =
        _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_and_ps(det, abs), _mm256_set1_ps(f32::INFINITY));
    let reject = _mm256_and_ps(
        _mm256_and_ps(nonzero, finite),
        _mm256_and_ps(some_neg, some_pos),
    );
    (!(_mm256_movemask_ps(reject) as u32) & 0xff, e)
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
    /// above; see `crate::traverse::level`).
    ///
    /// # Safety
    /// The CPU must have the level's instructions, and the caller must be
    /// compiled for them.
    #[inline(always)]
    pub(crate) unsafe fn indexed_edges_on<const SIMD: u8>(
        &self,
        block: IndexedBlock,
        lanes: usize,
    ) -> (u32, [[f32; BLOCK_WIDTH]; 3]) {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 {
            // SAFETY: the caller's contract (and it is compiled for AVX2:
            // `AVX2` is only set inside the AVX2 traversals).
            return unsafe { self.indexed_edges_avx2_inlined::<SIMD>(block, lanes) };
        }
        self.indexed_edges(block, lanes)
    }
}

/// One vertex moved to the ray origin and sheared, as `RayShear::sheared`
/// does, eight lanes at a time: `(p[kx] - o[kx]) - sx (p[kz] - o[kz])` and
/// the same with `ky`, `sy`. The block test puts triangles in the lanes
/// (the ray's constants broadcast), the packet test rays (the vertex
/// broadcast).
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) fn sheared_avx2(
    p: [Lanes8; 3],
    o: [Lanes8; 3],
    sx: Lanes8,
    sy: Lanes8,
) -> (Lanes8, Lanes8) {
    use std::arch::x86_64::*;
    let z = _mm256_sub_ps(p[2], o[2]);
    (
        _mm256_sub_ps(_mm256_sub_ps(p[0], o[0]), _mm256_mul_ps(sx, z)),
        _mm256_sub_ps(_mm256_sub_ps(p[1], o[1]), _mm256_mul_ps(sy, z)),
    )
}

/// Eight f32 lanes in a 256-bit register (AVX2 paths).
#[cfg(target_arch = "x86_64")]
pub(crate) type Lanes8 = std::arch::x86_64::__m256;

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
        unsafe { self.indexed_edges_avx2_inlined::<{ level::AVX2 }>(block, lanes) }
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
    pub(crate) unsafe fn indexed_edges_avx2_inlined<const SIMD: u8>(
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
    use crate::geometry::Ray;
    use crate::test_support::floats;

    #[test]
    fn pack_round_trips() {
        let mut f = floats(7);
        let tris: Vec<Triangle> = (0..5)
            .map(|_| {
                Triangle::new(
                    Vec3::new(f(), f(), f()),
                    Vec3::new(f(), f(), f()),
                    Vec3::new(f(), f(), f()),
                )
            })
            .collect();
        let b = TriangleBlock::pack(&tris);
        for (i, t) in tris.iter().enumerate() {
            assert_eq!(b.triangle(i), *t);
        }
    }

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
        if crate::traverse::simd::avx2() {
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
