//! A binary tree collapsed into eight-wide nodes: each wide node takes the
//! binary node's two children and opens, while it has fewer than eight, the
//! inner child of largest surface area into its two, the child a ray is
//! most likely to visit (by the SAH) and so the one whose split is best
//! decided in the same step (as Embree's and tinybvh's collapses do). In a
//! balanced tree that is three binary levels per wide node.

use super::binary::BinaryNode;
use super::BvhParams;
use crate::bvh::node::{leaf_ref, ChildRef, WideNode, ARITY, MAX_LEAF, MAX_LEAF_INDEX};
use crate::bvh::quad::Quad;
use crate::bvh::Bvh;
use crate::math::{Aabb, Triangle};

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
    };
    let Some(root) = root else {
        return out;
    };
    let mut w = Writer {
        tris,
        out: &mut out,
    };
    match root {
        // A tree of one leaf still has a root node: the walks start at one.
        BinaryNode::Leaf { .. } => {
            w.out.nodes.push(WideNode::new(&[(Aabb::EMPTY, 0)]));
            let r = w.child(root);
            w.out.nodes[0] = WideNode::new(&[(root.bounds(), r)]);
        }
        BinaryNode::Inner { .. } => {
            w.node(root);
        }
    }
    out
}

struct Writer<'a> {
    tris: &'a [Triangle],
    out: &'a mut Bvh,
}

impl Writer<'_> {
    /// Write the wide node rooted at the inner binary node `n`, then its
    /// leaves, then its inner children depth first; returns its index.
    fn node(&mut self, n: &BinaryNode) -> u32 {
        let index = self.out.nodes.len();
        self.out.nodes.push(WideNode::new(&[(Aabb::EMPTY, 0)]));
        let mut kids: Vec<&BinaryNode> = match n {
            BinaryNode::Inner { kids, .. } => vec![&kids[0], &kids[1]],
            BinaryNode::Leaf { .. } => unreachable!("a wide node is made from an inner node"),
        };
        while kids.len() < ARITY {
            // The inner child of largest area (the first of equals).
            let open = kids
                .iter()
                .enumerate()
                .filter(|(_, k)| matches!(k, BinaryNode::Inner { .. }))
                .max_by(|a, b| {
                    a.1.bounds()
                        .surface_area()
                        .total_cmp(&b.1.bounds().surface_area())
                        .then(b.0.cmp(&a.0))
                })
                .map(|(i, _)| i);
            let Some(i) = open else { break };
            let BinaryNode::Inner { kids: two, .. } = kids[i] else {
                unreachable!()
            };
            kids[i] = &two[0];
            kids.insert(i + 1, &two[1]);
        }
        // Leaves first, next to the node; then the subtrees.
        let mut refs = vec![0; kids.len()];
        for (r, k) in refs.iter_mut().zip(&kids) {
            if let BinaryNode::Leaf { .. } = k {
                *r = self.child(k);
            }
        }
        for (r, k) in refs.iter_mut().zip(&kids) {
            if let BinaryNode::Inner { .. } = k {
                *r = self.child(k);
            }
        }
        let children: Vec<(Aabb, ChildRef)> = kids.iter().map(|k| k.bounds()).zip(refs).collect();
        self.out.nodes[index] = WideNode::new(&children);
        index as u32
    }

    /// Write a child: a leaf's triangles, or a subtree.
    fn child(&mut self, k: &BinaryNode) -> ChildRef {
        match k {
            BinaryNode::Inner { .. } => self.node(k),
            BinaryNode::Leaf { .. } => {
                let tris = k.leaf_tris();
                assert!(!tris.is_empty() && tris.len() <= MAX_LEAF);
                let index = self.out.quads.len();
                assert!(
                    index as u64 <= MAX_LEAF_INDEX as u64,
                    "too many triangles for one hierarchy"
                );
                let ts: [Triangle; MAX_LEAF] =
                    std::array::from_fn(|i| self.tris[tris[i.min(tris.len() - 1)] as usize]);
                self.out.quads.push(Quad::pack(&ts[..tris.len()], tris));
                self.out.references += tris.len();
                leaf_ref(index as u32, tris.len())
            }
        }
    }
}
