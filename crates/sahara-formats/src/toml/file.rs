//! Scene files as read: TOML describing camera, materials, objects,
//! lights and render settings, checked into a [`SceneFile`].
//!
//! The format is documented in `docs/scene-format.md` at the repository
//! root; in short:
//!
//! ```toml
//! [camera]                       # required
//! eye = [0, 1, 5]                # required
//! target = [0, 1, 0]             # required
//! up = [0, 1, 0]                 # default [0, 1, 0]
//! vfov = 40                      # vertical field of view, degrees; default 45
//! aperture_radius = 0.05         # lens radius; default 0 (pinhole)
//! focus_distance = 5             # default: |target - eye|
//! shutter_open = 0               # default 0
//! shutter_close = 1              # default 0 (no motion blur)
//!
//! [[material]]                   # named; objects refer to them by name
//! name = "red"
//! type = "diffuse"               # a material kind: docs/scene-format.md lists them
//! albedo = [0.6, 0.1, 0.1]
//!
//! [[object]]
//! type = "mesh"                  # mesh | quad | disc | sphere | box
//! file = "bunny.obj"             # relative to this scene file
//! material = "red"               # optional: overrides the mesh's own materials
//! transform = { translate = [0, 0, 0], rotate = { axis = [0, 1, 0], degrees = 30 }, scale = 2 }
//!
//! [[light]]
//! type = "point"                 # a light kind: docs/scene-format.md lists them
//! position = [0, 5, 0]
//! intensity = [10, 10, 10]
//!
//! [integrator]
//! name = "path"                  # distribution | path | normals | depth | ao | cost
//! max_depth = 8
//!
//! [sampler]
//! name = "sobol"                 # independent | stratified | sobol
//! spp = 64
//! seed = 0
//!
//! [filter]
//! name = "gaussian"              # box | tent | gaussian | mitchell
//! radius = 1.5
//!
//! [film]                         # required
//! width = 640
//! height = 480
//! exposure = 0                   # stops: pixels are scaled by 2^exposure
//! tonemap = "clamp"              # clamp | filmic
//! output = "out.png"             # .png or .exr, relative to the working folder
//! ```
//!
//! Unknown keys, keys that do not apply to an entry's `type`, and values
//! out of range are errors; every error names the file, the line and column.
//! Input file paths are resolved relative to the scene file's folder; the
//! output relative to the working folder (unless absolute).

use std::path::PathBuf;

use glam::{Mat4, Quat, Vec3};
use sahara_render::{Light, Material, Medium, MediumInterface, Shape};

use crate::description::SettingsLayer;

/// A parsed and checked scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    /// What lights the scene besides its lights (`sky = "auto"`,
    /// `"default"`, `"none"` or an image file; `none` when absent).
    pub sky: crate::description::Sky,
    /// The camera.
    pub camera: CameraSpec,
    /// The medium the camera sits in (`[camera] medium`), by index into
    /// `media`.
    pub camera_medium: Option<u32>,
    /// Named media, in file order.
    pub media: Vec<MediumSpec>,
    /// Named materials, in file order.
    pub materials: Vec<MaterialSpec>,
    /// Objects, in file order.
    pub objects: Vec<ObjectSpec>,
    /// Lights, in file order (at most one environment).
    pub lights: Vec<LightSpec>,
    /// The render settings the file gives (`[integrator]`, `[sampler]`,
    /// `[filter]`, `[film]`): the keys given, the rest left to the
    /// defaults; an `[integrator]` or `[filter]` table's parameters not
    /// given take the renderer's defaults for the kind.
    pub settings: SettingsLayer,
}

/// `[camera]`: a thin-lens camera with a shutter interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpec {
    /// Position of the lens centre.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up direction (not parallel to `target - eye`).
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub vfov_deg: f32,
    /// Lens radius (0: pinhole).
    pub aperture_radius: f32,
    /// Distance from the eye to the plane in focus (> 0).
    pub focus_distance: f32,
    /// Time the shutter opens.
    pub shutter_open: f32,
    /// Time the shutter closes (>= `shutter_open`).
    pub shutter_close: f32,
}

/// `[[material]]`: a named material.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialSpec {
    /// The name objects use to refer to it (unique in the file).
    pub name: String,
    /// The material its kind built from its keys (without its texture).
    pub material: Material,
    /// The texture file (resolved; exists) multiplying its kind's
    /// textured key (`texture`), if given.
    pub texture: Option<PathBuf>,
}

/// `[[object]]`: a shape, its material and where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectSpec {
    /// The geometry.
    pub shape: ShapeSpec,
    /// Name of a `[[material]]` (checked to exist); `None`: the mesh's own materials, or a default.
    pub material: Option<String>,
    /// Object-to-world placement.
    pub placement: Placement,
    /// Its name, for the `object` render pass's list of names.
    pub name: Option<String>,
    /// The media inside and outside its surface (indices into
    /// [`SceneFile::media`]), if it bounds any.
    pub interface: Option<MediumInterface>,
}

/// `[[medium]]`: a named participating medium.
#[derive(Clone, Debug, PartialEq)]
pub struct MediumSpec {
    /// The name objects and the camera use to refer to it (unique).
    pub name: String,
    /// The medium (a grid's density read from its file).
    pub medium: Medium,
}

/// Geometry: a mesh file or a built-in shape.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeSpec {
    /// A mesh file (`.obj`, `.ply`, `.gltf`, `.glb`), resolved relative to the scene file (exists).
    Mesh {
        /// The resolved path.
        path: PathBuf,
    },
    /// A quad, disc, sphere or box in the object's own space (a disc's
    /// normal made unit; a quad's edges not parallel; a box's `max` above
    /// its `min` on every axis).
    Builtin(Shape),
}

/// Where an object is: fixed, or moving linearly over the shutter interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// One transform (identity when the object has no `transform`).
    Static(TransformSpec),
    /// `motion`: the transform at shutter open and at shutter close.
    Motion {
        /// Transform when the shutter opens.
        open: TransformSpec,
        /// Transform when the shutter closes.
        close: TransformSpec,
    },
}

/// Scale, then rotate about an axis through the origin, then translate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransformSpec {
    /// Translation.
    pub translate: Vec3,
    /// Unit rotation axis.
    pub rotate_axis: Vec3,
    /// Rotation angle in degrees (right-handed about `rotate_axis`).
    pub rotate_deg: f32,
    /// Per-axis scale (no component zero).
    pub scale: Vec3,
}

impl TransformSpec {
    /// The identity transform.
    pub const IDENTITY: TransformSpec = TransformSpec {
        translate: Vec3::ZERO,
        rotate_axis: Vec3::Y,
        rotate_deg: 0.0,
        scale: Vec3::ONE,
    };

    /// The matrix `T * R * S`.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(
            self.scale,
            Quat::from_axis_angle(self.rotate_axis, self.rotate_deg.to_radians()),
            self.translate,
        )
    }
}

/// `[[light]]`.
#[derive(Clone, Debug, PartialEq)]
pub enum LightSpec {
    /// A point, spot or directional light.
    Explicit(Light),
    /// An emitting quad, disc or sphere.
    Area {
        /// The shape (never a mesh or box).
        shape: ShapeSpec,
        /// Emitted radiance (>= 0).
        radiance: Vec3,
        /// Emit from both faces.
        two_sided: bool,
        /// Name of a `[[material]]` (checked to exist) the light's surface
        /// scatters with besides emitting; `None`: black but for its emission.
        material: Option<String>,
    },
    /// Light from infinitely far away in every direction.
    Environment(EnvironmentSpec),
}

/// The environment: one colour, or an equirectangular map.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSpec {
    /// The same radiance everywhere.
    Constant(Vec3),
    /// A lat-long image (`.hdr`, `.exr`, `.png`, `.jpg`), resolved and existing, scaled by `scale`.
    Map {
        /// The image file.
        path: PathBuf,
        /// Radiance multiplier (> 0, default 1).
        scale: f32,
    },
}
