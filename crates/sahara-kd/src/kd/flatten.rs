//! A built tree flattened into 8-byte nodes, with its leaf runs padded and
//! its leaf data packed.

use super::{KdTree, LeafStorage, Node};
use crate::build::{self, BuildParams, BuiltNode};

impl<P: LeafStorage> KdTree<P> {
    /// Build a tree over `prims` (their indices are the ones hits report).
    ///
    /// Primitives no ray can hit (for triangles: a non-finite coordinate or
    /// zero area, see [`crate::Triangle::is_hittable`]) are left out.
    pub fn build(prims: Vec<P>, params: &BuildParams) -> KdTree<P> {
        let (sub, bounds) = build::build(&prims, params);
        let (mut nodes, indices) = flatten(&sub.nodes, &sub.indices, P::LEAF_WIDTH);
        let leaf_data = P::leaf_data(&prims, &indices, &mut nodes, params);
        let wide_shift = P::LEAF_WIDTH.trailing_zeros();
        let wide = match params.wide_nodes && P::WIDE_NODES {
            true => super::wide::derive(&nodes, wide_shift).unwrap_or_default(),
            false => Vec::new(),
        };
        let mut tree = KdTree {
            nodes,
            indices,
            prim_count: prims.len(),
            leaf_data,
            bounds,
            params: *params,
            wide,
            wide_shift,
            expected_inner: 0.0,
            max_level: crate::simd::level::AVX512,
        };
        tree.expected_inner = tree.sah_expected_inner();
        tree
    }

    /// Inner nodes a ray meeting the root is expected to visit by the
    /// SAH's model (cell area over root area, summed over inner nodes;
    /// 0 for a degenerate root), as [`crate::TreeStats::expected_inner`]
    /// reports it.
    fn sah_expected_inner(&self) -> f64 {
        let root = self.bounds.surface_area();
        let inv_root = if root > 0.0 { 1.0 / root } else { 0.0 };
        let mut sum = 0.0f64;
        self.visit(|_, n, cell, _| {
            if !n.is_leaf() {
                sum += cell.surface_area() * inv_root;
            }
        });
        sum
    }
}

/// The 8-byte nodes of `built`, with every leaf's index run moved to a
/// multiple of `width` and padded to one with `u32::MAX`, so that run `k`
/// of a triangle leaf is block `k / width`.
fn flatten(built: &[BuiltNode], indices: &[u32], width: usize) -> (Vec<Node>, Vec<u32>) {
    let mut padded = Vec::with_capacity(indices.len() + indices.len() / 2);
    let nodes = built
        .iter()
        .map(|n| match *n {
            BuiltNode::Inner { axis, pos, above } => Node::inner(axis as usize, pos, above),
            BuiltNode::Leaf { offset, count } => {
                let (o, c) = (offset as usize, count as usize);
                let at = padded.len() as u32;
                padded.extend_from_slice(&indices[o..o + c]);
                padded.resize(padded.len().next_multiple_of(width), u32::MAX);
                Node::leaf(at, count)
            }
        })
        .collect();
    (nodes, padded)
}
