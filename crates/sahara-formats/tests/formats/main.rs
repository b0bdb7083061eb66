//! Tests for `sahara-formats`: bad input to the readers, glTF extensions, scene files and their conversion to renderer scenes, images in and out, and the shared scenes.

// Its counting allocator is the whole binary's global allocator; it only
// notes each thread's largest allocation.
mod bad_input;
mod bitterli_gallery;
// Shared with `sahara-readers`' tests (one copy of the helpers).
mod blocks;
mod bsdf_reference;
#[path = "../../../sahara-readers/tests/readers/common.rs"]
mod common;
#[path = "../../../sahara-readers/tests/readers/gltf_data.rs"]
mod gltf_data;
mod gltf_extensions;
mod image_in;
mod image_out;
mod media_reference;
mod mitsuba_kit;
mod scene_load;
mod scenes;
