//! A bare mesh file (`.obj`, `.ply`, `.gltf`, `.glb`) as a scene to render.
//!
//! Materials come from the file (MTL, glTF; grey for PLY), and so do a
//! glTF file's lights. The camera is, in order: the one asked for (a
//! sidecar file, or a glTF camera by name), the `<stem>.camera.json`
//! sidecar, the glTF file's first camera, else one that frames the mesh's
//! bounds from above and to the side. The sky follows [`crate::assembly::sky`]
//! (`auto` unless told otherwise: the default sky and sun when the file's
//! own lights are weak).

use std::path::{Path, PathBuf};

use sahara_render::{Camera, Scene};

use crate::assembly::assemble;
use crate::assembly::sky::SkyUsed;
use crate::description::Sky;
use crate::description::{CameraRequest, Geometry, Object, ObjectPlacement, SceneDescription};
use crate::FormatError;
use sahara_readers::camera::{read_sidecar, sidecar_path};

pub use crate::assembly::sky::{DEFAULT_SKY, DEFAULT_SUN, DEFAULT_SUN_DIRECTION};
pub use crate::assembly::AUTO_VFOV_DEG;

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
    let mut desc = read_mesh_scene(path, camera)?;
    desc.sky = sky.clone();
    let a = assemble(desc)?;
    Ok(MeshScene {
        scene: a.scene,
        camera_source: a.camera_source,
        sky: a.sky,
        warnings: a.warnings,
    })
}

/// The description of a mesh file as a scene: the file in world space
/// with its own materials, seen by `camera`, lit by the `auto` sky.
pub fn read_mesh_scene(
    path: &Path,
    camera: &CameraChoice,
) -> Result<SceneDescription, FormatError> {
    let mut desc = SceneDescription::new(path.display().to_string());
    let from_sidecar = |p: &Path| -> Result<CameraRequest, FormatError> {
        let c = read_sidecar(p)?;
        Ok(CameraRequest::Given {
            camera: Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, 1.0),
            source: p.display().to_string(),
        })
    };
    let sidecar = sidecar_path(path);
    desc.camera = match camera {
        CameraChoice::Sidecar(p) => from_sidecar(p)?,
        CameraChoice::Named(want) => CameraRequest::Named(want.clone()),
        CameraChoice::Auto if sidecar.exists() => from_sidecar(&sidecar)?,
        CameraChoice::Auto => CameraRequest::Automatic,
    };
    desc.sky = Sky::Auto;
    desc.objects.push(Object {
        geometry: Geometry::File(path.to_path_buf()),
        placement: ObjectPlacement::World,
        material: None,
    });
    Ok(desc)
}
