//! Numerics shared by the renderer's parts: counter-based hashing,
//! piecewise-constant distributions, and warps of uniform samples onto
//! discs, hemispheres, spheres, cones and triangles.

pub mod hash;
pub(crate) mod lanes;
pub mod piecewise;
pub mod warp;
