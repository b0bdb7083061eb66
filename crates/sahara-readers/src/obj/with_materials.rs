//! OBJ with its MTL materials, per-triangle material ids, normals and uvs.
//!
//! Triangles are in the same order as [`load_obj`](super::load_obj) gives
//! them, with the same corner coordinates. Vertices differ: here a vertex is
//! one distinct `v/vt/vn` triple of an object, so a position used with two
//! different normals or uvs is stored twice and `normals`/`uvs` are
//! per-vertex arrays parallel to `mesh.positions`.
//!
//! Problems that still let the mesh be rendered are warnings, not errors: a
//! missing `.mtl` file, a `usemtl` naming an unknown material, a missing
//! texture. Faces without a known material use
//! [`MtlMaterial::default_material`], appended as the last material.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::fs;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use sahara_kd::Mesh;

use super::{locate, obj_load_options, tobj_source};
use crate::error::FormatError;
use crate::fan::fan_triangulate;
use crate::mtl::MtlMaterial;

/// An OBJ mesh with its materials and optional per-vertex attributes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjScene {
    /// Positions (one per distinct `v/vt/vn` triple) and triangles (file order, fan-triangulated).
    pub mesh: Mesh,
    /// Per-vertex normals, parallel to `mesh.positions`, if the file has `vn` lines.
    ///
    /// A corner without a normal in a file that has some takes tobj's
    /// fallback (the previous corner's normal).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, parallel to `mesh.positions`, if the file has `vt` lines.
    pub uvs: Option<Vec<Vec2>>,
    /// Per-triangle index into `materials`, parallel to `mesh.indices`.
    pub material_ids: Vec<u32>,
    /// The materials of every `mtllib`, in file order, plus the default if some face needs it.
    pub materials: Vec<MtlMaterial>,
    /// Problems that did not stop loading, one line each, naming the file.
    pub warnings: Vec<String>,
}

/// Loads an OBJ file with its materials (`mtllib` resolved next to the OBJ), normals and uvs.
pub fn load_obj_with_materials(path: &Path) -> Result<ObjScene, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    let name = path.display().to_string();
    let folder = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let warnings = RefCell::new(Vec::new());
    let mtl_error = RefCell::new(None);
    let loader = |mtl: &Path| load_mtl(&folder.join(mtl), &name, &warnings, &mtl_error);
    let source = tobj_source(&bytes);
    let (models, materials) = tobj::load_obj_buf(&mut &source[..], &obj_load_options(), loader)
        .map_err(|e| locate::describe(&bytes, &name, e))?;
    if let Some(error) = mtl_error.into_inner() {
        return Err(error);
    }
    let mut warnings = warnings.into_inner();
    let materials = materials.unwrap_or_default();
    warn_unknown_materials(&bytes, &name, &materials, &mut warnings);
    let scene = build(&models, &name)?;
    let mut materials: Vec<MtlMaterial> = materials
        .iter()
        .map(|m| {
            // The loader stored the resolved MTL path in `unknown_param`.
            let mtl = m
                .unknown_param
                .get(MTL_PATH_KEY)
                .map(PathBuf::from)
                .unwrap_or_default();
            MtlMaterial::from_tobj(m, &mtl, &mut warnings)
        })
        .collect();
    let default = materials.len() as u32;
    let mut needs_default = false;
    let mut material_ids = Vec::with_capacity(scene.mesh.indices.len());
    for (model, &count) in models.iter().zip(&scene.triangles_per_model) {
        let id = match model.mesh.material_id {
            Some(i) if i < materials.len() => i as u32,
            _ => {
                needs_default |= count > 0;
                default
            }
        };
        material_ids.extend(std::iter::repeat_n(id, count));
    }
    if needs_default {
        materials.push(MtlMaterial::default_material());
    }
    Ok(ObjScene {
        mesh: scene.mesh,
        normals: scene.normals,
        uvs: scene.uvs,
        material_ids,
        materials,
        warnings,
    })
}

/// Loads an OBJ file's geometry, normals and uvs without its materials:
/// `mtllib` and `usemtl` are not read (a missing or malformed library is
/// no problem), `materials` is empty and every `material_ids` entry 0.
/// For scene formats whose own materials replace the file's (Mitsuba).
pub fn load_obj_geometry(path: &Path) -> Result<ObjScene, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    let name = path.display().to_string();
    let source = tobj_source(&bytes);
    let (models, _) = tobj::load_obj_buf(&mut &source[..], &obj_load_options(), |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| locate::describe(&bytes, &name, e))?;
    let scene = build(&models, &name)?;
    Ok(ObjScene {
        material_ids: vec![0; scene.mesh.indices.len()],
        mesh: scene.mesh,
        normals: scene.normals,
        uvs: scene.uvs,
        materials: Vec::new(),
        warnings: Vec::new(),
    })
}

/// Key under which the loader records, in each tobj material, the MTL file it came from.
const MTL_PATH_KEY: &str = "\u{0}sahara-mtl-path";

/// tobj's material loader: a missing file is a warning, a malformed one an error.
fn load_mtl(
    mtl: &Path,
    obj_name: &str,
    warnings: &RefCell<Vec<String>>,
    error: &RefCell<Option<FormatError>>,
) -> tobj::MTLLoadResult {
    let bytes = match fs::read(mtl) {
        Ok(bytes) => bytes,
        Err(e) => {
            warnings.borrow_mut().push(format!(
                "{obj_name}: material library {} cannot be read ({e}); its faces use the default material",
                mtl.display()
            ));
            return Ok(Default::default());
        }
    };
    match tobj::load_mtl_buf(&mut &bytes[..]) {
        Ok((mut materials, names)) => {
            let at = mtl.display().to_string();
            for m in &mut materials {
                m.unknown_param.insert(MTL_PATH_KEY.to_owned(), at.clone());
            }
            Ok((materials, names))
        }
        Err(e) => {
            error.borrow_mut().get_or_insert(FormatError::in_file(
                &mtl.display().to_string(),
                format!(
                    "bad MTL file ({e}); each line must be a known statement with valid numbers"
                ),
            ));
            Err(e)
        }
    }
}

/// Adds a warning for every `usemtl` naming a material no library defines.
fn warn_unknown_materials(
    bytes: &[u8],
    name: &str,
    materials: &[tobj::Material],
    warnings: &mut Vec<String>,
) {
    let known: HashSet<&str> = materials.iter().map(|m| m.name.as_str()).collect();
    let mut reported = HashSet::new();
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let Ok(text) = std::str::from_utf8(line) else {
            continue;
        };
        let text = text.trim_start();
        let Some(rest) = text.strip_prefix("usemtl") else {
            continue;
        };
        if !rest.starts_with(char::is_whitespace) {
            continue;
        }
        let material = rest.trim();
        if !known.contains(material) && reported.insert(material.to_owned()) {
            warnings.push(format!(
                "{name}: line {}: usemtl '{material}' is not defined by any material library; using the default material",
                i + 1
            ));
        }
    }
}

/// The geometry part of [`ObjScene`] and how many triangles each tobj model gave.
struct Built {
    mesh: Mesh,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    triangles_per_model: Vec<usize>,
}

/// Builds per-vertex arrays from tobj's separate index streams and fan-triangulates.
fn build(models: &[tobj::Model], name: &str) -> Result<Built, FormatError> {
    let inconsistent = |what: String| {
        FormatError::in_file(
            name,
            format!("tobj returned inconsistent data ({what}); please report this file"),
        )
    };
    let has_uvs = models.iter().any(|m| !m.mesh.texcoord_indices.is_empty());
    let has_normals = models.iter().any(|m| !m.mesh.normal_indices.is_empty());
    let mut out = Built {
        mesh: Mesh::default(),
        normals: has_normals.then(Vec::new),
        uvs: has_uvs.then(Vec::new),
        triangles_per_model: Vec::with_capacity(models.len()),
    };
    let mut polygon = Vec::new();
    for model in models {
        let m = &model.mesh;
        let corner_count = m.indices.len();
        let texcoords = (m.texcoord_indices.len() == corner_count).then_some(&m.texcoord_indices);
        let normals = (m.normal_indices.len() == corner_count).then_some(&m.normal_indices);
        let mut vertex_of: HashMap<(u32, u32, u32), u32> = HashMap::new();
        let mut corner_vertex = Vec::with_capacity(corner_count);
        for c in 0..corner_count {
            let p = m.indices[c];
            let t = texcoords.map_or(u32::MAX, |t| t[c]);
            let n = normals.map_or(u32::MAX, |n| n[c]);
            let next = out.mesh.positions.len();
            let vertex = match vertex_of.get(&(p, t, n)) {
                Some(&v) => v,
                None => {
                    let v = u32::try_from(next).map_err(|_| {
                        FormatError::in_file(
                            name,
                            "more than 2^32 vertices; Sahara's meshes use 32-bit indices",
                        )
                    })?;
                    let position = vec3_at(&m.positions, p)
                        .ok_or_else(|| inconsistent(format!("position index {p}")))?;
                    out.mesh.positions.push(position);
                    if let Some(uvs) = &mut out.uvs {
                        let uv = if t == u32::MAX {
                            Vec2::ZERO
                        } else {
                            let i = t as usize * 2;
                            m.texcoords
                                .get(i..i + 2)
                                .map(|s| Vec2::new(s[0], s[1]))
                                .ok_or_else(|| inconsistent(format!("texcoord index {t}")))?
                        };
                        uvs.push(uv);
                    }
                    if let Some(all) = &mut out.normals {
                        let normal = if n == u32::MAX {
                            Vec3::ZERO
                        } else {
                            vec3_at(&m.normals, n)
                                .ok_or_else(|| inconsistent(format!("normal index {n}")))?
                        };
                        all.push(normal);
                    }
                    vertex_of.insert((p, t, n), v);
                    v
                }
            };
            corner_vertex.push(vertex);
        }
        if has_normals && normals.is_none() && corner_count > 0 {
            // An object without normals in a file that has them: drop them all.
            out.normals = None;
        }
        let before = out.mesh.indices.len();
        let triangles_only = m.face_arities.is_empty();
        if triangles_only && corner_count % 3 != 0 {
            return Err(inconsistent(format!(
                "object '{}' has {corner_count} indices and no face sizes",
                model.name
            )));
        }
        let implied = if triangles_only { corner_count / 3 } else { 0 };
        let mut at = 0;
        for n in std::iter::repeat_n(3, implied).chain(m.face_arities.iter().copied()) {
            let face = corner_vertex
                .get(at..at + n as usize)
                .ok_or_else(|| inconsistent(format!("object '{}' face sizes", model.name)))?;
            at += n as usize;
            polygon.clear();
            polygon.extend_from_slice(face);
            fan_triangulate(&polygon, &mut out.mesh.indices);
        }
        out.triangles_per_model
            .push(out.mesh.indices.len() - before);
    }
    Ok(out)
}

/// The `i`-th three-float vector of a flat array.
fn vec3_at(flat: &[f32], i: u32) -> Option<Vec3> {
    let i = i as usize * 3;
    flat.get(i..i + 3).map(|s| Vec3::new(s[0], s[1], s[2]))
}
