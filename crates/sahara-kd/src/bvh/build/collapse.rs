//! A binary tree collapsed into eight-wide nodes: each wide node takes the
//! binary node's two children and opens, while it has fewer than eight, the
//! inner child of largest surface area into its two, the child a ray is
//! most likely to visit (by the SAH) and so the one whose split is best
//! decided in the same step (as Embree's and tinybvh's collapses do). In a
//! balanced tree that is three binary levels per wide node.
//!
//! Every inner binary node knows how many wide nodes and leaves the
//! hierarchy under it takes (counted as the binary tree is built), so each
//! subtree's place in the two arrays is known before it is written, and
//! subtrees are written on all threads.

use rayon::prelude::*;

use super::binary::BinaryNode;
use super::BvhParams;
use crate::bvh::node::{leaf_ref, ChildRef, WideNode, ARITY, MAX_LEAF, MAX_LEAF_INDEX};
use crate::bvh::quad::{Quad, QUAD};
use crate::bvh::Bvh;
use crate::math::{Aabb, Triangle};

/// Subtrees of at least this many wide nodes are written on their own
/// rayon task.
const PARALLEL_NODES: u32 = 64;

/// The hierarchy's nodes and leaves from the binary tree `root` (`None`: no
/// triangle). Bounds, scale and parameters are the caller's.
pub(crate) fn collapse(root: Option<&BinaryNode>, tris: &[Triangle], params: &BvhParams) -> Bvh {
    let mut out = Bvh {
        nodes: Vec::new(),
        quads: Vec::new(),
        prim_count: 0,
        bounds: Aabb::EMPTY,
        scale: 0.0,
        params: *params,
        references: 0,
        max_level: crate::simd::level::AVX512,
    };
    let Some(root) = root else {
        return out;
    };
    let w = Writer {
        tris,
        parallel: params.parallel,
    };
    match root {
        // A tree of one leaf still has a root node: the walks start at one.
        BinaryNode::Leaf { .. } => {
            let mut quad = [empty_quad()];
            out.references = w.leaf(root, &mut quad[0]);
            out.quads = quad.to_vec();
            out.nodes = vec![WideNode::new(&[(
                root.bounds(),
                leaf_ref(0, root.leaf_tris().len()),
            )])];
        }
        BinaryNode::Inner { wide, .. } => {
            let (n, q) = (wide.nodes as usize, wide.leaves as usize);
            assert!(
                q as u64 <= MAX_LEAF_INDEX as u64 + 1,
                "too many triangles for one hierarchy"
            );
            let blank = WideNode::new(&[(Aabb::EMPTY, 0)]);
            out.nodes = filled(n, blank);
            out.quads = filled(q, empty_quad());
            out.references = w.node(root, &mut out.nodes, &mut out.quads, 0, 0);
        }
    }
    out
}

/// `n` copies of `x`, written on all threads (the pages are touched where
/// they will be written again).
fn filled<T: Copy + Send + Sync>(n: usize, x: T) -> Vec<T> {
    if n >= 1 << 14 {
        (0..n).into_par_iter().map(|_| x).collect()
    } else {
        vec![x; n]
    }
}

fn empty_quad() -> Quad {
    Quad {
        v: [[[0.0; QUAD]; 3]; 3],
        tri: [u32::MAX; QUAD],
    }
}

/// How many wide nodes and leaves the hierarchy under an inner binary node
/// takes.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideCount {
    pub(crate) nodes: u32,
    pub(crate) leaves: u32,
}

/// The children of the wide node made from the inner binary node `n`, in
/// order, and their number.
fn open(n: &BinaryNode) -> ([&BinaryNode; ARITY], usize) {
    let BinaryNode::Inner { kids: two, .. } = n else {
        unreachable!("a wide node is made from an inner node")
    };
    let mut kids = [&two[0]; ARITY];
    kids[1] = &two[1];
    // The area of each inner child (-1 for a leaf: never opened).
    let area = |k: &BinaryNode| match k {
        BinaryNode::Inner { bounds, .. } => bounds.surface_area(),
        BinaryNode::Leaf { .. } => -1.0,
    };
    let mut areas = [-1.0f64; ARITY];
    areas[0] = area(kids[0]);
    areas[1] = area(kids[1]);
    let mut len = 2;
    while len < ARITY {
        // The inner child of largest area (the first of equals).
        let mut open: Option<(usize, f64)> = None;
        for (i, &a) in areas[..len].iter().enumerate() {
            if a >= 0.0 && open.is_none_or(|(_, b)| a > b) {
                open = Some((i, a));
            }
        }
        let Some((i, _)) = open else { break };
        let BinaryNode::Inner { kids: two, .. } = kids[i] else {
            unreachable!()
        };
        kids.copy_within(i + 1..len, i + 2);
        areas.copy_within(i + 1..len, i + 2);
        kids[i] = &two[0];
        kids[i + 1] = &two[1];
        areas[i] = area(kids[i]);
        areas[i + 1] = area(kids[i + 1]);
        len += 1;
    }
    (kids, len)
}

/// The count of the inner binary node `n`, from its descendants' counts.
pub(crate) fn count(n: &BinaryNode) -> WideCount {
    let (kids, len) = open(n);
    let mut c = WideCount {
        nodes: 1,
        leaves: 0,
    };
    for k in &kids[..len] {
        match k {
            BinaryNode::Leaf { .. } => c.leaves += 1,
            BinaryNode::Inner { wide, .. } => {
                c.nodes += wide.nodes;
                c.leaves += wide.leaves;
            }
        }
    }
    c
}

struct Writer<'a> {
    tris: &'a [Triangle],
    parallel: bool,
}

impl Writer<'_> {
    /// Write the wide node rooted at the inner binary node `n` to
    /// `nodes[0]` (index `node_base` in the hierarchy), its leaves to the
    /// start of `quads` (index `quad_base`), then its inner children's
    /// subtrees in order; returns the triangle references written.
    fn node(
        &self,
        n: &BinaryNode,
        nodes: &mut [WideNode],
        quads: &mut [Quad],
        node_base: u32,
        quad_base: u32,
    ) -> usize {
        let (kids, len) = open(n);
        let kids = &kids[..len];
        let mut children = [(Aabb::EMPTY, 0 as ChildRef); ARITY];
        let mut references = 0;
        // Leaves first, next to the node; then the subtrees.
        let mut q = 0;
        for (c, k) in children.iter_mut().zip(kids) {
            if let BinaryNode::Leaf { .. } = k {
                references += self.leaf(k, &mut quads[q]);
                *c = (
                    k.bounds(),
                    leaf_ref(quad_base + q as u32, k.leaf_tris().len()),
                );
                q += 1;
            }
        }
        let (this, mut rest_nodes) = nodes.split_first_mut().expect("room for the node");
        let mut rest_quads = &mut quads[q..];
        let (mut nb, mut qb) = (node_base + 1, quad_base + q as u32);
        let mut jobs = Vec::with_capacity(ARITY);
        let mut big = false;
        for (c, k) in children.iter_mut().zip(kids) {
            if let BinaryNode::Inner { wide, .. } = k {
                *c = (k.bounds(), nb);
                let (a, b) = std::mem::take(&mut rest_nodes).split_at_mut(wide.nodes as usize);
                let (x, y) = std::mem::take(&mut rest_quads).split_at_mut(wide.leaves as usize);
                jobs.push((*k, a, x, nb, qb));
                (rest_nodes, rest_quads) = (b, y);
                nb += wide.nodes;
                qb += wide.leaves;
                big |= wide.nodes >= PARALLEL_NODES;
            }
        }
        debug_assert!(rest_nodes.is_empty() && rest_quads.is_empty());
        *this = WideNode::new(&children[..len]);
        let write = |(k, a, x, nb, qb): (&BinaryNode, &mut [WideNode], &mut [Quad], u32, u32)| {
            self.node(k, a, x, nb, qb)
        };
        references
            + if self.parallel && big && jobs.len() > 1 {
                jobs.into_par_iter().map(write).sum::<usize>()
            } else {
                jobs.into_iter().map(write).sum::<usize>()
            }
    }

    /// Pack a leaf's triangles into `quad`; returns their number.
    fn leaf(&self, k: &BinaryNode, quad: &mut Quad) -> usize {
        let tris = k.leaf_tris();
        assert!(!tris.is_empty() && tris.len() <= MAX_LEAF);
        let ts: [Triangle; MAX_LEAF] =
            std::array::from_fn(|i| self.tris[tris[i.min(tris.len() - 1)] as usize]);
        *quad = Quad::pack(&ts[..tris.len()], tris);
        tris.len()
    }
}
