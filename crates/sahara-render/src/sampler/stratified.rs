//! Jittered stratification: the `count` samples of a pixel in one pass fall
//! one per stratum, in an order shuffled independently per dimension (so
//! the strata of different dimensions are not correlated).

use glam::Vec2;

use super::SampleId;
use crate::math::hash::{hash3, mix64, permute, unit_f32};

#[inline]
fn dim_key(id: &SampleId, dim: u32) -> u64 {
    hash3(id.stream, id.pass as u64, dim as u64)
}

/// One jittered-stratified number for dimension `dim`.
pub fn get_1d(id: &SampleId, dim: u32) -> f32 {
    let key = dim_key(id, dim);
    let n = id.count.max(1);
    let stratum = permute(id.index % n, n, key);
    let jitter = unit_f32(hash3(key, id.index as u64, 1));
    ((stratum as f32 + jitter) / n as f32).min(1.0 - f32::EPSILON * 0.5)
}

/// The grid `nx x ny = count` closest to square (nx the largest divisor of
/// `count` not above its square root).
fn grid(count: u32) -> (u32, u32) {
    let mut nx = (count as f64).sqrt() as u32;
    while nx > 1 && !count.is_multiple_of(nx) {
        nx -= 1;
    }
    let nx = nx.max(1);
    (nx, count / nx)
}

/// One jittered point of an `nx x ny` grid for dimension `dim`.
pub fn get_2d(id: &SampleId, dim: u32) -> Vec2 {
    let key = dim_key(id, dim);
    let n = id.count.max(1);
    let (nx, ny) = grid(n);
    let cell = permute(id.index % n, n, key);
    let h = hash3(key, id.index as u64, 2);
    let j = Vec2::new(unit_f32(h), unit_f32(mix64(h)));
    let p = Vec2::new(
        ((cell % nx) as f32 + j.x) / nx as f32,
        ((cell / nx) as f32 + j.y) / ny as f32,
    );
    p.min(Vec2::splat(1.0 - f32::EPSILON * 0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_per_stratum() {
        let count = 16;
        let mut hit = [false; 16];
        for index in 0..count {
            let id = SampleId {
                stream: 7,
                pass: 0,
                index,
                count,
            };
            let p = get_2d(&id, 5);
            let cell = (p.x * 4.0) as usize + 4 * (p.y * 4.0) as usize;
            assert!(!hit[cell]);
            hit[cell] = true;
        }
        assert_eq!(grid(12), (3, 4));
        assert_eq!(grid(7), (1, 7));
    }
}
