//! The SAH kd-tree collapsed into the hierarchy: the kd build's cells
//! become boxes, each leaf's box the bounds of its triangles clipped to its
//! cell (the kd-tree's exact clipping), each inner node's box the union of
//! its children's; empty leaves vanish. The result is a binary tree whose
//! splits are the kd-tree's "perfect splits", collapsed into wide nodes
//! like any other (three kd levels per wide node where the tree is
//! balanced).

use super::binary::{self, BinaryNode, Ref};
use super::BvhParams;
use crate::build::BuiltNode;
use crate::bvh::node::MAX_LEAF;
use crate::math::clip::clipped_bounds;
use crate::math::{Aabb, Triangle};

/// Levels near the root converted on both threads of a `rayon::join`.
const PARALLEL_DEPTH: u32 = 6;

/// The binary tree of the kd-tree built over `tris` with `params.kd`
/// (at least one triangle is hittable).
pub(crate) fn build(tris: &[Triangle], params: &BvhParams) -> BinaryNode {
    let (sub, bounds) = crate::build::build(tris, &params.kd);
    let kd = Kd {
        tris,
        nodes: &sub.nodes,
        indices: &sub.indices,
        params,
    };
    kd.convert(0, bounds, 0)
        .expect("a kd-tree over hittable triangles has a non-empty leaf")
}

struct Kd<'a> {
    tris: &'a [Triangle],
    nodes: &'a [BuiltNode],
    indices: &'a [u32],
    params: &'a BvhParams,
}

impl Kd<'_> {
    /// The binary node of kd node `i` with cell `cell`; `None` for a
    /// subtree without triangles.
    fn convert(&self, i: usize, cell: Aabb, depth: u32) -> Option<BinaryNode> {
        match self.nodes[i] {
            BuiltNode::Leaf { offset, count } => {
                let ids = &self.indices[offset as usize..(offset + count) as usize];
                self.leaf(ids, &cell)
            }
            BuiltNode::Inner { axis, pos, above } => {
                let (lo, hi) = cell.split(axis as usize, pos);
                let (a, b) = if self.params.parallel && depth < PARALLEL_DEPTH {
                    rayon::join(
                        || self.convert(i + 1, lo, depth + 1),
                        || self.convert(above as usize, hi, depth + 1),
                    )
                } else {
                    (
                        self.convert(i + 1, lo, depth + 1),
                        self.convert(above as usize, hi, depth + 1),
                    )
                };
                match (a, b) {
                    (Some(a), Some(b)) => Some(BinaryNode::inner(a, b)),
                    (a, b) => a.or(b),
                }
            }
        }
    }

    /// A kd leaf: its triangles' parts in the cell; a leaf larger than a
    /// hierarchy's leaf is split further by the binned build over those
    /// parts.
    fn leaf(&self, ids: &[u32], cell: &Aabb) -> Option<BinaryNode> {
        let parts: Vec<(Aabb, u32)> = ids
            .iter()
            .filter(|&&i| i != u32::MAX)
            .filter_map(|&i| clipped_bounds(&self.tris[i as usize], cell).map(|bounds| (bounds, i)))
            .collect();
        if parts.is_empty() {
            return None;
        }
        let refs: Vec<Ref> = parts.iter().map(|&(b, i)| Ref::new(b, i)).collect();
        if refs.len() <= MAX_LEAF {
            let bounds = parts.iter().fold(Aabb::EMPTY, |b, r| b.union(r.0));
            return Some(BinaryNode::leaf(&refs, bounds));
        }
        let mut p = *self.params;
        p.builder = super::BvhBuilder::Binned;
        p.parallel = false;
        Some(binary::build_refs(self.tris, refs, &p))
    }
}
