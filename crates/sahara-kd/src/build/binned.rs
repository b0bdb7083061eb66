//! Binned SAH build: the SAH evaluated only at the boundaries of a few equal
//! bins per axis (the lecture's "a few bins (16 is often enough)"; Hunt,
//! Mark & Stoll 2006 and Shevtsov, Soupikov & Kapustin 2007 for kd-trees).
//! One O(N) pass per node fills the bins; no sorting at all.

use rayon::prelude::*;

use super::cost::{SahModel, Split};
use super::partition::{count_straddlers, partition, root_refs, Ref};
use super::subtree::Subtree;
use super::BuildParams;
use super::Primitive;
use crate::math::Aabb;

/// Below this many references a subtree is built on the current thread.
const PARALLEL_MIN: usize = 2048;

struct Ctx<'a, P> {
    triangles: &'a [P],
    budget: super::budget::RefBudget,
    params: &'a BuildParams,
    bins: usize,
    max_depth: u32,
}

/// Build the tree over `live` inside `bounds` with `bins` bins per axis.
pub fn build<P: Primitive>(
    triangles: &[P],
    live: Vec<u32>,
    bounds: Aabb,
    bins: usize,
    params: &BuildParams,
) -> Subtree {
    let ctx = Ctx {
        triangles,
        budget: params.reference_budget(live.len()),
        params,
        bins: bins.max(2),
        max_depth: params.depth_limit(live.len()),
    };
    recurse(&ctx, root_refs(triangles, &live), bounds, 0)
}

fn recurse<P: Primitive>(ctx: &Ctx<P>, refs: Vec<Ref>, cell: Aabb, depth: u32) -> Subtree {
    let p = ctx.params;
    let n = refs.len();
    let leaf = |refs: Vec<Ref>| Subtree::leaf(refs.iter().map(|r| r.tri).collect(), &cell, p);
    let Some(model) = SahModel::new(cell, p) else {
        return leaf(refs);
    };
    if n == 0 || n <= p.max_leaf_size as usize || depth >= ctx.max_depth {
        return leaf(refs);
    }
    if n <= p.exact_below as usize {
        let (t, b, m) = (ctx.triangles, &ctx.budget, ctx.max_depth);
        return super::sah_sweep::build_cell(t, &refs, cell, depth, m, b, p);
    }
    let parallel = p.parallel && n >= PARALLEL_MIN;
    let Some(split) =
        best_split(ctx, &model, &refs, &cell, parallel).filter(|s| s.cost < model.leaf_cost(n))
    else {
        return leaf(refs);
    };
    if !ctx
        .budget
        .try_take(count_straddlers(&refs, split.axis, split.pos))
    {
        return leaf(refs);
    }
    let (lcell, rcell) = cell.split(split.axis, split.pos);
    let (lrefs, rrefs) = partition(
        ctx.triangles,
        refs,
        split.axis,
        split.pos,
        &lcell,
        &rcell,
        parallel,
    );
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
    Subtree::join(split.axis, split.pos, &cell, n, below, above, p, true)
}

/// Per axis and bin: references whose clipped bounds start / end there.
#[derive(Clone)]
struct Bins {
    starts: Vec<[u32; 3]>,
    ends: Vec<[u32; 3]>,
}

impl Bins {
    fn new(n: usize) -> Self {
        Self {
            starts: vec![[0; 3]; n],
            ends: vec![[0; 3]; n],
        }
    }
    fn add(mut self, o: &Bins) -> Self {
        for (a, b) in self.starts.iter_mut().zip(&o.starts) {
            (0..3).for_each(|k| a[k] += b[k]);
        }
        for (a, b) in self.ends.iter_mut().zip(&o.ends) {
            (0..3).for_each(|k| a[k] += b[k]);
        }
        self
    }
}

fn best_split<P: Primitive>(
    ctx: &Ctx<P>,
    model: &SahModel,
    refs: &[Ref],
    cell: &Aabb,
    parallel: bool,
) -> Option<Split> {
    let nb = ctx.bins;
    let ext = cell.extent();
    let scale: [f32; 3] = std::array::from_fn(|a| {
        if ext[a] > 0.0 {
            nb as f32 / ext[a]
        } else {
            0.0
        }
    });
    let bin = |x: f32, a: usize| (((x - cell.min[a]) * scale[a]) as usize).min(nb - 1);
    let fill = |mut b: Bins, r: &Ref| {
        for a in 0..3 {
            b.starts[bin(r.bounds.min[a], a)][a] += 1;
            b.ends[bin(r.bounds.max[a], a)][a] += 1;
        }
        b
    };
    let bins = if parallel {
        refs.par_chunks(4096)
            .map(|c| c.iter().fold(Bins::new(nb), fill))
            .reduce(|| Bins::new(nb), |a, b| a.add(&b))
    } else {
        refs.iter().fold(Bins::new(nb), fill)
    };
    let n = refs.len();
    let mut best: Option<Split> = None;
    for a in 0..3 {
        if ext[a] <= 0.0 {
            continue;
        }
        // Plane i lies between bin i-1 and bin i. A reference is below it if
        // it starts in a bin < i, above it if it ends in a bin >= i.
        let mut nl = 0usize;
        let mut nr = n;
        for i in 1..nb {
            nl += bins.starts[i - 1][a] as usize;
            nr -= bins.ends[i - 1][a] as usize;
            let pos = cell.min[a] + ext[a] * (i as f32 / nb as f32);
            if pos <= cell.min[a] || pos >= cell.max[a] {
                continue;
            }
            if let Some(cost) = model.cost(a, pos, nl, nr) {
                if best.is_none_or(|b| cost < b.cost) {
                    best = Some(Split {
                        axis: a,
                        pos,
                        planar: super::cost::PlanarSide::Left,
                        cost,
                        refs: nl + nr,
                    });
                }
            }
        }
    }
    best
}
