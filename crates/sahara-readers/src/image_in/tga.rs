//! Truevision TGA images: true-colour (15, 16, 24 or 32 bits), grey (8 or
//! 16 bits with alpha) and colour-mapped, raw or run-length encoded, rows
//! from the bottom or the top. Read here rather than with the `image`
//! crate so that a damaged file is reported at its byte offset and the
//! header's size is checked before any pixel memory is allocated.
//!
//! The pixels come out as their 8-bit codes (RGBA).

use super::{alpha_fractions, check_size, ImageFormat, Pixels, RawImage};
use crate::error::FormatError;

/// Length of the fixed header.
const HEADER: usize = 18;

/// The TGA 2.0 footer's signature (the file's last 18 bytes).
const SIGNATURE: &[u8] = b"TRUEVISION-XFILE.\0";

/// True if `bytes` end with the TGA 2.0 footer, or `name` ends in `.tga`
/// (TGA files have no leading signature).
pub(super) fn is_tga(bytes: &[u8], name: &str) -> bool {
    bytes.ends_with(SIGNATURE) || name.to_ascii_lowercase().ends_with(".tga")
}

/// A reader of the bytes after the header, naming offsets on error.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    name: &'a str,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], FormatError> {
        match self.bytes.get(self.at..self.at + n) {
            Some(s) => {
                self.at += n;
                Ok(s)
            }
            None => Err(FormatError::at_byte(
                self.name,
                self.bytes.len() as u64,
                format!(
                    "TGA {what} ends early ({n} bytes expected at byte {})",
                    self.at
                ),
            )),
        }
    }
}

/// One pixel's RGBA (8-bit, sRGB colour) from `b`, `depth` bits.
fn rgba(b: &[u8], depth: u8, grey: bool) -> [u8; 4] {
    match (depth, grey) {
        (8, true) => [b[0], b[0], b[0], 255],
        (16, true) => [b[0], b[0], b[0], b[1]],
        (15 | 16, false) => {
            let v = u16::from_le_bytes([b[0], b[1]]);
            let c = |s: u16| {
                let x = ((v >> s) & 31) as u32;
                ((x * 255 + 15) / 31) as u8
            };
            let a = if depth == 16 && v & 0x8000 == 0 {
                0
            } else {
                255
            };
            [c(10), c(5), c(0), a]
        }
        (24, false) => [b[2], b[1], b[0], 255],
        (32, false) => [b[2], b[1], b[0], b[3]],
        _ => unreachable!("depths are checked"),
    }
}

/// Decodes a TGA file.
///
/// One piece, in file order (header, image id, colour map, pixels, raw or
/// run-length, then orientation): the header's dozen fields feed every
/// step after it, and each check names the byte offset it reads at.
pub(super) fn decode(bytes: &[u8], name: &str) -> Result<RawImage, FormatError> {
    let bad = |offset: usize, message: String| FormatError::at_byte(name, offset as u64, message);
    let Some(h) = bytes.get(..HEADER) else {
        return Err(bad(
            bytes.len(),
            format!("TGA header ends early ({} of {HEADER} bytes)", bytes.len()),
        ));
    };
    let u16_at = |i: usize| u16::from_le_bytes([h[i], h[i + 1]]);
    let (id_len, map_type, kind) = (h[0] as usize, h[1], h[2]);
    let (map_first, map_len, map_bits) = (u16_at(3) as usize, u16_at(5) as usize, h[7]);
    let (width, height, depth, descriptor) = (u16_at(12) as u32, u16_at(14) as u32, h[16], h[17]);
    let (mapped, grey, rle) = match kind {
        1 => (true, false, false),
        2 => (false, false, false),
        3 => (false, true, false),
        9 => (true, false, true),
        10 => (false, false, true),
        11 => (false, true, true),
        0 => return Err(bad(2, "the TGA file holds no image (type 0)".into())),
        t => return Err(bad(2, format!("unknown TGA image type {t}"))),
    };
    if map_type > 1 || (mapped && map_type != 1) {
        return Err(bad(
            1,
            format!("bad TGA colour map type {map_type} for image type {kind}"),
        ));
    }
    let depth_ok = match (mapped, grey) {
        (true, _) => matches!(depth, 8 | 16),
        (false, true) => matches!(depth, 8 | 16),
        (false, false) => matches!(depth, 15 | 16 | 24 | 32),
    };
    if !depth_ok {
        return Err(bad(
            16,
            format!("unsupported TGA pixel depth {depth} for image type {kind}"),
        ));
    }
    if map_type == 1 && !matches!(map_bits, 15 | 16 | 24 | 32) {
        return Err(bad(
            7,
            format!("unsupported TGA colour map entry size {map_bits}"),
        ));
    }
    check_size(name, width, height)?;
    let mut r = Reader {
        bytes,
        at: HEADER,
        name,
    };
    r.take(id_len, "image ID")?;
    let map: Vec<[u8; 4]> = if map_type == 1 {
        let size = (map_bits as usize).div_ceil(8);
        let raw = r.take(map_len * size, "colour map")?;
        raw.chunks_exact(size)
            .map(|b| rgba(b, map_bits, false))
            .collect()
    } else {
        Vec::new()
    };
    let size = (depth as usize).div_ceil(8);
    let pixels = width as usize * height as usize;
    let mut out: Vec<[u8; 4]> = Vec::with_capacity(pixels);
    let pixel = |b: &[u8], at: usize| -> Result<[u8; 4], FormatError> {
        if !mapped {
            return Ok(rgba(b, depth, grey));
        }
        let index = if size == 1 {
            b[0] as usize
        } else {
            u16::from_le_bytes([b[0], b[1]]) as usize
        };
        index
            .checked_sub(map_first)
            .and_then(|i| map.get(i))
            .copied()
            .ok_or_else(|| {
                bad(
                    at,
                    format!(
                        "TGA colour index {index} is outside the colour map ({map_first}..{})",
                        map_first + map.len()
                    ),
                )
            })
    };
    if rle {
        while out.len() < pixels {
            let at = r.at;
            let head = r.take(1, "run-length packet")?[0];
            let n = (head & 0x7f) as usize + 1;
            if out.len() + n > pixels {
                return Err(bad(
                    at,
                    format!("TGA run of {n} pixels goes past the image's {pixels}"),
                ));
            }
            if head & 0x80 != 0 {
                let at = r.at;
                let p = pixel(r.take(size, "run-length packet")?, at)?;
                out.extend(std::iter::repeat_n(p, n));
            } else {
                for _ in 0..n {
                    let at = r.at;
                    out.push(pixel(r.take(size, "run-length packet")?, at)?);
                }
            }
        }
    } else {
        let start = r.at;
        let data = r.take(pixels * size, "pixel data")?;
        for (i, b) in data.chunks_exact(size).enumerate() {
            out.push(pixel(b, start + i * size)?);
        }
    }
    // Rows from the bottom unless bit 5 says top; columns from the right if bit 4.
    let (w, hgt) = (width as usize, height as usize);
    let (top, right) = (descriptor & 0x20 != 0, descriptor & 0x10 != 0);
    let alpha_bits = descriptor & 0x0f;
    // A 32- or 16-bit pixel's extra bits are alpha only if the descriptor
    // says so (writers leave them undefined otherwise).
    let has_alpha = if mapped {
        alpha_bits > 0 && matches!(map_bits, 16 | 32)
    } else if grey {
        depth == 16
    } else {
        alpha_bits > 0 && matches!(depth, 16 | 32)
    };
    let mut rgba = Vec::with_capacity(pixels * 4);
    for y in 0..hgt {
        let sy = if top { y } else { hgt - 1 - y };
        for x in 0..w {
            let sx = if right { w - 1 - x } else { x };
            let [r, g, b, a] = out[sy * w + sx];
            rgba.extend([r, g, b, if has_alpha { a } else { 255 }]);
        }
    }
    Ok(RawImage {
        width,
        height,
        format: ImageFormat::Tga,
        alpha: has_alpha.then(|| alpha_fractions(&rgba)),
        pixels: Pixels::Rgba8(rgba),
    })
}

#[cfg(test)]
mod tests {
    use super::super::{decode_raw, Pixels, RawImage};

    fn header(kind: u8, w: u16, h: u16, depth: u8, descriptor: u8, map: (u16, u8)) -> Vec<u8> {
        let mut b = vec![0, u8::from(map.0 > 0), kind, 0, 0];
        b.extend(map.0.to_le_bytes());
        b.push(map.1);
        b.extend([0, 0, 0, 0]);
        b.extend(w.to_le_bytes());
        b.extend(h.to_le_bytes());
        b.extend([depth, descriptor]);
        b
    }

    /// The RGB codes and, if the image has alpha, the alpha codes.
    fn codes(i: &RawImage) -> (Vec<u8>, Option<Vec<u8>>) {
        let Pixels::Rgba8(rgba) = &i.pixels else {
            panic!("TGA pixels are 8-bit codes");
        };
        let rgb = rgba
            .chunks_exact(4)
            .flat_map(|p| &p[..3])
            .copied()
            .collect();
        let alpha: Vec<u8> = rgba.chunks_exact(4).map(|p| p[3]).collect();
        if let Some(a) = &i.alpha {
            assert_eq!(
                a,
                &alpha
                    .iter()
                    .map(|&c| f32::from(c) / 255.0)
                    .collect::<Vec<_>>()
            );
        }
        (rgb, i.alpha.is_some().then_some(alpha))
    }

    #[test]
    fn raw_bottom_up_rows_are_flipped_and_bgr_swapped() {
        let mut b = header(2, 1, 2, 24, 0, (0, 0));
        b.extend([1, 2, 3, 4, 5, 6]); // bottom pixel, then top (B, G, R)
        let i = decode_raw(&b, "x.tga").unwrap();
        assert_eq!((i.width, i.height), (1, 2));
        assert_eq!(codes(&i), (vec![6, 5, 4, 3, 2, 1], None));
    }

    #[test]
    fn run_length_colour_mapped_and_grey_images_decode() {
        // 32 bits, top-down, 8 alpha bits: a run of 2, then 1 raw pixel.
        let mut b = header(10, 3, 1, 32, 0x28, (0, 0));
        b.extend([0x81, 10, 20, 30, 255, 0x00, 1, 2, 3, 0]);
        let i = decode_raw(&b, "r.tga").unwrap();
        assert_eq!(
            codes(&i),
            (
                vec![30, 20, 10, 30, 20, 10, 3, 2, 1],
                Some(vec![255, 255, 0])
            )
        );
        // Colour map of two 24-bit entries, 8-bit indices.
        let mut b = header(1, 2, 1, 8, 0x20, (2, 24));
        b.extend([0, 0, 255, 255, 0, 0, 1, 0]);
        let i = decode_raw(&b, "m.tga").unwrap();
        assert_eq!(codes(&i), (vec![0, 0, 255, 255, 0, 0], None));
        // 16-bit grey: value and alpha.
        let mut b = header(3, 1, 1, 16, 0x20, (0, 0));
        b.extend([128, 51]);
        let i = decode_raw(&b, "g.tga").unwrap();
        assert_eq!(codes(&i), (vec![128, 128, 128], Some(vec![51])));
    }

    #[test]
    fn bad_files_are_errors_at_their_byte() {
        let err = |b: &[u8]| decode_raw(b, "x.tga").unwrap_err().to_string();
        assert_eq!(
            err(&[0; 5]),
            "x.tga: byte 5: TGA header ends early (5 of 18 bytes)"
        );
        let mut b = header(10, 4, 1, 24, 0x20, (0, 0));
        b.extend([0x83, 1, 2]);
        assert_eq!(
            err(&b),
            "x.tga: byte 21: TGA run-length packet ends early (3 bytes expected at byte 19)"
        );
        let mut b = header(10, 2, 1, 24, 0x20, (0, 0));
        b.extend([0x84, 1, 2, 3]);
        assert_eq!(
            err(&b),
            "x.tga: byte 18: TGA run of 5 pixels goes past the image's 2"
        );
        let mut b = header(1, 1, 1, 8, 0x20, (1, 24));
        b.extend([0, 0, 255, 7]);
        assert_eq!(
            err(&b),
            "x.tga: byte 21: TGA colour index 7 is outside the colour map (0..1)"
        );
        assert_eq!(
            err(&header(7, 1, 1, 8, 0, (0, 0))),
            "x.tga: byte 2: unknown TGA image type 7"
        );
        // The size is checked before the pixels are read.
        assert!(err(&header(2, 65535, 65535, 24, 0, (0, 0))).contains("larger than the limit"));
    }
}
