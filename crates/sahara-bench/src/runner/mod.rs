//! Tracing, timing and counting ray sets on a kd-tree.
//!
//! [`Bench`] ties it together: it builds the tree (best of
//! [`BUILD_RUNS`]), owns a 1-thread and an N-thread rayon pool, and measures
//! sets into [`crate::report`] structs.

pub mod bench;
pub mod build;
pub mod counters;
pub mod packets;
pub mod pools;
pub mod throughput;
pub mod trace;

pub use bench::Bench;
pub use build::{build_timed, BUILD_RUNS};
pub use counters::{count_set, CountTotals};
pub use packets::{measure_packets, PacketMeasurement, PacketSize};
pub use pools::Pools;
pub use throughput::{measure, Measurement};
pub use trace::{trace_into, Query, CHUNK};
