//! Geometric primitives: rays, axis-aligned boxes, triangles and clipping.

pub mod aabb;
pub mod clip;
pub mod frustum;
pub mod indexed_block;
pub mod leaf_layout;
pub mod primitive;
pub mod ray;
pub mod triangle;
pub mod triangle_block;
pub mod triangle_packet;

pub use aabb::Aabb;
pub use indexed_block::{IndexedBlock, IndexedBlocks};
pub use leaf_layout::TriangleLeaves;
pub use primitive::Primitive;
pub use ray::Ray;
pub use triangle::{Triangle, TriangleHit};
pub use triangle_block::TriangleBlock;
