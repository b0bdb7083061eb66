//! What a scene file describes, as every scene reader gives it: the
//! [`SceneDescription`]. [`crate::assembly`] turns it into a renderer
//! scene.
//!
//! A description holds plain values: the renderer's cameras, materials,
//! lights, shapes and meshes where those are values, and references
//! where assembly has work to do. Mesh files are named, not loaded (the
//! assembly loads each once, however many objects show it); objects say
//! where they are and which material they wear, but not whether they
//! become an exact shape or a tessellated one; the camera may be left to
//! the assembly, and so may the sky. Nothing in it is indexed by the
//! renderer's scene.
//!
//! Every reader fills the same fields: TOML scene files
//! ([`crate::toml`]), pbrt ([`crate::pbrt`]), Mitsuba ([`crate::mitsuba`])
//! and bare mesh files ([`crate::mesh`]). The Mitsuba reader, for one,
//! maps its shapes (`rectangle`, `cube`, `sphere`, `disk` as
//! [`Geometry::Shape`]; `obj`, `ply` and `serialized`, read as it reads
//! the scene, as [`Geometry::Mesh`]), its bsdfs as
//! [`SceneDescription::materials`], its emitters (area: an object with an
//! emissive material; point and spot as [`SceneDescription::lights`];
//! `envmap` and `constant` as [`SceneDescription::environment`]), its
//! sensor as [`CameraRequest::Given`] and its integrator and sampler as
//! [`SettingsLayer`].

mod settings;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Affine3A;
use sahara_render::{
    Camera, Environment, Light, Material, Medium, MediumInterface, SceneMesh, Shape, Srt,
};

pub use settings::{FileCrop, PieceLayer, SettingsLayer, Split};

/// A scene as a file describes it, before assembly.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    /// What messages call the scene: its file.
    pub name: String,
    /// How the scene is seen.
    pub camera: CameraRequest,
    /// The materials objects refer to by index, in the order the
    /// renderer's scene numbers them.
    pub materials: Vec<Material>,
    /// The names the file gives materials, by index into
    /// [`SceneDescription::materials`] (for the `material` render pass's
    /// list of names; unnamed ones are named by the assembly).
    pub material_names: BTreeMap<u32, String>,
    /// Meshes given in the file itself (pbrt's triangle meshes and
    /// object definitions), referred to by index by [`Geometry::Mesh`];
    /// their per-triangle material ids are indices into
    /// [`SceneDescription::materials`].
    pub meshes: Vec<SceneMesh>,
    /// What the scene holds, in order.
    pub objects: Vec<Object>,
    /// Point, spot and directional lights, in order (a mesh file's own
    /// lights come with the file).
    pub lights: Vec<Light>,
    /// Light from infinitely far away, if the file gives it.
    pub environment: Option<Environment>,
    /// What lights the scene besides its own lights (the `auto` rule of
    /// [`crate::assembly::sky`] is applied by the assembly).
    pub sky: Sky,
    /// How the file asks to be rendered (`None`: a file that does not
    /// say, as a bare mesh).
    pub settings: Option<SettingsLayer>,
    /// Participating media, referred to by index by `camera_medium` and
    /// `medium_interfaces`.
    pub media: Vec<Medium>,
    /// The medium the camera sits in.
    pub camera_medium: Option<u32>,
    /// The media on the two sides of objects' surfaces: the object's
    /// index into [`SceneDescription::objects`], and the media.
    pub medium_interfaces: Vec<(u32, MediumInterface)>,
    /// Problems found while reading that did not stop it, one line each,
    /// naming the file.
    pub warnings: Vec<String>,
}

impl SceneDescription {
    /// An empty description of the file `name`: no camera (the automatic
    /// one), no sky, no settings.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            camera: CameraRequest::Automatic,
            materials: Vec::new(),
            material_names: BTreeMap::new(),
            meshes: Vec::new(),
            objects: Vec::new(),
            lights: Vec::new(),
            environment: None,
            sky: Sky::None,
            settings: None,
            media: Vec::new(),
            camera_medium: None,
            medium_interfaces: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Adds a material; returns its index.
    pub fn add_material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        self.materials.len() as u32 - 1
    }

    /// Adds a material named `name` in the file; returns its index.
    pub fn add_named_material(&mut self, name: impl Into<String>, m: Material) -> u32 {
        let id = self.add_material(m);
        self.material_names.insert(id, name.into());
        id
    }

    /// Adds a mesh; returns its index.
    pub fn add_mesh(&mut self, m: SceneMesh) -> u32 {
        self.meshes.push(m);
        self.meshes.len() as u32 - 1
    }
}

/// How a scene is seen.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraRequest {
    /// This camera (its aspect as the file knows it; the command line
    /// sets it from the image size).
    Given {
        /// The camera.
        camera: Camera,
        /// What the log calls it: a sidecar's path, or empty for the
        /// file's own camera.
        source: String,
    },
    /// The camera of this name among those the scene's mesh files bring
    /// (glTF cameras).
    Named(String),
    /// The first camera the scene's mesh files bring, else one framing
    /// the scene's bounds (`crate::assembly::camera`).
    Automatic,
}

/// Something the scene holds: geometry placed in the world, with a material.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// What it is.
    pub geometry: Geometry,
    /// Where it is.
    pub placement: ObjectPlacement,
    /// Index into [`SceneDescription::materials`]; `None`: the
    /// geometry's own materials (a mesh file's MTL or glTF materials, a
    /// mesh's per-triangle ids), or the grey default where it has none.
    pub material: Option<u32>,
    /// The name the file gives it, if any (for the `object` render
    /// pass's list of names).
    pub name: Option<String>,
}

/// An object's geometry.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// A mesh file (`.obj`, `.ply`, `.gltf`, `.glb`), with its own
    /// materials, cameras and lights; loaded once however many objects
    /// show it.
    File(PathBuf),
    /// A built-in shape, kept exact where its placement allows (so an
    /// emissive quad, disc or sphere is sampled analytically).
    Shape(Shape),
    /// Mesh `i` of [`SceneDescription::meshes`], shared by every object
    /// showing it.
    Mesh(u32),
}

/// Where an object is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ObjectPlacement {
    /// Where its geometry says: its coordinates are the world's (a bare
    /// mesh file, an area light given in world space).
    World,
    /// Placed by an object-to-world transform.
    Static(Affine3A),
    /// Moving from `open` to `close` over the shutter interval.
    Moving {
        /// Object to world when the shutter opens.
        open: Srt,
        /// Object to world when the shutter closes.
        close: Srt,
    },
}

impl ObjectPlacement {
    /// True if the object moves.
    pub fn is_moving(&self) -> bool {
        matches!(self, ObjectPlacement::Moving { .. })
    }
}

/// What lights a scene besides its own lights.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sky {
    /// The default sky and sun if the scene's own lights are weak.
    Auto,
    /// The default sky and sun.
    Default,
    /// Nothing.
    None,
    /// An equirectangular environment map.
    Map(PathBuf),
}

impl Sky {
    /// `auto`, `default`, `none`, or an image file's path (relative paths
    /// taken from `base`).
    pub fn parse(s: &str, base: &Path) -> Sky {
        match s {
            "auto" => Sky::Auto,
            "default" => Sky::Default,
            "none" => Sky::None,
            path => Sky::Map(base.join(path)),
        }
    }
}
