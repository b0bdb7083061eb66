//! The finished tree: 8-byte nodes and the flat triangle-index array.

use crate::build::BuildParams;
use crate::geometry::{Aabb, Primitive, Triangle};

/// One kd-tree node in 8 bytes (the layout of pbrt-v3's `KdAccelNode`,
/// itself after Havran's thesis).
///
/// The low two bits of `word1` are the split axis (0, 1, 2) or 3 for a leaf.
/// - Inner node: `word0` is the split position (f32 bits); `word1 >> 2` is
///   the index of the child above the plane. The child below the plane is the
///   next node in the array (depth-first order).
/// - Leaf: `word0` is the offset of its first entry in the index array
///   (for a triangle tree: of its first block in the leaf data, whose header
///   holds the index-array offset); `word1 >> 2` is the number of
///   triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Node {
    word0: u32,
    word1: u32,
}

const LEAF: u32 = 3;

/// The largest child index or leaf size a node can encode (30 bits).
pub const MAX_NODE_FIELD: u32 = (1 << 30) - 1;

impl Node {
    /// An inner node splitting `axis` at `pos`, its upper child at `above`.
    #[inline]
    pub fn inner(axis: usize, pos: f32, above: u32) -> Self {
        debug_assert!(axis < 3 && above <= MAX_NODE_FIELD);
        Self {
            word0: pos.to_bits(),
            word1: (above << 2) | axis as u32,
        }
    }

    /// A leaf with `count` triangles starting at `offset` (see [`Node`]).
    #[inline]
    pub fn leaf(offset: u32, count: u32) -> Self {
        debug_assert!(count <= MAX_NODE_FIELD);
        Self {
            word0: offset,
            word1: (count << 2) | LEAF,
        }
    }

    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.word1 & 3 == LEAF
    }

    /// Split axis of an inner node.
    #[inline(always)]
    pub fn axis(&self) -> usize {
        (self.word1 & 3) as usize
    }

    /// Split position of an inner node.
    #[inline(always)]
    pub fn split(&self) -> f32 {
        f32::from_bits(self.word0)
    }

    /// Index of the child above the split plane (inner nodes).
    #[inline(always)]
    pub fn above_child(&self) -> u32 {
        self.word1 >> 2
    }

    /// The children of inner node `index` in the order a ray meets them:
    /// `(near, far)`. A ray moving towards -axis (`neg[axis]`, the
    /// direction's sign bit, so that d = -0 orders like `1/d = -inf`) meets
    /// the cell above the plane first (Wald 2004).
    #[inline(always)]
    pub fn near_far(&self, index: u32, neg: &[bool; 3]) -> (u32, u32) {
        let (below, above) = (index + 1, self.above_child());
        debug_assert!(!self.is_leaf());
        if neg[self.axis()] {
            keep_branch();
            (above, below)
        } else {
            (below, above)
        }
    }

    /// Offset into the index array, or for a non-empty leaf of a triangle
    /// tree into its leaf data (leaves; see [`KdTree::leaf_primitives`]).
    #[inline(always)]
    pub fn leaf_offset(&self) -> u32 {
        self.word0
    }

    /// Triangle count (leaves).
    #[inline(always)]
    pub fn leaf_count(&self) -> u32 {
        self.word1 >> 2
    }

    /// This node with its child pointer or leaf offset moved by `delta`
    /// (used when subtrees built apart are concatenated).
    #[inline]
    pub(crate) fn shifted(self, node_delta: u32, index_delta: u32) -> Self {
        if self.is_leaf() {
            Self {
                word0: self.word0 + index_delta,
                ..self
            }
        } else {
            Self {
                word1: self.word1 + (node_delta << 2),
                ..self
            }
        }
    }
}

/// Keeps the path it is placed on a conditional branch: an empty `asm!`
/// block has side effects for LLVM, so the path cannot become a
/// conditional move.
///
/// Used where a select would put a load on the traversal's critical path
/// (`Node::near_far`): as a `cmov`, the next node's address waits for the
/// node's axis and the ray's sign; as a branch, the predictor guesses it and
/// the next node's load starts at once. Primary rays traced 1.2-1.4x
/// faster and shadow rays 1.2-1.5x (bunny, sponza, teapot_stadium).
#[inline(always)]
fn keep_branch() {
    // SAFETY: an empty instruction sequence, touching no memory or flags.
    #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
    unsafe {
        std::arch::asm!("", options(nomem, nostack, preserves_flags))
    }
}

/// A kd-tree over primitives: triangles by default.
///
/// Build it with [`KdTree::build`]; query a triangle tree with
/// [`KdTree::closest_hit`] and [`KdTree::any_hit`], a [`BoxTree`] with
/// closures (see `traverse`).
#[derive(Clone, Debug)]
pub struct KdTree<P: Primitive = Triangle> {
    pub(crate) nodes: Vec<Node>,
    /// Leaf runs, each starting at a multiple of `P::LEAF_WIDTH` and padded
    /// to one with `u32::MAX`.
    pub(crate) indices: Vec<u32>,
    /// Primitives given to the build (hittable or not).
    pub(crate) prim_count: usize,
    /// Leaf-ordered copies for fast tests (triangles: blocks of eight).
    pub(crate) leaf_data: P::LeafData,
    pub(crate) bounds: Aabb,
    pub(crate) params: BuildParams,
}

impl<P: Primitive> KdTree<P> {
    /// The nodes, root first, in depth-first order.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The leaves' triangle indices, one run per leaf; runs are padded with
    /// `u32::MAX` to a multiple of the primitive's leaf width.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// Number of primitives given to the build (hit indices range over them).
    /// The tree keeps no copy of them beyond its leaf data: a triangle tree
    /// stores each referenced triangle in its leaf blocks, a box tree only
    /// indices.
    pub fn primitive_count(&self) -> usize {
        self.prim_count
    }

    /// The leaf data (for a triangle tree, the leaf blocks in leaf order).
    pub fn leaf_data(&self) -> &P::LeafData {
        &self.leaf_data
    }

    /// The root cell: the bounds of all hittable triangles.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The parameters the tree was built with.
    pub fn params(&self) -> &BuildParams {
        &self.params
    }

    /// The primitive indices of leaf `node`.
    #[inline(always)]
    pub fn leaf_primitives(&self, node: &Node) -> &[u32] {
        let c = node.leaf_count() as usize;
        if c == 0 {
            return &[];
        }
        let o = P::leaf_run(&self.leaf_data, node.leaf_offset());
        &self.indices[o..o + c]
    }

    /// Visit every node with its cell and depth (root depth 0), depth first.
    pub fn visit(&self, mut f: impl FnMut(u32, &Node, &Aabb, u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0u32, self.bounds, 0u32)];
        while let Some((i, cell, depth)) = stack.pop() {
            let n = &self.nodes[i as usize];
            f(i, n, &cell, depth);
            if !n.is_leaf() {
                let (lo, hi) = cell.split(n.axis(), n.split());
                stack.push((n.above_child(), hi, depth + 1));
                stack.push((i + 1, lo, depth + 1));
            }
        }
    }
}

/// A kd-tree over boxes (e.g. a scene's object instances), queried with
/// closures that intersect the objects themselves.
pub type BoxTree = KdTree<Aabb>;

impl KdTree<Triangle> {
    /// The triangle indices of leaf `node`.
    #[inline(always)]
    pub fn leaf_triangles(&self, node: &Node) -> &[u32] {
        self.leaf_primitives(node)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_eight_bytes_and_round_trips() {
        assert_eq!(std::mem::size_of::<Node>(), 8);
        let n = Node::inner(2, -1.5, 12345);
        assert!(!n.is_leaf());
        assert_eq!((n.axis(), n.split(), n.above_child()), (2, -1.5, 12345));
        let l = Node::leaf(77, MAX_NODE_FIELD);
        assert!(l.is_leaf());
        assert_eq!((l.leaf_offset(), l.leaf_count()), (77, MAX_NODE_FIELD));
        assert_eq!(n.shifted(5, 9).above_child(), 12350);
        assert_eq!(l.shifted(5, 9).leaf_offset(), 86);
    }
}
