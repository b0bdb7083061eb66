//! A [`SceneDescription`] as a renderer [`Scene`]: the one step every
//! scene reader's output goes through.
//!
//! - Materials are numbered as the description numbers them; a mesh
//!   file's own materials (and the grey default, for geometry without
//!   one) follow, added when first needed.
//! - Mesh files are loaded once each by a [`MeshLibrary`], however many
//!   objects show them; objects only add instances (a glTF file one per
//!   node, placed by the object's placement times the node's). A file's
//!   materials are loaded if some object shows it with them; its lights
//!   come where the object puts the file (where it starts, if it moves).
//! - A static built-in shape whose transform maps it onto a shape of the
//!   same kind (any affine map for a quad; uniform scale for a disc or
//!   sphere; no rotation for a box) is transformed exactly and added with
//!   [`Scene::add_shape`], so an emissive quad, disc or sphere is sampled
//!   analytically as an area light; other shapes become a tessellated
//!   mesh with an instance transform.
//! - The camera is the description's, a named camera of its mesh files,
//!   or, when it leaves the choice to the assembly, the files' first
//!   camera, else the automatic one ([`camera`]).
//! - The sky follows [`sky`]: with `auto`, the default sky and sun
//!   light the scene only if its own lights are weak.
//! - Moving emissive objects are seen but not sampled as lights; that is
//!   a warning.
//! - An object's media (inside and outside its surface) go on every
//!   instance it adds.

pub(crate) mod camera;
pub(crate) mod sky;

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use glam::{Affine3A, Mat4, Vec3};
use sahara_readers::gltf::GltfCamera;
use sahara_render::{Camera, Instance, MediumInterface, Placement, Scene, SceneMesh, Shape, Srt};

use crate::description::{
    CameraRequest, Geometry, Object, ObjectPlacement, SceneDescription, SettingsLayer,
};
use crate::gltf::{gltf_camera, gltf_light};
use crate::mesh::library::{file_key, MeshLibrary};
use camera::has_finite_triangles;
use sky::SkyUsed;

use camera::{auto_camera_framing, View, AUTO_VFOV_DEG};
use sahara_readers::FormatError;

/// A scene ready to render, with what assembling it decided.
#[derive(Clone, Debug)]
pub struct AssembledScene {
    /// The scene (the camera's aspect as the description gave it, 1 for
    /// a camera the assembly chose: the caller sets it from the image
    /// size).
    pub scene: Scene,
    /// How the file asks to be rendered, if it says.
    pub settings: Option<SettingsLayer>,
    /// Where the camera came from: the description's source for a given
    /// camera, a glTF camera (`file: camera 'name'`), or `auto`.
    pub camera_source: String,
    /// What lights the scene besides its own lights.
    pub sky: SkyUsed,
    /// With `auto` lighting, the measure that decided it: the scene's own
    /// lights' power as a share of the default sky and sun's
    /// (weak below [`crate::WEAK_FRACTION`]).
    pub sky_share: Option<f32>,
    /// What the scene's objects and materials are called.
    pub names: SceneNames,
    /// Problems that did not stop loading, one line each, naming the
    /// file: the reader's, then the assembly's.
    pub warnings: Vec<String>,
}

/// What the scene's objects and materials are called, for the lists of
/// names beside the `object` and `material` render passes: the file's
/// names where it gives them, else made up from what the thing is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneNames {
    /// The name of each of the scene's instances, by index.
    pub objects: Vec<String>,
    /// The name of each of the scene's materials, by index.
    pub materials: Vec<String>,
}

impl SceneNames {
    /// Names by number (`object 1`, `material 1`, ...: the ids of the
    /// render passes) for a scene that gives none.
    pub fn numbered(scene: &Scene) -> Self {
        let list = |what: &str, n: usize| (1..=n).map(|i| format!("{what} {i}")).collect();
        Self {
            objects: list("object", scene.instances.len()),
            materials: list("material", scene.materials.len()),
        }
    }
}

impl AssembledScene {
    /// True if the default sky and sun were added.
    pub fn default_light(&self) -> bool {
        self.sky == SkyUsed::Default
    }
}

/// Assembles the scene `desc` describes: its objects, then its lights,
/// camera and sky.
pub fn assemble(mut desc: SceneDescription) -> Result<AssembledScene, FormatError> {
    let name = desc.name.clone();
    let mut warnings = desc.warnings;
    let placeholder = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, AUTO_VFOV_DEG, 1.0);
    let mut scene = Scene::new(match &desc.camera {
        CameraRequest::Given { camera, .. } => *camera,
        _ => placeholder,
    });
    scene.materials = desc.materials;
    let mut object_names: Vec<String> = Vec::new();
    let mut objects = Objects {
        meshes: vec![None; desc.meshes.len()],
        inline: desc.meshes.into_iter().map(Some).collect(),
        library: MeshLibrary::new(),
        cameras: Vec::new(),
        own: shown_with_own_materials(&desc.objects),
        interfaces: desc.medium_interfaces.iter().copied().collect(),
        filled: HashSet::new(),
        faces_z: None,
    };
    let mut moving_emitters = 0;
    // The file's media come first (the objects' interfaces name them by
    // index); a mesh file's glass volumes are added after them.
    scene.media = std::mem::take(&mut desc.media);
    for (k, o) in desc.objects.iter().enumerate() {
        let first_instance = scene.instances.len() as u32;
        let emits = objects.add(&mut scene, k, o, &name)?;
        if o.placement.is_moving() && emits {
            moving_emitters += 1;
        }
        objects.add_media(&mut scene, k, first_instance);
        name_instances(&mut object_names, &scene, &objects.library, o, k);
    }
    let mut library = objects.library;
    scene.camera_medium = desc.camera_medium;
    warnings.append(&mut library.warnings);
    if moving_emitters > 0 {
        warnings.push(format!(
            "{name}: {moving_emitters} moving object(s) emit light: they are seen, but not sampled as lights"
        ));
    }
    for l in desc.lights {
        scene.add_light(l);
    }
    if let Some(env) = desc.environment {
        scene.environment = Some(env);
    }
    scene.generate_tangents();
    let view = match objects.faces_z {
        Some(true) => View::Front,
        _ => View::ThreeQuarter,
    };
    let (camera, camera_source) = choose_camera(
        desc.camera,
        &objects.cameras,
        &scene,
        &name,
        view,
        &mut warnings,
    )?;
    scene.camera = camera;
    let (sky, sky_share) = sky::apply(&mut scene, &desc.sky)
        .map_err(|e| FormatError::in_file(&name, format!("sky: {e}")))?;
    // What the sky added (its ground) is named after it.
    object_names.resize(scene.instances.len(), "sky ground".into());
    let names = SceneNames {
        objects: object_names,
        materials: material_names(&scene, &desc.material_names, &library.material_names),
    };
    Ok(AssembledScene {
        scene,
        settings: desc.settings,
        camera_source,
        sky,
        sky_share,
        names,
        warnings,
    })
}

/// What adding a description's objects to a scene keeps track of.
struct Objects {
    /// The scene's mesh of each description mesh, once added.
    meshes: Vec<Option<u32>>,
    /// The description's meshes not yet added.
    inline: Vec<Option<SceneMesh>>,
    /// The mesh files, each loaded once.
    library: MeshLibrary,
    /// The cameras of the mesh files, in the order they were loaded.
    cameras: Vec<GltfCamera>,
    /// The mesh files some object shows with their own materials.
    own: HashSet<PathBuf>,
    /// Each object's media, which go on every instance it adds.
    interfaces: BTreeMap<u32, MediumInterface>,
    /// Instances whose glTF material fills them with a medium.
    filled: HashSet<u32>,
    /// Whether all the geometry so far comes from files whose models face
    /// +Z (glTF); `None` before any.
    faces_z: Option<bool>,
}

impl Objects {
    /// Adds object `o` (number `k` in the file `name`) to `scene`: true if
    /// it emits light.
    fn add(
        &mut self,
        scene: &mut Scene,
        k: usize,
        o: &Object,
        name: &str,
    ) -> Result<bool, FormatError> {
        if !matches!(o.geometry, Geometry::File(_)) {
            self.faces_z = Some(false);
        }
        Ok(match &o.geometry {
            Geometry::File(path) => self.add_file(scene, k, o, path, name)?,
            Geometry::Shape(shape) => {
                let material = match o.material {
                    Some(m) => m,
                    None => self.library.default_material(scene),
                };
                add_placed_shape(scene, *shape, &o.placement, material);
                is_emissive(scene, material)
            }
            Geometry::Mesh(i) => self.add_mesh(scene, o, *i as usize),
        })
    }

    /// Adds object `o` showing the mesh file `path`: an instance per
    /// part, the file's glass volumes and its lights. True if it emits.
    fn add_file(
        &mut self,
        scene: &mut Scene,
        k: usize,
        o: &Object,
        path: &Path,
        name: &str,
    ) -> Result<bool, FormatError> {
        let first = self.library.file_count();
        let f = self
            .library
            .load(scene, path, self.own.contains(&file_key(path)))
            .map_err(|e| {
                if path.display().to_string() == name {
                    e
                } else {
                    FormatError::in_file(name, format!("object {}: {e}", k + 1))
                }
            })?;
        if self.library.file_count() > first {
            self.cameras.extend(f.cameras.iter().cloned());
        }
        self.faces_z = Some(self.faces_z.unwrap_or(true) && f.faces_z);
        for part in &f.parts {
            let instance = scene.add_instance(Instance {
                mesh: part.mesh,
                placement: placed(&o.placement, part.transform),
                material: o.material.or(f.material),
            });
            if o.material.is_none() && !f.volumes.is_empty() {
                let outside = self.interfaces.get(&(k as u32)).and_then(|mi| mi.outside);
                if let Some(mi) = volume_interface(scene, part.mesh, &f.volumes, outside) {
                    scene.set_medium_interface(instance, mi);
                    self.filled.insert(instance);
                }
            }
        }
        // The file's lights, where the object puts the file (where it
        // starts, if it moves).
        let at = Mat4::from(placed(&o.placement, Mat4::IDENTITY).at(0.0));
        for l in &f.lights {
            scene.add_light(gltf_light(l, at));
        }
        Ok(o.material.map_or(f.emissive, |m| is_emissive(scene, m)))
    }

    /// Adds object `o` showing the description's mesh `i` (added to the
    /// scene on first use). True if it emits.
    fn add_mesh(&mut self, scene: &mut Scene, o: &Object, i: usize) -> bool {
        let mesh = match self.meshes[i] {
            Some(id) => id,
            None => {
                let id = scene.add_mesh(self.inline[i].take().expect("added once"));
                self.meshes[i] = Some(id);
                id
            }
        };
        scene.add_instance(Instance {
            mesh,
            placement: placed(&o.placement, Mat4::IDENTITY),
            material: o.material,
        });
        match o.material {
            Some(m) => is_emissive(scene, m),
            None => scene.meshes[mesh as usize]
                .material_ids
                .as_ref()
                .is_some_and(|ids| ids.iter().any(|&m| is_emissive(scene, m))),
        }
    }

    /// Puts object `k`'s media on the instances it added from
    /// `first_instance` on, except those a glTF volume fills.
    fn add_media(&self, scene: &mut Scene, k: usize, first_instance: u32) {
        if let Some(&mi) = self.interfaces.get(&(k as u32)) {
            for i in first_instance..scene.instances.len() as u32 {
                if !self.filled.contains(&i) {
                    scene.set_medium_interface(i, mi);
                }
            }
        }
    }
}

/// The mesh files some object shows with their own materials.
fn shown_with_own_materials(objects: &[Object]) -> HashSet<PathBuf> {
    objects
        .iter()
        .filter(|o| o.material.is_none())
        .filter_map(|o| match &o.geometry {
            Geometry::File(path) => Some(file_key(path)),
            _ => None,
        })
        .collect()
}

/// The name of each of `scene`'s materials: the description's name for
/// it, else its mesh file's, else its number.
fn material_names(
    scene: &Scene,
    described: &BTreeMap<u32, String>,
    files: &BTreeMap<u32, String>,
) -> Vec<String> {
    (0..scene.materials.len() as u32)
        .map(|id| {
            described
                .get(&id)
                .or(files.get(&id))
                .cloned()
                .unwrap_or_else(|| format!("material {}", id + 1))
        })
        .collect()
}

/// The camera the description asks for, and where it came from: the given
/// one, a named camera of its mesh files (`cameras`), or the files' first
/// camera, else the automatic one framing `scene` from the side `view`
/// says.
fn choose_camera(
    request: CameraRequest,
    cameras: &[GltfCamera],
    scene: &Scene,
    name: &str,
    view: View,
    warnings: &mut Vec<String>,
) -> Result<(Camera, String), FormatError> {
    Ok(match request {
        CameraRequest::Given { camera, source } => (camera, source),
        CameraRequest::Named(want) => match cameras
            .iter()
            .find(|c| c.name.as_deref() == Some(want.as_str()))
        {
            Some(c) => (gltf_camera(c), camera_name(name, c)),
            None => {
                let names: Vec<String> = cameras
                    .iter()
                    .map(|c| format!("'{}'", c.name.as_deref().unwrap_or("(unnamed)")))
                    .collect();
                return Err(FormatError::in_file(
                    name,
                    if names.is_empty() {
                        format!("no camera named '{want}': the file has no cameras (and no file {want} exists)")
                    } else {
                        format!(
                            "no camera named '{want}' (the file's cameras: {})",
                            names.join(", ")
                        )
                    },
                ));
            }
        },
        CameraRequest::Automatic => match cameras.first() {
            Some(c) => (gltf_camera(c), camera_name(name, c)),
            None if !has_finite_triangles(scene) => {
                warnings.push(format!(
                    "{name}: every triangle has a NaN or infinite corner: nothing to frame; \
                     the camera looks at the origin from +Z"
                ));
                (
                    Camera::look_at(
                        Vec3::new(0.0, 0.0, 5.0),
                        Vec3::ZERO,
                        Vec3::Y,
                        AUTO_VFOV_DEG,
                        1.0,
                    ),
                    "auto (nothing to frame)".into(),
                )
            }
            None => auto_camera_framing(scene, name, view)?,
        },
    })
}

/// Names the instances object `k` (`o`) added to `scene`: its own name or
/// what it is, with a glTF file's part names or numbers when it added more
/// than one.
fn name_instances(
    object_names: &mut Vec<String>,
    scene: &Scene,
    library: &MeshLibrary,
    o: &Object,
    k: usize,
) {
    let label = o.name.clone().unwrap_or_else(|| match &o.geometry {
        Geometry::File(path) => path.file_name().map_or_else(
            || path.display().to_string(),
            |f| f.to_string_lossy().into_owned(),
        ),
        Geometry::Shape(s) => format!("{} {}", s.kind(), k + 1),
        Geometry::Mesh(_) => format!("mesh {}", k + 1),
    });
    let added = scene.instances.len() - object_names.len();
    let parts = match &o.geometry {
        Geometry::File(path) => library.part_names(path),
        _ => Vec::new(),
    };
    for j in 0..added {
        object_names.push(match (added, parts.get(j).cloned().flatten()) {
            (_, Some(part)) => format!("{label}/{part}"),
            (1, None) => label.clone(),
            (_, None) => format!("{label}/{j}"),
        });
    }
}

/// What the log calls a glTF camera of the file `name`.
fn camera_name(name: &str, c: &GltfCamera) -> String {
    format!(
        "{name}: camera '{}'",
        c.name.as_deref().unwrap_or("(unnamed)")
    )
}

/// True if material `id` of `scene` emits.
fn is_emissive(scene: &Scene, id: u32) -> bool {
    scene.materials[id as usize].is_emissive()
}

/// The placement of geometry that sits at `inner` in its file (identity,
/// or a glTF node's transform) and that the scene places by `placement`.
///
/// A moving object with a non-identity `inner` has `open * inner` and
/// `close * inner` split into scale, rotation and translation (a shear is lost).
pub fn placed(placement: &ObjectPlacement, inner: Mat4) -> Placement {
    let identity = inner == Mat4::IDENTITY;
    match *placement {
        ObjectPlacement::World => Placement::Static(Affine3A::from_mat4(inner)),
        ObjectPlacement::Static(m) if identity => Placement::Static(m),
        ObjectPlacement::Static(m) => Placement::Static(Affine3A::from_mat4(Mat4::from(m) * inner)),
        ObjectPlacement::Moving { open, close } if identity => Placement::Moving { open, close },
        ObjectPlacement::Moving { open, close } => {
            let split = |t: &Srt| {
                let m = Mat4::from_scale_rotation_translation(t.scale, t.rotation, t.translation);
                let (scale, rotation, translation) = (m * inner).to_scale_rotation_translation();
                Srt {
                    scale,
                    rotation,
                    translation,
                }
            };
            Placement::Moving {
                open: split(&open),
                close: split(&close),
            }
        }
    }
}

/// `shape` under the affine map `m`, if it is again a shape of its kind.
pub fn transformed(shape: Shape, m: &Affine3A) -> Option<Shape> {
    let lin = m.matrix3;
    let cols = [lin.x_axis, lin.y_axis, lin.z_axis].map(Vec3::from);
    let lens = cols.map(Vec3::length);
    let uniform = lens.iter().all(|&l| (l - lens[0]).abs() <= 1e-5 * lens[0])
        && cols[0].dot(cols[1]).abs() <= 1e-5 * lens[0] * lens[0]
        && cols[1].dot(cols[2]).abs() <= 1e-5 * lens[0] * lens[0]
        && cols[0].dot(cols[2]).abs() <= 1e-5 * lens[0] * lens[0];
    let s = lens[0];
    Some(match shape {
        Shape::Quad {
            corner,
            edge_u,
            edge_v,
        } => Shape::Quad {
            corner: m.transform_point3(corner),
            edge_u: m.transform_vector3(edge_u),
            edge_v: m.transform_vector3(edge_v),
        },
        Shape::Disc {
            center,
            normal,
            radius,
        } if uniform => Shape::Disc {
            center: m.transform_point3(center),
            normal: (m.transform_vector3(normal) * m.matrix3.determinant().signum()).normalize(),
            radius: radius * s,
        },
        Shape::Sphere { center, radius } if uniform => Shape::Sphere {
            center: m.transform_point3(center),
            radius: radius * s,
        },
        Shape::Box { min, max } => {
            let off_diagonal = [lin.x_axis.y, lin.x_axis.z, lin.y_axis.x]
                .into_iter()
                .chain([lin.y_axis.z, lin.z_axis.x, lin.z_axis.y])
                .any(|v| v.abs() > 1e-6 * s);
            if off_diagonal {
                return None;
            }
            let (a, b) = (m.transform_point3(min), m.transform_point3(max));
            Shape::Box {
                min: a.min(b),
                max: a.max(b),
            }
        }
        _ => return None,
    })
}

/// Adds `shape` placed by `placement` with `material`: exact where the
/// placement keeps it a shape of its kind, else tessellated with an
/// instance transform. Returns its instance.
fn add_placed_shape(
    scene: &mut Scene,
    shape: Shape,
    placement: &ObjectPlacement,
    material: u32,
) -> u32 {
    let placement = match *placement {
        ObjectPlacement::World => return scene.add_shape(shape, material),
        ObjectPlacement::Static(m) => match transformed(shape, &m) {
            Some(exact) => return scene.add_shape(exact, material),
            None => Placement::Static(m),
        },
        ObjectPlacement::Moving { open, close } => Placement::Moving { open, close },
    };
    let mesh = scene.add_mesh(shape.to_mesh());
    scene.add_instance(Instance {
        mesh,
        placement,
        material: Some(material),
    })
}

/// The media on the sides of an instance of `mesh` whose triangles all
/// wear one material with a volume (glTF `KHR_materials_volume`
/// attenuation): its medium inside, `outside` (the object's own outside
/// medium, if it names one) around it.
fn volume_interface(
    scene: &Scene,
    mesh: u32,
    volumes: &std::collections::HashMap<u32, u32>,
    outside: Option<u32>,
) -> Option<sahara_render::MediumInterface> {
    let ids = scene.meshes[mesh as usize].material_ids.as_ref()?;
    let first = *ids.first()?;
    let inside = *volumes.get(&first)?;
    ids.iter()
        .all(|&m| m == first)
        .then_some(sahara_render::MediumInterface {
            inside: Some(inside),
            outside,
            index_matched: false,
        })
}
