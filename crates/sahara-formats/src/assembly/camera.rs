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

/// How much larger than everything else a flat object must be for the
/// automatic camera to leave it out: a ground plane or a sea that dwarfs
/// the subject would otherwise make it a speck in the frame.
const GROUND_DWARFS: f32 = 4.0;

/// Thickness, relative to its largest extent, below which an object is flat.
const FLAT: f32 = 1e-3;

/// A camera that sees the scene (see [`auto_camera_framing`]).
pub fn auto_camera(scene: &Scene, name: &str) -> Result<Camera, FormatError> {
    auto_camera_framing(scene, name).map(|(c, _)| c)
}

/// The scene's grounds: per instance, whether it is a flat object (a
/// ground plane, a sea) whose extent is at least [`GROUND_DWARFS`] times
/// the diagonal of the bounds of everything that is not flat; and those
/// bounds (the subject's; empty when everything is flat). The automatic
/// camera frames what is not ground, and `auto` lighting counts only the
/// light an emissive ground sheds on the subject.
pub(crate) fn grounds(scene: &Scene) -> (Vec<bool>, Option<(Vec3, Vec3)>) {
    let bounds: Vec<Option<(Vec3, Vec3)>> = scene
        .instances
        .iter()
        .map(|inst| {
            let m = &scene.meshes[inst.mesh as usize].mesh;
            let b = inst.placement.world_bounds(m.bounds());
            (!b.is_empty() && b.min.is_finite() && b.max.is_finite()).then_some((b.min, b.max))
        })
        .collect();
    let is_flat = |b: &(Vec3, Vec3)| {
        let e = b.1 - b.0;
        e.min_element() <= FLAT * e.max_element()
    };
    let (lo, hi) = bounds
        .iter()
        .flatten()
        .filter(|b| !is_flat(b))
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), b| {
            (lo.min(b.0), hi.max(b.1))
        });
    let subject = (lo.is_finite() && hi.is_finite()).then_some((lo, hi));
    // Without a subject (everything flat) nothing is ground.
    let diagonal = subject.map(|(lo, hi)| (hi - lo).length());
    let ground = bounds
        .iter()
        .map(|b| match (b, diagonal) {
            (Some(b), Some(d)) if d.is_finite() => {
                is_flat(b) && (b.1 - b.0).max_element() >= GROUND_DWARFS * d
            }
            _ => false,
        })
        .collect();
    (ground, subject)
}

/// A camera that sees the scene's objects: looking at the centre of their
/// bounds from above, the front (+Z) and the right (+X), at the distance
/// where their bounding sphere fills the vertical field of view; with the
/// log's words for how it chose. Grounds ([`grounds`]: flat objects at
/// least [`GROUND_DWARFS`] times the size of everything else) are left out
/// of the framing (they still render), so that the subject fills the
/// frame rather than the plane it stands on.
pub fn auto_camera_framing(scene: &Scene, name: &str) -> Result<(Camera, String), FormatError> {
    let (ground, _) = grounds(scene);
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut framed, mut left_out) = (0, 0);
    for (inst, &g) in scene.instances.iter().zip(&ground) {
        let m = &scene.meshes[inst.mesh as usize].mesh;
        let b = inst.placement.world_bounds(m.bounds());
        if b.is_empty() {
            continue;
        }
        if g {
            left_out += 1;
            continue;
        }
        framed += 1;
        lo = lo.min(b.min);
        hi = hi.max(b.max);
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
    let how = match left_out {
        0 if framed == 1 => "auto (framing the one object)".to_owned(),
        0 => format!("auto (framing all {framed} objects)"),
        n => format!(
            "auto (framing {framed} object{}; {n} flat object{} at least {GROUND_DWARFS} times their \
             size, a ground or water plane, left out of the framing)",
            if framed == 1 { "" } else { "s" },
            if n == 1 { "" } else { "s" }
        ),
    };
    Ok((Camera::look_at(eye, c, Vec3::Y, AUTO_VFOV_DEG, 1.0), how))
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

    /// A unit sphere on a square ground plane of side `side`.
    fn sphere_on_ground(side: f32) -> Scene {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let m = scene.add_material(Scene::default_material());
        scene.add_shape(
            sahara_render::Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            m,
        );
        scene.add_shape(
            sahara_render::Shape::Quad {
                corner: Vec3::new(-side / 2.0, -1.0, -side / 2.0),
                edge_u: Vec3::new(side, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, side),
            },
            m,
        );
        scene
    }

    #[test]
    fn a_ground_plane_that_dwarfs_the_subject_is_left_out_of_the_framing() {
        let (c, how) = auto_camera_framing(&sphere_on_ground(1000.0), "t").unwrap();
        // Framed on the sphere (radius 1): the eye is a few radii away,
        // not hundreds.
        assert!(c.eye.length() < 5.0, "{}", c.eye);
        assert!((c.forward.dot(-c.eye.normalize()) - 1.0).abs() < 1e-4);
        assert!(
            how.contains("1 flat object") && how.contains("left out"),
            "{how}"
        );
    }

    #[test]
    fn a_floor_of_the_subjects_size_is_framed_with_it() {
        let (c, how) = auto_camera_framing(&sphere_on_ground(3.0), "t").unwrap();
        assert_eq!(how, "auto (framing all 2 objects)");
        // Farther than the sphere alone needs (sqrt(3) / sin(22.5 deg) =
        // 4.5): the floor's corners are in the frame too (6.1).
        assert!(c.eye.length() > 6.0, "{}", c.eye);
    }
}
