//! Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen
//! Scrambling", via the `sobol_burley` crate).
//!
//! Every dimension of the renderer draws Sobol dimensions 0 (and 1 for 2D
//! draws), whose 2D projection is a (0, 2)-sequence, under a scramble and
//! index shuffle seeded by (pixel stream, dimension). So each draw is as well
//! stratified as the first two Sobol dimensions, and different dimensions
//! are decorrelated by their seeds. The sample index runs on across passes,
//! so a progressive render keeps the stratification of all its samples.
//!
//! The values are exactly those of `sobol_burley::sample(index, 0 | 1,
//! seed)`, computed more cheaply: what depends only on the pixel sample
//! (the index, its bit reversal, the first half of the seed hash) is done
//! once per pixel sample in [`SobolSample::new`]; a 2D draw shuffles its
//! index once for both coordinates; and the two Sobol dimensions are
//! evaluated in closed form instead of by a walk over direction vectors.

use glam::Vec2;
use sobol_burley::parts::{hash, owen_scramble_rev, u32_to_f32_norm};

use super::SampleId;
use crate::hash::mix64;

/// Samples per sequence that `sobol_burley` supports.
const MAX_INDEX: u32 = 1 << 16;

/// The key `crate::hash::hash2` xors into its first word, so that
/// `hash2(a, b) == mix64(mix64(a ^ HASH2_KEY) + b)` (checked by a test).
const HASH2_KEY: u64 = 0x9e37_79b9_7f4a_7c15;

// Constants of `sobol_burley::sample` (version 0.5): the index-shuffle key,
// the seed multiplier, and the per-dimension scramble keys of Sobol
// dimensions 0 and 1. The tests compare against `sobol_burley::sample`.
const SHUFFLE_KEY: u32 = 0x79c6_8e4a;
const SEED_MUL: u32 = 0x9c8f_2d3b;
const DIM0_KEY: u32 = 0x912f_69ba;
const DIM1_KEY: u32 = 0x174f_18ab;

/// The per-pixel-sample part of every draw of one pixel sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SobolSample {
    /// The sample index in its sequence, bit-reversed.
    index_rev: u32,
    /// The inner half of `hash2(stream ^ (epoch << 40), dim)`.
    stream_key: u64,
}

impl SobolSample {
    /// The state of pixel sample `id`.
    #[inline]
    pub fn new(id: &SampleId) -> Self {
        let global = id.pass as u64 * id.count as u64 + id.index as u64;
        // Past 2^16 samples a new, independent sequence starts.
        let epoch = global / MAX_INDEX as u64;
        let index = (global % MAX_INDEX as u64) as u32;
        Self {
            index_rev: index.reverse_bits(),
            stream_key: mix64(id.stream ^ (epoch << 40) ^ HASH2_KEY),
        }
    }

    /// The scramble seed of dimension `dim`.
    #[inline(always)]
    fn seed(&self, dim: u32) -> u32 {
        let s = mix64(self.stream_key.wrapping_add(dim as u64));
        (s ^ (s >> 32)) as u32
    }

    /// The shuffled sample index under `seed` (16 bits, not reversed).
    #[inline(always)]
    fn shuffled_index(&self, seed: u32) -> u32 {
        let rev = owen_scramble_rev(self.index_rev, hash(seed ^ SHUFFLE_KEY));
        // Only the top 16 bits of the reversed index enter the sequence.
        (rev & 0xffff_0000).reverse_bits()
    }

    /// One scrambled Sobol number for dimension `dim`.
    #[inline]
    pub fn get_1d(&self, dim: u32) -> f32 {
        let seed = self.seed(dim);
        let n = self.shuffled_index(seed);
        scramble(sobol0_rev(n), seed, DIM0_KEY)
    }

    /// One scrambled 2D Sobol point for dimension `dim`.
    #[inline]
    pub fn get_2d(&self, dim: u32) -> Vec2 {
        let seed = self.seed(dim);
        let n = self.shuffled_index(seed);
        Vec2::new(
            scramble(sobol0_rev(n), seed, DIM0_KEY),
            scramble(sobol1_rev(n), seed, DIM1_KEY),
        )
    }
}

/// Sobol dimension 0 (van der Corput) of the 16-bit index `n`, bit-reversed:
/// output bit `31 - i` is index bit `i`, so reversed it is the index.
#[inline(always)]
fn sobol0_rev(n: u32) -> u32 {
    n
}

/// Sobol dimension 1 of the 16-bit index `n`, bit-reversed. Its generator
/// matrix is Pascal's triangle mod 2: output bit `31 - i` is the xor of the
/// index bits `j` with `binom(j, i)` odd, i.e. (Lucas) with `i` a submask of
/// `j`. That superset sum over the four bits of a bit position takes four
/// shift-and-xor steps.
#[inline(always)]
fn sobol1_rev(mut n: u32) -> u32 {
    n ^= (n >> 1) & 0x5555;
    n ^= (n >> 2) & 0x3333;
    n ^= (n >> 4) & 0x0f0f;
    n ^= (n >> 8) & 0x00ff;
    n
}

/// Owen-scrambles the bit-reversed Sobol value `sobol_rev` of one dimension
/// (`key` that dimension's constant) and maps it to `[0, 1)`.
#[inline(always)]
fn scramble(sobol_rev: u32, seed: u32, key: u32) -> f32 {
    let s = hash(seed.wrapping_mul(SEED_MUL) ^ key);
    u32_to_f32_norm(owen_scramble_rev(sobol_rev, s).reverse_bits())
}

/// One scrambled Sobol number for dimension `dim`.
#[inline]
pub fn get_1d(id: &SampleId, dim: u32) -> f32 {
    SobolSample::new(id).get_1d(dim)
}

/// One scrambled 2D Sobol point for dimension `dim`.
#[inline]
pub fn get_2d(id: &SampleId, dim: u32) -> Vec2 {
    SobolSample::new(id).get_2d(dim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::hash2;

    /// The straightforward form: the seed hashed per draw and every
    /// coordinate from `sobol_burley::sample`.
    fn reference(id: &SampleId, dim: u32) -> (f32, f32) {
        let global = id.pass as u64 * id.count as u64 + id.index as u64;
        let epoch = global / MAX_INDEX as u64;
        let seed = hash2(id.stream ^ (epoch << 40), dim as u64);
        let (i, seed) = (
            (global % MAX_INDEX as u64) as u32,
            (seed ^ (seed >> 32)) as u32,
        );
        (
            sobol_burley::sample(i, 0, seed),
            sobol_burley::sample(i, 1, seed),
        )
    }

    #[test]
    fn hash2_splits_at_its_key() {
        for (a, b) in [
            (0u64, 0u64),
            (1, 2),
            (u64::MAX, 12345),
            (0xdead_beef, 1 << 40),
        ] {
            assert_eq!(hash2(a, b), mix64(mix64(a ^ HASH2_KEY).wrapping_add(b)));
        }
    }

    #[test]
    fn closed_form_dimensions_match_the_direction_vectors() {
        // Every 16-bit index: the top 16 bits of the reversed index are all
        // that `sobol_rev` reads.
        for n in 0..MAX_INDEX {
            let rev = n.reverse_bits();
            assert_eq!(sobol0_rev(n), sobol_burley::parts::sobol_rev(rev, 0), "{n}");
            assert_eq!(sobol1_rev(n), sobol_burley::parts::sobol_rev(rev, 1), "{n}");
        }
    }

    #[test]
    fn same_values_as_sobol_burley() {
        let mut ids = Vec::new();
        for stream in [0u64, 99, 0x1234_5678_9abc_def0, u64::MAX] {
            for (pass, count) in [(0u32, 64u32), (3, 16), (1, 1), (5000, 20)] {
                for index in 0..count.min(64) {
                    ids.push(SampleId {
                        stream,
                        pass,
                        index,
                        count,
                    });
                }
            }
        }
        let dims = [
            0u32,
            1,
            2,
            3,
            12,
            200,
            0x4000_0000 | (3 << 24) | (5 << 12) | 7,
        ];
        for id in &ids {
            let s = SobolSample::new(id);
            for &dim in &dims {
                let (x, y) = reference(id, dim);
                let p = s.get_2d(dim);
                assert_eq!(p.x.to_bits(), x.to_bits(), "{id:?} dim {dim}");
                assert_eq!(p.y.to_bits(), y.to_bits(), "{id:?} dim {dim}");
                assert_eq!(s.get_1d(dim).to_bits(), x.to_bits(), "{id:?} dim {dim}");
            }
        }
    }

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
