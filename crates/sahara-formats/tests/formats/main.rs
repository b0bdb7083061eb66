//! Tests for `sahara-formats`: PLY, OBJ, camera sidecars and the shared scenes.

mod camera;
mod common;
mod obj;
mod ply;
mod scenes;
