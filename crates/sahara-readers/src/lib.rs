//! `sahara-readers`: Sahara's file readers, files in and plain data out.
//!
//! - meshes: [`obj`] (with [`mtl`] materials), [`ply`], [`gltf`] (meshes,
//!   materials, instances, cameras and lights), any of them by extension
//!   with [`load_mesh`];
//! - images: [`image_in`] (PNG, JPEG, Radiance HDR, OpenEXR, TGA and PFM,
//!   as their stored values: 8-bit codes or floats, saying which);
//! - [`camera`] sidecars (JSON);
//! - [`fan`]: the fan triangulation of polygons that the mesh formats share;
//! - [`sniff`]: files that are images, archives or programs, by their first
//!   bytes (every mesh load refuses them in words).
//!
//! Everything comes out as plain data: [`Mesh`] (`sahara-kd`'s plain
//! arrays, the mesh type the renderer keeps too), attribute structs
//! such as [`obj::ObjScene`], [`ply::PlyMesh`] and [`gltf::GltfScene`],
//! [`image_in::RawImage`]. Nothing here depends on the renderer; turning
//! the data into a scene (materials, textures, lights, colour decoding) is
//! `sahara-formats`' job.
//!
//! Meshes are one merged triangle list in file order, polygons
//! fan-triangulated as `(v0, vi, vi+1)`, so triangle number `k` is the
//! `k`-th triangle of the file after triangulation.
//!
//! Every error is a [`FormatError`]: one line naming the file and the place
//! ([`one_line`] keeps quoted input from breaking that promise).

#![warn(missing_docs)]

pub mod camera;
pub mod error;
pub mod fan;
pub mod gltf;
pub mod image_in;
pub mod mtl;
pub mod nanovdb;
pub mod obj;
pub mod ply;
pub mod sniff;
pub mod vdb;
pub mod vol;

use std::path::Path;

pub use error::{in_words, one_line, FormatError};
pub use sahara_kd::Mesh;

/// Loads a mesh, choosing the format by extension (`.obj`, `.ply`, `.gltf` or
/// `.glb`, any case); see [`load_mesh_with_warnings`].
pub fn load_mesh(path: &Path) -> Result<Mesh, FormatError> {
    load_mesh_with_warnings(path).map(|(mesh, _)| mesh)
}

/// Loads a mesh as [`load_mesh`] does, with the problems that did not stop
/// loading (one line each, naming the file).
///
/// A glTF file becomes one triangle list: every use of a mesh by a node of
/// the scene, in scene order, with the node's transform applied to its
/// vertices (so triangle `k` is the same triangle the renderer sees).
pub fn load_mesh_with_warnings(path: &Path) -> Result<(Mesh, Vec<String>), FormatError> {
    if let Some(what) = sniff::foreign_kind(path) {
        return Err(FormatError::in_file(
            &path.display().to_string(),
            format!("is {what}, not a mesh (.obj, .ply, .gltf, .glb)"),
        ));
    }
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "obj" => Ok((obj::load_obj(path)?, Vec::new())),
        "ply" => Ok((ply::load_ply(path)?, Vec::new())),
        "gltf" | "glb" => {
            let g = gltf::load_gltf(path)?;
            let mut mesh = Mesh::default();
            for inst in &g.instances {
                let part = &g.meshes[inst.mesh].mesh;
                let base = mesh.positions.len();
                let base32 = u32::try_from(base)
                    .ok()
                    .filter(|b| {
                        u32::try_from(part.positions.len())
                            .is_ok_and(|n| b.checked_add(n).is_some())
                    })
                    .ok_or_else(|| {
                        FormatError::in_file(
                            &path.display().to_string(),
                            "the scene's mesh uses have more than 2^32 vertices in all",
                        )
                    })?;
                mesh.positions.extend(
                    part.positions
                        .iter()
                        .map(|&p| inst.transform.transform_point3(p)),
                );
                mesh.indices
                    .extend(part.indices.iter().map(|t| t.map(|i| i + base32)));
            }
            Ok((mesh, g.warnings))
        }
        _ => Err(FormatError::UnsupportedExtension {
            path: path.display().to_string(),
            extension,
        }),
    }
}
