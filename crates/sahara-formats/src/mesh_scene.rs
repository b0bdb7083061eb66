//! A bare mesh file (`.obj`, `.ply`, `.gltf`, `.glb`) as a scene to render.
//!
//! Materials come from the file (MTL, glTF; grey for PLY), the camera from
//! the `<stem>.camera.json` sidecar when there is one, else it frames the
//! mesh's bounds from above and to the side; a default sky and sun light
//! the scene only when none of its materials emits.

use std::path::Path;

use glam::Vec3;
use sahara_render::{Camera, Environment, Instance, Light, Placement, Scene};

use crate::camera::{read_sidecar, sidecar_path};
use crate::error::FormatError;
use crate::mesh_library::MeshLibrary;

/// Radiance of the default sky.
pub const DEFAULT_SKY: Vec3 = Vec3::new(0.55, 0.6, 0.7);
/// Direction the default sun's light travels.
pub const DEFAULT_SUN_DIRECTION: Vec3 = Vec3::new(-0.4, -1.0, -0.3);
/// Irradiance of the default sun.
pub const DEFAULT_SUN: Vec3 = Vec3::splat(2.5);
/// Vertical field of view of the automatic camera, degrees.
pub const AUTO_VFOV_DEG: f32 = 45.0;

/// A mesh file made into a scene.
#[derive(Clone, Debug)]
pub struct MeshScene {
    /// The scene (camera aspect 1: the caller sets it from the image size).
    pub scene: Scene,
    /// Where the camera came from: the sidecar's path, or `auto`.
    pub camera_source: String,
    /// True if the default sky and sun were added.
    pub default_light: bool,
    /// Problems that did not stop loading, one line each, naming the file.
    pub warnings: Vec<String>,
}

/// Loads a mesh file with its materials, camera and (if needed) the default light.
pub fn load_mesh_scene(path: &Path) -> Result<MeshScene, FormatError> {
    load_mesh_scene_with_camera(path, None)
}

/// Loads a mesh file as [`load_mesh_scene`] does, with the camera of the
/// sidecar `camera` if given (instead of `<stem>.camera.json` or the
/// automatic one).
pub fn load_mesh_scene_with_camera(
    path: &Path,
    camera: Option<&Path>,
) -> Result<MeshScene, FormatError> {
    // Placeholder camera until the bounds are known.
    let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
    let mut library = MeshLibrary::new();
    let file = library.load(&mut scene, path, true)?;
    for part in &file.parts {
        scene.add_instance(Instance {
            mesh: part.mesh,
            placement: Placement::Static(glam::Affine3A::from_mat4(part.transform)),
            material: file.material,
        });
    }
    let sidecar = camera.map_or_else(|| sidecar_path(path), Path::to_path_buf);
    let (camera, camera_source) = if camera.is_some() || sidecar.exists() {
        let c = read_sidecar(&sidecar)?;
        (
            Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, 1.0),
            sidecar.display().to_string(),
        )
    } else {
        (
            auto_camera(&scene, &path.display().to_string())?,
            "auto".into(),
        )
    };
    scene.camera = camera;
    let default_light = !file.emissive;
    if default_light {
        scene.environment = Some(Environment::Constant(DEFAULT_SKY));
        scene.add_light(Light::directional(DEFAULT_SUN_DIRECTION, DEFAULT_SUN));
    }
    Ok(MeshScene {
        scene,
        camera_source,
        default_light,
        warnings: library.warnings,
    })
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
