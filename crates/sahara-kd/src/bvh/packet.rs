//! Packets: up to sixteen rays walked through the hierarchy together, one
//! ray per vector lane (sixteen in an AVX-512 register, eight in an AVX2
//! one, sixteen as two AVX2 halves), then ray by ray once few of them are
//! left in a subtree: the hybrid of Embree's `rtcIntersect16` (Benthin,
//! Wald, Woop, Ernst & Mark 2012, "Combining single and packet-ray tracing
//! for arbitrary ray distributions on the Intel MIC architecture").
//!
//! **The walk.** The rays of a packet that share their direction signs (an
//! octant) walk together; a packet whose rays point into several octants
//! walks each octant's rays in turn (a camera tile almost always has one).
//! At a node each child's box is tested against all the rays at once, with
//! the single-ray walk's slab distances lane for lane
//! ([`BoxRay`](super::walk::BoxRay): the same widened boxes, the same
//! fused multiply-adds, the same NaN rules), so no ray misses a child that
//! holds its hit. The children some ray enters are visited in the node's
//! stored order for the packet's octant; those not visited next wait
//! on a stack with each ray's entry distance, and a ray takes part in a
//! child popped later only if it still enters it before its closest hit so
//! far. A leaf is tested triangle by triangle for all its rays at once:
//! each lane repeats the f32 operations of
//! [`RayShear::intersect`](crate::isect::RayShear::intersect) for its ray
//! (rays grouped by the test's axis permutation, which camera rays share),
//! and the lanes that pass finish as `RayShear::decide` does (the f64
//! plane distance, then the hit),
//! so every hit is bit-identical to the single-ray test's.
//!
//! **The switch.** A node or leaf reached by at most [`SWITCH`] of the
//! packet's rays is finished ray by ray: each of those rays walks the
//! subtree alone with the single-ray walk (its eight-wide node step), from
//! its closest hit so far. The packet pays for a node by the number of its
//! lanes, the single rays by the number of rays; see [`SWITCH`] for the
//! measurement.
//!
//! **Exactness.** Each ray ends with the smallest `(t, triangle index)` of
//! the hits found in the leaves it reached, whichever way it reached them,
//! and it reaches every leaf whose box holds a hit no farther than its
//! closest: the answers are those of [`Bvh::closest_hit`], bit for bit.

use super::node::{is_leaf, leaf_parts, ChildRef};
use super::quad::Quad;

use super::Bvh;
use crate::isect::Hit;
use crate::kd::NoCounters;
use crate::math::Ray;
use crate::simd::level;

/// Rays in a packet (its lanes).
pub(crate) const LANES: usize = 16;

/// A node or leaf that at most this many of a packet's rays reach is
/// finished ray by ray with the single-ray walk.
///
/// Measured (4x4 camera tiles of the bunny, dragon and Sponza, one thread,
/// CPU time, interleaved): 0, 1 and 2 alike within the noise, 4 slower by
/// 5-15 %, 8 by 10-30 %; one keeps a lone ray off the sixteen lanes.
pub(crate) const SWITCH: u32 = 1;

/// Sixteen floats on a cache line: one value per lane.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Row([f32; LANES]);

/// Sixteen `u32` on a cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct IntRow([u32; LANES]);

/// A packet's rays lane by lane, prepared for the box and triangle tests,
/// and their closest hits so far.
pub(crate) struct Packet {
    /// `1 / d` by axis.
    inv: [Row; 3],
    /// `near_origin * inv` and `far_origin * inv` of [`BoxRay`] by axis.
    near_oinv: [Row; 3],
    far_oinv: [Row; 3],
    /// `tmin` (`+inf` on lanes without a ray to trace).
    tmin: Row,
    /// Origins and directions by axis.
    org: [Row; 3],
    dir: [Row; 3],
    /// The watertight test's constants of each lane's ray in its own
    /// permuted frame: `o[kx]`, `o[ky]`, `o[kz]`, `dx/dz`, `dy/dz`.
    shear_o: [Row; 3],
    shear_s: [Row; 2],
    /// The closest hit so far: `t` (the ray's `tmax` while there is none),
    /// triangle (`u32::MAX`: none) and barycentrics.
    best_t: Row,
    best_tri: IntRow,
    best_u: Row,
    best_v: Row,
    /// Each lane's octant (bit `a`: negative direction along `a`).
    octant: [u8; LANES],
    /// The lanes whose watertight permutation has `kz` = 0, 1, 2.
    by_kz: [u32; 3],
    /// The lanes with a ray to trace.
    valid: u32,
}

impl Packet {
    /// Set bit `axis` of the octant of the lanes `neg` (their direction's
    /// sign is negative along `axis`).
    #[inline(always)]
    fn octant_bits_into(&mut self, axis: usize, neg: u32) {
        for l in set_bits(neg) {
            self.octant[l] |= 1 << axis;
        }
    }

    /// The closest hit of lane `l` so far, as the single-ray walk keeps it.
    #[inline(always)]
    fn best(&self, l: usize) -> Hit {
        Hit {
            t: self.best_t.0[l],
            tri: self.best_tri.0[l],
            u: self.best_u.0[l],
            v: self.best_v.0[l],
        }
    }

    /// Set lane `l`'s closest hit so far.
    #[inline(always)]
    fn set_best(&mut self, l: usize, best_t: f32, h: Hit) {
        self.best_t.0[l] = best_t;
        self.best_tri.0[l] = h.tri;
        self.best_u.0[l] = h.u;
        self.best_v.0[l] = h.v;
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

/// What a packet walk answers for each ray: its closest hit, or whether
/// it hits anything.
pub(crate) trait Answer: Sized {
    /// A lane ends at its first hit.
    const ANY: bool;
    /// The single-ray walk's answer (at the portable level).
    fn single<const SIMD: u8>(bvh: &Bvh, ray: &Ray) -> Self;
    /// Lane `l`'s answer once the packet has been walked.
    fn of(p: &Packet, l: usize) -> Self;
}

impl Answer for Option<Hit> {
    const ANY: bool = false;
    #[inline(always)]
    fn single<const SIMD: u8>(bvh: &Bvh, ray: &Ray) -> Self {
        bvh.walk_closest::<_, SIMD>(ray, &mut NoCounters)
    }
    #[inline(always)]
    fn of(p: &Packet, l: usize) -> Self {
        (p.best_tri.0[l] != u32::MAX).then(|| p.best(l))
    }
}

impl Answer for bool {
    const ANY: bool = true;
    #[inline(always)]
    fn single<const SIMD: u8>(bvh: &Bvh, ray: &Ray) -> Self {
        bvh.walk_any::<_, SIMD>(ray, &mut NoCounters)
    }
    #[inline(always)]
    fn of(p: &Packet, l: usize) -> Self {
        p.best_tri.0[l] != u32::MAX
    }
}

impl Bvh {
    /// Closest hits (`A = Option<Hit>`) or any hits (`A = bool`) of up to
    /// [`LANES`] rays traced as packets, sixteen lanes wide with `wide16`
    /// (else eight), at level `SIMD` (the single-ray walk per ray at the
    /// portable level); `out[i]` answers `rays[i]`.
    ///
    /// # Safety
    /// The CPU must have the level's instructions, and the caller must be
    /// compiled for them.
    #[inline(always)]
    pub(crate) unsafe fn trace_packet<const SIMD: u8, A: Answer>(
        &self,
        wide16: bool,
        switch: u32,
        rays: &[Ray],
        out: &mut [A],
    ) {
        #[cfg(target_arch = "x86_64")]
        if SIMD >= level::AVX2 && !self.nodes.is_empty() {
            use std::arch::x86_64::{__m256, __m512};
            // SAFETY: the level's instructions (the caller's contract).
            unsafe {
                if !wide16 || rays.len() <= 8 {
                    for (r, o) in rays.chunks(8).zip(out.chunks_mut(8)) {
                        x86::trace::<__m256, SIMD, A>(self, switch, r, o);
                    }
                } else if SIMD >= level::AVX512 {
                    x86::trace::<__m512, SIMD, A>(self, switch, rays, out);
                } else {
                    x86::trace::<x86::Pair, SIMD, A>(self, switch, rays, out);
                }
            }
            return;
        }
        let _ = (wide16, switch);
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = A::single::<SIMD>(self, r);
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod x86 {
    use std::arch::x86_64::*;

    use super::{is_leaf, leaf_parts, set_bits, ChildRef, Packet, Quad, Row, LANES};
    use crate::bvh::quad::sse::{quad_edges, QuadRay};
    use crate::bvh::walk::x86::{compact, step, Lanes};
    use crate::bvh::walk::{leaf_any, leaf_closest, BoxRay, STACK};
    use crate::bvh::Bvh;
    use crate::isect::{keep_closer, permutation, RayShear};
    use crate::kd::NoCounters;
    use crate::math::Ray;

    /// A packet's lanes in registers: sixteen in a `__m512`, eight in a
    /// `__m256`, sixteen in a [`Pair`] of them. Every operation is the
    /// scalar one lane for lane (ordered comparisons as Rust's `<`, `<=`,
    /// `>`; `min`/`max` return the second operand when the first is NaN,
    /// as `minps`/`maxps` do; no fused multiply-add but [`Wide::fmsub`]).
    ///
    /// # Safety
    /// Each form may only be used in code compiled for its instructions
    /// (AVX-512 F for `__m512`, AVX2 and FMA for the others) on a CPU
    /// that has them.
    pub(crate) trait Wide: Copy {
        /// Lanes.
        const N: usize;
        /// A truth value per lane.
        type M: Copy;
        unsafe fn splat(x: f32) -> Self;
        unsafe fn splat_u32(x: u32) -> Self;
        /// The first `N` floats of a row.
        unsafe fn load(r: *const f32) -> Self;
        unsafe fn store(self, r: *mut f32);
        unsafe fn add(self, o: Self) -> Self;
        unsafe fn sub(self, o: Self) -> Self;
        unsafe fn mul(self, o: Self) -> Self;
        /// `self * b - c`, rounded once.
        unsafe fn fmsub(self, b: Self, c: Self) -> Self;
        unsafe fn div(self, o: Self) -> Self;
        unsafe fn min(self, o: Self) -> Self;
        unsafe fn max(self, o: Self) -> Self;
        unsafe fn or(self, o: Self) -> Self;
        unsafe fn xor(self, o: Self) -> Self;
        unsafe fn le(self, o: Self) -> Self::M;
        unsafe fn lt(self, o: Self) -> Self::M;
        unsafe fn gt(self, o: Self) -> Self::M;
        /// `self != 0` (true for NaN).
        unsafe fn nonzero(self) -> Self::M;
        /// `|self| < inf`.
        unsafe fn finite(self) -> Self::M;
        /// `|self|` (for non-NaN lanes).
        #[inline(always)]
        unsafe fn abs(self) -> Self {
            unsafe { self.max(Self::splat(0.0).sub(self)) }
        }
        /// The sign bit is clear.
        unsafe fn sign_clear(self) -> Self::M;
        /// `self < o` as `u32` bit patterns.
        unsafe fn ult(self, o: Self) -> Self::M;
        unsafe fn and(a: Self::M, b: Self::M) -> Self::M;
        unsafe fn or_m(a: Self::M, b: Self::M) -> Self::M;
        unsafe fn bits(m: Self::M) -> u32;
        unsafe fn from_bits(b: u32) -> Self::M;
        /// `if m { a } else { b }` lane by lane.
        unsafe fn select(m: Self::M, a: Self, b: Self) -> Self;
        /// `((v0 - o) . n) / (d . n)` lane by lane in f64, rounded to f32:
        /// [`crate::isect::TrianglePlane::distance`]'s operations in its
        /// order (see [`plane`]). Only the lanes `want` are asked for: a
        /// half of the register none of them is in may be left undefined
        /// (its f64 division skipped).
        unsafe fn distance(
            v0: [f64; 3],
            n: [f64; 3],
            o: [Self; 3],
            d: [Self; 3],
            want: u32,
        ) -> Self;
    }

    impl Wide for __m512 {
        const N: usize = 16;
        type M = __mmask16;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            unsafe { _mm512_set1_ps(x) }
        }
        #[inline(always)]
        unsafe fn splat_u32(x: u32) -> Self {
            unsafe { _mm512_castsi512_ps(_mm512_set1_epi32(x as i32)) }
        }
        #[inline(always)]
        unsafe fn load(r: *const f32) -> Self {
            unsafe { _mm512_load_ps(r) }
        }
        #[inline(always)]
        unsafe fn store(self, r: *mut f32) {
            unsafe { _mm512_store_ps(r, self) }
        }
        #[inline(always)]
        unsafe fn add(self, o: Self) -> Self {
            unsafe { _mm512_add_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn sub(self, o: Self) -> Self {
            unsafe { _mm512_sub_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn mul(self, o: Self) -> Self {
            unsafe { _mm512_mul_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn fmsub(self, b: Self, c: Self) -> Self {
            unsafe { _mm512_fmsub_ps(self, b, c) }
        }
        #[inline(always)]
        unsafe fn div(self, o: Self) -> Self {
            unsafe { _mm512_div_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn min(self, o: Self) -> Self {
            unsafe { _mm512_min_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn max(self, o: Self) -> Self {
            unsafe { _mm512_max_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            unsafe {
                _mm512_castsi512_ps(_mm512_or_si512(
                    _mm512_castps_si512(self),
                    _mm512_castps_si512(o),
                ))
            }
        }
        #[inline(always)]
        unsafe fn xor(self, o: Self) -> Self {
            unsafe {
                _mm512_castsi512_ps(_mm512_xor_si512(
                    _mm512_castps_si512(self),
                    _mm512_castps_si512(o),
                ))
            }
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> Self::M {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self, o) }
        }
        #[inline(always)]
        unsafe fn lt(self, o: Self) -> Self::M {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self, o) }
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> Self::M {
            unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self, o) }
        }
        #[inline(always)]
        unsafe fn nonzero(self) -> Self::M {
            unsafe { _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(self, _mm512_setzero_ps()) }
        }
        #[inline(always)]
        unsafe fn finite(self) -> Self::M {
            unsafe {
                let abs = _mm512_castsi512_ps(_mm512_and_si512(
                    _mm512_castps_si512(self),
                    _mm512_set1_epi32(0x7fff_ffff),
                ));
                _mm512_cmp_ps_mask::<_CMP_LT_OQ>(abs, _mm512_set1_ps(f32::INFINITY))
            }
        }
        #[inline(always)]
        unsafe fn sign_clear(self) -> Self::M {
            unsafe { _mm512_cmpgt_epi32_mask(_mm512_castps_si512(self), _mm512_set1_epi32(-1)) }
        }
        #[inline(always)]
        unsafe fn ult(self, o: Self) -> Self::M {
            unsafe { _mm512_cmplt_epu32_mask(_mm512_castps_si512(self), _mm512_castps_si512(o)) }
        }
        #[inline(always)]
        unsafe fn and(a: Self::M, b: Self::M) -> Self::M {
            a & b
        }
        #[inline(always)]
        unsafe fn or_m(a: Self::M, b: Self::M) -> Self::M {
            a | b
        }
        #[inline(always)]
        unsafe fn bits(m: Self::M) -> u32 {
            m as u32
        }
        #[inline(always)]
        unsafe fn from_bits(b: u32) -> Self::M {
            b as __mmask16
        }
        #[inline(always)]
        unsafe fn select(m: Self::M, a: Self, b: Self) -> Self {
            unsafe { _mm512_mask_blend_ps(m, b, a) }
        }
        #[inline(always)]
        unsafe fn distance(
            v0: [f64; 3],
            n: [f64; 3],
            o: [Self; 3],
            d: [Self; 3],
            want: u32,
        ) -> Self {
            unsafe {
                // No closures: they would be compiled without the level's
                // instructions and call each intrinsic.
                let (dl, dh) = (halves512(d[0]), halves512(d[1]));
                let dz = halves512(d[2]);
                let (ol, oh) = (halves512(o[0]), halves512(o[1]));
                let oz = halves512(o[2]);
                let lo = if want & 0xff != 0 {
                    plane_t512(v0, n, [ol.0, oh.0, oz.0], [dl.0, dh.0, dz.0])
                } else {
                    _mm256_setzero_ps()
                };
                let hi = if want >> 8 & 0xff != 0 {
                    plane_t512(v0, n, [ol.1, oh.1, oz.1], [dl.1, dh.1, dz.1])
                } else {
                    _mm256_setzero_ps()
                };
                _mm512_castpd_ps(_mm512_insertf64x4::<1>(
                    _mm512_castpd256_pd512(_mm256_castps_pd(lo)),
                    _mm256_castps_pd(hi),
                ))
            }
        }
    }

    /// The low and high eight lanes of `x` in f64.
    #[inline(always)]
    unsafe fn halves512(x: __m512) -> (__m512d, __m512d) {
        unsafe {
            (
                _mm512_cvtps_pd(_mm512_castps512_ps256(x)),
                _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd::<1>(
                    _mm512_castps_pd(x),
                ))),
            )
        }
    }

    /// `((v0 - o) . n) / (d . n)` on eight f64 lanes, rounded to f32.
    #[inline(always)]
    unsafe fn plane_t512(v0: [f64; 3], n: [f64; 3], o: [__m512d; 3], d: [__m512d; 3]) -> __m256 {
        unsafe {
            let den = _mm512_add_pd(
                _mm512_add_pd(
                    _mm512_mul_pd(d[0], _mm512_set1_pd(n[0])),
                    _mm512_mul_pd(d[1], _mm512_set1_pd(n[1])),
                ),
                _mm512_mul_pd(d[2], _mm512_set1_pd(n[2])),
            );
            let a0 = _mm512_sub_pd(_mm512_set1_pd(v0[0]), o[0]);
            let a1 = _mm512_sub_pd(_mm512_set1_pd(v0[1]), o[1]);
            let a2 = _mm512_sub_pd(_mm512_set1_pd(v0[2]), o[2]);
            let num = _mm512_add_pd(
                _mm512_add_pd(
                    _mm512_mul_pd(a0, _mm512_set1_pd(n[0])),
                    _mm512_mul_pd(a1, _mm512_set1_pd(n[1])),
                ),
                _mm512_mul_pd(a2, _mm512_set1_pd(n[2])),
            );
            _mm512_cvtpd_ps(_mm512_div_pd(num, den))
        }
    }

    /// The low and high four lanes of `x` in f64.
    #[inline(always)]
    unsafe fn halves256(x: __m256) -> (__m256d, __m256d) {
        unsafe {
            (
                _mm256_cvtps_pd(_mm256_castps256_ps128(x)),
                _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(x)),
            )
        }
    }

    /// `((v0 - o) . n) / (d . n)` on four f64 lanes, rounded to f32.
    #[inline(always)]
    unsafe fn plane_t256(v0: [f64; 3], n: [f64; 3], o: [__m256d; 3], d: [__m256d; 3]) -> __m128 {
        unsafe {
            let den = _mm256_add_pd(
                _mm256_add_pd(
                    _mm256_mul_pd(d[0], _mm256_set1_pd(n[0])),
                    _mm256_mul_pd(d[1], _mm256_set1_pd(n[1])),
                ),
                _mm256_mul_pd(d[2], _mm256_set1_pd(n[2])),
            );
            let a0 = _mm256_sub_pd(_mm256_set1_pd(v0[0]), o[0]);
            let a1 = _mm256_sub_pd(_mm256_set1_pd(v0[1]), o[1]);
            let a2 = _mm256_sub_pd(_mm256_set1_pd(v0[2]), o[2]);
            let num = _mm256_add_pd(
                _mm256_add_pd(
                    _mm256_mul_pd(a0, _mm256_set1_pd(n[0])),
                    _mm256_mul_pd(a1, _mm256_set1_pd(n[1])),
                ),
                _mm256_mul_pd(a2, _mm256_set1_pd(n[2])),
            );
            _mm256_cvtpd_ps(_mm256_div_pd(num, den))
        }
    }

    impl Wide for __m256 {
        const N: usize = 8;
        type M = __m256;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            unsafe { _mm256_set1_ps(x) }
        }
        #[inline(always)]
        unsafe fn splat_u32(x: u32) -> Self {
            unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(x as i32)) }
        }
        #[inline(always)]
        unsafe fn load(r: *const f32) -> Self {
            unsafe { _mm256_load_ps(r) }
        }
        #[inline(always)]
        unsafe fn store(self, r: *mut f32) {
            unsafe { _mm256_store_ps(r, self) }
        }
        #[inline(always)]
        unsafe fn add(self, o: Self) -> Self {
            unsafe { _mm256_add_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn sub(self, o: Self) -> Self {
            unsafe { _mm256_sub_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn mul(self, o: Self) -> Self {
            unsafe { _mm256_mul_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn fmsub(self, b: Self, c: Self) -> Self {
            unsafe { _mm256_fmsub_ps(self, b, c) }
        }
        #[inline(always)]
        unsafe fn div(self, o: Self) -> Self {
            unsafe { _mm256_div_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn min(self, o: Self) -> Self {
            unsafe { _mm256_min_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn max(self, o: Self) -> Self {
            unsafe { _mm256_max_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            unsafe { _mm256_or_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn xor(self, o: Self) -> Self {
            unsafe { _mm256_xor_ps(self, o) }
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> Self::M {
            unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self, o) }
        }
        #[inline(always)]
        unsafe fn lt(self, o: Self) -> Self::M {
            unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self, o) }
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> Self::M {
            unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self, o) }
        }
        #[inline(always)]
        unsafe fn nonzero(self) -> Self::M {
            unsafe { _mm256_cmp_ps::<_CMP_NEQ_UQ>(self, _mm256_setzero_ps()) }
        }
        #[inline(always)]
        unsafe fn finite(self) -> Self::M {
            unsafe {
                let abs = _mm256_and_ps(self, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff)));
                _mm256_cmp_ps::<_CMP_LT_OQ>(abs, _mm256_set1_ps(f32::INFINITY))
            }
        }
        #[inline(always)]
        unsafe fn sign_clear(self) -> Self::M {
            unsafe {
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                    _mm256_castps_si256(self),
                    _mm256_set1_epi32(-1),
                ))
            }
        }
        #[inline(always)]
        unsafe fn ult(self, o: Self) -> Self::M {
            unsafe {
                let flip = _mm256_set1_epi32(i32::MIN);
                let a = _mm256_xor_si256(_mm256_castps_si256(self), flip);
                let b = _mm256_xor_si256(_mm256_castps_si256(o), flip);
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(b, a))
            }
        }
        #[inline(always)]
        unsafe fn and(a: Self::M, b: Self::M) -> Self::M {
            unsafe { _mm256_and_ps(a, b) }
        }
        #[inline(always)]
        unsafe fn or_m(a: Self::M, b: Self::M) -> Self::M {
            unsafe { _mm256_or_ps(a, b) }
        }
        #[inline(always)]
        unsafe fn bits(m: Self::M) -> u32 {
            unsafe { _mm256_movemask_ps(m) as u32 }
        }
        #[inline(always)]
        unsafe fn from_bits(b: u32) -> Self::M {
            unsafe {
                let sel = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let m = _mm256_and_si256(_mm256_set1_epi32(b as i32), sel);
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(m, sel))
            }
        }
        #[inline(always)]
        unsafe fn select(m: Self::M, a: Self, b: Self) -> Self {
            unsafe { _mm256_blendv_ps(b, a, m) }
        }
        #[inline(always)]
        unsafe fn distance(
            v0: [f64; 3],
            n: [f64; 3],
            o: [Self; 3],
            d: [Self; 3],
            want: u32,
        ) -> Self {
            unsafe {
                let (dl, dh) = (halves256(d[0]), halves256(d[1]));
                let dz = halves256(d[2]);
                let (ol, oh) = (halves256(o[0]), halves256(o[1]));
                let oz = halves256(o[2]);
                let lo = if want & 0xf != 0 {
                    plane_t256(v0, n, [ol.0, oh.0, oz.0], [dl.0, dh.0, dz.0])
                } else {
                    _mm_setzero_ps()
                };
                let hi = if want >> 4 & 0xf != 0 {
                    plane_t256(v0, n, [ol.1, oh.1, oz.1], [dl.1, dh.1, dz.1])
                } else {
                    _mm_setzero_ps()
                };
                _mm256_set_m128(hi, lo)
            }
        }
    }

    /// Sixteen lanes as two AVX2 halves (the sixteen-ray packet without
    /// AVX-512).
    #[derive(Clone, Copy)]
    pub(crate) struct Pair(__m256, __m256);

    /// Both halves of a [`Pair`] through one [`__m256`] operation.
    macro_rules! both {
        ($f:ident, $a:expr $(, $o:expr)*) => {
            Pair(
                <__m256 as Wide>::$f($a.0 $(, $o.0)*),
                <__m256 as Wide>::$f($a.1 $(, $o.1)*),
            )
        };
    }

    impl Wide for Pair {
        const N: usize = 16;
        type M = Pair;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            unsafe {
                let v = _mm256_set1_ps(x);
                Pair(v, v)
            }
        }
        #[inline(always)]
        unsafe fn splat_u32(x: u32) -> Self {
            unsafe {
                let v = <__m256 as Wide>::splat_u32(x);
                Pair(v, v)
            }
        }
        #[inline(always)]
        unsafe fn load(r: *const f32) -> Self {
            unsafe { Pair(_mm256_load_ps(r), _mm256_load_ps(r.add(8))) }
        }
        #[inline(always)]
        unsafe fn store(self, r: *mut f32) {
            unsafe {
                _mm256_store_ps(r, self.0);
                _mm256_store_ps(r.add(8), self.1);
            }
        }
        #[inline(always)]
        unsafe fn add(self, o: Self) -> Self {
            unsafe { both!(add, self, o) }
        }
        #[inline(always)]
        unsafe fn sub(self, o: Self) -> Self {
            unsafe { both!(sub, self, o) }
        }
        #[inline(always)]
        unsafe fn mul(self, o: Self) -> Self {
            unsafe { both!(mul, self, o) }
        }
        #[inline(always)]
        unsafe fn fmsub(self, b: Self, c: Self) -> Self {
            unsafe { both!(fmsub, self, b, c) }
        }
        #[inline(always)]
        unsafe fn div(self, o: Self) -> Self {
            unsafe { both!(div, self, o) }
        }
        #[inline(always)]
        unsafe fn min(self, o: Self) -> Self {
            unsafe { both!(min, self, o) }
        }
        #[inline(always)]
        unsafe fn max(self, o: Self) -> Self {
            unsafe { both!(max, self, o) }
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            unsafe { both!(or, self, o) }
        }
        #[inline(always)]
        unsafe fn xor(self, o: Self) -> Self {
            unsafe { both!(xor, self, o) }
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> Self::M {
            unsafe { both!(le, self, o) }
        }
        #[inline(always)]
        unsafe fn lt(self, o: Self) -> Self::M {
            unsafe { both!(lt, self, o) }
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> Self::M {
            unsafe { both!(gt, self, o) }
        }
        #[inline(always)]
        unsafe fn nonzero(self) -> Self::M {
            unsafe { both!(nonzero, self) }
        }
        #[inline(always)]
        unsafe fn finite(self) -> Self::M {
            unsafe { both!(finite, self) }
        }
        #[inline(always)]
        unsafe fn sign_clear(self) -> Self::M {
            unsafe { both!(sign_clear, self) }
        }
        #[inline(always)]
        unsafe fn ult(self, o: Self) -> Self::M {
            unsafe { both!(ult, self, o) }
        }
        #[inline(always)]
        unsafe fn and(a: Self::M, b: Self::M) -> Self::M {
            unsafe { Pair(_mm256_and_ps(a.0, b.0), _mm256_and_ps(a.1, b.1)) }
        }
        #[inline(always)]
        unsafe fn or_m(a: Self::M, b: Self::M) -> Self::M {
            unsafe { Pair(_mm256_or_ps(a.0, b.0), _mm256_or_ps(a.1, b.1)) }
        }
        #[inline(always)]
        unsafe fn bits(m: Self::M) -> u32 {
            unsafe { <__m256 as Wide>::bits(m.0) | <__m256 as Wide>::bits(m.1) << 8 }
        }
        #[inline(always)]
        unsafe fn from_bits(b: u32) -> Self::M {
            unsafe {
                Pair(
                    <__m256 as Wide>::from_bits(b & 0xff),
                    <__m256 as Wide>::from_bits(b >> 8),
                )
            }
        }
        #[inline(always)]
        unsafe fn select(m: Self::M, a: Self, b: Self) -> Self {
            unsafe {
                Pair(
                    _mm256_blendv_ps(b.0, a.0, m.0),
                    _mm256_blendv_ps(b.1, a.1, m.1),
                )
            }
        }
        #[inline(always)]
        unsafe fn distance(
            v0: [f64; 3],
            n: [f64; 3],
            o: [Self; 3],
            d: [Self; 3],
            want: u32,
        ) -> Self {
            unsafe {
                Pair(
                    <__m256 as Wide>::distance(
                        v0,
                        n,
                        [o[0].0, o[1].0, o[2].0],
                        [d[0].0, d[1].0, d[2].0],
                        want & 0xff,
                    ),
                    <__m256 as Wide>::distance(
                        v0,
                        n,
                        [o[0].1, o[1].1, o[2].1],
                        [d[0].1, d[1].1, d[2].1],
                        want >> 8 & 0xff,
                    ),
                )
            }
        }
    }

    /// A triangle's plane as [`crate::isect::TrianglePlane::new`] computes
    /// it (the same glam operations, so the same bits): its first vertex
    /// and unnormalised normal in f64.
    #[inline(always)]
    pub(crate) fn plane(q: &Quad, j: usize) -> ([f64; 3], [f64; 3]) {
        let p = |k: usize| {
            glam::DVec3::new(
                q.v[k][0][j] as f64,
                q.v[k][1][j] as f64,
                q.v[k][2][j] as f64,
            )
        };
        let v0 = p(0);
        let n = (p(1) - v0).cross(p(2) - v0);
        (v0.to_array(), n.to_array())
    }

    /// The packet walk's stack: children still to visit, the rays that
    /// entered each (bit `l` = lane `l`) and their entry distances.
    struct Stack<W> {
        refs: [std::mem::MaybeUninit<ChildRef>; STACK],
        rays: [std::mem::MaybeUninit<u32>; STACK],
        dist: [std::mem::MaybeUninit<W>; STACK],
        len: usize,
    }

    /// The packet's rays in registers for the box tests of one octant.
    struct BoxLanes<W> {
        inv: [W; 3],
        near_oinv: [W; 3],
        far_oinv: [W; 3],
        tmin: W,
        /// Offsets of each axis' near and far planes in a node's bounds.
        near: [usize; 3],
        far: [usize; 3],
    }

    /// Trace `rays` (at most `W::N`) as a packet into `out`.
    ///
    /// # Safety
    /// The level's instructions (`W`'s among them); the caller is compiled
    /// for them. `bvh` is not empty.
    #[inline(always)]
    pub(crate) unsafe fn trace<W: Wide, const SIMD: u8, A: super::Answer>(
        bvh: &Bvh,
        switch: u32,
        rays: &[Ray],
        out: &mut [A],
    ) {
        debug_assert!(rays.len() <= W::N && rays.len() == out.len());
        // SAFETY: the caller's contract.
        let p = unsafe {
            if A::ANY {
                run::<W, SIMD, true>(bvh, switch, rays)
            } else {
                run::<W, SIMD, false>(bvh, switch, rays)
            }
        };
        for (l, o) in out.iter_mut().enumerate() {
            *o = A::of(&p, l);
        }
    }

    /// The packet of `rays` walked, octant by octant; with `ANY`, a lane
    /// stops at its first hit (its `best_t` set to `-inf`, which no box
    /// and no triangle passes, and its `best_tri` to the triangle).
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn run<W: Wide, const SIMD: u8, const ANY: bool>(
        bvh: &Bvh,
        switch: u32,
        rays: &[Ray],
    ) -> Packet {
        // SAFETY: the caller's contract.
        let mut p = unsafe { packet::<W>(bvh, rays) };
        let mut todo = p.valid;
        while todo != 0 {
            let octant = p.octant[todo.trailing_zeros() as usize];
            let mut group = 0;
            for l in set_bits(todo) {
                group |= ((p.octant[l] == octant) as u32) << l;
            }
            todo &= !group;
            // SAFETY: the caller's contract.
            unsafe { walk::<W, SIMD, ANY>(bvh, &mut p, rays, switch, group, octant as u32) };
        }
        p
    }

    /// The packet of `rays` (at most `W::N`) for `bvh`: each lane
    /// holds [`BoxRay::new`]'s and [`RayShear::new`]'s values for its ray
    /// (the same operations, so the same bits), computed for all lanes at
    /// once after one transposition of the rays into rows; lanes without a
    /// valid ray hold zeros, `tmin = +inf` and `best_t = -inf`.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    pub(super) unsafe fn packet<W: Wide>(bvh: &Bvh, rays: &[Ray]) -> Packet {
        debug_assert!(rays.len() <= W::N);
        let z = Row([0.0; LANES]);
        // Origin, direction, tmin, tmax: eight rows.
        let mut raw = [z; 8];
        for (l, ray) in rays.iter().enumerate() {
            let f = [
                ray.origin.x,
                ray.origin.y,
                ray.origin.z,
                ray.dir.x,
                ray.dir.y,
                ray.dir.z,
                ray.tmin,
                ray.tmax,
            ];
            for k in 0..8 {
                raw[k].0[l] = f[k];
            }
        }
        let mut p = Packet {
            inv: [z; 3],
            near_oinv: [z; 3],
            far_oinv: [z; 3],
            tmin: Row([f32::INFINITY; LANES]),
            org: [z; 3],
            dir: [z; 3],
            shear_o: [z; 3],
            shear_s: [z; 2],
            best_t: Row([f32::NEG_INFINITY; LANES]),
            best_tri: super::IntRow([u32::MAX; LANES]),
            best_u: z,
            best_v: z,
            octant: [0; LANES],
            by_kz: [0; 3],
            valid: 0,
        };
        // SAFETY: the caller's contract; rows are 64-byte aligned.
        unsafe {
            let o = [ld::<W>(&raw[0]), ld::<W>(&raw[1]), ld::<W>(&raw[2])];
            let d = [ld::<W>(&raw[3]), ld::<W>(&raw[4]), ld::<W>(&raw[5])];
            let (tmin, tmax) = (ld::<W>(&raw[6]), ld::<W>(&raw[7]));
            let zero = W::splat(0.0);
            let all = (1u32 << rays.len()) - 1;
            // `Ray::is_valid` and `tmin <= tmax` (no NaN passes `<=`).
            let finite = W::and(
                W::and(W::and(o[0].finite(), o[1].finite()), o[2].finite()),
                W::and(W::and(d[0].finite(), d[1].finite()), d[2].finite()),
            );
            let nonzero = W::or_m(W::or_m(d[0].nonzero(), d[1].nonzero()), d[2].nonzero());
            let interval = W::and(zero.le(tmin), tmin.le(tmax));
            let valid = W::bits(W::and(W::and(finite, nonzero), interval)) & all;
            p.valid = valid;
            let vm = W::from_bits(valid);
            // `BoxRay::new`.
            let pad = o[0]
                .abs()
                .max(o[1].abs().max(o[2].abs()))
                .add(W::splat(bvh.scale))
                .mul(W::splat(crate::bvh::walk::PAD));
            let neg_pad = zero.sub(pad);
            for a in 0..3 {
                let pos = d[a].sign_clear();
                p.octant_bits_into(a, !W::bits(pos) & valid);
                let inv = W::splat(1.0).div(d[a]);
                let toward = W::select(pos, pad, neg_pad);
                let near = o[a].add(toward);
                let far = o[a].sub(toward);
                sel0::<W>(vm, inv).store(p.inv[a].0.as_mut_ptr());
                sel0::<W>(vm, near.mul(inv)).store(p.near_oinv[a].0.as_mut_ptr());
                sel0::<W>(vm, far.mul(inv)).store(p.far_oinv[a].0.as_mut_ptr());
                sel0::<W>(vm, o[a]).store(p.org[a].0.as_mut_ptr());
                sel0::<W>(vm, d[a]).store(p.dir[a].0.as_mut_ptr());
            }
            W::select(vm, tmin, W::splat(f32::INFINITY)).store(p.tmin.0.as_mut_ptr());
            W::select(vm, tmax, W::splat(f32::NEG_INFINITY)).store(p.best_t.0.as_mut_ptr());
            // `RayShear::new`: the dominant axis (`x >= y && x >= z`, else
            // `y >= z`), its sign, the permutation.
            let ad = [d[0].abs(), d[1].abs(), d[2].abs()];
            let x_wins = W::bits(ad[1].le(ad[0])) & W::bits(ad[2].le(ad[0]));
            let y_ge_z = W::bits(ad[2].le(ad[1]));
            let kz = [x_wins, !x_wins & y_ge_z, !x_wins & !y_ge_z];
            let dz = pick::<W>(kz, d);
            let neg = W::bits(dz.lt(zero));
            // `kx`, `ky` follow `kz` cyclically, swapped when negative.
            let (kz0, kz1, kz2) = (kz[0], kz[1], kz[2]);
            let kx = [
                (kz2 & !neg) | (kz1 & neg),
                (kz0 & !neg) | (kz2 & neg),
                (kz1 & !neg) | (kz0 & neg),
            ];
            let ky = [
                (kz1 & !neg) | (kz2 & neg),
                (kz2 & !neg) | (kz0 & neg),
                (kz0 & !neg) | (kz1 & neg),
            ];
            sel0::<W>(vm, pick::<W>(kx, o)).store(p.shear_o[0].0.as_mut_ptr());
            sel0::<W>(vm, pick::<W>(ky, o)).store(p.shear_o[1].0.as_mut_ptr());
            sel0::<W>(vm, pick::<W>(kz, o)).store(p.shear_o[2].0.as_mut_ptr());
            sel0::<W>(vm, pick::<W>(kx, d).div(dz)).store(p.shear_s[0].0.as_mut_ptr());
            sel0::<W>(vm, pick::<W>(ky, d).div(dz)).store(p.shear_s[1].0.as_mut_ptr());
            p.by_kz = [kz0 & valid, kz1 & valid, kz2 & valid];
        }
        p
    }

    /// `x` on the lanes `m`, zero on the others.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn sel0<W: Wide>(m: W::M, x: W) -> W {
        unsafe { W::select(m, x, W::splat(0.0)) }
    }

    /// Lane by lane, `v[0]` on the lanes `m[0]`, else `v[1]` on the lanes
    /// `m[1]`, else `v[2]`.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn pick<W: Wide>(m: [u32; 3], v: [W; 3]) -> W {
        unsafe {
            W::select(
                W::from_bits(m[0]),
                v[0],
                W::select(W::from_bits(m[1]), v[1], v[2]),
            )
        }
    }

    /// The rays `group` of `p`, all in `octant`, through the hierarchy.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn walk<W: Wide, const SIMD: u8, const ANY: bool>(
        bvh: &Bvh,
        p: &mut Packet,
        rays: &[Ray],
        switch: u32,
        group: u32,
        octant: u32,
    ) {
        // SAFETY: the caller's contract; rows are 64-byte aligned; child
        // references name nodes and leaves the build wrote.
        unsafe {
            let b = BoxLanes {
                inv: [ld::<W>(&p.inv[0]), ld::<W>(&p.inv[1]), ld::<W>(&p.inv[2])],
                near_oinv: [
                    ld::<W>(&p.near_oinv[0]),
                    ld::<W>(&p.near_oinv[1]),
                    ld::<W>(&p.near_oinv[2]),
                ],
                far_oinv: [
                    ld::<W>(&p.far_oinv[0]),
                    ld::<W>(&p.far_oinv[1]),
                    ld::<W>(&p.far_oinv[2]),
                ],
                tmin: ld::<W>(&p.tmin),
                near: [0, 1, 2].map(|a| 16 * a + 8 * (octant >> a & 1) as usize),
                far: [0, 1, 2].map(|a| 16 * a + 8 * (!octant >> a & 1) as usize),
            };
            let mut stack: Stack<W> = Stack {
                refs: [const { std::mem::MaybeUninit::uninit() }; STACK],
                rays: [const { std::mem::MaybeUninit::uninit() }; STACK],
                dist: [const { std::mem::MaybeUninit::uninit() }; STACK],
                len: 0,
            };
            let mut c: ChildRef = 0;
            let mut active = group;
            loop {
                if active.count_ones() <= switch {
                    for l in set_bits(active) {
                        single::<SIMD, ANY>(bvh, p, rays, l, c);
                    }
                } else if is_leaf(c) {
                    leaf::<W, ANY>(bvh, p, rays, c, active, octant);
                } else {
                    let n = bvh.node(c);
                    if let Some((next, rays_next)) =
                        node_step::<W>(n, &b, p, active, octant, &mut stack)
                    {
                        c = next;
                        active = rays_next;
                        continue;
                    }
                }
                // The next child on the stack that some ray still enters
                // before its closest hit so far.
                loop {
                    if stack.len == 0 {
                        return;
                    }
                    stack.len -= 1;
                    let i = stack.len;
                    let t = stack.dist.get_unchecked(i).assume_init();
                    let best = ld::<W>(&p.best_t);
                    active = stack.rays.get_unchecked(i).assume_init() & W::bits(t.le(best));
                    if active != 0 {
                        c = stack.refs.get_unchecked(i).assume_init();
                        break;
                    }
                }
            }
        }
    }

    /// One node step for the rays `active`: the children some ray enters
    /// before its closest hit so far, the nearest returned with its rays,
    /// the others pushed far to near; `None` when no ray enters any.
    ///
    /// The order is the node's own for the rays' octant (the single-ray
    /// walk's): all eight boxes are tested first, without a branch per
    /// child, and no distance is reduced across the lanes to sort them
    /// (measured faster on camera tiles than ordering by each child's
    /// smallest entry distance among the rays).
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn node_step<W: Wide>(
        n: &crate::bvh::node::WideNode,
        b: &BoxLanes<W>,
        p: &Packet,
        active: u32,
        octant: u32,
        stack: &mut Stack<W>,
    ) -> Option<(ChildRef, u32)> {
        // SAFETY: the caller's contract; the node's bounds are 48 floats.
        unsafe {
            // Lanes not taking part end every slab test at -inf.
            let tfar = W::select(
                W::from_bits(active),
                W::load(p.best_t.0.as_ptr()),
                W::splat(f32::NEG_INFINITY),
            );
            let bounds = n.bounds.as_ptr() as *const f32;
            let mut masks = [0u32; 8];
            let mut dists = [std::mem::MaybeUninit::<W>::uninit(); 8];
            let mut hit = 0u32;
            // Unused slots hold the empty box, which no ray enters (as in
            // the single-ray step).
            for slot in 0..8 {
                // The running interval is the second operand: a NaN slab
                // distance leaves it as it is (as the single-ray walk).
                let near = [
                    W::splat(*bounds.add(b.near[0] + slot)).fmsub(b.inv[0], b.near_oinv[0]),
                    W::splat(*bounds.add(b.near[1] + slot)).fmsub(b.inv[1], b.near_oinv[1]),
                    W::splat(*bounds.add(b.near[2] + slot)).fmsub(b.inv[2], b.near_oinv[2]),
                ];
                let far = [
                    W::splat(*bounds.add(b.far[0] + slot)).fmsub(b.inv[0], b.far_oinv[0]),
                    W::splat(*bounds.add(b.far[1] + slot)).fmsub(b.inv[1], b.far_oinv[1]),
                    W::splat(*bounds.add(b.far[2] + slot)).fmsub(b.inv[2], b.far_oinv[2]),
                ];
                let tn = near[0].max(near[1].max(near[2].max(b.tmin)));
                let tf = far[0].min(far[1].min(far[2].min(tfar)));
                let bits = W::bits(tn.le(tf));
                *masks.get_unchecked_mut(slot) = bits;
                dists.get_unchecked_mut(slot).write(tn);
                hit |= ((bits != 0) as u32) << slot;
            }
            if hit == 0 {
                return None;
            }
            if hit & (hit - 1) == 0 {
                let slot = hit.trailing_zeros() as usize;
                return Some((*n.child.get_unchecked(slot), masks[slot]));
            }
            // Far to near, so that the nearest ends on top.
            for i in 0..8 {
                let slot = n.slot_in_order(i, octant);
                if hit >> slot & 1 == 1 {
                    let at = stack.len;
                    debug_assert!(at < STACK);
                    stack
                        .refs
                        .get_unchecked_mut(at)
                        .write(*n.child.get_unchecked(slot));
                    stack
                        .rays
                        .get_unchecked_mut(at)
                        .write(*masks.get_unchecked(slot));
                    *stack.dist.get_unchecked_mut(at) = *dists.get_unchecked(slot);
                    stack.len += 1;
                }
            }
            stack.len -= 1;
            let top = stack.len;
            Some((
                stack.refs.get_unchecked(top).assume_init(),
                stack.rays.get_unchecked(top).assume_init(),
            ))
        }
    }

    /// Leaf `c` for the rays `active` (all in `octant`): each triangle
    /// against all of them at once, rays grouped by the watertight test's
    /// permutation.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn leaf<W: Wide, const ANY: bool>(
        bvh: &Bvh,
        p: &mut Packet,
        rays: &[Ray],
        c: ChildRef,
        active: u32,
        octant: u32,
    ) {
        let (line, count) = leaf_parts(c);
        // SAFETY: leaf references name leaves the build wrote.
        let q = unsafe { bvh.quad(line) };
        for kz in 0..3 {
            let m = p.by_kz[kz] & active;
            if m == 0 {
                continue;
            }
            let k = permutation(kz, octant >> kz & 1 == 1);
            for j in 0..count {
                // SAFETY: the caller's contract.
                unsafe { triangle::<W, ANY>(p, rays, q, j, k, m) };
            }
        }
    }

    /// Row `r`'s first `W::N` lanes.
    ///
    /// # Safety
    /// As [`trace`]. (Helpers are functions, not closures: a closure is
    /// compiled without the level's instructions and would call every
    /// intrinsic in it.)
    #[inline(always)]
    unsafe fn ld<W: Wide>(r: &Row) -> W {
        unsafe { W::load(r.0.as_ptr()) }
    }

    /// `RayShear::intersect`'s `a[kx] - s.x * a[kz]` and `a[ky] - s.y *
    /// a[kz]` with `a = v - origin`, for vertex `k` of triangle `j` of `q`,
    /// lane by lane.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn sheared<W: Wide>(
        q: &Quad,
        k: usize,
        j: usize,
        [kx, ky, kz]: [usize; 3],
        [ox, oy, oz]: [W; 3],
        [sx, sy]: [W; 2],
    ) -> (W, W) {
        unsafe {
            let v = &q.v[k];
            let z = W::splat(v[kz][j]).sub(oz);
            (
                W::splat(v[kx][j]).sub(ox).sub(sx.mul(z)),
                W::splat(v[ky][j]).sub(oy).sub(sy.mul(z)),
            )
        }
    }

    /// Triangle `j` of `q` against the rays `m`, whose watertight
    /// permutation is `k`: [`RayShear::intersect`] lane by lane, the
    /// closest hits updated as [`keep_closer`] does.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn triangle<W: Wide, const ANY: bool>(
        p: &mut Packet,
        rays: &[Ray],
        q: &Quad,
        j: usize,
        [kx, ky, kz]: [usize; 3],
        m: u32,
    ) {
        // SAFETY: the caller's contract; rows are 64-byte aligned.
        unsafe {
            let o = [
                ld::<W>(&p.shear_o[0]),
                ld::<W>(&p.shear_o[1]),
                ld::<W>(&p.shear_o[2]),
            ];
            let s = [ld::<W>(&p.shear_s[0]), ld::<W>(&p.shear_s[1])];
            let (ax, ay) = sheared::<W>(q, 0, j, [kx, ky, kz], o, s);
            let (bx, by) = sheared::<W>(q, 1, j, [kx, ky, kz], o, s);
            let (cx, cy) = sheared::<W>(q, 2, j, [kx, ky, kz], o, s);
            let u = cx.mul(by).sub(cy.mul(bx));
            let v = ax.mul(cy).sub(ay.mul(cx));
            let w = bx.mul(ay).sub(by.mul(ax));
            let det = u.add(v).add(w);
            // Non-zero and finite (a finite sum means finite terms): the
            // f32 test decides, and accepts when the signs agree.
            let normal = W::and(
                W::and(u.nonzero(), v.nonzero()),
                W::and(w.nonzero(), det.finite()),
            );
            let normal = W::bits(normal);
            let same = W::bits(u.xor(v).or(u.xor(w)).sign_clear());
            let fast = normal & same & m;
            let slow = !normal & m;
            if fast != 0 {
                let (v0, n) = plane(q, j);
                let o = [ld::<W>(&p.org[0]), ld::<W>(&p.org[1]), ld::<W>(&p.org[2])];
                let d = [ld::<W>(&p.dir[0]), ld::<W>(&p.dir[1]), ld::<W>(&p.dir[2])];
                let t = W::distance(v0, n, o, d, fast);
                let best = ld::<W>(&p.best_t);
                let tri = q.tri[j];
                let best_tri = W::load(p.best_tri.0.as_ptr() as *const f32);
                // As `decide_in_plane`, then `keep_closer`.
                let inside = W::and(t.gt(ld::<W>(&p.tmin)), t.le(best));
                let closer = W::or_m(t.lt(best), W::splat_u32(tri).ult(best_tri));
                let upd = W::bits(W::and(inside, closer)) & fast;
                if upd != 0 && ANY {
                    // A lane that hits anything is done.
                    let um = W::from_bits(upd);
                    W::select(um, W::splat(f32::NEG_INFINITY), best).store(p.best_t.0.as_mut_ptr());
                    W::select(um, W::splat_u32(tri), best_tri)
                        .store(p.best_tri.0.as_mut_ptr() as *mut f32);
                } else if upd != 0 {
                    let um = W::from_bits(upd);
                    let rcp = W::splat(1.0).div(det);
                    W::select(um, t.add(W::splat(0.0)), best).store(p.best_t.0.as_mut_ptr());
                    W::select(um, W::splat_u32(tri), best_tri)
                        .store(p.best_tri.0.as_mut_ptr() as *mut f32);
                    let bu = ld::<W>(&p.best_u);
                    let bv = ld::<W>(&p.best_v);
                    W::select(um, v.mul(rcp), bu).store(p.best_u.0.as_mut_ptr());
                    W::select(um, w.mul(rcp), bv).store(p.best_v.0.as_mut_ptr());
                }
            }
            // An edge function exactly zero or an overflow: the scalar test
            // (its f64 path), ray by ray.
            for l in set_bits(slow) {
                let s = RayShear::from_ray(rays.get_unchecked(l));
                let mut best_t = p.best_t.0[l];
                if let Some(h) = s.intersect(&q.triangle(j), p.tmin.0[l], best_t) {
                    if ANY {
                        p.best_t.0[l] = f32::NEG_INFINITY;
                        p.best_tri.0[l] = q.tri[j];
                        continue;
                    }
                    let mut best = p.best(l);
                    keep_closer(&mut best_t, &mut best, h, q.tri[j]);
                    p.set_best(l, best_t, best);
                }
            }
        }
    }

    /// Lane `l`'s ray through the subtree of `c` alone, from its closest
    /// hit so far, with the single-ray walk (`Bvh::walk_closest`'s loop
    /// from a node other than the root); with `ANY`, `Bvh::walk_any`'s
    /// loop, a hit ending the lane as [`run`] says.
    ///
    /// # Safety
    /// As [`trace`].
    #[inline(always)]
    unsafe fn single<const SIMD: u8, const ANY: bool>(
        bvh: &Bvh,
        p: &mut Packet,
        rays: &[Ray],
        l: usize,
        c: ChildRef,
    ) {
        // SAFETY: the caller's contract; `l` is a lane of a ray.
        unsafe {
            let ray = rays.get_unchecked(l);
            let r = BoxRay::new(ray, bvh.scale);
            let shear = RayShear::from_ray(ray);
            let qr = QuadRay::new(&shear);
            let edges = |q: &Quad, n| quad_edges(&qr, q, n);
            let mut best_t = p.best_t.0[l];
            let mut best = p.best(l);
            let mut stack = crate::bvh::walk::Stack::new();
            let lanes = Lanes::new(&r);
            let mut tfar = _mm256_set1_ps(best_t);
            let mut c = c;
            'walk: loop {
                while !is_leaf(c) {
                    // Occlusion rays take the children in slot order.
                    let next = if ANY {
                        step::<SIMD, false>(bvh.node(c), &lanes, tfar, &mut stack)
                    } else {
                        step::<SIMD, true>(bvh.node(c), &lanes, tfar, &mut stack)
                    };
                    match next {
                        Some(next) => c = next,
                        None => match stack.pop() {
                            Some((next, _)) => c = next,
                            None => break 'walk,
                        },
                    }
                }
                if ANY {
                    if leaf_any(bvh, c, edges, &shear, ray.tmin, ray.tmax, &mut NoCounters) {
                        best_t = f32::NEG_INFINITY;
                        // Any triangle index but `u32::MAX`: the lane hit.
                        best.tri = 0;
                        break;
                    }
                } else if leaf_closest(
                    bvh,
                    c,
                    edges,
                    &shear,
                    ray.tmin,
                    &mut best_t,
                    &mut best,
                    &mut NoCounters,
                ) {
                    tfar = _mm256_set1_ps(best_t);
                    compact::<SIMD>(&mut stack, best_t);
                }
                match stack.pop() {
                    Some((next, _)) => c = next,
                    None => break,
                }
            }
            p.set_best(l, best_t, best);
        }
    }

    const _: () = assert!(LANES == 16);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brute;
    use crate::bvh::batch::PacketQuery;
    use crate::bvh::{BvhBuilder, BvhParams};
    use crate::math::Triangle;
    use crate::simd::dispatch;
    use crate::test_support::{floats, soup};
    use glam::Vec3;

    /// A hit's bits (so that `-0.0` differs from `0.0`).
    fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
        h.map(|h| (h.t.to_bits(), h.tri, h.u.to_bits(), h.v.to_bits()))
    }

    /// A random soup and a closed grid of shared edges and vertices (some
    /// of it axis-aligned, some of it degenerate).
    fn scene(f: &mut impl FnMut() -> f32) -> Vec<Triangle> {
        let mut tris = soup(f, 1500, 0.6);
        let at = |i: i32, j: i32| Vec3::new(i as f32 * 0.5 - 3.0, j as f32 * 0.5 - 3.0, 0.25);
        for i in 0..12 {
            for j in 0..12 {
                tris.push(Triangle::new(at(i, j), at(i + 1, j), at(i + 1, j + 1)));
                tris.push(Triangle::new(at(i, j), at(i + 1, j + 1), at(i, j + 1)));
            }
        }
        // Repeated triangles (ties of `t` decided by the index) and
        // degenerate ones (a point, a segment).
        for k in 0..40 {
            tris.push(tris[k * 7]);
        }
        let c = Vec3::new(0.5, 0.5, 0.5);
        tris.push(Triangle::new(c, c, c));
        tris.push(Triangle::new(c, c + Vec3::X, c + 2.0 * Vec3::X));
        tris
    }

    /// Packets of every kind: camera-like tiles (a shared eye, nearby
    /// directions), incoherent rays (random origins and directions), rays
    /// along the axes with zero (and negative zero) direction components
    /// from vertex coordinates, rays through vertices and edge midpoints,
    /// mixed `tmin`/`tmax`, invalid rays; one to sixteen rays.
    fn packet(f: &mut impl FnMut() -> f32, tris: &[Triangle], p: usize) -> Vec<Ray> {
        let n = if p.is_multiple_of(3) {
            1 + p % LANES
        } else {
            LANES
        };
        let eye = Vec3::new(f(), f(), -6.0) * 0.5;
        let aim = Vec3::new(f() * 0.3, f() * 0.3, 1.0);
        let spread = [0.002, 0.03, 0.3][p % 3];
        let mut rays: Vec<Ray> = (0..n)
            .map(|k| {
                let (x, y) = ((k % 4) as f32, (k / 4) as f32);
                Ray::new(eye, aim + Vec3::new(x, y, 0.0) * spread)
            })
            .collect();
        match p % 8 {
            0 => {
                // Incoherent: random origins and directions (every octant).
                for r in &mut rays {
                    *r = Ray::new(Vec3::new(f(), f(), f()) * 5.0, Vec3::new(f(), f(), f()));
                }
            }
            1 => {
                // Along an axis, from vertex coordinates: slab distances of
                // `0 * inf`, origins on box faces.
                let axis = p / 8 % 3;
                for (k, r) in rays.iter_mut().enumerate() {
                    let v = tris[(p * 31 + k * 7) % tris.len()].v[k % 3];
                    let mut d = Vec3::ZERO;
                    if p % 16 == 1 {
                        d = Vec3::splat(-0.0);
                    }
                    d[axis] = if k % 2 == 0 { 1.0 } else { -1.0 };
                    let mut o = v;
                    o[axis] = if k % 2 == 0 { -6.0 } else { 6.0 };
                    *r = Ray::new(o, d);
                }
            }
            2 => {
                // From the eye exactly at vertices and edge midpoints.
                for (k, r) in rays.iter_mut().enumerate() {
                    let t = &tris[(p * 17 + k / 3) % tris.len()];
                    r.dir = if k % 2 == 0 {
                        t.v[k % 3]
                    } else {
                        (t.v[k % 3] + t.v[(k + 1) % 3]) * 0.5
                    } - eye;
                }
            }
            3 => {
                // Down onto the grid's vertices and edges, some of them
                // tilted by a zero-sign component.
                for (k, r) in rays.iter_mut().enumerate() {
                    let (i, j) = ((p + k) % 12, (p / 3 + k * 5) % 12);
                    let x = i as f32 * 0.5 - 3.0 + if k % 3 == 0 { 0.25 } else { 0.0 };
                    let y = j as f32 * 0.5 - 3.0;
                    *r = Ray::new(Vec3::new(x, y, 3.0), Vec3::new(0.0, -0.0, -1.0));
                }
            }
            4 => {
                // Mixed intervals.
                for (k, r) in rays.iter_mut().enumerate() {
                    r.tmin = [0.0, 2.0, 5.5, 0.0][k % 4];
                    r.tmax = [f32::INFINITY, 7.0, 6.5, 5.0][k / 4 % 4];
                }
            }
            5 => {
                // Invalid rays among valid ones.
                let bad = [
                    Ray::new(eye, Vec3::ZERO),
                    Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z),
                    Ray::new(eye, Vec3::new(0.0, f32::INFINITY, 1.0)),
                    Ray::with_interval(eye, Vec3::Z, -1.0, 9.0),
                    Ray::with_interval(eye, Vec3::Z, 5.0, 4.0),
                    Ray::with_interval(eye, Vec3::Z, 0.0, f32::NAN),
                ];
                for (k, r) in rays.iter_mut().enumerate().step_by(3) {
                    *r = bad[(k / 3 + p) % bad.len()];
                }
            }
            6 => {
                // Two octants in one tile: half the rays look back.
                for r in rays.iter_mut().skip(n / 2) {
                    r.dir.x = -r.dir.x - 0.01;
                }
            }
            _ => {}
        }
        rays
    }

    /// Every level, both packet widths, with and without the switch to
    /// single rays: every ray's answer is brute force's, bit for bit, on
    /// every builder.
    #[test]
    fn packets_agree_with_brute_force() {
        let mut f = floats(1616);
        let tris = scene(&mut f);
        for builder in [BvhBuilder::Binned, BvhBuilder::Spatial, BvhBuilder::FromKd] {
            let bvh = Bvh::build(tris.clone(), &BvhParams::new(builder));
            let mut hits = 0;
            for p in 0..600 {
                let rays = packet(&mut f, &tris, p);
                let want: Vec<_> = rays
                    .iter()
                    .map(|r| bits(brute::closest_hit(&tris, r)))
                    .collect();
                hits += want.iter().filter(|h| h.is_some()).count();
                let mut out = vec![None; rays.len()];
                bvh.closest_hit_packet16(&rays, &mut out);
                assert_eq!(
                    out.iter().map(|&h| bits(h)).collect::<Vec<_>>(),
                    want,
                    "{builder:?} packet {p}"
                );
                for top in [level::PORTABLE, level::AVX2, level::AVX512] {
                    for wide16 in [false, true] {
                        for switch in [0, SWITCH, 8] {
                            out.fill(None);
                            for (r, o) in rays
                                .chunks(if wide16 { 16 } else { 8 })
                                .zip(out.chunks_mut(if wide16 { 16 } else { 8 }))
                            {
                                let q = PacketQuery {
                                    bvh: &bvh,
                                    wide16,
                                    switch,
                                    rays: r,
                                    out: o,
                                };
                                dispatch(top, q);
                            }
                            let got: Vec<_> = out.iter().map(|&h| bits(h)).collect();
                            assert_eq!(
                                got, want,
                                "{builder:?} packet {p} level {top} wide16 {wide16} switch {switch}"
                            );
                        }
                    }
                }
            }
            assert!(hits > 2000, "{hits} hits");
        }
    }

    /// The any-hit packet walk, at every level, both widths, with and
    /// without the switch to single rays: every ray's answer is brute
    /// force's, on every builder.
    #[test]
    fn any_hit_packets_agree_with_brute_force() {
        let mut f = floats(1717);
        let tris = scene(&mut f);
        for builder in [BvhBuilder::Binned, BvhBuilder::Spatial, BvhBuilder::FromKd] {
            let bvh = Bvh::build(tris.clone(), &BvhParams::new(builder));
            let (mut hit, mut missed) = (0, 0);
            for p in 0..600 {
                let rays = packet(&mut f, &tris, p);
                let want: Vec<bool> = rays.iter().map(|r| brute::any_hit(&tris, r)).collect();
                hit += want.iter().filter(|&&h| h).count();
                missed += want.iter().filter(|&&h| !h).count();
                let mut out = vec![false; rays.len()];
                bvh.any_hit_packet16(&rays, &mut out);
                assert_eq!(out, want, "{builder:?} packet {p}");
                for top in [level::PORTABLE, level::AVX2, level::AVX512] {
                    for wide16 in [false, true] {
                        for switch in [0, SWITCH, 8] {
                            out.fill(false);
                            let q = PacketQuery {
                                bvh: &bvh,
                                wide16,
                                switch,
                                rays: &rays,
                                out: &mut out,
                            };
                            dispatch(top, q);
                            assert_eq!(
                                out, want,
                                "{builder:?} packet {p} level {top} wide16 {wide16} switch {switch}"
                            );
                        }
                    }
                }
            }
            assert!(hit > 2000 && missed > 500, "{hit} hit, {missed} missed");
        }
    }

    /// The eight-ray entry point takes up to eight rays, and answers as
    /// the sixteen-ray one; an empty hierarchy answers nothing.
    #[test]
    fn eight_ray_packets_and_empty_hierarchies() {
        let mut f = floats(88);
        let tris = scene(&mut f);
        let bvh = Bvh::build(tris.clone(), &BvhParams::default());
        for p in 0..200 {
            let rays = packet(&mut f, &tris, p);
            let rays = &rays[..rays.len().min(8)];
            let mut out = vec![None; rays.len()];
            bvh.closest_hit_packet(rays, &mut out);
            for (r, o) in rays.iter().zip(&out) {
                assert_eq!(bits(*o), bits(brute::closest_hit(&tris, r)), "packet {p}");
            }
        }
        let empty = Bvh::build(Vec::new(), &BvhParams::default());
        let rays = [Ray::new(Vec3::ZERO, Vec3::X); 16];
        let mut out = [Some(Hit {
            t: 1.0,
            tri: 0,
            u: 0.0,
            v: 0.0,
        }); 16];
        empty.closest_hit_packet16(&rays, &mut out);
        assert!(out.iter().all(|h| h.is_none()));
    }

    /// Lane `l` of a packet holds its ray's single-ray set-up
    /// (`BoxRay::new`, `RayShear::new`) bit for bit, and lanes without a
    /// valid ray hold no ray.
    fn assert_set_up(bvh: &Bvh, rays: &[Ray], p: &Packet, what: &str) {
        use crate::bvh::walk::BoxRay;
        use crate::isect::RayShear;
        let b = |x: f32| x.to_bits();
        for (l, ray) in rays.iter().enumerate() {
            let valid = ray.is_valid() && ray.tmin <= ray.tmax;
            assert_eq!(p.valid >> l & 1 == 1, valid, "{what} lane {l} {ray:?}");
            if !valid {
                assert_eq!(p.tmin.0[l], f32::INFINITY, "{what} lane {l}");
                assert_eq!(p.best_t.0[l], f32::NEG_INFINITY, "{what} lane {l}");
                assert!((0..3).all(|k| p.by_kz[k] >> l & 1 == 0), "{what} lane {l}");
                continue;
            }
            let r = BoxRay::new(ray, bvh.scale);
            let s = RayShear::from_ray(ray);
            for a in 0..3 {
                assert_eq!(b(p.inv[a].0[l]), b(r.inv[a]), "{what} lane {l} inv {a}");
                let near = r.near_origin[a] * r.inv[a];
                let far = r.far_origin[a] * r.inv[a];
                assert_eq!(b(p.near_oinv[a].0[l]), b(near), "{what} lane {l} near {a}");
                assert_eq!(b(p.far_oinv[a].0[l]), b(far), "{what} lane {l} far {a}");
                assert_eq!(b(p.org[a].0[l]), b(ray.origin[a]), "{what} lane {l}");
                assert_eq!(b(p.dir[a].0[l]), b(ray.dir[a]), "{what} lane {l}");
                let o = ray.origin[s.k[a]];
                assert_eq!(b(p.shear_o[a].0[l]), b(o), "{what} lane {l} shear o {a}");
            }
            assert_eq!(b(p.shear_s[0].0[l]), b(s.s.x), "{what} lane {l} shear x");
            assert_eq!(b(p.shear_s[1].0[l]), b(s.s.y), "{what} lane {l} shear y");
            assert_eq!(b(p.tmin.0[l]), b(ray.tmin), "{what} lane {l}");
            assert_eq!(b(p.best_t.0[l]), b(ray.tmax), "{what} lane {l}");
            assert_eq!(p.best_tri.0[l], u32::MAX, "{what} lane {l}");
            assert_eq!(p.octant[l] as u32, r.octant, "{what} lane {l} octant");
            assert_eq!(p.by_kz[s.k[2]] >> l & 1, 1, "{what} lane {l} kz");
        }
    }

    /// The packet set-up, computed for all lanes at once, equals the
    /// single-ray set-up of each lane's ray on every lane form: camera
    /// tiles, rays in every octant, along the axes with zero and negative
    /// zero components, invalid rays.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn packet_set_up_equals_each_rays_own() {
        use std::arch::x86_64::{__m256, __m512};
        if !crate::simd::has_avx2() {
            return;
        }
        #[target_feature(enable = "avx2,fma")]
        unsafe fn eight(bvh: &Bvh, rays: &[Ray]) -> Packet {
            unsafe { x86::packet::<__m256>(bvh, rays) }
        }
        #[target_feature(enable = "avx2,fma")]
        unsafe fn pair(bvh: &Bvh, rays: &[Ray]) -> Packet {
            unsafe { x86::packet::<x86::Pair>(bvh, rays) }
        }
        #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
        unsafe fn sixteen(bvh: &Bvh, rays: &[Ray]) -> Packet {
            unsafe { x86::packet::<__m512>(bvh, rays) }
        }
        let mut f = floats(77);
        let tris = scene(&mut f);
        let bvh = Bvh::build(tris.clone(), &BvhParams::default());
        for p in 0..800 {
            let rays = packet(&mut f, &tris, p);
            // SAFETY (all three): the CPU has the instructions (checked).
            for r in rays.chunks(8) {
                assert_set_up(&bvh, r, &unsafe { eight(&bvh, r) }, "eight lanes");
            }
            assert_set_up(&bvh, &rays, &unsafe { pair(&bvh, &rays) }, "two halves");
            if crate::simd::has_avx512() {
                assert_set_up(&bvh, &rays, &unsafe { sixteen(&bvh, &rays) }, "sixteen");
            }
        }
    }

    /// The vectorised plane distance is `TrianglePlane::distance` bit for
    /// bit.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn plane_distances_equal_the_scalar_ones() {
        if !crate::simd::has_avx2() {
            return;
        }
        use crate::isect::TrianglePlane;
        use std::arch::x86_64::__m256;
        let mut f = floats(5);
        for _ in 0..2000 {
            let tris: Vec<Triangle> = (0..4)
                .map(|_| {
                    let c = Vec3::new(f(), f(), f()) * 1e3;
                    Triangle::new(
                        c,
                        c + Vec3::new(f(), f(), f()),
                        c + Vec3::new(f(), f(), f()),
                    )
                })
                .collect();
            let q = Quad::pack(&tris, &[0, 1, 2, 3]);
            let mut o = [Row([0.0; LANES]); 3];
            let mut d = [Row([0.0; LANES]); 3];
            for a in 0..3 {
                for l in 0..8 {
                    o[a].0[l] = f() * 10.0;
                    d[a].0[l] = f();
                }
            }
            for (j, tri) in tris.iter().enumerate() {
                let (v0, n) = x86::plane(&q, j);
                let mut t = Row([0.0; LANES]);
                // SAFETY: the CPU has AVX2 (checked); the lanes are rows.
                unsafe {
                    #[target_feature(enable = "avx2,fma")]
                    unsafe fn run(
                        v0: [f64; 3],
                        n: [f64; 3],
                        o: &[Row; 3],
                        d: &[Row; 3],
                        t: &mut Row,
                    ) {
                        use x86::Wide;
                        unsafe {
                            let ld = |r: &Row| <__m256 as Wide>::load(r.0.as_ptr());
                            <__m256 as Wide>::distance(
                                v0,
                                n,
                                [ld(&o[0]), ld(&o[1]), ld(&o[2])],
                                [ld(&d[0]), ld(&d[1]), ld(&d[2])],
                                0xff,
                            )
                            .store(t.0.as_mut_ptr());
                        }
                    }
                    run(v0, n, &o, &d, &mut t);
                }
                let plane = TrianglePlane::new(tri);
                for l in 0..8 {
                    let org = Vec3::new(o[0].0[l], o[1].0[l], o[2].0[l]);
                    let dir = Vec3::new(d[0].0[l], d[1].0[l], d[2].0[l]);
                    assert_eq!(t.0[l].to_bits(), plane.distance(org, dir).to_bits());
                }
            }
        }
    }
}
