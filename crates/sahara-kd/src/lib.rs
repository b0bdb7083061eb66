//! `sahara-kd`: Sahara's accelerator.
//!
//! Two structures over triangle soups, both built by the surface area
//! heuristic: kd-trees (an exact O(N log N) event sweep with split
//! clipping, binned, or the naive baselines), and eight-wide bounding volume
//! hierarchies (binned, with spatial splits, or collapsed from the
//! kd-tree). Closest-hit and any-hit queries for single rays, 8- and 16-ray
//! packets and parallel batches; [`TriangleAccel`] holds either structure
//! behind one set of queries. Statistics; a structural validator; and the
//! brute-force oracle both structures are held to, bit for bit. No I/O, no
//! rendering.
//!
//! ```
//! use glam::Vec3;
//! use sahara_kd::{AccelParams, BuildParams, KdTree, Ray, Triangle, TriangleAccel};
//!
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 5.0), Vec3::new(1.0, -1.0, 5.0), Vec3::new(0.0, 1.0, 5.0))];
//! let ray = Ray::new(Vec3::ZERO, Vec3::Z);
//! let tree = KdTree::build(tris.clone(), &BuildParams::default());
//! let hit = tree.closest_hit(&ray).unwrap();
//! assert_eq!((hit.t, hit.tri), (5.0, 0));
//! // The eight-wide hierarchy (the default structure), same answer.
//! let accel = TriangleAccel::build(tris, &AccelParams::default());
//! assert_eq!(accel.closest_hit(&ray), Some(hit));
//! ```
//!
//! The crate's parts, each importing only those before it in this list:
//! `math` (rays, boxes, triangles, indexed meshes, clipping, float slack) and `simd`
//! (instruction-set levels and dispatch); `isect` (the watertight test and
//! hit records); `leaf` (leaf storage and the leaf tests) and `build` (the
//! builders); `kd` (the tree, its node, walks, queries, batches and
//! packets); `bvh` (the hierarchy: its node, leaves of four, builds, walks,
//! packets); `accel` (either structure); then `stats`, `validate` and
//! `brute`. See `docs/accelerator.md` for the design.

#![deny(missing_docs)]

mod accel;
pub mod brute;
mod build;
mod bvh;
mod isect;
mod kd;
mod leaf;
mod math;
mod simd;
mod stats;
#[cfg(test)]
mod test_support;
mod validate;

pub use accel::{AccelKind, AccelParams, AccelSummary, TriangleAccel};
pub use build::{AxisRule, BuildParams, Builder, PositionRule, Primitive, MAX_DEPTH};
pub use bvh::{Bvh, BvhBuilder, BvhParams, BvhStats, MAX_LEAF as BVH_MAX_LEAF};
pub use isect::{intersect_ray_triangle, Hit, TriangleHit};
pub use kd::{
    BoxTree, Counters, KdTree, LeafStorage, NoCounters, Node, TraversalCounters, PACKET, PACKET16,
};
pub use leaf::{TriangleBlock, TriangleLeaves};
pub use math::slack::gamma;
pub use math::{Aabb, Mesh, Ray, Triangle};
pub use simd::Isa;
pub use stats::TreeStats;
pub use validate::validate;

/// The README's library example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeExample;

/// Internals for the repository's benchmarks and fuzz targets: the leaf
/// tests and packet forms on their own. Not part of the API; may change
/// without notice.
#[doc(hidden)]
pub mod internals {
    pub use crate::isect::RayShear;
    pub use crate::kd::BatchWalk;
    pub use crate::leaf::{Frustum, IndexedBlocks, PacketShear, BLOCK_WIDTH};
}
