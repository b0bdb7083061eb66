//! A scene file's render settings as renderer values.

use std::path::PathBuf;

use sahara_render::{Filter, Integrator, SamplerKind, ToneMap};

use crate::scene_file::{
    FilmSpec, FilterSpec, IntegratorSpec, SamplerKind as SamplerSpecKind, SamplerSpec, ToneMapSpec,
};

/// How a scene file asks to be rendered (`[integrator]`, `[sampler]`, `[filter]`, `[film]`).
#[derive(Clone, Debug, PartialEq)]
pub struct FileSettings {
    /// Light transport with its parameters.
    pub integrator: Integrator,
    /// Sample generator.
    pub sampler: SamplerKind,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of every random decision.
    pub seed: u64,
    /// Reconstruction filter.
    pub filter: Filter,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Exposure in stops.
    pub exposure: f32,
    /// Tone map for 8-bit output.
    pub tonemap: ToneMap,
    /// Output image, resolved relative to the scene file, if the file names one.
    pub output: Option<PathBuf>,
}

impl FileSettings {
    /// The settings of a parsed scene file.
    pub fn from_specs(
        integrator: &IntegratorSpec,
        sampler: &SamplerSpec,
        filter: &FilterSpec,
        film: &FilmSpec,
    ) -> Self {
        Self {
            integrator: integrator_of(integrator),
            sampler: match sampler.kind {
                SamplerSpecKind::Independent => SamplerKind::Independent,
                SamplerSpecKind::Stratified => SamplerKind::Stratified,
                SamplerSpecKind::Sobol => SamplerKind::Sobol,
            },
            spp: sampler.spp,
            seed: sampler.seed,
            filter: filter_of(filter),
            width: film.width,
            height: film.height,
            exposure: film.exposure,
            tonemap: match film.tonemap {
                ToneMapSpec::Clamp => ToneMap::Clamp,
                ToneMapSpec::Filmic => ToneMap::Filmic,
            },
            output: film.output.clone(),
        }
    }
}

/// The renderer's integrator for an `[integrator]` table.
pub fn integrator_of(spec: &IntegratorSpec) -> Integrator {
    match *spec {
        IntegratorSpec::Distribution {
            max_depth,
            light_samples,
        } => Integrator::Distribution {
            max_depth,
            light_samples,
        },
        IntegratorSpec::Path {
            max_depth,
            rr_depth,
        } => Integrator::Path {
            max_depth,
            rr_depth,
        },
        IntegratorSpec::Normals => Integrator::Normals,
        IntegratorSpec::Depth => Integrator::Depth,
        IntegratorSpec::Ao { samples, distance } => Integrator::Ao { samples, distance },
        IntegratorSpec::Cost => Integrator::Cost,
    }
}

/// The renderer's filter for a `[filter]` table.
pub fn filter_of(spec: &FilterSpec) -> Filter {
    match *spec {
        FilterSpec::Box { radius } => Filter::Box { radius },
        FilterSpec::Tent { radius } => Filter::Tent { radius },
        FilterSpec::Gaussian { radius, sigma } => Filter::Gaussian { radius, sigma },
        FilterSpec::Mitchell { radius, b, c } => Filter::Mitchell { radius, b, c },
    }
}
