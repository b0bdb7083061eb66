//! Mesh files loaded into a [`Scene`] once each, however many objects use them.
//!
//! A file becomes one or more scene meshes ([`MeshPart`]s: one for OBJ and
//! PLY, one per glTF mesh with a transform per glTF node using it) plus, when
//! asked for, its own materials converted by [`crate::mesh::mtl`] and [`crate::gltf::material`] and
//! appended to the scene's materials, with the meshes' per-triangle
//! material ids pointing at them. Objects then only add instances, so many
//! copies of a mesh cost one mesh's memory (and one kd-tree).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2};
use sahara_render::{Material, Scene, SceneMesh};

use crate::common::materials::TextureCache;
use crate::gltf::material::gltf_material;
use crate::gltf::volume::volume_medium;
use crate::mesh::mtl::mtl_material;
use sahara_readers::gltf::{GltfCamera, GltfLight};
use sahara_readers::FormatError;

/// One scene mesh made from a file, and where the file puts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshPart {
    /// Index into the scene's meshes.
    pub mesh: u32,
    /// Transform from the mesh to the file's space (identity except for glTF nodes).
    pub transform: Mat4,
}

/// What a file added to the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedFile {
    /// The meshes and their placements in the file.
    pub parts: Vec<MeshPart>,
    /// The names the file gives its parts (glTF mesh names), parallel to
    /// `parts`.
    pub part_names: Vec<Option<String>>,
    /// Material for instances that do not override it: `None` when the
    /// meshes carry per-triangle ids of the file's own materials, else the
    /// scene's default material (a PLY, or materials not asked for).
    pub material: Option<u32>,
    /// True if a material of the file emits light.
    pub emissive: bool,
    /// True if the file's format says where a model's front is: glTF's
    /// models face +Z (with +Y up), and the automatic camera shows them
    /// from the front, as glTF viewers do.
    pub faces_z: bool,
    /// The file's cameras (glTF), placed in the file's space.
    pub cameras: Vec<GltfCamera>,
    /// The file's lights (glTF `KHR_lights_punctual`), placed in the
    /// file's space.
    pub lights: Vec<GltfLight>,
    /// The media inside the file's materials (glTF `KHR_materials_volume`
    /// attenuation): the scene's material index to the medium's in
    /// [`Scene::media`].
    pub volumes: HashMap<u32, u32>,
}

/// Every mesh file loaded so far, by canonical path.
#[derive(Debug, Default)]
pub struct MeshLibrary {
    files: HashMap<PathBuf, LoadedFile>,
    textures: TextureCache,
    default_material: Option<u32>,
    /// The names of the materials the files brought (and of the default
    /// one), by the scene's material index.
    pub material_names: BTreeMap<u32, String>,
    /// Problems that did not stop loading, one line each, naming the file.
    pub warnings: Vec<String>,
}

/// The key a file is known by: its canonical path, or the path as given.
pub fn file_key(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}

impl MeshLibrary {
    /// An empty library.
    pub fn new() -> Self {
        Self::default()
    }

    /// The names of the parts of the loaded file `path` (none if not loaded).
    pub fn part_names(&self, path: &Path) -> Vec<Option<String>> {
        self.files
            .get(&file_key(path))
            .map_or_else(Vec::new, |f| f.part_names.clone())
    }

    /// Number of distinct files loaded.
    pub fn file_count(&self) -> usize {
        self.files.len()
    }

    /// The scene's grey default material, added on first use.
    pub fn default_material(&mut self, scene: &mut Scene) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            let id = scene.add_material(Material::default());
            self.material_names.insert(id, "default".into());
            id
        })
    }

    /// Loads `path` into `scene` unless it already is; with
    /// `own_materials` the file's materials come too (decided on a file's
    /// first load). The format follows the extension: `.obj`, `.ply`,
    /// `.gltf`, `.glb` (any case).
    pub fn load(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        own_materials: bool,
    ) -> Result<LoadedFile, FormatError> {
        let key = file_key(path);
        if let Some(f) = self.files.get(&key) {
            return Ok(f.clone());
        }
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let loaded = match ext.as_str() {
            "obj" => self.load_obj(scene, path, own_materials)?,
            "ply" => {
                let mesh = sahara_readers::ply::load_ply(path)?;
                let mesh = scene.add_mesh(mesh);
                LoadedFile {
                    parts: vec![MeshPart {
                        mesh,
                        transform: Mat4::IDENTITY,
                    }],
                    part_names: vec![None],
                    material: Some(self.default_material(scene)),
                    emissive: false,
                    faces_z: false,
                    cameras: Vec::new(),
                    lights: Vec::new(),
                    volumes: HashMap::new(),
                }
            }
            "gltf" | "glb" => self.load_gltf(scene, path, own_materials)?,
            _ => {
                return Err(FormatError::in_file(
                    &path.display().to_string(),
                    format!(
                    "unsupported mesh file extension {ext:?}; expected .obj, .ply, .gltf or .glb"
                ),
                ))
            }
        };
        self.files.insert(key, loaded.clone());
        Ok(loaded)
    }

    /// An OBJ with (optionally) its MTL materials.
    fn load_obj(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        own_materials: bool,
    ) -> Result<LoadedFile, FormatError> {
        let obj = sahara_readers::obj::load_obj_with_materials(path)?;
        self.warnings.extend(obj.warnings);
        let mut mesh = SceneMesh {
            mesh: obj.mesh,
            normals: obj.normals,
            uvs: obj.uvs,
            ..SceneMesh::default()
        };
        let mut emissive = false;
        let material = if own_materials {
            let first = scene.materials.len() as u32;
            for mtl in &obj.materials {
                let m = mtl_material(mtl, &mut self.textures, &mut self.warnings);
                emissive |= m.is_emissive();
                let id = scene.add_material(m);
                self.material_names.insert(id, mtl.name.clone());
            }
            mesh.material_ids = Some(obj.material_ids.iter().map(|&i| first + i).collect());
            None
        } else {
            Some(self.default_material(scene))
        };
        let mesh = scene.add_mesh(mesh);
        Ok(LoadedFile {
            parts: vec![MeshPart {
                mesh,
                transform: Mat4::IDENTITY,
            }],
            part_names: vec![None],
            material,
            emissive,
            faces_z: false,
            cameras: Vec::new(),
            lights: Vec::new(),
            volumes: HashMap::new(),
        })
    }

    /// A glTF file: its meshes once each, an instance part per node.
    fn load_gltf(
        &mut self,
        scene: &mut Scene,
        path: &Path,
        own_materials: bool,
    ) -> Result<LoadedFile, FormatError> {
        let g = sahara_readers::gltf::load_gltf(path)?;
        let name = path.display().to_string();
        self.warnings.extend(g.warnings);
        let mut emissive = false;
        let mut volumes = HashMap::new();
        let first = scene.materials.len() as u32;
        let material = if own_materials {
            for gm in &g.materials {
                let m = gltf_material(gm, &name, &mut self.textures, &mut self.warnings);
                emissive |= m.is_emissive();
                let id = scene.add_material(m);
                if let Some(medium) = volume_medium(gm) {
                    volumes.insert(id, scene.add_medium(medium));
                }
                if let Some(n) = &gm.name {
                    self.material_names.insert(id, n.clone());
                }
            }
            None
        } else {
            Some(self.default_material(scene))
        };
        // glTF puts uv (0, 0) at the image's top left; textures here have v
        // running bottom to top. (Tangents need no change: glTF's bitangent
        // already points up the image.)
        let flip = |uvs: Option<Vec<Vec2>>| {
            uvs.map(|uvs| uvs.iter().map(|uv| Vec2::new(uv.x, 1.0 - uv.y)).collect())
        };
        let mesh_names: Vec<Option<String>> = g.meshes.iter().map(|m| m.name.clone()).collect();
        let ids: Vec<u32> = g
            .meshes
            .into_iter()
            .map(|m| {
                scene.add_mesh(SceneMesh {
                    mesh: m.mesh,
                    normals: m.normals,
                    uvs: flip(m.uvs),
                    uvs1: flip(m.uvs1),
                    tangents: m.tangents,
                    material_ids: own_materials
                        .then(|| m.material_ids.iter().map(|&i| first + i).collect()),
                })
            })
            .collect();
        if g.instances.is_empty() {
            self.warnings.push(format!(
                "{name}: the scene has no mesh nodes; nothing to render"
            ));
        }
        let parts = g
            .instances
            .iter()
            .map(|i| MeshPart {
                mesh: ids[i.mesh],
                transform: i.transform,
            })
            .collect();
        Ok(LoadedFile {
            parts,
            part_names: g
                .instances
                .iter()
                .map(|i| mesh_names[i.mesh].clone())
                .collect(),
            material,
            emissive,
            faces_z: true,
            cameras: g.cameras,
            lights: g.lights,
            volumes,
        })
    }
}
