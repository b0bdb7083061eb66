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
use crate::tree::KdTree;

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
        KdTree {
            nodes: sub.nodes,
            indices: sub.indices,
            prims: triangles,
            bounds,
            params: *params,
        }
    }
}
