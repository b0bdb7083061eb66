//! KTX2 textures: the first mip level, layer and face of
//!
//! - a plain (uncompressed) format: 8-bit UNORM and SRGB with one to four
//!   channels (R, RG, RGB, BGR, RGBA, BGRA, ABGR packed), 16-bit UNORM,
//!   16-bit and 32-bit floats, and the packed floats B10G11R11 and
//!   E5B9G9R9; its level stored as is, or with Zstandard or zlib
//!   supercompression;
//! - Basis Universal (ETC1S, UASTC, and the ASTC and HDR payloads the
//!   `basisu` crate transcodes), as glTF's `KHR_texture_basisu` stores
//!   textures.
//!
//! 8-bit formats give their codes ([`Pixels::Rgba8`]) and 16-bit UNORM
//! its values in `[0, 1]` ([`Pixels::EncodedRgbF32`]), both as stored:
//! the UNORM or SRGB of the format is not applied, for a texture's role
//! decides how its codes are read, as for a PNG (glTF requires the two to
//! agree). Float formats are linear ([`Pixels::LinearRgbF32`]). Channels a
//! format lacks read as Vulkan samples them (green and blue 0, alpha
//! opaque), unless the file's `KTXswizzle` says otherwise (`rrr1` for a
//! grey image stored as one channel).
//!
//! A format or scheme outside these is said to be not supported (naming
//! it); a file whose numbers disagree with each other is corrupt. Every
//! size is checked before anything is allocated: a level is unpacked only
//! as far as its first image, whose size is within Sahara's limits.

use std::io::Read;

use super::{alpha_fractions, check_size, ImageFormat, Pixels, RawImage, MAX_IMAGE_PIXELS};
use crate::error::FormatError;

/// What the header says, as far as reading the first image needs.
struct Header {
    vk_format: u32,
    width: u32,
    height: u32,
    depth: u32,
    layers: u32,
    faces: u32,
    scheme: u32,
    kvd: (u32, u32),
    /// Level 0: byte offset, byte length, unpacked byte length.
    level0: (u64, u64, u64),
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
}

fn u64_at(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
}

impl Header {
    /// The header and level 0's entry of the level index; `None` if the
    /// file is too short for them.
    fn read(bytes: &[u8]) -> Option<Header> {
        let at = |k: usize| u32_at(bytes, 12 + 4 * k);
        Some(Header {
            vk_format: at(0)?,
            width: at(2)?,
            height: at(3)?,
            depth: at(4)?,
            layers: at(5)?,
            faces: at(6)?,
            scheme: at(8)?,
            kvd: (at(11)?, at(12)?),
            level0: (u64_at(bytes, 80)?, u64_at(bytes, 88)?, u64_at(bytes, 96)?),
        })
    }
}

/// How a plain format stores a channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Component {
    /// An 8-bit code.
    U8,
    /// A 16-bit unsigned normalized value.
    Unorm16,
    /// A half float.
    F16,
    /// A float.
    F32,
    /// Three floats packed in 32 bits: 10-bit blue, 11-bit green and red.
    B10G11R11,
    /// Three 9-bit mantissas and a shared 5-bit exponent in 32 bits.
    E5B9G9R9,
}

/// A plain format: its Vulkan name, how many channels, how each is stored,
/// and whether they come blue first (B, G, R, A) or alpha last in a packed
/// 32-bit word (A8B8G8R8, which is R, G, B, A in bytes).
#[derive(Clone, Copy, Debug)]
struct Plain {
    name: &'static str,
    channels: usize,
    component: Component,
    bgr: bool,
}

impl Plain {
    /// Bytes a texel takes.
    fn texel_bytes(&self) -> usize {
        match self.component {
            Component::U8 => self.channels,
            Component::Unorm16 | Component::F16 => 2 * self.channels,
            Component::F32 => 4 * self.channels,
            Component::B10G11R11 | Component::E5B9G9R9 => 4,
        }
    }
}

/// The plain format of a `vkFormat`, if Sahara reads it.
fn plain_format(vk_format: u32) -> Option<Plain> {
    use Component::*;
    let f = |name, channels, component, bgr| Plain {
        name,
        channels,
        component,
        bgr,
    };
    Some(match vk_format {
        9 => f("R8_UNORM", 1, U8, false),
        15 => f("R8_SRGB", 1, U8, false),
        16 => f("R8G8_UNORM", 2, U8, false),
        22 => f("R8G8_SRGB", 2, U8, false),
        23 => f("R8G8B8_UNORM", 3, U8, false),
        29 => f("R8G8B8_SRGB", 3, U8, false),
        30 => f("B8G8R8_UNORM", 3, U8, true),
        36 => f("B8G8R8_SRGB", 3, U8, true),
        37 => f("R8G8B8A8_UNORM", 4, U8, false),
        43 => f("R8G8B8A8_SRGB", 4, U8, false),
        44 => f("B8G8R8A8_UNORM", 4, U8, true),
        50 => f("B8G8R8A8_SRGB", 4, U8, true),
        51 => f("A8B8G8R8_UNORM_PACK32", 4, U8, false),
        57 => f("A8B8G8R8_SRGB_PACK32", 4, U8, false),
        70 => f("R16_UNORM", 1, Unorm16, false),
        77 => f("R16G16_UNORM", 2, Unorm16, false),
        84 => f("R16G16B16_UNORM", 3, Unorm16, false),
        91 => f("R16G16B16A16_UNORM", 4, Unorm16, false),
        76 => f("R16_SFLOAT", 1, F16, false),
        83 => f("R16G16_SFLOAT", 2, F16, false),
        90 => f("R16G16B16_SFLOAT", 3, F16, false),
        97 => f("R16G16B16A16_SFLOAT", 4, F16, false),
        100 => f("R32_SFLOAT", 1, F32, false),
        103 => f("R32G32_SFLOAT", 2, F32, false),
        106 => f("R32G32B32_SFLOAT", 3, F32, false),
        109 => f("R32G32B32A32_SFLOAT", 4, F32, false),
        122 => f("B10G11R11_UFLOAT_PACK32", 3, B10G11R11, false),
        123 => f("E5B9G9R9_UFLOAT_PACK32", 3, E5B9G9R9, false),
        _ => return None,
    })
}

/// What kind of format a `vkFormat` Sahara does not read is, for the
/// message that says so.
fn unsupported_kind(vk_format: u32) -> &'static str {
    match vk_format {
        1..=8 => "a packed format of fewer than 8 bits a channel",
        10..=14 | 17..=21 | 24..=28 | 31..=35 | 38..=42 | 45..=49 | 52..=56 => {
            "an 8-bit signed, scaled or integer format"
        }
        58..=69 => "a 10-bit packed format",
        71..=75 | 78..=82 | 85..=89 | 92..=96 => "a 16-bit signed, scaled or integer format",
        98 | 99 | 101 | 102 | 104 | 105 | 107 | 108 => "a 32-bit integer format",
        110..=121 => "a 64-bit format",
        124..=130 => "a depth or stencil format",
        131..=146 => "a BC1 to BC7 block-compressed format",
        147..=156 => "an ETC2 or EAC block-compressed format",
        1_000_054_000..=1_000_054_007 => "a PVRTC block-compressed format",
        _ => "a format Sahara does not know",
    }
}

/// Where a channel of the image comes from (`KTXswizzle`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    Channel(usize),
    Zero,
    One,
}

/// The file's `KTXswizzle` (four of `r`, `g`, `b`, `a`, `0`, `1`), if it
/// has a well-formed one; Vulkan's identity otherwise.
fn swizzle(bytes: &[u8], (at, len): (u32, u32)) -> [Source; 4] {
    let identity = [0, 1, 2, 3].map(Source::Channel);
    let Some(kvd) = bytes.get(at as usize..(at as usize).saturating_add(len as usize)) else {
        return identity;
    };
    // Entries: a u32 length, `key\0value` of that length, padding to 4.
    let mut p = 0usize;
    while let Some(n) = u32_at(kvd, p) {
        let Some(entry) = kvd.get(p + 4..(p + 4).saturating_add(n as usize)) else {
            break;
        };
        if let Some(value) = entry.strip_prefix(b"KTXswizzle\0") {
            let value = value.strip_suffix(b"\0").unwrap_or(value);
            let mut out = identity;
            if value.len() != 4 {
                return identity;
            }
            for (o, c) in out.iter_mut().zip(value) {
                *o = match c {
                    b'r' => Source::Channel(0),
                    b'g' => Source::Channel(1),
                    b'b' => Source::Channel(2),
                    b'a' => Source::Channel(3),
                    b'0' => Source::Zero,
                    b'1' => Source::One,
                    _ => return identity,
                };
            }
            return out;
        }
        p = (p + 4 + n as usize).next_multiple_of(4);
    }
    identity
}

/// Decodes a KTX2 file's first image (see the module's documentation).
pub(super) fn decode(bytes: &[u8], name: &str) -> Result<RawImage, FormatError> {
    let fail =
        |why: String| FormatError::in_file(name, format!("cannot read the KTX2 texture: {why}"));
    let Some(h) = Header::read(bytes) else {
        return Err(fail("the file is truncated".into()));
    };
    const BASISLZ: u32 = 1;
    // vkFormat 0 (UNDEFINED) is a Basis Universal payload, as are the ASTC
    // formats the transcoder takes (LDR blocks, and HDR 4x4 and 6x6).
    let astc =
        (157..=184).contains(&h.vk_format) || [1_000_066_000, 1_000_066_004].contains(&h.vk_format);
    if h.vk_format == 0 || astc || h.scheme == BASISLZ {
        return basis::decode(bytes, name, h.vk_format);
    }
    let Some(format) = plain_format(h.vk_format) else {
        return Err(fail(format!(
            "its format, vkFormat {} ({}), is not supported (Sahara reads 8-bit, 16-bit and \
             float UNORM and SRGB formats, and Basis Universal; convert the texture to one of \
             those, or to PNG)",
            h.vk_format,
            unsupported_kind(h.vk_format)
        )));
    };
    if h.depth > 1 {
        return Err(fail(format!(
            "it is a 3D texture ({}x{}x{}), which is not supported",
            h.width, h.height, h.depth
        )));
    }
    // pixelHeight 0 is a 1D texture: one row.
    let (width, height) = (h.width, h.height.max(1));
    check_size(name, width, height)?;
    let texels = width as usize * height as usize;
    let image_bytes = texels * format.texel_bytes();
    // Level 0 holds every layer and face; the first image comes first.
    let stack = u64::from(h.layers.max(1)) * u64::from(h.faces.max(1));
    let level_bytes = (image_bytes as u64).saturating_mul(stack);
    let (offset, length, unpacked) = h.level0;
    let stored = offset
        .checked_add(length)
        .filter(|&end| end <= bytes.len() as u64)
        .map(|end| &bytes[offset as usize..end as usize])
        .ok_or_else(|| {
            fail(format!(
                "it is corrupt or truncated: its level 0 ({length} bytes at byte {offset}) \
                 lies past the end of the file ({} bytes)",
                bytes.len()
            ))
        })?;
    let size_error = |what: &str, n: u64| {
        fail(format!(
            "it is corrupt: its level 0 {what} {n} bytes, where {images} {level_bytes}",
            images = if stack == 1 {
                format!("one {width}x{height} {} image takes", format.name)
            } else {
                format!("{stack} {width}x{height} {} images take", format.name)
            }
        ))
    };
    const NONE: u32 = 0;
    const ZSTANDARD: u32 = 2;
    const ZLIB: u32 = 3;
    let data: Vec<u8> = match h.scheme {
        NONE => {
            if length < level_bytes {
                return Err(size_error("holds", length));
            }
            stored[..image_bytes].to_vec()
        }
        ZSTANDARD | ZLIB => {
            if unpacked != level_bytes {
                return Err(size_error("says it unpacks to", unpacked));
            }
            let scheme = if h.scheme == ZLIB {
                "zlib"
            } else {
                "Zstandard"
            };
            let unpack_error = |e: std::io::Error| {
                fail(format!(
                    "it is corrupt: its level 0 does not unpack ({scheme}: {e})"
                ))
            };
            // Only the first image is unpacked: no more than that is
            // allocated, whatever the level says.
            let mut out = vec![0u8; image_bytes];
            if h.scheme == ZLIB {
                flate2::read::ZlibDecoder::new(stored)
                    .read_exact(&mut out)
                    .map_err(unpack_error)?;
            } else {
                ruzstd::StreamingDecoder::new(stored)
                    .map_err(|e| {
                        fail(format!(
                            "it is corrupt: its level 0 is not Zstandard data ({e})"
                        ))
                    })?
                    .read_exact(&mut out)
                    .map_err(unpack_error)?;
            }
            out
        }
        s => {
            return Err(fail(format!(
                "its supercompression scheme {s} is not supported (Sahara reads KTX2 textures \
                 stored as they are, or with Zstandard or zlib supercompression)"
            )))
        }
    };
    let order = swizzle(bytes, h.kvd);
    Ok(to_raw(&data, width, height, &format, order))
}

/// The texels of one image of a plain format as Sahara's raw image.
fn to_raw(data: &[u8], width: u32, height: u32, format: &Plain, order: [Source; 4]) -> RawImage {
    let n = format.channels;
    let step = format.texel_bytes();
    let texels = data.chunks_exact(step);
    // Whether the image's alpha comes from a channel the format has.
    let has_alpha = match order[3] {
        Source::Channel(c) => c < n,
        _ => false,
    };
    let pick = |stored: &[f32; 4], zero: f32, one: f32| {
        order.map(|s| match s {
            Source::Channel(c) if c < n => stored[c],
            Source::Channel(3) | Source::One => one,
            Source::Channel(_) | Source::Zero => zero,
        })
    };
    let (pixels, alpha) = match format.component {
        Component::U8 => {
            let mut rgba = Vec::with_capacity(4 * data.len() / step);
            for t in texels {
                let mut stored = [0.0f32; 4];
                for (v, c) in stored.iter_mut().zip(t) {
                    *v = f32::from(*c);
                }
                if format.bgr {
                    stored.swap(0, 2);
                }
                rgba.extend(pick(&stored, 0.0, 255.0).map(|v| v as u8));
            }
            let alpha = has_alpha.then(|| alpha_fractions(&rgba));
            (Pixels::Rgba8(rgba), alpha)
        }
        component => {
            let mut rgb = Vec::with_capacity(3 * data.len() / step);
            let mut alpha = Vec::new();
            for t in texels {
                let stored = float_texel(t, component, n);
                let [r, g, b, a] = pick(&stored, 0.0, 1.0);
                rgb.extend([r, g, b]);
                if has_alpha {
                    alpha.push(a.clamp(0.0, 1.0));
                }
            }
            let pixels = if component == Component::Unorm16 {
                Pixels::EncodedRgbF32(rgb)
            } else {
                Pixels::LinearRgbF32(rgb)
            };
            (pixels, has_alpha.then_some(alpha))
        }
    };
    RawImage {
        width,
        height,
        format: ImageFormat::Ktx2,
        pixels,
        alpha,
    }
}

/// A texel of a 16-bit or float format as up to four values (the rest 0).
fn float_texel(t: &[u8], component: Component, channels: usize) -> [f32; 4] {
    let mut out = [0.0f32; 4];
    let word = |k: usize| u32::from_le_bytes([t[4 * k], t[4 * k + 1], t[4 * k + 2], t[4 * k + 3]]);
    let half = |k: usize| u16::from_le_bytes([t[2 * k], t[2 * k + 1]]);
    match component {
        Component::U8 => unreachable!("8-bit texels stay codes"),
        Component::Unorm16 => {
            for (c, v) in out.iter_mut().enumerate().take(channels) {
                *v = f32::from(half(c)) / 65535.0;
            }
        }
        Component::F16 => {
            for (c, v) in out.iter_mut().enumerate().take(channels) {
                *v = half::f16::from_bits(half(c)).to_f32();
            }
        }
        Component::F32 => {
            for (c, v) in out.iter_mut().enumerate().take(channels) {
                *v = f32::from_bits(word(c));
            }
        }
        Component::B10G11R11 => {
            let w = word(0);
            out[0] = small_float(w & 0x7FF, 6);
            out[1] = small_float((w >> 11) & 0x7FF, 6);
            out[2] = small_float(w >> 22, 5);
        }
        Component::E5B9G9R9 => {
            let w = word(0);
            let scale = 2f32.powi((w >> 27) as i32 - 15 - 9);
            out[0] = (w & 0x1FF) as f32 * scale;
            out[1] = ((w >> 9) & 0x1FF) as f32 * scale;
            out[2] = ((w >> 18) & 0x1FF) as f32 * scale;
        }
    }
    out
}

/// An unsigned float of a 5-bit exponent (bias 15) and a `mantissa_bits`
/// mantissa, as the packed formats store them.
fn small_float(bits: u32, mantissa_bits: u32) -> f32 {
    let exponent = bits >> mantissa_bits;
    let mantissa = (bits & ((1 << mantissa_bits) - 1)) as f32 / (1 << mantissa_bits) as f32;
    match exponent {
        0 => mantissa * 2f32.powi(-14),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mantissa) * 2f32.powi(e as i32 - 15),
    }
}

/// Basis Universal payloads, through the `basisu` crate's transcoder.
mod basis {
    use super::*;

    /// A KTX2 texture whose payload is Basis Universal (ETC1S or UASTC,
    /// with or without Zstandard supercompression, or an ASTC or HDR
    /// payload the transcoder takes), transcoded to 8-bit RGBA (LDR) or
    /// half floats (HDR): its first mip level, first layer and face.
    /// Colour codes stay as stored (sRGB for colour textures), as for an
    /// 8-bit PNG; HDR texels are linear.
    pub(super) fn decode(
        bytes: &[u8],
        name: &str,
        vk_format: u32,
    ) -> Result<RawImage, FormatError> {
        use basisu::{DecodeFlags, Error, SourceFormat, TargetFormat, Transcoder};
        let why = |e: Error| match e {
            Error::InvalidData => {
                "it is not a Basis Universal texture it can read, or it is corrupt".to_owned()
            }
            Error::Truncated => "the file is truncated".to_owned(),
            Error::Unsupported { source, .. } => {
                format!("its {source:?} payload is not supported")
            }
            Error::UnsupportedFeature(what) => format!("not supported: {what}"),
            Error::VideoRequiresState => {
                "it is a video, not a texture, which is not supported".to_owned()
            }
            Error::InvalidImageOrLevel => "it holds no image".to_owned(),
            Error::ZstdRequired => "its Zstandard supercompression cannot be read".to_owned(),
            e => format!("{e:?}"),
        };
        let fail = |e: Error| {
            FormatError::in_file(name, format!("cannot read the KTX2 texture: {}", why(e)))
        };
        if let Some(model) = unsupported_model(bytes, vk_format) {
            return Err(FormatError::in_file(
                name,
                format!(
                    "cannot read the KTX2 texture: its format, vkFormat {vk_format} with data \
                     format model {model}, is not supported (Sahara reads 8-bit, 16-bit and \
                     float UNORM and SRGB formats, and Basis Universal)"
                ),
            ));
        }
        sound(bytes).map_err(|what| {
            FormatError::in_file(
                name,
                format!("cannot read the KTX2 texture: its {what} is corrupt"),
            )
        })?;
        let texture = Transcoder::new(bytes).map_err(fail)?;
        let (width, height) = texture.base_dimensions();
        check_size(name, width, height)?;
        let texels = width as usize * height as usize;
        let hdr = matches!(
            texture.source_format(),
            SourceFormat::UastcHdr4x4 | SourceFormat::AstcHdr6x6 | SourceFormat::UastcHdr6x6
        );
        let target = if hdr {
            TargetFormat::RgbaHalf
        } else {
            TargetFormat::Rgba32
        };
        let out = texture
            .transcode_image(0, 0, 0, target, DecodeFlags::NONE)
            .map_err(fail)?;
        let bytes_per_texel = if hdr { 8 } else { 4 };
        if out.len() != bytes_per_texel * texels {
            return Err(FormatError::in_file(
                name,
                "cannot read the KTX2 texture: its first level is not one 2D image",
            ));
        }
        let (pixels, alpha) = if hdr {
            let rgb = out
                .chunks_exact(8)
                .flat_map(|t| {
                    (0..3).map(move |c| half::f16::from_le_bytes([t[2 * c], t[2 * c + 1]]).to_f32())
                })
                .collect();
            (Pixels::LinearRgbF32(rgb), None)
        } else {
            let alpha = texture.has_alpha().then(|| alpha_fractions(&out));
            (Pixels::Rgba8(out), alpha)
        };
        Ok(RawImage {
            width,
            height,
            format: ImageFormat::Ktx2,
            pixels,
            alpha,
        })
    }

    /// For vkFormat 0, the data format descriptor's colour model if it is
    /// none of Basis Universal's (ETC1S 163, UASTC 166, UASTC HDR 6x6 168,
    /// XUASTC 169): a format the transcoder cannot take, which is no sign
    /// of corruption.
    fn unsupported_model(bytes: &[u8], vk_format: u32) -> Option<u32> {
        if vk_format != 0 {
            return None;
        }
        let dfd = u32_at(bytes, 48)? as usize;
        let model = u32_at(bytes, dfd.checked_add(12)?)? & 0xFF;
        (![163, 166, 168, 169].contains(&model)).then_some(model)
    }

    /// Checks what `basisu` 0.1 trusts in a KTX2 header: Zstandard-compressed
    /// levels whose stated uncompressed size is beyond what their blocks can
    /// take would have it allocate that much (up to exabytes, an abort), and a
    /// key/value entry that ends past the key/value data would have it read
    /// out of bounds (a panic). `Err` names the part that is wrong.
    fn sound(bytes: &[u8]) -> Result<(), &'static str> {
        let u32_at = |at: usize| u32_at(bytes, at).map(u64::from);
        let u64_at = |at: usize| u64_at(bytes, at);
        let header = (|| {
            Some((
                [u32_at(20)?, u32_at(24)?, u32_at(32)?, u32_at(36)?],
                u32_at(40)?,
                u32_at(44)?,
                (u32_at(56)?, u32_at(60)?),
            ))
        })();
        // A file too short for its header is left to the transcoder, which
        // says it is truncated.
        let Some(([width, height, layers, faces], levels, scheme, (kvd_at, kvd_len))) = header
        else {
            return Ok(());
        };
        // A level's byte offset plus its length past 2^64 (the transcoder adds
        // them unchecked).
        for level in 0..levels.clamp(1, 32) {
            let at = 80 + 24 * level as usize;
            let (Some(offset), Some(length)) = (u64_at(at), u64_at(at + 8)) else {
                break;
            };
            if offset.checked_add(length).is_none() {
                return Err("level index");
            }
        }
        const ZSTANDARD: u64 = 2;
        if scheme == ZSTANDARD {
            // 16 bytes per 4 x 4 block (UASTC and ASTC blocks), for each layer
            // and face of the level; the whole stack within Sahara's pixel
            // limit. A side of 0 (a 1D texture's height) counts as 1, as the
            // blocks below do, so a 0 cannot hide a huge other factor.
            let stack = layers.max(1).saturating_mul(faces.max(1));
            let texels = width.max(1).saturating_mul(height.max(1));
            if texels.saturating_mul(stack) > MAX_IMAGE_PIXELS {
                return Err("size");
            }
            for level in 0..levels.clamp(1, 32) {
                let Some(stated) = u64_at(80 + 24 * level as usize + 16) else {
                    return Ok(());
                };
                let side = |s: u64| (s >> level).max(1).div_ceil(4);
                if stated > 16 * side(width) * side(height) * stack {
                    // (At most 2^4 x 2^26 x 2^4: the pixel limit bounds each.)
                    return Err("level index");
                }
            }
        }
        // Key/value entries: a length, that many bytes, padding to a multiple
        // of 4 (from the file's start); the transcoder walks them as long as
        // more than 4 bytes remain, stopping at a length that does not fit.
        let (start, end) = (kvd_at, kvd_at + kvd_len);
        if kvd_len == 0 || end > bytes.len() as u64 {
            return Ok(());
        }
        let mut p = start;
        while end - p > 4 {
            let length = u32_at(p as usize).ok_or("key/value data")?;
            p += 4;
            if length < 2 || end - p < length {
                return Ok(());
            }
            p += length;
            p += (4 - (p & 3)) & 3;
            if p > end {
                return Err("key/value data");
            }
        }
        Ok(())
    }
}
