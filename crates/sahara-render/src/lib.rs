//! `sahara-render`: Sahara's renderer. It knows meshes as plain arrays,
//! never as files: scenes come in as Rust values ([`Scene`]), images go out
//! as float buffers ([`Film`]).
//!
//! ```
//! use sahara_render::{builtin, render, RenderSettings};
//!
//! let scene = builtin::cornell_box();
//! let settings = RenderSettings { width: 16, height: 16, spp: 4, ..Default::default() };
//! let result = render(&scene, &settings, &|_| {});
//! assert_eq!(result.film.pixels.len(), 256);
//! assert_eq!(result.stats.nan_samples, 0);
//! ```

#![deny(missing_docs)]

pub mod accel;
pub mod builtin;
pub mod camera;
mod cpu_time;
pub mod digest;
pub mod distribution;
pub mod film;
pub mod filter;
pub mod hash;
pub mod instance;
pub mod integrator;
pub mod light;
pub mod material;
pub mod mesh;
pub mod names;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod shape;
pub mod split;
pub mod sums;
mod tangents;
pub mod texture;
pub mod world;

pub use camera::Camera;
pub use film::{Film, ToneMap};
pub use filter::{Filter, FilterKind};
pub use instance::{Instance, Placement, Srt};
pub use integrator::{Integrator, IntegratorKind};
pub use light::{Environment, Light};
pub use material::{AlphaMode, Bsdf, Material, MaterialTextures};
pub use mesh::{Mesh, SceneMesh};
pub use names::{Named, UnknownName};
pub use render::{
    cost_maps, render, render_watched, CostMaps, Preview, Progress, RenderResult, RenderSettings,
    RenderStats,
};
pub use sampler::SamplerKind;
pub use scene::Scene;
pub use shape::{Shape, ShapeKind};
pub use split::PixelWindow;
pub use sums::{PixelSum, SumBuffer};
pub use texture::{Texture, TextureMap};
