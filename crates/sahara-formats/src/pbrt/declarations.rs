//! What a pbrt file declares, after its directives have been run: every
//! entity with its parameters, the transforms in effect and where it was
//! written; nothing mapped to Sahara yet.

use std::collections::HashMap;
use std::path::PathBuf;

use glam::DMat4;

use super::params::ParamList;
use crate::common::position::Loc;
use crate::common::warnings::Warnings;

/// Reports the parameters of `e` nothing asked for.
pub(super) fn unknown_params(e: &Entity, what: &str, w: &mut Warnings) {
    for p in e.params.unused() {
        w.add(
            format!(
                "{what} '{}': unknown parameter \"{} {}\", ignored",
                e.kind, p.ty, p.name
            ),
            &p.loc,
        );
    }
}

/// A directive's type name (`"perspective"`, `"trianglemesh"`, ...) with its parameters.
#[derive(Clone, Debug)]
pub(crate) struct Entity {
    /// The type named in the directive.
    pub(crate) kind: String,
    /// Its parameters (with `Attribute` defaults appended).
    pub(crate) params: ParamList,
    /// Where the directive is.
    pub(crate) loc: Loc,
    /// The folders relative file names in it are looked up in, first to last.
    pub(crate) folders: Vec<PathBuf>,
}

/// The transform in effect: at the start and the end of `TransformTimes`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Xform {
    /// Matrices at the two times (object to world; for the camera, world to camera).
    pub(crate) m: [DMat4; 2],
}

impl Xform {
    /// True if the two matrices differ (the object moves).
    pub(crate) fn is_animated(&self) -> bool {
        self.m[0] != self.m[1]
    }
}

/// Which material a shape uses.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum MaterialRef {
    /// pbrt's default (diffuse, reflectance 0.5).
    Default,
    /// A `Material` directive: index into [`Declarations::materials`].
    Anonymous(usize),
    /// A `NamedMaterial` directive.
    Named(String, Loc),
}

/// A `Shape` with the state it was declared in.
#[derive(Clone, Debug)]
pub(crate) struct ShapeDecl {
    /// The shape.
    pub(crate) entity: Entity,
    /// Object to world.
    pub(crate) xform: Xform,
    /// `ReverseOrientation` in effect.
    pub(crate) reverse: bool,
    /// Its material.
    pub(crate) material: MaterialRef,
    /// The `AreaLightSource` in effect, if any.
    pub(crate) area_light: Option<Entity>,
    /// The `MediumInterface` in effect, if any.
    pub(crate) media: Option<MediaDecl>,
}

/// A `MediumInterface`: the media named inside and outside the surfaces
/// declared after it (`""`: vacuum).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MediaDecl {
    /// The medium behind the surface (against its normal).
    pub(crate) inside: String,
    /// The medium in front of the surface.
    pub(crate) outside: String,
    /// Where the directive is.
    pub(crate) loc: Loc,
}

/// A `MakeNamedMedium`.
#[derive(Clone, Debug)]
pub(crate) struct MediumDecl {
    /// The name it is given.
    pub(crate) name: String,
    /// Its parameters (the type is `"string type"`).
    pub(crate) entity: Entity,
    /// Medium to world: the transform in effect where it is declared.
    pub(crate) xform: Xform,
}

/// An `ObjectInstance`.
#[derive(Clone, Debug)]
pub(crate) struct InstanceDecl {
    /// The object's name.
    pub(crate) name: String,
    /// Instance to world.
    pub(crate) xform: Xform,
    /// Where the directive is.
    pub(crate) loc: Loc,
}

/// A `Texture`.
#[derive(Clone, Debug)]
pub(crate) struct TextureDecl {
    /// The texture class and its parameters.
    pub(crate) entity: Entity,
}

/// A `LightSource`.
#[derive(Clone, Debug)]
pub(crate) struct LightDecl {
    /// The light.
    pub(crate) entity: Entity,
    /// Light to world.
    pub(crate) xform: Xform,
}

/// Everything a pbrt file declares.
#[derive(Clone, Debug, Default)]
pub(crate) struct Declarations {
    /// `Camera` and the world-to-camera transform when it was given.
    pub(crate) camera: Option<(Entity, Xform)>,
    /// `Film`.
    pub(crate) film: Option<Entity>,
    /// `Sampler`.
    pub(crate) sampler: Option<Entity>,
    /// `PixelFilter`.
    pub(crate) filter: Option<Entity>,
    /// `Integrator`.
    pub(crate) integrator: Option<Entity>,
    /// `Accelerator`, `ColorSpace`, `Option` and other directives that change nothing Sahara
    /// renders, as (directive, where), for one warning each.
    pub(crate) ignored: Vec<(String, Loc)>,
    /// `Material` directives, in order.
    pub(crate) materials: Vec<Entity>,
    /// `MakeNamedMaterial`, by name (a later definition replaces an earlier one).
    pub(crate) named_materials: HashMap<String, Entity>,
    /// `Texture`, by name and kind (float textures and spectrum textures
    /// have separate name spaces).
    pub(crate) textures: HashMap<(String, bool), TextureDecl>,
    /// `Shape`s outside object definitions.
    pub(crate) shapes: Vec<ShapeDecl>,
    /// `ObjectBegin` ... `ObjectEnd`: the shapes of each object, by name.
    pub(crate) objects: HashMap<String, (Vec<ShapeDecl>, Loc)>,
    /// `ObjectInstance`s.
    pub(crate) instances: Vec<InstanceDecl>,
    /// `LightSource`s.
    pub(crate) lights: Vec<LightDecl>,
    /// `MakeNamedMedium`s, in order (a later one of the same name
    /// replaces an earlier one).
    pub(crate) media: Vec<MediumDecl>,
    /// The `MediumInterface` in effect at `Camera` (its outside medium
    /// holds the camera).
    pub(crate) camera_medium: Option<MediaDecl>,
    /// `TransformTimes` (default 0 and 1).
    pub(crate) transform_times: (f64, f64),
}
