//! Values in SIMD lanes: `N` floats ([`F`]), integers ([`U`], [`U64`]),
//! vectors ([`V`]) and masks ([`M`]) computed lane by lane, with the
//! few functions the lane loop needs (square root, sine and cosine,
//! exponential) written without branches.
//!
//! Why these types and not `wide`'s or `pulp`'s own: the lane code runs in
//! a function that `pulp` dispatches at run time to AVX-512 (16 lanes) or
//! AVX2 (8 lanes) on the machine at hand ([`dispatch`]), while the release
//! build targets plain x86-64. `wide` picks its instruction set when the
//! crate is compiled, so there its `f32x8` would be two SSE halves; `pulp`'s
//! own vectors are associated types of a generic `S: Simd` driven by method
//! calls (`simd.add_f32s(a, b)`), in which a BSDF would be unreadable. These
//! types are plain arrays whose operations are loops over the lanes, every
//! one `#[inline(always)]`: inlined into the dispatched function, each loop
//! becomes one vector instruction of the instruction set `pulp` enabled
//! there (checked in the profile: `vfmadd`-free `zmm` arithmetic).
//!
//! Every operation is the IEEE operation of each lane (no fused
//! multiply-add, no approximate reciprocals), so a lane's value is the same
//! bits whichever instruction set runs it, and whatever the other lanes hold.

use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub};

use glam::Vec3;
use sahara_kd::Isa;

/// `N` floats.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct F<const N: usize>(pub [f32; N]);

/// `N` unsigned 32-bit integers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub struct U<const N: usize>(pub [u32; N]);

/// `N` unsigned 64-bit integers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub struct U64<const N: usize>(pub [u64; N]);

/// `N` truth values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub struct M<const N: usize>(pub [bool; N]);

/// `N` three-vectors, as three lanes of coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V<const N: usize> {
    /// The x coordinates.
    pub x: F<N>,
    /// The y coordinates.
    pub y: F<N>,
    /// The z coordinates.
    pub z: F<N>,
}

macro_rules! lanewise {
    ($t:ident, $e:ty, $tr:ident, $f:ident, $op:tt) => {
        impl<const N: usize> $tr for $t<N> {
            type Output = Self;
            #[inline(always)]
            fn $f(mut self, o: Self) -> Self {
                for i in 0..N {
                    self.0[i] $op o.0[i];
                }
                self
            }
        }
        impl<const N: usize> $tr<$e> for $t<N> {
            type Output = Self;
            #[inline(always)]
            fn $f(mut self, o: $e) -> Self {
                for i in 0..N {
                    self.0[i] $op o;
                }
                self
            }
        }
    };
}

lanewise!(F, f32, Add, add, +=);
lanewise!(F, f32, Sub, sub, -=);
lanewise!(F, f32, Mul, mul, *=);
lanewise!(F, f32, Div, div, /=);

impl<const N: usize> AddAssign for F<N> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<const N: usize> MulAssign for F<N> {
    #[inline(always)]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl<const N: usize> Neg for F<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(mut self) -> Self {
        for i in 0..N {
            self.0[i] = -self.0[i];
        }
        self
    }
}

impl<const N: usize> Mul<F<N>> for f32 {
    type Output = F<N>;
    #[inline(always)]
    fn mul(self, o: F<N>) -> F<N> {
        o * self
    }
}

impl<const N: usize> Sub<F<N>> for f32 {
    type Output = F<N>;
    #[inline(always)]
    fn sub(self, o: F<N>) -> F<N> {
        F::splat(self) - o
    }
}

impl<const N: usize> Default for F<N> {
    #[inline(always)]
    fn default() -> Self {
        Self([0.0; N])
    }
}

impl<const N: usize> F<N> {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: f32) -> Self {
        Self([v; N])
    }

    /// Lane `i` of `f(i)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        Self(std::array::from_fn(f))
    }

    /// `f` of each lane.
    #[inline(always)]
    pub fn map(mut self, f: impl Fn(f32) -> f32) -> Self {
        for i in 0..N {
            self.0[i] = f(self.0[i]);
        }
        self
    }

    /// `f` of each lane of `self` and `o`.
    #[inline(always)]
    pub fn zip(mut self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        for i in 0..N {
            self.0[i] = f(self.0[i], o.0[i]);
        }
        self
    }

    /// `f` of each lane, as a mask.
    #[inline(always)]
    pub fn test(self, o: Self, f: impl Fn(f32, f32) -> bool) -> M<N> {
        let mut m = M([false; N]);
        for i in 0..N {
            m.0[i] = f(self.0[i], o.0[i]);
        }
        m
    }

    /// The lanes' minimum with `o`.
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        self.zip(o, |a, b| if a < b { a } else { b })
    }

    /// The lanes' maximum with `o`.
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        self.zip(o, |a, b| if a > b { a } else { b })
    }

    /// Absolute values.
    #[inline(always)]
    pub fn abs(self) -> Self {
        self.map(f32::abs)
    }

    /// Square roots.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }

    /// `self < o`, lane by lane.
    #[inline(always)]
    pub fn lt(self, o: Self) -> M<N> {
        self.test(o, |a, b| a < b)
    }

    /// `self <= o`, lane by lane.
    #[inline(always)]
    pub fn le(self, o: Self) -> M<N> {
        self.test(o, |a, b| a <= b)
    }

    /// `self > o`, lane by lane.
    #[inline(always)]
    pub fn gt(self, o: Self) -> M<N> {
        self.test(o, |a, b| a > b)
    }

    /// `self >= o`, lane by lane.
    #[inline(always)]
    pub fn ge(self, o: Self) -> M<N> {
        self.test(o, |a, b| a >= b)
    }

    /// `self == o`, lane by lane.
    #[inline(always)]
    pub fn eq(self, o: Self) -> M<N> {
        self.test(o, |a, b| a == b)
    }

    /// `1` with each lane's sign (of `self`, zeros included: `copysign`).
    #[inline(always)]
    pub fn sign(self) -> Self {
        self.map(|a| 1.0f32.copysign(a))
    }

    /// True where the lane is finite.
    #[inline(always)]
    pub fn is_finite(self) -> M<N> {
        let mut m = M([false; N]);
        for i in 0..N {
            m.0[i] = self.0[i].is_finite();
        }
        m
    }

    /// Sine and cosine of each lane: Cody and Waite's reduction by pi/4 in
    /// three parts, then the minimax polynomials of Cephes' `sinf` and
    /// `cosf` on `[-pi/4, pi/4]` (about 1 ulp there; arguments up to some
    /// thousands of radians).
    #[inline(always)]
    pub fn sin_cos(self) -> (Self, Self) {
        let mut s = self;
        let mut c = self;
        for i in 0..N {
            let (si, ci) = sin_cos(self.0[i]);
            s.0[i] = si;
            c.0[i] = ci;
        }
        (s, c)
    }

    /// `e^x` of each lane (Cephes' `expf`: `2^n e^r` with `|r| <= ln 2 / 2`,
    /// a degree-6 polynomial; 0 below -87, infinity above 88).
    #[inline(always)]
    pub fn exp(self) -> Self {
        self.map(exp)
    }
}

/// The sine and cosine of `x` (see [`F::sin_cos`]).
#[inline(always)]
pub fn sin_cos(x: f32) -> (f32, f32) {
    const FOPI: f32 = 4.0 / std::f32::consts::PI;
    const DP1: f32 = 0.785_156_25;
    const DP2: f32 = 2.418_756_5e-4;
    const DP3: f32 = 3.774_895e-8;
    let sign_x = x < 0.0;
    let a = x.abs();
    // The octant, rounded up to even: j in {0, 2, 4, 6, ...}.
    let mut j = (a * FOPI) as i32 as u32;
    j = (j + 1) & !1;
    let y = j as f32;
    let r = ((a - y * DP1) - y * DP2) - y * DP3;
    let z = r * r;
    let cos_p =
        ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    let sin_p = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * r + r;
    let swap = j & 2 != 0;
    let (s, c) = if swap { (cos_p, sin_p) } else { (sin_p, cos_p) };
    let s_neg = (j & 4 != 0) != sign_x;
    let c_neg = ((j + 2) & 4) != 0;
    (if s_neg { -s } else { s }, if c_neg { -c } else { c })
}

/// `e^x` (see [`F::exp`]).
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    const C1: f32 = 0.693_359_4;
    const C2: f32 = -2.121_944_4e-4;
    let xc = x.clamp(-87.0, 88.0);
    let n = (xc * LOG2E + 0.5).floor();
    let r = (xc - n * C1) - n * C2;
    let z = r * r;
    let p = ((((1.987_569_1e-4 * r + 1.398_199_9e-3) * r + 8.333_452e-3) * r + 4.166_579_6e-2) * r
        + 1.666_666_5e-1)
        * r
        + 0.5;
    let e = p * z + r + 1.0;
    let scaled = e * f32::from_bits((((n as i32) + 127) as u32) << 23);
    if x < -87.0 {
        0.0
    } else if x > 88.0 {
        f32::INFINITY
    } else {
        scaled
    }
}

impl<const N: usize> U<N> {
    /// `f` of each lane.
    #[inline(always)]
    pub fn map(mut self, f: impl Fn(u32) -> u32) -> Self {
        for i in 0..N {
            self.0[i] = f(self.0[i]);
        }
        self
    }

    /// `self >= v`, lane by lane.
    #[inline(always)]
    pub fn ge(self, v: u32) -> M<N> {
        let mut m = M([false; N]);
        for i in 0..N {
            m.0[i] = self.0[i] >= v;
        }
        m
    }
}

impl<const N: usize> M<N> {
    /// [`M::select`] of integers.
    #[inline(always)]
    pub fn select_u(self, a: U<N>, b: U<N>) -> U<N> {
        let mut r = b;
        for i in 0..N {
            if self.0[i] {
                r.0[i] = a.0[i];
            }
        }
        r
    }

    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: bool) -> Self {
        Self([v; N])
    }

    /// True if any lane is.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().any(|&b| b)
    }

    /// True if every lane is.
    #[inline(always)]
    pub fn all(self) -> bool {
        self.0.iter().all(|&b| b)
    }

    /// `a` where true, `b` where false.
    #[inline(always)]
    pub fn select(self, a: F<N>, b: F<N>) -> F<N> {
        let mut r = b;
        for i in 0..N {
            if self.0[i] {
                r.0[i] = a.0[i];
            }
        }
        r
    }

    /// [`M::select`] of vectors.
    #[inline(always)]
    pub fn select_v(self, a: V<N>, b: V<N>) -> V<N> {
        V {
            x: self.select(a.x, b.x),
            y: self.select(a.y, b.y),
            z: self.select(a.z, b.z),
        }
    }

    /// [`M::select`] of masks.
    #[inline(always)]
    pub fn select_m(self, a: M<N>, b: M<N>) -> M<N> {
        let mut r = b;
        for i in 0..N {
            if self.0[i] {
                r.0[i] = a.0[i];
            }
        }
        r
    }

    /// True where `self` is and `o` is not.
    #[inline(always)]
    pub fn and_not(self, o: Self) -> Self {
        self & !o
    }
}

impl<const N: usize> BitAnd for M<N> {
    type Output = Self;
    #[inline(always)]
    fn bitand(mut self, o: Self) -> Self {
        for i in 0..N {
            self.0[i] &= o.0[i];
        }
        self
    }
}

impl<const N: usize> BitOr for M<N> {
    type Output = Self;
    #[inline(always)]
    fn bitor(mut self, o: Self) -> Self {
        for i in 0..N {
            self.0[i] |= o.0[i];
        }
        self
    }
}

impl<const N: usize> Not for M<N> {
    type Output = Self;
    #[inline(always)]
    fn not(mut self) -> Self {
        for i in 0..N {
            self.0[i] = !self.0[i];
        }
        self
    }
}

impl<const N: usize> V<N> {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        Self {
            x: F::splat(v.x),
            y: F::splat(v.y),
            z: F::splat(v.z),
        }
    }

    /// The vector `(x, y, z)`.
    #[inline(always)]
    pub fn new(x: F<N>, y: F<N>, z: F<N>) -> Self {
        Self { x, y, z }
    }

    /// Lane `i` of `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Vec3) -> Self {
        let mut v = Self::default();
        for i in 0..N {
            v.set(i, f(i));
        }
        v
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    /// Sets lane `i` to `v`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: Vec3) {
        self.x.0[i] = v.x;
        self.y.0[i] = v.y;
        self.z.0[i] = v.z;
    }

    /// The lanes' dot products with `o`.
    #[inline(always)]
    pub fn dot(self, o: Self) -> F<N> {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The lanes' squared lengths.
    #[inline(always)]
    pub fn length_squared(self) -> F<N> {
        self.dot(self)
    }

    /// The lanes scaled to unit length (as glam's `normalize`: times the
    /// reciprocal of the length).
    #[inline(always)]
    pub fn normalize(self) -> Self {
        let r = F::splat(1.0) / self.length_squared().sqrt();
        self * r
    }

    /// The lanes' cross products with `o`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }

    /// The largest coordinate of each lane.
    #[inline(always)]
    pub fn max_element(self) -> F<N> {
        self.x.max(self.y).max(self.z)
    }
}

impl<const N: usize> Add for V<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<const N: usize> Sub for V<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<const N: usize> Neg for V<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

impl<const N: usize> Mul<F<N>> for V<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: F<N>) -> Self {
        Self::new(self.x * o, self.y * o, self.z * o)
    }
}

impl<const N: usize> Mul for V<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
}

impl<const N: usize> Mul<f32> for V<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: f32) -> Self {
        Self::new(self.x * o, self.y * o, self.z * o)
    }
}

impl<const N: usize> Div<F<N>> for V<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: F<N>) -> Self {
        Self::new(self.x / o, self.y / o, self.z / o)
    }
}

impl<const N: usize> AddAssign for V<N> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<const N: usize> Default for V<N> {
    #[inline(always)]
    fn default() -> Self {
        Self::splat(Vec3::ZERO)
    }
}

/// A lane-loop kernel: `run::<N>()` with `N` the lanes of the machine's
/// vector unit.
pub trait Kernel {
    /// What the kernel returns.
    type Output;
    /// Runs the kernel on `N` lanes. Everything it calls that should run
    /// in vector registers must be `#[inline(always)]`.
    fn run<const N: usize>(self) -> Self::Output;
}

/// Runs `k` with 16 lanes under AVX-512 or 8 under AVX2 (and FMA), as the
/// machine has them and `limit` allows (`pulp` checks once and enables the
/// instruction set for the code inlined into it); 8 lanes of plain code
/// otherwise.
#[inline(always)]
pub fn dispatch<K: Kernel>(limit: Isa, k: K) -> K::Output {
    struct Wide<K>(K);
    impl<K: Kernel> pulp::WithSimd for Wide<K> {
        type Output = K::Output;
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _: S) -> K::Output {
            if S::F32_LANES >= 16 {
                self.0.run::<16>()
            } else {
                self.0.run::<8>()
            }
        }
    }
    #[cfg(target_arch = "x86_64")]
    {
        use pulp::Simd;
        if limit == Isa::Avx512 {
            if let Some(v4) = pulp::x86::V4::try_new() {
                return Simd::vectorize(v4, Wide(k));
            }
        }
        if limit != Isa::Portable {
            if let Some(v3) = pulp::x86::V3::try_new() {
                return Simd::vectorize(v3, Wide(k));
            }
        }
        Simd::vectorize(pulp::Scalar::new(), Wide(k))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = limit;
        pulp::Arch::new().dispatch(Wide(k))
    }
}

/// The number of lanes [`dispatch`] runs kernels with on this machine.
#[cfg(test)]
pub fn width() -> usize {
    struct Width;
    impl Kernel for Width {
        type Output = usize;
        fn run<const N: usize>(self) -> usize {
            N
        }
    }
    dispatch(Isa::Avx512, Width)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_within_a_few_ulps() {
        let mut worst = 0.0f32;
        for k in -20000..=20000 {
            let x = k as f32 * 1e-3;
            let (s, c) = sin_cos(x);
            let (es, ec) = ((x as f64).sin(), (x as f64).cos());
            worst = worst
                .max((s as f64 - es).abs() as f32)
                .max((c as f64 - ec).abs() as f32);
        }
        assert!(worst < 3e-7, "{worst}");
    }

    #[test]
    fn exp_within_a_few_ulps() {
        for k in -870..=880 {
            let x = k as f32 * 0.1;
            let e = exp(x);
            let r = (x as f64).exp();
            assert!(((e as f64 - r) / r).abs() < 4e-7, "{x}: {e} vs {r}");
        }
        assert_eq!(exp(-100.0), 0.0);
        assert_eq!(exp(100.0), f32::INFINITY);
    }

    #[test]
    fn lanes_are_lanewise() {
        let a = F::<8>::from_fn(|i| i as f32 - 3.0);
        let b = F::<8>::splat(2.0);
        let m = a.lt(b);
        assert_eq!(m.0, [true, true, true, true, true, false, false, false]);
        assert_eq!(
            m.select(a, b).0,
            [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 2.0, 2.0]
        );
        assert_eq!((a * b + 1.0).0[7], 9.0);
        assert!(width() == 8 || width() == 16);
    }
}
