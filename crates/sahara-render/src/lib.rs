//! `sahara-render`: Sahara's renderer. It knows meshes as plain arrays,
//! never as files: scenes come in as Rust values ([`Scene`]), images go out
//! as float buffers ([`Film`]) and exact per-pixel sums ([`SumBuffer`]).
//!
//! ```
//! use sahara_render::{builtin, render, FrameSettings, RenderSettings};
//!
//! let scene = builtin::cornell_box();
//! let frame = FrameSettings { width: 16, height: 16, spp: 4, ..Default::default() };
//! let settings = RenderSettings::from(frame);
//! let result = render(&scene, &settings, &|_| {})?;
//! assert_eq!(result.film.pixels.len(), 256);
//! assert_eq!(result.stats.nan_samples, 0);
//! # Ok::<(), sahara_render::SettingsError>(())
//! ```
//!
//! What each integrator supports beyond a whole frame (parts by pixels or
//! by samples, adaptive sampling, render passes and so denoising) is
//! declared by its kind ([`IntegratorKind::supports`]); a render asking
//! for more is refused with a [`SettingsError`] before it starts.
//!
//! The crate's parts, each importing only those before it in this list:
//! `math` (hashing, piecewise distributions, warps), `names` (the name
//! tables of settings) and `keys` (the keys of material and light
//! kinds); `texture`; `material`, `light`, `medium` and
//! `sampler`;
//! `scene` (camera, meshes, shapes, instances); `film` (the image,
//! reconstruction filters, exact sums, pixel windows) and `accel` (the
//! instances' kd-trees); `world` (the scene prepared for tracing);
//! `integrator` (light transport); `settings` (what a frame is, described
//! once, and the layers of it a scene file or a caller gives); `render`
//! (the render's settings, the loop of passes, tiles and strips with the
//! sample loops that trace a strip's samples, the frame digest). See
//! `docs/renderer.md` for the design.

#![deny(missing_docs)]

mod accel;
mod cpu_time;
mod film;
mod integrator;
mod keys;
mod light;
mod material;
mod math;
mod medium;
mod names;
mod render;
mod sampler;
mod scene;
mod settings;
mod texture;
mod world;

// The scene model.
pub use accel::AccelLayout;
pub use scene::builtin;
pub use scene::camera::Camera;
pub use scene::instance::{Instance, Placement, Srt};
pub use scene::mesh::{Mesh, SceneMesh};
pub use scene::shape::{Shape, ShapeKind};
pub use scene::{Scene, ShapeInstance};

// Materials, textures and lights.
pub use light::environment::{coordinates as environment_uv, direction as environment_direction};
pub use light::{Environment, Light, LightKind, LightOf, LightSampler, AREA_SHAPES};
pub use material::{
    fresnel, isotropic_mean, metals, roughness_from_alpha, AlphaMode, Bsdf, Clearcoat,
    Distribution, Material, MaterialKind, MaterialTextures, NormalMap, OcclusionMap,
};
pub use medium::{
    CloudMedium, ColourGrid, ColourVolume, DensityGrid, GridCoefficients, GridMedium,
    HenyeyGreenstein, Homogeneous, Medium, MediumInterface,
};
pub use texture::footprint::UvFootprint;
pub use texture::{
    linear_to_srgb8, srgb8_to_linear, srgb_to_linear, Channel, Encoding, ScalarMap, Texture,
    TextureMap, Wrap,
};

// How to render: the settings and their names.
pub use film::filter::{Filter, FilterKind};
pub use film::ToneMap;
pub use integrator::guiding::Guiding;
pub use integrator::{
    defaults, Feature, Integrator, IntegratorKind, LaneCounts, SettingsError, Support, Supports,
    TraceStats,
};
pub use keys::{Fallback, Key, KeyError, KeyType, Value, Values};
pub use names::{one_of, Accepts, Named, Parameter, UnknownName};
pub use render::{AdaptiveStats, PathLoop, RenderSettings, UNLIMITED_SPP};
pub use sampler::SamplerKind;
pub use settings::{Adaptive, AdaptiveChoice, Choice, FrameLayer, FrameSettings, Pick, Pickable};

// Rendering, and what comes out: the image, its exact sums, pieces of a frame.
pub use film::sums::{PixelSum, SumBuffer};
pub use film::window::{crop, sample_range, tile, PixelWindow};
pub use film::Film;
pub use math::warp::luminance;
pub use render::digest::frame_digest;
pub use render::{
    cost_maps, render, render_watched, Aov, Aux, AuxImages, AuxSums, CostMaps, Preview, Progress,
    RenderResult, RenderStats, TimeShares, TimeSplit,
};

/// Internals for the repository's tests and benchmarks: the scene prepared
/// for tracing and the samplers on their own. Not part of the API; may
/// change without notice.
#[doc(hidden)]
pub mod internals {
    pub use crate::math::hash::hash2;
    pub use crate::render::render_world;
    pub use crate::sampler::{dims, PixelSampler, SampleId};
    pub use crate::world::World;
}
