//! End-to-end tests of the `sahara` binary: commands, rendering, farms, signals, progress.
//!
//! One test binary for the crate's integration tests, each file a module:
//! every test binary is compiled and linked (with LTO) on its own, so one
//! binary instead of one per file saves most of the test build.

mod cli;
mod common;
mod farm;
mod mitsuba;
mod progress;
mod render;
mod signals;
