//! A scene file's render settings as renderer values.

use std::path::PathBuf;

use sahara_render::{Filter, Integrator, PixelWindow, SamplerKind, ToneMap};

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
    /// The part of the image to render, if the file asks for one.
    pub crop: Option<FileCrop>,
}

/// The pixels a scene file asks to render (pbrt's film `cropwindow` and
/// `pixelbounds`), resolved against the image size when that is known.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FileCrop {
    /// `x0, x1, y0, y1` as fractions of the image, y from the top: pixels
    /// `ceil(x0 W)..ceil(x1 W)`, `ceil(y0 H)..ceil(y1 H)` (pbrt-v4's rule).
    Fractions([f64; 4]),
    /// Pixels `x0..x1`, `y0..y1`, clipped to the image.
    Pixels([i64; 4]),
}

impl FileCrop {
    /// The pixels of a `width x height` image this crop keeps (may be empty).
    pub fn window(&self, width: u32, height: u32) -> PixelWindow {
        match *self {
            FileCrop::Fractions(f) => sahara_render::split::crop(width, height, f),
            FileCrop::Pixels([x0, x1, y0, y1]) => {
                let clip = |v: i64, size: u32| v.clamp(0, i64::from(size)) as u32;
                let (x0, y0) = (clip(x0, width), clip(y0, height));
                PixelWindow {
                    x0,
                    x1: clip(x1, width).max(x0),
                    y0,
                    y1: clip(y1, height).max(y0),
                }
            }
        }
    }
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
            crop: None,
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
