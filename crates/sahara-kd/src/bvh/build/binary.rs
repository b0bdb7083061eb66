//! The binary SAH build the eight-wide hierarchy is collapsed from: binned
//! object splits over the references' centroids (Wald 2007, "On fast
//! construction of SAH-based bounding volume hierarchies"), and, when asked,
//! spatial splits (Stich, Friedrich & Dietrich 2009, "Spatial splits in
//! bounding volume hierarchies"), whose clipped references come from the
//! kd-tree's exact triangle clipping.
//!
//! The cost of a split is `K_T + K_I (A_L blocks(N_L) + A_R blocks(N_R)) / A`
//! with `blocks(n) = ceil(n / W)`: a leaf's triangles are tested a block of
//! `W` at a time, so the heuristic counts blocks, not triangles (as Embree
//! rounds to its four-triangle blocks).

use glam::Vec3;
use rayon::prelude::*;

use super::BvhParams;
use crate::bvh::node::MAX_LEAF;
use crate::math::clip::{clipped_bounds, slab_bounds};
use crate::math::{Aabb, Triangle};

/// Below this many references a subtree is built on the current thread,
/// and the bins of a node are filled by one thread.
const PARALLEL_MIN: usize = 4096;

/// Depth past which splits stop looking at the SAH: a subtree this deep
/// (degenerate input: thousands of triangles sharing one centroid) is cut
/// in halves by index, which keeps every leaf at most [`MAX_LEAF`]
/// triangles and the depth bounded.
const SAH_DEPTH: u32 = 48;

/// The deepest a binary tree gets: [`SAH_DEPTH`] levels of SAH splits and
/// then halving (at most 32 more levels for 2^32 references).
pub(crate) const MAX_BINARY_DEPTH: usize = SAH_DEPTH as usize + 32;

/// A reference to a triangle: the bounds of its part in the node (its own
/// bounds, or tighter after spatial splits) and its index.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ref {
    pub(crate) bounds: Aabb,
    pub(crate) tri: u32,
}

impl Ref {
    #[inline(always)]
    fn centroid2(&self) -> Vec3 {
        self.bounds.min + self.bounds.max
    }
}

/// A node of the binary tree.
pub(crate) enum BinaryNode {
    /// Triangle indices (at most [`MAX_LEAF`]).
    Leaf { bounds: Aabb, tris: Vec<u32> },
    /// Two children.
    Inner {
        bounds: Aabb,
        kids: Box<[BinaryNode; 2]>,
    },
}

impl BinaryNode {
    /// The node's box.
    pub(crate) fn bounds(&self) -> Aabb {
        match self {
            BinaryNode::Leaf { bounds, .. } | BinaryNode::Inner { bounds, .. } => *bounds,
        }
    }
}

/// The context of one build.
struct Ctx<'a> {
    tris: &'a [Triangle],
    params: &'a BvhParams,
    /// Spatial splits are tried where the object split's children overlap
    /// by more than this much area.
    min_overlap: f64,
}

/// Build the binary tree over the triangles `live` of `tris` (all
/// hittable), with spatial splits if the builder makes them.
pub(crate) fn build(tris: &[Triangle], live: &[u32], params: &BvhParams) -> BinaryNode {
    let refs: Vec<Ref> = if live.len() >= PARALLEL_MIN {
        live.par_iter()
            .map(|&i| Ref {
                bounds: tris[i as usize].bounds(),
                tri: i,
            })
            .collect()
    } else {
        live.iter()
            .map(|&i| Ref {
                bounds: tris[i as usize].bounds(),
                tri: i,
            })
            .collect()
    };
    build_refs(tris, refs, params)
}

/// Build the binary tree over `refs` (references to hittable triangles of
/// `tris`, with bounds inside the triangles' own).
pub(crate) fn build_refs(tris: &[Triangle], refs: Vec<Ref>, params: &BvhParams) -> BinaryNode {
    let bounds = bounds_of(&refs);
    let root_area = bounds.surface_area();
    let ctx = Ctx {
        tris,
        params,
        min_overlap: root_area * params.overlap_threshold as f64,
    };
    let budget = if params.builder.spatial_splits() {
        (refs.len() as f64 * (params.max_duplication as f64 - 1.0).max(0.0)) as usize
    } else {
        0
    };
    recurse(&ctx, refs, bounds, 0, budget)
}

/// The union of the references' bounds.
fn bounds_of(refs: &[Ref]) -> Aabb {
    if refs.len() >= PARALLEL_MIN {
        refs.par_chunks(PARALLEL_MIN)
            .map(|c| c.iter().fold(Aabb::EMPTY, |b, r| b.union(r.bounds)))
            .reduce(|| Aabb::EMPTY, Aabb::union)
    } else {
        refs.iter().fold(Aabb::EMPTY, |b, r| b.union(r.bounds))
    }
}

/// A chosen split.
#[derive(Clone, Copy, Debug)]
enum Split {
    /// Centroids in bins below `bin` of `axis` go left.
    Object {
        axis: usize,
        bin: usize,
        cost: f64,
        binner: Binner,
    },
    /// References are cut at the plane `axis = pos`.
    Spatial { axis: usize, pos: f32, cost: f64 },
}

impl Split {
    fn cost(&self) -> f64 {
        match *self {
            Split::Object { cost, .. } | Split::Spatial { cost, .. } => cost,
        }
    }
}

fn recurse(ctx: &Ctx, refs: Vec<Ref>, bounds: Aabb, depth: u32, budget: usize) -> BinaryNode {
    let p = ctx.params;
    let n = refs.len();
    let leaf = |refs: Vec<Ref>| BinaryNode::Leaf {
        bounds,
        tris: refs.iter().map(|r| r.tri).collect(),
    };
    if n <= p.min_leaf.max(1) {
        return leaf(refs);
    }
    let leaf_cost = p.intersection_cost as f64 * blocks(n, p.leaf_width) as f64;
    let split = if depth >= SAH_DEPTH {
        None
    } else {
        best_split(ctx, &refs, &bounds, budget)
    };
    let split = match split {
        Some(s) if n > MAX_LEAF || s.cost() < leaf_cost => s,
        _ if n <= MAX_LEAF => return leaf(refs),
        _ => return halve(ctx, refs, bounds, depth, budget),
    };
    let (left, right, used) = match split {
        Split::Object {
            axis, bin, binner, ..
        } => {
            let (l, r) = partition_object(refs, &binner, axis, bin);
            (l, r, 0)
        }
        Split::Spatial { axis, pos, .. } => partition_spatial(ctx, refs, axis, pos),
    };
    if left.is_empty() || right.is_empty() {
        // A split that sends everything one way (rounding at a bin
        // boundary): halve instead, so the recursion always progresses.
        let mut all = left;
        all.extend(right);
        return if all.len() <= MAX_LEAF {
            leaf(all)
        } else {
            halve(ctx, all, bounds, depth, budget)
        };
    }
    children(ctx, left, right, depth, budget.saturating_sub(used))
}

/// Recurse into two reference lists, sharing out the budget in proportion.
fn children(ctx: &Ctx, left: Vec<Ref>, right: Vec<Ref>, depth: u32, budget: usize) -> BinaryNode {
    let (nl, nr) = (left.len(), right.len());
    let bl = budget * nl / (nl + nr);
    let br = budget - bl;
    let (lb, rb) = (bounds_of(&left), bounds_of(&right));
    let bounds = lb.union(rb);
    let (a, b) = if ctx.params.parallel && nl + nr >= PARALLEL_MIN {
        rayon::join(
            || recurse(ctx, left, lb, depth + 1, bl),
            || recurse(ctx, right, rb, depth + 1, br),
        )
    } else {
        (
            recurse(ctx, left, lb, depth + 1, bl),
            recurse(ctx, right, rb, depth + 1, br),
        )
    };
    BinaryNode::Inner {
        bounds,
        kids: Box::new([a, b]),
    }
}

/// Cut `refs` in two halves by their order (no heuristic): for degenerate
/// input the SAH cannot split.
fn halve(ctx: &Ctx, mut refs: Vec<Ref>, _bounds: Aabb, depth: u32, budget: usize) -> BinaryNode {
    let right = refs.split_off(refs.len() / 2);
    children(ctx, refs, right, depth, budget)
}

/// Blocks of `w` the heuristic counts for `n` triangles.
#[inline(always)]
fn blocks(n: usize, w: u32) -> usize {
    n.div_ceil(w.max(1) as usize)
}

/// One bin of an object split.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Aabb::EMPTY,
    count: 0,
};

/// The bins of all three axes.
#[derive(Clone)]
struct Bins {
    bins: [Vec<Bin>; 3],
}

impl Bins {
    fn new(k: usize) -> Self {
        Self {
            bins: [vec![EMPTY_BIN; k], vec![EMPTY_BIN; k], vec![EMPTY_BIN; k]],
        }
    }

    fn merge(mut self, o: Bins) -> Bins {
        for a in 0..3 {
            for (x, y) in self.bins[a].iter_mut().zip(&o.bins[a]) {
                x.bounds = x.bounds.union(y.bounds);
                x.count += y.count;
            }
        }
        self
    }
}

/// Maps a centroid (times two) to its bin along each axis.
#[derive(Clone, Copy, Debug)]
struct Binner {
    lo: Vec3,
    scale: Vec3,
    k: usize,
}

impl Binner {
    /// Over the centroid bounds `cb` (in doubled coordinates).
    fn new(cb: &Aabb, k: usize) -> Self {
        let ext = cb.extent();
        let scale = Vec3::select(
            ext.cmpgt(Vec3::ZERO),
            Vec3::splat(k as f32 * (1.0 - 1e-6)) / ext,
            Vec3::ZERO,
        );
        Self {
            lo: cb.min,
            scale,
            k,
        }
    }

    #[inline(always)]
    fn bin(&self, c2: Vec3, axis: usize) -> usize {
        let b = ((c2[axis] - self.lo[axis]) * self.scale[axis]) as usize;
        b.min(self.k - 1)
    }
}

fn fill(refs: &[Ref], binner: &Binner) -> Bins {
    let mut bins = Bins::new(binner.k);
    for r in refs {
        let c = r.centroid2();
        for a in 0..3 {
            let b = &mut bins.bins[a][binner.bin(c, a)];
            b.bounds = b.bounds.union(r.bounds);
            b.count += 1;
        }
    }
    bins
}

/// The best split of the node: the cheapest object split and, where the
/// object split's children overlap and the budget allows, spatial splits.
fn best_split(ctx: &Ctx, refs: &[Ref], bounds: &Aabb, budget: usize) -> Option<Split> {
    let p = ctx.params;
    let k = p.bins.max(2);
    let area = bounds.surface_area();
    if area <= 0.0 {
        return None;
    }
    let cb = if refs.len() >= PARALLEL_MIN {
        refs.par_chunks(PARALLEL_MIN)
            .map(|c| c.iter().fold(Aabb::EMPTY, |b, r| b.grow(r.centroid2())))
            .reduce(|| Aabb::EMPTY, Aabb::union)
    } else {
        refs.iter().fold(Aabb::EMPTY, |b, r| b.grow(r.centroid2()))
    };
    let binner = Binner::new(&cb, k);
    let bins = if refs.len() >= PARALLEL_MIN && p.parallel {
        refs.par_chunks(PARALLEL_MIN)
            .map(|c| fill(c, &binner))
            .reduce(|| Bins::new(k), Bins::merge)
    } else {
        fill(refs, &binner)
    };
    let inv_area = 1.0 / area;
    let (kt, ki, w) = (
        p.traversal_cost as f64,
        p.intersection_cost as f64,
        p.leaf_width,
    );
    let mut best: Option<(Split, Aabb, Aabb)> = None;
    for axis in 0..3 {
        if binner.scale[axis] == 0.0 {
            continue;
        }
        let bins = &bins.bins[axis];
        // Right-to-left sweep: areas and counts of the right sides.
        let mut right_area = vec![0.0f64; k];
        let mut right_box = vec![Aabb::EMPTY; k];
        let mut acc = Aabb::EMPTY;
        for i in (1..k).rev() {
            acc = acc.union(bins[i].bounds);
            right_box[i] = acc;
            right_area[i] = acc.surface_area();
        }
        let mut left = Aabb::EMPTY;
        let mut nl = 0usize;
        let total: usize = bins.iter().map(|b| b.count as usize).sum();
        for i in 1..k {
            left = left.union(bins[i - 1].bounds);
            nl += bins[i - 1].count as usize;
            let nr = total - nl;
            if nl == 0 || nr == 0 {
                continue;
            }
            let cost = kt
                + ki * inv_area
                    * (left.surface_area() * blocks(nl, w) as f64
                        + right_area[i] * blocks(nr, w) as f64);
            if best.as_ref().is_none_or(|(b, _, _)| cost < b.cost()) {
                best = Some((
                    Split::Object {
                        axis,
                        bin: i,
                        cost,
                        binner,
                    },
                    left,
                    right_box[i],
                ));
            }
        }
    }
    if budget == 0 || !p.builder.spatial_splits() {
        return best.map(|b| b.0);
    }
    // Spatial splits only where the object split's children overlap
    // (Stich et al.'s lambda test): elsewhere they cannot do better.
    let overlap = best
        .as_ref()
        .map_or(f64::INFINITY, |(_, l, r)| l.intersection(*r).surface_area());
    if overlap <= ctx.min_overlap {
        return best.map(|b| b.0);
    }
    let spatial = best_spatial(ctx, refs, bounds, refs.len() + budget);
    match (best, spatial) {
        (Some((o, _, _)), Some(s)) if s.cost() < o.cost() => Some(s),
        (Some((o, _, _)), _) => Some(o),
        (None, s) => s,
    }
}

/// One bin of a spatial split: the clipped bounds of the references'
/// parts in it, and how many references enter and leave there.
#[derive(Clone, Copy)]
struct SpatialBin {
    bounds: Aabb,
    enter: u32,
    exit: u32,
}

/// The cheapest spatial split of the node over `bins` equal slabs per
/// axis, if it keeps the references within `max_refs`.
fn best_spatial(ctx: &Ctx, refs: &[Ref], bounds: &Aabb, max_refs: usize) -> Option<Split> {
    let p = ctx.params;
    let k = p.spatial_bins.max(2);
    let area = bounds.surface_area();
    let inv_area = 1.0 / area;
    let (kt, ki, w) = (
        p.traversal_cost as f64,
        p.intersection_cost as f64,
        p.leaf_width,
    );
    let per_axis = |axis: usize| -> Option<(f64, f32)> {
        let lo = bounds.min[axis];
        let ext = bounds.max[axis] - lo;
        if ext <= 0.0 {
            return None;
        }
        let plane = |i: usize| {
            if i == k {
                bounds.max[axis]
            } else {
                lo + ext * (i as f32 / k as f32)
            }
        };
        let bin_of = |x: f32| (((x - lo) / ext * k as f32) as usize).min(k - 1);
        let fill = |chunk: &[Ref]| {
            let mut bins = vec![
                SpatialBin {
                    bounds: Aabb::EMPTY,
                    enter: 0,
                    exit: 0,
                };
                k
            ];
            for r in chunk {
                let b0 = bin_of(r.bounds.min[axis]);
                let b1 = bin_of(r.bounds.max[axis]).max(b0);
                bins[b0].enter += 1;
                bins[b1].exit += 1;
                if b0 == b1 {
                    bins[b0].bounds = bins[b0].bounds.union(r.bounds);
                    continue;
                }
                let tri = &ctx.tris[r.tri as usize];
                for (b, bin) in bins.iter_mut().enumerate().take(b1 + 1).skip(b0) {
                    let (lo, hi) = (plane(b), plane(b + 1));
                    if let Some(c) = slab_bounds(tri, axis, lo, hi, &r.bounds) {
                        bin.bounds = bin.bounds.union(c);
                    }
                }
            }
            bins
        };
        let merge = |mut a: Vec<SpatialBin>, b: Vec<SpatialBin>| {
            for (x, y) in a.iter_mut().zip(&b) {
                x.bounds = x.bounds.union(y.bounds);
                x.enter += y.enter;
                x.exit += y.exit;
            }
            a
        };
        let bins = if refs.len() >= PARALLEL_MIN && p.parallel {
            refs.par_chunks(PARALLEL_MIN / 4)
                .map(fill)
                .reduce_with(merge)
                .unwrap()
        } else {
            fill(refs)
        };
        let mut right_area = vec![0.0f64; k];
        let mut acc = Aabb::EMPTY;
        for i in (1..k).rev() {
            acc = acc.union(bins[i].bounds);
            right_area[i] = acc.surface_area();
        }
        let mut right_count: usize = bins.iter().map(|b| b.exit as usize).sum();
        let (mut left, mut nl) = (Aabb::EMPTY, 0usize);
        let mut best: Option<(f64, f32)> = None;
        for i in 1..k {
            left = left.union(bins[i - 1].bounds);
            nl += bins[i - 1].enter as usize;
            right_count -= bins[i - 1].exit as usize;
            let nr = right_count;
            if nl == 0 || nr == 0 || nl + nr > max_refs {
                continue;
            }
            let cost = kt
                + ki * inv_area
                    * (left.surface_area() * blocks(nl, w) as f64
                        + right_area[i] * blocks(nr, w) as f64);
            if best.is_none_or(|(c, _)| cost < c) {
                best = Some((cost, plane(i)));
            }
        }
        best
    };
    let found: Vec<Option<(f64, f32)>> = if refs.len() >= PARALLEL_MIN && p.parallel {
        (0..3).into_par_iter().map(per_axis).collect()
    } else {
        (0..3).map(per_axis).collect()
    };
    let mut best: Option<Split> = None;
    for (axis, f) in found.into_iter().enumerate() {
        if let Some((cost, pos)) = f {
            if best.is_none_or(|b| cost < b.cost()) {
                best = Some(Split::Spatial { axis, pos, cost });
            }
        }
    }
    best
}

/// The references with centroids below bin boundary `bin` and the rest.
fn partition_object(
    mut refs: Vec<Ref>,
    binner: &Binner,
    axis: usize,
    bin: usize,
) -> (Vec<Ref>, Vec<Ref>) {
    let mut i = 0;
    let mut j = refs.len();
    while i < j {
        if binner.bin(refs[i].centroid2(), axis) < bin {
            i += 1;
        } else {
            j -= 1;
            refs.swap(i, j);
        }
    }
    let right = refs.split_off(i);
    (refs, right)
}

/// The references cut at `axis = pos`: wholly below go left, wholly above
/// go right, and each one crossing the plane goes to the side where it
/// costs less or, split in two clipped parts, to both (Stich et al.'s
/// reference unsplitting). Returns both sides and the number of copies
/// made.
fn partition_spatial(
    ctx: &Ctx,
    refs: Vec<Ref>,
    axis: usize,
    pos: f32,
) -> (Vec<Ref>, Vec<Ref>, usize) {
    let w = ctx.params.leaf_width;
    let mut left = Vec::with_capacity(refs.len());
    let mut right = Vec::with_capacity(refs.len() / 2);
    let mut straddle = Vec::new();
    let (mut lb, mut rb) = (Aabb::EMPTY, Aabb::EMPTY);
    for r in refs {
        if r.bounds.max[axis] <= pos {
            lb = lb.union(r.bounds);
            left.push(r);
        } else if r.bounds.min[axis] >= pos {
            rb = rb.union(r.bounds);
            right.push(r);
        } else {
            straddle.push(r);
        }
    }
    let mut copies = 0;
    let (mut nl, mut nr) = (left.len() + straddle.len(), right.len() + straddle.len());
    for r in straddle {
        let tri = &ctx.tris[r.tri as usize];
        let mut lcell = r.bounds;
        lcell.max[axis] = pos;
        let mut rcell = r.bounds;
        rcell.min[axis] = pos;
        let lpart = clipped_bounds(tri, &lcell);
        let rpart = clipped_bounds(tri, &rcell);
        let (lpart, rpart) = match (lpart, rpart) {
            (Some(l), Some(r)) => (l, r),
            (Some(_), None) => {
                nr -= 1;
                lb = lb.union(r.bounds);
                left.push(r);
                continue;
            }
            (None, _) => {
                nl -= 1;
                rb = rb.union(r.bounds);
                right.push(r);
                continue;
            }
        };
        // Unsplitting: the cost of the split as it is, of the whole
        // reference on the left, and on the right (areas of the sides as
        // they grow; counts in blocks).
        let (ls, rs) = (lb.union(lpart), rb.union(rpart));
        let c_split =
            ls.surface_area() * blocks(nl, w) as f64 + rs.surface_area() * blocks(nr, w) as f64;
        let c_left = lb.union(r.bounds).surface_area() * blocks(nl, w) as f64
            + rs.surface_area() * blocks(nr - 1, w) as f64;
        let c_right = ls.surface_area() * blocks(nl - 1, w) as f64
            + rb.union(r.bounds).surface_area() * blocks(nr, w) as f64;
        if c_left < c_split && c_left <= c_right {
            nr -= 1;
            lb = lb.union(r.bounds);
            left.push(r);
        } else if c_right < c_split {
            nl -= 1;
            rb = rb.union(r.bounds);
            right.push(r);
        } else {
            lb = ls;
            rb = rs;
            left.push(Ref {
                bounds: lpart,
                tri: r.tri,
            });
            right.push(Ref {
                bounds: rpart,
                tri: r.tri,
            });
            copies += 1;
        }
    }
    (left, right, copies)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BvhBuilder;
    use glam::Vec3;

    /// Long thin diagonal triangles crossing a field of small ones: object
    /// splits overlap badly, spatial splits cut the long ones.
    #[test]
    fn spatial_splits_cut_long_triangles() {
        let mut tris = Vec::new();
        for i in 0..64 {
            let y = i as f32 * 0.1;
            tris.push(Triangle::new(
                Vec3::new(0.0, y, 0.0),
                Vec3::new(100.0, y + 100.0, 0.0),
                Vec3::new(0.0, y + 0.05, 0.1),
            ));
        }
        for i in 0..2000 {
            let (x, y) = ((i % 50) as f32 * 2.0, (i / 50) as f32 * 2.5);
            tris.push(Triangle::new(
                Vec3::new(x, y, 1.0),
                Vec3::new(x + 0.5, y, 1.0),
                Vec3::new(x, y + 0.5, 1.0),
            ));
        }
        let live: Vec<u32> = (0..tris.len() as u32).collect();
        let count = |n: &BinaryNode| -> usize {
            fn walk(n: &BinaryNode) -> usize {
                match n {
                    BinaryNode::Leaf { tris, .. } => tris.len(),
                    BinaryNode::Inner { kids, .. } => walk(&kids[0]) + walk(&kids[1]),
                }
            }
            walk(n)
        };
        let object = build(&tris, &live, &BvhParams::new(BvhBuilder::Binned));
        assert_eq!(count(&object), tris.len());
        let p = BvhParams::new(BvhBuilder::Spatial);
        let spatial = build(&tris, &live, &p);
        let refs = count(&spatial);
        assert!(refs > tris.len(), "no spatial split: {refs} references");
        assert!(
            refs as f32 <= tris.len() as f32 * p.max_duplication + 1.0,
            "{refs}"
        );
    }
}
