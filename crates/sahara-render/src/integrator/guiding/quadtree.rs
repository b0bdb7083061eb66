//! The directional half of the SD-tree: a quadtree over the square of
//! cylindrical coordinates `(cos θ, φ)`, a density over the sphere of
//! directions proportional to the radiance it was trained on.
//!
//! The map from the square to the sphere, `cos θ = 2x − 1`, `φ = 2πy`,
//! preserves area (Archimedes' hat-box theorem), so a density over the
//! square is a density over directions divided by 4π, and the quadtree's
//! cells, each a quarter of its parent's square, are cells of equal solid
//! angle at each depth.
//!
//! Two forms share the structure: [`Quadtree`] holds the sums in floats
//! and is what paths sample and evaluate; [`Training`] holds them as
//! integers, added to from every thread with atomic integer additions.
//! Integer addition does not depend on the order it is done in, so a
//! trained tree is the same bit for bit whatever the threads did.

use std::f32::consts::PI;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Vec2, Vec3};

/// The deepest a quadtree's cells go (the paper's limit: cells of
/// 4^-20 of the sphere).
pub(crate) const MAX_DEPTH: u32 = 20;

/// Fixed-point scale of the training sums: a value `v` is added as
/// `v * 2^16` rounded stochastically (so that the integer sums are
/// unbiased estimates of the float sums).
const SCALE: f64 = 65536.0;
/// The largest value one splat adds (about 4e9 in radiance units over
/// density): a guard against overflow, not a clamp that matters.
const MAX_ADD: f64 = (1u64 << 48) as f64;

/// The direction of point `p` of the square.
#[inline]
pub(crate) fn to_direction(p: Vec2) -> Vec3 {
    let cos = (2.0 * p.x - 1.0).clamp(-1.0, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * p.y).sin_cos();
    Vec3::new(sin * c, sin * s, cos)
}

/// The point of the square of unit direction `d`.
#[inline]
pub(crate) fn to_square(d: Vec3) -> Vec2 {
    let x = (d.z.clamp(-1.0, 1.0) + 1.0) * 0.5;
    let mut phi = d.y.atan2(d.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let y = phi / (2.0 * PI);
    // Keep both in [0, 1).
    Vec2::new(x.min(ONE_BELOW), y.min(ONE_BELOW))
}

const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// How far a sampled point keeps from its cell's edges, in cell widths.
const EDGE: f32 = 1e-3;

/// The quadrant of `p` in a cell's unit square (`x` the low bit), and
/// `p` in that quadrant's unit square.
#[inline]
fn quadrant(p: Vec2) -> (usize, Vec2) {
    let cx = (p.x >= 0.5) as usize;
    let cy = (p.y >= 0.5) as usize;
    let q = Vec2::new(p.x * 2.0 - cx as f32, p.y * 2.0 - cy as f32);
    (cx | cy << 1, q.clamp(Vec2::ZERO, Vec2::splat(ONE_BELOW)))
}

/// A quadtree's shape: per node, its four children's node indices, 0
/// for a quadrant that is a leaf (the root, node 0, is nobody's child).
pub(crate) type Children = Vec<[u32; 4]>;

/// A directional distribution: per node, the radiance its four
/// quadrants received (a node's quadrant sum is the sum of the child
/// node's four).
#[derive(Clone, Debug)]
pub(crate) struct Quadtree {
    children: Children,
    sums: Vec<[f32; 4]>,
}

impl Quadtree {
    /// The tree of one node, with nothing in it.
    pub(crate) fn empty() -> Self {
        Self {
            children: vec![[0; 4]],
            sums: vec![[0.0; 4]],
        }
    }

    /// Everything the tree received.
    #[inline]
    pub(crate) fn total(&self) -> f32 {
        self.sums[0].iter().sum()
    }

    /// Nodes in the tree.
    #[cfg(test)]
    pub(crate) fn nodes(&self) -> usize {
        self.children.len()
    }

    /// The density over directions (per steradian) of unit direction
    /// `d`: 0 if the tree is empty.
    pub(crate) fn pdf(&self, d: Vec3) -> f32 {
        let total = self.total();
        if total <= 0.0 {
            return 0.0;
        }
        let mut p = to_square(d);
        let mut node = 0usize;
        let mut density = 1.0f32;
        let mut node_total = total;
        loop {
            let (c, q) = quadrant(p);
            let s = self.sums[node][c];
            if s <= 0.0 {
                return 0.0;
            }
            density *= 4.0 * s / node_total;
            let child = self.children[node][c];
            if child == 0 {
                break;
            }
            node = child as usize;
            node_total = self.sums[node].iter().sum();
            p = q;
        }
        density / (4.0 * PI)
    }

    /// A direction drawn from the density with `u` in `[0, 1)^2`, and its
    /// density; None if the tree is empty.
    pub(crate) fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        if self.total() <= 0.0 {
            return None;
        }
        let mut u = u.clamp(Vec2::ZERO, Vec2::splat(ONE_BELOW));
        let mut origin = Vec2::ZERO;
        let mut size = 1.0f32;
        let mut node = 0usize;
        let mut density = 1.0f32;
        loop {
            let s = self.sums[node];
            let total: f32 = s.iter().sum();
            if total <= 0.0 {
                return None;
            }
            // A column (x half), then a cell within it, each by its share.
            let left = (s[0] + s[2]) / total;
            let cx = if u.x < left {
                u.x /= left;
                0
            } else {
                u.x = (u.x - left) / (1.0 - left);
                1
            };
            let (a, b) = (s[cx], s[cx + 2]);
            let bottom = a / (a + b);
            let cy = if u.y < bottom {
                u.y /= bottom;
                0
            } else {
                u.y = (u.y - bottom) / (1.0 - bottom);
                1
            };
            u = u.clamp(Vec2::ZERO, Vec2::splat(ONE_BELOW));
            let c = cx | cy << 1;
            density *= 4.0 * s[c] / total;
            size *= 0.5;
            origin += Vec2::new(cx as f32, cy as f32) * size;
            let child = self.children[node][c];
            if child == 0 {
                // Kept off the cell's edges: the round trip through a
                // direction moves a point by about 1e-7, which must not
                // carry it into a neighbour of another density.
                let u = u.clamp(Vec2::splat(EDGE), Vec2::splat(1.0 - EDGE));
                let p = origin + u * size;
                return Some((to_direction(p), density / (4.0 * PI)));
            }
            node = child as usize;
        }
    }

    /// The shape of the next iteration's tree: a quadrant is a node of
    /// its own where it holds more than `rho` of the whole (and the tree
    /// is not yet [`MAX_DEPTH`] deep), a leaf elsewhere; where this tree
    /// has no finer cells, a quadrant's share is taken as spread evenly
    /// over it. An empty tree gives the root alone.
    pub(crate) fn refined(&self, rho: f32) -> Children {
        let total = self.total();
        let mut out: Children = vec![[0; 4]];
        if total > 0.0 {
            self.refine_node(Some(0), self.sums[0], total, rho, 1, 0, &mut out);
        }
        out
    }

    #[allow(clippy::too_many_arguments)]
    fn refine_node(
        &self,
        old: Option<usize>,
        sums: [f32; 4],
        total: f32,
        rho: f32,
        depth: u32,
        at: usize,
        out: &mut Children,
    ) {
        for c in 0..4 {
            if sums[c] / total <= rho || depth >= MAX_DEPTH {
                continue;
            }
            let finer = old.map(|n| self.children[n][c]).filter(|&ch| ch != 0);
            let child_sums = match finer {
                Some(ch) => self.sums[ch as usize],
                None => [sums[c] / 4.0; 4],
            };
            let idx = out.len();
            out.push([0; 4]);
            out[at][c] = idx as u32;
            self.refine_node(
                finer.map(|ch| ch as usize),
                child_sums,
                total,
                rho,
                depth + 1,
                idx,
                out,
            );
        }
    }
}

/// A quadtree being trained: the shape fixed, the sums integers added to
/// atomically.
#[derive(Debug)]
pub(crate) struct Training {
    children: Children,
    sums: Vec<[AtomicU64; 4]>,
}

impl Training {
    /// A tree of shape `children` with nothing in it.
    pub(crate) fn new(children: Children) -> Self {
        let sums = children.iter().map(|_| Default::default()).collect();
        Self { children, sums }
    }

    /// Adds `value` (radiance over density, at least 0) to the cells
    /// holding direction `d`, at every depth; `jitter` in `[0, 1)` rounds
    /// the fixed-point value stochastically.
    pub(crate) fn splat(&self, d: Vec3, value: f32, jitter: f32) {
        let v = (value as f64 * SCALE).min(MAX_ADD);
        if v.is_nan() || v <= 0.0 {
            return;
        }
        let n = (v + jitter as f64) as u64;
        if n == 0 {
            return;
        }
        let mut p = to_square(d);
        let mut node = 0usize;
        loop {
            let (c, q) = quadrant(p);
            self.sums[node][c].fetch_add(n, Ordering::Relaxed);
            let child = self.children[node][c];
            if child == 0 {
                return;
            }
            node = child as usize;
            p = q;
        }
    }

    /// The trained distribution.
    pub(crate) fn finish(self) -> Quadtree {
        let sums = self
            .sums
            .into_iter()
            .map(|s| s.map(|v| (v.into_inner() as f64 / SCALE) as f32))
            .collect();
        Quadtree {
            children: self.children,
            sums,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::hash::hash2;

    fn unit(k: u64, salt: u64) -> f32 {
        (hash2(k, salt) >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A tree trained on radiance from a bright small region, a dimmer
    /// large one and a faint everywhere, refined twice.
    fn trained() -> Quadtree {
        let mut tree = Quadtree::empty();
        for round in 0..3u64 {
            let t = Training::new(tree.refined(0.01));
            for k in 0..20_000u64 {
                let d = to_direction(Vec2::new(unit(k, round), unit(k, round + 100)));
                let v = if d.dot(Vec3::new(0.3, 0.4, 0.866).normalize()) > 0.95 {
                    50.0
                } else if d.z < -0.5 {
                    3.0
                } else {
                    0.1
                };
                t.splat(d, v, unit(k, round + 200));
            }
            tree = t.finish();
        }
        tree
    }

    #[test]
    fn the_square_maps_to_the_sphere_and_back() {
        for k in 0..1000 {
            let p = Vec2::new(unit(k, 1), unit(k, 2));
            let d = to_direction(p);
            assert!((d.length() - 1.0).abs() < 1e-5);
            let q = to_square(d);
            assert!((p - q).abs().max_element() < 1e-4, "{p} {q}");
        }
    }

    #[test]
    fn the_density_integrates_to_one_and_sampling_agrees_with_it() {
        let tree = trained();
        assert!(tree.nodes() > 20, "{} nodes", tree.nodes());
        // Integral over the square on a fine grid (the cells of the tree
        // at depth <= 8 are unions of grid cells of 1/512).
        let n = 512;
        let mut integral = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let p = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                integral += tree.pdf(to_direction(p)) as f64 * 4.0 * std::f64::consts::PI;
            }
        }
        integral /= (n * n) as f64;
        assert!((integral - 1.0).abs() < 2e-3, "integral {integral}");
        // Sampling: the density returned is the tree's, and the samples
        // fall in bins as often as the density says (chi-square over 16 x
        // 16 bins of the square).
        let bins = 16usize;
        let mut expected = vec![0.0f64; bins * bins];
        let m = 8;
        for bi in 0..bins {
            for bj in 0..bins {
                let mut e = 0.0;
                for a in 0..m {
                    for b in 0..m {
                        let p = Vec2::new(
                            (bi * m + a) as f32 / (bins * m) as f32 + 0.5 / (bins * m) as f32,
                            (bj * m + b) as f32 / (bins * m) as f32 + 0.5 / (bins * m) as f32,
                        );
                        e += tree.pdf(to_direction(p)) as f64 * 4.0 * std::f64::consts::PI;
                    }
                }
                expected[bi * bins + bj] = e / (bins * bins * m * m) as f64;
            }
        }
        let draws = 200_000u64;
        let mut counts = vec![0u64; bins * bins];
        for k in 0..draws {
            let (d, pdf) = tree.sample(Vec2::new(unit(k, 7), unit(k, 8))).unwrap();
            let ratio = pdf / tree.pdf(d);
            assert!(
                (ratio - 1.0).abs() < 1e-3,
                "sampled pdf {pdf} vs {} at {} from {k}",
                tree.pdf(d),
                to_square(d)
            );
            let p = to_square(d);
            let (i, j) = (
                (p.x * bins as f32) as usize % bins,
                (p.y * bins as f32) as usize % bins,
            );
            counts[i * bins + j] += 1;
        }
        let mut chi2 = 0.0;
        let mut dof = 0;
        for (c, e) in counts.iter().zip(&expected) {
            let e = e * draws as f64;
            if e > 5.0 {
                chi2 += (*c as f64 - e).powi(2) / e;
                dof += 1;
            }
        }
        // 256 bins: the 99.9 % point of chi-square with ~255 degrees of
        // freedom is about 330.
        assert!(dof > 100, "{dof} bins");
        assert!(
            chi2 < dof as f64 + 4.5 * (2.0 * dof as f64).sqrt(),
            "chi2 {chi2} over {dof}"
        );
    }

    #[test]
    fn training_sums_do_not_depend_on_the_order_of_splats() {
        let shape = trained().refined(0.01);
        let a = Training::new(shape.clone());
        let b = Training::new(shape);
        let splats: Vec<(Vec3, f32, f32)> = (0..5000u64)
            .map(|k| {
                (
                    to_direction(Vec2::new(unit(k, 3), unit(k, 4))),
                    unit(k, 5) * 10.0,
                    unit(k, 6),
                )
            })
            .collect();
        for s in &splats {
            a.splat(s.0, s.1, s.2);
        }
        for s in splats.iter().rev() {
            b.splat(s.0, s.1, s.2);
        }
        let (a, b) = (a.finish(), b.finish());
        assert_eq!(a.sums, b.sums);
    }
}
