//! Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen
//! Scrambling", via the `sobol_burley` crate).
//!
//! Every dimension of the renderer draws Sobol dimensions 0 (and 1 for 2D
//! draws), whose 2D projection is a (0, 2)-sequence, under a scramble and
//! index shuffle seeded by (pixel stream, dimension). So each draw is as well
//! stratified as the first two Sobol dimensions, and different dimensions
//! are decorrelated by their seeds. The sample index runs on across passes,
//! so a progressive render keeps the stratification of all its samples.

use glam::Vec2;

use super::SampleId;
use crate::hash::hash2;

/// Samples per sequence that `sobol_burley` supports.
const MAX_INDEX: u32 = 1 << 16;

#[inline]
fn index_and_seed(id: &SampleId, dim: u32) -> (u32, u32) {
    let global = id.pass as u64 * id.count as u64 + id.index as u64;
    // Past 2^16 samples a new, independent sequence starts.
    let epoch = global / MAX_INDEX as u64;
    let seed = hash2(id.stream ^ (epoch << 40), dim as u64);
    (
        (global % MAX_INDEX as u64) as u32,
        (seed ^ (seed >> 32)) as u32,
    )
}

/// One scrambled Sobol number for dimension `dim`.
#[inline]
pub fn get_1d(id: &SampleId, dim: u32) -> f32 {
    let (i, seed) = index_and_seed(id, dim);
    sobol_burley::sample(i, 0, seed)
}

/// One scrambled 2D Sobol point for dimension `dim`.
#[inline]
pub fn get_2d(id: &SampleId, dim: u32) -> Vec2 {
    let (i, seed) = index_and_seed(id, dim);
    Vec2::new(
        sobol_burley::sample(i, 0, seed),
        sobol_burley::sample(i, 1, seed),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_16_points_are_elementary_intervals() {
        // A (0, 2)-sequence puts one of 16 points in each 4x4 cell.
        let mut hit = [false; 16];
        for index in 0..16 {
            let id = SampleId {
                stream: 99,
                pass: 0,
                index,
                count: 16,
            };
            let p = get_2d(&id, 12);
            let cell = (p.x * 4.0) as usize + 4 * (p.y * 4.0) as usize;
            assert!(!hit[cell]);
            hit[cell] = true;
        }
    }
}
