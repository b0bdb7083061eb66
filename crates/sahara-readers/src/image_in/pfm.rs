//! Portable Float Map (`.pfm`) images: a text header `PF` (RGB) or `Pf`
//! (grey), the width and height, and a scale whose sign gives the byte
//! order (negative: little-endian); then 32-bit floats, rows from the
//! bottom, each value times |scale| (as pbrt reads them). No crate reads
//! them; the format is a dozen lines.

use super::{check_size, ImageFormat, Pixels, RawImage};
use crate::error::FormatError;

/// The next whitespace-separated header token after `*at`, and its offset.
fn token<'a>(
    bytes: &'a [u8],
    at: &mut usize,
    name: &str,
    what: &str,
) -> Result<(&'a [u8], usize), FormatError> {
    while bytes.get(*at).is_some_and(u8::is_ascii_whitespace) {
        *at += 1;
    }
    let start = *at;
    while bytes.get(*at).is_some_and(|b| !b.is_ascii_whitespace()) {
        *at += 1;
    }
    if start == *at {
        return Err(FormatError::at_byte(
            name,
            start as u64,
            format!("PFM header: expected {what}, found the end of the file"),
        ));
    }
    Ok((&bytes[start..*at], start))
}

/// True if `bytes` start like a PFM file.
pub(super) fn is_pfm(bytes: &[u8]) -> bool {
    matches!(bytes, [b'P', b'F' | b'f', c, ..] if c.is_ascii_whitespace())
}

/// Decodes a PFM file (linear values, as stored; a grey map is expanded to RGB).
pub(super) fn decode(bytes: &[u8], name: &str) -> Result<RawImage, FormatError> {
    let mut at = 0;
    let (magic, _) = token(bytes, &mut at, name, "PF or Pf")?;
    let channels = match magic {
        b"PF" => 3usize,
        b"Pf" => 1,
        _ => {
            return Err(FormatError::at_byte(
                name,
                0,
                "not a PFM file (expected PF or Pf)",
            ))
        }
    };
    let mut number = |what: &str| -> Result<(f64, usize), FormatError> {
        let (t, off) = token(bytes, &mut at, name, what)?;
        let v = std::str::from_utf8(t)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                FormatError::at_byte(
                    name,
                    off as u64,
                    format!(
                        "PFM header: expected {what}, found '{}'",
                        String::from_utf8_lossy(t)
                    ),
                )
            })?;
        Ok((v, off))
    };
    let mut side = |what: &str| -> Result<u32, FormatError> {
        let (v, off) = number(what)?;
        if v.fract() != 0.0 || !(1.0..=f64::from(u32::MAX)).contains(&v) {
            return Err(FormatError::at_byte(
                name,
                off as u64,
                format!("PFM header: bad {what} {v}"),
            ));
        }
        Ok(v as u32)
    };
    let width = side("the width")?;
    let height = side("the height")?;
    let (scale, off) = number("the scale")?;
    if scale == 0.0 {
        return Err(FormatError::at_byte(
            name,
            off as u64,
            "PFM header: the scale is 0",
        ));
    }
    check_size(name, width, height)?;
    // One whitespace byte ends the header.
    let data = at + 1;
    let row = width as usize * channels * 4;
    let need = row * height as usize;
    let have = bytes.len().saturating_sub(data);
    if have < need {
        return Err(FormatError::at_byte(
            name,
            bytes.len() as u64,
            format!("PFM data ends early: {width}x{height}x{channels} floats need {need} bytes, found {have}"),
        ));
    }
    let little = scale < 0.0;
    // pbrt (and the format's authors) multiply the values by |scale|.
    let factor = scale.abs() as f32;
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
    // Rows are stored bottom to top; images here run from the top.
    for y in (0..height as usize).rev() {
        let start = data + y * row;
        for (i, px) in bytes[start..start + row]
            .chunks_exact(4 * channels)
            .enumerate()
        {
            let mut v = [0f32; 3];
            for (c, b) in px.chunks_exact(4).enumerate() {
                let b = [b[0], b[1], b[2], b[3]];
                v[c] = if little {
                    f32::from_le_bytes(b)
                } else {
                    f32::from_be_bytes(b)
                };
                if !v[c].is_finite() {
                    let off = start + (i * channels + c) * 4;
                    return Err(FormatError::at_byte(
                        name,
                        off as u64,
                        format!("PFM value {} is not finite", v[c]),
                    ));
                }
            }
            if channels == 1 {
                v = [v[0]; 3];
            }
            let v = v.map(|x| x * factor);
            rgb.extend_from_slice(&v);
        }
    }
    Ok(RawImage {
        width,
        height,
        format: ImageFormat::Pfm,
        pixels: Pixels::LinearRgbF32(rgb),
        alpha: None,
    })
}

#[cfg(test)]
mod tests {
    use super::super::{decode_raw, Pixels};

    fn pfm(header: &str, values: &[f32], little: bool) -> Vec<u8> {
        let mut b = header.as_bytes().to_vec();
        for v in values {
            b.extend(if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            });
        }
        b
    }

    #[test]
    fn rows_run_from_the_bottom_and_values_are_scaled() {
        // Two rows of one pixel: the file's first row is the image's bottom.
        let b = pfm("PF\n1 2\n-1\n", &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], true);
        let i = decode_raw(&b, "x.pfm").unwrap();
        assert_eq!((i.width, i.height, i.alpha), (1, 2, None));
        assert_eq!(
            i.pixels,
            Pixels::LinearRgbF32(vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0])
        );
        let b = pfm("Pf 2 1 2.0\n", &[0.25, 1.5], false);
        let i = decode_raw(&b, "g.pfm").unwrap();
        assert_eq!(
            i.pixels,
            Pixels::LinearRgbF32(vec![0.5, 0.5, 0.5, 3.0, 3.0, 3.0])
        );
    }

    #[test]
    fn bad_files_are_errors_at_their_byte() {
        let err = |b: &[u8]| decode_raw(b, "x.pfm").unwrap_err().to_string();
        assert_eq!(
            err(&pfm("PF\n2 2\n-1\n", &[0.0; 11], true)),
            "x.pfm: byte 54: PFM data ends early: 2x2x3 floats need 48 bytes, found 44"
        );
        assert_eq!(
            err(b"PF\n2 x\n-1\n"),
            "x.pfm: byte 5: PFM header: expected the height, found 'x'"
        );
        assert_eq!(
            err(&pfm("Pf\n1 1\n-1\n", &[f32::NAN], true)),
            "x.pfm: byte 10: PFM value NaN is not finite"
        );
        // A huge size is refused before anything is allocated.
        assert!(err(b"PF\n100000 100000\n-1\n").contains("larger than the limit"));
    }
}
