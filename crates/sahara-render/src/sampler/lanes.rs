//! The draws of `N` pixel samples at once, one sample a lane: the same
//! numbers, bit for bit, as each sample's [`PixelSampler`] draws alone.
//!
//! Sobol and independent draws are integer hashes and a conversion, done in
//! the lanes (64-bit multiplies included). A stratified draw shuffles its
//! stratum by cycle-walking a permutation, a loop whose length depends on
//! the lane: it is drawn lane by lane through [`PixelSampler`].

use super::independent;
use super::sobol::{scramble, sobol0_rev, sobol1_rev, DIM0_KEY, DIM1_KEY};
use super::{PixelSampler, SampleId, SamplerKind};
use crate::math::hash::{mix64, unit_f32};
use crate::math::lanes::{F, U, U64};

/// The samplers of `N` lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SamplerLanes<const N: usize> {
    kind: SamplerKind,
    /// Sobol: each lane's bit-reversed index.
    index_rev: U<N>,
    /// Sobol: each lane's stream key; independent: each lane's stream.
    key: U64<N>,
    /// Independent: each lane's pass and index (`pass << 32 | index`).
    pass_index: U64<N>,
    /// Each lane's sampler (the stratified draws).
    samplers: [PixelSampler; N],
}

impl<const N: usize> SamplerLanes<N> {
    /// Lanes of generator `kind`, each the first sample of stream 0 until
    /// set.
    pub fn new(kind: SamplerKind) -> Self {
        let s = PixelSampler::new(
            kind,
            SampleId {
                stream: 0,
                pass: 0,
                index: 0,
                count: 1,
            },
        );
        let mut lanes = Self {
            kind,
            index_rev: U([0; N]),
            key: U64([0; N]),
            pass_index: U64([0; N]),
            samplers: [s; N],
        };
        for i in 0..N {
            lanes.set(i, &s);
        }
        lanes
    }

    /// Lane `i` draws as `s` (of this generator).
    #[inline]
    pub fn set(&mut self, i: usize, s: &PixelSampler) {
        debug_assert_eq!(s.kind(), self.kind);
        let id = s.id();
        match self.kind {
            SamplerKind::Sobol => {
                let sobol = s.sobol();
                self.index_rev.0[i] = sobol.index_rev;
                self.key.0[i] = sobol.stream_key;
            }
            SamplerKind::Independent => {
                self.key.0[i] = id.stream;
                self.pass_index.0[i] = ((id.pass as u64) << 32) | id.index as u64;
            }
            SamplerKind::Stratified => {}
        }
        self.samplers[i] = *s;
    }

    /// Lane `i`'s sampler.
    #[inline]
    pub fn get(&self, i: usize) -> PixelSampler {
        self.samplers[i]
    }

    /// Each lane's scramble seed of its dimension (Sobol).
    #[inline(always)]
    fn sobol_seed(&self, dim: U<N>) -> U<N> {
        let mut seed = U([0; N]);
        for i in 0..N {
            let s = mix64(self.key.0[i].wrapping_add(dim.0[i] as u64));
            seed.0[i] = (s ^ (s >> 32)) as u32;
        }
        seed
    }

    /// Each lane's shuffled index under its seed (Sobol).
    #[inline(always)]
    fn sobol_index(&self, seed: U<N>) -> U<N> {
        let mut n = U([0; N]);
        for i in 0..N {
            let s = super::sobol::SobolSample {
                index_rev: self.index_rev.0[i],
                stream_key: 0,
            };
            n.0[i] = s.shuffled_index(seed.0[i]);
        }
        n
    }

    /// Each lane's hash key of its dimension (independent).
    #[inline(always)]
    fn independent_key(&self, dim: U<N>) -> U64<N> {
        let mut h = U64([0; N]);
        for i in 0..N {
            h.0[i] = independent::key_of(self.key.0[i], self.pass_index.0[i], dim.0[i]);
        }
        h
    }

    /// One number in `[0, 1)` per lane, for each lane's dimension.
    #[inline(always)]
    pub fn get_1d(&self, dim: U<N>) -> F<N> {
        let mut x = F::splat(0.0);
        match self.kind {
            SamplerKind::Sobol => {
                let seed = self.sobol_seed(dim);
                let n = self.sobol_index(seed);
                for i in 0..N {
                    x.0[i] = scramble(sobol0_rev(n.0[i]), seed.0[i], DIM0_KEY);
                }
            }
            SamplerKind::Independent => {
                let h = self.independent_key(dim);
                for i in 0..N {
                    x.0[i] = unit_f32(h.0[i]);
                }
            }
            SamplerKind::Stratified => {
                for i in 0..N {
                    x.0[i] = self.samplers[i].get_1d(dim.0[i]);
                }
            }
        }
        x
    }

    /// A point in `[0, 1)^2` per lane, for each lane's dimension.
    #[inline(always)]
    pub fn get_2d(&self, dim: U<N>) -> (F<N>, F<N>) {
        let mut x = F::splat(0.0);
        let mut y = F::splat(0.0);
        match self.kind {
            SamplerKind::Sobol => {
                let seed = self.sobol_seed(dim);
                let n = self.sobol_index(seed);
                for i in 0..N {
                    x.0[i] = scramble(sobol0_rev(n.0[i]), seed.0[i], DIM0_KEY);
                    y.0[i] = scramble(sobol1_rev(n.0[i]), seed.0[i], DIM1_KEY);
                }
            }
            SamplerKind::Independent => {
                let h = self.independent_key(dim);
                for i in 0..N {
                    x.0[i] = unit_f32(h.0[i]);
                    y.0[i] = unit_f32(mix64(h.0[i]));
                }
            }
            SamplerKind::Stratified => {
                for i in 0..N {
                    let p = self.samplers[i].get_2d(dim.0[i]);
                    x.0[i] = p.x;
                    y.0[i] = p.y;
                }
            }
        }
        (x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::dims;

    /// Every generator's lane draws are its samplers' draws, bit for bit,
    /// whatever dimension each lane asks for.
    #[test]
    fn lanes_draw_what_each_sampler_draws() {
        for kind in [
            SamplerKind::Sobol,
            SamplerKind::Independent,
            SamplerKind::Stratified,
        ] {
            let mut lanes = SamplerLanes::<8>::new(kind);
            let samplers: Vec<PixelSampler> = (0..8u32)
                .map(|i| {
                    PixelSampler::new(
                        kind,
                        SampleId {
                            stream: 0x1234_5678 + 77 * (i as u64 % 3),
                            pass: i / 3,
                            index: i % 5,
                            count: 5,
                        },
                    )
                })
                .collect();
            for (i, s) in samplers.iter().enumerate() {
                lanes.set(i, s);
            }
            for depth in 0..4u32 {
                let dim = U(std::array::from_fn(|i| {
                    dims::bounce(depth + i as u32 % 2, dims::BSDF_DIR)
                }));
                let x = lanes.get_1d(dim);
                let (u, v) = lanes.get_2d(dim);
                for (i, s) in samplers.iter().enumerate() {
                    assert_eq!(x.0[i].to_bits(), s.get_1d(dim.0[i]).to_bits());
                    let p = s.get_2d(dim.0[i]);
                    assert_eq!(
                        (u.0[i].to_bits(), v.0[i].to_bits()),
                        (p.x.to_bits(), p.y.to_bits())
                    );
                }
            }
        }
    }
}
