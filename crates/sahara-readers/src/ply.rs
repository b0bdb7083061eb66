//! Stanford PLY meshes: ascii, binary little- and big-endian.
//!
//! Positions come from the `vertex` element's `x`, `y`, `z` properties (any
//! scalar type; other properties are skipped). Triangles come from the `face`
//! element's `vertex_indices` (or `vertex_index`, or else its first list)
//! property, polygons fan-triangulated as `(v0, vi, vi+1)`; faces with fewer
//! than three indices give no triangles. Other elements are skipped. In an
//! ascii file every record is one line: a line with too few or too many
//! values is an error at that line.
//!
//! Header counts are never trusted: before an element is read (and anything
//! allocated for it), its count times its smallest possible record size is
//! checked against the bytes left in the file.

mod header;
mod reader;

use std::fs;
use std::path::Path;

use glam::{Vec2, Vec3};
use sahara_kd::Mesh;

use crate::error::FormatError;
use crate::fan::fan_triangulate;
use header::{parse_header, Element, Encoding, Header, Kind};
use reader::{Ascii, Binary, Reader};

/// Loads a PLY file; errors name the file and the header line or body line/byte offset.
pub fn load_ply(path: &Path) -> Result<Mesh, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    parse_ply(&bytes, &path.display().to_string())
}

/// Parses a PLY file held in memory; `name` is used in error messages.
pub fn parse_ply(bytes: &[u8], name: &str) -> Result<Mesh, FormatError> {
    parse_ply_with_attributes(bytes, name).map(|p| p.mesh)
}

/// A PLY mesh with the per-vertex attributes the file has.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlyMesh {
    /// Positions and triangles.
    pub mesh: Mesh,
    /// Normals from `nx`, `ny`, `nz`, if the vertices have all three.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates from `u`, `v` (or `s`, `t`, `texture_u`,
    /// `texture_v`, `texture_s`, `texture_t`), if the vertices have both.
    pub uvs: Option<Vec<Vec2>>,
}

/// Parses a PLY file held in memory with its normals and texture
/// coordinates; `name` is used in error messages.
pub fn parse_ply_with_attributes(bytes: &[u8], name: &str) -> Result<PlyMesh, FormatError> {
    let header = parse_header(bytes, name)?;
    let layout = Layout::of(&header, name)?;
    match header.encoding {
        Encoding::Ascii => read_body(
            &mut Ascii::new(bytes, header.body_offset, header.body_line, name),
            &header,
            &layout,
        ),
        Encoding::BinaryLittleEndian => read_body(
            &mut Binary::new(bytes, header.body_offset, false, name),
            &header,
            &layout,
        ),
        Encoding::BinaryBigEndian => read_body(
            &mut Binary::new(bytes, header.body_offset, true, name),
            &header,
            &layout,
        ),
    }
}

/// Names of the optional vertex attributes, by slot after x, y, z: the
/// normal's three components, then u and v (each with its aliases).
const ATTRIBUTE_NAMES: [&[&str]; 5] = [
    &["nx"],
    &["ny"],
    &["nz"],
    &["u", "s", "texture_u", "texture_s"],
    &["v", "t", "texture_v", "texture_t"],
];

/// Where the mesh data sits among the header's elements and properties.
struct Layout {
    /// Index of the `vertex` element and, per property, which slot it
    /// fills: 0..3 the position's axes, 3..6 the normal's, 6..8 u and v.
    vertex: Option<(usize, Vec<Option<usize>>)>,
    /// Index of the `face` element and of its index-list property.
    face: Option<(usize, usize)>,
    /// Number of vertices the file declares.
    vertex_count: u64,
}

impl Layout {
    fn of(header: &Header, name: &str) -> Result<Layout, FormatError> {
        let mut layout = Layout {
            vertex: None,
            face: None,
            vertex_count: 0,
        };
        for (e, element) in header.elements.iter().enumerate() {
            let err = |message: String| FormatError::at_line(name, element.line, message);
            let duplicate = || err(format!("second '{}' element", element.name));
            match element.name.as_str() {
                "vertex" => {
                    if layout.vertex.is_some() {
                        return Err(duplicate());
                    }
                    let mut axes = vec![None; element.properties.len()];
                    for (axis, axis_name) in ["x", "y", "z"].into_iter().enumerate() {
                        let p = element
                            .properties
                            .iter()
                            .position(|p| p.name == axis_name)
                            .ok_or_else(|| {
                                err(format!("element vertex has no property '{axis_name}'"))
                            })?;
                        if let Kind::List { .. } = element.properties[p].kind {
                            return Err(err(format!(
                                "vertex property '{axis_name}' is a list; it must be a single number"
                            )));
                        }
                        axes[p] = Some(axis);
                    }
                    for (k, names) in ATTRIBUTE_NAMES.iter().enumerate() {
                        if let Some(p) = element.properties.iter().position(|p| {
                            names.contains(&p.name.as_str()) && matches!(p.kind, Kind::Scalar(_))
                        }) {
                            if axes[p].is_none() {
                                axes[p] = Some(3 + k);
                            }
                        }
                    }
                    layout.vertex = Some((e, axes));
                    layout.vertex_count = element.count;
                }
                "face" => {
                    if layout.face.is_some() {
                        return Err(duplicate());
                    }
                    let is_list = |p: &&header::Property| matches!(p.kind, Kind::List { .. });
                    let props = &element.properties;
                    let p = props
                        .iter()
                        .position(|p| p.name == "vertex_indices" && is_list(&p))
                        .or_else(|| {
                            props
                                .iter()
                                .position(|p| p.name == "vertex_index" && is_list(&p))
                        })
                        .or_else(|| props.iter().position(|p| is_list(&p)))
                        .ok_or_else(|| {
                            err("element face has no list property (expected 'property list uchar int vertex_indices')".to_owned())
                        })?;
                    if let Kind::List { item, .. } = props[p].kind {
                        if !item.is_integer() {
                            return Err(err(format!(
                                "face list '{}' holds {} values; vertex indices must be integers",
                                props[p].name,
                                item.name()
                            )));
                        }
                    }
                    layout.face = Some((e, p));
                }
                _ => {}
            }
        }
        Ok(layout)
    }
}

/// Rejects an element whose declared count cannot fit in what is left of the
/// file, before anything is allocated for it: every record needs at least its
/// scalars and its list lengths (binary) or one character and one separator
/// per value (ascii).
fn check_count<R: Reader>(r: &mut R, element: &Element) -> Result<(), FormatError> {
    let smallest_record: u64 = element
        .properties
        .iter()
        .map(|p| match p.kind {
            Kind::Scalar(ty) | Kind::List { count: ty, .. } => r.smallest(ty),
        })
        .sum();
    let needed = u128::from(element.count) * u128::from(smallest_record);
    if needed > r.remaining() as u128 + u128::from(r.slack()) {
        let at = r.here();
        return Err(r.error(
            at,
            format!(
                "element '{}' (header line {}) declares {} records of at least {smallest_record} bytes each, but only {} bytes are left: the file is truncated or the count is wrong",
                element.name,
                element.line,
                element.count,
                r.remaining()
            ),
        ));
    }
    Ok(())
}

/// Reads every element in order.
fn read_body<R: Reader>(
    r: &mut R,
    header: &Header,
    layout: &Layout,
) -> Result<PlyMesh, FormatError> {
    let mut mesh = PlyMesh::default();
    for (e, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            // Records of nothing: there is nothing to read, however many there are.
            continue;
        }
        check_count(r, element)?;
        match (&layout.vertex, layout.face) {
            (Some((v, axes)), _) if *v == e => read_vertices(r, element, axes, &mut mesh)?,
            (_, Some((f, list))) if f == e => {
                read_faces(r, element, list, layout.vertex_count, &mut mesh.mesh)?
            }
            _ => skip_element(r, element)?,
        }
    }
    Ok(mesh)
}

/// Reads a list length at the reader's position and checks it can fit.
fn list_len<R: Reader>(
    r: &mut R,
    element: &Element,
    record: u64,
    property: &str,
    count: header::Scalar,
    item: header::Scalar,
) -> Result<u64, FormatError> {
    let at = r.here();
    let n = r
        .int(count)
        .map_err(|e| with_context(e, element, record, property))?;
    let Ok(n) = u64::try_from(n) else {
        return Err(r.error(
            at,
            format!(
                "{} {record}: list '{property}' has negative length {n}",
                element.name
            ),
        ));
    };
    r.more_values(n);
    if !r.fits(n, item) {
        return Err(r.error(
            at,
            format!(
                "{} {record}: list '{property}' claims {n} {} values but only {} bytes are left in the file",
                element.name,
                item.name(),
                r.remaining()
            ),
        ));
    }
    Ok(n)
}

/// Prefixes a reader error's message with the record and property being read.
fn with_context(e: FormatError, element: &Element, record: u64, property: &str) -> FormatError {
    e.map_message(|m| format!("{} {record}, property '{property}': {m}", element.name))
}

fn read_vertices<R: Reader>(
    r: &mut R,
    element: &Element,
    axes: &[Option<usize>],
    out: &mut PlyMesh,
) -> Result<(), FormatError> {
    let has = |slots: std::ops::Range<usize>| slots.into_iter().all(|s| axes.contains(&Some(s)));
    let (with_normals, with_uvs) = (has(3..6), has(6..8));
    let mesh = &mut out.mesh;
    if element.count > u64::from(u32::MAX) {
        let at = r.here();
        return Err(r.error(
            at,
            format!(
                "element vertex (header line {}) declares {} vertices; at most {} are supported",
                element.line,
                element.count,
                u32::MAX
            ),
        ));
    }
    // `check_count` has bounded the count by the file size.
    mesh.positions.reserve_exact(element.count as usize);
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    if with_normals {
        normals.reserve_exact(element.count as usize);
    }
    if with_uvs {
        uvs.reserve_exact(element.count as usize);
    }
    for v in 0..element.count {
        r.begin_record(element.properties.len() as u64);
        let mut p = [0.0f32; 8];
        for (property, axis) in element.properties.iter().zip(axes) {
            let ctx = |e| with_context(e, element, v, &property.name);
            match (property.kind, axis) {
                (Kind::Scalar(ty), Some(axis)) => p[*axis] = r.coord(ty).map_err(ctx)?,
                (Kind::Scalar(ty), None) => r.skip(ty, 1).map_err(ctx)?,
                (Kind::List { count, item }, _) => {
                    let n = list_len(r, element, v, &property.name, count, item)?;
                    r.skip(item, n).map_err(ctx)?;
                }
            }
        }
        r.end_record()?;
        mesh.positions.push(Vec3::new(p[0], p[1], p[2]));
        if with_normals {
            normals.push(Vec3::new(p[3], p[4], p[5]));
        }
        if with_uvs {
            uvs.push(Vec2::new(p[6], p[7]));
        }
    }
    out.normals = with_normals.then_some(normals);
    out.uvs = with_uvs.then_some(uvs);
    Ok(())
}

fn read_faces<R: Reader>(
    r: &mut R,
    element: &Element,
    list: usize,
    vertex_count: u64,
    mesh: &mut Mesh,
) -> Result<(), FormatError> {
    // `check_count` has bounded the count by the file size; most faces are triangles.
    mesh.indices.reserve(element.count as usize);
    let mut polygon: Vec<u32> = Vec::new();
    for f in 0..element.count {
        r.begin_record(element.properties.len() as u64);
        for (p, property) in element.properties.iter().enumerate() {
            let ctx = |e| with_context(e, element, f, &property.name);
            match property.kind {
                Kind::Scalar(ty) => r.skip(ty, 1).map_err(ctx)?,
                Kind::List { count, item } => {
                    let n = list_len(r, element, f, &property.name, count, item)?;
                    if p != list {
                        r.skip(item, n).map_err(ctx)?;
                        continue;
                    }
                    polygon.clear();
                    for _ in 0..n {
                        let at = r.here();
                        let index = r.int(item).map_err(ctx)?;
                        if index < 0 {
                            return Err(
                                r.error(at, format!("face {f} has negative vertex index {index}"))
                            );
                        }
                        if index as u64 >= vertex_count {
                            return Err(r.error(
                                at,
                                format!(
                                    "face {f} has index {index} but the file has {vertex_count} vertices"
                                ),
                            ));
                        }
                        polygon.push(index as u32);
                    }
                    fan_triangulate(&polygon, &mut mesh.indices);
                }
            }
        }
        r.end_record()?;
    }
    Ok(())
}

fn skip_element<R: Reader>(r: &mut R, element: &Element) -> Result<(), FormatError> {
    for i in 0..element.count {
        r.begin_record(element.properties.len() as u64);
        for property in &element.properties {
            let ctx = |e| with_context(e, element, i, &property.name);
            match property.kind {
                Kind::Scalar(ty) => r.skip(ty, 1).map_err(ctx)?,
                Kind::List { count, item } => {
                    let n = list_len(r, element, i, &property.name, count, item)?;
                    r.skip(item, n).map_err(ctx)?;
                }
            }
        }
        r.end_record()?;
    }
    Ok(())
}
