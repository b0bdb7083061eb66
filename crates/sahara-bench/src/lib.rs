//! `sahara-bench`: the ray-casting benchmark protocol of
//! `docs/bench-protocol.md` on Sahara's kd-tree.
//!
//! The crate reads no scene files: it takes a [`sahara_kd::Mesh`]
//! and, optionally, a camera, and
//! - generates the protocol's four ray sets bit for bit as the reference
//!   program `shared/bench/embree/embree_bench.c` does ([`protocol`]),
//! - reads and writes the protocol's ray and hit files ([`files`]),
//! - traces, times and counts ([`runner`]) and reports the results as plain
//!   serialisable structs ([`report`]);
//! - walks the binary tree node by node for the counts of its examples
//!   ([`walk`]).
//!
//! One ray's result is a [`record::HitRecord`], the hit file's record.

#![warn(missing_docs)]

pub mod files;
pub mod protocol;
pub mod record;
pub mod report;
pub mod runner;
pub mod walk;

pub use protocol::{ImageSize, ProtocolCamera, SceneFrame, SetKind, SplitMix64};
pub use record::HitRecord;
pub use runner::Query;
