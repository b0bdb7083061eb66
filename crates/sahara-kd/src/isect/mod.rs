//! Ray/triangle intersection: the watertight reference test, the hit
//! records, and the tie rule every query and the oracle share.

mod hit;
mod watertight;

pub(crate) use hit::keep_closer;
pub use hit::{Hit, TriangleHit};
pub(crate) use watertight::permutation;
pub use watertight::{intersect_ray_triangle, RayShear, TrianglePlane};
