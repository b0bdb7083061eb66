//! Triangle references with clipped bounds, and how a split distributes
//! them: shared by the binned and the naive builders.

use rayon::prelude::*;

use super::Primitive;
use crate::math::Aabb;

/// A triangle in a cell, with the bounds of its part inside the cell.
#[derive(Clone, Copy, Debug)]
pub struct Ref {
    /// Triangle index.
    pub tri: u32,
    /// Bounds of the triangle clipped to the cell.
    pub bounds: Aabb,
}

/// The references of the root cell.
pub fn root_refs<P: Primitive>(triangles: &[P], live: &[u32]) -> Vec<Ref> {
    live.iter()
        .map(|&t| Ref {
            tri: t,
            bounds: triangles[t as usize].bounds(),
        })
        .collect()
}

/// True if `r` crosses the plane `axis = pos` and so goes to both sides
/// (the rule [`partition`] follows).
#[inline]
fn straddles(r: &Ref, axis: usize, pos: f32) -> bool {
    let (lo, hi) = (r.bounds.min[axis], r.bounds.max[axis]);
    lo < pos && hi > pos
}

/// How many references a split at `axis = pos` would duplicate.
pub fn count_straddlers(refs: &[Ref], axis: usize, pos: f32) -> usize {
    refs.iter().filter(|r| straddles(r, axis, pos)).count()
}

/// Below this many references a partition runs on the current thread.
const PARALLEL_MIN: usize = 1 << 14;

/// Distribute `refs` to the cells below and above `axis = pos`.
///
/// A reference that lies in the plane goes below; one that only touches the
/// plane goes to its own side; one that crosses it is clipped to each child
/// cell (perfect splits), so its child bounds are exact.
pub fn partition<P: Primitive>(
    triangles: &[P],
    refs: Vec<Ref>,
    axis: usize,
    pos: f32,
    below_cell: &Aabb,
    above_cell: &Aabb,
    parallel: bool,
) -> (Vec<Ref>, Vec<Ref>) {
    let one = |r: &Ref, below: &mut Vec<Ref>, above: &mut Vec<Ref>| {
        let (lo, hi) = (r.bounds.min[axis], r.bounds.max[axis]);
        if hi < pos || (hi == pos && (lo < pos || lo == hi)) {
            below.push(*r);
        } else if lo >= pos {
            above.push(*r);
        } else {
            let tri = &triangles[r.tri as usize];
            if let Some(b) = tri.clipped_bounds(below_cell) {
                below.push(Ref {
                    tri: r.tri,
                    bounds: b.intersection(r.bounds),
                });
            }
            if let Some(b) = tri.clipped_bounds(above_cell) {
                above.push(Ref {
                    tri: r.tri,
                    bounds: b.intersection(r.bounds),
                });
            }
        }
    };
    if parallel && refs.len() >= PARALLEL_MIN {
        let parts: Vec<(Vec<Ref>, Vec<Ref>)> = refs
            .par_chunks(PARALLEL_MIN / 4)
            .map(|chunk| {
                let (mut b, mut a) = (Vec::new(), Vec::new());
                chunk.iter().for_each(|r| one(r, &mut b, &mut a));
                (b, a)
            })
            .collect();
        let (mut below, mut above) = (Vec::new(), Vec::new());
        for (b, a) in parts {
            below.extend(b);
            above.extend(a);
        }
        (below, above)
    } else {
        let (mut below, mut above) = (
            Vec::with_capacity(refs.len() / 2),
            Vec::with_capacity(refs.len() / 2),
        );
        refs.iter().for_each(|r| one(r, &mut below, &mut above));
        (below, above)
    }
}
