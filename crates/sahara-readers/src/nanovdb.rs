//! NanoVDB grids (`.nvdb`, pbrt-v4's `nanovdb` medium), read with the
//! `nanovdb-rs` crate into a dense grid, as [`crate::vdb`] reads OpenVDB
//! files.
//!
//! A `.nvdb` file holds one or more grids, each a sparse tree (a root
//! table, 32³ and 16³ internal nodes, 8³ leaves) and a map from voxel
//! indices to world space. This reader takes the float grid of a given
//! name, reads every voxel of its index bounding box (the box of its
//! active values, which NanoVDB keeps in the grid's metadata) into a
//! dense box, and gives the map that places the box in the world, voxel
//! centres on the centres of the renderer's cells.
//!
//! What `nanovdb-rs` 0.0.7 reads, and so what this reader accepts:
//! NanoVDB 32.x files (OpenVDB 10 onwards), uncompressed or ZIP, grids of
//! 32-bit floats, maps that scale and translate (no rotation). Refused
//! with a message naming the file: a file that is not NanoVDB, Blosc
//! compression (convert with `nanovdb_convert` without `-b`), a grid name
//! the file does not hold (the message lists those it does), a grid of
//! another type (quantised `Fp4`/`Fp8`/`Fp16`/`FpN`, half, vector or
//! double grids), a tree whose links do not hold together, a rotated map,
//! a dense box of more than [`MAX_VALUES`] voxels (checked before
//! anything is allocated).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use nanovdb_rs::{GridType, NvdbFile, ReadAccessor, ValidatedFloatTree};

use crate::error::FormatError;
use crate::vdb::{check_size, panic_text, VdbGrid, MAX_VALUES};

/// Reads the float grid named `grid` from the `.nvdb` file at `path`.
pub fn read_nanovdb(path: &Path, grid: &str) -> Result<VdbGrid, FormatError> {
    NanoVdbFile::open(path)?.grid(grid)
}

/// An opened `.nvdb` file, whose grids are read by name (one opening, and
/// one decompression, for a density and a temperature grid alike).
pub struct NanoVdbFile {
    file: NvdbFile,
    name: String,
}

impl NanoVdbFile {
    /// Opens the `.nvdb` file at `path` and reads its grids' metadata.
    pub fn open(path: &Path) -> Result<Self, FormatError> {
        let name = path.display().to_string();
        // Opening first gives an unreadable file its own error.
        std::fs::File::open(path).map_err(|source| FormatError::Io {
            path: name.clone(),
            source,
        })?;
        let in_file = |message: String| FormatError::InFile {
            path: name.clone(),
            message,
        };
        // `nanovdb-rs` indexes its bytes without checking every offset a
        // damaged file may hold; such a panic becomes an error naming the
        // file.
        let file = catch_unwind(AssertUnwindSafe(|| NvdbFile::open(path)))
            .map_err(|p| in_file(format!("not a NanoVDB file it can read: {}", panic_text(p))))?
            .map_err(|e| match e {
                nanovdb_rs::Error::CompressionUnsupported(codec) => in_file(format!(
                    "its grids are compressed with {codec:?}, which is not read; \
                     write it uncompressed or with ZIP (nanovdb_convert without -b, or with -z)"
                )),
                e => in_file(e.to_string()),
            })?;
        Ok(Self { file, name })
    }

    /// Whether the file holds a grid named `grid`.
    pub fn has(&self, grid: &str) -> bool {
        self.file.grids().iter().any(|g| g.name() == grid)
    }

    /// The float grid named `grid`, laid out densely over its index
    /// bounding box.
    pub fn grid(&self, grid: &str) -> Result<VdbGrid, FormatError> {
        let name = &self.name;
        let in_file = |message: String| FormatError::InFile {
            path: name.clone(),
            message,
        };
        let Some(g) = self.file.grids().iter().find(|g| g.name() == grid) else {
            let mut names: Vec<&str> = self.file.grids().iter().map(|g| g.name()).collect();
            names.sort_unstable();
            return Err(in_file(format!(
                "no grid is named '{grid}'; the file holds {}",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )));
        };
        let what = format!("grid '{grid}'");
        if g.value_type() != GridType::Float {
            return Err(in_file(format!(
                "{what} holds {:?} values; a density grid of 32-bit floats is read",
                g.value_type()
            )));
        }
        let (lo, hi) = g.index_bbox();
        if g.voxel_count() == 0 {
            return Err(in_file(format!("{what} has no active voxels")));
        }
        let size = check_size(lo, hi, name, &what)?;
        let read = catch_unwind(AssertUnwindSafe(|| dense(g, lo, size)))
            .map_err(|p| in_file(format!("{what}: a damaged tree: {}", panic_text(p))))?;
        let (values, map) = read.ok_or_else(|| {
            in_file(format!(
                "{what}: its tree does not hold together (a link points outside the grid)"
            ))
        })?;
        let m = map.mat_d;
        let diagonal = [m[0][0], m[1][1], m[2][2]];
        let off_diagonal = [m[0][1], m[0][2], m[1][0], m[1][2], m[2][0], m[2][1]];
        if off_diagonal.iter().any(|&v| v != 0.0)
            || diagonal.iter().any(|s| !s.is_finite() || *s == 0.0)
            || map.vec_d.iter().any(|t| !t.is_finite())
        {
            return Err(in_file(format!(
                "{what}: its map {m:?} + {:?} must scale and translate (no rotation), finitely",
                map.vec_d
            )));
        }
        Ok(VdbGrid {
            size,
            index_min: lo,
            values,
            voxel_size: diagonal,
            translation: map.vec_d,
        })
    }
}

/// The grid's values over the box of `size` voxels from index `lo`, x
/// fastest, and its map; `None` if its tree fails validation.
fn dense(
    g: &nanovdb_rs::Grid,
    lo: [i32; 3],
    size: [u32; 3],
) -> Option<(Vec<f32>, nanovdb_rs::Map)> {
    let bytes = g.raw_bytes();
    // Validation walks every link of the tree once, so the lookups below
    // stay inside the grid's bytes.
    ValidatedFloatTree::new(bytes)?;
    let map = g.header()?.map;
    let mut acc = ReadAccessor::<f32>::from_grid_bytes(bytes)?;
    let n = size.iter().map(|&v| v as usize).product::<usize>();
    debug_assert!(n as u64 <= MAX_VALUES);
    let mut values = Vec::with_capacity(n);
    for z in 0..size[2] as i32 {
        for y in 0..size[1] as i32 {
            for x in 0..size[0] as i32 {
                values.push(acc.get_value([lo[0] + x, lo[1] + y, lo[2] + z]));
            }
        }
    }
    Some((values, map))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn asset(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes/assets")
            .join(name)
    }

    /// `blob.nvdb` is `blob.vdb` converted by NanoVDB's own
    /// `nanovdb_convert -z` (ZIP): the same dense box, values and
    /// placement, to the bit.
    #[test]
    fn nanovdb_twins_hold_the_vdb_files_values() {
        let nvdb = read_nanovdb(&asset("blob.nvdb"), "density").unwrap();
        let vdb = crate::vdb::read_vdb(&asset("blob.vdb"), "density").unwrap();
        assert_eq!(nvdb, vdb);
        assert!(nvdb.values.iter().filter(|&&v| v > 0.0).count() > 1000);
    }

    /// A copy of `blob.nvdb` with its bytes changed, written for the test.
    fn altered(name: &str, change: impl FnOnce(&mut Vec<u8>)) -> std::path::PathBuf {
        let mut bytes = std::fs::read(asset("blob.nvdb")).unwrap();
        change(&mut bytes);
        let dir = std::env::temp_dir().join(format!("sahara-nvdb-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    /// Files the reader refuses say why, naming the file; damaged files
    /// are errors, not crashes.
    #[test]
    fn unreadable_grids_are_named() {
        let err = |path: &Path, grid: &str| read_nanovdb(path, grid).unwrap_err().to_string();
        let e = err(&asset("blob.nvdb"), "smoke");
        assert!(
            e.contains("blob.nvdb: no grid is named 'smoke'; the file holds density"),
            "{e}"
        );
        let e = err(&asset("blob_fp8.nvdb"), "density");
        assert!(
            e.contains("blob_fp8.nvdb: grid 'density' holds Fp8 values"),
            "{e}"
        );
        let e = err(&asset("blob.vdb"), "density");
        assert!(e.contains("blob.vdb: bad magic"), "{e}");
        let e = err(&asset("missing.nvdb"), "density");
        assert!(e.contains("missing.nvdb"), "{e}");
        // The segment header's codec (bytes 14..16) set to Blosc.
        let blosc = altered("blosc.nvdb", |b| {
            b[14..16].copy_from_slice(&2u16.to_le_bytes())
        });
        let e = err(&blosc, "density");
        assert!(
            e.contains("blosc.nvdb: its grids are compressed with Blosc"),
            "{e}"
        );
        // Cut short at every tenth of its length, or with its compressed
        // grid's bytes scrambled: an error naming the file each time.
        let len = std::fs::read(asset("blob.nvdb")).unwrap().len();
        for tenth in 1..10 {
            let cut = altered("cut.nvdb", |b| b.truncate(len * tenth / 10));
            let e = err(&cut, "density");
            assert!(e.contains("cut.nvdb"), "{tenth}: {e}");
        }
        let scrambled = altered("scrambled.nvdb", |b| {
            let n = b.len();
            b[n / 2..n / 2 + 64].fill(0xa5)
        });
        let e = err(&scrambled, "density");
        assert!(e.contains("scrambled.nvdb"), "{e}");
    }
}
