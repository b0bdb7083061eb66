//! Statistics of a finished tree, including its true SAH cost.

use crate::kd::KdTree;
use crate::kd::LeafStorage;

/// Shape, size and cost of a tree.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TreeStats {
    /// Triangles given to the build.
    pub triangles: usize,
    /// All nodes.
    pub nodes: usize,
    /// Inner nodes.
    pub inner: usize,
    /// Leaves, empty ones included.
    pub leaves: usize,
    /// Leaves with no triangle.
    pub empty_leaves: usize,
    /// Depth of the deepest leaf (the root has depth 0).
    pub max_depth: u32,
    /// Mean depth over all leaves.
    pub mean_leaf_depth: f64,
    /// Mean triangle count over non-empty leaves.
    pub mean_leaf_triangles: f64,
    /// Largest leaf.
    pub max_leaf_triangles: usize,
    /// Triangle references stored in leaves.
    pub references: usize,
    /// References per referenced triangle (1 = no duplication).
    pub duplication: f64,
    /// Bytes of nodes + wide nodes + index array + leaf data (a triangle
    /// tree's leaf blocks hold its triangles; it keeps no other copy).
    pub memory_bytes: usize,
    /// Bytes of the wide nodes derived for the batch walks (included in
    /// `memory_bytes`; 0 without them).
    pub wide_node_bytes: usize,
    /// The tree's SAH cost with its build's K_T, K_I and leaf width W:
    /// `sum_inner SA/SA_root K_T + sum_leaves SA/SA_root K_I ceil(n / W)`.
    pub sah_cost: f64,
    /// What the SAH predicts a ray meeting the root visits (no early exit):
    /// inner nodes `sum_inner SA/SA_root`.
    pub expected_inner: f64,
    /// Leaves: `sum_leaves SA/SA_root`.
    pub expected_leaves: f64,
    /// Triangle tests: `sum_leaves SA/SA_root n`.
    pub expected_triangles: f64,
    /// Leaf tests as the SAH counts them: `sum_leaves SA/SA_root ceil(n / W)`.
    pub expected_leaf_tests: f64,
}

impl<P: LeafStorage> KdTree<P> {
    /// Compute the statistics (one pass over the nodes).
    pub fn stats(&self) -> TreeStats {
        let mut s = TreeStats {
            triangles: self.prim_count,
            ..Default::default()
        };
        let root_area = self.bounds.surface_area();
        let inv_root = if root_area > 0.0 {
            1.0 / root_area
        } else {
            0.0
        };
        let (k_t, k_i) = (
            self.params.traversal_cost as f64,
            self.params.intersection_cost as f64,
        );
        let mut depth_sum = 0u64;
        let mut referenced = vec![false; self.prim_count];
        self.visit(|_, n, cell, depth| {
            s.nodes += 1;
            let p = cell.surface_area() * inv_root;
            if n.is_leaf() {
                let c = n.leaf_count() as usize;
                s.leaves += 1;
                s.empty_leaves += (c == 0) as usize;
                s.max_depth = s.max_depth.max(depth);
                s.max_leaf_triangles = s.max_leaf_triangles.max(c);
                depth_sum += depth as u64;
                s.references += c;
                s.expected_leaves += p;
                s.expected_triangles += p * c as f64;
                s.expected_leaf_tests += p * self.params.leaf_tests(c);
                for &t in self.leaf_primitives(n) {
                    referenced[t as usize] = true;
                }
            } else {
                s.inner += 1;
            }
        });
        if root_area == 0.0 {
            // A degenerate root (a point or a segment): one leaf, visited by
            // every ray that reaches it.
            s.expected_leaves = 1.0;
            s.expected_triangles = s.references as f64;
            s.expected_leaf_tests = self.params.leaf_tests(s.references);
        }
        // Summed at the build, in this visit's order.
        s.expected_inner = self.expected_inner;
        s.sah_cost = s.expected_inner * k_t + s.expected_leaf_tests * k_i;
        s.mean_leaf_depth = depth_sum as f64 / s.leaves.max(1) as f64;
        let non_empty = s.leaves - s.empty_leaves;
        s.mean_leaf_triangles = s.references as f64 / non_empty.max(1) as f64;
        let distinct = referenced.iter().filter(|&&r| r).count();
        s.duplication = s.references as f64 / distinct.max(1) as f64;
        s.wide_node_bytes = std::mem::size_of_val(self.wide.as_slice());
        s.memory_bytes = std::mem::size_of_val(self.nodes.as_slice())
            + s.wide_node_bytes
            + std::mem::size_of_val(self.indices.as_slice())
            + P::leaf_data_bytes(&self.leaf_data);
        s
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use crate::build::{BuildParams, Builder};
    use crate::kd::KdTree;
    use crate::math::Triangle;

    /// A single leaf of ten triangles costs K_I per block of W: two blocks
    /// at W = 8, ten tests at W = 1.
    #[test]
    fn a_leaf_costs_k_i_per_block_of_the_leaf_width() {
        let tris: Vec<Triangle> = (0..10)
            .map(|i| {
                let z = i as f32;
                Triangle::new(
                    Vec3::new(0.0, 0.0, z),
                    Vec3::new(1.0, 0.0, z),
                    Vec3::new(0.0, 1.0, z),
                )
            })
            .collect();
        for (width, tests) in [(8, 2.0), (1, 10.0), (4, 3.0)] {
            let mut p = BuildParams::new(Builder::Sah);
            p.max_leaf_size = 10; // one leaf, no split evaluated
            p.leaf_width = width;
            let s = KdTree::build(tris.clone(), &p).stats();
            assert_eq!((s.leaves, s.references), (1, 10));
            assert_eq!(s.expected_triangles, 10.0);
            assert_eq!(s.expected_leaf_tests, tests);
            assert_eq!(s.sah_cost, tests * p.intersection_cost as f64);
        }
    }
}
