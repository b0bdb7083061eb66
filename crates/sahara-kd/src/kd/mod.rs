//! The kd-tree: its 8-byte nodes, the flattening of a build into them, the
//! single-ray walk and its queries, batches and packets.

pub(crate) mod batch;
mod box_query;
mod counters;
mod flatten;
mod interval;
mod leaves;
mod node;
pub(crate) mod packet;
mod query;
mod walk;
mod wide;

pub use batch::BatchWalk;
pub use counters::{Counters, NoCounters, TraversalCounters};
pub use leaves::LeafStorage;
pub use node::Node;
pub use packet::{PACKET, PACKET16};

use crate::build::BuildParams;
use crate::math::{Aabb, Triangle};

/// A kd-tree over primitives: triangles by default.
///
/// Build it with [`KdTree::build`]; query a triangle tree with
/// [`KdTree::closest_hit`] and [`KdTree::any_hit`], a [`BoxTree`] with
/// closures (see `traverse`).
#[derive(Clone, Debug)]
pub struct KdTree<P: LeafStorage = Triangle> {
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
    /// The wide nodes derived from `nodes` for batch walks (empty when
    /// not derived; see `wide`).
    pub(crate) wide: Vec<wide::WideNode>,
    /// The SAH expects a ray meeting the root to visit this many inner
    /// nodes (see [`crate::TreeStats::expected_inner`]); batches on
    /// shallower trees take the binary walk.
    pub(crate) expected_inner: f64,
    /// Leaf offsets in `wide`'s leaf words are shifted down by this.
    pub(crate) wide_shift: u32,
    /// The highest dispatch level of its queries ([`crate::Isa`]).
    pub(crate) max_level: u8,
}

impl<P: LeafStorage> KdTree<P> {
    /// Hold its queries to the instructions of `isa` at most (the default
    /// is the best the CPU has; see [`crate::Isa`] for why a caller would
    /// lower it). Answers do not change.
    pub fn set_isa(&mut self, isa: crate::Isa) {
        self.max_level = isa.level();
    }

    /// The widest instructions its queries may use.
    pub fn isa(&self) -> crate::Isa {
        crate::Isa::of_level(self.max_level)
    }

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
