//! The spatial half of the SD-tree: a binary tree over a cube around the
//! scene, each node cut in half across x, y and z in turn, with a
//! directional quadtree ([`Quadtree`]) in every leaf.
//!
//! A leaf is cut, after an iteration, while the path vertices it received
//! exceed `c·√n` (the iteration drew `n` samples per pixel; Müller et al.
//! take c = 12 000), each half taking half the count and a copy of the
//! leaf's distribution: where paths go often, the tree learns finer
//! places.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec3;
use sahara_kd::Aabb;

use super::quadtree::{Quadtree, Training};

/// The deepest the spatial tree goes (well within a float's precision of
/// the cube's coordinates).
const MAX_DEPTH: u32 = 48;

/// A node of the spatial tree.
#[derive(Clone, Copy, Debug)]
enum Node {
    /// Cut in half across axis `depth % 3`: the lower and upper halves.
    Inner([u32; 2]),
    /// A leaf: its index among the leaves.
    Leaf(u32),
}

/// A leaf: the distribution paths sample there this iteration (learned
/// in the last), the one it learns for the next, and the path vertices
/// it received.
#[derive(Debug)]
pub(crate) struct Leaf {
    pub(crate) sampling: Quadtree,
    pub(crate) training: Training,
    count: AtomicU64,
}

/// The SD-tree of one iteration.
#[derive(Debug)]
pub(crate) struct SdTree {
    min: Vec3,
    /// The cube's edge.
    size: f32,
    nodes: Vec<Node>,
    leaves: Vec<Leaf>,
}

impl SdTree {
    /// The tree of one leaf over a cube holding `bounds`, with nothing
    /// learned.
    pub(crate) fn new(bounds: Aabb) -> Self {
        let (min, max) = if bounds.min.cmple(bounds.max).all() {
            (bounds.min, bounds.max)
        } else {
            (Vec3::ZERO, Vec3::ONE)
        };
        // A little margin, so that points on the bounds fall inside.
        let size = (max - min).max_element().max(1e-6) * 1.001;
        let centre = (min + max) * 0.5;
        let empty = Quadtree::empty();
        Self {
            min: centre - Vec3::splat(size * 0.5),
            size,
            nodes: vec![Node::Leaf(0)],
            leaves: vec![Leaf {
                training: Training::new(empty.refined(super::RHO)),
                sampling: empty,
                count: AtomicU64::new(0),
            }],
        }
    }

    /// The index of the leaf holding `p` (points outside the cube go to
    /// the leaf nearest).
    #[inline]
    pub(crate) fn leaf_index(&self, p: Vec3) -> u32 {
        let below = 1.0 - f32::EPSILON;
        let mut local = ((p - self.min) / self.size).clamp(Vec3::ZERO, Vec3::splat(below));
        let mut node = 0usize;
        let mut axis = 0usize;
        loop {
            match self.nodes[node] {
                Node::Leaf(l) => return l,
                Node::Inner(children) => {
                    let upper = local[axis] >= 0.5;
                    local[axis] = (local[axis] * 2.0 - upper as u32 as f32).clamp(0.0, below);
                    node = children[upper as usize] as usize;
                    axis = (axis + 1) % 3;
                }
            }
        }
    }

    /// Leaf `l`.
    #[inline]
    pub(crate) fn leaf(&self, l: u32) -> &Leaf {
        &self.leaves[l as usize]
    }

    /// Leaves in the tree.
    #[cfg(test)]
    pub(crate) fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    /// Counts a path vertex in leaf `l`.
    #[inline]
    pub(crate) fn count(&self, l: u32) {
        self.leaves[l as usize]
            .count
            .fetch_add(1, Ordering::Relaxed);
    }

    /// The tree of the next iteration: every leaf's trained distribution
    /// becomes the one sampled, leaves whose vertices exceed `threshold`
    /// are cut (recursively, halving the count), and each leaf's new
    /// training tree takes the shape its distribution asks for
    /// ([`Quadtree::refined`] with `rho`).
    pub(crate) fn next(self, threshold: f64, rho: f32) -> SdTree {
        let mut leaves: Vec<Option<Leaf>> = self.leaves.into_iter().map(Some).collect();
        let mut out = SdTree {
            min: self.min,
            size: self.size,
            nodes: Vec::new(),
            leaves: Vec::new(),
        };
        out.rebuild(&self.nodes, 0, 0, &mut leaves, threshold, rho);
        out
    }

    fn rebuild(
        &mut self,
        old: &[Node],
        node: usize,
        depth: u32,
        leaves: &mut [Option<Leaf>],
        threshold: f64,
        rho: f32,
    ) -> u32 {
        match old[node] {
            Node::Inner(children) => {
                let at = self.nodes.len();
                self.nodes.push(Node::Leaf(0));
                let a = self.rebuild(old, children[0] as usize, depth + 1, leaves, threshold, rho);
                let b = self.rebuild(old, children[1] as usize, depth + 1, leaves, threshold, rho);
                self.nodes[at] = Node::Inner([a, b]);
                at as u32
            }
            Node::Leaf(l) => {
                let leaf = leaves[l as usize]
                    .take()
                    .expect("each leaf is visited once");
                let count = leaf.count.into_inner() as f64;
                let dist = leaf.training.finish();
                self.split(dist, count, depth, threshold, rho)
            }
        }
    }

    fn split(&mut self, dist: Quadtree, count: f64, depth: u32, threshold: f64, rho: f32) -> u32 {
        let at = self.nodes.len();
        if count > threshold && depth < MAX_DEPTH {
            self.nodes.push(Node::Leaf(0));
            let a = self.split(dist.clone(), count / 2.0, depth + 1, threshold, rho);
            let b = self.split(dist, count / 2.0, depth + 1, threshold, rho);
            self.nodes[at] = Node::Inner([a, b]);
        } else {
            self.nodes.push(Node::Leaf(self.leaves.len() as u32));
            self.leaves.push(Leaf {
                training: Training::new(dist.refined(rho)),
                sampling: dist,
                count: AtomicU64::new(0),
            });
        }
        at as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_are_cut_where_vertices_crowd_and_points_find_their_leaf() {
        let bounds = Aabb::new(Vec3::splat(-1.0), Vec3::new(3.0, 1.0, 1.0));
        let tree = SdTree::new(bounds);
        assert_eq!(tree.leaf_count(), 1);
        for _ in 0..1000 {
            tree.count(0);
        }
        let tree = tree.next(300.0, super::super::RHO);
        // 1000 -> 500 -> 250: two levels, four leaves.
        assert_eq!(tree.leaf_count(), 4);
        // The cube's edge is 4: cuts across x at 1, then y at 0.
        let a = tree.leaf_index(Vec3::new(0.0, -0.5, 0.0));
        let b = tree.leaf_index(Vec3::new(0.0, 0.5, 0.0));
        let c = tree.leaf_index(Vec3::new(2.0, -0.5, 0.0));
        let d = tree.leaf_index(Vec3::new(2.0, 0.5, 0.0));
        let mut all = vec![a, b, c, d];
        all.sort();
        assert_eq!(all, vec![0, 1, 2, 3]);
        // Outside the cube: the nearest leaf.
        assert_eq!(tree.leaf_index(Vec3::new(-50.0, -50.0, 0.0)), a);
    }
}
