//! Statistics of a finished hierarchy, with its SAH cost.

use super::node::{is_leaf, leaf_parts, ARITY, EMPTY};
use super::quad::QUAD;
use super::Bvh;
use crate::math::Aabb;

/// Shape, size and cost of a hierarchy.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BvhStats {
    /// Triangles given to the build.
    pub triangles: usize,
    /// Wide nodes.
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Mean used child slots per wide node.
    pub mean_children: f64,
    /// Depth of the deepest leaf in wide nodes (a leaf of the root: 1).
    pub max_depth: u32,
    /// Mean triangles per leaf.
    pub mean_leaf_triangles: f64,
    /// Triangle references stored in leaves.
    pub references: usize,
    /// References per hittable triangle (1: no spatial split copies).
    pub duplication: f64,
    /// Bytes of nodes and leaves.
    pub memory_bytes: usize,
    /// The SAH cost with one unit per wide node visited and one per leaf
    /// of up to four triangles tested: `sum_nodes SA/SA_root + sum_leaves
    /// SA/SA_root`.
    pub sah_cost: f64,
    /// Wide nodes the SAH expects a ray meeting the root to visit (no
    /// early exit): `sum_nodes SA/SA_root`.
    pub expected_nodes: f64,
    /// Leaves: `sum_leaves SA/SA_root`.
    pub expected_leaves: f64,
    /// Four-triangle tests: `sum_leaves SA/SA_root ceil(n / 4)` (every
    /// leaf is one).
    pub expected_blocks: f64,
    /// Triangle tests: `sum_leaves SA/SA_root n`.
    pub expected_triangles: f64,
}

impl Bvh {
    /// Compute the statistics (one pass over the nodes).
    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats {
            triangles: self.prim_count,
            nodes: self.nodes.len(),
            references: self.references,
            memory_bytes: std::mem::size_of_val(self.nodes.as_slice())
                + std::mem::size_of_val(self.quads.as_slice()),
            ..Default::default()
        };
        if self.nodes.is_empty() {
            return s;
        }
        let root_area = self.bounds.surface_area();
        let inv = if root_area > 0.0 {
            1.0 / root_area
        } else {
            0.0
        };
        let mut hittable = std::collections::HashSet::<u32>::new();
        let mut children = 0usize;
        let mut todo: Vec<(u32, Aabb, u32)> = vec![(0, self.bounds, 1)];
        while let Some((i, b, depth)) = todo.pop() {
            // SAFETY: `i` is the root or an inner reference.
            let n = unsafe { self.node(i) };
            s.expected_nodes += b.surface_area() * inv;
            for slot in 0..ARITY {
                let c = n.child[slot];
                if c == EMPTY {
                    continue;
                }
                children += 1;
                let cb = n.child_bounds(slot);
                if is_leaf(c) {
                    let (line, count) = leaf_parts(c);
                    s.leaves += 1;
                    s.max_depth = s.max_depth.max(depth);
                    let a = cb.surface_area() * inv;
                    s.expected_leaves += a;
                    s.expected_blocks += a * count.div_ceil(QUAD) as f64;
                    s.expected_triangles += a * count as f64;
                    // SAFETY: a leaf reference.
                    let q = unsafe { self.quad(line) };
                    hittable.extend(&q.tri[..count]);
                } else {
                    todo.push((c, cb, depth + 1));
                }
            }
        }
        s.mean_children = children as f64 / s.nodes as f64;
        s.mean_leaf_triangles = self.references as f64 / s.leaves.max(1) as f64;
        s.duplication = self.references as f64 / hittable.len().max(1) as f64;
        s.sah_cost = s.expected_nodes + s.expected_blocks;
        s
    }
}
