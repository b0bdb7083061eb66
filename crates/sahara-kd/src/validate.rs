//! A structural validator for trees: used by the test suite on every builder.

use glam::DVec3;

use crate::kd::{KdTree, Node};
use crate::leaf::TriangleLeaves;
use crate::leaf::BLOCK_WIDTH;
use crate::math::{Aabb, Triangle};

/// Check a tree's structure and coverage; the first problem found is
/// returned as a message.
///
/// - Layout: nodes depth first, the child below the plane right after its
///   parent, every node reached once, leaf ranges inside the index array,
///   split planes inside their cells.
/// - Coverage: every hittable triangle that overlaps the interior of a leaf's
///   cell is referenced by that leaf, and every referenced triangle touches
///   the cell. ("Interior" shrinks the cell by 1e-5 of its extent on each
///   axis that has one; a flat cell's interior is the inside of its plane
///   rectangle, which only triangles lying in that plane overlap in area.)
/// - Leaf blocks: every leaf's run starts at a multiple of the block width,
///   its block lanes hold exactly the triangles its indices name (bit for
///   bit), and the padding lanes' indices are `u32::MAX`.
///
/// `triangles` are the triangles the tree was built from.
pub fn validate(tree: &KdTree, triangles: &[Triangle]) -> Result<(), String> {
    let nodes = tree.nodes();
    if nodes.is_empty() {
        return Err("no root node".into());
    }
    if tree.primitive_count() != triangles.len() {
        return Err(format!(
            "built from {} triangles, validated against {}",
            tree.primitive_count(),
            triangles.len()
        ));
    }
    let mut seen = vec![false; nodes.len()];
    let mut err = None;
    let mut leaves = Vec::new();
    tree.visit(|i, n, cell, _| {
        if err.is_some() {
            return;
        }
        if std::mem::replace(&mut seen[i as usize], true) {
            err = Some(format!("node {i} reached twice"));
            return;
        }
        if n.is_leaf() {
            let count = n.leaf_count() as usize;
            let run = match tree.leaf_data().leaf_run(n.leaf_offset()) {
                _ if count == 0 => 0,
                Some(run) => run,
                None => {
                    err = Some(format!("leaf {i} points past its leaf data"));
                    return;
                }
            };
            if run + count > tree.indices().len() {
                err = Some(format!("leaf {i} indexes past the index array"));
            } else if let Some(&t) = tree
                .leaf_triangles(n)
                .iter()
                .find(|&&t| t as usize >= triangles.len())
            {
                err = Some(format!(
                    "leaf {i} references triangle {t} of {}",
                    triangles.len()
                ));
            } else if let Err(e) = check_blocks(tree, triangles, n) {
                err = Some(format!("leaf {i}: {e}"));
            } else {
                leaves.push((i, *n, *cell));
            }
        } else {
            let (a, p) = (n.axis(), n.split());
            let above = n.above_child() as usize;
            if above <= i as usize + 1 || above >= nodes.len() {
                err = Some(format!(
                    "node {i}: child above at {above} breaks the depth-first layout"
                ));
            } else if !(p >= cell.min[a] && p <= cell.max[a]) {
                err = Some(format!(
                    "node {i}: split {p} outside its cell [{}, {}] on axis {a}",
                    cell.min[a], cell.max[a]
                ));
            }
        }
    });
    if let Some(e) = err {
        return Err(e);
    }
    if let Some(i) = seen.iter().position(|&s| !s) {
        return Err(format!("node {i} is unreachable"));
    }
    for (i, n, cell) in leaves {
        let refs = tree.leaf_triangles(&n);
        let interior = shrink(&cell, 1e-5);
        let outside = shrink(&cell, -1e-5);
        for (t, tri) in triangles.iter().enumerate() {
            if !tri.is_hittable() {
                continue;
            }
            let referenced = refs.contains(&(t as u32));
            // A flat cell's interior is a piece of a plane: only a triangle
            // lying in that plane overlaps it in more than a segment (one
            // that merely pierces it is held by the cells on either side).
            let in_flat_planes = (0..3)
                .all(|a| cell.min[a] < cell.max[a] || tri.v.iter().all(|v| v[a] == cell.min[a]));
            if !referenced && in_flat_planes && overlaps(tri, &interior, Certainty::Surely) {
                return Err(format!(
                    "leaf {i} (cell {cell:?}) misses triangle {t}, which overlaps it"
                ));
            }
            if referenced && !overlaps(tri, &outside, Certainty::Possibly) {
                return Err(format!(
                    "leaf {i} (cell {cell:?}) references triangle {t}, which does not touch it"
                ));
            }
        }
    }
    Ok(())
}

/// A leaf's blocks against its index run (see [`validate`]).
fn check_blocks(tree: &KdTree, triangles: &[Triangle], leaf: &Node) -> Result<(), String> {
    let (offset, count) = (leaf.leaf_offset() as usize, leaf.leaf_count() as usize);
    if count == 0 {
        return Ok(());
    }
    match tree.leaf_data() {
        TriangleLeaves::Whole(v) => {
            if offset % BLOCK_WIDTH != 0 {
                return Err(format!("run at {offset} is not block aligned"));
            }
            let first = offset / BLOCK_WIDTH;
            let Some(blocks) = v.get(first..first + count.div_ceil(BLOCK_WIDTH)) else {
                return Err("blocks past the block array".into());
            };
            for (b, block) in blocks.iter().enumerate() {
                let run = offset + b * BLOCK_WIDTH;
                check_lanes(tree, triangles, count, b, run, |l| Some(block.triangle(l)))?;
            }
        }
        TriangleLeaves::Indexed(pool) => {
            let (mut at, mut first_run) = (offset, 0);
            for b in 0..count.div_ceil(BLOCK_WIDTH) {
                let Some(block) = pool.checked_block(at) else {
                    return Err(format!(
                        "block {b} of a leaf starts past the leaf data ({at})"
                    ));
                };
                let run = block.run();
                if b == 0 {
                    if run % BLOCK_WIDTH != 0 {
                        return Err(format!("run at {run} is not block aligned"));
                    }
                    first_run = run;
                } else if run != first_run + b * BLOCK_WIDTH {
                    let want = first_run + b * BLOCK_WIDTH;
                    return Err(format!("block {b} names run {run}, not {want}"));
                }
                check_lanes(tree, triangles, count, b, run, |l| {
                    let named = (0..3).all(|v| block.number(v, l) < block.table_len());
                    named.then(|| block.triangle(l))
                })?;
                at += block.len();
            }
        }
    }
    Ok(())
}

/// Block `b` of a leaf of `count` triangles, whose lane 0 is index-array
/// entry `run`: its lanes hold the triangles the entries name, bit for bit
/// (`lane` gives a lane's triangle, `None` if the block cannot say), and
/// its padding entries are `u32::MAX`.
fn check_lanes(
    tree: &KdTree,
    triangles: &[Triangle],
    count: usize,
    b: usize,
    run: usize,
    lane: impl Fn(usize) -> Option<Triangle>,
) -> Result<(), String> {
    let Some(entries) = tree.indices().get(run..run + BLOCK_WIDTH) else {
        return Err("padded run past the index array".into());
    };
    for (l, &t) in entries.iter().enumerate() {
        let k = b * BLOCK_WIDTH + l;
        if k >= count {
            if t != u32::MAX {
                return Err(format!("padding entry {k} holds {t}"));
            }
            continue;
        }
        let Some(got) = lane(l) else {
            return Err(format!("block lane {k} names a vertex past its table"));
        };
        let want = triangles[t as usize];
        let bits = |tri: &Triangle| tri.v.map(|p| p.to_array().map(f32::to_bits));
        if bits(&got) != bits(&want) {
            return Err(format!(
                "block lane {k} holds {got:?}, not triangle {t} {want:?}"
            ));
        }
    }
    Ok(())
}

/// The cell shrunk (`f > 0`) or grown (`f < 0`) by `f` of its extent on
/// every axis with an extent; growth also pads flat axes.
fn shrink(c: &Aabb, f: f64) -> (DVec3, DVec3) {
    let (lo, hi) = (c.min.as_dvec3(), c.max.as_dvec3());
    let e = hi - lo;
    let scale = lo.abs().max(hi.abs()).max_element().max(e.max_element());
    let d = DVec3::new(e.x, e.y, e.z) * f;
    let pad = if f < 0.0 {
        DVec3::splat(-f * scale)
    } else {
        DVec3::ZERO
    };
    (lo + d - pad, hi - d + pad)
}

/// How [`overlaps`] treats a case that f64 rounding cannot decide.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Certainty {
    /// Report overlap only when it survives the rounding error.
    Surely,
    /// Report overlap unless separation survives the rounding error.
    Possibly,
}

/// Triangle / box overlap by the separating axis theorem (Akenine-Möller
/// 2001), in f64; touching counts as overlapping.
fn overlaps(tri: &Triangle, (lo, hi): &(DVec3, DVec3), certainty: Certainty) -> bool {
    let c = (*lo + *hi) * 0.5;
    let h = (*hi - *lo) * 0.5;
    if h.min_element() < 0.0 {
        return false;
    }
    let v = tri.v.map(|p| p.as_dvec3() - c);
    // The box's face normals.
    for a in 0..3 {
        let (mn, mx) = (
            v[0][a].min(v[1][a]).min(v[2][a]),
            v[0][a].max(v[1][a]).max(v[2][a]),
        );
        let err = 8.0 * f64::EPSILON * (h[a] + c[a].abs() + mn.abs().max(mx.abs()));
        let slack = if certainty == Certainty::Surely {
            -err
        } else {
            err
        };
        if mn > h[a] + slack || mx < -h[a] - slack {
            return false;
        }
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let mut axes: Vec<DVec3> = vec![e[0].cross(e[1])];
    for ei in e {
        for a in [DVec3::X, DVec3::Y, DVec3::Z] {
            axes.push(ei.cross(a));
        }
    }
    for ax in axes {
        if ax == DVec3::ZERO {
            continue;
        }
        let p = v.map(|q| q.dot(ax));
        let r = h.x * ax.x.abs() + h.y * ax.y.abs() + h.z * ax.z.abs();
        let (mn, mx) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        // The rounding error of the projections, counted against the
        // verdict that is asked for.
        let err = 8.0
            * f64::EPSILON
            * (r + mn.abs().max(mx.abs()) + v.iter().map(|q| q.abs().dot(ax.abs())).sum::<f64>());
        let slack = if certainty == Certainty::Surely {
            -err
        } else {
            err
        };
        if mn > r + slack || mx < -r - slack {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::build::BuildParams;

    /// The block check fails on a block that no longer matches its
    /// indices, in either layout; and on an indexed block whose header
    /// claims more table than the pool holds.
    #[test]
    fn a_corrupted_leaf_block_is_reported() {
        // Strips of two triangles sharing an edge: the indexed blocks hold
        // 4 distinct vertices per pair.
        let tris: Vec<Triangle> = (0..40)
            .map(|i| {
                let x = (i / 2) as f32;
                let (a, b, c, d) = (
                    Vec3::new(x, 0.0, 1.0),
                    Vec3::new(x + 0.5, 0.0, 1.0),
                    Vec3::new(x, 1.0, 1.0),
                    Vec3::new(x + 0.5, 1.0, 1.0),
                );
                if i % 2 == 0 {
                    Triangle::new(a, b, c)
                } else {
                    Triangle::new(b, d, c)
                }
            })
            .collect();
        for compact in [false, true] {
            let params = BuildParams {
                compact_leaves: compact,
                ..BuildParams::default()
            };
            let mut tree = KdTree::build(tris.clone(), &params);
            validate(&tree, &tris).unwrap();
            match &mut tree.leaf_data {
                TriangleLeaves::Whole(v) => v[0].v[1][2][0] += 1.0,
                TriangleLeaves::Indexed(p) => {
                    // The z of the first block's table entry 1 (after the
                    // eight header words, rows of `stride` entries).
                    let words = p.words_mut();
                    let stride = (words[1] >> 8) as usize;
                    assert!(stride < 24, "a shared-vertex block");
                    let z = &mut words[8 + 2 * stride + 1];
                    *z = (f32::from_bits(*z) + 1.0).to_bits();
                }
            }
            let e = validate(&tree, &tris).unwrap_err();
            assert!(e.contains("block lane"), "{e}");
            assert!(validate(&tree, &tris[1..]).is_err(), "wrong triangle count");
            if let TriangleLeaves::Indexed(p) = &mut tree.leaf_data {
                p.words_mut()[1] |= 200 << 8;
                let e = validate(&tree, &tris).unwrap_err();
                assert!(e.contains("past"), "{e}");
            }
        }
    }
}
