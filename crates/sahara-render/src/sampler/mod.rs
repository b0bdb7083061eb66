//! Sample generators and the assignment of sample dimensions.
//!
//! Samplers here are stateless: a value is a pure function of a
//! [`SampleId`] and a dimension. Each dimension is consumed by exactly one
//! 1D or 2D draw and is stratified on its own over a pixel's samples (the
//! "padded" construction), so every distributed effect (film position, lens,
//! time, light choice and position, BSDF lobe and direction at every bounce)
//! receives a well-stratified set whatever the path length.

pub mod independent;
pub(crate) mod lanes;
pub mod sobol;
pub mod stratified;

use glam::Vec2;

use crate::names::name_table;

/// Which sample generator fills the dimensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum SamplerKind {
    /// Independent uniform random numbers.
    Independent,
    /// Jittered strata per dimension (2D grids for 2D draws), strata shuffled
    /// per dimension; stratified within each pass.
    Stratified,
    /// Owen-scrambled Sobol points (Burley 2020), one independent scramble
    /// per dimension; stratified across all passes.
    #[default]
    Sobol,
}

name_table!(SamplerKind, "sampler", {
    SamplerKind::Independent => "independent",
    SamplerKind::Stratified => "stratified",
    SamplerKind::Sobol => "sobol",
});

/// Identity of one pixel sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleId {
    /// Hash of (render seed, pixel): the pixel's own random stream.
    pub stream: u64,
    /// Progressive pass.
    pub pass: u32,
    /// Sample index within the pass.
    pub index: u32,
    /// Samples per pixel in each pass.
    pub count: u32,
}

/// The sampler of one pixel sample: the draw functions of a [`SamplerKind`]
/// bound to a [`SampleId`], with what the generator can compute once per
/// pixel sample rather than once per draw.
#[derive(Clone, Copy, Debug)]
pub struct PixelSampler {
    kind: SamplerKind,
    id: SampleId,
    sobol: sobol::SobolSample,
}

impl PixelSampler {
    /// The sampler of pixel sample `id` under generator `kind`.
    #[inline]
    pub fn new(kind: SamplerKind, id: SampleId) -> Self {
        let sobol = match kind {
            SamplerKind::Sobol => sobol::SobolSample::new(&id),
            _ => sobol::SobolSample::default(),
        };
        Self { kind, id, sobol }
    }

    /// The generator.
    #[inline]
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// The sample.
    #[inline]
    pub fn id(&self) -> SampleId {
        self.id
    }

    /// The Sobol generator's per-sample state (default for the others).
    #[inline]
    pub(crate) fn sobol(&self) -> sobol::SobolSample {
        self.sobol
    }

    /// One number in `[0, 1)` for dimension `dim`.
    #[inline]
    pub fn get_1d(&self, dim: u32) -> f32 {
        match self.kind {
            SamplerKind::Independent => independent::get_1d(&self.id, dim),
            SamplerKind::Stratified => stratified::get_1d(&self.id, dim),
            SamplerKind::Sobol => self.sobol.get_1d(dim),
        }
    }

    /// A point in `[0, 1)^2` for dimension `dim`.
    #[inline]
    pub fn get_2d(&self, dim: u32) -> Vec2 {
        match self.kind {
            SamplerKind::Independent => independent::get_2d(&self.id, dim),
            SamplerKind::Stratified => stratified::get_2d(&self.id, dim),
            SamplerKind::Sobol => self.sobol.get_2d(dim),
        }
    }
}

/// The fixed assignment of dimensions to the decisions of a path.
pub mod dims {
    /// Film position in the pixel (2D).
    pub const FILM: u32 = 0;
    /// Point on the lens (2D).
    pub const LENS: u32 = 1;
    /// Time in the shutter interval (1D).
    pub const TIME: u32 = 2;
    /// First dimension of the per-bounce blocks.
    const BOUNCE_BASE: u32 = 3;
    /// Dimensions reserved per bounce.
    const PER_BOUNCE: u32 = 8;
    /// Which light next-event estimation samples (1D).
    pub const LIGHT_PICK: u32 = 0;
    /// Point on the chosen light (2D).
    pub const LIGHT_POINT: u32 = 1;
    /// BSDF lobe choice (1D).
    pub const BSDF_LOBE: u32 = 2;
    /// BSDF direction (2D).
    pub const BSDF_DIR: u32 = 3;
    /// Russian roulette (1D).
    pub const ROULETTE: u32 = 4;

    /// Dimension `offset` of bounce `depth`'s block.
    #[inline]
    pub const fn bounce(depth: u32, offset: u32) -> u32 {
        BOUNCE_BASE + depth * PER_BOUNCE + offset
    }

    /// Dimension of the `k`-th of several samples of light `light` at bounce
    /// `depth` (the distribution integrator and ambient occlusion draw many
    /// per vertex); kept far above the per-bounce blocks.
    #[inline]
    pub const fn extra(depth: u32, light: u32, k: u32) -> u32 {
        0x4000_0000 | (depth << 24) | ((light & 0xfff) << 12) | (k & 0xfff)
    }
}
