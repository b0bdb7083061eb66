//! Tests for `sahara-readers`: OBJ/MTL, PLY and glTF meshes, camera sidecars.

mod camera;
mod common;
mod gltf;
mod gltf_data;
mod obj;
mod obj_materials;
mod ply;
