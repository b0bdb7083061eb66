//! Exact SAH build in O(N log N) (Wald & Havran 2006, "On building fast
//! kd-trees for ray tracing, and on doing that in O(N log N)").
//!
//! Every boundary of every triangle's clipped bounds is a candidate plane.
//! Per axis, the triangles' start / end / planar events are kept in one list
//! sorted by position, so one linear sweep evaluates the SAH at every
//! candidate. After the split, the events of triangles that lie wholly on one
//! side stay sorted when filtered; only the straddling triangles are clipped
//! to their child cell ("perfect splits"), get new events, and are sorted and
//! merged in. No level ever re-sorts the whole list, hence O(N log N).

use rayon::prelude::*;

use super::cost::{PlanarSide, SahModel, Split};
use super::subtree::Subtree;
use super::BuildParams;
use crate::geometry::{Aabb, Primitive};

/// Event kinds, in their sort order at equal position: a triangle that ends
/// at `p` is left of `p` before one that lies in `p` or starts at `p`.
const END: u32 = 0;
const PLANAR: u32 = 1;
const START: u32 = 2;
const KIND_SHIFT: u32 = 30;
const TRI_MASK: u32 = (1 << KIND_SHIFT) - 1;

/// One event: a position and `kind << 30 | local triangle index`.
///
/// Sorting by (position, key) orders equal positions by kind, then triangle,
/// so the order is total and the build deterministic.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Event {
    pos: f32,
    key: u32,
}

impl Event {
    fn new(pos: f32, kind: u32, tri: u32) -> Self {
        // `+ 0.0` turns -0 into +0, so that `total_cmp` (the sort) and `==`
        // (the sweep's grouping) agree.
        Self {
            pos: pos + 0.0,
            key: (kind << KIND_SHIFT) | tri,
        }
    }
    #[inline(always)]
    fn kind(&self) -> u32 {
        self.key >> KIND_SHIFT
    }
    #[inline(always)]
    fn tri(&self) -> u32 {
        self.key & TRI_MASK
    }
    #[inline(always)]
    fn before(&self, o: &Event) -> bool {
        self.pos < o.pos || (self.pos == o.pos && self.key < o.key)
    }
}

fn sort_events(ev: &mut [Event], parallel: bool) {
    let cmp = |a: &Event, b: &Event| a.pos.total_cmp(&b.pos).then(a.key.cmp(&b.key));
    if parallel {
        ev.par_sort_unstable_by(cmp);
    } else {
        ev.sort_unstable_by(cmp);
    }
}

/// Push the events of a triangle with bounds `b` (local index `tri`).
fn push_events(events: &mut [Vec<Event>; 3], b: &Aabb, tri: u32) {
    for (a, list) in events.iter_mut().enumerate() {
        if b.min[a] == b.max[a] {
            list.push(Event::new(b.min[a], PLANAR, tri));
        } else {
            list.push(Event::new(b.min[a], START, tri));
            list.push(Event::new(b.max[a], END, tri));
        }
    }
}

/// A node under construction: its triangles (global indices; an event's
/// local index is a position in this list) and its three event lists.
struct Work {
    tris: Vec<u32>,
    events: [Vec<Event>; 3],
    cell: Aabb,
    depth: u32,
}

/// Below this many triangles a subtree is built on the current thread.
const PARALLEL_MIN: usize = 2048;

struct Ctx<'a, P> {
    triangles: &'a [P],
    budget: super::budget::RefBudget,
    params: &'a BuildParams,
    max_depth: u32,
}

/// Build the tree over the triangles `live` (indices into `triangles`)
/// inside `bounds`.
pub fn build<P: Primitive>(
    triangles: &[P],
    live: Vec<u32>,
    bounds: Aabb,
    params: &BuildParams,
) -> Subtree {
    let ctx = Ctx {
        triangles,
        budget: params.reference_budget(live.len()),
        params,
        max_depth: params.depth_limit(live.len()),
    };
    let mut events: [Vec<Event>; 3] = Default::default();
    for list in events.iter_mut() {
        list.reserve(2 * live.len());
    }
    for (local, &t) in live.iter().enumerate() {
        push_events(&mut events, &triangles[t as usize].bounds(), local as u32);
    }
    let par = params.parallel && live.len() >= PARALLEL_MIN;
    for list in events.iter_mut() {
        sort_events(list, par);
    }
    recurse(
        &ctx,
        Work {
            tris: live,
            events,
            cell: bounds,
            depth: 0,
        },
    )
}

fn recurse<P: Primitive>(ctx: &Ctx<P>, w: Work) -> Subtree {
    let p = ctx.params;
    let n = w.tris.len();
    let Some(model) = SahModel::new(w.cell, p) else {
        return Subtree::leaf(w.tris, &w.cell, p);
    };
    if n == 0 || n <= p.max_leaf_size as usize || w.depth >= ctx.max_depth {
        return Subtree::leaf(w.tris, &w.cell, p);
    }
    let split = find_split(&model, &w, p.parallel && n >= 64 * PARALLEL_MIN);
    let Some(split) = split.filter(|s| s.cost < model.leaf_cost(n)) else {
        return Subtree::leaf(w.tris, &w.cell, p);
    };
    if !ctx.budget.try_take(split.refs.saturating_sub(n)) {
        return Subtree::leaf(w.tris, &w.cell, p);
    }
    let cell = w.cell;
    let (left, right) = split_work(ctx, w, &split);
    let (below, above) = if p.parallel && n >= PARALLEL_MIN {
        rayon::join(|| recurse(ctx, left), || recurse(ctx, right))
    } else {
        (recurse(ctx, left), recurse(ctx, right))
    };
    Subtree::join(split.axis, split.pos, &cell, n, below, above, p, true)
}

/// The cheapest plane over all three sweeps.
fn find_split(model: &SahModel, w: &Work, parallel: bool) -> Option<Split> {
    let sweep = |axis: usize| sweep_axis(model, &w.events[axis], axis, w.tris.len(), &w.cell);
    let best = if parallel {
        let (a, (b, c)) = rayon::join(|| sweep(0), || rayon::join(|| sweep(1), || sweep(2)));
        [a, b, c]
    } else {
        [sweep(0), sweep(1), sweep(2)]
    };
    // Ties go to the lower axis, so the result does not depend on threading.
    best.into_iter()
        .flatten()
        .fold(None, |acc: Option<Split>, s| match acc {
            Some(a) if a.cost <= s.cost => Some(a),
            _ => Some(s),
        })
}

/// Wald & Havran's sweep (their Algorithm 4) over one axis.
fn sweep_axis(
    model: &SahModel,
    events: &[Event],
    axis: usize,
    n: usize,
    cell: &Aabb,
) -> Option<Split> {
    if cell.min[axis] == cell.max[axis] {
        return None; // a flat axis has nothing to split
    }
    let (mut nl, mut nr) = (0usize, n);
    let mut best: Option<Split> = None;
    let mut i = 0;
    while i < events.len() {
        let pos = events[i].pos;
        let (mut ends, mut planars, mut starts) = (0usize, 0usize, 0usize);
        while i < events.len() && events[i].pos == pos && events[i].kind() == END {
            ends += 1;
            i += 1;
        }
        while i < events.len() && events[i].pos == pos && events[i].kind() == PLANAR {
            planars += 1;
            i += 1;
        }
        while i < events.len() && events[i].pos == pos && events[i].kind() == START {
            starts += 1;
            i += 1;
        }
        nr -= planars + ends;
        if let Some(s) = model.best_planar(axis, pos, nl, planars, nr) {
            if best.is_none_or(|b| s.cost < b.cost) {
                best = Some(s);
            }
        }
        nl += starts + planars;
    }
    best
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Both,
    Left,
    Right,
}

/// Distribute the node's triangles and events to its two children.
fn split_work<P: Primitive>(ctx: &Ctx<P>, w: Work, s: &Split) -> (Work, Work) {
    let n = w.tris.len();
    let mut side = vec![Side::Both; n];
    for e in &w.events[s.axis] {
        let t = e.tri() as usize;
        match e.kind() {
            END if e.pos <= s.pos => side[t] = Side::Left,
            START if e.pos >= s.pos => side[t] = Side::Right,
            PLANAR => {
                let left = e.pos < s.pos || (e.pos == s.pos && s.planar == PlanarSide::Left);
                side[t] = if left { Side::Left } else { Side::Right };
            }
            _ => {}
        }
    }
    let (lcell, rcell) = w.cell.split(s.axis, s.pos);
    let depth = w.depth + 1;
    let parallel = ctx.params.parallel && n >= PARALLEL_MIN;
    let make = |keep: Side, cell: Aabb| child(ctx, &w, &side, keep, cell, depth, parallel);
    if parallel {
        rayon::join(|| make(Side::Left, lcell), || make(Side::Right, rcell))
    } else {
        (make(Side::Left, lcell), make(Side::Right, rcell))
    }
}

/// One child's work: the triangles wholly on its side keep their (filtered,
/// still sorted) events; straddlers are clipped to the child's cell and their
/// new events merged in.
fn child<P: Primitive>(
    ctx: &Ctx<P>,
    w: &Work,
    side: &[Side],
    keep: Side,
    cell: Aabb,
    depth: u32,
    parallel: bool,
) -> Work {
    const DROPPED: u32 = u32::MAX;
    let mut remap = vec![DROPPED; w.tris.len()];
    let mut tris = Vec::with_capacity(w.tris.len() / 2 + 1);
    let mut straddlers: [Vec<Event>; 3] = Default::default();
    for (local, (&global, &sd)) in w.tris.iter().zip(side).enumerate() {
        if sd == keep {
            remap[local] = tris.len() as u32;
            tris.push(global);
        } else if sd == Side::Both {
            if let Some(b) = ctx.triangles[global as usize].clipped_bounds(&cell) {
                push_events(&mut straddlers, &b, tris.len() as u32);
                tris.push(global);
            }
        }
    }
    let mut events: [Vec<Event>; 3] = Default::default();
    for (axis, out) in events.iter_mut().enumerate() {
        let mut fresh = std::mem::take(&mut straddlers[axis]);
        let big = parallel && fresh.len() > 1 << 16;
        sort_events(&mut fresh, big);
        let kept = w.events[axis].iter().filter_map(|e| {
            let r = remap[e.tri() as usize];
            (r != DROPPED && side[e.tri() as usize] == keep).then_some(Event {
                pos: e.pos,
                key: (e.key & !TRI_MASK) | r,
            })
        });
        *out = merge(kept, &fresh);
    }
    Work {
        tris,
        events,
        cell,
        depth,
    }
}

/// Merge a sorted iterator with a sorted slice.
fn merge(a: impl Iterator<Item = Event>, b: &[Event]) -> Vec<Event> {
    let (lo, _) = a.size_hint();
    let mut out = Vec::with_capacity(lo + b.len());
    let mut j = 0;
    for e in a {
        while j < b.len() && b[j].before(&e) {
            out.push(b[j]);
            j += 1;
        }
        out.push(e);
    }
    out.extend_from_slice(&b[j..]);
    out
}
