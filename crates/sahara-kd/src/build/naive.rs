//! The "intuitive" builders the lecture dismisses ("these techniques
//! stink"): a fixed axis rule (round robin or largest extent) and a fixed
//! position rule (middle of the cell or median of the geometry), stopping at
//! a leaf size or a depth. They exist to be measured against.

use super::partition::{count_straddlers, partition, root_refs, Ref};
use super::subtree::Subtree;
use super::Primitive;
use super::{AxisRule, BuildParams, PositionRule};
use crate::math::Aabb;

struct Ctx<'a, P> {
    triangles: &'a [P],
    budget: super::budget::RefBudget,
    params: &'a BuildParams,
    axis: AxisRule,
    position: PositionRule,
    max_depth: u32,
}

/// Below this many references a subtree is built on the current thread.
const PARALLEL_MIN: usize = 2048;

/// Build the tree over `live` inside `bounds` with the given rules.
pub fn build<P: Primitive>(
    triangles: &[P],
    live: Vec<u32>,
    bounds: Aabb,
    axis: AxisRule,
    position: PositionRule,
    params: &BuildParams,
) -> Subtree {
    let ctx = Ctx {
        triangles,
        budget: params.reference_budget(live.len()),
        params,
        axis,
        position,
        max_depth: params.depth_limit(live.len()),
    };
    recurse(&ctx, root_refs(triangles, &live), bounds, 0)
}

fn recurse<P: Primitive>(ctx: &Ctx<P>, mut refs: Vec<Ref>, cell: Aabb, depth: u32) -> Subtree {
    let p = ctx.params;
    let n = refs.len();
    let leaf = |refs: Vec<Ref>| Subtree::leaf(refs.iter().map(|r| r.tri).collect(), &cell, p);
    if n <= p.max_leaf_size as usize || depth >= ctx.max_depth {
        return leaf(refs);
    }
    let axis = match ctx.axis {
        AxisRule::RoundRobin => depth as usize % 3,
        AxisRule::LargestExtent => cell.largest_axis(),
    };
    let (lo, hi) = (cell.min[axis], cell.max[axis]);
    let middle = lo + (hi - lo) * 0.5;
    let mut pos = match ctx.position {
        PositionRule::Middle => middle,
        PositionRule::Median => {
            let k = n / 2;
            let key = |r: &Ref| r.bounds.min[axis] + r.bounds.max[axis];
            refs.select_nth_unstable_by(k, |a, b| key(a).total_cmp(&key(b)));
            key(&refs[k]) * 0.5
        }
    };
    if !(pos > lo && pos < hi) {
        pos = middle;
    }
    if !(pos > lo && pos < hi) {
        return leaf(refs); // the cell is flat along the axis
    }
    if !ctx.budget.try_take(count_straddlers(&refs, axis, pos)) {
        return leaf(refs);
    }
    let (lcell, rcell) = cell.split(axis, pos);
    let parallel = p.parallel && n >= PARALLEL_MIN;
    let (lrefs, rrefs) = partition(ctx.triangles, refs, axis, pos, &lcell, &rcell, parallel);
    let (below, above) = if parallel {
        rayon::join(
            || recurse(ctx, lrefs, lcell, depth + 1),
            || recurse(ctx, rrefs, rcell, depth + 1),
        )
    } else {
        (
            recurse(ctx, lrefs, lcell, depth + 1),
            recurse(ctx, rrefs, rcell, depth + 1),
        )
    };
    Subtree::join(axis, pos, &cell, n, below, above, p, false)
}
