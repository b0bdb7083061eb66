//! Wavefront OBJ meshes, read with `tobj`.
//!
//! All objects, groups and material runs are merged into one mesh in file
//! order. Polygons are fan-triangulated here as `(v0, vi, vi+1)` (tobj is asked
//! not to triangulate, so the order is ours, not tobj's). Relative (negative)
//! indices work. Points (`p`, and `f` with fewer than three corners) and
//! polylines (`l`) give no triangles. Materials (`mtllib`) are not read here;
//! [`load_obj_with_materials`] reads them, with normals and uvs.
//!
//! `positions` are not the file's `v` list verbatim: tobj compacts them per
//! object in first-use order, so unreferenced vertices are dropped and vertices
//! shared by two objects appear twice. Triangle corner coordinates are exactly
//! the file's.

mod locate;
mod with_materials;

use std::borrow::Cow;
use std::fs;
use std::path::Path;

use glam::Vec3;
use sahara_kd::Mesh;

use crate::error::FormatError;
use crate::fan::fan_triangulate;

pub use with_materials::{load_obj_geometry, load_obj_with_materials, ObjScene};

/// Loads an OBJ file; errors name the file and, when it can be found, the line.
pub fn load_obj(path: &Path) -> Result<Mesh, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    parse_obj(&bytes, &path.display().to_string())
}

/// Parses an OBJ file held in memory; `name` is used in error messages.
pub fn parse_obj(bytes: &[u8], name: &str) -> Result<Mesh, FormatError> {
    let source = tobj_source(bytes);
    let (models, _materials) = tobj::load_obj_buf(&mut &source[..], &obj_load_options(), |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| locate::describe(bytes, name, e))?;
    merge(&models, name)
}

/// How tobj is asked to read OBJ: separate index streams, no triangulation, no points or lines.
fn obj_load_options() -> tobj::LoadOptions {
    // Another crate enabling tobj's `merging`/`reordering` features adds
    // fields to LoadOptions; the struct update keeps them at their defaults.
    #[allow(clippy::needless_update)]
    tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    }
}

/// The text handed to tobj: `bytes` with polylines commented out and
/// overflowing texture/normal indices defused (see the two functions below).
/// Line structure is kept, so tobj's errors are found on the same lines.
fn tobj_source(bytes: &[u8]) -> Cow<'_, [u8]> {
    let source = without_polylines(bytes);
    match without_overflowing_indices(&source) {
        Some(fixed) => Cow::Owned(fixed),
        None => source,
    }
}

/// `bytes` with every `l` (polyline) statement turned into a comment.
///
/// tobj parses `l` like `f`, so a polyline with three or more points would
/// otherwise become a polygon. Line structure is kept, so line numbers hold.
fn without_polylines(bytes: &[u8]) -> Cow<'_, [u8]> {
    let mut out: Option<Vec<u8>> = None;
    let mut start = 0;
    for line in bytes.split(|&b| b == b'\n') {
        if let Some(i) = line.iter().position(|b| !b.is_ascii_whitespace()) {
            let is_polyline =
                line[i] == b'l' && line.get(i + 1).is_none_or(|b| b.is_ascii_whitespace());
            if is_polyline {
                out.get_or_insert_with(|| bytes.to_vec())[start + i] = b'#';
            }
        }
        start += line.len() + 1;
    }
    out.map_or(Cow::Borrowed(bytes), Cow::Owned)
}

/// A `vt` or `vn` index that tobj can multiply without overflow, and that
/// no file can reach (2^61 texture coordinates would take exabytes).
const DEFUSED_INDEX: &str = "2305843009213693951";

/// `bytes` with every texture and normal index of a face that would make
/// tobj overflow replaced by [`DEFUSED_INDEX`], or `None` if there is none.
///
/// tobj turns a corner's `vt` and `vn` indices into `usize` unchecked and
/// then computes `vt * 2 + 1` and `vn * 3 + 2`: a relative index reaching
/// more than one before the first `vt`/`vn` line, or a huge one, overflows
/// (0, or a relative index landing just before the first line, becomes
/// `usize::MAX`, which tobj takes for "no index" and leaves alone), which panics where overflow is checked (debug
/// builds, fuzzing) and is at best an accident elsewhere. Replaced by an
/// index that is merely out of range, the corner gets tobj's ordinary
/// out-of-bounds error, on the same line, in the same order among other
/// errors (or, as before, nothing when the file has no `vt`/`vn` lines, which
/// tobj then never looks up). Vertex indices need no help: tobj saturates
/// those.
fn without_overflowing_indices(bytes: &[u8]) -> Option<Vec<u8>> {
    // Largest 0-based index that tobj can use safely: DEFUSED_INDEX.
    const LIMIT: i128 = 2305843009213693951;
    let mut out: Option<Vec<u8>> = None;
    let mut start = 0;
    // `vt` and `vn` lines so far: tobj's base for relative indices.
    let (mut texcoords, mut normals) = (0i128, 0i128);
    for line in bytes.split(|&b| b == b'\n') {
        let line_start = start;
        start += line.len() + 1;
        let Ok(text) = std::str::from_utf8(line) else {
            // tobj stops at a line that is not UTF-8: the rest is copied as it is.
            start = line_start;
            break;
        };
        let mut words = text.split_whitespace();
        match words.next() {
            Some("vt") => texcoords += 1,
            Some("vn") => normals += 1,
            Some("f") => {
                // Offsets in `line` of the index texts to replace.
                let mut defuse: Vec<(usize, usize)> = Vec::new();
                for word in words {
                    let word_at = word.as_ptr() as usize - text.as_ptr() as usize;
                    let mut part_at = word_at;
                    for (slot, part) in word.split('/').enumerate() {
                        let base = match slot {
                            1 => Some(texcoords),
                            2 => Some(normals),
                            _ => None,
                        };
                        if let Some(base) = base {
                            // What tobj cannot parse (as isize) is its FaceParseError.
                            if let Ok(x) = part.parse::<isize>() {
                                // tobj's 0-based index: relative from the end, else x - 1.
                                let x = x as i128;
                                let index = if x < 0 { base + x } else { x - 1 };
                                // -1 is tobj's "no index" (usize::MAX): never multiplied.
                                if index != -1 && !(0..=LIMIT).contains(&index) {
                                    defuse.push((part_at, part_at + part.len()));
                                }
                            }
                        }
                        part_at += part.len() + 1;
                    }
                }
                if !defuse.is_empty() {
                    let out = out.get_or_insert_with(|| bytes[..line_start].to_vec());
                    let mut at = 0;
                    for (from, to) in defuse {
                        out.extend_from_slice(&line[at..from]);
                        out.extend_from_slice(DEFUSED_INDEX.as_bytes());
                        at = to;
                    }
                    out.extend_from_slice(&line[at..]);
                    if start <= bytes.len() {
                        out.push(b'\n');
                    }
                    continue;
                }
            }
            _ => {}
        }
        if let Some(out) = out.as_mut() {
            out.extend_from_slice(&bytes[line_start..start.min(bytes.len())]);
        }
    }
    if let Some(out) = out.as_mut() {
        if start < bytes.len() {
            out.extend_from_slice(&bytes[start..]);
        }
    }
    out
}

/// Concatenates tobj's models into one fan-triangulated mesh, checking every index.
fn merge(models: &[tobj::Model], name: &str) -> Result<Mesh, FormatError> {
    let inconsistent = |what: String| {
        FormatError::in_file(
            name,
            format!("tobj returned inconsistent data ({what}); please report this file"),
        )
    };
    let mut mesh = Mesh::default();
    mesh.positions
        .reserve(models.iter().map(|m| m.mesh.positions.len() / 3).sum());
    mesh.indices
        .reserve(models.iter().map(|m| m.mesh.indices.len() / 3).sum());
    let mut polygon = Vec::new();
    for model in models {
        let m = &model.mesh;
        let base = mesh.positions.len();
        let count = m.positions.len() / 3;
        if base + count > u32::MAX as usize {
            return Err(FormatError::in_file(
                name,
                format!(
                    "more than {} vertices; Sahara's meshes use 32-bit indices",
                    u32::MAX
                ),
            ));
        }
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        let global = |i: u32| {
            if (i as usize) < count {
                Ok(base as u32 + i)
            } else {
                Err(inconsistent(format!(
                    "object '{}' has index {i} but {count} positions",
                    model.name
                )))
            }
        };
        // tobj leaves face_arities empty when every face is a triangle.
        let triangles_only = m.face_arities.is_empty();
        if triangles_only && m.indices.len() % 3 != 0 {
            return Err(inconsistent(format!(
                "object '{}' has {} indices and no face sizes",
                model.name,
                m.indices.len()
            )));
        }
        let implied_triangles = if triangles_only {
            m.indices.len() / 3
        } else {
            0
        };
        let face_sizes =
            std::iter::repeat_n(3, implied_triangles).chain(m.face_arities.iter().copied());
        let mut at = 0;
        for n in face_sizes {
            let face = m.indices.get(at..at + n as usize).ok_or_else(|| {
                inconsistent(format!(
                    "object '{}' face sizes exceed its indices",
                    model.name
                ))
            })?;
            at += n as usize;
            polygon.clear();
            for &i in face {
                polygon.push(global(i)?);
            }
            fan_triangulate(&polygon, &mut mesh.indices);
        }
        if at != m.indices.len() {
            return Err(inconsistent(format!(
                "object '{}' has indices beyond its face sizes",
                model.name
            )));
        }
    }
    Ok(mesh)
}
