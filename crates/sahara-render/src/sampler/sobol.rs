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
use crate::math::hash::mix64;

/// Samples per sequence that `sobol_burley` supports.
const MAX_INDEX: u32 = 1 << 16;

/// The key `crate::math::hash::hash2` xors into its first word, so that
/// `hash2(a, b) == mix64(mix64(a ^ HASH2_KEY) + b)` (checked by a test).
const HASH2_KEY: u64 = 0x9e37_79b9_7f4a_7c15;

// Constants of `sobol_burley::sample` (version 0.5): the index-shuffle key,
// the seed multiplier, and the per-dimension scramble keys of Sobol
// dimensions 0 and 1. The tests compare against `sobol_burley::sample`.
const SHUFFLE_KEY: u32 = 0x79c6_8e4a;
const SEED_MUL: u32 = 0x9c8f_2d3b;
pub(super) const DIM0_KEY: u32 = 0x912f_69ba;
pub(super) const DIM1_KEY: u32 = 0x174f_18ab;

/// The per-pixel-sample part of every draw of one pixel sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SobolSample {
    /// The sample index in its sequence, bit-reversed.
    pub(super) index_rev: u32,
    /// The inner half of `hash2(stream ^ (epoch << 40), dim)`.
    pub(super) stream_key: u64,
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
    pub(super) fn seed(&self, dim: u32) -> u32 {
        let s = mix64(self.stream_key.wrapping_add(dim as u64));
        (s ^ (s >> 32)) as u32
    }

    /// The shuffled sample index under `seed` (16 bits, not reversed).
    #[inline(always)]
    pub(super) fn shuffled_index(&self, seed: u32) -> u32 {
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
pub(super) fn sobol0_rev(n: u32) -> u32 {
    n
}

/// Sobol dimension 1 of the 16-bit index `n`, bit-reversed. Its generator
/// matrix is Pascal's triangle mod 2: output bit `31 - i` is the xor of the
/// index bits `j` with `binom(j, i)` odd, i.e. (Lucas) with `i` a submask of
/// `j`. That superset sum over the four bits of a bit position takes four
/// shift-and-xor steps.
#[inline(always)]
pub(super) fn sobol1_rev(mut n: u32) -> u32 {
    n ^= (n >> 1) & 0x5555;
    n ^= (n >> 2) & 0x3333;
    n ^= (n >> 4) & 0x0f0f;
    n ^= (n >> 8) & 0x00ff;
    n
}

/// Owen-scrambles the bit-reversed Sobol value `sobol_rev` of one dimension
/// (`key` that dimension's constant) and maps it to `[0, 1)`.
#[inline(always)]
pub(super) fn scramble(sobol_rev: u32, seed: u32, key: u32) -> f32 {
    let s = hash(seed.wrapping_mul(SEED_MUL) ^ key);
    u32_to_f32_norm(owen_scramble_rev(sobol_rev, s).reverse_bits())
}

/// One scrambled 2D Sobol point for dimension `dim` (the renderer draws
/// through [`SobolSample`], which scrambles once per pixel sample).
#[cfg(test)]
fn get_2d(id: &SampleId, dim: u32) -> Vec2 {
    SobolSample::new(id).get_2d(dim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::hash::hash2;

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

    /// Whether `points` (2^k of them) put exactly one point in each
    /// elementary interval `[i / 2^a, (i + 1) / 2^a) x [j / 2^b, (j + 1) /
    /// 2^b)` of every shape `a + b = k`: the (0, k, 2)-net property.
    fn is_0_k_2_net(points: &[Vec2], k: u32) -> Result<(), String> {
        assert_eq!(points.len(), 1 << k);
        for a in 0..=k {
            let b = k - a;
            let mut hit = vec![false; 1 << k];
            for (n, p) in points.iter().enumerate() {
                let (cx, cy) = (p.x * (1u32 << a) as f32, p.y * (1u32 << b) as f32);
                let cell = cx as usize + (cy as usize) * (1 << a);
                if hit[cell] {
                    return Err(format!(
                        "2^{a} x 2^{b} cell {cell} holds a second point, {n}"
                    ));
                }
                hit[cell] = true;
            }
        }
        Ok(())
    }

    #[test]
    fn first_2_to_the_k_points_of_a_pixel_are_stratified() {
        // As the renderer draws them: samples of a pixel in passes of
        // `count`, through `PixelSampler`, for the camera dimensions, the
        // per-bounce blocks and the many-sample dimensions; also across the
        // start of the second 2^16-sample sequence.
        use super::super::{dims, PixelSampler, SamplerKind};
        let dimensions = [
            dims::FILM,
            dims::LENS,
            dims::TIME,
            dims::bounce(0, dims::LIGHT_POINT),
            dims::bounce(0, dims::BSDF_DIR),
            dims::bounce(7, dims::ROULETTE),
            dims::extra(2, 3, 5),
        ];
        let count = 8;
        for pixel in 0..6u64 {
            let stream = hash2(pixel / 3, pixel);
            let first_pass = if pixel % 3 == 2 { MAX_INDEX / count } else { 0 };
            for &dim in &dimensions {
                for k in 0..=12 {
                    let points: Vec<Vec2> = (0..1u32 << k)
                        .map(|n| {
                            let id = SampleId {
                                stream,
                                pass: first_pass + n / count,
                                index: n % count,
                                count,
                            };
                            PixelSampler::new(SamplerKind::Sobol, id).get_2d(dim)
                        })
                        .collect();
                    if let Err(e) = is_0_k_2_net(&points, k) {
                        panic!("pixel {pixel}, dimension {dim}, 2^{k} points: {e}");
                    }
                    // A 1D draw is the first coordinate of the 2D one.
                    for (n, p) in points.iter().enumerate() {
                        let id = SampleId {
                            stream,
                            pass: first_pass + n as u32 / count,
                            index: n as u32 % count,
                            count,
                        };
                        let x = PixelSampler::new(SamplerKind::Sobol, id).get_1d(dim);
                        assert_eq!(x.to_bits(), p.x.to_bits());
                    }
                }
            }
        }
    }

    #[test]
    fn the_net_check_catches_a_broken_sequence() {
        // The second coordinate of dimension 1 taken from a different seed
        // than the first (a plausible bug) is no longer a net.
        let points: Vec<Vec2> = (0..64u32)
            .map(|i| Vec2::new(sobol_burley::sample(i, 0, 5), sobol_burley::sample(i, 1, 6)))
            .collect();
        assert!(is_0_k_2_net(&points, 6).is_err());
        let points: Vec<Vec2> = (0..64u32)
            .map(|i| Vec2::new(sobol_burley::sample(i, 0, 5), sobol_burley::sample(i, 1, 5)))
            .collect();
        assert!(is_0_k_2_net(&points, 6).is_ok());
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
