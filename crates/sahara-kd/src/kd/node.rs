//! The 8-byte node: the reference layout every builder's output is
//! flattened into and every walk reads.

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
    /// tree into its leaf data (leaves; see [`crate::KdTree::leaf_primitives`]).
    #[inline(always)]
    pub fn leaf_offset(&self) -> u32 {
        self.word0
    }

    /// Triangle count (leaves).
    #[inline(always)]
    pub fn leaf_count(&self) -> u32 {
        self.word1 >> 2
    }
}

/// Keeps the path it is placed on a conditional branch: an empty `asm!`
/// block has side effects for LLVM, so the path cannot become a
/// conditional move.
///
/// Used where a select would put a load on the traversal's critical path
/// (`Node::near_far`): as a `cmov`, the next node's address waits for the
/// node's axis and the ray's sign; as a branch, the predictor guesses it and
/// the next node's load starts at once (figures in `docs/performance.md`).
#[inline(always)]
fn keep_branch() {
    // SAFETY: an empty instruction sequence, touching no memory or flags.
    #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
    unsafe {
        std::arch::asm!("", options(nomem, nostack, preserves_flags))
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
    }
}
