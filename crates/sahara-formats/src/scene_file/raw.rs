//! The TOML shape of a scene file, as serde reads it, before any check.
//!
//! Every table rejects unknown keys. Values that are checked later are kept
//! `Spanned` so an error can point at their line and column. Tables whose
//! keys depend on a `type` (materials, objects, lights) list the union of
//! all types' keys; which apply to which type is checked in `resolve`.

use serde::Deserialize;
use toml::Spanned;

/// An optional value with its position in the file.
pub(super) type Opt<T> = Option<Spanned<T>>;

/// Three numbers.
pub(super) type V3 = [f32; 3];

/// The whole file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    pub sky: Opt<String>,
    pub camera: Option<Spanned<RawCamera>>,
    #[serde(default)]
    pub material: Vec<Spanned<RawMaterial>>,
    #[serde(default)]
    pub object: Vec<Spanned<RawObject>>,
    #[serde(default)]
    pub light: Vec<Spanned<RawLight>>,
    pub integrator: Option<Spanned<RawIntegrator>>,
    pub sampler: Option<Spanned<RawSampler>>,
    pub filter: Option<Spanned<RawFilter>>,
    pub film: Option<Spanned<RawFilm>>,
}

/// `[camera]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCamera {
    pub eye: Spanned<V3>,
    pub target: Spanned<V3>,
    pub up: Opt<V3>,
    pub vfov: Opt<f32>,
    pub aperture_radius: Opt<f32>,
    pub focus_distance: Opt<f32>,
    pub shutter_open: Opt<f32>,
    pub shutter_close: Opt<f32>,
}

/// Material kinds (`type` of a `[[material]]`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum MaterialType {
    Diffuse,
    #[serde(alias = "glossy")]
    Conductor,
    Mirror,
    Dielectric,
    RoughDielectric,
    ThinDielectric,
    MetallicRoughness,
    CoatedDiffuse,
    Emission,
}

/// `[[material]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMaterial {
    pub name: Spanned<String>,
    #[serde(rename = "type")]
    pub kind: Spanned<MaterialType>,
    pub albedo: Opt<V3>,
    pub texture: Opt<String>,
    pub color: Opt<V3>,
    pub roughness: Opt<f32>,
    pub ior: Opt<f32>,
    pub radiance: Opt<V3>,
    pub two_sided: Opt<bool>,
    pub metal: Opt<String>,
    pub eta: Opt<V3>,
    pub k: Opt<V3>,
    pub base_color: Opt<V3>,
    pub metallic: Opt<f32>,
    pub specular: Opt<f32>,
    pub specular_color: Opt<V3>,
    pub alpha: Opt<f32>,
    pub alpha_mode: Opt<AlphaModeName>,
    pub alpha_cutoff: Opt<f32>,
}

/// `alpha_mode` of a `[[material]]`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum AlphaModeName {
    Opaque,
    Mask,
    Blend,
}

/// Shape kinds (`type` of an `[[object]]`, `shape` of an area light).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum ShapeType {
    Mesh,
    Quad,
    Disc,
    Sphere,
    Box,
}

/// `[[object]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawObject {
    #[serde(rename = "type")]
    pub kind: Spanned<ShapeType>,
    pub file: Opt<String>,
    pub corner: Opt<V3>,
    pub edge_u: Opt<V3>,
    pub edge_v: Opt<V3>,
    pub center: Opt<V3>,
    pub normal: Opt<V3>,
    pub radius: Opt<f32>,
    pub min: Opt<V3>,
    pub max: Opt<V3>,
    pub material: Opt<String>,
    pub transform: Opt<RawTransform>,
    pub motion: Opt<RawMotion>,
}

/// A uniform (`scale = 2`) or per-axis (`scale = [1, 2, 1]`) scale.
#[derive(Clone, Copy, Deserialize)]
#[serde(untagged)]
pub(super) enum RawScale {
    Uniform(f32),
    PerAxis(V3),
}

/// `transform = { translate, rotate, scale }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawTransform {
    pub translate: Opt<V3>,
    pub rotate: Opt<RawRotate>,
    pub scale: Opt<RawScale>,
}

/// `rotate = { axis = [x, y, z], degrees = d }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRotate {
    pub axis: V3,
    pub degrees: f32,
}

/// `motion = { open = {transform}, close = {transform} }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMotion {
    pub open: Spanned<RawTransform>,
    pub close: Spanned<RawTransform>,
}

/// Light kinds (`type` of a `[[light]]`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum LightType {
    Point,
    Spot,
    Directional,
    Area,
    Environment,
}

/// `[[light]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLight {
    #[serde(rename = "type")]
    pub kind: Spanned<LightType>,
    pub position: Opt<V3>,
    pub target: Opt<V3>,
    pub direction: Opt<V3>,
    pub intensity: Opt<V3>,
    pub irradiance: Opt<V3>,
    pub inner_angle: Opt<f32>,
    pub outer_angle: Opt<f32>,
    pub radiance: Opt<V3>,
    pub two_sided: Opt<bool>,
    pub shape: Opt<ShapeType>,
    pub corner: Opt<V3>,
    pub edge_u: Opt<V3>,
    pub edge_v: Opt<V3>,
    pub center: Opt<V3>,
    pub normal: Opt<V3>,
    pub radius: Opt<f32>,
    pub map: Opt<String>,
    pub scale: Opt<f32>,
    pub material: Opt<String>,
}

/// Integrator names.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum IntegratorName {
    Distribution,
    Path,
    Normals,
    Depth,
    Ao,
    Cost,
}

/// `[integrator]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawIntegrator {
    pub name: Spanned<IntegratorName>,
    pub max_depth: Opt<i64>,
    pub rr_depth: Opt<i64>,
    pub light_samples: Opt<i64>,
    pub samples: Opt<i64>,
    pub distance: Opt<f32>,
}

/// Sampler names.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum SamplerName {
    Independent,
    Stratified,
    Sobol,
}

/// `[sampler]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSampler {
    pub name: Opt<SamplerName>,
    pub spp: Opt<i64>,
    pub seed: Opt<i64>,
}

/// Filter names.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum FilterName {
    Box,
    Tent,
    Gaussian,
    Mitchell,
}

/// `[filter]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFilter {
    pub name: Spanned<FilterName>,
    pub radius: Opt<f32>,
    pub sigma: Opt<f32>,
    pub b: Opt<f32>,
    pub c: Opt<f32>,
}

/// Tone mapping curves.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum ToneMapName {
    Clamp,
    Filmic,
}

/// `[film]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFilm {
    pub width: Spanned<i64>,
    pub height: Spanned<i64>,
    pub exposure: Opt<f32>,
    pub tonemap: Opt<ToneMapName>,
    pub output: Opt<String>,
}
