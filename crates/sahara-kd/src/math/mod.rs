//! The geometry everything else stands on: rays, boxes, triangles, indexed
//! triangle meshes, the clipping of a triangle to a box, and the float
//! slack of the distance comparisons. Imports nothing else of the crate.

pub(crate) mod aabb;
pub(crate) mod clip;
pub(crate) mod mesh;
pub(crate) mod ray;
pub(crate) mod slack;
pub(crate) mod triangle;

pub use aabb::Aabb;
pub use mesh::Mesh;
pub use ray::Ray;
pub use triangle::Triangle;
