//! A bare mesh file (`.obj`, `.ply`, `.gltf`, `.glb`) as a scene to render.
//!
//! Materials come from the file (MTL, glTF; grey for PLY), and so do a
//! glTF file's lights. The camera is, in order: the one asked for (a
//! sidecar file, or a glTF camera by name), the `<stem>.camera.json`
//! sidecar, the glTF file's first camera, else one that frames the mesh's
//! bounds from above and to the side. The sky follows [`crate::assembly::sky`]
//! (`auto` unless told otherwise: the default sky and sun when the file's
//! own lights are weak).
//!
//! The mesh files themselves are read by `sahara-readers` as plain data;
//! [`library`] loads each file a description names once, with its own
//! materials ([`mtl`] for OBJ, [`crate::gltf`] for glTF).

pub(crate) mod library;
pub(crate) mod mtl;

use std::path::{Path, PathBuf};

use sahara_render::Camera;

use crate::description::Sky;
use crate::description::{CameraRequest, Geometry, Object, ObjectPlacement, SceneDescription};
use sahara_readers::camera::{read_sidecar, sidecar_path};
use sahara_readers::FormatError;

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

/// The description of a mesh file as a scene: the file in world space
/// with its own materials, seen by `camera`, lit by the `auto` sky.
pub(crate) fn read_mesh_scene(
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
        name: None,
    });
    Ok(desc)
}

/// Mesh files (OBJ, PLY, glTF's meshes) as the renderer's meshes, the
/// readers' own functions: their `Mesh` is the renderer's.
pub use sahara_readers::{load_mesh, load_mesh_with_warnings};
