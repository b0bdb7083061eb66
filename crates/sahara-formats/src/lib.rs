//! `sahara-formats`: scenes for the renderer, and images out.
//!
//! - scenes, each read into a [`description::SceneDescription`]:
//!   [`scene_file`] (TOML, documented in `docs/scene-format.md`) with
//!   [`scene_load`] (its description), [`pbrt`] (pbrt-v4 scenes),
//!   [`mitsuba`] (Mitsuba 3 XML scenes),
//!   [`mesh_scene`] (a bare mesh file as a scene);
//! - any of them by its extension: [`load`] (and [`load_builtin`], the
//!   built-in Cornell box), read and assembled in one call;
//! - to the renderer: [`assembly`] (a description as a
//!   `sahara_render::Scene`: the sky rule, the automatic camera), using
//!   [`mesh_library`] (each mesh file loaded once), [`material_map`]
//!   (MTL / glTF materials) and [`gltf_scene`] (glTF cameras and lights);
//! - images: [`image_out`] (PNG/EXR via [`atomic`] replacement), [`image_in`]
//!   (textures and environment maps as linear colour);
//! - render parts: [`part_file`] (a piece of a frame and its exact sums, as EXR);
//! - every error is a [`FormatError`]: one line naming the file and the place.
//!
//! The mesh, image and camera-sidecar files themselves are read by
//! `sahara-readers`, which returns plain data; this crate turns that data
//! into the renderer's types. [`load_mesh`] gives a mesh file as a
//! [`sahara_render::Mesh`]: one merged triangle list in file order,
//! polygons fan-triangulated as `(v0, vi, vi+1)`, so triangle number `k` is
//! the `k`-th triangle of the file after triangulation.

#![warn(missing_docs)]

pub mod assembly;
pub mod atomic;
mod common;
pub mod description;
pub mod gltf_scene;
pub mod image_in;
pub mod image_out;
mod load;
pub mod material_map;
pub mod mesh_library;
pub mod mesh_scene;
pub mod mitsuba;
pub mod part_file;
pub mod pbrt;
pub mod scene_file;
pub mod scene_load;
pub mod srgb;

use std::path::Path;

use sahara_readers::TriangleMesh;
use sahara_render::Mesh;

pub use load::{load, load_builtin, LoadOptions, Loaded};
pub use sahara_readers::FormatError;

/// A mesh as read as the renderer's mesh (both vectors are moved, not copied).
pub fn render_mesh(mesh: TriangleMesh) -> Mesh {
    let TriangleMesh { positions, indices } = mesh;
    Mesh { positions, indices }
}

/// Loads a mesh file as the renderer's mesh: [`sahara_readers::load_mesh`]
/// and [`render_mesh`].
pub fn load_mesh(path: &Path) -> Result<Mesh, FormatError> {
    sahara_readers::load_mesh(path).map(render_mesh)
}

/// Loads a mesh file as the renderer's mesh, with the problems that did not
/// stop loading: [`sahara_readers::load_mesh_with_warnings`] and
/// [`render_mesh`].
pub fn load_mesh_with_warnings(path: &Path) -> Result<(Mesh, Vec<String>), FormatError> {
    sahara_readers::load_mesh_with_warnings(path).map(|(mesh, w)| (render_mesh(mesh), w))
}
