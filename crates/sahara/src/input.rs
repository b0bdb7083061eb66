//! Reading what a command works on: the mesh and its camera.

use std::path::Path;

use anyhow::{anyhow, Context, Result};
use sahara_bench::report::CameraReport;
use sahara_bench::{ProtocolCamera, SceneFrame};
use sahara_readers::camera::{read_sidecar, sidecar_path, CameraSidecar};
use sahara_render::Mesh;

/// Load a mesh (`.obj`, `.ply`, `.gltf`, `.glb`; a glTF scene's meshes
/// merged in scene order), print its loading warnings, and check that the
/// protocol can use it (triangles, indices in range).
pub fn load_mesh(path: &Path) -> Result<Mesh> {
    // A `FormatError`'s message already holds its cause: flatten it so the
    // cause is not printed twice by `{:#}`.
    let loading = crate::status::Step::start(format!("loading {}", path.display()));
    let loaded = sahara_formats::load_mesh_with_warnings(path);
    drop(loading);
    let (mesh, mut warnings) = loaded
        .map_err(|e| anyhow!("{e}"))
        .with_context(|| format!("cannot load mesh {}", path.display()))?;
    let skipped = mesh.unhittable_count();
    if skipped > 0 {
        warnings.push(format!(
            "{}: {skipped} of {} triangles skipped (non-finite coordinates or zero area)",
            path.display(),
            mesh.triangle_count()
        ));
    }
    crate::warnings::print(&warnings);
    SceneFrame::from_mesh(&mesh).with_context(|| format!("mesh {}", path.display()))?;
    Ok(mesh)
}

/// The protocol camera of a sidecar.
fn from_sidecar(c: &CameraSidecar) -> ProtocolCamera {
    ProtocolCamera {
        eye: c.eye,
        target: c.target,
        up: c.up,
        vfov_deg: c.vfov_deg,
    }
}

/// The camera for a mesh: `explicit` if given, else the mesh's sidecar if it
/// exists, else the protocol's auto camera; with where it came from.
pub fn camera_for(
    mesh_path: Option<&Path>,
    explicit: Option<&Path>,
    frame: &SceneFrame,
) -> Result<(ProtocolCamera, CameraReport)> {
    let sidecar = match explicit {
        Some(p) => Some(p.to_path_buf()),
        None => mesh_path.map(sidecar_path).filter(|p| p.exists()),
    };
    let camera = match &sidecar {
        Some(p) => from_sidecar(
            &read_sidecar(p)
                .map_err(|e| anyhow!("{e}"))
                .with_context(|| format!("cannot read camera {}", p.display()))?,
        ),
        None => ProtocolCamera::auto(frame),
    };
    let source = sidecar.map_or_else(|| "auto".to_owned(), |p| p.display().to_string());
    let report = CameraReport::new(&camera, source);
    Ok((camera, report))
}
