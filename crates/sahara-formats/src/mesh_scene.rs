//! A bare mesh file (`.obj`, `.ply`, `.gltf`, `.glb`) as a scene to render.
//!
//! Materials come from the file (MTL, glTF; grey for PLY), and so do a
//! glTF file's lights. The camera is, in order: the one asked for (a
//! sidecar file, or a glTF camera by name), the `<stem>.camera.json`
//! sidecar, the glTF file's first camera, else one that frames the mesh's
//! bounds from above and to the side. The sky follows [`crate::sky`]
//! (`auto` unless told otherwise: the default sky and sun when the file's
//! own lights are weak).

use std::path::{Path, PathBuf};

use glam::Vec3;
use sahara_render::{Camera, Instance, Placement, Scene};

use crate::gltf_scene::{gltf_camera, gltf_light};
use crate::mesh_library::MeshLibrary;
use crate::sky::{self, Sky, SkyUsed};
use crate::FormatError;
use sahara_readers::camera::{read_sidecar, sidecar_path};

pub use crate::sky::{DEFAULT_SKY, DEFAULT_SUN, DEFAULT_SUN_DIRECTION};

/// Vertical field of view of the automatic camera, degrees.
pub const AUTO_VFOV_DEG: f32 = 45.0;

/// Which camera a mesh file is seen by.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum CameraChoice {
    /// The `<stem>.camera.json` sidecar, else the file's first camera,
    /// else the automatic one.
    #[default]
    Auto,
    /// A camera sidecar file.
    Sidecar(PathBuf),
    /// The glTF file's camera of this name.
    Named(String),
}

impl CameraChoice {
    /// What `--camera VALUE` means: a sidecar if `VALUE` names an
    /// existing file or ends in `.json`, else a camera name.
    pub fn from_arg(value: &str) -> CameraChoice {
        let path = Path::new(value);
        if path.is_file() || value.to_ascii_lowercase().ends_with(".json") {
            CameraChoice::Sidecar(path.to_path_buf())
        } else {
            CameraChoice::Named(value.to_owned())
        }
    }
}

/// A mesh file made into a scene.
#[derive(Clone, Debug)]
pub struct MeshScene {
    /// The scene (camera aspect 1: the caller sets it from the image size).
    pub scene: Scene,
    /// Where the camera came from: the sidecar's path, the glTF camera, or
    /// `auto`.
    pub camera_source: String,
    /// What lights the scene besides its own lights.
    pub sky: SkyUsed,
    /// Problems that did not stop loading, one line each, naming the file.
    pub warnings: Vec<String>,
}

impl MeshScene {
    /// True if the default sky and sun were added.
    pub fn default_light(&self) -> bool {
        self.sky == SkyUsed::Default
    }
}

/// Loads a mesh file with its materials, lights, camera and (if its own
/// lights are weak) the default sky and sun.
pub fn load_mesh_scene(path: &Path) -> Result<MeshScene, FormatError> {
    load_mesh_scene_with(path, &CameraChoice::Auto, &Sky::Auto)
}

/// Loads a mesh file as [`load_mesh_scene`] does, seen by `camera` and
/// lit as `sky` says.
pub fn load_mesh_scene_with(
    path: &Path,
    camera: &CameraChoice,
    sky: &Sky,
) -> Result<MeshScene, FormatError> {
    let name = path.display().to_string();
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
    for l in &file.lights {
        scene.add_light(gltf_light(l, glam::Mat4::IDENTITY));
    }
    scene.generate_tangents();
    let sidecar = sidecar_path(path);
    let from_sidecar = |p: &Path| -> Result<(Camera, String), FormatError> {
        let c = read_sidecar(p)?;
        Ok((
            Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, 1.0),
            p.display().to_string(),
        ))
    };
    let named = |c: &sahara_readers::gltf::GltfCamera| {
        (
            gltf_camera(c),
            format!(
                "{name}: camera '{}'",
                c.name.as_deref().unwrap_or("(unnamed)")
            ),
        )
    };
    let (camera, camera_source) = match camera {
        CameraChoice::Sidecar(p) => from_sidecar(p)?,
        CameraChoice::Named(want) => {
            let found = file
                .cameras
                .iter()
                .find(|c| c.name.as_deref() == Some(want.as_str()));
            match found {
                Some(c) => named(c),
                None => {
                    let names: Vec<String> = file
                        .cameras
                        .iter()
                        .map(|c| format!("'{}'", c.name.as_deref().unwrap_or("(unnamed)")))
                        .collect();
                    return Err(FormatError::in_file(
                        &name,
                        if names.is_empty() {
                            format!("no camera named '{want}': the file has no cameras (and no file {want} exists)")
                        } else {
                            format!(
                                "no camera named '{want}' (the file's cameras: {})",
                                names.join(", ")
                            )
                        },
                    ));
                }
            }
        }
        CameraChoice::Auto if sidecar.exists() => from_sidecar(&sidecar)?,
        CameraChoice::Auto => match file.cameras.first() {
            Some(c) => named(c),
            None if !has_finite_triangles(&scene) => {
                library.warnings.push(format!(
                    "{name}: every triangle has a NaN or infinite corner: nothing to frame; \
                     the camera looks at the origin from +Z"
                ));
                (
                    Camera::look_at(
                        Vec3::new(0.0, 0.0, 5.0),
                        Vec3::ZERO,
                        Vec3::Y,
                        AUTO_VFOV_DEG,
                        1.0,
                    ),
                    "auto (nothing to frame)".into(),
                )
            }
            None => (auto_camera(&scene, &name)?, "auto".into()),
        },
    };
    scene.camera = camera;
    let sky = sky::apply(&mut scene, sky)?;
    Ok(MeshScene {
        scene,
        camera_source,
        sky,
        warnings: library.warnings,
    })
}

/// True if some instance has a triangle whose corners are all finite.
fn has_finite_triangles(scene: &Scene) -> bool {
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
