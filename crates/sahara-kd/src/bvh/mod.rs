//! The eight-wide bounding volume hierarchy: built by the same surface
//! area heuristic as the kd-tree (binned, with spatial splits, or from the
//! kd-tree itself), traversed the way wide vector units want: all eight
//! child boxes of a node in one step, a short stack ordered by the ray's
//! octant, leaves of eight-triangle blocks under the kd-tree's watertight
//! block test. Every query gives the brute-force oracle's answer bit for
//! bit, as the kd-tree's do. See `docs/accelerator.md`.

mod batch;
pub(crate) mod build;
pub(crate) mod node;
mod packet;
mod quad;
mod query;
mod stats;
mod walk;

pub use build::{BvhBuilder, BvhParams};
pub use node::MAX_LEAF;
pub use stats::BvhStats;

use crate::math::{Aabb, Triangle};
use node::WideNode;
use quad::Quad;

/// An eight-wide bounding volume hierarchy over triangles.
///
/// Build it with [`Bvh::build`]; query it with [`Bvh::closest_hit`],
/// [`Bvh::any_hit`] and their batch forms. Answers are those of
/// [`crate::brute`], bit for bit, as the kd-tree's are.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Wide nodes, root first, depth first (empty: no triangle).
    pub(crate) nodes: Vec<WideNode>,
    /// Leaves, each node's next to one another.
    pub(crate) quads: Vec<Quad>,
    /// Triangles given to the build (hit indices range over them).
    pub(crate) prim_count: usize,
    /// The bounds of all hittable triangles.
    pub(crate) bounds: Aabb,
    /// The largest coordinate magnitude of `bounds`, for the walk's
    /// widening of boxes (see `walk`).
    pub(crate) scale: f32,
    pub(crate) params: BvhParams,
    /// Triangle references in leaves.
    pub(crate) references: usize,
    /// The highest dispatch level of its queries ([`crate::Isa`]).
    pub(crate) max_level: u8,
}

impl Bvh {
    /// Build the hierarchy over `triangles` (those no ray can hit, with a
    /// coordinate that is not finite or of zero area, are left out; hit
    /// indices are positions in `triangles`).
    pub fn build(triangles: Vec<Triangle>, params: &BvhParams) -> Bvh {
        build::build(triangles, params)
    }

    /// Hold its queries to the instructions of `isa` at most (the default
    /// is the best the CPU has; see [`crate::Isa`] for why a caller would
    /// lower it). Answers do not change.
    pub fn set_isa(&mut self, isa: crate::Isa) {
        self.max_level = isa.level();
    }

    /// The widest instructions its queries may use.
    pub fn isa(&self) -> crate::Isa {
        crate::Isa::of_level(self.max_level)
    }

    /// Number of wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Node `i`.
    ///
    /// # Safety
    /// `i` must be an inner child reference (or 0 of a non-empty
    /// hierarchy).
    #[inline(always)]
    pub(crate) unsafe fn node(&self, i: u32) -> &WideNode {
        debug_assert!((i as usize) < self.nodes.len());
        // SAFETY: the caller's contract; references name nodes the build
        // wrote.
        unsafe { self.nodes.get_unchecked(i as usize) }
    }

    /// Leaf `i`.
    ///
    /// # Safety
    /// `i` must be a leaf reference's index.
    #[inline(always)]
    pub(crate) unsafe fn quad(&self, i: usize) -> &Quad {
        debug_assert!(i < self.quads.len());
        // SAFETY: as `node`.
        unsafe { self.quads.get_unchecked(i) }
    }

    /// The bounds of the hittable triangles.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of triangles given to the build.
    pub fn primitive_count(&self) -> usize {
        self.prim_count
    }

    /// The parameters the hierarchy was built with.
    pub fn params(&self) -> &BvhParams {
        &self.params
    }
}
