//! Mitsuba's binary volume grids (`.vol`, the format of its `gridvolume`).
//!
//! The layout (Mitsuba's documentation of `gridvolume`): the bytes `VOL`,
//! a version byte (3), then little-endian 32-bit fields: the encoding
//! (1: 32-bit floats; other encodings are refused), the x, y and z
//! resolutions and the number of channels (1 for a density, 3 for a
//! colour), six floats of bounding box (min x, y, z, max x, y, z), then
//! the values, x varying fastest, then y, then z, channels interleaved.
//! The sizes in the header are checked against the file's length before
//! anything is allocated.

use std::fs;
use std::path::Path;

use crate::error::FormatError;

/// A grid as the file holds it.
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    /// Resolution (x, y, z).
    pub size: [u32; 3],
    /// Values per grid point (1 or 3).
    pub channels: u32,
    /// The box the file says the grid spans (lower corner).
    pub bounds_min: [f32; 3],
    /// The box's upper corner.
    pub bounds_max: [f32; 3],
    /// `size` product times `channels` values, x fastest, channels
    /// interleaved.
    pub values: Vec<f32>,
}

/// Bytes before the values.
const HEADER: usize = 48;

/// Reads a `.vol` file.
pub fn read_vol(path: &Path) -> Result<VolGrid, FormatError> {
    let name = path.display().to_string();
    let bytes = fs::read(path).map_err(|source| FormatError::Io {
        path: name.clone(),
        source,
    })?;
    parse_vol(&bytes, &name)
}

/// Parses the bytes of a `.vol` file; `name` names it in errors.
pub fn parse_vol(bytes: &[u8], name: &str) -> Result<VolGrid, FormatError> {
    let at = |offset: usize, message: String| FormatError::AtByte {
        path: name.to_owned(),
        offset: offset as u64,
        message,
    };
    if bytes.len() < HEADER {
        return Err(at(
            bytes.len(),
            format!(
                "the file ends after {} bytes, inside the {HEADER}-byte header of a .vol grid",
                bytes.len()
            ),
        ));
    }
    if &bytes[0..3] != b"VOL" {
        return Err(at(
            0,
            "not a .vol grid (it does not start with `VOL`)".into(),
        ));
    }
    if bytes[3] != 3 {
        return Err(at(
            3,
            format!("version {} of the .vol format; version 3 is read", bytes[3]),
        ));
    }
    let i32_at = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let encoding = i32_at(4);
    if encoding != 1 {
        return Err(at(
            4,
            format!("encoding {encoding}; only 1 (32-bit floats) is read"),
        ));
    }
    let mut size = [0u32; 3];
    for (a, s) in size.iter_mut().enumerate() {
        let v = i32_at(8 + 4 * a);
        if v <= 0 {
            return Err(at(8 + 4 * a, format!("resolution {v} must be positive")));
        }
        *s = v as u32;
    }
    let channels = i32_at(20);
    if channels != 1 && channels != 3 {
        return Err(at(
            20,
            format!("{channels} channels; a grid has 1 (density) or 3 (colour)"),
        ));
    }
    let bounds_min = [f32_at(24), f32_at(28), f32_at(32)];
    let bounds_max = [f32_at(36), f32_at(40), f32_at(44)];
    let count = size.iter().map(|&s| s as u64).product::<u64>() * channels as u64;
    let want = HEADER as u64 + 4 * count;
    if bytes.len() as u64 != want {
        return Err(at(
            HEADER,
            format!(
                "the header's {}x{}x{} grid of {channels} channel(s) needs {want} bytes, the file has {}",
                size[0],
                size[1],
                size[2],
                bytes.len()
            ),
        ));
    }
    let values = bytes[HEADER..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    Ok(VolGrid {
        size,
        channels: channels as u32,
        bounds_min,
        bounds_max,
        values,
    })
}

/// The bytes of a `.vol` file holding `grid` (for tests and for scripts'
/// scenes).
pub fn vol_bytes(grid: &VolGrid) -> Vec<u8> {
    let mut b = Vec::with_capacity(HEADER + 4 * grid.values.len());
    b.extend_from_slice(b"VOL");
    b.push(3);
    b.extend_from_slice(&1i32.to_le_bytes());
    for s in grid.size {
        b.extend_from_slice(&(s as i32).to_le_bytes());
    }
    b.extend_from_slice(&(grid.channels as i32).to_le_bytes());
    for v in grid.bounds_min.iter().chain(&grid.bounds_max) {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in &grid.values {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> VolGrid {
        VolGrid {
            size: [2, 3, 4],
            channels: 1,
            bounds_min: [-1.0, -2.0, -3.0],
            bounds_max: [1.0, 2.0, 3.0],
            values: (0..24).map(|i| i as f32 * 0.5).collect(),
        }
    }

    #[test]
    fn grids_round_trip() {
        let g = grid();
        assert_eq!(parse_vol(&vol_bytes(&g), "g.vol").unwrap(), g);
    }

    #[test]
    fn bad_files_name_the_byte() {
        let good = vol_bytes(&grid());
        let err = |b: &[u8]| parse_vol(b, "g.vol").unwrap_err().to_string();
        assert!(err(&good[..20]).starts_with("g.vol: byte 20: the file ends after 20 bytes"));
        let mut b = good.clone();
        b[0] = b'X';
        assert!(err(&b).contains("byte 0: not a .vol grid"));
        let mut b = good.clone();
        b[4] = 2;
        assert!(err(&b).contains("byte 4: encoding 2"));
        let mut b = good.clone();
        b[20] = 2;
        assert!(err(&b).contains("byte 20: 2 channels"));
        // A header that promises more than the file holds is refused
        // before allocating (a resolution of 2^30 per side).
        let mut b = good.clone();
        b[8..12].copy_from_slice(&(1i32 << 30).to_le_bytes());
        assert!(err(&b).contains("needs"), "{}", err(&b));
        assert!(err(&good[..good.len() - 4]).contains("needs 144 bytes, the file has 140"));
        let mut b = good;
        b[12..16].copy_from_slice(&(-3i32).to_le_bytes());
        assert!(err(&b).contains("byte 12: resolution -3"));
    }
}
