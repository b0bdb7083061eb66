//! Image readers for textures and environment maps: linear float RGB out.
//!
//! PNG, JPEG and 8-bit TGA are taken as sRGB-encoded and converted to
//! linear; Radiance HDR, OpenEXR and PFM are linear already. The format is
//! recognised by the file's first bytes (TGA, which has no signature, by
//! its footer or a `.tga` name). Grey images are expanded to RGB; alpha is
//! kept by [`decode_image`] for PNG and TGA. The size in the header is
//! checked against [`MAX_IMAGE_SIDE`] and [`MAX_IMAGE_PIXELS`] before any
//! pixel memory is allocated.

mod pfm;
mod tga;

use std::fs;
use std::io::Cursor;
use std::path::Path;

use crate::error::FormatError;
use crate::srgb::{srgb8_to_linear, srgb_to_linear};

/// Largest width or height accepted, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 1 << 16;

/// Largest number of pixels accepted (at 12 bytes a pixel: 768 MiB).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// An image as linear float RGB: width, height, `width * height * 3` values row-major from the top left.
pub type RgbF32Image = (u32, u32, Vec<f32>);

/// A decoded image: linear float RGB and, if it has one, its alpha channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 3` values, row-major from the top left.
    pub rgb: Vec<f32>,
    /// `width * height` opacities in `[0, 1]`, if the file has alpha.
    pub alpha: Option<Vec<f32>>,
}

/// Loads a PNG, JPEG, HDR, EXR, TGA or PFM file as linear float RGB (`(width, height, rgb)`).
pub fn load_rgb_f32(path: &Path) -> Result<RgbF32Image, FormatError> {
    let i = load_image(path)?;
    Ok((i.width, i.height, i.rgb))
}

/// Loads an image file with its alpha channel (PNG and TGA have one).
pub fn load_image(path: &Path) -> Result<Image, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    decode_image(&bytes, &path.display().to_string())
}

/// Decodes an image held in memory as linear float RGB; `name` is used in error messages.
pub fn decode_rgb_f32(bytes: &[u8], name: &str) -> Result<RgbF32Image, FormatError> {
    let i = decode_image(bytes, name)?;
    Ok((i.width, i.height, i.rgb))
}

/// Decodes an image held in memory with its alpha channel; `name` is used
/// in error messages (and recognises a TGA file by its extension).
pub fn decode_image(bytes: &[u8], name: &str) -> Result<Image, FormatError> {
    let image = if pfm::is_pfm(bytes) {
        pfm::decode(bytes, name)
    } else if tga::is_tga(bytes, name) {
        tga::decode(bytes, name)
    } else {
        decode(bytes, name).map(|(width, height, rgb)| Image {
            width,
            height,
            rgb,
            alpha: None,
        })
    };
    let mut image = image.map_err(crate::scene_file::one_line)?;
    if image.alpha.is_none() && bytes.starts_with(b"\x89PNG") {
        image.alpha = decode_png_alpha(bytes);
    }
    Ok(image)
}

fn decode(bytes: &[u8], name: &str) -> Result<RgbF32Image, FormatError> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return decode_exr(bytes, name);
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
    let rgb = match format {
        image::ImageFormat::Hdr => decoded.into_rgb32f().into_raw(),
        image::ImageFormat::Png | image::ImageFormat::Jpeg => {
            if matches!(
                decoded.color(),
                image::ColorType::L8
                    | image::ColorType::La8
                    | image::ColorType::Rgb8
                    | image::ColorType::Rgba8
            ) {
                decoded
                    .into_rgb8()
                    .into_raw()
                    .into_iter()
                    .map(srgb8_to_linear)
                    .collect()
            } else {
                let mut rgb = decoded.into_rgb32f().into_raw();
                rgb.iter_mut().for_each(|v| *v = srgb_to_linear(*v));
                rgb
            }
        }
        other => {
            return Err(FormatError::in_file(
                name,
                format!("{other:?} images are not supported; use PNG, JPEG, HDR or EXR"),
            ))
        }
    };
    Ok((width, height, rgb))
}

/// The alpha channel of a PNG image held in memory (values in `[0, 1]`,
/// row-major from the top left), or `None` if it has none or is not a PNG.
/// Call it on bytes that [`decode_rgb_f32`] accepted (which checked the
/// size).
pub fn decode_png_alpha(bytes: &[u8]) -> Option<Vec<f32>> {
    let image = image::load_from_memory_with_format(bytes, image::ImageFormat::Png).ok()?;
    if !image.color().has_alpha() {
        return None;
    }
    Some(image.into_rgba32f().pixels().map(|p| p.0[3]).collect())
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

/// Decodes the first layer with R, G and B channels of an OpenEXR file.
fn decode_exr(bytes: &[u8], name: &str) -> Result<RgbF32Image, FormatError> {
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
