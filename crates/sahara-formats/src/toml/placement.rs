//! Scene-file transforms and motion as object placements.

use glam::{Affine3A, Mat4, Quat};
use sahara_render::Srt;

use super::file::{Placement as PlacementSpec, TransformSpec};
use crate::description::ObjectPlacement;

/// The scale-rotation-translation of a transform.
pub fn srt(t: &TransformSpec) -> Srt {
    Srt {
        scale: t.scale,
        rotation: Quat::from_axis_angle(t.rotate_axis, t.rotate_deg.to_radians()),
        translation: t.translate,
    }
}

/// The placement an object's `transform` or `motion` gives.
pub fn placement(spec: &PlacementSpec) -> ObjectPlacement {
    match spec {
        // The product with the identity makes -0 entries +0, as scene
        // files have always been placed (the same images, bit for bit).
        PlacementSpec::Static(t) => {
            ObjectPlacement::Static(Affine3A::from_mat4(t.matrix() * Mat4::IDENTITY))
        }
        PlacementSpec::Motion { open, close } => ObjectPlacement::Moving {
            open: srt(open),
            close: srt(close),
        },
    }
}
