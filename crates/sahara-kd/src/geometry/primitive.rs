//! What a kd-tree can be built over.

use super::clip::clipped_bounds;
use super::indexed_block::IndexedBlocks;
use super::leaf_layout::TriangleLeaves;
use super::triangle_block::{run_triangles, TriangleBlock, BLOCK_WIDTH};
use super::{Aabb, Triangle};
use crate::build::BuildParams;
use crate::tree::Node;

/// A primitive a kd-tree can hold: it has bounds, and bounds of its part
/// inside a cell (for split clipping).
pub trait Primitive: Send + Sync + Sized {
    /// Bounds of the whole primitive.
    fn bounds(&self) -> Aabb;
    /// Bounds of the primitive clipped to `cell`, `None` if they do not meet.
    fn clipped_bounds(&self, cell: &Aabb) -> Option<Aabb>;
    /// False for primitives no ray can hit; the tree leaves them out.
    fn is_hittable(&self) -> bool;

    /// What a tree keeps beside its primitives for fast leaf tests.
    type LeafData: Clone + std::fmt::Debug + Default + Send + Sync;
    /// Leaf index runs start at and are padded to a multiple of this.
    const LEAF_WIDTH: usize;
    /// The leaf data for a padded index array (`u32::MAX` marks padding);
    /// it may re-point the non-empty leaves of `nodes` (whose offsets are
    /// into that array) at itself.
    fn leaf_data(
        prims: &[Self],
        padded_indices: &[u32],
        nodes: &mut [Node],
        params: &BuildParams,
    ) -> Self::LeafData;
    /// The index-array offset of the non-empty leaf whose offset field is
    /// `offset`.
    fn leaf_run(data: &Self::LeafData, offset: u32) -> usize;
    /// Heap bytes of the leaf data.
    fn leaf_data_bytes(data: &Self::LeafData) -> usize;
}

impl Primitive for Triangle {
    fn bounds(&self) -> Aabb {
        Triangle::bounds(self)
    }
    fn clipped_bounds(&self, cell: &Aabb) -> Option<Aabb> {
        clipped_bounds(self, cell)
    }
    fn is_hittable(&self) -> bool {
        Triangle::is_hittable(self)
    }

    /// Copies of the leaves' triangles in leaf order, eight to a block,
    /// whole or (`BuildParams::compact_leaves`) with each block's distinct
    /// vertices once; then a leaf's offset is the word offset of its first
    /// block.
    type LeafData = TriangleLeaves;
    const LEAF_WIDTH: usize = BLOCK_WIDTH;
    fn leaf_data(
        prims: &[Self],
        padded_indices: &[u32],
        nodes: &mut [Node],
        params: &BuildParams,
    ) -> TriangleLeaves {
        if !params.compact_leaves {
            return TriangleLeaves::Whole(
                padded_indices
                    .chunks(BLOCK_WIDTH)
                    .map(|run| TriangleBlock::pack(&run_triangles(prims, run)))
                    .collect(),
            );
        }
        let (blocks, starts) = IndexedBlocks::pack(prims, padded_indices);
        for n in nodes
            .iter_mut()
            .filter(|n| n.is_leaf() && n.leaf_count() != 0)
        {
            let run = n.leaf_offset() as usize / BLOCK_WIDTH;
            *n = Node::leaf(starts[run], n.leaf_count());
        }
        TriangleLeaves::Indexed(blocks)
    }
    fn leaf_run(data: &TriangleLeaves, offset: u32) -> usize {
        data.leaf_run(offset).expect("a leaf offset names a block")
    }
    fn leaf_data_bytes(data: &TriangleLeaves) -> usize {
        data.bytes()
    }
}

/// Boxes, for trees over objects (e.g. the instances of a scene): a box
/// clipped to a cell is their intersection.
impl Primitive for Aabb {
    fn bounds(&self) -> Aabb {
        *self
    }
    fn clipped_bounds(&self, cell: &Aabb) -> Option<Aabb> {
        let b = self.intersection(*cell);
        (!b.is_empty()).then_some(b)
    }
    fn is_hittable(&self) -> bool {
        !self.is_empty() && self.min.is_finite() && self.max.is_finite()
    }

    /// Box trees hand indices to the caller's closures: nothing extra.
    type LeafData = ();
    const LEAF_WIDTH: usize = 1;
    fn leaf_data(_: &[Self], _: &[u32], _: &mut [Node], _: &BuildParams) {}
    fn leaf_run(_: &(), offset: u32) -> usize {
        offset as usize
    }
    fn leaf_data_bytes(_: &()) -> usize {
        0
    }
}
