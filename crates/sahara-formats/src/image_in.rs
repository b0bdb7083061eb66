//! Image readers for textures and environment maps: PNG, JPEG, Radiance
//! HDR, OpenEXR, TGA and PFM.
//!
//! - [`decode_texture`]: a material's texture. 8-bit PNG and JPEG stay
//!   8-bit, their colour channels read as sRGB or as plain values as the
//!   texture's role says ([`Encoding`]: colours are sRGB, data such as
//!   normals and roughness is not); 16-bit PNG and 8-bit TGA become float
//!   the same way; Radiance HDR, OpenEXR and PFM are linear floats. Alpha
//!   is kept.
//! - [`decode_image`]: linear float RGB and alpha (8-bit images taken as
//!   sRGB); [`decode_rgb_f32`] without the alpha (environment maps).
//!
//! The format is recognised by the file's first bytes (TGA, which has no
//! signature, by its footer or a `.tga` name). Grey images are expanded to
//! RGB. The size in the header is checked against [`MAX_IMAGE_SIDE`] and
//! [`MAX_IMAGE_PIXELS`] before any pixel memory is allocated.

mod pfm;
mod tga;

use std::fs;
use std::io::Cursor;
use std::path::Path;

use glam::Vec3;
use sahara_render::Encoding;
use sahara_render::Texture;

use crate::error::FormatError;
use crate::srgb::{linear_to_srgb8, srgb8_to_linear, srgb_to_linear};

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

/// An image as the `image` crate decodes it, after the size checks.
enum Decoded {
    /// A PNG, JPEG or HDR image.
    Image(image::DynamicImage, image::ImageFormat),
    /// An OpenEXR image (linear RGB).
    Exr(RgbF32Image),
}

fn decode_any(bytes: &[u8], name: &str) -> Result<Decoded, FormatError> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return decode_exr(bytes, name).map(Decoded::Exr);
    }
    if bytes.starts_with(&[0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB]) {
        return Err(FormatError::in_file(
            name,
            "KTX2/Basis Universal textures are not supported; convert the texture to PNG or JPEG",
        ));
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
    if !matches!(
        format,
        image::ImageFormat::Hdr | image::ImageFormat::Png | image::ImageFormat::Jpeg
    ) {
        return Err(FormatError::in_file(
            name,
            format!("{format:?} images are not supported; use PNG, JPEG, HDR, EXR, TGA or PFM"),
        ));
    }
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
    Ok(Decoded::Image(decoded, format))
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

fn decode(bytes: &[u8], name: &str) -> Result<RgbF32Image, FormatError> {
    let (decoded, format) = match decode_any(bytes, name)? {
        Decoded::Exr(rgb) => return Ok(rgb),
        Decoded::Image(d, f) => (d, f),
    };
    let (width, height) = (decoded.width(), decoded.height());
    let rgb = match format {
        image::ImageFormat::Hdr => decoded.into_rgb32f().into_raw(),
        _ if is_8bit(decoded.color()) => decoded
            .into_rgb8()
            .into_raw()
            .into_iter()
            .map(srgb8_to_linear)
            .collect(),
        _ => {
            let mut rgb = decoded.into_rgb32f().into_raw();
            rgb.iter_mut().for_each(|v| *v = srgb_to_linear(*v));
            rgb
        }
    };
    Ok((width, height, rgb))
}

/// Decodes an image held in memory as a material texture whose colour
/// channels are encoded as `encoding` says (float images are linear
/// whatever the role); `name` is used in error messages.
pub fn decode_texture(
    bytes: &[u8],
    name: &str,
    encoding: Encoding,
) -> Result<Texture, FormatError> {
    if pfm::is_pfm(bytes) || tga::is_tga(bytes, name) {
        // Float textures: PFM is linear; an 8-bit TGA's codes, decoded as
        // sRGB by `decode_image`, are recovered exactly for data roles.
        let tga = !pfm::is_pfm(bytes);
        let i = decode_image(bytes, name)?;
        let value = |v: f32| match encoding {
            Encoding::Linear if tga => f32::from(linear_to_srgb8(v)) / 255.0,
            _ => v,
        };
        let rgb = i
            .rgb
            .chunks_exact(3)
            .map(|t| Vec3::new(value(t[0]), value(t[1]), value(t[2])))
            .collect();
        let t = Texture::new(i.width, i.height, rgb);
        return Ok(match i.alpha {
            Some(a) => t.with_alpha(a),
            None => t,
        });
    }
    let (decoded, format) = match decode_any(bytes, name).map_err(crate::scene_file::one_line)? {
        Decoded::Exr((w, h, rgb)) => {
            return Ok(Texture::new(
                w,
                h,
                rgb.chunks_exact(3).map(Vec3::from_slice).collect(),
            ))
        }
        Decoded::Image(d, f) => (d, f),
    };
    let (w, h) = (decoded.width(), decoded.height());
    let has_alpha = decoded.color().has_alpha();
    if format != image::ImageFormat::Hdr && is_8bit(decoded.color()) {
        let texels = decoded
            .into_rgba8()
            .into_raw()
            .chunks_exact(4)
            .map(|t| [t[0], t[1], t[2], t[3]])
            .collect();
        return Ok(Texture::from_rgba8(w, h, texels, encoding, has_alpha));
    }
    let rgba = decoded.into_rgba32f().into_raw();
    let decode = |v: f32| match (format, encoding) {
        (image::ImageFormat::Hdr, _) | (_, Encoding::Linear) => v,
        (_, Encoding::Srgb) => srgb_to_linear(v),
    };
    let rgb = rgba
        .chunks_exact(4)
        .map(|t| Vec3::new(decode(t[0]), decode(t[1]), decode(t[2])))
        .collect();
    let t = Texture::new(w, h, rgb);
    Ok(if has_alpha {
        t.with_alpha(rgba.chunks_exact(4).map(|t| t[3]).collect())
    } else {
        t
    })
}

/// Reads an image file as a material texture (see [`decode_texture`]).
pub fn load_texture(path: &Path, encoding: Encoding) -> Result<Texture, FormatError> {
    let bytes = fs::read(path).map_err(|e| FormatError::io(path, e))?;
    decode_texture(&bytes, &path.display().to_string(), encoding)
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
