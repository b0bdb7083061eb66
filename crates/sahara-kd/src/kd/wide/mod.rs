//! Wide kd nodes: a traversal form derived from the binary tree, three of
//! its levels in one 64-byte node whose seven planes a ray is tested
//! against at once (see `node` for the layout, `walk` for the walk).
//!
//! The binary 8-byte nodes stay the tree's reference form: every builder
//! makes them, the packet walks, statistics and the validator read them,
//! and the wide nodes are derived from them after the build. The wide walk
//! visits every cell the binary walk visits, so both give the same hits
//! (the property tests hold both to brute force).

mod interleave;
mod node;
mod walk;

pub(crate) use node::{derive, WideNode};
