//! Independent uniform random samples from a counter-based hash.

use glam::Vec2;

use super::SampleId;
use crate::math::hash::{hash3, mix64, unit_f32};

#[inline]
fn key(id: &SampleId, dim: u32) -> u64 {
    hash3(
        id.stream,
        ((id.pass as u64) << 32) | id.index as u64,
        dim as u64,
    )
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
