//! Leaf storage: a triangle tree's leaves as blocks of eight triangles,
//! whole or compact, and the leaf tests over them — one ray against a
//! block, a packet against a triangle, and a packet's frustum against a
//! block.

pub(crate) mod compact;
pub(crate) mod edges;
pub(crate) mod frustum;
pub(crate) mod layout;
pub(crate) mod packet_shear;
pub(crate) mod ray_block;
pub(crate) mod whole;

pub use compact::{IndexedBlock, IndexedBlocks};
pub use frustum::Frustum;
pub use layout::TriangleLeaves;
pub use packet_shear::PacketShear;
pub(crate) use whole::run_triangles;
pub use whole::{TriangleBlock, BLOCK_WIDTH};
