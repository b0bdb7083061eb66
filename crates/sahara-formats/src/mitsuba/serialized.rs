//! Mitsuba's `.serialized` meshes: little-endian, a `u16` format id
//! `0x041C` and a `u16` version (3 or 4), then a zlib stream holding a
//! `u32` of flags (`0x1` normals, `0x2` uvs, `0x8` colours, `0x10` face
//! normals, `0x2000` doubles), the shape's name (version 4, a
//! NUL-terminated string), `u64` vertex and triangle counts, positions,
//! normals, uvs and colours as the flags say, and `u32` triangle
//! indices. A file may hold several meshes one after the other; its last
//! bytes are the offset of each (`u64`s in version 4, `u32`s in 3)
//! followed by their `u32` count.

use std::io::Read;

use glam::{Vec2, Vec3};
use sahara_readers::FormatError;
use sahara_render::{Mesh, SceneMesh};

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x1;
const HAS_UVS: u32 = 0x2;
const HAS_COLORS: u32 = 0x8;
const FACE_NORMALS: u32 = 0x10;
const DOUBLE: u32 = 0x2000;

/// Largest vertex or triangle count read (2^31: indices are `u32`, and
/// a larger mesh would not fit in memory here).
const MAX_COUNT: u64 = 1 << 31;

/// A mesh of a serialized file, and whether the file asks for face
/// normals.
pub(crate) struct SerializedMesh {
    /// Positions, triangles, normals and uvs as stored.
    pub(crate) mesh: SceneMesh,
    /// The file's face-normals flag.
    pub(crate) face_normals: bool,
}

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// An error at byte `offset` of the file `name`.
fn at_byte(name: &str, offset: usize, what: &str) -> FormatError {
    FormatError::AtByte {
        path: name.to_owned(),
        offset: offset as u64,
        message: what.to_owned(),
    }
}

/// The file `bytes`, called `name`: its version (3 or 4) and where mesh
/// number `index` starts.
fn mesh_start(bytes: &[u8], name: &str, index: usize) -> Result<(u16, usize), FormatError> {
    let bad = |offset: usize, what: &str| at_byte(name, offset, what);
    if u16_at(bytes, 0) != Some(MAGIC) {
        return Err(bad(
            0,
            "not a Mitsuba serialized mesh (no 0x041C format id)",
        ));
    }
    let version = u16_at(bytes, 2).unwrap_or(0);
    if version != 3 && version != 4 {
        return Err(bad(
            2,
            &format!("serialized version {version}: Sahara reads 3 and 4"),
        ));
    }
    let start = if index == 0 {
        0
    } else {
        let n = bytes.len();
        let count = n
            .checked_sub(4)
            .and_then(|at| u32_at(bytes, at))
            .ok_or_else(|| bad(n, "the file ends before its table of meshes"))?
            as usize;
        if index >= count {
            return Err(FormatError::in_file(
                name,
                format!("shape_index {index}: the file holds {count} mesh(es)"),
            ));
        }
        let width = if version == 4 { 8 } else { 4 };
        let at = n
            .checked_sub(4 + width * (count - index))
            .ok_or_else(|| bad(n, "the table of meshes is longer than the file"))?;
        let offset = if version == 4 {
            u64_at(bytes, at).unwrap_or(u64::MAX)
        } else {
            u64::from(u32_at(bytes, at).unwrap_or(u32::MAX))
        };
        usize::try_from(offset)
            .ok()
            .filter(|&o| o + 4 <= n)
            .ok_or_else(|| {
                bad(
                    at,
                    &format!("mesh {index} starts at {offset}, past the end"),
                )
            })?
    };
    Ok((version, start))
}

/// Mesh number `index` of the serialized file `bytes`, called `name`.
pub(crate) fn parse_serialized(
    bytes: &[u8],
    name: &str,
    index: usize,
) -> Result<SerializedMesh, FormatError> {
    let bad = |offset: usize, what: &str| at_byte(name, offset, what);
    let (version, start) = mesh_start(bytes, name, index)?;
    let mut z = flate2::read::ZlibDecoder::new(&bytes[start + 4..]);
    let mut read = |len: usize, what: &str| -> Result<Vec<u8>, FormatError> {
        let mut buf = Vec::new();
        (&mut z)
            .take(len as u64)
            .read_to_end(&mut buf)
            .map_err(|e| bad(start + 4, &format!("cannot decompress the mesh: {e}")))?;
        if buf.len() != len {
            return Err(bad(
                start + 4,
                &format!("the mesh data ends inside its {what}"),
            ));
        }
        Ok(buf)
    };
    let flags = u32::from_le_bytes(read(4, "flags")?.try_into().expect("4 bytes"));
    if version == 4 {
        // The shape's name: up to a NUL.
        let mut len = 0;
        while read(1, "name")?[0] != 0 {
            len += 1;
            if len > 1 << 16 {
                return Err(bad(start + 4, "the mesh's name runs on without end"));
            }
        }
    }
    let counts = read(16, "header")?;
    let vertices = u64::from_le_bytes(counts[..8].try_into().expect("8 bytes"));
    let triangles = u64::from_le_bytes(counts[8..].try_into().expect("8 bytes"));
    if vertices > MAX_COUNT || triangles > MAX_COUNT {
        return Err(bad(
            start + 4,
            &format!(
                "{vertices} vertices and {triangles} triangles: more than Sahara reads (2^31)"
            ),
        ));
    }
    let (nv, nt) = (vertices as usize, triangles as usize);
    let size = if flags & DOUBLE != 0 { 8 } else { 4 };
    let mut floats = |count: usize, what: &str| -> Result<Vec<f32>, FormatError> {
        let b = read(count * size, what)?;
        Ok(if size == 8 {
            b.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")) as f32)
                .collect()
        } else {
            b.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
                .collect()
        })
    };
    let v3 = |f: Vec<f32>| -> Vec<Vec3> { f.chunks_exact(3).map(Vec3::from_slice).collect() };
    let positions = v3(floats(3 * nv, "positions")?);
    let normals = if flags & HAS_NORMALS != 0 {
        Some(v3(floats(3 * nv, "normals")?))
    } else {
        None
    };
    let uvs = if flags & HAS_UVS != 0 {
        Some(
            floats(2 * nv, "texture coordinates")?
                .chunks_exact(2)
                .map(Vec2::from_slice)
                .collect(),
        )
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        floats(3 * nv, "colours")?;
    }
    let raw = read(12 * nt, "triangles")?;
    let mut indices = Vec::with_capacity(nt);
    for (k, c) in raw.chunks_exact(12).enumerate() {
        let t = [0, 4, 8].map(|o| u32::from_le_bytes(c[o..o + 4].try_into().expect("4 bytes")));
        if let Some(&i) = t.iter().find(|&&i| i as usize >= nv) {
            return Err(FormatError::in_file(
                name,
                format!("triangle {k}: vertex {i} is out of range ({nv} vertices)"),
            ));
        }
        indices.push(t);
    }
    Ok(SerializedMesh {
        mesh: SceneMesh {
            mesh: Mesh { positions, indices },
            normals,
            uvs,
            ..SceneMesh::default()
        },
        face_normals: flags & FACE_NORMALS != 0,
    })
}

/// Positions, triangles and flags of a mesh to write.
#[cfg(test)]
pub(crate) type MeshToWrite = (Vec<[f32; 3]>, Vec<[u32; 3]>, u32);

/// A serialized file of `meshes`, version 4 with doubles when `double`,
/// for tests.
#[cfg(test)]
pub(crate) fn write_serialized(meshes: &[MeshToWrite], double: bool) -> Vec<u8> {
    use std::io::Write;
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for (p, t, flags) in meshes {
        offsets.push(out.len() as u64);
        out.extend_from_slice(&MAGIC.to_le_bytes());
        out.extend_from_slice(&4u16.to_le_bytes());
        let mut body = Vec::new();
        let flags = flags | if double { DOUBLE } else { 0x1000 };
        body.extend_from_slice(&flags.to_le_bytes());
        body.extend_from_slice(b"mesh\0");
        body.extend_from_slice(&(p.len() as u64).to_le_bytes());
        body.extend_from_slice(&(t.len() as u64).to_le_bytes());
        for v in p.iter().flatten() {
            if double {
                body.extend_from_slice(&f64::from(*v).to_le_bytes());
            } else {
                body.extend_from_slice(&v.to_le_bytes());
            }
        }
        for i in t.iter().flatten() {
            body.extend_from_slice(&i.to_le_bytes());
        }
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(&body).unwrap();
        out.extend_from_slice(&z.finish().unwrap());
    }
    for o in &offsets {
        out.extend_from_slice(&o.to_le_bytes());
    }
    out.extend_from_slice(&(offsets.len() as u32).to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mesh_of_a_file_reads_by_its_index() {
        let tri = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let quad = vec![
            [0.0, 0.0, 2.0],
            [1.0, 0.0, 2.0],
            [1.0, 1.0, 2.0],
            [0.0, 1.0, 2.0],
        ];
        for double in [false, true] {
            let bytes = write_serialized(
                &[
                    (tri.clone(), vec![[0, 1, 2]], 0),
                    (quad.clone(), vec![[0, 1, 2], [0, 2, 3]], FACE_NORMALS),
                ],
                double,
            );
            let a = parse_serialized(&bytes, "m.serialized", 0).unwrap();
            assert_eq!(a.mesh.mesh.indices, vec![[0, 1, 2]]);
            assert!(!a.face_normals);
            let b = parse_serialized(&bytes, "m.serialized", 1).unwrap();
            assert_eq!(b.mesh.mesh.positions[2], Vec3::new(1.0, 1.0, 2.0));
            assert_eq!(b.mesh.mesh.indices.len(), 2);
            assert!(b.face_normals);
            let e = parse_serialized(&bytes, "m.serialized", 2)
                .err()
                .unwrap()
                .to_string();
            assert_eq!(e, "m.serialized: shape_index 2: the file holds 2 mesh(es)");
        }
        let e = parse_serialized(b"PK\x03\x04", "m.serialized", 0)
            .err()
            .unwrap()
            .to_string();
        assert_eq!(
            e,
            "m.serialized: byte 0: not a Mitsuba serialized mesh (no 0x041C format id)"
        );
    }
}
