//! `sahara-formats`: files in, plain arrays out; images out, atomically.
//!
//! - meshes: [`obj`] (with [`mtl`] materials), [`ply`], [`gltf`] (meshes plus instances);
//! - scenes: [`scene_file`] (TOML, documented in `docs/scene-format.md`), [`camera`] sidecars;
//! - to the renderer: [`scene_load`] (a scene file as a `sahara_render::Scene`),
//!   [`mesh_scene`] (a bare mesh file as one), sharing [`mesh_library`] (each
//!   mesh file loaded once) and [`material_map`] (MTL / glTF materials);
//! - images: [`image_out`] (PNG/EXR via [`atomic`] replacement), [`image_in`] (textures);
//! - every error is a [`FormatError`]: one line naming the file and the place.
//!
//! Meshes come out as [`sahara_render::mesh::Mesh`]: one merged triangle list
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
pub mod ply;
pub mod scene_file;
pub mod scene_load;
pub mod srgb;

use std::path::{Path, PathBuf};

use sahara_render::mesh::Mesh;

pub use error::FormatError;

/// Loads a mesh, choosing the format by extension (`.obj` or `.ply`, any case).
pub fn load_mesh(path: &Path) -> Result<Mesh, FormatError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "obj" => obj::load_obj(path),
        "ply" => ply::load_ply(path),
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
