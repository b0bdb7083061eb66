//! Tests for `sahara-formats`: meshes, materials, glTF, scene files and their conversion to renderer scenes, images, camera sidecars and the shared scenes.

mod camera;
mod common;
mod gltf;
mod gltf_extensions;
mod image_in;
mod image_out;
mod obj;
mod obj_materials;
mod ply;
mod scene_file;
mod scene_load;
mod scenes;
