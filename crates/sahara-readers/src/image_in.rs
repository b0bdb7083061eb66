//! Image readers: PNG, JPEG, Radiance HDR, OpenEXR, TGA, PFM and KTX2
//! (plain formats and Basis Universal), as the values the file stores.
//!
//! [`decode_raw`] (and [`load_raw`]) give a [`RawImage`]: 8-bit PNG, JPEG
//! and TGA images and 8-bit KTX2 textures (Basis Universal ones transcoded
//! to 8 bits) as their 8-bit codes, 16-bit PNG and KTX2 as floats in
//! `[0, 1]` still encoded as the file encodes them, and Radiance HDR,
//! OpenEXR, PFM and float KTX2 as linear floats ([`Pixels`] says which). Nothing is converted to
//! linear colour here: what the codes mean (sRGB colours, or data such as
//! normals and roughness) depends on the image's use, which the caller
//! knows (`sahara-formats` decodes them for the renderer).
//!
//! The format is recognised by the file's first bytes (TGA, which has no
//! signature, by its footer or a `.tga` name). Grey images are expanded to
//! RGB. The size in the header is checked against [`MAX_IMAGE_SIDE`] and
//! [`MAX_IMAGE_PIXELS`] before any pixel memory is allocated.

mod ktx2;
mod pfm;
mod tga;

use std::fs;
use std::io::Cursor;
use std::path::Path;

use crate::error::FormatError;

/// Largest width or height accepted, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 1 << 16;

/// Largest number of pixels accepted (at 12 bytes a pixel: 768 MiB).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// The file format an image was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Portable Network Graphics.
    Png,
    /// JPEG.
    Jpeg,
    /// Radiance HDR (RGBE).
    Hdr,
    /// OpenEXR.
    Exr,
    /// Truevision TGA.
    Tga,
    /// Portable Float Map.
    Pfm,
    /// KTX2: a plain 8-bit, 16-bit or float format, or a Basis Universal
    /// payload (ETC1S or UASTC), as glTF's `KHR_texture_basisu` stores
    /// textures.
    Ktx2,
}

/// An image's pixels as stored, row-major from the top left.
#[derive(Clone, Debug, PartialEq)]
pub enum Pixels {
    /// 8-bit codes, four a pixel (R, G, B, A; A is 255 when the file has
    /// no alpha): 8-bit PNG, JPEG and TGA. Colour files store sRGB codes.
    Rgba8(Vec<u8>),
    /// Values in `[0, 1]`, three a pixel (R, G, B), encoded as the file
    /// encodes them (sRGB for colours): 16-bit PNG and JPEG.
    EncodedRgbF32(Vec<f32>),
    /// Linear floats, three a pixel (R, G, B), no alpha: Radiance HDR,
    /// OpenEXR and PFM.
    LinearRgbF32(Vec<f32>),
}

/// A decoded image: its size, format and stored pixel values.
#[derive(Clone, Debug, PartialEq)]
pub struct RawImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The file's format.
    pub format: ImageFormat,
    /// The pixel values.
    pub pixels: Pixels,
    /// The alpha channel as opacities in `[0, 1]` (`width * height`
    /// values), if the file has one. Alpha is linear whatever the colour
    /// encoding, so it is given as a fraction; 8-bit codes stay in
    /// [`Pixels::Rgba8`] too.
    pub alpha: Option<Vec<f32>>,
}

/// Reads an image file (PNG, JPEG, HDR, EXR, TGA or PFM) as stored; see [`decode_raw`].
pub fn load_raw(path: &Path) -> Result<RawImage, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    decode_raw(&bytes, &path.display().to_string())
}

/// Decodes an image held in memory as stored; `name` is used in error
/// messages (and recognises a TGA file by its extension).
pub fn decode_raw(bytes: &[u8], name: &str) -> Result<RawImage, FormatError> {
    let image = if pfm::is_pfm(bytes) {
        pfm::decode(bytes, name)
    } else if tga::is_tga(bytes, name) {
        tga::decode(bytes, name)
    } else {
        decode_any(bytes, name)
    };
    image.map_err(crate::error::one_line)
}

fn decode_any(bytes: &[u8], name: &str) -> Result<RawImage, FormatError> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let (width, height, rgb) = decode_exr(bytes, name)?;
        return Ok(RawImage {
            width,
            height,
            format: ImageFormat::Exr,
            pixels: Pixels::LinearRgbF32(rgb),
            alpha: None,
        });
    }
    if bytes.starts_with(&[0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB]) {
        return ktx2::decode(bytes, name);
    }
    if bytes.len() >= 12 && &bytes[..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        return Err(FormatError::in_file(
            name,
            "WebP textures are not supported; convert the texture to PNG or JPEG",
        ));
    }
    let reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| FormatError::in_file(name, format!("cannot read the image: {e}")))?;
    let format = reader.format().ok_or_else(|| {
        FormatError::in_file(
            name,
            "not a PNG, JPEG, Radiance HDR, OpenEXR, TGA or PFM image (unrecognised first bytes)",
        )
    })?;
    let ours = match format {
        image::ImageFormat::Hdr => ImageFormat::Hdr,
        image::ImageFormat::Png => ImageFormat::Png,
        image::ImageFormat::Jpeg => ImageFormat::Jpeg,
        _ => {
            return Err(FormatError::in_file(
                name,
                format!("{format:?} images are not supported; use PNG, JPEG, HDR, EXR, TGA or PFM"),
            ))
        }
    };
    let (width, height) = image::ImageReader::with_format(Cursor::new(bytes), format)
        .into_dimensions()
        .map_err(|e| FormatError::in_file(name, format!("bad {format:?} header: {e}")))?;
    check_size(name, width, height)?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_IMAGE_PIXELS * 16);
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
    reader.limits(limits);
    let decoded = reader
        .decode()
        .map_err(|e| FormatError::in_file(name, format!("cannot decode {format:?} image: {e}")))?;
    let (width, height) = (decoded.width(), decoded.height());
    let color = decoded.color();
    let (pixels, alpha) = if ours == ImageFormat::Hdr {
        (Pixels::LinearRgbF32(decoded.into_rgb32f().into_raw()), None)
    } else if is_8bit(color) {
        // The image crate turns a grey-and-alpha image's alpha into
        // fractions a little differently from `a / 255` (in the last bit
        // for some codes); taken as it gives them, so images do not change.
        let alpha = match color {
            image::ColorType::La8 => Some(alpha_of(decoded.to_rgba32f().into_raw())),
            _ => None,
        };
        let rgba = decoded.into_rgba8().into_raw();
        let alpha = color
            .has_alpha()
            .then(|| alpha.unwrap_or_else(|| alpha_fractions(&rgba)));
        (Pixels::Rgba8(rgba), alpha)
    } else {
        let rgba = decoded.into_rgba32f().into_raw();
        let rgb = rgba
            .chunks_exact(4)
            .flat_map(|p| &p[..3])
            .copied()
            .collect();
        let alpha = color.has_alpha().then(|| alpha_of(rgba));
        (Pixels::EncodedRgbF32(rgb), alpha)
    };
    Ok(RawImage {
        width,
        height,
        format: ours,
        pixels,
        alpha,
    })
}

/// The fourth value of each pixel of float RGBA.
fn alpha_of(rgba: Vec<f32>) -> Vec<f32> {
    rgba.chunks_exact(4).map(|p| p[3]).collect()
}

/// The alpha codes of 8-bit RGBA as fractions, `a / 255`.
pub(crate) fn alpha_fractions(rgba: &[u8]) -> Vec<f32> {
    rgba.chunks_exact(4)
        .map(|p| f32::from(p[3]) / 255.0)
        .collect()
}

/// True for the 8-bit colour types.
fn is_8bit(c: image::ColorType) -> bool {
    matches!(
        c,
        image::ColorType::L8
            | image::ColorType::La8
            | image::ColorType::Rgb8
            | image::ColorType::Rgba8
    )
}

/// Rejects empty images and images beyond the size limits.
pub(crate) fn check_size(name: &str, width: u32, height: u32) -> Result<(), FormatError> {
    if width == 0 || height == 0 {
        return Err(FormatError::in_file(
            name,
            format!("the image is {width}x{height}: it has no pixels"),
        ));
    }
    if width > MAX_IMAGE_SIDE
        || height > MAX_IMAGE_SIDE
        || width as u64 * height as u64 > MAX_IMAGE_PIXELS
    {
        return Err(FormatError::in_file(
            name,
            format!(
                "the image is {width}x{height}, larger than the limit ({MAX_IMAGE_SIDE} a side, {MAX_IMAGE_PIXELS} pixels)"
            ),
        ));
    }
    Ok(())
}

/// Decodes the first layer with R, G and B channels of an OpenEXR file:
/// width, height and `width * height * 3` linear values.
fn decode_exr(bytes: &[u8], name: &str) -> Result<(u32, u32, Vec<f32>), FormatError> {
    use exr::prelude::{read, ReadChannels, ReadLayers};

    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| FormatError::in_file(name, format!("bad EXR header: {e}")))?;
    let has_rgb = |h: &&exr::meta::header::Header| {
        ["R", "G", "B"]
            .iter()
            .all(|c| h.channels.list.iter().any(|d| d.name == **c))
    };
    let too_big = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    let mut rgb_layers = meta.headers.iter().filter(has_rgb).peekable();
    if rgb_layers.peek().is_none() {
        return Err(FormatError::in_file(
            name,
            "the EXR file has no layer with R, G and B channels",
        ));
    }
    // Checked for every candidate layer: the reader allocates before we learn which one it took.
    for header in rgb_layers {
        let size = header.layer_size;
        check_size(name, too_big(size.width()), too_big(size.height()))?;
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| (size.width(), vec![0f32; size.width() * size.height() * 3]),
            |(w, pixels): &mut (usize, Vec<f32>), p, (r, g, b): (f32, f32, f32)| {
                let i = 3 * (p.y() * *w + p.x());
                if let Some(out) = pixels.get_mut(i..i + 3) {
                    out.copy_from_slice(&[r, g, b]);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| FormatError::in_file(name, format!("cannot decode EXR image: {e}")))?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    Ok((w as u32, h as u32, layer.channel_data.pixels.1))
}
