//! pbrt textures as what a Sahara material can hold: a colour times at most
//! one image.
//!
//! - `constant`, `scale` and `mix` of constants fold into the colour;
//!   `scale` of an image by a constant keeps the image and scales the colour.
//! - `imagemap` (PNG, JPEG, HDR, EXR, TGA, PFM) becomes the image, with
//!   `scale` and `invert` applied, read as Sahara reads every texture
//!   (trilinear MIP-mapping by the ray's footprint, whatever `filter`
//!   says), with its `wrap` mode and the `uv` mapping's `uscale`,
//!   `vscale`, `udelta`, `vdelta` as the map's transform.
//! - `checkerboard` (2D) and `bilerp` of constants are baked into images.
//! - Everything else (3D checkerboards, `dots`, `fbm`, `wrinkled`, `windy`,
//!   `marble`, `ptex`, `mix` of images, mapping other than `uv` with unit
//!   scale) is approximated by a constant or left as is, with a warning
//!   per kind.
//! - Float textures (roughness, amounts) become a constant: an image's mean.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine2, Mat2, Vec2, Vec3};
use sahara_render::Texture;
use sahara_render::Wrap;

use super::declarations::{Entity, TextureDecl};
use super::params::{FloatParam, SpectrumParam};
use crate::common::image::load_image;
use crate::common::spectrum::{self, Use};
use crate::common::tint::{alpha_of, texel_count, with_alpha_of, Sampling, Tint};
use crate::common::warnings::Warnings;
use sahara_readers::FormatError;
use sahara_render::linear_to_srgb8;

/// Deepest chain of textures referring to textures.
const MAX_TEXTURE_DEPTH: usize = 32;

/// Largest side of a baked checkerboard or bilerp image.
const MAX_BAKED_SIDE: u32 = 2048;

/// The textures of a file, converted on first use.
pub(crate) struct Textures<'a> {
    decls: &'a HashMap<(String, bool), TextureDecl>,
    cache: HashMap<(String, bool), Tint>,
    images: HashMap<std::path::PathBuf, Option<Arc<Texture>>>,
}

/// A spectrum parameter's colour (an illuminant, a reflectance, an index ...).
pub(crate) fn rgb_of(
    p: &SpectrumParam,
    usage: Use,
    folders: &[std::path::PathBuf],
    warnings: &mut Warnings,
) -> Result<Vec3, FormatError> {
    let v = match p {
        SpectrumParam::Rgb(c) => *c,
        SpectrumParam::Blackbody(t, scale) => {
            if t.is_nan() || *t <= 0.0 {
                return Ok(Vec3::ZERO);
            }
            spectrum::blackbody_rgb(*t).map(|c| c * scale)
        }
        SpectrumParam::Sampled(pairs) => {
            spectrum::spectrum_to_rgb(|l| spectrum::piecewise_linear(pairs, l), usage)
        }
        SpectrumParam::Named(name, loc) => match spectrum::named(name) {
            Some(spectrum::Named::Rgb(c)) => c,
            Some(spectrum::Named::White) => [1.0; 3],
            Some(spectrum::Named::Blackbody(t)) => spectrum::blackbody_rgb(t),
            None => match read_spectrum_file(&super::parser::resolve(folders, name)) {
                Some(pairs) => {
                    spectrum::spectrum_to_rgb(|l| spectrum::piecewise_linear(&pairs, l), usage)
                }
                None => {
                    warnings.add(
                        format!("spectrum \"{name}\" is neither a known named spectrum nor a readable file; grey 1 used"),
                        loc,
                    );
                    [1.0; 3]
                }
            },
        },
        SpectrumParam::Texture(_) => unreachable!("textures are looked up by the caller"),
    };
    Ok(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))
}

/// The samples of a spectrum given as wavelength-value pairs or as a
/// file, `None` for the other kinds (and for an unreadable file, which
/// [`rgb_of`] reports).
pub(crate) fn spectral_samples(
    p: &SpectrumParam,
    folders: &[std::path::PathBuf],
) -> Option<Vec<(f64, f64)>> {
    match p {
        SpectrumParam::Sampled(pairs) => Some(pairs.clone()),
        SpectrumParam::Named(name, _) if spectrum::named(name).is_none() => {
            read_spectrum_file(&super::parser::resolve(folders, name))
        }
        _ => None,
    }
}

/// A spectrum file: wavelength-value pairs, `#` comments.
fn read_spectrum_file(path: &Path) -> Option<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(path).ok()?;
    let nums: Vec<f64> = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(str::split_whitespace)
        .map(str::parse)
        .collect::<Result<_, _>>()
        .ok()?;
    if nums.len() < 2 || !nums.len().is_multiple_of(2) {
        return None;
    }
    let pairs: Vec<(f64, f64)> = nums.chunks_exact(2).map(|c| (c[0], c[1])).collect();
    pairs.windows(2).all(|w| w[1].0 > w[0].0).then_some(pairs)
}

impl<'a> Textures<'a> {
    /// The textures declared in a file.
    pub(crate) fn new(decls: &'a HashMap<(String, bool), TextureDecl>) -> Self {
        Self {
            decls,
            cache: HashMap::new(),
            images: HashMap::new(),
        }
    }

    /// The colour of spectrum parameter `name` of `e` (a value or a
    /// spectrum texture), or `default`.
    pub(crate) fn spectrum(
        &mut self,
        e: &Entity,
        name: &str,
        default: Vec3,
        usage: Use,
        warnings: &mut Warnings,
    ) -> Result<Tint, FormatError> {
        match e.params.spectrum(name, true)? {
            None => Ok(Tint::constant(default)),
            Some(SpectrumParam::Texture(t)) => {
                let loc = e.params.get(name).expect("present").loc.clone();
                self.texture(&t, false, &loc, warnings, 0)
            }
            Some(p) => Ok(Tint::constant(rgb_of(&p, usage, &e.folders, warnings)?)),
        }
    }

    /// The value of float parameter `name` of `e` (a texture gives its mean), or `default`.
    pub(crate) fn float(
        &mut self,
        e: &Entity,
        name: &str,
        default: f64,
        warnings: &mut Warnings,
    ) -> Result<f64, FormatError> {
        match e.params.float_or_texture(name)? {
            None => Ok(default),
            Some(FloatParam::Value(v)) => Ok(v),
            Some(FloatParam::Texture(t)) => {
                let loc = e.params.get(name).expect("present").loc.clone();
                let tint = self.texture(&t, true, &loc, warnings, 0)?;
                if tint.image.is_some() {
                    warnings.add(
                        format!("a float texture for '{name}' is replaced by its mean value"),
                        &loc,
                    );
                }
                Ok(f64::from(tint.mean().x))
            }
        }
    }

    /// The value of float parameter `name` of `e` as a tint whose red
    /// channel holds it (a texture keeps its image), or `default`.
    pub(crate) fn float_tint(
        &mut self,
        e: &Entity,
        name: &str,
        default: f64,
        warnings: &mut Warnings,
    ) -> Result<Tint, FormatError> {
        match e.params.float_or_texture(name)? {
            None => Ok(Tint::constant(Vec3::splat(default as f32))),
            Some(FloatParam::Value(v)) => Ok(Tint::constant(Vec3::splat(v as f32))),
            Some(FloatParam::Texture(t)) => {
                let loc = e.params.get(name).expect("present").loc.clone();
                self.texture(&t, true, &loc, warnings, 0)
            }
        }
    }

    /// The texture called `name` (a float texture if `float`), referred to at `loc`.
    fn texture(
        &mut self,
        name: &str,
        float: bool,
        loc: &crate::common::position::Loc,
        warnings: &mut Warnings,
        depth: usize,
    ) -> Result<Tint, FormatError> {
        let key = (name.to_owned(), float);
        if let Some(t) = self.cache.get(&key) {
            return Ok(t.clone());
        }
        if depth > MAX_TEXTURE_DEPTH {
            return Err(loc.error(format!(
                "textures refer to each other more than {MAX_TEXTURE_DEPTH} deep (a cycle?)"
            )));
        }
        let Some(decl) = self.decls.get(&key) else {
            let kind = if float { "float" } else { "spectrum" };
            return Err(loc.error(format!("unknown {kind} texture \"{name}\"")));
        };
        let t = self.convert(&decl.entity, float, warnings, depth)?;
        for p in decl.entity.params.unused() {
            warnings.add(
                format!(
                    "texture '{}': unknown parameter '{}', ignored",
                    decl.entity.kind, p.name
                ),
                &p.loc,
            );
        }
        self.cache.insert(key, t.clone());
        Ok(t)
    }

    /// A parameter of a texture that may itself be a texture.
    fn operand(
        &mut self,
        e: &Entity,
        name: &str,
        default: f64,
        float: bool,
        warnings: &mut Warnings,
        depth: usize,
    ) -> Result<Tint, FormatError> {
        let p = if float {
            e.params.float_or_texture(name)?.map(|f| match f {
                FloatParam::Value(v) => SpectrumParam::Rgb([v; 3]),
                FloatParam::Texture(t) => SpectrumParam::Texture(t),
            })
        } else {
            e.params.spectrum(name, true)?
        };
        match p {
            None => Ok(Tint::constant(Vec3::splat(default as f32))),
            Some(SpectrumParam::Texture(t)) => {
                let loc = e.params.get(name).expect("present").loc.clone();
                self.texture(&t, float, &loc, warnings, depth + 1)
            }
            Some(p) => Ok(Tint::constant(rgb_of(
                &p,
                Use::Reflectance,
                &e.folders,
                warnings,
            )?)),
        }
    }

    /// The texture `e` as a tint (`float`: a float texture), `depth`
    /// textures deep.
    ///
    /// One piece on purpose: it is pbrt's one texture table, an arm per
    /// texture type as the module's list has them, after the `uv`
    /// mapping they share.
    fn convert(
        &mut self,
        e: &Entity,
        float: bool,
        warnings: &mut Warnings,
        depth: usize,
    ) -> Result<Tint, FormatError> {
        let mapping = e.params.string("mapping")?.unwrap_or("uv");
        let (us, vs) = (
            e.params.float("uscale", 1.0)?,
            e.params.float("vscale", 1.0)?,
        );
        let (ud, vd) = (
            e.params.float("udelta", 0.0)?,
            e.params.float("vdelta", 0.0)?,
        );
        let plain_uv = mapping == "uv" && us == 1.0 && vs == 1.0 && ud == 0.0 && vd == 0.0;
        Ok(match e.kind.as_str() {
            "constant" => self.operand(e, "value", 1.0, float, warnings, depth)?,
            "scale" => {
                let tex = self.operand(e, "tex", 1.0, float, warnings, depth)?;
                let scale = self.operand(e, "scale", 1.0, true, warnings, depth)?;
                // pbrt-v3 names them tex1 and tex2.
                let t1 = self.operand(e, "tex1", 1.0, float, warnings, depth)?;
                let t2 = self.operand(e, "tex2", 1.0, float, warnings, depth)?;
                combine(&[&tex, &scale, &t1, &t2], |v| v[0] * v[1] * v[2] * v[3])
            }
            "mix" => {
                let a = self.operand(e, "tex1", 0.0, float, warnings, depth)?;
                let b = self.operand(e, "tex2", 1.0, float, warnings, depth)?;
                let amount = self.operand(e, "amount", 0.5, true, warnings, depth)?;
                combine(&[&a, &b, &amount], |v| v[0].lerp(v[1], v[2].x))
            }
            "imagemap" => {
                let Some(file) = e.params.string("filename")? else {
                    return Err(e.loc.error("texture 'imagemap' needs \"string filename\""));
                };
                let path = super::parser::resolve(&e.folders, file);
                let scale = e.params.float("scale", 1.0)? as f32;
                let invert = e.params.bool("invert", false)?;
                let _ = e.params.string("filter")?;
                let wrap = match e.params.string("wrap")?.unwrap_or("repeat") {
                    "repeat" => Wrap::Repeat,
                    "clamp" => Wrap::Clamp,
                    other => {
                        warnings.add(
                            format!("imagemap wrap '{other}' is not supported; 'clamp' used"),
                            &e.loc,
                        );
                        Wrap::Clamp
                    }
                };
                let sampling = Sampling {
                    wrap,
                    transform: Affine2::from_mat2_translation(
                        Mat2::from_diagonal(Vec2::new(us as f32, vs as f32)),
                        Vec2::new(ud as f32, vd as f32),
                    ),
                };
                let _ = (e.params.float("maxanisotropy", 8.0)?, e.params.bool("trilinear", false)?);
                let encoding = e.params.string("encoding")?.map(str::to_owned);
                let v3_gamma = match e.params.has("gamma") {
                    true => Some(e.params.bool("gamma", true)?),
                    false => None,
                };
                let Some(img) = self.image(&path, &e.loc, warnings) else {
                    return Ok(Tint::constant(Vec3::splat(0.5 * scale)));
                };
                let img = match recode(&img, &path, encoding.as_deref(), v3_gamma) {
                    Ok(Some(t)) => Arc::new(t),
                    Ok(None) => img,
                    Err(what) => {
                        warnings.add(format!("imagemap encoding {what}; read as sRGB"), &e.loc);
                        img
                    }
                };
                // A float texture of a colour image is the mean of its
                // channels, or its alpha when it has one (as pbrt-v4 filters them).
                let img = if float { Arc::new(float_channel(&img)) } else { img };
                if invert {
                    let texels = img
                        .texels()
                        .map(|v| (Vec3::ONE - v * scale).max(Vec3::ZERO))
                        .collect();
                    Tint {
                        color: Vec3::ONE,
                        image: Some(Arc::new(with_alpha_of(
                            &img,
                            Texture::new(img.width, img.height, texels),
                        ))),
                        sampling,
                    }
                } else {
                    Tint {
                        color: Vec3::splat(scale),
                        image: Some(img),
                        sampling,
                    }
                }
            }
            "checkerboard" => {
                let dim = e.params.int("dimension", 2)?;
                let a = self.operand(e, "tex1", 1.0, float, warnings, depth)?;
                let b = self.operand(e, "tex2", 0.0, float, warnings, depth)?;
                if dim != 2 || mapping != "uv" {
                    warnings.add(
                        "texture 'checkerboard' other than 2D in uv: replaced by the mean of its two values",
                        &e.loc,
                    );
                    return Ok(Tint::constant((a.mean() + b.mean()) * 0.5));
                }
                let mask = checkerboard(us, vs, ud, vd);
                return Ok(if a.image.is_none() && b.image.is_none() {
                    let t = mask.image.expect("an image");
                    let texels = t.texels().map(|m| if m.x > 0.5 { a.color } else { b.color }).collect();
                    Tint {
                        color: Vec3::ONE,
                        image: Some(Arc::new(Texture::new(t.width, t.height, texels))),
                        sampling: Sampling::default(),
                    }
                } else {
                    combine(&[&a, &b, &mask], |v| if v[2].x > 0.5 { v[0] } else { v[1] })
                });
            }
            "bilerp" => {
                let mut v = [Vec3::ZERO; 4];
                for (i, (n, d)) in [("v00", 0.0), ("v01", 1.0), ("v10", 0.0), ("v11", 1.0)]
                    .into_iter()
                    .enumerate()
                {
                    v[i] = self.operand(e, n, d, float, warnings, depth)?.mean();
                }
                let [v00, v01, v10, v11] = v;
                if !plain_uv {
                    warnings.add("texture 'bilerp' with a uv scale or offset: drawn over the unit square", &e.loc);
                }
                return Ok(bilerp(v00, v01, v10, v11));
            }
            other => {
                warnings.add(
                    format!("texture '{other}' is not supported; replaced by grey 0.5"),
                    &e.loc,
                );
                e.params.mark_all_used();
                return Ok(Tint::constant(Vec3::splat(0.5)));
            }
        })
        .inspect(|t| {
            if !plain_uv && t.image.is_some() && !(e.kind == "imagemap" && mapping == "uv") {
                warnings.add(
                    "texture mapping other than 'uv' with unit scale and no offset is not supported; the plain uv mapping is used",
                    &e.loc,
                );
            }
        })
    }

    /// An image file, read once however many textures use it; `None` (a
    /// warning) if it cannot be read.
    fn image(
        &mut self,
        path: &Path,
        loc: &crate::common::position::Loc,
        warnings: &mut Warnings,
    ) -> Option<Arc<Texture>> {
        if let Some(t) = self.images.get(path) {
            return t.clone();
        }
        let t = match load_image(path) {
            Ok(i) if i.width > 0 && i.height > 0 => {
                let texels = i.rgb.chunks_exact(3).map(Vec3::from_slice).collect();
                let t = Texture::new(i.width, i.height, texels);
                Some(Arc::new(match i.alpha {
                    Some(a) => t.with_alpha(a),
                    None => t,
                }))
            }
            Ok(_) => {
                warnings.add(
                    format!("{}: empty image; grey 0.5 used", path.display()),
                    loc,
                );
                None
            }
            Err(e) => {
                warnings.add(format!("{e}; grey 0.5 used"), loc);
                None
            }
        };
        self.images.insert(path.to_path_buf(), t.clone());
        t
    }
}

/// An 8-bit image (PNG, JPEG, TGA, which are read as sRGB) as another
/// `encoding` says: pbrt-v4's `"linear"` or `"gamma G"`, pbrt-v3's `gamma`
/// false (linear). `Ok(None)`: as read (sRGB, or a float image, whose
/// values are linear whatever the encoding says).
fn recode(
    img: &Texture,
    path: &Path,
    encoding: Option<&str>,
    v3_gamma: Option<bool>,
) -> Result<Option<Texture>, String> {
    let eight_bit = path
        .extension()
        .map(|x| x.to_string_lossy().to_ascii_lowercase())
        .is_some_and(|x| matches!(x.as_str(), "png" | "jpg" | "jpeg" | "tga"));
    let gamma = match (encoding, v3_gamma) {
        (Some("sRGB") | None, None | Some(true)) => return Ok(None),
        (None, Some(false)) | (Some("linear"), _) => 1.0,
        (Some(enc), _) => match enc.strip_prefix("gamma ").map(|g| g.trim().parse::<f32>()) {
            Some(Ok(g)) if g > 0.0 && g.is_finite() => g,
            _ => return Err(format!("\"{enc}\" is not sRGB, linear or gamma G")),
        },
    };
    if !eight_bit {
        return Ok(None);
    }
    // The stored byte, recovered exactly from its sRGB decoding.
    let byte = |v: f32| f32::from(linear_to_srgb8(v)) / 255.0;
    let texels = img
        .texels()
        .map(|v| Vec3::from_array(v.to_array().map(|c| byte(c).powf(gamma))))
        .collect();
    Ok(Some(with_alpha_of(
        img,
        Texture::new(img.width, img.height, texels),
    )))
}

/// A colour image as a float texture (the value in every channel): its
/// alpha where it has some below 1, else the mean of its channels.
fn float_channel(img: &Texture) -> Texture {
    let alpha = alpha_of(img).filter(|a| a.iter().any(|&v| v < 1.0));
    let texels = match alpha {
        Some(a) => a.iter().map(|&v| Vec3::splat(v)).collect(),
        None => img
            .texels()
            .map(|v| Vec3::splat((v.x + v.y + v.z) / 3.0))
            .collect(),
    };
    Texture::new(img.width, img.height, texels)
}

/// `f` of several tints texel by texel: of constants, a constant; else an
/// image on the grid of the largest operand image (keeping its alpha), each
/// operand looked up bilinearly at that grid's texel centres (exact when
/// the images have the same size).
fn combine(ops: &[&Tint], f: impl Fn(&[Vec3]) -> Vec3) -> Tint {
    let Some((grid, sampling)) = ops
        .iter()
        .filter_map(|t| t.image.as_ref().map(|i| (i, t.sampling)))
        .max_by_key(|(i, _)| texel_count(i))
    else {
        let v: Vec<Vec3> = ops.iter().map(|t| t.color).collect();
        return Tint::constant(f(&v));
    };
    let (w, h) = (grid.width, grid.height);
    let mut texels = Vec::with_capacity(texel_count(grid));
    let mut v = vec![Vec3::ZERO; ops.len()];
    for y in 0..h {
        for x in 0..w {
            let uv = glam::Vec2::new(
                (x as f32 + 0.5) / w as f32,
                1.0 - (y as f32 + 0.5) / h as f32,
            );
            for (slot, t) in v.iter_mut().zip(ops) {
                *slot = match &t.image {
                    Some(i) if Arc::ptr_eq(i, grid) => t.color * i.texel(x.into(), y.into()),
                    Some(i) => t.color * i.bilinear(uv),
                    None => t.color,
                };
            }
            texels.push(f(&v));
        }
    }
    Tint {
        color: Vec3::ONE,
        image: Some(Arc::new(with_alpha_of(grid, Texture::new(w, h, texels)))),
        sampling,
    }
}

/// Texels per check of a baked checkerboard (while the image stays within
/// [`MAX_BAKED_SIDE`]): a bilinear lookup blurs a check's edge over one
/// texel, 1/32 of the check.
const TEXELS_PER_CHECK: f64 = 32.0;

/// pbrt's 2D checkerboard over the unit square of uv: 1 where
/// `floor(u us + ud) + floor(v vs + vd)` is even (pbrt's `tex1`), else 0,
/// evaluated at the texel centres of an image of [`TEXELS_PER_CHECK`]
/// texels per check. Texture coordinates outside the unit square repeat
/// it (pbrt's pattern continues; the two agree for even integer scales).
fn checkerboard(us: f64, vs: f64, ud: f64, vd: f64) -> Tint {
    let side =
        |s: f64| (s.abs().ceil().max(1.0) * TEXELS_PER_CHECK).min(f64::from(MAX_BAKED_SIDE)) as u32;
    let (w, h) = (side(us), side(vs));
    let mut texels = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        // Row 0 is the top (v = 1).
        let v = 1.0 - (f64::from(y) + 0.5) / f64::from(h);
        for x in 0..w {
            let u = (f64::from(x) + 0.5) / f64::from(w);
            let parity = ((u * us + ud).floor() + (v * vs + vd).floor()).rem_euclid(2.0);
            texels.push(Vec3::splat(if parity == 0.0 { 1.0 } else { 0.0 }));
        }
    }
    Tint {
        color: Vec3::ONE,
        image: Some(Arc::new(Texture::new(w, h, texels))),
        sampling: Sampling::default(),
    }
}

/// Bilinear interpolation of four corner values (`v00` at u = v = 0,
/// `v10` at u = 1), baked at 64 x 64.
fn bilerp(v00: Vec3, v01: Vec3, v10: Vec3, v11: Vec3) -> Tint {
    let n = 64u32;
    let mut texels = Vec::with_capacity((n * n) as usize);
    for y in 0..n {
        let v = 1.0 - (y as f32 + 0.5) / n as f32;
        for x in 0..n {
            let u = (x as f32 + 0.5) / n as f32;
            texels.push(
                v00 * (1.0 - u) * (1.0 - v)
                    + v10 * u * (1.0 - v)
                    + v01 * (1.0 - u) * v
                    + v11 * u * v,
            );
        }
    }
    Tint {
        color: Vec3::ONE,
        image: Some(Arc::new(Texture::new(n, n, texels))),
        sampling: Sampling::default(),
    }
}
