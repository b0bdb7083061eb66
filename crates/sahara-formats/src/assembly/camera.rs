//! The automatic camera: the whole scene seen from above, the front and
//! the right.

use glam::Vec3;
use sahara_render::{Camera, Scene};

use crate::FormatError;

/// Vertical field of view of the automatic camera, degrees.
pub const AUTO_VFOV_DEG: f32 = 45.0;

/// True if some instance has a triangle whose corners are all finite.
pub(crate) fn has_finite_triangles(scene: &Scene) -> bool {
    scene
        .instances
        .iter()
        .any(|i| !scene.meshes[i.mesh as usize].mesh.bounds().is_empty())
}

/// A camera that sees the whole scene: looking at the centre of its bounds
/// from above, the front (+Z) and the right (+X), at the distance where the
/// bounding sphere fills the vertical field of view.
pub fn auto_camera(scene: &Scene, name: &str) -> Result<Camera, FormatError> {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for inst in &scene.instances {
        let m = &scene.meshes[inst.mesh as usize].mesh;
        let b = inst.placement.world_bounds(m.bounds());
        if !b.is_empty() {
            lo = lo.min(b.min);
            hi = hi.max(b.max);
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(FormatError::in_file(
            name,
            "the mesh has no triangles with finite corners; nothing to frame",
        ));
    }
    let c = 0.5 * lo + 0.5 * hi;
    let r = (0.5 * (hi - lo).length()).max(1e-6);
    let eye =
        c + Vec3::new(0.3, 0.5, 1.0).normalize() * (r / (0.5 * AUTO_VFOV_DEG.to_radians()).sin());
    // Coordinates near the float range put the eye at infinity, and
    // coordinates far from the origin beside a tiny mesh leave no room
    // between eye and target.
    if !(eye.is_finite() && c.is_finite() && r.is_finite()) || eye == c {
        return Err(FormatError::in_file(
            name,
            format!(
                "the mesh's bounds ({lo} to {hi}) are too large to frame automatically; \
                 give a camera sidecar (--camera FILE or {{stem}}.camera.json)"
            ),
        ));
    }
    Ok(Camera::look_at(eye, c, Vec3::Y, AUTO_VFOV_DEG, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_camera_sees_the_bounds_centre() {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let m = scene.add_material(Scene::default_material());
        scene.add_shape(
            sahara_render::Shape::Box {
                min: Vec3::splat(1.0),
                max: Vec3::splat(3.0),
            },
            m,
        );
        let c = auto_camera(&scene, "t").unwrap();
        let to_centre = (Vec3::splat(2.0) - c.eye).normalize();
        assert!(to_centre.dot(c.forward) > 0.9999);
        assert!(c.eye.distance(Vec3::splat(2.0)) > 3.0f32.sqrt());
    }
}
