//! Images in, as the renderer wants them: linear colour, or material
//! textures. The files are read by [`sahara_readers::image_in`], which gives
//! their stored values; here those become linear with the renderer's sRGB
//! transfer function (`sahara_render::srgb_to_linear`).
//!
//! - [`decode_texture`]: a material's texture. 8-bit PNG and JPEG stay
//!   8-bit, their colour channels read as sRGB or as plain values as the
//!   texture's role says ([`Encoding`]: colours are sRGB, data such as
//!   normals and roughness is not); 16-bit PNG and 8-bit TGA become float
//!   the same way; Radiance HDR, OpenEXR and PFM are linear floats. Alpha
//!   is kept.
//! - [`decode_image`]: linear float RGB and alpha (8-bit images taken as
//!   sRGB); [`decode_rgb_f32`] without the alpha (environment maps).

use std::path::Path;

use glam::Vec3;
use sahara_readers::image_in::{decode_raw, load_raw, ImageFormat, Pixels, RawImage};
use sahara_render::Encoding;
use sahara_render::Texture;

use sahara_readers::FormatError;
use sahara_render::{srgb8_to_linear, srgb_to_linear};

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
    load_raw(path).map(linear)
}

/// Decodes an image held in memory as linear float RGB; `name` is used in error messages.
pub fn decode_rgb_f32(bytes: &[u8], name: &str) -> Result<RgbF32Image, FormatError> {
    let i = decode_image(bytes, name)?;
    Ok((i.width, i.height, i.rgb))
}

/// Decodes an image held in memory with its alpha channel; `name` is used
/// in error messages (and recognises a TGA file by its extension).
pub fn decode_image(bytes: &[u8], name: &str) -> Result<Image, FormatError> {
    decode_raw(bytes, name).map(linear)
}

/// An image's stored values as linear colour: 8-bit codes and encoded
/// floats are sRGB; alpha is linear.
pub fn linear(raw: RawImage) -> Image {
    let RawImage {
        width,
        height,
        pixels,
        alpha,
        ..
    } = raw;
    let rgb = match pixels {
        Pixels::Rgba8(rgba) => rgba
            .chunks_exact(4)
            .flat_map(|p| p[..3].iter().map(|&c| srgb8_to_linear(c)))
            .collect(),
        Pixels::EncodedRgbF32(rgb) => rgb.into_iter().map(srgb_to_linear).collect(),
        Pixels::LinearRgbF32(rgb) => rgb,
    };
    Image {
        width,
        height,
        rgb,
        alpha,
    }
}

/// Decodes an image held in memory as a material texture whose colour
/// channels are encoded as `encoding` says (float images are linear
/// whatever the role); `name` is used in error messages.
pub fn decode_texture(
    bytes: &[u8],
    name: &str,
    encoding: Encoding,
) -> Result<Texture, FormatError> {
    decode_raw(bytes, name).map(|raw| texture(raw, encoding))
}

/// Reads an image file as a material texture (see [`decode_texture`]).
pub fn load_texture(path: &Path, encoding: Encoding) -> Result<Texture, FormatError> {
    load_raw(path).map(|raw| texture(raw, encoding))
}

/// An image's stored values as a texture whose colour channels are encoded
/// as `encoding` says.
pub fn texture(raw: RawImage, encoding: Encoding) -> Texture {
    let RawImage {
        width: w,
        height: h,
        format,
        pixels,
        alpha,
    } = raw;
    let has_alpha = alpha.is_some();
    let float = |rgb: Vec<Vec3>| {
        let t = Texture::new(w, h, rgb);
        match alpha {
            Some(a) => t.with_alpha(a),
            None => t,
        }
    };
    match pixels {
        // TGA textures are float textures (8-bit PNG and JPEG keep their codes).
        Pixels::Rgba8(rgba) if format == ImageFormat::Tga => {
            let value = |c: u8| match encoding {
                Encoding::Srgb => srgb8_to_linear(c),
                Encoding::Linear => f32::from(c) / 255.0,
            };
            float(
                rgba.chunks_exact(4)
                    .map(|t| Vec3::new(value(t[0]), value(t[1]), value(t[2])))
                    .collect(),
            )
        }
        Pixels::Rgba8(rgba) => {
            let texels = rgba
                .chunks_exact(4)
                .map(|t| [t[0], t[1], t[2], t[3]])
                .collect();
            Texture::from_rgba8(w, h, texels, encoding, has_alpha)
        }
        Pixels::EncodedRgbF32(rgb) => {
            let decode = |v: f32| match encoding {
                Encoding::Linear => v,
                Encoding::Srgb => srgb_to_linear(v),
            };
            float(
                rgb.chunks_exact(3)
                    .map(|t| Vec3::new(decode(t[0]), decode(t[1]), decode(t[2])))
                    .collect(),
            )
        }
        Pixels::LinearRgbF32(rgb) => float(rgb.chunks_exact(3).map(Vec3::from_slice).collect()),
    }
}
