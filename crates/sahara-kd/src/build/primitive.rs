//! What a kd-tree can be built over: anything with bounds, bounds clipped
//! to a cell, and a way to tell that no ray can hit it.

use crate::math::clip::clipped_bounds;
use crate::math::{Aabb, Triangle};

/// A primitive a kd-tree can be built over: it has bounds, and bounds of
/// its part inside a cell (for split clipping).
pub trait Primitive: Send + Sync + Sized {
    /// Bounds of the whole primitive.
    fn bounds(&self) -> Aabb;
    /// Bounds of the primitive clipped to `cell`, `None` if they do not meet.
    fn clipped_bounds(&self, cell: &Aabb) -> Option<Aabb>;
    /// False for primitives no ray can hit; the tree leaves them out.
    fn is_hittable(&self) -> bool;
}

impl Primitive for Triangle {
    fn bounds(&self) -> Aabb {
        Triangle::bounds(self)
    }
    fn clipped_bounds(&self, cell: &Aabb) -> Option<Aabb> {
        clipped_bounds(self, cell)
    }
    fn is_hittable(&self) -> bool {
        Triangle::is_hittable(self)
    }
}

/// Boxes, for trees over objects (e.g. the instances of a scene): a box
/// clipped to a cell is their intersection.
impl Primitive for Aabb {
    fn bounds(&self) -> Aabb {
        *self
    }
    fn clipped_bounds(&self, cell: &Aabb) -> Option<Aabb> {
        let b = self.intersection(*cell);
        (!b.is_empty()).then_some(b)
    }
    fn is_hittable(&self) -> bool {
        !self.is_empty() && self.min.is_finite() && self.max.is_finite()
    }
}
