//! The eight-lane `f32` vectors of the leaf tests and packets, in array
//! form (loops the compiler vectorises) and in intrinsic form.

/// Lanes of a leaf block (triangles) or a packet (rays).
pub(crate) const WIDTH: usize = 8;

/// Eight `f32` lanes as an array.
pub(crate) type Lanes = [f32; WIDTH];

/// Eight `f32` lanes in a 256-bit register (AVX2 paths).
#[cfg(target_arch = "x86_64")]
pub(crate) type Lanes8 = std::arch::x86_64::__m256;

/// The operations the walks do on their rays' intervals, for one lane
/// (`f32`), eight (`[f32; 8]`, or `__m256` with AVX2) or sixteen (`__m512`
/// with AVX-512): the single-ray walk and the packet walk are written once
/// over this trait, so every form computes the same expressions and so the
/// same bits.
///
/// Comparisons are ordered (false for NaN, as Rust's `<`, `>`, `<=`);
/// `min` and `max` return `other` when `self` is NaN, as `f32::min` does
/// and as `minps` does with its second operand.
///
/// The intrinsic forms may only be used in code compiled for their
/// instruction set on a CPU that has it (the walks that use them are
/// reached only through [`super::dispatch`]).
pub(crate) trait FloatLanes: Copy {
    /// One truth value per lane.
    type Mask: Copy;
    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// Lane-wise `self + o`.
    fn add(self, o: Self) -> Self;
    /// Lane-wise `self - o`.
    fn sub(self, o: Self) -> Self;
    /// Lane-wise `self * o`.
    fn mul(self, o: Self) -> Self;
    /// Lane-wise `|self|`.
    fn abs(self) -> Self;
    /// Lane-wise `self.min(o)`.
    fn min(self, o: Self) -> Self;
    /// Lane-wise `self.max(o)`.
    fn max(self, o: Self) -> Self;
    /// Lane-wise `self > o`.
    fn gt(self, o: Self) -> Self::Mask;
    /// Lane-wise `self < o`.
    fn lt(self, o: Self) -> Self::Mask;
    /// Lane-wise `self <= o`.
    fn le(self, o: Self) -> Self::Mask;
    /// Lane-wise `a && b`.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Lane-wise `!a && b`.
    fn and_not(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Lane-wise `if m { a } else { b }`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// The mask as bits (bit `l` = lane `l`).
    fn bits(m: Self::Mask) -> u32;
}

impl FloatLanes for f32 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        self * o
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        f32::min(self, o)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        f32::max(self, o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn and(a: bool, b: bool) -> bool {
        a & b
    }
    #[inline(always)]
    fn and_not(a: bool, b: bool) -> bool {
        !a & b
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn bits(m: bool) -> u32 {
        m as u32
    }
}

/// The array form: each operation a loop over the lanes (masks as bits).
impl FloatLanes for Lanes {
    type Mask = u32;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        [x; WIDTH]
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        std::array::from_fn(|l| self[l] + o[l])
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        std::array::from_fn(|l| self[l] - o[l])
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        std::array::from_fn(|l| self[l] * o[l])
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        std::array::from_fn(|l| self[l].min(o[l]))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        std::array::from_fn(|l| self[l].max(o[l]))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> u32 {
        (0..WIDTH).fold(0, |m, l| m | ((self[l] > o[l]) as u32) << l)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> u32 {
        (0..WIDTH).fold(0, |m, l| m | ((self[l] < o[l]) as u32) << l)
    }
    #[inline(always)]
    fn le(self, o: Self) -> u32 {
        (0..WIDTH).fold(0, |m, l| m | ((self[l] <= o[l]) as u32) << l)
    }
    #[inline(always)]
    fn and(a: u32, b: u32) -> u32 {
        a & b
    }
    #[inline(always)]
    fn and_not(a: u32, b: u32) -> u32 {
        !a & b
    }
    #[inline(always)]
    fn select(m: u32, a: Self, b: Self) -> Self {
        std::array::from_fn(|l| if m >> l & 1 != 0 { a[l] } else { b[l] })
    }
    #[inline(always)]
    fn bits(m: u32) -> u32 {
        m
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::FloatLanes;
    use std::arch::x86_64::*;

    // SAFETY (every intrinsic below): these impls are used only in code
    // compiled for AVX2 (and AVX-512 F for `__m512`) and reached through
    // the dispatch, which checks that the CPU has it.
    impl FloatLanes for __m256 {
        type Mask = __m256;
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { _mm256_set1_ps(x) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { _mm256_add_ps(self, o) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { _mm256_sub_ps(self, o) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { _mm256_mul_ps(self, o) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { _mm256_and_ps(self, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff))) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            unsafe { _mm256_min_ps(self, o) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { _mm256_max_ps(self, o) }
        }
        #[inline(always)]
        fn gt(self, o: Self) -> Self {
            unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self, o) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> Self {
            unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self, o) }
        }
        #[inline(always)]
        fn le(self, o: Self) -> Self {
            unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self, o) }
        }
        #[inline(always)]
        fn and(a: Self, b: Self) -> Self {
            unsafe { _mm256_and_ps(a, b) }
        }
        #[inline(always)]
        fn and_not(a: Self, b: Self) -> Self {
            unsafe { _mm256_andnot_ps(a, b) }
        }
        #[inline(always)]
        fn select(m: Self, a: Self, b: Self) -> Self {
            unsafe { _mm256_blendv_ps(b, a, m) }
        }
        #[inline(always)]
        fn bits(m: Self) -> u32 {
            unsafe { _mm256_movemask_ps(m) as u32 }
        }
    }

    impl FloatLanes for __m512 {
        type Mask = __mmask16;
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { _mm512_set1_ps(x) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { _mm512_add_ps(self, o) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { _mm512_sub_ps(self, o) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { _mm512_mul_ps(self, o) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { _mm512_abs_ps(self) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            unsafe { _mm512_min_ps(self, o) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { _mm512_max_ps(self, o) }
        }
        #[inline(always)]
        fn gt(self, o: Self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self, o) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self, o) }
        }
        #[inline(always)]
        fn le(self, o: Self) -> __mmask16 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self, o) }
        }
        #[inline(always)]
        fn and(a: __mmask16, b: __mmask16) -> __mmask16 {
            a & b
        }
        #[inline(always)]
        fn and_not(a: __mmask16, b: __mmask16) -> __mmask16 {
            !a & b
        }
        #[inline(always)]
        fn select(m: __mmask16, a: Self, b: Self) -> Self {
            unsafe { _mm512_mask_blend_ps(m, b, a) }
        }
        #[inline(always)]
        fn bits(m: __mmask16) -> u32 {
            u32::from(m)
        }
    }
}
