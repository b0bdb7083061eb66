//! How a tree stores the leaves of each primitive type beside its nodes.

use super::Node;
use crate::build::{BuildParams, Primitive};
use crate::leaf::{run_triangles, IndexedBlocks, TriangleBlock, TriangleLeaves, BLOCK_WIDTH};
use crate::math::{Aabb, Triangle};

/// A primitive type a [`crate::KdTree`] can hold, and what the tree keeps
/// beside its nodes for fast leaf tests. Implemented for [`Triangle`]
/// (leaf blocks of eight) and [`Aabb`] (indices only).
pub trait LeafStorage: Primitive {
    /// What a tree keeps beside its nodes for fast leaf tests.
    type LeafData: Clone + std::fmt::Debug + Default + Send + Sync;
    /// Leaf index runs start at and are padded to a multiple of this.
    const LEAF_WIDTH: usize;
    /// Whether the tree derives wide nodes for its walks (when
    /// [`BuildParams::wide_nodes`] asks for them).
    const WIDE_NODES: bool;
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

impl LeafStorage for Triangle {
    /// Copies of the leaves' triangles in leaf order, eight to a block,
    /// whole or (`BuildParams::compact_leaves`) with each block's distinct
    /// vertices once; then a leaf's offset is the word offset of its first
    /// block.
    type LeafData = TriangleLeaves;
    const LEAF_WIDTH: usize = BLOCK_WIDTH;
    const WIDE_NODES: bool = true;
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

/// Box trees hand indices to the caller's closures: nothing extra.
impl LeafStorage for Aabb {
    type LeafData = ();
    const LEAF_WIDTH: usize = 1;
    /// The top levels of a scene walk their boxes with the caller's
    /// closures, outside the instruction-set dispatch: binary nodes.
    const WIDE_NODES: bool = false;
    fn leaf_data(_: &[Self], _: &[u32], _: &mut [Node], _: &BuildParams) {}
    fn leaf_run(_: &(), offset: u32) -> usize {
        offset as usize
    }
    fn leaf_data_bytes(_: &()) -> usize {
        0
    }
}
