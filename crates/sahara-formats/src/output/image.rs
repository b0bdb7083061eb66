//! Image writers: 8-bit sRGB PNG and linear 32-bit float OpenEXR, written atomically.
//!
//! Pixels are row-major from the top-left corner, three interleaved channels
//! (R, G, B) per pixel. Every writer goes through
//! [`crate::output::atomic::write_atomically`]: a failed write
//! leaves an existing file as it was. Metadata (`key`, `value`) pairs become
//! text attributes: PNG `tEXt` chunks (`iTXt` for non-ASCII values) and EXR
//! header string attributes.

use std::io::{BufWriter, Write};
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2 as ExrVec2, WritableImage,
};

use crate::output::atomic::write_atomically;
use sahara_readers::FormatError;
use sahara_render::{linear_to_srgb8, srgb8_to_linear};

/// The image file formats this module writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB PNG.
    Png,
    /// Linear 32-bit float OpenEXR (ZIP compressed, lossless).
    Exr,
}

impl ImageFormat {
    /// The format named by `path`'s extension (`.png` or `.exr`, any case).
    pub fn from_path(path: &Path) -> Result<ImageFormat, FormatError> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match extension.as_str() {
            "png" => Ok(ImageFormat::Png),
            "exr" => Ok(ImageFormat::Exr),
            _ => Err(FormatError::in_file(
                &path.display().to_string(),
                format!("unsupported image file extension {extension:?}; expected .png or .exr"),
            )),
        }
    }
}

/// Pixels handed to [`write_image`]: display-ready 8-bit sRGB or linear floats.
#[derive(Clone, Copy, Debug)]
pub enum Pixels<'a> {
    /// 8-bit sRGB-encoded R, G, B per pixel.
    Rgb8(&'a [u8]),
    /// Linear R, G, B per pixel.
    LinearRgbF32(&'a [f32]),
}

/// Writes `pixels` to `path` as PNG or EXR, chosen by the extension (any case).
///
/// A PNG from linear floats is clamped to `[0, 1]` and sRGB-encoded (tone
/// mapping is the caller's job); an EXR from 8-bit pixels is sRGB-decoded.
pub fn write_image(
    path: &Path,
    width: u32,
    height: u32,
    pixels: Pixels<'_>,
    metadata: &[(String, String)],
) -> Result<(), FormatError> {
    match (ImageFormat::from_path(path)?, pixels) {
        (ImageFormat::Png, Pixels::Rgb8(rgb8)) => png(path, width, height, rgb8, metadata),
        (ImageFormat::Png, Pixels::LinearRgbF32(rgb)) => {
            check_len(path, width, height, rgb.len())?;
            let rgb8: Vec<u8> = rgb.iter().map(|&v| linear_to_srgb8(v)).collect();
            png(path, width, height, &rgb8, metadata)
        }
        (ImageFormat::Exr, Pixels::LinearRgbF32(rgb)) => {
            write_exr(path, width, height, rgb, metadata)
        }
        (ImageFormat::Exr, Pixels::Rgb8(rgb8)) => {
            check_len(path, width, height, rgb8.len())?;
            let rgb: Vec<f32> = rgb8.iter().map(|&v| srgb8_to_linear(v)).collect();
            write_exr(path, width, height, &rgb, metadata)
        }
    }
}

/// Writes an 8-bit sRGB PNG (`width * height * 3` bytes, R G B per pixel) atomically.
pub fn write_png(path: &Path, width: u32, height: u32, rgb8: &[u8]) -> Result<(), FormatError> {
    png(path, width, height, rgb8, &[])
}

/// Named channels written beside the beauty in one EXR part, as
/// `LAYER.CHANNEL` (`albedo.R`, `normal.X`, `depth.Z`): the multi-layer
/// convention compositors read.
#[derive(Clone, Copy, Debug)]
pub struct ExrLayer<'a> {
    /// The layer's name (`albedo`).
    pub name: &'a str,
    /// Its channels' names (`["R", "G", "B"]`).
    pub channels: &'a [&'a str],
    /// `width * height * channels.len()` values, interleaved per pixel,
    /// row-major from the top left.
    pub values: &'a [f32],
}

/// Writes a linear float EXR of the beauty (`R`, `G`, `B`: `width * height
/// * 3` values) and further `layers`, with string attributes, atomically.
pub fn write_exr_layers(
    path: &Path,
    width: u32,
    height: u32,
    rgb_f32: &[f32],
    layers: &[ExrLayer<'_>],
    metadata: &[(String, String)],
) -> Result<(), FormatError> {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, SmallVec};
    let name = path.display().to_string();
    check_len(path, width, height, rgb_f32.len())?;
    let pixels = width as usize * height as usize;
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    let mut plane = |label: String, values: &[f32], stride: usize, c: usize| {
        let v: Vec<f32> = (0..pixels).map(|i| values[i * stride + c]).collect();
        channels.push(AnyChannel::new(label.as_str(), FlatSamples::F32(v)));
    };
    for (c, label) in ["R", "G", "B"].iter().enumerate() {
        plane(label.to_string(), rgb_f32, 3, c);
    }
    for layer in layers {
        let n = layer.channels.len();
        if n == 0 || layer.values.len() != pixels * n {
            return Err(FormatError::in_file(
                &name,
                format!(
                    "layer '{}' holds {} values, not {pixels} pixels x {n} channels",
                    layer.name,
                    layer.values.len()
                ),
            ));
        }
        for (c, ch) in layer.channels.iter().enumerate() {
            plane(format!("{}.{ch}", layer.name), layer.values, n, c);
        }
    }
    let mut layer_attributes = LayerAttributes::default();
    layer_attributes
        .other
        .extend(exr_attributes(&name, metadata)?);
    let layer = Layer::new(
        (width as usize, height as usize),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    encode_exr(path, |out| {
        Image::from_layer(layer).write().to_buffered(out)
    })
}

/// Writes a linear float EXR (`width * height * 3` values) with string attributes, atomically.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    rgb_f32: &[f32],
    metadata: &[(String, String)],
) -> Result<(), FormatError> {
    let name = path.display().to_string();
    check_len(path, width, height, rgb_f32.len())?;
    let attributes = exr_attributes(&name, metadata)?;
    let w = width as usize;
    let pixel = |p: ExrVec2<usize>| {
        let i = 3 * (p.y() * w + p.x());
        (rgb_f32[i], rgb_f32[i + 1], rgb_f32[i + 2])
    };
    let mut layer_attributes = LayerAttributes::default();
    layer_attributes.other.extend(attributes);
    let layer = Layer::new(
        (w, height as usize),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        SpecificChannels::rgb(pixel),
    );
    encode_exr(path, |out| {
        Image::from_layer(layer).write().to_buffered(out)
    })
}

/// The metadata as EXR text attributes.
fn exr_attributes(
    name: &str,
    metadata: &[(String, String)],
) -> Result<Vec<(Text, AttributeValue)>, FormatError> {
    let mut attributes = Vec::with_capacity(metadata.len());
    for (key, value) in metadata {
        if RESERVED_EXR_ATTRIBUTES.contains(&key.as_str()) {
            return Err(FormatError::in_file(
                name,
                format!("metadata key {key:?} is a standard EXR header attribute"),
            ));
        }
        let text = |s: &str| {
            Text::new_or_none(s).ok_or_else(|| {
                FormatError::in_file(
                    name,
                    format!(
                        "metadata {key:?} = {value:?} cannot be stored as EXR text (Latin-1 only)"
                    ),
                )
            })
        };
        if key.is_empty() {
            return Err(FormatError::in_file(name, "metadata key is empty"));
        }
        attributes.push((text(key)?, AttributeValue::Text(text(value)?)));
    }
    Ok(attributes)
}

/// Encodes an image with `encode`, puts its header in a stable order and
/// writes it atomically.
fn encode_exr(
    path: &Path,
    encode: impl FnOnce(&mut std::io::Cursor<Vec<u8>>) -> exr::error::UnitResult,
) -> Result<(), FormatError> {
    let name = path.display().to_string();
    let mut bytes = std::io::Cursor::new(Vec::new());
    encode(&mut bytes)
        .map_err(|e| FormatError::in_file(&name, format!("cannot encode EXR: {e}")))?;
    let mut bytes = bytes.into_inner();
    // The encoder writes the custom attributes in hash-map order, which
    // changes from run to run: put the header in name order so that the
    // same image gives the same bytes.
    sort_exr_header(&mut bytes)
        .map_err(|e| FormatError::in_file(&name, format!("cannot encode EXR: {e}")))?;
    write_atomically(path, |out: &mut BufWriter<std::fs::File>| {
        out.write_all(&bytes)
            .and_then(|()| out.flush())
            .map_err(|e| FormatError::write(path, e))
    })
}

/// Reorders the attributes of a single-part EXR file's header by name, in
/// place. The header keeps its length, so the offset table after it stays
/// valid.
pub(crate) fn sort_exr_header(bytes: &mut [u8]) -> Result<(), String> {
    const MULTIPART: u32 = 0x1000;
    let truncated = || "the encoded header is truncated".to_string();
    let version = bytes.get(4..8).ok_or_else(truncated)?;
    if u32::from_le_bytes(version.try_into().expect("4 bytes")) & MULTIPART != 0 {
        return Err("a multi-part file was encoded".into());
    }
    let start = 8;
    let mut attributes: Vec<(usize, usize)> = Vec::new();
    let mut at = start;
    // Each attribute: name NUL, type NUL, i32 size, value; a NUL ends the header.
    loop {
        let first = *bytes.get(at).ok_or_else(truncated)?;
        if first == 0 {
            break;
        }
        let begin = at;
        for _ in 0..2 {
            let nul = bytes[at..]
                .iter()
                .position(|&b| b == 0)
                .ok_or_else(truncated)?;
            at += nul + 1;
        }
        let size = bytes.get(at..at + 4).ok_or_else(truncated)?;
        let size = i32::from_le_bytes(size.try_into().expect("4 bytes"));
        let size = usize::try_from(size).map_err(|_| "negative attribute size".to_string())?;
        at += 4 + size;
        if at > bytes.len() {
            return Err(truncated());
        }
        attributes.push((begin, at));
    }
    let end = at;
    let name = |&(b, _): &(usize, usize)| {
        let n = bytes[b..].iter().position(|&c| c == 0).unwrap_or(0);
        bytes[b..b + n].to_vec()
    };
    let mut sorted = attributes.clone();
    sorted.sort_by_key(name);
    let header: Vec<u8> = sorted
        .iter()
        .flat_map(|&(b, e)| bytes[b..e].iter().copied())
        .collect();
    bytes[start..end].copy_from_slice(&header);
    Ok(())
}

/// EXR header attributes the format itself defines; metadata may not reuse them.
const RESERVED_EXR_ATTRIBUTES: &[&str] = &[
    "channels",
    "compression",
    "dataWindow",
    "displayWindow",
    "lineOrder",
    "pixelAspectRatio",
    "screenWindowCenter",
    "screenWindowWidth",
    "tiles",
    "name",
    "type",
    "version",
    "chunkCount",
];

/// Writes an 8-bit RGB PNG with text chunks.
fn png(
    path: &Path,
    width: u32,
    height: u32,
    rgb8: &[u8],
    metadata: &[(String, String)],
) -> Result<(), FormatError> {
    let name = path.display().to_string();
    check_len(path, width, height, rgb8.len())?;
    for (key, _) in metadata {
        let valid = (1..=79).contains(&key.len())
            && key.bytes().all(|b| (0x20..0x7f).contains(&b))
            && !key.starts_with(' ')
            && !key.ends_with(' ')
            && !key.contains("  ");
        if !valid {
            return Err(FormatError::in_file(
                &name,
                format!("metadata key {key:?} is not a valid PNG keyword (1-79 printable ASCII characters, single inner spaces)"),
            ));
        }
    }
    let encoding_error =
        |e: png::EncodingError| FormatError::in_file(&name, format!("cannot encode PNG: {e}"));
    write_atomically(path, |out| {
        let mut encoder = png::Encoder::new(&mut *out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        for (key, value) in metadata {
            if value.is_ascii() {
                encoder.add_text_chunk(key.clone(), value.clone())
            } else {
                encoder.add_itxt_chunk(key.clone(), value.clone())
            }
            .map_err(encoding_error)?;
        }
        let mut writer = encoder.write_header().map_err(encoding_error)?;
        writer.write_image_data(rgb8).map_err(encoding_error)?;
        writer.finish().map_err(encoding_error)?;
        out.flush().map_err(|e| FormatError::write(path, e))
    })
}

/// Checks that an image is non-empty and that a buffer holds exactly its `width * height * 3` values.
fn check_len(path: &Path, width: u32, height: u32, len: usize) -> Result<(), FormatError> {
    let name = path.display().to_string();
    if width == 0 || height == 0 {
        return Err(FormatError::in_file(
            &name,
            format!("cannot write a {width}x{height} image: it has no pixels"),
        ));
    }
    let expected = (width as u64) * (height as u64) * 3;
    if len as u64 != expected {
        return Err(FormatError::in_file(
            &name,
            format!(
                "a {width}x{height} RGB image needs {expected} values but the buffer has {len}"
            ),
        ));
    }
    Ok(())
}
