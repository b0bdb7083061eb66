//! `sahara-kd`: Sahara's accelerator.
//!
//! Kd-trees over triangle soups, built by the surface area heuristic (an
//! exact O(N log N) event sweep with split clipping, or binned) or by the
//! naive baselines; front-to-back traversal with early exit for closest-hit
//! and any-hit queries, single rays or packets of eight, over leaves whose
//! triangles sit in 8-wide blocks; tree statistics; and the brute-force
//! oracle the tests hold the tree to. No I/O, no rendering.
//!
//! ```
//! use glam::Vec3;
//! use sahara_kd::{BuildParams, KdTree, Ray, Triangle};
//!
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 5.0), Vec3::new(1.0, -1.0, 5.0), Vec3::new(0.0, 1.0, 5.0))];
//! let tree = KdTree::build(tris, &BuildParams::default());
//! let hit = tree.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z)).unwrap();
//! assert_eq!((hit.t, hit.tri), (5.0, 0));
//! ```

pub mod brute;
pub mod build;
pub mod geometry;
pub mod packet;
pub mod stats;
#[cfg(test)]
mod test_support;
pub mod traverse;
pub mod tree;
pub mod validate;

pub use build::{AxisRule, BuildParams, Builder, PositionRule};
pub use geometry::{Aabb, Primitive, Ray, Triangle, TriangleBlock, TriangleHit};
pub use stats::TreeStats;
pub use traverse::{Counters, Hit, NoCounters, TraversalCounters};
pub use tree::{BoxTree, KdTree, Node};
