//! Tree construction: one entry point, [`KdTree::build`], and one module per
//! algorithm.

pub mod binned;
pub mod budget;
pub mod cost;
pub mod naive;
pub mod params;
pub mod partition;
pub mod sah_sweep;
pub mod subtree;

pub use params::{AxisRule, BuildParams, Builder, PositionRule};

use crate::geometry::{Aabb, Primitive};
use crate::tree::{KdTree, Node};

impl<P: Primitive> KdTree<P> {
    /// Build a tree over `triangles` (their indices are the ones hits report).
    ///
    /// Primitives no ray can hit (for triangles: a non-finite coordinate or
    /// zero area, see [`crate::Triangle::is_hittable`]) are left out.
    pub fn build(triangles: Vec<P>, params: &BuildParams) -> KdTree<P> {
        let live: Vec<u32> = (0..triangles.len() as u32)
            .filter(|&i| triangles[i as usize].is_hittable())
            .collect();
        let bounds = live
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(triangles[i as usize].bounds()));
        let sub = if live.is_empty() {
            subtree::Subtree::leaf(Vec::new(), &bounds, params)
        } else {
            match params.builder {
                Builder::Sah => sah_sweep::build(&triangles, live, bounds, params),
                Builder::Binned { bins } => {
                    binned::build(&triangles, live, bounds, bins as usize, params)
                }
                Builder::Naive { axis, position } => {
                    naive::build(&triangles, live, bounds, axis, position, params)
                }
            }
        };
        let (mut nodes, indices) = pad_leaf_runs(sub.nodes, &sub.indices, P::LEAF_WIDTH);
        let leaf_data = P::leaf_data(&triangles, &indices, &mut nodes, params);
        KdTree {
            nodes,
            indices,
            prim_count: triangles.len(),
            leaf_data,
            bounds,
            params: *params,
        }
    }
}

/// Moves every leaf's index run to a multiple of `width` and pads it to one
/// with `u32::MAX`, so that run `k` of a triangle leaf is block `k / width`.
fn pad_leaf_runs(mut nodes: Vec<Node>, indices: &[u32], width: usize) -> (Vec<Node>, Vec<u32>) {
    let mut padded = Vec::with_capacity(indices.len() + indices.len() / 2);
    for n in nodes.iter_mut().filter(|n| n.is_leaf()) {
        let (o, c) = (n.leaf_offset() as usize, n.leaf_count() as usize);
        let at = padded.len() as u32;
        padded.extend_from_slice(&indices[o..o + c]);
        padded.resize(padded.len().next_multiple_of(width), u32::MAX);
        *n = Node::leaf(at, c as u32);
    }
    (nodes, padded)
}
