//! Adaptive sampling: pixels stop taking samples once their noise is
//! below a threshold, and the render's time goes to the others.
//!
//! A pixel's noise is the standard error of its mean, estimated from the
//! sample variance of its own samples (before the reconstruction filter),
//! relative to the square root of its brightness, so that it follows the
//! noise a viewer sees after tone mapping rather than the absolute
//! variance (bright pixels are not held back for noise no one can see):
//!
//! `error = sqrt(2/π) (se_R + se_G + se_B) / (1e-4 + sqrt(R + G + B))`,
//! with `se_c = sqrt(var_c / n)` and `R, G, B` the pixel's mean.
//!
//! Cycles estimates the same quantity from two interleaved half-buffers,
//! `|I - A|` of the whole mean `I` and the odd samples' mean `A`, whose
//! expected value is `sqrt(2/π)` standard errors: the factor keeps its
//! thresholds' meaning. The halves' difference is one draw per channel,
//! though, and pixels stopped on a lucky draw: on the Cornell box at equal
//! samples it rendered no better than uniform sampling (docs/clean-image.md),
//! while the variance of `n` samples is a steady estimate. With Sobol
//! samples, whose means converge faster than `σ / sqrt(n)`, the estimate
//! errs on the safe side.
//!
//! The test runs after each pass once a pixel has `min_spp` samples, and
//! pixels stop in 2x2 blocks: a block stops when all four of its pixels
//! are below the threshold. The estimate of a pixel whose samples are
//! mostly dark with rare bright ones (a glint, a small light seen through
//! a rough reflection) is low until a bright sample comes; judged alone,
//! such pixels stop early on a lucky run, darker than they should be
//! (docs/clean-image.md has what that costs). A neighbour in the block
//! that has seen its bright samples keeps the block going (Cycles widens
//! the active pixels by one for the same reason). The blocks lie on a grid
//! fixed to the image's corner and a piece of the frame renders whole
//! blocks, so a window of the frame rendered alone (a farm tile) makes the
//! same decisions as the whole frame, and the frame split into tiles and
//! merged is the frame rendered whole, bit for bit. The sums are in `f64`,
//! added in sample order per pixel, and so do not depend on the number of
//! threads either.

use glam::Vec3;

use crate::film::window::PixelWindow;
pub use crate::settings::Adaptive;

/// The expected difference of two half-buffers' means, in standard errors
/// of the whole mean: `sqrt(2/π)`, which keeps Cycles' threshold scale.
const HALVES: f64 = 0.797_884_560_802_865_4;

/// The side of the pixel blocks that stop together, on a grid aligned with
/// the image's corner.
pub(crate) const BLOCK: u32 = 2;

/// What adaptive sampling did, over the window's pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdaptiveStats {
    /// Samples taken.
    pub samples: u64,
    /// Samples the window's pixels would have taken without it (the pixels
    /// times the passes' samples per pixel).
    pub budget: u64,
    /// Pixels that stopped below the threshold before the cap.
    pub converged: u64,
    /// Pixels of the window.
    pub pixels: u64,
}

/// One pixel's own samples: their sums and sums of squares, per channel.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PixelSums {
    all: [f64; 3],
    squares: [f64; 3],
    count: u32,
}

impl PixelSums {
    /// Adds a sample of radiance `l`.
    #[inline]
    pub(crate) fn add(&mut self, l: Vec3) {
        for (c, v) in l.to_array().into_iter().enumerate() {
            let v = f64::from(v);
            self.all[c] += v;
            self.squares[c] += v * v;
        }
        self.count += 1;
    }

    /// Adds another run of the same pixel's samples (later in order).
    fn merge(&mut self, o: &PixelSums) {
        for c in 0..3 {
            self.all[c] += o.all[c];
            self.squares[c] += o.squares[c];
        }
        self.count += o.count;
    }

    /// The noise estimate of the module's formula (infinite with fewer
    /// than two samples).
    pub(crate) fn error(&self) -> f64 {
        if self.count < 2 {
            return f64::INFINITY;
        }
        let n = f64::from(self.count);
        let (mut standard_error, mut mean) = (0.0, 0.0);
        for c in 0..3 {
            let m = self.all[c] / n;
            let variance = ((self.squares[c] - n * m * m) / (n - 1.0)).max(0.0);
            standard_error += (variance / n).sqrt();
            mean += m;
        }
        HALVES * standard_error / (1e-4 + mean.max(0.0).sqrt())
    }
}

/// Which pixels of the rendered region still take samples, how many each
/// takes in the next round, and their sums so far.
#[derive(Clone, Debug)]
pub(crate) struct Convergence {
    /// The pixels rendered: the window and the filter's margin around it.
    region: PixelWindow,
    settings: Adaptive,
    /// Samples per pass, and the most a pixel takes.
    pass: u32,
    cap: u32,
    /// False: every round is one pass.
    grow: bool,
    sums: Vec<PixelSums>,
    /// Samples each pixel takes in the next round (0: none, it stopped).
    take: Vec<u32>,
    /// Pixels that stopped below the threshold.
    converged: Vec<bool>,
}

impl Convergence {
    /// Every pixel of `region` active, taking one pass of `pass` samples
    /// in the first round, at most `cap` in all; with `grow` false, every
    /// round is one pass (a render under a time limit, which drops the
    /// round under way when time runs out, then loses little).
    pub(crate) fn new(
        region: PixelWindow,
        settings: Adaptive,
        pass: u32,
        cap: u32,
        grow: bool,
    ) -> Self {
        let n = region.pixels() as usize;
        let pass = pass.max(1);
        Self {
            region,
            settings,
            pass,
            cap,
            grow,
            sums: vec![PixelSums::default(); n],
            take: vec![pass.min(cap); n],
            converged: vec![false; n],
        }
    }

    /// The index of pixel `(x, y)` (one past the end outside the region,
    /// so that a lookup there finds nothing rather than panics).
    fn index(&self, x: u32, y: u32) -> usize {
        let (i, j) = (
            x.wrapping_sub(self.region.x0),
            y.wrapping_sub(self.region.y0),
        );
        if i < self.region.width() && j < self.region.height() {
            (j * self.region.width() + i) as usize
        } else {
            self.take.len()
        }
    }

    /// True if pixel `(x, y)` of the region takes samples in this round
    /// (false outside it).
    #[inline]
    pub(crate) fn is_active(&self, x: u32, y: u32) -> bool {
        self.take.get(self.index(x, y)).is_some_and(|&t| t > 0)
    }

    /// The samples pixel `(x, y)` takes in this round, numbered over all
    /// passes (empty outside the region).
    #[inline]
    pub(crate) fn round(&self, x: u32, y: u32) -> std::ops::Range<u32> {
        let i = self.index(x, y);
        match (self.sums.get(i), self.take.get(i)) {
            (Some(s), Some(&t)) => s.count..s.count + t,
            _ => 0..0,
        }
    }

    /// True if any pixel of `[x0, x1) x [y0, y1)` takes samples.
    pub(crate) fn any_active(&self, x0: u32, x1: u32, y0: u32, y1: u32) -> bool {
        (y0..y1).any(|y| (x0..x1).any(|x| self.is_active(x, y)))
    }

    /// Adds a tile's per-pixel sums of this pass (`own` over `[x0, x1) x
    /// [y0, y1)`, rows top to bottom).
    pub(crate) fn add(&mut self, own: &TileSums) {
        let mut k = 0;
        for y in own.y0..own.y1 {
            for x in own.x0..own.x1 {
                let i = self.index(x, y);
                self.sums[i].merge(&own.sums[k]);
                k += 1;
            }
        }
    }

    /// After a round: the blocks whose pixels all have at least `min_spp`
    /// samples and noise below the threshold stop; the others are given
    /// the samples of their next round. Returns how many pixels remain
    /// active.
    ///
    /// A block takes whole passes, as many as its noise says it needs to
    /// reach the threshold (`n ((error / threshold)^2 - 1)` more samples,
    /// the error falling as `1 / sqrt(n)`), but at most as many as it has:
    /// the pixels still noisy late in a render take many samples at a time,
    /// which keeps the batches traced together full when few pixels are
    /// left, while a block near the threshold takes one pass and is tested
    /// again.
    pub(crate) fn update(&mut self) -> usize {
        let min = self.settings.min_spp.max(2);
        let threshold = f64::from(self.settings.threshold);
        let b = BLOCK;
        let r = self.region;
        let mut left = 0;
        for by in (r.y0 / b * b..r.y1).step_by(b as usize) {
            for bx in (r.x0 / b * b..r.x1).step_by(b as usize) {
                let (ys, xs) = (
                    by.max(r.y0)..(by + b).min(r.y1),
                    bx.max(r.x0)..(bx + b).min(r.x1),
                );
                let pixels = || ys.clone().flat_map(|y| xs.clone().map(move |x| (x, y)));
                // A block's pixels start, and so stay, in one state, with
                // the same number of samples.
                if !self.is_active(xs.start, ys.start) {
                    continue;
                }
                let n = self.sums[self.index(xs.start, ys.start)].count;
                let worst = pixels()
                    .map(|(x, y)| self.sums[self.index(x, y)].error())
                    .fold(0.0, f64::max);
                let done = n >= min && worst < threshold;
                let want = if n < min {
                    min - n
                } else if !self.grow {
                    1
                } else {
                    // (NaN, for a flat block and a zero threshold, is one pass.)
                    let more = f64::from(n) * ((worst / threshold).powi(2) - 1.0);
                    more.ceil().max(1.0).min(f64::from(n)) as u32
                };
                let take = if done {
                    0
                } else {
                    (want.div_ceil(self.pass) * self.pass).min(self.cap.saturating_sub(n))
                };
                for (x, y) in pixels() {
                    let i = self.index(x, y);
                    self.take[i] = take;
                    self.converged[i] = done;
                }
                if take > 0 {
                    left += pixels().count();
                }
            }
        }
        left
    }

    /// The most samples a pixel of `window` took.
    pub(crate) fn most_samples(&self, window: &PixelWindow) -> u32 {
        self.samples(window).into_iter().max().unwrap_or(0)
    }

    /// The samples each pixel of `window` took, rows top to bottom.
    pub(crate) fn samples(&self, window: &PixelWindow) -> Vec<u32> {
        let mut out = Vec::with_capacity(window.pixels() as usize);
        for y in window.y0..window.y1 {
            for x in window.x0..window.x1 {
                out.push(self.sums[self.index(x, y)].count);
            }
        }
        out
    }

    /// What adaptive sampling did over `window`, whose pixels would each
    /// have taken `spp` samples without it.
    pub(crate) fn stats(&self, window: &PixelWindow, spp: u32) -> AdaptiveStats {
        let mut st = AdaptiveStats {
            pixels: window.pixels(),
            budget: window.pixels() * u64::from(spp),
            ..Default::default()
        };
        for y in window.y0..window.y1 {
            for x in window.x0..window.x1 {
                let i = self.index(x, y);
                st.samples += u64::from(self.sums[i].count);
                // A pixel below the threshold only at the cap took every
                // sample: it did not stop early.
                st.converged += (self.converged[i] && self.sums[i].count < spp) as u64;
            }
        }
        st
    }
}

/// A tile's per-pixel sums of one pass, `[x0, x1) x [y0, y1)`.
#[derive(Clone, Debug)]
pub(crate) struct TileSums {
    pub(crate) x0: u32,
    pub(crate) x1: u32,
    pub(crate) y0: u32,
    pub(crate) y1: u32,
    pub(crate) sums: Vec<PixelSums>,
}

impl TileSums {
    /// Empty sums over the tile.
    pub(crate) fn new(x0: u32, x1: u32, y0: u32, y1: u32) -> Self {
        let n = ((x1 - x0) * (y1 - y0)) as usize;
        Self {
            x0,
            x1,
            y0,
            y1,
            sums: vec![PixelSums::default(); n],
        }
    }

    /// Pixel `(x, y)`'s sums.
    #[inline]
    pub(crate) fn at(&mut self, x: u32, y: u32) -> &mut PixelSums {
        let i = ((y - self.y0) * (self.x1 - self.x0) + (x - self.x0)) as usize;
        &mut self.sums[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant pixel has no noise; samples alternating between 0 and 1
    /// in red have a standard error of sqrt(0.25 n / (n - 1) / n).
    #[test]
    fn the_error_is_the_standard_error_over_the_brightness() {
        let mut flat = PixelSums::default();
        for _ in 0..8 {
            flat.add(Vec3::splat(0.25));
        }
        assert_eq!(flat.error(), 0.0);
        let mut noisy = PixelSums::default();
        for k in 0..8 {
            noisy.add(Vec3::new((k % 2) as f32, 0.0, 0.0));
        }
        let se = (0.25f64 * 8.0 / 7.0 / 8.0).sqrt();
        let want = HALVES * se / (1e-4 + 0.5f64.sqrt());
        assert!((noisy.error() - want).abs() < 1e-12, "{}", noisy.error());
        assert_eq!(PixelSums::default().error(), f64::INFINITY);
        assert!((HALVES - (2.0 / std::f64::consts::PI).sqrt()).abs() < 1e-15);
    }

    /// Pixels stop in the 2x2 blocks of the image's grid, a block once all
    /// of its pixels have the minimum samples and are below the threshold.
    #[test]
    fn pixels_stop_in_blocks_with_enough_samples() {
        // Columns 1..5 of row 0: the blocks are columns 0..2 (only 1 in the
        // region), 2..4 and 4..6 (only 4).
        let region = PixelWindow {
            x0: 1,
            x1: 5,
            y0: 0,
            y1: 1,
        };
        let mut c = Convergence::new(
            region,
            Adaptive {
                threshold: 0.01,
                min_spp: 4,
            },
            2,
            8,
            true,
        );
        assert_eq!(c.round(1, 0), 0..2, "the first round is one pass");
        let mut tile = TileSums::new(1, 5, 0, 1);
        for k in 0..2 {
            for x in 1..4 {
                tile.at(x, 0).add(Vec3::ONE);
            }
            tile.at(4, 0).add(Vec3::splat(k as f32));
        }
        c.add(&tile);
        assert_eq!(c.update(), 4, "two samples are under the minimum");
        c.add(&tile);
        assert_eq!(c.update(), 1, "the flat pixels stop, the noisy one not");
        assert!((1..4).all(|x| !c.is_active(x, 0)) && c.is_active(4, 0));
        // Far above the threshold: as many samples as it has, to the cap.
        assert_eq!(c.round(4, 0), 4..8);
        let st = c.stats(&region, 8);
        assert_eq!(
            (st.samples, st.budget, st.converged, st.pixels),
            (16, 32, 3, 4)
        );
        // A flat pixel beside a noisy one in its block keeps going.
        let mut c = Convergence::new(
            PixelWindow {
                x0: 2,
                x1: 4,
                y0: 0,
                y1: 1,
            },
            Adaptive {
                threshold: 0.01,
                min_spp: 4,
            },
            4,
            8,
            true,
        );
        let mut tile = TileSums::new(2, 4, 0, 1);
        for k in 0..4 {
            tile.at(2, 0).add(Vec3::ONE);
            tile.at(3, 0).add(Vec3::splat((k % 2) as f32));
        }
        c.add(&tile);
        assert_eq!(c.update(), 2);
        assert!(c.is_active(2, 0));
        assert_eq!(c.round(2, 0), 4..8);
        // At the cap the block stops without having converged.
        c.add(&tile);
        assert_eq!(c.update(), 0);
        let st = c.stats(&c.region, 8);
        assert_eq!((st.samples, st.converged), (16, 0));
    }

    /// A block just above the threshold takes one pass; one at twice the
    /// threshold three times its samples, but at most as many as it has.
    #[test]
    fn a_block_takes_the_passes_its_noise_asks_for() {
        let region = PixelWindow {
            x0: 0,
            x1: 1,
            y0: 0,
            y1: 1,
        };
        let mut sums = PixelSums::default();
        for k in 0..16 {
            sums.add(Vec3::splat(1.0 + (k % 2) as f32));
        }
        let e = sums.error();
        let mut tile = TileSums::new(0, 1, 0, 1);
        *tile.at(0, 0) = sums;
        for (threshold, take) in [(e * 0.99, 8), (e / 2.0 * 1.0001, 16), (e / 1.5, 16)] {
            let mut c = Convergence::new(
                region,
                Adaptive {
                    threshold: threshold as f32,
                    min_spp: 4,
                },
                8,
                1024,
                true,
            );
            c.add(&tile);
            c.update();
            assert_eq!(c.round(0, 0).len() as u32, take, "threshold {threshold}");
        }
        let settings = Adaptive {
            threshold: (e / 2.0) as f32,
            min_spp: 4,
        };
        let mut c = Convergence::new(region, settings, 8, 1024, false);
        c.add(&tile);
        c.update();
        assert_eq!(c.round(0, 0), 16..24, "one pass a round");
    }
}
