//! Scene-file transforms and motion as renderer placements.

use glam::{Affine3A, Mat4, Quat};
use sahara_render::{Placement, Srt};

use crate::scene_file::{Placement as PlacementSpec, TransformSpec};

/// The scale-rotation-translation of a transform.
pub fn srt(t: &TransformSpec) -> Srt {
    Srt {
        scale: t.scale,
        rotation: Quat::from_axis_angle(t.rotate_axis, t.rotate_deg.to_radians()),
        translation: t.translate,
    }
}

/// The placement of an object whose geometry sits at `inner` in its file
/// (identity, or a glTF node's transform) and that the scene places by `spec`.
///
/// A moving object with a non-identity `inner` has `open * inner` and
/// `close * inner` split into scale, rotation and translation (a shear is lost).
pub fn placement(spec: &PlacementSpec, inner: Mat4) -> Placement {
    let identity = inner == Mat4::IDENTITY;
    match spec {
        PlacementSpec::Static(t) => Placement::Static(Affine3A::from_mat4(t.matrix() * inner)),
        PlacementSpec::Motion { open, close } if identity => Placement::Moving {
            open: srt(open),
            close: srt(close),
        },
        PlacementSpec::Motion { open, close } => {
            let split = |t: &TransformSpec| {
                let (scale, rotation, translation) =
                    (t.matrix() * inner).to_scale_rotation_translation();
                Srt {
                    scale,
                    rotation,
                    translation,
                }
            };
            Placement::Moving {
                open: split(open),
                close: split(close),
            }
        }
    }
}
