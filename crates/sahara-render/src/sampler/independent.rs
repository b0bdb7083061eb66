//! Independent uniform random samples from a counter-based hash.

use glam::Vec2;

use super::SampleId;
use crate::math::hash::{hash3, mix64, unit_f32};

#[inline]
fn key(id: &SampleId, dim: u32) -> u64 {
    key_of(id.stream, ((id.pass as u64) << 32) | id.index as u64, dim)
}

/// The hash of a draw from its stream, `pass << 32 | index`, and
/// dimension.
#[inline(always)]
pub(crate) fn key_of(stream: u64, pass_index: u64, dim: u32) -> u64 {
    hash3(stream, pass_index, dim as u64)
}

/// One uniform number for dimension `dim`.
#[inline]
pub fn get_1d(id: &SampleId, dim: u32) -> f32 {
    unit_f32(key(id, dim))
}

/// A uniform point for dimension `dim`.
#[inline]
pub fn get_2d(id: &SampleId, dim: u32) -> Vec2 {
    let h = key(id, dim);
    Vec2::new(unit_f32(h), unit_f32(mix64(h)))
}
