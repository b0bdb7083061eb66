//! The TOML shape of a scene file, as serde reads it, before any check.
//!
//! Every table rejects unknown keys. Values that are checked later are kept
//! `Spanned` so an error can point at their line and column. Objects list
//! the union of their shapes' keys (which apply to which shape is checked
//! in `resolve`); materials and lights are kept as tables of values, read
//! through the renderer's descriptions of their kinds.

use std::fmt;

use sahara_render::{Named, SamplerKind, ShapeKind, ToneMap};
use serde::{de, Deserialize, Deserializer};
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
    pub material: Vec<Spanned<RawDescribed>>,
    #[serde(default)]
    pub object: Vec<Spanned<RawObject>>,
    #[serde(default)]
    pub light: Vec<Spanned<RawDescribed>>,
    #[serde(default)]
    pub medium: Vec<Spanned<RawMedium>>,
    pub integrator: Option<Spanned<RawNamedTable>>,
    pub sampler: Option<Spanned<RawSampler>>,
    pub filter: Option<Spanned<RawNamedTable>>,
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
    pub medium: Opt<String>,
}

/// Medium kinds (`type` of a `[[medium]]`).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum MediumType {
    Homogeneous,
    Grid,
}

/// `[[medium]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMedium {
    pub name: Spanned<String>,
    #[serde(rename = "type")]
    pub kind: Spanned<MediumType>,
    pub sigma_a: Opt<V3>,
    pub sigma_s: Opt<V3>,
    pub scale: Opt<f32>,
    pub g: Opt<f32>,
    pub emission: Opt<V3>,
    pub emission_scale: Opt<f32>,
    pub file: Opt<String>,
    pub grid: Opt<String>,
    pub min: Opt<V3>,
    pub max: Opt<V3>,
}

/// A setting's value read by its name in the renderer's name table, so an
/// unknown name is an error at its place that lists the names there are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Name<T>(pub T);

impl<'de, T: Named> Deserialize<'de> for Name<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        T::from_name(&name).map(Name).map_err(de::Error::custom)
    }
}

/// What an `[[object]]` is (`type`), and an area light's `shape`: a mesh
/// file or one of the renderer's built-in shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ShapeType {
    Mesh,
    Builtin(ShapeKind),
}

impl<'de> Deserialize<'de> for ShapeType {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        if name == "mesh" {
            return Ok(ShapeType::Mesh);
        }
        ShapeKind::from_name(&name)
            .map(ShapeType::Builtin)
            .map_err(|_| {
                let mut names = vec!["mesh"];
                names.extend(ShapeKind::names());
                de::Error::custom(format!(
                    "unknown shape '{name}'; expected {}",
                    sahara_render::one_of(&names)
                ))
            })
    }
}

impl fmt::Display for ShapeType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShapeType::Mesh => f.write_str("mesh"),
            ShapeType::Builtin(kind) => kind.fmt(f),
        }
    }
}

/// `[[object]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawObject {
    #[serde(rename = "type")]
    pub kind: Spanned<ShapeType>,
    pub name: Opt<String>,
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
    pub medium_inside: Opt<String>,
    pub medium_outside: Opt<String>,
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

/// `[sampler]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSampler {
    pub name: Opt<Name<SamplerKind>>,
    pub spp: Opt<i64>,
    pub seed: Opt<i64>,
    pub noise_threshold: Opt<f32>,
    pub min_spp: Opt<i64>,
}

/// A table whose keys depend on a setting named in it (`[filter]`: `name`
/// and the named filter's parameters, which the renderer lists), with the
/// position of every value.
pub(super) type RawNamedTable = std::collections::BTreeMap<String, Spanned<toml::Value>>;

/// A table of a kind the renderer describes (`[[material]]`,
/// `[[light]]`): `type`, the kind's keys and the few the reader reads
/// itself, with the position of every value.
pub(super) type RawDescribed = RawNamedTable;

/// `[film]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFilm {
    pub width: Spanned<i64>,
    pub height: Spanned<i64>,
    pub exposure: Opt<f32>,
    pub tonemap: Opt<Name<ToneMap>>,
    pub output: Opt<String>,
    pub denoise: Opt<bool>,
}
