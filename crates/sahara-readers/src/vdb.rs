//! OpenVDB grids (`.vdb`), read with the `vdb-rs` crate into a dense grid.
//!
//! A `.vdb` file holds named sparse grids: a tree of 8³ leaves of voxels
//! and larger constant tiles, of which only the *active* values matter
//! (the rest is the background, zero for a density), and a map from voxel
//! indices to world space. This reader takes one float grid, lays its
//! active voxels and tiles into a dense box spanning them (inactive voxels
//! inside the box are zero), and gives the map that places that box in the
//! world, so the renderer's cell-centred trilinear grid reproduces the
//! VDB's values at the voxel centres.
//!
//! What `vdb-rs` 0.6 reads, and so what this reader accepts: file format
//! versions 219 to 224 (OpenVDB 2 onwards; 224 is what OpenVDB 6 to 12
//! write, and the one tested), Blosc, zlib or no compression, 32-bit
//! floats, and the scale and scale-translate maps (a voxel size per axis
//! and an offset; no rotation). Refused with a message naming the
//! file: a file that is not an OpenVDB file, another version, a grid name
//! the file does not hold (the message lists those it does), a grid of
//! another type (vectors, doubles, level sets are floats and are read but
//! their negative values are refused as densities later), a grid saved
//! as half floats (which `vdb-rs` 0.6 misreads), an instanced
//! grid, a rotated or frustum map, a dense box of more than
//! [`MAX_VALUES`] voxels (checked from the file's bounding-box metadata
//! before the tree is read, and from the active values before the dense
//! box is allocated). Tiles at the tree's root (4096³ voxels each) are
//! skipped by `vdb-rs`.

use std::fs;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use glam::{Affine3A, DVec3, Quat, Vec3};
use vdb_rs::{GridDescriptor, Map, MetadataValue, VdbLevel, VdbReader};

use crate::error::FormatError;

/// The most voxels a dense grid read from a `.vdb` file may hold (2^28:
/// one GiB of 32-bit floats).
pub const MAX_VALUES: u64 = 1 << 28;

/// The file versions read (see the module's documentation).
const VERSIONS: std::ops::RangeInclusive<u32> = 219..=224;

/// One grid of a `.vdb` (or NanoVDB `.nvdb`) file, laid out densely over
/// its active box.
#[derive(Clone, Debug, PartialEq)]
pub struct VdbGrid {
    /// Voxels per axis (x, y, z) of the dense box.
    pub size: [u32; 3],
    /// The index of the box's first voxel in the file's index space.
    pub index_min: [i32; 3],
    /// `size` product values, x varying fastest, then y, then z.
    pub values: Vec<f32>,
    /// World size of a voxel per axis (the map's scale).
    pub voxel_size: [f64; 3],
    /// World position of voxel (0, 0, 0)'s centre (the map's translation).
    pub translation: [f64; 3],
}

impl VdbGrid {
    /// The map from the unit cube, its cells centred on the dense box's
    /// voxels (value `(x, y, z)` at `((x + 1/2) / nx, ...)`), to world space.
    pub fn to_world(&self) -> Affine3A {
        let s = DVec3::from_array(self.voxel_size);
        let n = DVec3::from_array(self.size.map(f64::from));
        let lo = DVec3::from_array(self.index_min.map(f64::from)) - 0.5;
        let t = DVec3::from_array(self.translation) + s * lo;
        Affine3A::from_scale_rotation_translation(
            (s * n).as_vec3(),
            Quat::IDENTITY,
            Vec3::new(t.x as f32, t.y as f32, t.z as f32),
        )
    }
}

/// Reads the float grid named `grid` from the `.vdb` file at `path`.
pub fn read_vdb(path: &Path, grid: &str) -> Result<VdbGrid, FormatError> {
    let name = path.display().to_string();
    let bytes = fs::read(path).map_err(|source| FormatError::Io {
        path: name.clone(),
        source,
    })?;
    parse_vdb(&bytes, &name, grid)
}

/// The text of a panic's payload.
pub(crate) fn panic_text(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "an unexpected structure".into())
}

/// Parses the bytes of a `.vdb` file and reads its float grid named
/// `grid`; `name` names the file in errors.
pub fn parse_vdb(bytes: &[u8], name: &str, grid: &str) -> Result<VdbGrid, FormatError> {
    let in_file = |message: String| FormatError::InFile {
        path: name.to_owned(),
        message,
    };
    check_header(bytes, name)?;
    // `vdb-rs` panics (rather than failing) on some structures it does not
    // read; those become errors naming the file.
    let guarded = |what: &str, f: &mut dyn FnMut() -> Result<(), String>| match catch_unwind(
        AssertUnwindSafe(f),
    ) {
        Ok(r) => r.map_err(|m| in_file(format!("{what}: {m}"))),
        Err(p) => Err(in_file(format!(
            "{what}: unsupported by the VDB reader (vdb-rs): {}",
            panic_text(p)
        ))),
    };
    let mut reader = None;
    guarded("reading the file's header", &mut || {
        reader = Some(VdbReader::new(Cursor::new(bytes)).map_err(|e| e.to_string())?);
        Ok(())
    })?;
    let mut reader = reader.expect("set when Ok");
    let Some(desc) = reader.grid_descriptors.get(grid).cloned() else {
        let mut names = reader.available_grids();
        names.sort();
        return Err(in_file(format!(
            "no grid is named '{grid}'; the file holds {}",
            if names.is_empty() {
                "none".to_string()
            } else {
                names
                    .iter()
                    .map(|n| format!("'{n}'"))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        )));
    };
    let what = format!("grid '{grid}'");
    check_descriptor(&desc, name, &what)?;
    let mut read = None;
    guarded(&format!("reading {what}"), &mut || {
        read = Some(reader.read_grid::<f32>(grid).map_err(|e| e.to_string())?);
        Ok(())
    })?;
    let g = read.expect("set when Ok");
    let (voxel_size, translation) = match g.transform {
        Map::UniformScaleMap { scale_values, .. } => (scale_values, None),
        Map::ScaleTranslateMap {
            scale_values,
            translation,
            ..
        } => (scale_values, Some(translation)),
    };
    let voxel_size = [voxel_size.x, voxel_size.y, voxel_size.z];
    let translation = translation.map_or([0.0; 3], |t| [t.x, t.y, t.z]);
    if voxel_size.iter().any(|s| !s.is_finite() || *s == 0.0)
        || translation.iter().any(|t| !t.is_finite())
    {
        return Err(in_file(format!(
            "{what}: voxel size {voxel_size:?} and offset {translation:?} must be finite, the size not zero"
        )));
    }
    // Active voxels and tiles: (first index, side, value).
    let items: Vec<([i32; 3], i32, f32)> = g
        .iter()
        .map(|(c, v, level)| {
            let side = match level {
                VdbLevel::Voxel => 1,
                VdbLevel::Node3 => 8,
                VdbLevel::Node4 => 128,
            };
            ([c.x as i32, c.y as i32, c.z as i32], side, v)
        })
        .collect();
    if items.is_empty() {
        return Err(in_file(format!("{what} has no active voxels")));
    }
    let (size, lo, values) = dense(items, name, &what)?;
    Ok(VdbGrid {
        size,
        index_min: lo,
        values,
        voxel_size,
        translation,
    })
}

/// Refuses a file that is not OpenVDB or is of a format version `vdb-rs`
/// does not read, naming the byte; `vdb-rs` does not check the magic
/// number itself.
fn check_header(bytes: &[u8], name: &str) -> Result<(), FormatError> {
    let at = |offset: u64, message: String| FormatError::AtByte {
        path: name.to_owned(),
        offset,
        message,
    };
    if bytes.len() < 12 || bytes[0..8] != [0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0] {
        return Err(at(
            0,
            "not an OpenVDB file (it does not start with the bytes of ' BDV')".into(),
        ));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if !VERSIONS.contains(&version) {
        return Err(at(
            8,
            format!(
                "OpenVDB file format version {version}; versions {} to {} are read",
                VERSIONS.start(),
                VERSIONS.end()
            ),
        ));
    }
    Ok(())
}

/// Refuses a grid `vdb-rs` cannot read into a density (another type,
/// half floats, an instance of another grid) or whose recorded active box
/// is too large, before its tree is read.
fn check_descriptor(desc: &GridDescriptor, name: &str, what: &str) -> Result<(), FormatError> {
    let in_file = |message: String| FormatError::InFile {
        path: name.to_owned(),
        message,
    };
    let kind = desc.grid_type.trim_end_matches("_HalfFloat");
    if kind != "Tree_float_5_4_3" {
        return Err(in_file(format!(
            "{what} is of type '{}'; a density is read from a float grid (Tree_float_5_4_3)",
            desc.grid_type
        )));
    }
    // vdb-rs 0.6 misreads the tree of a grid saved as half floats and
    // then asks for petabytes (an abort, not an error): refused here.
    if desc.grid_type.ends_with("_HalfFloat") || desc.meta_data.is_half_float() {
        return Err(in_file(format!(
            "{what} is saved as 16-bit (half) floats, which the VDB reader (vdb-rs 0.6) \
             cannot read; save it with 32-bit floats"
        )));
    }
    if !desc.instance_parent.is_empty() {
        return Err(in_file(format!(
            "{what} shares the tree of grid '{}' (an instanced grid), which is not read",
            desc.instance_parent
        )));
    }
    // The active box the file records, checked before the tree is read.
    let meta_box = match (
        desc.meta_data.0.get("file_bbox_min"),
        desc.meta_data.0.get("file_bbox_max"),
    ) {
        (Some(MetadataValue::Vec3i(a)), Some(MetadataValue::Vec3i(b))) => {
            Some(([a.x, a.y, a.z], [b.x, b.y, b.z]))
        }
        _ => None,
    };
    if let Some((lo, hi)) = meta_box {
        check_size(lo, hi, name, what)?;
    }
    Ok(())
}

/// A dense block of voxels: its size, its first index and the values,
/// x fastest.
type DenseBlock = ([u32; 3], [i32; 3], Vec<f32>);

/// Lays active voxels and tiles (first index, side, value) out densely
/// over the box that spans them: its size, its first index and the values,
/// x fastest.
fn dense(
    items: Vec<([i32; 3], i32, f32)>,
    name: &str,
    what: &str,
) -> Result<DenseBlock, FormatError> {
    let mut lo = [i32::MAX; 3];
    let mut hi = [i32::MIN; 3];
    for (c, side, _) in &items {
        for a in 0..3 {
            lo[a] = lo[a].min(c[a]);
            hi[a] = hi[a].max(c[a].saturating_add(side - 1));
        }
    }
    let size = check_size(lo, hi, name, what)?;
    let [nx, ny, nz] = size.map(|n| n as usize);
    let mut values = vec![0.0f32; nx * ny * nz];
    for (c, side, v) in items {
        for z in c[2]..c[2] + side {
            for y in c[1]..c[1] + side {
                let row = ((z - lo[2]) as usize * ny + (y - lo[1]) as usize) * nx;
                let x0 = (c[0] - lo[0]) as usize;
                values[row + x0..row + x0 + side as usize].fill(v);
            }
        }
    }
    Ok((size, lo, values))
}

/// The voxels per axis of the inclusive index box `lo` to `hi`, or an
/// error naming the file if it is empty or holds more than [`MAX_VALUES`].
pub(crate) fn check_size(
    lo: [i32; 3],
    hi: [i32; 3],
    name: &str,
    what: &str,
) -> Result<[u32; 3], FormatError> {
    let n = [0, 1, 2].map(|a| i64::from(hi[a]) - i64::from(lo[a]) + 1);
    let total = n.iter().map(|&v| v.max(0) as u128).product::<u128>();
    if n.iter().any(|&v| v <= 0) || total > u128::from(MAX_VALUES) {
        return Err(FormatError::InFile {
            path: name.to_owned(),
            message: format!(
                "{what}: its active voxels span {}x{}x{} (index {lo:?} to {hi:?}); a dense grid \
                 of at most {MAX_VALUES} voxels is read",
                n[0], n[1], n[2]
            ),
        });
    }
    Ok(n.map(|v| v as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert_eq!(
            check_size([0; 3], [1, 2, 3], "a.vdb", "g").unwrap(),
            [2, 3, 4]
        );
        let e = check_size([0; 3], [4095; 3], "a.vdb", "grid 'd'").unwrap_err();
        assert!(e
            .to_string()
            .starts_with("a.vdb: grid 'd': its active voxels span 4096x4096x4096"));
        assert!(check_size([0; 3], [-1, 0, 0], "a.vdb", "g").is_err());
    }

    fn asset(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes/assets")
            .join(name)
    }

    /// The VDB twin of blob.vol (scripts/make_vdb.py) holds its values at
    /// its voxels, exactly, placed where the .vol file places them.
    #[test]
    fn vdb_twins_hold_the_vol_files_values() {
        let vol = crate::vol::read_vol(&asset("blob.vol")).unwrap();
        let lo = Vec3::from_array(vol.bounds_min);
        let h = (Vec3::from_array(vol.bounds_max) - lo) / 32.0;
        {
            let file = "blob.vdb";
            let g = read_vdb(&asset(file), "density").unwrap();
            let to_world = g.to_world();
            let n = g.size.map(|v| v as i32);
            let mut inside = 0;
            for k in 0..32 {
                for j in 0..32 {
                    for i in 0..32 {
                        let want = vol.values[(k * 32 + j) * 32 + i];
                        let c = [i as i32, j as i32, k as i32];
                        let d = [0, 1, 2].map(|a| c[a] - g.index_min[a]);
                        if (0..3).any(|a| d[a] < 0 || d[a] >= n[a]) {
                            assert_eq!(want, 0.0, "{file}: {c:?} outside the active box");
                            continue;
                        }
                        inside += 1;
                        let got = g.values[((d[2] * n[1] + d[1]) * n[0] + d[0]) as usize];
                        assert_eq!(got, want, "{file}: {c:?}");
                        // The voxel's centre lands where the .vol file puts it.
                        let u = (Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32) + 0.5)
                            / Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
                        let world = to_world.transform_point3(u);
                        let centre = lo + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * h;
                        assert!(
                            (world - centre).abs().max_element() < 1e-5,
                            "{world} {centre}"
                        );
                    }
                }
            }
            // The active box is the blob's, smaller than the .vol's grid.
            assert!(
                inside > 1000 && g.size.iter().product::<u32>() < 32 * 32 * 32,
                "{:?}",
                g.size
            );
        }
    }

    /// Files the reader refuses say why, naming the file.
    #[test]
    fn unreadable_grids_are_named() {
        let err = |file: &str, grid: &str| read_vdb(&asset(file), grid).unwrap_err().to_string();
        let e = err("blob.vdb", "smoke");
        assert!(
            e.contains("blob.vdb: no grid is named 'smoke'; the file holds 'density'"),
            "{e}"
        );
        let e = err("vdb_vector.vdb", "velocity");
        assert!(
            e.contains("vdb_vector.vdb: grid 'velocity' is of type 'Tree_vec3s_5_4_3'"),
            "{e}"
        );
        let e = err("blob_half.vdb", "density");
        assert!(
            e.contains("blob_half.vdb: grid 'density' is saved as 16-bit (half) floats"),
            "{e}"
        );
        let e = err("vdb_huge.vdb", "density");
        assert!(
            e.contains("vdb_huge.vdb: grid 'density': its active voxels span 4096x4096x4096"),
            "{e}"
        );
        let e = err("vdb_rotated.vdb", "density");
        assert!(
            e.contains("vdb_rotated.vdb: reading grid 'density': unsupported"),
            "{e}"
        );
        let e = err("blob.vol", "density");
        assert!(e.contains("blob.vol: byte 0: not an OpenVDB file"), "{e}");
    }

    #[test]
    fn other_files_are_not_vdb() {
        let e = parse_vdb(b"VOL\x03 and more bytes", "x.vdb", "density").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("x.vdb: byte 0: not an OpenVDB file"),
            "{e}"
        );
        let mut b = vec![0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0];
        b.extend_from_slice(&210u32.to_le_bytes());
        let e = parse_vdb(&b, "x.vdb", "density").unwrap_err();
        assert!(
            e.to_string()
                .contains("byte 8: OpenVDB file format version 210"),
            "{e}"
        );
    }
}
