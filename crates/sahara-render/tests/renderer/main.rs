//! Tests of `sahara-render`: the render loop, integrators, lighting, textures, cameras, split and adaptive renders, what each integrator supports.
//!
//! One test binary for the crate's integration tests, each file a module:
//! every test binary is compiled and linked (with LTO) on its own, so one
//! binary instead of one per file saves most of the test build.

mod adaptive;
mod bad_scenes;
mod bidirectional;
mod camera;
mod common;
mod energy;
mod guiding;
mod lanes;
mod light_choice;
mod lighting;
mod photons;
mod render_loop;
mod split_render;
mod supports;
mod textures;
