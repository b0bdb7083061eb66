//! Tests of `sahara-kd`: builders and queries against brute force, watertightness, limits, bad input.
//!
//! One test binary for the crate's integration tests, each file a module:
//! every test binary is compiled and linked (with LTO) on its own, so one
//! binary instead of one per file saves most of the test build.

mod bad_input;
mod box_tree;
mod brute_force_agreement;
mod common;
mod limits;
mod watertight;
