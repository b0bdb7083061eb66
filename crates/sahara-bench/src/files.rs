//! The protocol's binary files, little endian, no header:
//! - ray file: 32 bytes per ray, `f32 ox oy oz tmin dx dy dz tmax`;
//! - hit file: 8 bytes per ray, `f32 t, u32 triangle` (see [`HitRecord`]).

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use glam::Vec3;
use sahara_kd::Ray;

use crate::record::HitRecord;

/// Bytes per ray in a ray file.
pub const RAY_BYTES: usize = 32;
/// Bytes per record in a hit file.
pub const HIT_BYTES: usize = 8;

/// Why a ray or hit file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be opened, read or written.
    #[error("{}: {io}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said (part of the message, so not a `source`).
        io: io::Error,
    },
    /// The file's size is not a whole number of records.
    #[error("{}: {len} bytes is not a whole number of {record}-byte {what} records", path.display())]
    BadSize {
        /// The file.
        path: PathBuf,
        /// Its size in bytes.
        len: usize,
        /// The record size.
        record: usize,
        /// `ray` or `hit`.
        what: &'static str,
    },
}

/// The ray file bytes of `rays`.
pub fn rays_to_bytes(rays: &[Ray]) -> Vec<u8> {
    let mut out = Vec::with_capacity(rays.len() * RAY_BYTES);
    for r in rays {
        for f in [
            r.origin.x, r.origin.y, r.origin.z, r.tmin, r.dir.x, r.dir.y, r.dir.z, r.tmax,
        ] {
            out.extend_from_slice(&f.to_le_bytes());
        }
    }
    out
}

/// The rays in ray file bytes, or `None` if the length is not a multiple of
/// [`RAY_BYTES`].
pub fn rays_from_bytes(bytes: &[u8]) -> Option<Vec<Ray>> {
    if !bytes.len().is_multiple_of(RAY_BYTES) {
        return None;
    }
    let rays = bytes
        .chunks_exact(RAY_BYTES)
        .map(|c| {
            let f =
                |k: usize| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
            Ray::with_interval(
                Vec3::new(f(0), f(1), f(2)),
                Vec3::new(f(4), f(5), f(6)),
                f(3),
                f(7),
            )
        })
        .collect();
    Some(rays)
}

/// The hit file bytes of `records`.
pub fn hits_to_bytes(records: &[HitRecord]) -> Vec<u8> {
    let mut out = Vec::with_capacity(records.len() * HIT_BYTES);
    for r in records {
        out.extend_from_slice(&r.t.to_le_bytes());
        out.extend_from_slice(&r.tri.to_le_bytes());
    }
    out
}

/// The records in hit file bytes, or `None` if the length is not a multiple
/// of [`HIT_BYTES`].
pub fn hits_from_bytes(bytes: &[u8]) -> Option<Vec<HitRecord>> {
    if !bytes.len().is_multiple_of(HIT_BYTES) {
        return None;
    }
    let records = bytes
        .chunks_exact(HIT_BYTES)
        .map(|c| HitRecord {
            t: f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
            tri: u32::from_le_bytes([c[4], c[5], c[6], c[7]]),
        })
        .collect();
    Some(records)
}

fn read(path: &Path) -> Result<Vec<u8>, FileError> {
    fs::read(path).map_err(|io| FileError::Io {
        path: path.to_owned(),
        io,
    })
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    fs::write(path, bytes).map_err(|io| FileError::Io {
        path: path.to_owned(),
        io,
    })
}

fn bad_size(path: &Path, len: usize, record: usize, what: &'static str) -> FileError {
    FileError::BadSize {
        path: path.to_owned(),
        len,
        record,
        what,
    }
}

/// Write a ray file.
pub fn write_rays(path: &Path, rays: &[Ray]) -> Result<(), FileError> {
    write(path, &rays_to_bytes(rays))
}

/// Read a ray file, checking that its size is a multiple of 32 bytes.
pub fn read_rays(path: &Path) -> Result<Vec<Ray>, FileError> {
    let bytes = read(path)?;
    rays_from_bytes(&bytes).ok_or_else(|| bad_size(path, bytes.len(), RAY_BYTES, "ray"))
}

/// Write a hit file.
pub fn write_hits(path: &Path, records: &[HitRecord]) -> Result<(), FileError> {
    write(path, &hits_to_bytes(records))
}

/// Read a hit file, checking that its size is a multiple of 8 bytes.
pub fn read_hits(path: &Path) -> Result<Vec<HitRecord>, FileError> {
    let bytes = read(path)?;
    hits_from_bytes(&bytes).ok_or_else(|| bad_size(path, bytes.len(), HIT_BYTES, "hit"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh, empty directory under the system temp dir.
    fn temp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("sahara-bench-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn sample_rays() -> Vec<Ray> {
        vec![
            Ray::with_interval(
                Vec3::new(1.0, -2.5, 3.25),
                Vec3::new(0.0, -0.0, 1.0),
                0.0,
                f32::INFINITY,
            ),
            Ray::with_interval(
                Vec3::new(f32::MIN_POSITIVE, 1e30, -7.0),
                Vec3::new(0.6, 0.8, 0.0),
                0.125,
                99.5,
            ),
        ]
    }

    #[test]
    fn ray_layout_is_little_endian_ox_oy_oz_tmin_dx_dy_dz_tmax() {
        let b = rays_to_bytes(&sample_rays()[..1]);
        assert_eq!(b.len(), 32);
        assert_eq!(&b[0..4], &1.0f32.to_le_bytes());
        assert_eq!(&b[12..16], &0.0f32.to_le_bytes()); // tmin
        assert_eq!(&b[16..20], &0.0f32.to_le_bytes()); // dx
        assert_eq!(&b[20..24], &[0, 0, 0, 0x80]); // dy = -0.0, little endian
        assert_eq!(&b[28..32], &[0, 0, 0x80, 0x7f]); // tmax = +inf
    }

    #[test]
    fn rays_round_trip_bit_for_bit() {
        let dir = temp_dir("rays");
        let path = dir.join("r.bin");
        let rays = sample_rays();
        write_rays(&path, &rays).unwrap();
        assert_eq!(fs::metadata(&path).unwrap().len(), 64);
        let back = read_rays(&path).unwrap();
        assert_eq!(rays_to_bytes(&back), rays_to_bytes(&rays));
        assert_eq!(back[1].tmin, 0.125);
        assert!(back[0].dir.y.is_sign_negative());
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn hits_round_trip_with_miss_and_occluded_markers() {
        let dir = temp_dir("hits");
        let path = dir.join("h.bin");
        let recs = vec![
            HitRecord { t: 1.5, tri: 0 },
            HitRecord::MISS,
            HitRecord::OCCLUDED,
            HitRecord {
                t: 3.0e-7,
                tri: 123_456,
            },
        ];
        write_hits(&path, &recs).unwrap();
        let bytes = fs::read(&path).unwrap();
        assert_eq!(bytes.len(), 32);
        assert_eq!(&bytes[8..16], &[0, 0, 0x80, 0x7f, 0xff, 0xff, 0xff, 0xff]);
        assert_eq!(&bytes[16..24], &[0, 0, 0, 0, 0xfe, 0xff, 0xff, 0xff]);
        assert_eq!(read_hits(&path).unwrap(), recs);
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn wrong_sizes_and_missing_files_are_clear_errors() {
        let dir = temp_dir("bad");
        let path = dir.join("odd.bin");
        fs::write(&path, vec![0u8; 33]).unwrap();
        let e = read_rays(&path).unwrap_err();
        assert!(matches!(
            e,
            FileError::BadSize {
                len: 33,
                record: 32,
                ..
            }
        ));
        let msg = e.to_string();
        assert!(
            msg.contains("odd.bin") && msg.contains("33 bytes") && msg.contains("32-byte ray"),
            "{msg}"
        );
        fs::write(&path, vec![0u8; 12]).unwrap();
        let msg = read_hits(&path).unwrap_err().to_string();
        assert!(
            msg.contains("12 bytes") && msg.contains("8-byte hit"),
            "{msg}"
        );
        // Empty files are valid: zero records.
        fs::write(&path, []).unwrap();
        assert!(read_rays(&path).unwrap().is_empty());
        assert!(read_hits(&path).unwrap().is_empty());
        let missing = dir.join("nope.bin");
        let msg = read_rays(&missing).unwrap_err().to_string();
        assert!(msg.contains("nope.bin"), "{msg}");
        fs::remove_dir_all(dir).unwrap();
    }
}
