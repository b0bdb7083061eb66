//! The benchmark protocol's ray generation, operation for operation as the
//! reference program `shared/bench/embree/embree_bench.c` does it, so that
//! Sahara and the reference trace bit-identical rays.
//!
//! All arithmetic is f32 in the reference's order ([`arith`]); `sin`, `cos`,
//! `tan` and `sqrt` are the C library's (`f32::sin` calls libm's `sinf` on
//! Linux) and Rust never fuses a multiply and an add. One known gap: the
//! reference runs with FTZ/DAZ set, Rust without, so a subnormal intermediate
//! (a normal component below ~1e-19, say) could round differently.

pub mod arith;
pub mod camera;
pub mod frame;
pub mod random;
pub mod secondary;
pub mod set;
pub mod splitmix;

pub use camera::{CameraBasis, ImageSize, ProtocolCamera};
pub use frame::SceneFrame;
pub use random::random_rays;
pub use secondary::{secondary_rays, SecondaryRays};
pub use set::SetKind;
pub use splitmix::SplitMix64;

/// Number of rays in the `random` set.
pub const RANDOM_RAYS: usize = 1_048_576;

/// Added to the ray index to seed the generator of a `random` ray.
pub const RANDOM_SEED_OFFSET: u64 = 0x9E37_79B9;

/// Why rays could not be generated.
#[derive(Debug, thiserror::Error)]
pub enum ProtocolError {
    /// The mesh has no triangle.
    #[error("the mesh has no triangles")]
    EmptyMesh,
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    BadIndex {
        /// The triangle.
        triangle: usize,
        /// The vertex index it holds.
        vertex: u32,
        /// The number of vertices.
        vertices: usize,
    },
    /// Primary rays and their hits do not pair up.
    #[error("{rays} primary rays but {hits} hit records")]
    LengthMismatch {
        /// Number of primary rays.
        rays: usize,
        /// Number of hit records.
        hits: usize,
    },
    /// A primary hit names a triangle the mesh does not have.
    #[error("primary ray {ray} hit triangle {triangle}, but the mesh has {triangles} triangles")]
    BadHit {
        /// The primary ray (pixel index).
        ray: usize,
        /// The triangle in its record.
        triangle: u32,
        /// The number of triangles.
        triangles: usize,
    },
}
