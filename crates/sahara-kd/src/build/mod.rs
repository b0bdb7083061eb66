//! Tree construction: the surface area heuristic's exact sweep and binned
//! builds, the naive baselines, and their shared parts. The result is a
//! depth-first list of [`BuiltNode`]s and an index array, which the
//! kd-tree flattens into its 8-byte nodes.

pub(crate) mod binned;
pub(crate) mod budget;
pub(crate) mod cost;
pub(crate) mod naive;
pub(crate) mod params;
pub(crate) mod partition;
mod primitive;
pub(crate) mod sah_sweep;
pub(crate) mod subtree;

pub use params::{AxisRule, BuildParams, Builder, PositionRule, MAX_DEPTH};
pub use primitive::Primitive;
pub use subtree::BuiltNode;

use crate::math::Aabb;
use subtree::Subtree;

/// The tree over the hittable ones of `prims` (primitives no ray can hit
/// are left out): its nodes, its index array and its root cell.
pub(crate) fn build<P: Primitive>(prims: &[P], params: &BuildParams) -> (Subtree, Aabb) {
    let live: Vec<u32> = (0..prims.len() as u32)
        .filter(|&i| prims[i as usize].is_hittable())
        .collect();
    let bounds = live
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(prims[i as usize].bounds()));
    let sub = if live.is_empty() {
        Subtree::leaf(Vec::new(), &bounds, params)
    } else {
        match params.builder {
            Builder::Sah => sah_sweep::build(prims, live, bounds, params),
            Builder::Binned { bins } => binned::build(prims, live, bounds, bins as usize, params),
            Builder::Naive { axis, position } => {
                naive::build(prims, live, bounds, axis, position, params)
            }
        }
    };
    (sub, bounds)
}
