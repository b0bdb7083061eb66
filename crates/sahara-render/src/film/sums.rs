//! Exact filter-weighted sums: the accumulation that makes an image
//! independent of how its samples are grouped.
//!
//! A pixel's estimate is `sum w L / sum w` over the samples within the
//! filter's reach. Floating-point addition is not associative, so summing
//! the same contributions per tile, per pass, per thread or per process
//! would give different bits depending on the grouping. Here every
//! contribution (`w L` per channel, and `w`) is computed in `f64` (the
//! product of two `f32` is exact there), converted to a signed fixed-point
//! number with [`FRACTION_BITS`] fractional bits and added as an `i128`.
//! Integer addition is associative and commutative, so a pixel's sums are
//! the same bits however the samples are split into tiles, passes, sample
//! ranges or processes, and in whatever order the pieces are added.
//!
//! The conversion rounds toward zero below `2^-52` (far below what an `f32`
//! pixel can show) and clamps a contribution to `±2^40`, so that no sum of
//! fewer than `2^35` contributions overflows. A contribution below `2^11`
//! in magnitude (nearly all of them) is one multiplication by `2^52`, which
//! is exact, and one truncating conversion to `i64`; larger ones convert
//! the integer part and the fraction as two `i64`, which avoids the slow
//! general `f64` to `i128` conversion. Both give the same bits.
//!
//! A render's samples are splatted into these sums in bulk, a few
//! instructions per tap, by [`crate::film::splat`].

use glam::{Vec2, Vec3};

use crate::film::filter::Filter;

/// Fractional bits of the fixed-point sums.
pub const FRACTION_BITS: i32 = 52;

/// Largest magnitude of one contribution; larger ones are clamped.
const MAX_CONTRIBUTION: f64 = (1u64 << 40) as f64;

/// `2^FRACTION_BITS`: a contribution times this is its fixed-point value
/// before truncation (exactly: scaling by a power of two is exact).
const ONE: f64 = (1u64 << FRACTION_BITS) as f64;

/// Scaled contributions below this magnitude (`2^63`, a contribution of
/// `2^11`) convert to `i64` directly.
const FAST_BELOW: f64 = 9_223_372_036_854_775_808.0;

/// One contribution as a fixed-point number, truncated toward zero.
#[inline]
fn fixed(v: f64) -> i128 {
    let s = v * ONE;
    if s.abs() < FAST_BELOW {
        // SAFETY: |s| < 2^63, so s truncated fits an i64 (NaN fails the test).
        // The same bits as the general case: `whole * 2^52` is an integer
        // and the fraction's part has the sign of `v`, so truncating their
        // sum truncates the fraction's part alone.
        return i128::from(unsafe { s.to_int_unchecked::<i64>() });
    }
    fixed_general(v)
}

/// [`fixed`] for any contribution: the integer part and the fraction
/// converted apart.
#[cold]
fn fixed_general(v: f64) -> i128 {
    let v = v.clamp(-MAX_CONTRIBUTION, MAX_CONTRIBUTION);
    let whole = v as i64;
    // Exact (|v| < 2^52), with the sign of v; scaling by a power of two is
    // exact too, and the cast truncates.
    let fraction = ((v - whole as f64) * (2.0f64).powi(FRACTION_BITS)) as i64;
    ((whole as i128) << FRACTION_BITS) + fraction as i128
}

/// A fixed-point sum as a float (rounded to nearest).
#[inline]
fn float(v: i128) -> f64 {
    v as f64 * (2.0f64).powi(-FRACTION_BITS)
}

/// The sums of one pixel: filter-weighted radiance per channel and the
/// filter weights, in fixed point (`FRACTION_BITS` fractional bits).
///
/// Aligned to 64 bytes, its size: one cache line each.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(align(64))]
pub struct PixelSum {
    /// `sum w L` for R, G and B.
    pub rgb: [i128; 3],
    /// `sum w`.
    pub weight: i128,
}

impl PixelSum {
    /// Adds one sample of radiance `l` with filter weight `w`.
    #[inline]
    pub fn add_sample(&mut self, l: Vec3, w: f32) {
        let w64 = w as f64;
        self.rgb[0] += fixed(l.x as f64 * w64);
        self.rgb[1] += fixed(l.y as f64 * w64);
        self.rgb[2] += fixed(l.z as f64 * w64);
        self.weight += fixed(w64);
    }

    /// Adds radiance `l` with filter weight `w` to the radiance sums
    /// only, not to the weight (light arriving from other pixels' samples).
    #[inline]
    pub fn add_radiance(&mut self, l: Vec3, w: f32) {
        let w64 = w as f64;
        self.rgb[0] += fixed(l.x as f64 * w64);
        self.rgb[1] += fixed(l.y as f64 * w64);
        self.rgb[2] += fixed(l.z as f64 * w64);
    }

    /// Adds another pixel's sums (exactly).
    #[inline]
    pub fn add(&mut self, other: &PixelSum) {
        for c in 0..3 {
            self.rgb[c] += other.rgb[c];
        }
        self.weight += other.weight;
    }

    /// The pixel's radiance: the weighted mean, zero where no weight
    /// arrived; negative estimates (from the negative lobes of some
    /// filters) become zero, since radiance is not negative.
    pub fn value(&self) -> Vec3 {
        self.mean().max(Vec3::ZERO)
    }

    /// The weighted mean, with its sign (zero where no weight arrived).
    pub fn mean(&self) -> Vec3 {
        if self.weight <= 0 {
            return Vec3::ZERO;
        }
        let w = float(self.weight);
        Vec3::new(
            (float(self.rgb[0]) / w) as f32,
            (float(self.rgb[1]) / w) as f32,
            (float(self.rgb[2]) / w) as f32,
        )
    }
}

/// A rectangle of pixels `[x0, x0 + width) x [y0, y0 + height)` of an
/// image, with each pixel's [`PixelSum`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SumBuffer {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width * height` sums, row-major from `(x0, y0)`.
    pub sums: Vec<PixelSum>,
}

impl SumBuffer {
    /// Zero sums over `[x0, x0 + width) x [y0, y0 + height)`.
    pub fn new(x0: u32, y0: u32, width: u32, height: u32) -> Self {
        Self {
            x0,
            y0,
            width,
            height,
            sums: vec![PixelSum::default(); width as usize * height as usize],
        }
    }

    /// The sums of pixel `(x, y)` (image coordinates), if it is inside.
    pub fn get(&self, x: u32, y: u32) -> Option<&PixelSum> {
        self.index(x, y).map(|k| &self.sums[k])
    }

    /// The index in `sums` of pixel `(x, y)`, if it is inside.
    pub(crate) fn index(&self, x: u32, y: u32) -> Option<usize> {
        let (i, j) = (x.checked_sub(self.x0)?, y.checked_sub(self.y0)?);
        (i < self.width && j < self.height).then(|| j as usize * self.width as usize + i as usize)
    }

    /// Adds light that arrives at film position `pos` (pixel units) from
    /// samples of other pixels (light tracing): `f(centre - pos) l` to the
    /// radiance sums of every pixel of the buffer whose centre lies within
    /// the filter's radius, nothing to their weights.
    ///
    /// A pixel's value is its radiance sum over its weight sum, and the
    /// weights of one sample per pixel across the image add up, in
    /// expectation, to the filter's integral at every pixel (to its part
    /// inside the image at the border, where light tracing's positions end
    /// too). So a contribution per sample of each pixel, splatted here,
    /// counts as pbrt's splats do after division by the samples per pixel
    /// and the filter's integral, with no normalisation of its own; and
    /// the sums stay exact, so the image still does not depend on the
    /// order the contributions arrive in.
    pub fn add_splat(&mut self, filter: &Filter, pos: Vec2, l: Vec3) {
        let (x0, y0, width, height) = (self.x0, self.y0, self.width, self.height);
        splat_rows(&mut self.sums, x0, y0, width, height, filter, pos, l);
    }

    /// [`SumBuffer::add_splat`] for every splat of `groups`, each `scale`
    /// times, spread over the thread pool by bands of rows (the sums are
    /// exact, so the order they arrive in does not matter).
    pub(crate) fn add_splats(&mut self, filter: &Filter, groups: &[&[Splat]], scale: f32) {
        use rayon::prelude::*;
        let w = self.width as usize;
        if w == 0 || self.height == 0 || groups.iter().all(|g| g.is_empty()) {
            return;
        }
        let band = (self.height as usize)
            .div_ceil(4 * rayon::current_num_threads().max(1))
            .max(1);
        let r = filter.radius();
        let (x0, y0, width) = (self.x0, self.y0, self.width);
        self.sums
            .par_chunks_mut(band * w)
            .enumerate()
            .for_each(|(b, rows)| {
                let top = y0 + (b * band) as u32;
                let n = (rows.len() / w) as u32;
                // Pixel centres y + 1/2 within the filter's radius of the band.
                let (lo, hi) = (top as f32 + 0.5 - r, (top + n) as f32 - 0.5 + r);
                for s in groups.iter().flat_map(|g| g.iter()) {
                    if s.pos.y >= lo && s.pos.y <= hi {
                        splat_rows(rows, x0, top, width, n, filter, s.pos, s.l * scale);
                    }
                }
            });
    }

    /// Adds `other`'s sums over the pixels both cover.
    pub fn add(&mut self, other: &SumBuffer) {
        let x0 = self.x0.max(other.x0);
        let y0 = self.y0.max(other.y0);
        let x1 = (self.x0 + self.width).min(other.x0 + other.width);
        let y1 = (self.y0 + self.height).min(other.y0 + other.height);
        for y in y0..y1.max(y0) {
            for x in x0..x1.max(x0) {
                let (Some(a), Some(b)) = (self.index(x, y), other.index(x, y)) else {
                    continue;
                };
                let b = other.sums[b];
                self.sums[a].add(&b);
            }
        }
    }
}

/// Light arriving at a film position from the samples of other pixels
/// (light tracing), added to the pixels around it without weight (see
/// [`SumBuffer::add_splat`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Splat {
    /// Film position, in pixels from the top-left corner.
    pub pos: Vec2,
    /// The contribution.
    pub l: Vec3,
}

/// [`SumBuffer::add_splat`] into the pixel sums `sums` of the rectangle
/// `[x0, x0 + width) x [y0, y0 + height)`, row-major.
#[allow(clippy::too_many_arguments)]
fn splat_rows(
    sums: &mut [PixelSum],
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    filter: &Filter,
    pos: Vec2,
    l: Vec3,
) {
    if width == 0 || height == 0 || !pos.is_finite() {
        return;
    }
    let r = filter.radius();
    let lo = |p: f32, o: u32| ((p - 0.5 - r).ceil().max(o as f32)) as u32;
    let hi = |p: f32, o: u32, n: u32| (p - 0.5 + r).floor().min((o + n - 1) as f32);
    let (px0, py0) = (lo(pos.x, x0), lo(pos.y, y0));
    let (px1, py1) = (hi(pos.x, x0, width), hi(pos.y, y0, height));
    if px1 < px0 as f32 || py1 < py0 as f32 {
        return;
    }
    for py in py0..=py1 as u32 {
        let wy = filter.eval_1d(pos.y - (py as f32 + 0.5));
        if wy == 0.0 {
            continue;
        }
        let row = (py - y0) as usize * width as usize;
        for px in px0..=px1 as u32 {
            let w = wy * filter.eval_1d(pos.x - (px as f32 + 0.5));
            if w != 0.0 {
                sums[row + (px - x0) as usize].add_radiance(l, w);
            }
        }
    }
}

/// Pixels beyond a pixel's own that its samples reach through the filter.
pub fn filter_margin(f: &Filter) -> u32 {
    (f.radius() - 0.5).ceil().max(0.0) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_do_not_depend_on_grouping() {
        // Values whose float sums differ by grouping: (a + b) + c != a + (b + c).
        let samples = [1e8f32, 1.0, -1e8, 3.3, 1e-7, 7.25];
        let mut one = PixelSum::default();
        for &v in &samples {
            one.add_sample(Vec3::splat(v.abs()), 0.75);
        }
        let mut left = PixelSum::default();
        let mut right = PixelSum::default();
        for &v in &samples[..2] {
            left.add_sample(Vec3::splat(v.abs()), 0.75);
        }
        for &v in samples[2..].iter().rev() {
            right.add_sample(Vec3::splat(v.abs()), 0.75);
        }
        right.add(&left);
        assert_eq!(one, right);
        let exact: f64 = samples.iter().map(|v| v.abs() as f64).sum::<f64>() / 6.0;
        assert!((one.value().x as f64 - exact).abs() <= 1e-6 * exact);
    }

    #[test]
    fn fixed_point_is_exact_down_to_its_resolution() {
        for v in [0.0, 1.0, -1.0, 0.75, -3.5e-9, 123456.789, -1e12, 1e300] {
            let f = fixed(v);
            let back = float(f);
            let v = v.clamp(-MAX_CONTRIBUTION, MAX_CONTRIBUTION);
            assert!(back.abs() <= v.abs(), "{v}: truncated toward zero");
            assert!((v - back).abs() < (2.0f64).powi(-FRACTION_BITS), "{v}");
        }
        assert_eq!(fixed(0.5), 1i128 << (FRACTION_BITS - 1));
        assert_eq!(fixed(-2.25), -(9i128 << (FRACTION_BITS - 2)));
    }

    #[test]
    fn the_one_step_conversion_gives_the_general_bits() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut values = vec![
            0.0, -0.0, 2047.999, -2047.999, 2048.0, -2048.0, 1e-300, -5e-324,
        ];
        for _ in 0..20_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            // Magnitudes from 2^-60 to 2^14, both signs, fractions of all kinds.
            let m = (state >> 11) as f64 / (1u64 << 53) as f64;
            let e = (state % 75) as i32 - 60;
            let v = m * (2.0f64).powi(e);
            values.push(if state & 1 == 0 { v } else { -v });
        }
        for v in values {
            assert_eq!(fixed(v), fixed_general(v), "{v:e}");
        }
    }

    #[test]
    fn negative_estimates_become_zero_and_empty_pixels_black() {
        let mut p = PixelSum::default();
        assert_eq!(p.value(), Vec3::ZERO);
        p.add_sample(Vec3::ONE, 0.5);
        assert_eq!(p.value(), Vec3::ONE);
        // A negative lobe: sum w L = 0.5 - 1 < 0 with sum w = 0.25 > 0.
        p.add_sample(Vec3::splat(4.0), -0.25);
        assert_eq!(p.value(), Vec3::ZERO);
        // No weight at all: black.
        let mut q = PixelSum::default();
        q.add_sample(Vec3::ONE, -0.5);
        assert_eq!(q.value(), Vec3::ZERO);
    }

    #[test]
    fn splat_reaches_the_filter_footprint_inside_the_buffer_only() {
        let f = Filter::Box { radius: 1.0 };
        let m = filter_margin(&f);
        assert_eq!(m, 1);
        let mut b = SumBuffer::new(2, 2, 2, 2);
        // A sample in pixel (1, 1) near its lower right corner reaches (2, 2) only.
        b.splat(&f, m, 1, 1, Vec2::new(1.9, 1.9), Vec3::ONE);
        assert_eq!(b.get(2, 2).unwrap().value(), Vec3::ONE);
        assert_eq!(b.get(3, 2).unwrap().weight, 0);
        let mut c = SumBuffer::new(0, 0, 4, 4);
        c.add(&b);
        assert_eq!(c.get(2, 2), b.get(2, 2));
        assert_eq!(c.get(1, 1).unwrap().weight, 0);
    }
}
