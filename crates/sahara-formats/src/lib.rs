//! `sahara-formats`: files in, plain arrays out; images out, atomically.
//!
//! - meshes: [`obj`] (with [`mtl`] materials), [`ply`], [`gltf`] (meshes plus instances);
//! - scenes: [`scene_file`] (TOML, documented in `docs/scene-format.md`), [`camera`] sidecars;
//! - to the renderer: [`scene_load`] (a scene file as a `sahara_render::Scene`),
//!   [`mesh_scene`] (a bare mesh file as one), sharing [`mesh_library`] (each
//!   mesh file loaded once) and [`material_map`] (MTL / glTF materials);
//! - images: [`image_out`] (PNG/EXR via [`atomic`] replacement), [`image_in`] (textures);
//! - render parts: [`part_file`] (a piece of a frame and its exact sums, as EXR);
//! - every error is a [`FormatError`]: one line naming the file and the place.
//!
//! Meshes come out as [`sahara_render::Mesh`]: one merged triangle list
//! in file order, polygons fan-triangulated as `(v0, vi, vi+1)`, so triangle
//! number `k` is the `k`-th triangle of the file after triangulation.

#![warn(missing_docs)]

pub mod atomic;
pub mod camera;
pub mod error;
mod fan;
pub mod gltf;
pub mod image_in;
pub mod image_out;
pub mod material_map;
pub mod mesh_library;
pub mod mesh_scene;
pub mod mtl;
pub mod obj;
pub mod part_file;
pub mod pbrt;
pub mod ply;
pub mod scene_file;
pub mod scene_load;
pub mod sky;
pub mod srgb;

use std::path::{Path, PathBuf};

use sahara_render::Mesh;

pub use error::FormatError;

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

/// The shared scene folder: `$SAHARA_SCENES` if set, else `shared/scenes` beside the workspace.
pub fn scenes_dir() -> PathBuf {
    match std::env::var_os("SAHARA_SCENES") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => {
            let dir = Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../../shared/scenes"
            ));
            dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf())
        }
    }
}
