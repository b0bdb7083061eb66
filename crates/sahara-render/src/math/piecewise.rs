//! Piecewise-constant distributions in one and two dimensions (tabulated
//! CDFs inverted by binary search).

use glam::Vec2;

/// A piecewise-constant density on `[0, 1)` over `n` equal cells, also usable
/// as a discrete distribution over the cells.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    /// A distribution proportional to the non-negative weights `func`
    /// (all-zero or non-finite input falls back to uniform).
    pub fn new(func: Vec<f32>) -> Self {
        let n = func.len().max(1);
        let mut func = func;
        if func.is_empty() {
            func.push(0.0);
        }
        for f in &mut func {
            if !f.is_finite() || *f < 0.0 {
                *f = 0.0;
            }
        }
        // Accumulate in f64 so that long tables (an environment map row has
        // thousands of cells) keep their small entries.
        let mut cdf = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0f32);
        for f in &func {
            acc += *f as f64 / n as f64;
            cdf.push(acc as f32);
        }
        let integral = acc as f32;
        if integral > 0.0 {
            for c in &mut cdf {
                *c /= integral;
            }
        } else {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f32 / n as f32;
            }
        }
        cdf[n] = 1.0;
        Self {
            func,
            cdf,
            integral,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// True if there are no cells (never: `new` makes at least one).
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// Integral of the tabulated function over `[0, 1)`.
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The cell holding `u`: the last `i` with `cdf[i] <= u`.
    #[inline]
    fn find(&self, u: f32) -> usize {
        // partition_point returns the first index with cdf > u; the cell is
        // one before. Cells of zero probability are never returned because
        // their cdf entries equal the next one's.
        let i = self.cdf.partition_point(|&c| c <= u);
        i.saturating_sub(1).min(self.func.len() - 1)
    }

    /// A cell index chosen with probability proportional to its weight, and
    /// that probability.
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32) {
        let i = self.find(u);
        (i, self.pmf(i))
    }

    /// Probability of cell `i` in [`Distribution1D::sample_discrete`].
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// A point in `[0, 1)` with its density, and its cell.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let i = self.find(u);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let n = self.func.len() as f32;
        let x = ((i as f32 + du) / n).min(1.0 - f32::EPSILON * 0.5);
        (x, self.pdf_cell(i), i)
    }

    /// Density of the continuous distribution in cell `i`.
    #[inline]
    pub fn pdf_cell(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            self.func[i] / self.integral
        } else {
            1.0
        }
    }
}

/// A piecewise-constant density on `[0, 1)^2` over a `nu x nv` grid: a
/// marginal over rows (v) and one conditional per row (u).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// A distribution proportional to `f[v * nu + u]`.
    pub fn new(f: &[f32], nu: usize, nv: usize) -> Self {
        assert_eq!(f.len(), nu * nv, "one weight per cell");
        let rows: Vec<Distribution1D> = (0..nv)
            .map(|v| Distribution1D::new(f[v * nu..(v + 1) * nu].to_vec()))
            .collect();
        let marginal = Distribution1D::new(rows.iter().map(|r| r.integral()).collect());
        Self { rows, marginal }
    }

    /// A point `(u, v)` and its density.
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_u, _) = self.rows[row].sample_continuous(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u)
    }

    /// Density at `(u, v)`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        let nv = self.rows.len();
        let nu = self.rows[0].len();
        let iv = ((p.y * nv as f32) as usize).min(nv - 1);
        let iu = ((p.x * nu as f32) as usize).min(nu - 1);
        self.marginal.pdf_cell(iv) * self.rows[iv].pdf_cell(iu)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_probabilities_match_weights() {
        let d = Distribution1D::new(vec![1.0, 0.0, 3.0]);
        assert_eq!(d.sample_discrete(0.1).0, 0);
        assert_eq!(d.sample_discrete(0.3).0, 2);
        assert!((d.pmf(0) - 0.25).abs() < 1e-6);
        assert_eq!(d.pmf(1), 0.0);
        assert!((d.pmf(2) - 0.75).abs() < 1e-6);
    }

    #[test]
    fn continuous_pdf_integrates_to_one() {
        let f: Vec<f32> = (0..8 * 4).map(|i| (i % 5) as f32).collect();
        let d = Distribution2D::new(&f, 8, 4);
        // Midpoint rule over the cells is exact for a piecewise constant.
        let mut sum = 0.0;
        for v in 0..4 {
            for u in 0..8 {
                sum += d.pdf(Vec2::new((u as f32 + 0.5) / 8.0, (v as f32 + 0.5) / 4.0)) / 32.0;
            }
        }
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        let (p, pdf) = d.sample(Vec2::new(0.37, 0.81));
        assert!((pdf - d.pdf(p)).abs() < 1e-4);
    }
}
