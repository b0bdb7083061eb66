//! The watertight test's edge step, eight lanes at a time: shared by the
//! block test (lanes are triangles) and the packet test (lanes are rays).

#[cfg(target_arch = "x86_64")]
use crate::simd::lanes::Lanes8;
use crate::simd::lanes::{Lanes, WIDTH};

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
    (ax, ay): (Lanes, Lanes),
    (bx, by): (Lanes, Lanes),
    (cx, cy): (Lanes, Lanes),
) -> (u32, [Lanes; 3]) {
    let mut keep = [false; WIDTH];
    let mut e = [[0.0f32; WIDTH]; 3];
    for l in 0..WIDTH {
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
) -> (u32, [Lanes; 3]) {
    use std::arch::x86_64::*;
    let cross = |p: __m256, q: __m256, r: __m256, s: __m256| {
        _mm256_sub_ps(_mm256_mul_ps(p, q), _mm256_mul_ps(r, s))
    };
    let u = cross(cx, by, cy, bx);
    let v = cross(ax, cy, ay, cx);
    let w = cross(bx, ay, by, ax);
    let mut e = [[0.0f32; WIDTH]; 3];
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
