//! A finished subtree, in depth-first order, ready to be concatenated.
//!
//! Subtrees are built apart (and in parallel) and joined under their parent:
//! the parent node, then the subtree below the plane, then the one above.
//! Child pointers and leaf offsets are relative to the subtree's own arrays
//! and are moved when it is appended, one linear pass per level.

use crate::build::BuildParams;
use crate::math::Aabb;

/// A node of a built tree, in depth-first order: the child below an inner
/// node's plane is the next node. The kd-tree flattens these into its
/// 8-byte nodes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BuiltNode {
    /// A split of `axis` at `pos`; the child above the plane is node `above`.
    Inner {
        /// Split axis (0, 1, 2).
        axis: u8,
        /// Split position.
        pos: f32,
        /// Index of the child above the plane.
        above: u32,
    },
    /// A leaf: `count` entries of the index array from `offset`.
    Leaf {
        /// Offset of the leaf's first entry in the index array.
        offset: u32,
        /// Number of entries.
        count: u32,
    },
}

impl BuiltNode {
    /// This node with its child pointer or leaf offset moved by `delta`
    /// (used when subtrees built apart are concatenated).
    #[inline]
    fn shifted(self, node_delta: u32, index_delta: u32) -> Self {
        match self {
            BuiltNode::Inner { axis, pos, above } => BuiltNode::Inner {
                axis,
                pos,
                above: above + node_delta,
            },
            BuiltNode::Leaf { offset, count } => BuiltNode::Leaf {
                offset: offset + index_delta,
                count,
            },
        }
    }
}

/// Nodes and leaf indices of a subtree, with its SAH cost.
pub struct Subtree {
    /// Nodes in depth-first order; pointers relative to this array.
    pub nodes: Vec<BuiltNode>,
    /// Leaf triangle indices; offsets relative to this array.
    pub indices: Vec<u32>,
    /// Area-weighted cost: `sum SA(inner) K_T + sum SA(leaf) K_I tests(n)`.
    pub cost: f64,
}

impl Subtree {
    /// A single leaf holding `tris`.
    pub fn leaf(tris: Vec<u32>, cell: &Aabb, p: &BuildParams) -> Self {
        let cost = cell.surface_area() * p.intersection_cost as f64 * p.leaf_tests(tris.len());
        Self {
            nodes: vec![BuiltNode::Leaf {
                offset: 0,
                count: tris.len() as u32,
            }],
            indices: tris,
            cost,
        }
    }

    /// An inner node over two subtrees.
    ///
    /// With `retract`, a subtree that costs more than a leaf with the same
    /// triangles becomes that leaf (Wald & Havran 2006: the greedy SAH can
    /// be wrong about a split once its children are known).
    /// `n` is the number of triangles in the cell.
    #[allow(clippy::too_many_arguments)]
    pub fn join(
        axis: usize,
        pos: f32,
        cell: &Aabb,
        n: usize,
        below: Subtree,
        above: Subtree,
        p: &BuildParams,
        retract: bool,
    ) -> Self {
        let area = cell.surface_area();
        let cost = area * p.traversal_cost as f64 + below.cost + above.cost;
        if retract && area * p.intersection_cost as f64 * p.leaf_tests(n) <= cost {
            let mut tris: Vec<u32> = below
                .indices
                .iter()
                .chain(&above.indices)
                .copied()
                .collect();
            tris.sort_unstable();
            tris.dedup();
            let leaf_cost = area * p.intersection_cost as f64 * p.leaf_tests(tris.len());
            if leaf_cost <= cost {
                return Self::leaf(tris, cell, p);
            }
        }
        let above_at = 1 + below.nodes.len() as u32;
        let mut nodes = Vec::with_capacity(1 + below.nodes.len() + above.nodes.len());
        nodes.push(BuiltNode::Inner {
            axis: axis as u8,
            pos,
            above: above_at,
        });
        nodes.extend(below.nodes.iter().map(|n| n.shifted(1, 0)));
        let index_delta = below.indices.len() as u32;
        nodes.extend(above.nodes.iter().map(|n| n.shifted(above_at, index_delta)));
        let mut indices = below.indices;
        indices.extend_from_slice(&above.indices);
        Self {
            nodes,
            indices,
            cost,
        }
    }
}
