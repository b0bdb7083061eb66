//! Splatting a render's samples into a tile's exact sums, at a cost of a
//! few instructions per tap.
//!
//! Each sample adds, to every pixel its filter reaches, four fixed-point
//! contributions (`w L` per channel, and `w`; see [`crate::film::sums`]).
//! What makes that cheap, with the same bits as
//! [`PixelSum::add_sample`](crate::film::sums::PixelSum::add_sample):
//!
//! - The filter's kind is matched once per batch of samples, not per
//!   sample ([`Splatter`]), and its weights are computed inline
//!   ([`Kernel`]), a row and a column of them per sample, four at a time
//!   where the kind allows.
//! - The radiance is scaled by `2^52` once per sample; a tap's products
//!   with its weight are then the fixed-point values before truncation,
//!   and one bound per sample (its largest radiance times its largest
//!   weights) shows that every one of them fits an `i64`, so each converts
//!   in one instruction with no test of its own.
//! - The contributions go to [`Parts`] that add without carries: each
//!   `i64` contribution as its low 32 bits (zero-extended) and its high
//!   part (shifted down by 32, with its sign), in two sums of 64-bit words
//!   that cannot overflow within `2^32` additions. The parts are folded
//!   into the `i128` sums at the end of a tile ([`SplatSums::into_sums`]),
//!   or sooner if that many samples could reach a pixel.
//! - With AVX-512 (F, DQ, VL), detected at run time, two taps' eight
//!   contributions are multiplied, converted and split in one vector each.
//!
//! A sample whose contributions could reach `2^11` (a very bright one)
//! takes the general conversion straight into the `i128` sums.

use glam::{Vec2, Vec3, Vec4};
use sahara_kd::Isa;

use crate::film::filter::{BoxKernel, Filter, GaussianKernel, Kernel, MitchellKernel, TentKernel};
use crate::film::sums::{filter_margin, PixelSum, SumBuffer, FRACTION_BITS};

/// `2^FRACTION_BITS`: a contribution times this is its fixed-point value
/// before truncation (exactly: scaling by a power of two is exact).
const ONE: f64 = (1u64 << FRACTION_BITS) as f64;

/// A bound on a sample's largest scaled contribution under which all of
/// them convert to `i64` directly: `2^62`, half the limit, which leaves
/// room for the rounding of `wy * wx` and of the bound itself.
const FAST_BOUND: f64 = 4_611_686_018_427_387_904.0;

/// Most columns (and rows) of a sample's footprint whose weights a splat
/// computes together: a radius of up to 3.5 pixels.
const LANES: usize = 8;

/// Samples splatted between two folds of the parts: each adds at most one
/// contribution per pixel and channel, so no sum of parts can overflow
/// (`2^31` additions of values below `2^32` in magnitude).
const FOLD_EVERY: u64 = 1 << 31;

/// A filter made ready for splatting: its kind's constants computed once
/// and its reach in whole pixels.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Splatter {
    kernel: Kernels,
    margin: u32,
    /// Whether it may add taps with AVX-512 (where the CPU has it).
    wide: bool,
}

/// The kernel of each filter kind.
#[derive(Clone, Copy, Debug)]
enum Kernels {
    Box(BoxKernel),
    Tent(TentKernel),
    Gaussian(GaussianKernel),
    Mitchell(MitchellKernel),
}

impl Splatter {
    /// The splatter of `filter`.
    pub fn new(filter: &Filter) -> Self {
        let kernel = match *filter {
            Filter::Box { radius } => Kernels::Box(BoxKernel { radius }),
            Filter::Tent { radius } => Kernels::Tent(TentKernel { radius }),
            Filter::Gaussian { radius, sigma } => {
                Kernels::Gaussian(GaussianKernel::new(radius, sigma))
            }
            Filter::Mitchell { radius, b, c } => Kernels::Mitchell(MitchellKernel { radius, b, c }),
        };
        Self {
            kernel,
            margin: filter_margin(filter),
            wide: true,
        }
    }

    /// This splatter held to the instructions of `isa` at most (the sums
    /// are the same bit for bit; see [`sahara_kd::Isa`] for why).
    pub fn at_most(self, isa: Isa) -> Self {
        Self {
            wide: self.wide && isa == Isa::Avx512,
            ..self
        }
    }

    /// Pixels beyond a pixel's own that its samples reach.
    pub fn margin(&self) -> u32 {
        self.margin
    }
}

/// The pixels `[x0, x1) x [y0, y1)` of a batch of samples, row by row, and
/// where each one's samples start in the batch ([`SplatSums::splat_each`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pixels<'a> {
    /// Left column.
    pub x0: u32,
    /// One past the right column.
    pub x1: u32,
    /// Top row.
    pub y0: u32,
    /// One past the bottom row.
    pub y1: u32,
    /// Pixel `i`'s first sample; it has those up to the next pixel's (the
    /// last pixel's, to the end of the batch).
    pub first: &'a [u32],
}

impl Pixels<'_> {
    /// Calls `f(x, y, pos, l)` for each sample of each pixel, in order,
    /// but those whose radiance is NaN.
    #[inline(always)]
    fn each(self, pos: &[Vec2], radiance: &[Vec3], mut f: impl FnMut(u32, u32, Vec2, Vec3)) {
        let n = pos.len().min(radiance.len());
        let mut i = 0;
        for y in self.y0..self.y1 {
            for x in self.x0..self.x1 {
                let Some(&start) = self.first.get(i) else {
                    return;
                };
                let end = self.first.get(i + 1).map_or(n, |&e| e as usize);
                i += 1;
                let (start, end) = (start as usize, end.min(n));
                if start >= end {
                    continue;
                }
                for (&p, &l) in pos[start..end].iter().zip(&radiance[start..end]) {
                    if !l.x.is_nan() {
                        f(x, y, p, l);
                    }
                }
            }
        }
    }
}

/// One pixel's contributions since the last fold, as parts that add
/// without carries: for red, green, blue and the weight, the sum of the
/// contributions' low 32 bits and the sum of their high parts, so that
/// the contributions' sum is `high * 2^32 + low`. In memory, 64 bytes
/// aligned to 64, the lows then the highs, as the vector splat adds them.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct Parts {
    low: [u64; 4],
    high: [i64; 4],
}

impl Parts {
    /// Adds a contribution (already in fixed point) to channel `c`.
    #[inline(always)]
    fn add(&mut self, c: usize, x: i64) {
        self.low[c] += u64::from(x as u32);
        self.high[c] += x >> 32;
    }

    /// Adds the parts into `sum` and clears them.
    #[inline]
    fn fold_into(&mut self, sum: &mut PixelSum) {
        let value = |c: usize| (i128::from(self.high[c]) << 32) + i128::from(self.low[c]);
        for c in 0..3 {
            sum.rgb[c] += value(c);
        }
        sum.weight += value(3);
        *self = Parts::default();
    }
}

/// A tile's exact sums while samples are splatted into it: the sums, and
/// the parts most contributions go to until they are folded in.
pub(crate) struct SplatSums {
    sums: SumBuffer,
    /// One per pixel of `sums`, in the same order.
    parts: Vec<Parts>,
    /// Samples splatted since the parts were last folded.
    pending: u64,
}

impl SplatSums {
    /// Zero sums over `[x0, x0 + width) x [y0, y0 + height)`.
    pub fn new(x0: u32, y0: u32, width: u32, height: u32) -> Self {
        let sums = SumBuffer::new(x0, y0, width, height);
        Self {
            parts: vec![Parts::default(); sums.sums.len()],
            sums,
            pending: 0,
        }
    }

    /// The sums, with everything splatted.
    pub fn into_sums(mut self) -> SumBuffer {
        self.fold();
        self.sums
    }

    /// Adds the parts into the sums.
    fn fold(&mut self) {
        if self.pending > 0 {
            for (p, s) in self.parts.iter_mut().zip(&mut self.sums.sums) {
                p.fold_into(s);
            }
        }
        self.pending = 0;
    }

    /// Splats the samples of `pixels` as [`SumBuffer::splat`] does: pixel
    /// `i`'s at `pos[k]` with radiance `radiance[k]` for `k` from
    /// `pixels.first[i]` to the next pixel's first. A sample whose radiance
    /// is NaN is left out (a render's samples come here finite, so NaN can
    /// mark one). The filter's kind and the CPU's instructions are chosen
    /// once, not per sample. Not inlined: it is called once per strip, and
    /// profiles then show the film apart.
    #[inline(never)]
    pub fn splat_each(
        &mut self,
        splatter: &Splatter,
        pixels: Pixels,
        pos: &[Vec2],
        radiance: &[Vec3],
    ) {
        if self.sums.width == 0 || self.sums.height == 0 {
            return;
        }
        let n = pos.len().min(radiance.len());
        if self.pending + n as u64 > FOLD_EVERY {
            self.fold();
            if n as u64 > FOLD_EVERY {
                // More samples than the parts may take at once (not a
                // real render's strip): the pixels one by one.
                for (i, (y, x)) in (pixels.y0..pixels.y1)
                    .flat_map(|y| (pixels.x0..pixels.x1).map(move |x| (y, x)))
                    .enumerate()
                {
                    let one = Pixels {
                        x0: x,
                        x1: x + 1,
                        y0: y,
                        y1: y + 1,
                        first: &[0],
                    };
                    let start = pixels.first.get(i).map_or(n, |&s| s as usize).min(n);
                    let end = pixels.first.get(i + 1).map_or(n, |&e| e as usize).min(n);
                    for k in (start..end).step_by(FOLD_EVERY as usize) {
                        let e = (k + FOLD_EVERY as usize).min(end);
                        self.splat_each(splatter, one, &pos[k..e], &radiance[k..e]);
                    }
                }
                return;
            }
        }
        self.pending += n as u64;
        let (pos, radiance) = (&pos[..n], &radiance[..n]);
        #[cfg(target_arch = "x86_64")]
        if splatter.wide && avx512::available() {
            // SAFETY: the CPU has the instructions (detected).
            unsafe { self.splat_each_avx512(splatter, pixels, pos, radiance) };
            return;
        }
        self.splat_each_with::<Portable>(splatter, pixels, pos, radiance);
    }

    /// [`SplatSums::splat_each`] compiled with AVX-512 (F, DQ, VL).
    ///
    /// # Safety
    /// The CPU must have them.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512vl")]
    unsafe fn splat_each_avx512(
        &mut self,
        splatter: &Splatter,
        pixels: Pixels,
        pos: &[Vec2],
        radiance: &[Vec3],
    ) {
        self.splat_each_with::<avx512::Avx512>(splatter, pixels, pos, radiance);
    }

    /// [`SplatSums::splat_each`] with the taps added by `T`.
    #[inline(always)]
    fn splat_each_with<T: AddTaps>(
        &mut self,
        splatter: &Splatter,
        pixels: Pixels,
        pos: &[Vec2],
        radiance: &[Vec3],
    ) {
        let m = splatter.margin;
        match splatter.kernel {
            Kernels::Box(k) if m == 0 => pixels.each(pos, radiance, |x, y, pos, l| {
                self.splat_own::<T, _>(k, x, y, pos, l)
            }),
            Kernels::Box(k) => pixels.each(pos, radiance, |x, y, pos, l| {
                self.splat_taps::<T, _>(k, m, x, y, pos, l)
            }),
            Kernels::Tent(k) => pixels.each(pos, radiance, |x, y, pos, l| {
                self.splat_taps::<T, _>(k, m, x, y, pos, l)
            }),
            Kernels::Gaussian(k) => pixels.each(pos, radiance, |x, y, pos, l| {
                self.splat_taps::<T, _>(k, m, x, y, pos, l)
            }),
            Kernels::Mitchell(k) => pixels.each(pos, radiance, |x, y, pos, l| {
                self.splat_taps::<T, _>(k, m, x, y, pos, l)
            }),
        }
    }

    /// A sample whose filter reaches no pixel but its own (a box of radius
    /// at most 1/2, the default): one tap.
    #[inline(always)]
    fn splat_own<T: AddTaps, K: Kernel>(&mut self, k: K, x: u32, y: u32, pos: Vec2, l: Vec3) {
        let Some(i) = self.sums.index(x, y) else {
            return;
        };
        let wt = k.eval(pos.y - (y as f32 + 0.5)) * k.eval(pos.x - (x as f32 + 0.5));
        let ls = scaled(l);
        if largest(&ls) * f64::from(wt.abs()) < FAST_BOUND {
            T::add_row(&mut self.parts[i..=i], &ls, 1.0, &[wt]);
        } else {
            self.sums.sums[i].add_sample(l, wt);
        }
    }

    /// A sample's taps: the pixels within `margin` of `(x, y)` and inside
    /// the buffer, each weighed by the filter at its centre (the rows and
    /// columns at the footprint's edges that it weighs 0 left out).
    #[inline(always)]
    fn splat_taps<T: AddTaps, K: Kernel>(
        &mut self,
        k: K,
        margin: u32,
        x: u32,
        y: u32,
        pos: Vec2,
        l: Vec3,
    ) {
        let b = &self.sums;
        let px0 = x.saturating_sub(margin).max(b.x0);
        let px1 = (x.saturating_add(margin)).min(b.x0 + b.width - 1);
        let py0 = y.saturating_sub(margin).max(b.y0);
        let py1 = (y.saturating_add(margin)).min(b.y0 + b.height - 1);
        if px1 < px0 || py1 < py0 {
            return;
        }
        let (x0, y0, w) = (b.x0, b.y0, b.width as usize);
        let (nx, ny) = ((px1 - px0 + 1) as usize, (py1 - py0 + 1) as usize);
        if nx > LANES || ny > LANES {
            // A filter of radius over 3.5 pixels: every tap weighed as it
            // comes, by the general conversion.
            for py in py0..=py1 {
                let wy = k.eval(pos.y - (py as f32 + 0.5));
                let row = (py - y0) as usize * w;
                for px in px0..=px1 {
                    let wt = wy * k.eval(pos.x - (px as f32 + 0.5));
                    self.sums.sums[row + (px - x0) as usize].add_sample(l, wt);
                }
            }
            return;
        }
        // The columns' and rows' weights, once per sample, then the
        // footprint trimmed to the taps the filter weighs (a footprint 2r
        // pixels across meets 2r + 1 columns, but a sample's own pixel
        // holds it within 2r of the centres it reaches).
        let (mut wx, mut wy) = ([0.0f32; LANES], [0.0f32; LANES]);
        let Some(ax) = weights(&mut wx, k, pos.x, px0, nx) else {
            return;
        };
        let Some(ay) = weights(&mut wy, k, pos.y, py0, ny) else {
            return;
        };
        let (px0, py0) = (px0 + ax.first as u32, py0 + ay.first as u32);
        let (wx, wy) = (&wx[ax.first..=ax.last], &wy[ay.first..=ay.last]);
        let first = (py0 - y0) as usize * w + (px0 - x0) as usize;
        let ls = scaled(l);
        if largest(&ls) * (f64::from(ax.most) * f64::from(ay.most)) < FAST_BOUND {
            // Every contribution below 2^11 (nearly always). A weight of 0
            // adds 0, so none is skipped.
            for (j, &wy) in wy.iter().enumerate() {
                let start = first + j * w;
                T::add_row(&mut self.parts[start..start + wx.len()], &ls, wy, wx);
            }
        } else {
            for (j, &wy) in wy.iter().enumerate() {
                let start = first + j * w;
                for (p, &wx) in self.sums.sums[start..start + wx.len()].iter_mut().zip(wx) {
                    p.add_sample(l, wy * wx);
                }
            }
        }
    }
}

impl SumBuffer {
    /// Splats a sample of pixel `(x, y)` at film position `pos` (pixel
    /// units) with radiance `l` into every pixel of the buffer whose centre
    /// lies within the filter's radius; `margin` is the filter's reach in
    /// whole pixels (`filter_margin`). A render splats its samples in bulk
    /// ([`SplatSums::splat_each`]); this goes through a buffer of the
    /// sample's footprint.
    pub fn splat(&mut self, filter: &Filter, margin: u32, x: u32, y: u32, pos: Vec2, l: Vec3) {
        let splatter = Splatter::new(filter);
        debug_assert_eq!(margin, splatter.margin());
        let m = splatter.margin();
        let (fx, fy) = (x.saturating_sub(m), y.saturating_sub(m));
        let side = |c: u32, f: u32| c.saturating_add(m).saturating_add(1) - f;
        let mut one = SplatSums::new(fx, fy, side(x, fx), side(y, fy));
        let pixels = Pixels {
            x0: x,
            x1: x + 1,
            y0: y,
            y1: y + 1,
            first: &[0],
        };
        one.splat_each(&splatter, pixels, &[pos], &[l]);
        self.add(&one.into_sums());
    }
}

/// Where a sample's weights along one axis of its footprint are non-zero,
/// and their largest magnitude.
#[derive(Clone, Copy)]
struct Axis {
    /// The first and last non-zero weight.
    first: usize,
    last: usize,
    /// The largest magnitude of a weight.
    most: f32,
}

/// The weights `w` of columns (or rows) `c0, c0 + 1, ...` for a sample at
/// `p` (pixel units) along that axis, the first `n` of them (0 after), and
/// where the non-zero ones are (None if all are 0): all [`LANES`] computed
/// together, as vectors, when the kernel calls nothing. (Written in place:
/// the arrays are not moved about.)
#[inline(always)]
fn weights<K: Kernel>(w: &mut [f32; LANES], k: K, p: f32, c0: u32, n: usize) -> Option<Axis> {
    let (mask, most) = if K::PLAIN && c0 < (1 << 24) - LANES as u32 {
        // The centres `(c0 + i) as f32 + 0.5` as `c0 as f32 + i + 0.5`:
        // the same bits, the integers being exact below 2^24.
        let c = Vec4::splat(c0 as f32);
        let (i_lo, i_hi) = (Vec4::new(0.0, 1.0, 2.0, 3.0), Vec4::new(4.0, 5.0, 6.0, 7.0));
        let lo = k.eval4(Vec4::splat(p) - (c + i_lo + 0.5));
        // Four columns are enough for a radius up to 1.5 (tent, Gaussian).
        let hi = if n > 4 {
            k.eval4(Vec4::splat(p) - (c + i_hi + 0.5))
        } else {
            Vec4::ZERO
        };
        // Lanes from `n` on are beyond the footprint (outside the buffer,
        // or the filter's margin): weight 0, chosen lane by lane.
        let n = Vec4::splat(n as f32);
        let lo = Vec4::select(i_lo.cmplt(n), lo, Vec4::ZERO);
        let hi = Vec4::select(i_hi.cmplt(n), hi, Vec4::ZERO);
        w[..4].copy_from_slice(&lo.to_array());
        w[4..].copy_from_slice(&hi.to_array());
        // Which are non-zero, as a bit mask, rather than by branching lane
        // by lane.
        let mask = lo.cmpne(Vec4::ZERO).bitmask() | hi.cmpne(Vec4::ZERO).bitmask() << 4;
        (mask, lo.abs().max(hi.abs()).max_element())
    } else {
        let (mut mask, mut most) = (0, 0.0f32);
        for (i, w) in w.iter_mut().enumerate() {
            *w = if i < n {
                k.eval(p - (c0.wrapping_add(i as u32) as f32 + 0.5))
            } else {
                0.0
            };
            mask |= u32::from(*w != 0.0) << i;
            most = most.max(w.abs());
        }
        (mask, most)
    };
    (mask != 0).then(|| Axis {
        first: mask.trailing_zeros() as usize,
        last: 31 - mask.leading_zeros() as usize,
        most,
    })
}

/// `l` per channel times `2^52`, in `f64` (exact), and the weight's scale
/// `2^52`: a tap's four products with its weight are its four
/// contributions in fixed point, before truncation.
#[inline(always)]
fn scaled(l: Vec3) -> [f64; 4] {
    [l.x as f64 * ONE, l.y as f64 * ONE, l.z as f64 * ONE, ONE]
}

/// A bound on the magnitudes of `ls`'s contributions at weight 1: their
/// sum, which is at least the largest, and NaN if one is NaN (which then
/// fails every bound).
#[inline(always)]
fn largest(ls: &[f64; 4]) -> f64 {
    ls[0].abs() + ls[1].abs() + ls[2].abs() + ls[3]
}

/// How a splat adds a row of taps (a sample's radiance, each with one
/// pixel's weight) to those pixels' parts; every way gives the same sums.
trait AddTaps {
    /// Adds `ls` (from [`scaled`]) with weights `wy * wx[i]` to `parts[i]`,
    /// every contribution known to be below `2^11`.
    fn add_row(parts: &mut [Parts], ls: &[f64; 4], wy: f32, wx: &[f32]);
}

/// Taps added by scalar code, on any CPU.
struct Portable;

impl AddTaps for Portable {
    #[inline(always)]
    fn add_row(parts: &mut [Parts], ls: &[f64; 4], wy: f32, wx: &[f32]) {
        for (p, &wx) in parts.iter_mut().zip(wx) {
            let w64 = (wy * wx) as f64;
            for (c, &ls) in ls.iter().enumerate() {
                // SAFETY: the caller's bound: |ls * w| < 2^63, so the
                // truncated value fits an i64. The products are exact (an
                // f32 times an f32, and a power of two).
                p.add(c, unsafe { (ls * w64).to_int_unchecked::<i64>() });
            }
        }
    }
}

/// Taps added with AVX-512, two at a time.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::{AddTaps, Parts};

    /// True when the CPU has AVX-512 F, DQ and VL (std caches the query).
    #[inline(always)]
    pub(super) fn available() -> bool {
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx512vl")
    }

    /// Taps added with AVX-512; used only by functions compiled for it, on
    /// CPUs that have it.
    pub(super) struct Avx512;

    impl AddTaps for Avx512 {
        #[inline(always)]
        fn add_row(parts: &mut [Parts], ls: &[f64; 4], wy: f32, wx: &[f32]) {
            // SAFETY: `Avx512` is used only by `splat_each_avx512`, which
            // runs on CPUs with AVX-512 F, DQ, VL and is compiled for them.
            unsafe { add_row(parts, ls, wy, wx) }
        }
    }

    /// [`AddTaps::add_row`] with two taps in each vector: their eight
    /// products, conversions and splits into low and high parts at once,
    /// then each tap's lows and highs, in a [`Parts`]'s order, added to it.
    #[target_feature(enable = "avx512f,avx512dq,avx512vl")]
    #[inline]
    unsafe fn add_row(parts: &mut [Parts], ls: &[f64; 4], wy: f32, wx: &[f32]) {
        let n = parts.len().min(wx.len());
        // SAFETY: `ls` is four f64.
        let ls4 = unsafe { _mm256_loadu_pd(ls.as_ptr()) };
        let ls8 = _mm512_broadcast_f64x4(ls4);
        let low_bits = _mm512_set1_epi64(0xffff_ffff);
        let add = |p: &mut Parts, v: __m512i| {
            let at = (p as *mut Parts).cast::<__m512i>();
            // SAFETY: a Parts is 64 bytes aligned to 64, borrowed mutably.
            unsafe { _mm512_store_si512(at, _mm512_add_epi64(_mm512_load_si512(at), v)) };
        };
        let mut i = 0;
        while i + 1 < n {
            let (w0, w1) = ((wy * wx[i]) as f64, (wy * wx[i + 1]) as f64);
            let w = _mm512_insertf64x4::<1>(_mm512_set1_pd(w0), _mm256_set1_pd(w1));
            let x = _mm512_cvttpd_epi64(_mm512_mul_pd(ls8, w));
            let (low, high) = (_mm512_and_si512(x, low_bits), _mm512_srai_epi64::<32>(x));
            // Lanes 0-3 are the first tap's, 4-7 the second's.
            add(
                &mut parts[i],
                _mm512_shuffle_i64x2::<0b01_00_01_00>(low, high),
            );
            add(
                &mut parts[i + 1],
                _mm512_shuffle_i64x2::<0b11_10_11_10>(low, high),
            );
            i += 2;
        }
        if i < n {
            let w = _mm256_set1_pd((wy * wx[i]) as f64);
            let x = _mm256_cvttpd_epi64(_mm256_mul_pd(ls4, w));
            let low = _mm256_and_si256(x, _mm256_set1_epi64x(0xffff_ffff));
            let high = _mm256_srai_epi64::<32>(x);
            add(
                &mut parts[i],
                _mm512_inserti64x4::<1>(_mm512_castsi256_si512(low), high),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic pseudo-random numbers in [0, 1).
    fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// Every filter, samples of every brightness (some past the fast
    /// bound, some negative, some NaN-marked), pixels at the buffer's
    /// edges: the bulk splat gives the sums of adding each tap on its own
    /// with `PixelSum::add_sample`, bit for bit.
    #[test]
    fn bulk_splats_are_the_taps_added_one_by_one() {
        let mut next = rng(7);
        let filters = [
            Filter::Box { radius: 0.5 },
            Filter::Box { radius: 1.2 },
            Filter::Tent { radius: 1.0 },
            Filter::Gaussian {
                radius: 1.5,
                sigma: 0.5,
            },
            Filter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
            Filter::Mitchell {
                radius: 4.5,
                b: 0.2,
                c: 0.4,
            },
        ];
        for filter in filters {
            let splatter = Splatter::new(&filter);
            let m = splatter.margin();
            let (x0, y0, w, h) = (3, 2, 9, 7);
            let mut bulk = SplatSums::new(x0, y0, w, h);
            let mut one_by_one = SumBuffer::new(x0, y0, w, h);
            // The pixels whose footprint meets the buffer, with three
            // samples each.
            let (px0, py0) = (x0 - m.min(x0), y0 - m.min(y0));
            let (px1, py1) = (x0 + w + m, y0 + h + m);
            let (mut pos, mut radiance, mut first) = (vec![], vec![], vec![]);
            for y in py0..py1 {
                for x in px0..px1 {
                    first.push(pos.len() as u32);
                    for s in 0..3 {
                        let p = Vec2::new(x as f32 + next(), y as f32 + next());
                        let scale = match (x + y + s) % 7 {
                            0 => 3000.0,
                            1 => 1e-9,
                            _ => 2.0,
                        };
                        let mut l = Vec3::new(next(), next(), next()) * scale;
                        if (x * 3 + y + s) % 11 == 0 {
                            l.y = -l.y;
                        }
                        if (x + 2 * y + s) % 13 == 0 {
                            l = Vec3::NAN;
                        }
                        pos.push(p);
                        radiance.push(l);
                        if l.x.is_nan() {
                            continue;
                        }
                        for ty in y.saturating_sub(m)..=y + m {
                            for tx in x.saturating_sub(m)..=x + m {
                                let wt = filter.eval_1d(p.y - (ty as f32 + 0.5))
                                    * filter.eval_1d(p.x - (tx as f32 + 0.5));
                                if let Some(k) = one_by_one.index(tx, ty) {
                                    one_by_one.sums[k].add_sample(l, wt);
                                }
                            }
                        }
                    }
                }
            }
            let pixels = Pixels {
                x0: px0,
                x1: px1,
                y0: py0,
                y1: py1,
                first: &first,
            };
            bulk.splat_each(&splatter, pixels, &pos, &radiance);
            assert_eq!(bulk.into_sums(), one_by_one, "{filter:?}");
        }
    }

    #[test]
    fn parts_fold_into_the_sum_of_their_contributions() {
        let mut p = Parts::default();
        let mut s = PixelSum::default();
        let xs = [
            i64::MAX,
            i64::MIN + 1,
            -1,
            1,
            0xffff_ffff,
            -(1 << 40),
            12345,
        ];
        let mut exact = 0i128;
        for &x in &xs {
            p.add(1, x);
            exact += i128::from(x);
        }
        p.fold_into(&mut s);
        assert_eq!(s.rgb[1], exact);
        assert_eq!(s.rgb[0], 0);
        assert_eq!((p.low, p.high), ([0; 4], [0; 4]));
    }
}
