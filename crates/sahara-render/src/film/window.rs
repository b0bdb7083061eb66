//! Dividing a frame: pixel windows, balanced tiles, sample ranges and crop
//! windows, for renders split over several processes.

use std::ops::Range;

/// A rectangle of pixels `[x0, x1) x [y0, y1)` (it may be empty).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PixelWindow {
    /// Left column.
    pub x0: u32,
    /// One past the right column.
    pub x1: u32,
    /// Top row.
    pub y0: u32,
    /// One past the bottom row.
    pub y1: u32,
}

impl PixelWindow {
    /// The whole `width x height` image.
    pub fn full(width: u32, height: u32) -> Self {
        Self {
            x0: 0,
            x1: width,
            y0: 0,
            y1: height,
        }
    }

    /// Columns.
    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    /// Rows.
    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    /// Number of pixels.
    pub fn pixels(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }

    /// True if it holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.pixels() == 0
    }

    /// The pixels both hold (empty if none).
    pub fn intersect(&self, o: &PixelWindow) -> PixelWindow {
        let w = PixelWindow {
            x0: self.x0.max(o.x0),
            x1: self.x1.min(o.x1),
            y0: self.y0.max(o.y0),
            y1: self.y1.min(o.y1),
        };
        if w.is_empty() {
            PixelWindow {
                x0: w.x0,
                x1: w.x0,
                y0: w.y0,
                y1: w.y0,
            }
        } else {
            w
        }
    }

    /// Grown by `m` pixels on every side, within a `width x height` image.
    pub fn grow(&self, m: u32, width: u32, height: u32) -> PixelWindow {
        if self.is_empty() {
            return *self;
        }
        PixelWindow {
            x0: self.x0.saturating_sub(m),
            x1: self.x1.saturating_add(m).min(width),
            y0: self.y0.saturating_sub(m),
            y1: self.y1.saturating_add(m).min(height),
        }
    }

    /// Grown outwards to the grid of `b x b` pixel blocks aligned with the
    /// image's corner, within a `width x height` image.
    pub fn align(&self, b: u32, width: u32, height: u32) -> PixelWindow {
        let b = b.max(1);
        if self.is_empty() {
            return *self;
        }
        PixelWindow {
            x0: self.x0 / b * b,
            x1: self.x1.div_ceil(b).saturating_mul(b).min(width),
            y0: self.y0 / b * b,
            y1: self.y1.div_ceil(b).saturating_mul(b).min(height),
        }
    }
}

impl std::fmt::Display for PixelWindow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "x {}..{}, y {}..{}", self.x0, self.x1, self.y0, self.y1)
    }
}

/// The columns x rows grid that divides `window` into `n` tiles with the
/// shortest cuts (a prime `n` gives strips across the longer side).
fn grid(window: &PixelWindow, n: u32) -> (u32, u32) {
    let (w, h) = (window.width() as u64, window.height() as u64);
    (1..=n)
        .filter(|c| n.is_multiple_of(*c))
        .map(|c| (c, n / c))
        .min_by_key(|&(c, r)| (c as u64 - 1) * h + (r as u64 - 1) * w)
        .unwrap_or((1, 1))
}

/// Tile `i` (0-based, row-major) of `window` divided into `n` tiles of
/// nearly equal pixel counts: a grid whose column widths and row heights
/// differ by at most one pixel. A tile is empty when the window has fewer
/// columns or rows than the grid.
pub fn tile(window: &PixelWindow, i: u32, n: u32) -> PixelWindow {
    let n = n.max(1);
    let (cols, rows) = grid(window, n);
    let (c, r) = (i % cols, i / cols);
    let cut =
        |a: u32, len: u32, k: u32, parts: u32| a + (len as u64 * k as u64 / parts as u64) as u32;
    PixelWindow {
        x0: cut(window.x0, window.width(), c, cols),
        x1: cut(window.x0, window.width(), c + 1, cols),
        y0: cut(window.y0, window.height(), r, rows),
        y1: cut(window.y0, window.height(), r + 1, rows),
    }
}

/// Range `i` (0-based) of `samples` divided into `n` contiguous ranges of
/// nearly equal length (some empty when there are fewer samples than `n`).
pub fn sample_range(samples: &Range<u32>, i: u32, n: u32) -> Range<u32> {
    let n = n.max(1) as u64;
    let len = samples.end.saturating_sub(samples.start) as u64;
    let at = |k: u64| samples.start + (len * k / n) as u32;
    at(i as u64)..at(i as u64 + 1)
}

/// The pixels of a crop window given as fractions `[x0, x1] x [y0, y1]` of
/// a `width x height` image (y from the top), as pbrt-v4 computes them:
/// each bound is `ceil(fraction * size)`.
pub fn crop(width: u32, height: u32, fractions: [f64; 4]) -> PixelWindow {
    let at = |f: f64, size: u32| (f.clamp(0.0, 1.0) * size as f64).ceil() as u32;
    let [x0, x1, y0, y1] = fractions;
    PixelWindow {
        x0: at(x0, width),
        x1: at(x1, width).max(at(x0, width)),
        y0: at(y0, height),
        y1: at(y1, height).max(at(y0, height)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_window_once_and_are_balanced() {
        let win = PixelWindow {
            x0: 3,
            x1: 103,
            y0: 1,
            y1: 58,
        };
        for n in 1..=17 {
            let mut count = vec![0u8; (win.x1 * win.y1) as usize];
            let mut sizes = Vec::new();
            for i in 0..n {
                let t = tile(&win, i, n);
                sizes.push(t.pixels());
                for y in t.y0..t.y1 {
                    for x in t.x0..t.x1 {
                        count[(y * win.x1 + x) as usize] += 1;
                    }
                }
            }
            for y in 0..win.y1 {
                for x in 0..win.x1 {
                    let inside = x >= win.x0 && y >= win.y0;
                    assert_eq!(count[(y * win.x1 + x) as usize], inside as u8, "n {n}");
                }
            }
            let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
            // Rows and columns differ by at most one.
            assert!(hi - lo <= win.width() as u64 + win.height() as u64, "n {n}");
        }
        // A 1-pixel-wide window in 4 parts: some tiles are empty.
        let thin = PixelWindow::full(1, 2);
        let total: u64 = (0..4).map(|i| tile(&thin, i, 4).pixels()).sum();
        assert_eq!(total, 2);
    }

    #[test]
    fn aligned_windows_cover_whole_blocks_within_the_image() {
        let w = PixelWindow {
            x0: 3,
            x1: 6,
            y0: 4,
            y1: 9,
        };
        let a = w.align(2, 100, 9);
        assert_eq!((a.x0, a.x1, a.y0, a.y1), (2, 6, 4, 9));
        assert_eq!(a.align(2, 100, 9), a);
        assert_eq!(w.align(1, 100, 100), w);
    }

    #[test]
    fn sample_ranges_are_contiguous() {
        let r = 5..17;
        let parts: Vec<_> = (0..5).map(|i| sample_range(&r, i, 5)).collect();
        assert_eq!(parts[0].start, 5);
        assert_eq!(parts[4].end, 17);
        for p in parts.windows(2) {
            assert_eq!(p[0].end, p[1].start);
        }
        assert_eq!(sample_range(&(0..2), 0, 4), 0..0);
    }

    #[test]
    fn crop_rounds_up_like_pbrt() {
        let c = crop(100, 50, [0.0, 0.333, 0.5, 1.0]);
        assert_eq!(
            c,
            PixelWindow {
                x0: 0,
                x1: 34,
                y0: 25,
                y1: 50
            }
        );
    }
}
