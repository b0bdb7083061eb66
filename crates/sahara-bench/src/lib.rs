//! `sahara-bench`: the ray-casting benchmark protocol.
