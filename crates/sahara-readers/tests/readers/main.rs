//! Tests for `sahara-readers`: OBJ/MTL, PLY and glTF meshes, images, camera sidecars.

mod camera;
mod common;
mod gltf;
mod gltf_data;
mod image_in;
mod obj;
mod obj_materials;
mod ply;
