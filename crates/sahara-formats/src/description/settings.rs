//! How a scene file asks to be rendered, in the renderer's values.

use std::path::PathBuf;

use sahara_render::{Adaptive, Filter, Integrator, PixelWindow, SamplerKind, ToneMap};

/// How a scene file asks to be rendered: light transport, sampling,
/// filter and film (a TOML file's `[integrator]`, `[sampler]`, `[filter]`
/// and `[film]`; pbrt's `Integrator`, `Sampler`, `PixelFilter` and `Film`).
#[derive(Clone, Debug, PartialEq)]
pub struct FileSettings {
    /// Light transport with its parameters.
    pub integrator: Integrator,
    /// Sample generator.
    pub sampler: SamplerKind,
    /// Samples per pixel (the cap, with adaptive sampling).
    pub spp: u32,
    /// Adaptive sampling, if the file asks for it.
    pub adaptive: Option<Adaptive>,
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
    /// Output image as the file names it (relative to the working folder
    /// unless absolute), if it names one.
    pub output: Option<PathBuf>,
    /// The part of the image to render, if the file asks for one.
    pub crop: Option<FileCrop>,
    /// Denoise the image (with Intel Open Image Denoise).
    pub denoise: bool,
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
            FileCrop::Fractions(f) => sahara_render::crop(width, height, f),
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
