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
//!
//! The build works in place on one array of references, allocated once with
//! room for every copy spatial splits may make: a node owns a slice of it,
//! its references first and its share of the free room (its budget of
//! copies) after them. A split partitions the references in place (copies
//! go into the free room), then shares the remaining room out to the two
//! children in proportion to their reference counts, so the tree does not
//! depend on how many threads build it. A node's box and its centroids'
//! box come from its parent's bins and partition pass, so no pass over a
//! node's references is spent on bounds alone.

use glam::{Vec3A, Vec4};

use super::collapse::{self, WideCount};
use super::BvhParams;
use crate::bvh::node::MAX_LEAF;
use crate::math::clip::{clipped_bounds, slab_parts};
use crate::math::{Aabb, Triangle};

/// Below this many references a subtree is built on the current thread.
const PARALLEL_MIN: usize = 4096;

/// From this many references up, a node's bins are filled on all threads.
const PARALLEL_FILL: usize = 1 << 16;

/// Nodes of at most this many references choose their object split by an
/// exact sweep over their centroids sorted along each axis, not by bins:
/// for so few references sorting is cheaper than filling and sweeping 32
/// bins per axis, and it finds the best cut between any two centroids.
const SMALL: usize = 16;

/// The most bins per axis (of object and of spatial splits).
pub(crate) const MAX_BINS: usize = 32;

/// Depth past which splits stop looking at the SAH: a subtree this deep
/// (degenerate input: thousands of triangles sharing one centroid) is cut
/// in halves by index, which keeps every leaf at most [`MAX_LEAF`]
/// triangles and the depth bounded.
const SAH_DEPTH: u32 = 48;

/// The deepest a binary tree gets: [`SAH_DEPTH`] levels of SAH splits and
/// then halving (at most 32 more levels for 2^32 references).
pub(crate) const MAX_BINARY_DEPTH: usize = SAH_DEPTH as usize + 32;

/// A box in SIMD registers (the fourth lane is ignored).
#[derive(Clone, Copy, Debug)]
struct Box3 {
    lo: Vec3A,
    hi: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };

    #[inline(always)]
    fn union(self, o: Box3) -> Box3 {
        Box3 {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    #[inline(always)]
    fn grow(self, p: Vec3A) -> Box3 {
        Box3 {
            lo: self.lo.min(p),
            hi: self.hi.max(p),
        }
    }

    fn from_aabb(b: &Aabb) -> Box3 {
        Box3 {
            lo: b.min.into(),
            hi: b.max.into(),
        }
    }

    fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo.into(),
            max: self.hi.into(),
        }
    }

    /// Surface area as [`Aabb::surface_area`] computes it.
    #[inline(always)]
    fn area(&self) -> f64 {
        if !self.lo.cmple(self.hi).all() {
            return 0.0;
        }
        let e = (self.hi - self.lo).as_dvec3();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

/// A reference to a triangle: the bounds of its part in the node (its own
/// bounds, or tighter after spatial splits), with the triangle's index in
/// the lower corner's fourth lane; 32 bytes, two SIMD registers.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub(crate) struct Ref {
    lo: Vec4,
    hi: Vec4,
}

impl Ref {
    /// A reference to triangle `tri` with `bounds`.
    pub(crate) fn new(bounds: Aabb, tri: u32) -> Self {
        Self {
            lo: bounds.min.extend(f32::from_bits(tri)),
            hi: bounds.max.extend(0.0),
        }
    }

    /// The triangle's index.
    #[inline(always)]
    pub(crate) fn tri(&self) -> u32 {
        self.lo.w.to_bits()
    }

    #[inline(always)]
    fn lo(&self) -> Vec3A {
        Vec3A::from_vec4(self.lo)
    }

    #[inline(always)]
    fn hi(&self) -> Vec3A {
        Vec3A::from_vec4(self.hi)
    }

    #[inline(always)]
    fn boxed(&self) -> Box3 {
        Box3 {
            lo: self.lo(),
            hi: self.hi(),
        }
    }

    /// The centroid times two.
    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        self.lo() + self.hi()
    }

    fn with_bounds(&self, b: Aabb) -> Ref {
        Ref::new(b, self.tri())
    }
}

/// A node of the binary tree.
pub(crate) enum BinaryNode {
    /// One to [`MAX_LEAF`] triangles.
    Leaf {
        bounds: Aabb,
        count: u8,
        tris: [u32; MAX_LEAF],
    },
    /// Two children.
    Inner {
        bounds: Aabb,
        kids: Box<[BinaryNode; 2]>,
        /// The wide nodes and leaves of the hierarchy collapsed from here.
        wide: WideCount,
    },
}

impl BinaryNode {
    /// The node's box.
    pub(crate) fn bounds(&self) -> Aabb {
        match self {
            BinaryNode::Leaf { bounds, .. } | BinaryNode::Inner { bounds, .. } => *bounds,
        }
    }

    /// An inner node over `a` and `b`.
    pub(crate) fn inner(a: BinaryNode, b: BinaryNode) -> Self {
        let mut n = BinaryNode::Inner {
            bounds: a.bounds().union(b.bounds()),
            kids: Box::new([a, b]),
            wide: WideCount::default(),
        };
        let c = collapse::count(&n);
        if let BinaryNode::Inner { wide, .. } = &mut n {
            *wide = c;
        }
        n
    }

    /// A leaf of the references `refs` (one to [`MAX_LEAF`]).
    pub(crate) fn leaf(refs: &[Ref], bounds: Aabb) -> Self {
        assert!(!refs.is_empty() && refs.len() <= MAX_LEAF);
        let mut tris = [0; MAX_LEAF];
        for (t, r) in tris.iter_mut().zip(refs) {
            *t = r.tri();
        }
        BinaryNode::Leaf {
            bounds,
            count: refs.len() as u8,
            tris,
        }
    }

    /// A leaf's triangles (empty for an inner node).
    pub(crate) fn leaf_tris(&self) -> &[u32] {
        match self {
            BinaryNode::Leaf { count, tris, .. } => &tris[..*count as usize],
            BinaryNode::Inner { .. } => &[],
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
    /// Bins per axis of object splits.
    bins: usize,
    /// Bins per axis of spatial splits.
    spatial_bins: usize,
}

/// Build the binary tree over the triangles `live` of `tris` (all
/// hittable), with spatial splits if the builder makes them.
pub(crate) fn build(tris: &[Triangle], live: &[u32], params: &BvhParams) -> BinaryNode {
    let refs = map_chunks(live, |&i| Ref::new(tris[i as usize].bounds(), i));
    build_refs(tris, refs, params)
}

/// `f` of every item, on all threads for long slices.
fn map_chunks<T: Sync, U: Send>(items: &[T], f: impl Fn(&T) -> U + Sync + Send) -> Vec<U> {
    use rayon::prelude::*;
    if items.len() >= PARALLEL_FILL {
        items.par_iter().map(f).collect()
    } else {
        items.iter().map(f).collect()
    }
}

/// Build the binary tree over `refs` (references to hittable triangles of
/// `tris`, with bounds inside the triangles' own).
pub(crate) fn build_refs(tris: &[Triangle], mut refs: Vec<Ref>, params: &BvhParams) -> BinaryNode {
    let n = refs.len();
    let (geom, cent) = bounds_of(&refs);
    let ctx = Ctx {
        tris,
        params,
        min_overlap: geom.area() * params.overlap_threshold as f64,
        bins: params.bins.clamp(2, MAX_BINS),
        spatial_bins: params.spatial_bins.clamp(2, MAX_BINS),
    };
    let budget = if params.builder.spatial_splits() {
        (n as f64 * (params.max_duplication as f64 - 1.0).max(0.0)) as usize
    } else {
        0
    };
    refs.resize(n + budget, Ref::new(Aabb::EMPTY, 0));
    recurse(&ctx, &mut refs, n, geom, cent, 0)
}

/// The union of the references' bounds and the box of their centroids
/// (times two).
fn bounds_of(refs: &[Ref]) -> (Box3, Box3) {
    let f = |c: &[Ref]| {
        c.iter().fold((Box3::EMPTY, Box3::EMPTY), |(g, k), r| {
            (g.union(r.boxed()), k.grow(r.centroid2()))
        })
    };
    if refs.len() >= PARALLEL_FILL {
        use rayon::prelude::*;
        refs.par_chunks(PARALLEL_FILL / 4).map(f).reduce(
            || (Box3::EMPTY, Box3::EMPTY),
            |a, b| (a.0.union(b.0), a.1.union(b.1)),
        )
    } else {
        f(refs)
    }
}

/// A chosen split.
#[derive(Clone, Copy, Debug)]
enum Split {
    /// Centroids in bins below `bin` of `axis` go left; `left` and `right`
    /// are the two sides' boxes (the unions of their bins).
    Object {
        axis: usize,
        bin: usize,
        cost: f64,
        binner: Binner,
        left: Box3,
        right: Box3,
    },
    /// A small node's references sorted along `axis` (by
    /// [`centroid_order`]): the first `count` go left.
    Sorted {
        axis: usize,
        count: usize,
        cost: f64,
        left: Box3,
        right: Box3,
    },
    /// References are cut at the plane `axis = pos`.
    Spatial { axis: usize, pos: f32, cost: f64 },
}

impl Split {
    fn cost(&self) -> f64 {
        match *self {
            Split::Object { cost, .. }
            | Split::Sorted { cost, .. }
            | Split::Spatial { cost, .. } => cost,
        }
    }
}

/// Build the subtree of the first `n` references of `refs`, with box
/// `geom` and centroid box `cent`; the rest of `refs` is free room for the
/// copies spatial splits make.
fn recurse(
    ctx: &Ctx,
    refs: &mut [Ref],
    n: usize,
    geom: Box3,
    cent: Box3,
    depth: u32,
) -> BinaryNode {
    let p = ctx.params;
    let budget = refs.len() - n;
    let leaf = |refs: &[Ref]| BinaryNode::leaf(&refs[..n], geom.aabb());
    if n <= p.min_leaf.max(1) {
        return leaf(refs);
    }
    let (kt, ki) = (p.traversal_cost as f64, p.intersection_cost as f64);
    let leaf_cost = ki * blocks(n, p.leaf_width) as f64;
    // A node of one block: a split costs at least `K_T` plus a block test
    // on some side, so where `K_T >= K_I` no split beats the leaf.
    if n <= MAX_LEAF && blocks(n, p.leaf_width) == 1 && kt >= ki {
        return leaf(refs);
    }
    let split = if depth >= SAH_DEPTH {
        None
    } else {
        best_split(ctx, &refs[..n], &geom, &cent, budget)
    };
    let split = match split {
        Some(s) if n > MAX_LEAF || s.cost() < leaf_cost => s,
        _ if n <= MAX_LEAF => return leaf(refs),
        _ => return halve(ctx, refs, n, depth),
    };
    let (nl, nr, lg, rg, lc, rc) = match split {
        Split::Object {
            axis,
            bin,
            binner,
            left,
            right,
            ..
        } => {
            let (nl, lc, rc) = partition_object(&mut refs[..n], &binner, axis, bin);
            (nl, n - nl, left, right, lc, rc)
        }
        Split::Sorted {
            axis,
            count,
            left,
            right,
            ..
        } => {
            refs[..n].sort_unstable_by(|a, b| centroid_order(a, b, axis));
            let cent = |s: &[Ref]| s.iter().fold(Box3::EMPTY, |c, r| c.grow(r.centroid2()));
            let (lc, rc) = (cent(&refs[..count]), cent(&refs[count..n]));
            (count, n - count, left, right, lc, rc)
        }
        Split::Spatial { axis, pos, .. } => partition_spatial(ctx, refs, n, axis, pos),
    };
    if nl == 0 || nr == 0 {
        // A split that sends everything one way: halve instead, so the
        // recursion always progresses.
        let all = nl + nr;
        return if all <= MAX_LEAF {
            BinaryNode::leaf(&refs[..all], lg.union(rg).aabb())
        } else {
            halve(ctx, refs, all, depth)
        };
    }
    children(ctx, refs, [nl, nr], [lg, rg], [lc, rc], depth)
}

/// Recurse into the two sides of a split: the first `n[0]` references of
/// `refs` and the `n[1]` after them, with boxes `geom` and centroid boxes
/// `cent`, sharing out the free room in proportion to the counts.
fn children(
    ctx: &Ctx,
    refs: &mut [Ref],
    n: [usize; 2],
    geom: [Box3; 2],
    cent: [Box3; 2],
    depth: u32,
) -> BinaryNode {
    let [nl, nr] = n;
    let room = refs.len() - nl - nr;
    let bl = room * nl / (nl + nr);
    if bl > 0 {
        refs.copy_within(nl..nl + nr, nl + bl);
    }
    let (l, r) = refs.split_at_mut(nl + bl);
    let (a, b) = if ctx.params.parallel && nl + nr >= PARALLEL_MIN {
        rayon::join(
            || recurse(ctx, l, nl, geom[0], cent[0], depth + 1),
            || recurse(ctx, r, nr, geom[1], cent[1], depth + 1),
        )
    } else {
        (
            recurse(ctx, l, nl, geom[0], cent[0], depth + 1),
            recurse(ctx, r, nr, geom[1], cent[1], depth + 1),
        )
    };
    BinaryNode::inner(a, b)
}

/// Cut the first `n` references of `refs` in two halves by their order (no
/// heuristic): for degenerate input the SAH cannot split.
fn halve(ctx: &Ctx, refs: &mut [Ref], n: usize, depth: u32) -> BinaryNode {
    let h = n / 2;
    let (lg, lc) = bounds_of(&refs[..h]);
    let (rg, rc) = bounds_of(&refs[h..n]);
    children(ctx, refs, [h, n - h], [lg, rg], [lc, rc], depth)
}

/// Blocks of `w` the heuristic counts for `n` triangles.
#[inline(always)]
fn blocks(n: usize, w: u32) -> usize {
    n.div_ceil(w.max(1) as usize)
}

/// Maps a centroid (times two) to its bin along each axis.
#[derive(Clone, Copy, Debug)]
struct Binner {
    lo: Vec3A,
    scale: Vec3A,
    k: usize,
}

impl Binner {
    /// Over the centroid bounds `cb` (in doubled coordinates).
    fn new(cb: &Box3, k: usize) -> Self {
        let ext = cb.hi - cb.lo;
        let scale = Vec3A::select(
            ext.cmpgt(Vec3A::ZERO),
            Vec3A::splat(k as f32 * (1.0 - 1e-6)) / ext,
            Vec3A::ZERO,
        );
        Self {
            lo: cb.lo,
            scale,
            k,
        }
    }

    /// The bins of `c2` along the three axes (below [`MAX_BINS`]).
    #[inline(always)]
    fn bins(&self, c2: Vec3A) -> [usize; 3] {
        let f = (c2 - self.lo) * self.scale;
        let m = self.k - 1;
        [
            (f.x as usize).min(m) & (MAX_BINS - 1),
            (f.y as usize).min(m) & (MAX_BINS - 1),
            (f.z as usize).min(m) & (MAX_BINS - 1),
        ]
    }
}

/// The object bins of all three axes.
#[derive(Clone, Copy)]
struct Bins {
    boxes: [[Box3; MAX_BINS]; 3],
    counts: [[u32; MAX_BINS]; 3],
}

impl Bins {
    fn new() -> Self {
        Self {
            boxes: [[Box3::EMPTY; MAX_BINS]; 3],
            counts: [[0; MAX_BINS]; 3],
        }
    }

    fn fill(mut self, refs: &[Ref], binner: &Binner) -> Self {
        for r in refs {
            let b = r.boxed();
            let i = binner.bins(b.lo + b.hi);
            for (a, &i) in i.iter().enumerate() {
                self.boxes[a][i] = self.boxes[a][i].union(b);
                self.counts[a][i] += 1;
            }
        }
        self
    }

    fn merge(mut self, o: &Bins) -> Self {
        for a in 0..3 {
            for i in 0..MAX_BINS {
                self.boxes[a][i] = self.boxes[a][i].union(o.boxes[a][i]);
                self.counts[a][i] += o.counts[a][i];
            }
        }
        self
    }
}

/// The cheapest cut of `k` bins with boxes `boxes`, `enter[i]` references
/// starting and `exit[i]` ending in bin `i` (for object bins both are the
/// bin's count): the cost and the boundary (left side: bins below it),
/// among cuts leaving references on both sides and at most `max_refs` in
/// all.
fn sweep(
    ctx: &Ctx,
    boxes: &[Box3],
    enter: &[u32],
    exit: &[u32],
    inv_area: f64,
    max_refs: usize,
) -> Option<(f64, usize)> {
    let p = ctx.params;
    let k = boxes.len();
    let (kt, ki, w) = (
        p.traversal_cost as f64,
        p.intersection_cost as f64,
        p.leaf_width,
    );
    let mut right_area = [0.0f64; MAX_BINS];
    let mut acc = Box3::EMPTY;
    for i in (1..k).rev() {
        acc = acc.union(boxes[i]);
        right_area[i] = acc.area();
    }
    let mut nr: usize = exit.iter().map(|&c| c as usize).sum();
    let (mut left, mut nl) = (Box3::EMPTY, 0usize);
    let mut best: Option<(f64, usize)> = None;
    for i in 1..k {
        left = left.union(boxes[i - 1]);
        nl += enter[i - 1] as usize;
        nr -= exit[i - 1] as usize;
        if nl == 0 || nr == 0 || nl + nr > max_refs {
            continue;
        }
        let cost = kt
            + ki * inv_area
                * (left.area() * blocks(nl, w) as f64 + right_area[i] * blocks(nr, w) as f64);
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, i));
        }
    }
    best
}

/// The best split of the node: the cheapest object split and, where the
/// object split's children overlap and the budget allows, spatial splits.
fn best_split(ctx: &Ctx, refs: &[Ref], geom: &Box3, cent: &Box3, budget: usize) -> Option<Split> {
    let p = ctx.params;
    let area = geom.area();
    if area <= 0.0 {
        return None;
    }
    let best = if refs.len() <= SMALL {
        best_sorted(ctx, refs, area)
    } else {
        best_binned(ctx, refs, area, cent)
    };
    if budget == 0 || !p.builder.spatial_splits() || refs.len() <= p.spatial_min {
        return best;
    }
    // Spatial splits only where the object split's children overlap
    // (Stich et al.'s lambda test): elsewhere they cannot do better.
    let overlap = match best {
        Some(Split::Object { left, right, .. } | Split::Sorted { left, right, .. }) => Box3 {
            lo: left.lo.max(right.lo),
            hi: left.hi.min(right.hi),
        }
        .area(),
        _ => f64::INFINITY,
    };
    if overlap <= ctx.min_overlap || overlap <= area * p.node_overlap_threshold as f64 {
        return best;
    }
    match (best, best_spatial(ctx, refs, geom, refs.len() + budget)) {
        (Some(o), Some(s)) if s.cost() < o.cost() => Some(s),
        (Some(o), _) => Some(o),
        (None, s) => s,
    }
}

/// The order of references along `axis` for [`Split::Sorted`]: by
/// centroid, then by triangle (a node never holds two parts of one
/// triangle), so the order does not depend on where the sort starts.
fn centroid_order(a: &Ref, b: &Ref, axis: usize) -> std::cmp::Ordering {
    a.centroid2()[axis]
        .total_cmp(&b.centroid2()[axis])
        .then(a.tri().cmp(&b.tri()))
}

/// The cheapest object split of a small node: every cut between
/// consecutive centroids along each axis.
fn best_sorted(ctx: &Ctx, refs: &[Ref], area: f64) -> Option<Split> {
    let n = refs.len();
    let mut boxes = [Box3::EMPTY; SMALL];
    let ones = [1u32; SMALL];
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        let mut order: [u8; SMALL] = std::array::from_fn(|i| i as u8);
        order[..n]
            .sort_unstable_by(|&a, &b| centroid_order(&refs[a as usize], &refs[b as usize], axis));
        for (b, &i) in boxes.iter_mut().zip(&order[..n]) {
            *b = refs[i as usize].boxed();
        }
        let Some((cost, count)) = sweep(
            ctx,
            &boxes[..n],
            &ones[..n],
            &ones[..n],
            1.0 / area,
            usize::MAX,
        ) else {
            continue;
        };
        if best.is_none_or(|b| cost < b.cost()) {
            let side = |s: &[Box3]| s.iter().fold(Box3::EMPTY, |a, b| a.union(*b));
            best = Some(Split::Sorted {
                axis,
                count,
                cost,
                left: side(&boxes[..count]),
                right: side(&boxes[count..n]),
            });
        }
    }
    best
}

/// The cheapest binned object split of a node.
fn best_binned(ctx: &Ctx, refs: &[Ref], area: f64, cent: &Box3) -> Option<Split> {
    let p = ctx.params;
    let binner = Binner::new(cent, ctx.bins);
    let bins = if refs.len() >= PARALLEL_FILL && p.parallel {
        use rayon::prelude::*;
        refs.par_chunks(PARALLEL_FILL / 4)
            .map(|c| Bins::new().fill(c, &binner))
            .reduce(Bins::new, |a, b| a.merge(&b))
    } else {
        Bins::new().fill(refs, &binner)
    };
    let inv_area = 1.0 / area;
    let k = binner.k;
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        if binner.scale[axis] == 0.0 {
            continue;
        }
        let (boxes, counts) = (&bins.boxes[axis][..k], &bins.counts[axis][..k]);
        let Some((cost, bin)) = sweep(ctx, boxes, counts, counts, inv_area, usize::MAX) else {
            continue;
        };
        if best.is_none_or(|b| cost < b.cost()) {
            let side = |s: &[Box3]| s.iter().fold(Box3::EMPTY, |a, b| a.union(*b));
            best = Some(Split::Object {
                axis,
                bin,
                cost,
                binner,
                left: side(&boxes[..bin]),
                right: side(&boxes[bin..]),
            });
        }
    }
    best
}

/// The bins of a spatial split along the three axes: the clipped bounds of
/// the references' parts in each, and how many references enter and leave
/// there.
#[derive(Clone, Copy)]
struct SpatialBins {
    boxes: [[Box3; MAX_BINS]; 3],
    enter: [[u32; MAX_BINS]; 3],
    exit: [[u32; MAX_BINS]; 3],
}

/// The slab planes of a node's spatial bins.
struct Slabs {
    /// `planes[axis][i]`: the lower plane of bin `i`; `planes[axis][k]`
    /// the node's upper bound.
    planes: [[f32; MAX_BINS + 1]; 3],
    lo: Vec3A,
    /// Bins per unit length (zero along a flat axis).
    scale: Vec3A,
    k: usize,
}

impl Slabs {
    fn new(geom: &Box3, k: usize) -> Self {
        let ext = geom.hi - geom.lo;
        let mut planes = [[0.0; MAX_BINS + 1]; 3];
        for (axis, pl) in planes.iter_mut().enumerate() {
            for (i, x) in pl.iter_mut().enumerate().take(k + 1) {
                *x = if i == k {
                    geom.hi[axis]
                } else {
                    geom.lo[axis] + ext[axis] * (i as f32 / k as f32)
                };
            }
        }
        let scale = Vec3A::select(
            ext.cmpgt(Vec3A::ZERO),
            Vec3A::splat(k as f32) / ext,
            Vec3A::ZERO,
        );
        Self {
            planes,
            lo: geom.lo,
            scale,
            k,
        }
    }

    /// The bins of `x` along the three axes.
    #[inline(always)]
    fn bins(&self, x: Vec3A) -> [usize; 3] {
        let f = ((x - self.lo) * self.scale).max(Vec3A::ZERO);
        let m = self.k - 1;
        [
            (f.x as usize).min(m) & (MAX_BINS - 1),
            (f.y as usize).min(m) & (MAX_BINS - 1),
            (f.z as usize).min(m) & (MAX_BINS - 1),
        ]
    }
}

impl SpatialBins {
    fn new() -> Self {
        Self {
            boxes: [[Box3::EMPTY; MAX_BINS]; 3],
            enter: [[0; MAX_BINS]; 3],
            exit: [[0; MAX_BINS]; 3],
        }
    }

    fn fill(mut self, ctx: &Ctx, refs: &[Ref], slabs: &Slabs) -> Self {
        for r in refs {
            let b = r.boxed();
            let (b0, b1) = (slabs.bins(b.lo), slabs.bins(b.hi));
            for axis in 0..3 {
                if slabs.scale[axis] == 0.0 {
                    continue;
                }
                let (b0, b1) = (b0[axis], b1[axis].max(b0[axis]));
                self.enter[axis][b0] += 1;
                self.exit[axis][b1] += 1;
                if b0 == b1 {
                    self.boxes[axis][b0] = self.boxes[axis][b0].union(b);
                    continue;
                }
                let boxes = &mut self.boxes[axis];
                slab_parts(
                    &ctx.tris[r.tri() as usize],
                    axis,
                    &slabs.planes[axis][b0..=b1 + 1],
                    (b.lo, b.hi),
                    |i, lo, hi| {
                        let bin = &mut boxes[(b0 + i) & (MAX_BINS - 1)];
                        *bin = bin.union(Box3 { lo, hi });
                    },
                );
            }
        }
        self
    }

    fn merge(mut self, o: &SpatialBins) -> Self {
        for a in 0..3 {
            for i in 0..MAX_BINS {
                self.boxes[a][i] = self.boxes[a][i].union(o.boxes[a][i]);
                self.enter[a][i] += o.enter[a][i];
                self.exit[a][i] += o.exit[a][i];
            }
        }
        self
    }
}

/// The cheapest spatial split of the node over equal slabs per axis, if it
/// keeps the references within `max_refs`.
fn best_spatial(ctx: &Ctx, refs: &[Ref], geom: &Box3, max_refs: usize) -> Option<Split> {
    let slabs = Slabs::new(geom, ctx.spatial_bins);
    let bins = if refs.len() >= PARALLEL_FILL / 4 && ctx.params.parallel {
        use rayon::prelude::*;
        refs.par_chunks(PARALLEL_FILL / 16)
            .map(|c| SpatialBins::new().fill(ctx, c, &slabs))
            .reduce(SpatialBins::new, |a, b| a.merge(&b))
    } else {
        SpatialBins::new().fill(ctx, refs, &slabs)
    };
    let inv_area = 1.0 / geom.area();
    let k = slabs.k;
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        if slabs.scale[axis] == 0.0 {
            continue;
        }
        let found = sweep(
            ctx,
            &bins.boxes[axis][..k],
            &bins.enter[axis][..k],
            &bins.exit[axis][..k],
            inv_area,
            max_refs,
        );
        if let Some((cost, i)) = found {
            if best.is_none_or(|b| cost < b.cost()) {
                best = Some(Split::Spatial {
                    axis,
                    pos: slabs.planes[axis][i],
                    cost,
                });
            }
        }
    }
    best
}

/// Partition `refs` in place: centroids below bin boundary `bin` first.
/// Returns the left count and the two sides' centroid boxes.
fn partition_object(
    refs: &mut [Ref],
    binner: &Binner,
    axis: usize,
    bin: usize,
) -> (usize, Box3, Box3) {
    let (mut lc, mut rc) = (Box3::EMPTY, Box3::EMPTY);
    let (mut i, mut j) = (0, refs.len());
    loop {
        while i < j {
            let c = refs[i].centroid2();
            if binner.bins(c)[axis] >= bin {
                break;
            }
            lc = lc.grow(c);
            i += 1;
        }
        while i < j {
            let c = refs[j - 1].centroid2();
            if binner.bins(c)[axis] < bin {
                break;
            }
            rc = rc.grow(c);
            j -= 1;
        }
        if i >= j {
            break;
        }
        refs.swap(i, j - 1);
    }
    (i, lc, rc)
}

/// Cut the first `n` references of `refs` at `axis = pos`: wholly below go
/// left, wholly above go right, and each one crossing the plane goes to the
/// side where it costs less or, split in two clipped parts, to both (Stich
/// et al.'s reference unsplitting; the right part is written after the
/// `n` references). Leaves the left side first and the right side after
/// it; returns their counts, boxes and centroid boxes.
fn partition_spatial(
    ctx: &Ctx,
    refs: &mut [Ref],
    n: usize,
    axis: usize,
    pos: f32,
) -> (usize, usize, Box3, Box3, Box3, Box3) {
    let w = ctx.params.leaf_width;
    // Three ways: [below | crossing | above].
    let (mut lo, mut mid, mut hi) = (0, 0, n);
    let (mut lb, mut rb) = (Box3::EMPTY, Box3::EMPTY);
    while mid < hi {
        let r = refs[mid];
        if r.hi[axis] <= pos {
            lb = lb.union(r.boxed());
            refs.swap(lo, mid);
            lo += 1;
            mid += 1;
        } else if r.lo[axis] >= pos {
            rb = rb.union(r.boxed());
            hi -= 1;
            refs.swap(mid, hi);
        } else {
            mid += 1;
        }
    }
    // The crossing references, in order; those that go right whole are
    // moved to the end of the crossing range, next to the references above.
    let mut copies = 0;
    let (mut nl, mut nr) = (hi, n - lo);
    let (mut i, mut j) = (lo, hi);
    while i < j {
        let r = refs[i];
        let bounds = r.boxed().aabb();
        let tri = &ctx.tris[r.tri() as usize];
        let (mut lcell, mut rcell) = (bounds, bounds);
        lcell.max[axis] = pos;
        rcell.min[axis] = pos;
        let go_right = match (clipped_bounds(tri, &lcell), clipped_bounds(tri, &rcell)) {
            (Some(lpart), Some(rpart)) => {
                // Unsplitting: the cost of the split as it is, of the whole
                // reference on the left, and on the right (areas of the
                // sides as they grow; counts in blocks).
                let (lpb, rpb) = (Box3::from_aabb(&lpart), Box3::from_aabb(&rpart));
                let (ls, rs) = (lb.union(lpb), rb.union(rpb));
                let whole = r.boxed();
                let c_split = ls.area() * blocks(nl, w) as f64 + rs.area() * blocks(nr, w) as f64;
                let c_left = lb.union(whole).area() * blocks(nl, w) as f64
                    + rs.area() * blocks(nr - 1, w) as f64;
                let c_right = ls.area() * blocks(nl - 1, w) as f64
                    + rb.union(whole).area() * blocks(nr, w) as f64;
                if c_left < c_split && c_left <= c_right {
                    nr -= 1;
                    lb = lb.union(whole);
                    false
                } else if c_right < c_split {
                    nl -= 1;
                    rb = rb.union(whole);
                    true
                } else {
                    lb = ls;
                    rb = rs;
                    refs[i] = r.with_bounds(lpart);
                    refs[n + copies] = r.with_bounds(rpart);
                    copies += 1;
                    false
                }
            }
            (Some(_), None) => {
                nr -= 1;
                lb = lb.union(r.boxed());
                false
            }
            (None, _) => {
                nl -= 1;
                rb = rb.union(r.boxed());
                true
            }
        };
        if go_right {
            j -= 1;
            refs.swap(i, j);
        } else {
            i += 1;
        }
    }
    debug_assert_eq!((j, n + copies - j), (nl, nr));
    let cent = |s: &[Ref]| s.iter().fold(Box3::EMPTY, |c, r| c.grow(r.centroid2()));
    let (lc, rc) = (cent(&refs[..j]), cent(&refs[j..n + copies]));
    (j, n + copies - j, lb, rb, lc, rc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BvhBuilder;
    use glam::Vec3;

    fn count(n: &BinaryNode) -> usize {
        match n {
            BinaryNode::Leaf { .. } => n.leaf_tris().len(),
            BinaryNode::Inner { kids, .. } => count(&kids[0]) + count(&kids[1]),
        }
    }

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
