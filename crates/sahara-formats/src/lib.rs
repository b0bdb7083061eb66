//! `sahara-formats`: scenes for the renderer, and images out.
//!
//! A file's way to the renderer is file → description → assembly → scene:
//!
//! - each reader turns its files into one scene description, the model
//!   they all share: Sahara's TOML scene files (`docs/scene-format.md`),
//!   pbrt-v4 (`docs/pbrt.md`), Mitsuba 3 XML (`docs/mitsuba.md`), and bare
//!   mesh files (OBJ with MTL, PLY, glTF with its materials, cameras and
//!   lights) as a scene;
//! - the assembly turns a description into a [`sahara_render::Scene`]:
//!   mesh files loaded once each, the sky rule ([`SkyUsed`]), the
//!   automatic camera ([`AUTO_VFOV_DEG`]);
//! - [`load`] reads any of them, choosing the reader by the file's
//!   extension, and assembles it; [`load_builtin`] gives the built-in
//!   Cornell box. The command line and the Python package load scenes
//!   this way; the per-format loaders ([`load_scene`], [`load_pbrt`],
//!   [`load_mitsuba`], [`load_mesh_scene`]) and their in-memory forms
//!   ([`parse_scene`], [`parse_pbrt`], [`parse_mitsuba`]) are for tests,
//!   fuzzing and callers that know their format.
//!
//! Out: images ([`write_image`]: PNG and EXR, [`write_exr_layers`] with
//! render passes), render parts for the farm ([`write_part`],
//! [`read_part`]), each file replaced atomically ([`write_atomically`]).
//! In: textures and environment maps as linear colour ([`load_rgb_f32`],
//! [`load_image`]).
//!
//! Every error is a [`FormatError`]: one line naming the file and the
//! place.
//!
//! The mesh, image and camera-sidecar files themselves are read by
//! `sahara-readers`, which returns plain data; this crate turns that data
//! into the renderer's types. [`load_mesh`] gives a mesh file as a
//! [`sahara_render::Mesh`]: one merged triangle list in file order,
//! polygons fan-triangulated as `(v0, vi, vi+1)`, so triangle number `k` is
//! the `k`-th triangle of the file after triangulation.

#![warn(missing_docs)]

mod assembly;
mod common;
mod description;
mod gltf;
mod load;
mod mesh;
mod mitsuba;
mod output;
mod pbrt;
pub mod request;
mod toml;

// Loading scenes: any file by its extension, or one format.

/// Any scene or mesh file by its extension, the built-in Cornell box, and
/// the per-format loaders (file → description → assembled scene).
pub use load::{
    is_scene_file, load, load_builtin, load_mesh_scene, load_mesh_scene_with, load_mitsuba,
    load_pbrt, load_scene, parse_mitsuba, parse_pbrt, parse_scene, LoadOptions, Loaded,
};

/// What assembling a description gave: the renderer's scene, the file's
/// settings, the names of objects and materials, and what lit the scene.
pub use assembly::{AssembledScene, SceneNames};

/// The sky rule: what lights a scene besides its own lights, and the
/// default sky and sun's colours and direction.
pub use assembly::sky::{SkyUsed, DEFAULT_SKY, DEFAULT_SUN, DEFAULT_SUN_DIRECTION, WEAK_FRACTION};

/// The vertical field of view of the automatic camera, degrees.
pub use assembly::camera::AUTO_VFOV_DEG;

/// What a scene file (or a caller) asks of a render, one layer of
/// settings; a file's crop; what lights a scene besides its own lights.
pub use description::{FileCrop, PieceLayer, SettingsLayer, Sky, Split};

// Mesh files.

/// Mesh files as the renderer's meshes, and which camera a mesh file
/// shown as a scene is seen by.
pub use mesh::{load_mesh, load_mesh_with_warnings, CameraChoice};

/// MTL materials as the renderer's.
pub use mesh::mtl::{mtl_bsdf, mtl_material, phong_roughness, DEFAULT_GLASS_IOR};

/// glTF cameras and lights as the renderer's (light in watts from
/// lumens at [`LUMENS_PER_WATT`]).
pub use gltf::{gltf_camera, gltf_light, LUMENS_PER_WATT};

/// glTF materials as the renderer's.
pub use gltf::material::{gltf_bsdf, gltf_material};

/// Textures decoded once per image and encoding.
pub use common::materials::TextureCache;

// Images in and out, render parts.

/// Images in as linear colour: environment maps and textures.
pub use common::image::{
    decode_image, decode_rgb_f32, decode_texture, load_image, load_rgb_f32, load_texture, Image,
    RgbF32Image,
};

/// Images out: PNG and EXR, EXR with layers (render passes).
pub use output::image::{
    write_exr, write_exr_layers, write_image, write_png, ExrLayer, ImageFormat, Pixels,
};

/// Files replaced atomically, and the check that a path can be written.
pub use output::atomic::{check_writable, write_atomically};

/// Render parts: a piece of a frame and its exact sums, as EXR.
pub use output::part::{read_part, read_part_info, write_part, PartInfo, PartSums};

/// The one front door: a loaded scene and a caller's settings as a plan
/// of the render, the settings table both front ends offer, and the
/// finishing of a render (denoising, writing).
pub use request::{
    existing_part_differs, Asked, Denoised, Given, Note, Piece, Plan, Refused, Request,
    RequestError, Setting, Spelling, Takes, Written, SETTINGS,
};

/// How a rendered frame is written, its image written out, the checks on
/// its path, and the list of names of its id passes.
pub use output::frame::{
    check_output, names_path, partial_path, write_names_beside, FrameImage, OutputLayer,
    OutputSettings,
};

/// Every error of this crate: one line naming the file and the place.
pub use sahara_readers::FormatError;
