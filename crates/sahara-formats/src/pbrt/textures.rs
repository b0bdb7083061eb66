//! pbrt textures as what a Sahara material can hold: a colour times at most
//! one image.
//!
//! - `constant`, `scale` and `mix` of constants fold into the colour;
//!   `scale` of an image by a constant keeps the image and scales the colour.
//! - `imagemap` (PNG, JPEG, HDR, EXR) becomes the image, with `scale` and
//!   `invert` applied; its filtering is Sahara's bilinear lookup with
//!   repeat wrapping whatever `filter` and `wrap` say.
//! - `checkerboard` (2D) and `bilerp` of constants are baked into images.
//! - Everything else (3D checkerboards, `dots`, `fbm`, `wrinkled`, `windy`,
//!   `marble`, `ptex`, `mix` of images, mapping other than `uv` with unit
//!   scale) is approximated by a constant or left as is, with a warning
//!   per kind.
//! - Float textures (roughness, amounts) become a constant: an image's mean.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use sahara_render::Texture;

use super::description::{Entity, TextureDecl};
use super::params::{FloatParam, SpectrumParam};
use super::spectrum::{self, Use};
use super::warnings::Warnings;
use crate::error::FormatError;
use crate::image_in::load_rgb_f32;

/// A colour, optionally times an image.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tint {
    /// The constant factor.
    pub(crate) color: Vec3,
    /// The image (linear RGB), if any.
    pub(crate) image: Option<Arc<Texture>>,
}

impl Tint {
    /// A constant.
    pub(crate) fn constant(c: Vec3) -> Self {
        Self {
            color: c,
            image: None,
        }
    }

    /// The mean value (the image's mean texel times the colour).
    pub(crate) fn mean(&self) -> Vec3 {
        match &self.image {
            Some(t) => self.color * t.mean(),
            None => self.color,
        }
    }
}

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

    /// The texture called `name` (a float texture if `float`), referred to at `loc`.
    fn texture(
        &mut self,
        name: &str,
        float: bool,
        loc: &super::lexer::Loc,
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
                product(product(tex, scale, e, warnings), product(t1, t2, e, warnings), e, warnings)
            }
            "mix" => {
                let a = self.operand(e, "tex1", 0.0, float, warnings, depth)?;
                let b = self.operand(e, "tex2", 1.0, float, warnings, depth)?;
                let amount = self.operand(e, "amount", 0.5, true, warnings, depth)?;
                if a.image.is_some() || b.image.is_some() || amount.image.is_some() {
                    warnings.add("texture 'mix' of images: replaced by the mix of their means", &e.loc);
                }
                let t = amount.mean().x;
                Tint::constant(a.mean() * (1.0 - t) + b.mean() * t)
            }
            "imagemap" => {
                let Some(file) = e.params.string("filename")? else {
                    return Err(e.loc.error("texture 'imagemap' needs \"string filename\""));
                };
                let path = super::parser::resolve(&e.folders, file);
                let scale = e.params.float("scale", 1.0)? as f32;
                let invert = e.params.bool("invert", false)?;
                let _ = (e.params.string("filter")?, e.params.string("wrap")?);
                let _ = (e.params.float("maxanisotropy", 8.0)?, e.params.bool("trilinear", false)?);
                if let Some(enc) = e.params.string("encoding")? {
                    if enc != "sRGB" {
                        warnings.add(
                            format!("imagemap encoding \"{enc}\": 8-bit images are always read as sRGB"),
                            &e.loc,
                        );
                    }
                }
                if e.params.bool("gamma", false)? {
                    warnings.add("imagemap \"gamma\": 8-bit images are always read as sRGB", &e.loc);
                }
                match self.image(&path, &e.loc, warnings) {
                    Some(img) if !invert => Tint {
                        color: Vec3::splat(scale),
                        image: Some(img),
                    },
                    Some(img) => {
                        let texels = img
                            .texels()
                            .map(|t| (Vec3::ONE - t * scale).max(Vec3::ZERO))
                            .collect();
                        Tint {
                            color: Vec3::ONE,
                            image: Some(Arc::new(Texture::new(img.width, img.height, texels))),
                        }
                    }
                    None => Tint::constant(Vec3::splat(0.5 * scale)),
                }
            }
            "checkerboard" => {
                let dim = e.params.int("dimension", 2)?;
                let a = self.operand(e, "tex1", 1.0, float, warnings, depth)?.mean();
                let b = self.operand(e, "tex2", 0.0, float, warnings, depth)?.mean();
                if dim != 2 || mapping != "uv" || ud != 0.0 || vd != 0.0 {
                    warnings.add(
                        "texture 'checkerboard' other than 2D in uv: replaced by the mean of its two values",
                        &e.loc,
                    );
                    return Ok(Tint::constant((a + b) * 0.5));
                }
                return Ok(checkerboard(a, b, us, vs));
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
            if !plain_uv && t.image.is_some() {
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
        loc: &super::lexer::Loc,
        warnings: &mut Warnings,
    ) -> Option<Arc<Texture>> {
        if let Some(t) = self.images.get(path) {
            return t.clone();
        }
        let t = match load_rgb_f32(path) {
            Ok((w, h, rgb)) if w > 0 && h > 0 => {
                let texels = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
                Some(Arc::new(Texture::new(w, h, texels)))
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

/// `a` times `b`: colours multiply; of two images only the first is kept (a warning).
fn product(a: Tint, b: Tint, e: &Entity, warnings: &mut Warnings) -> Tint {
    let image = match (a.image, b.image) {
        (Some(x), Some(_)) => {
            warnings.add(
                "texture 'scale' of two images: the second is replaced by its mean",
                &e.loc,
            );
            Some(x)
        }
        (x, y) => x.or(y),
    };
    Tint {
        color: a.color * b.color,
        image,
    }
}

/// A 2D checkerboard of `us` x `vs` checks over the unit square, `a` where
/// `floor(u us) + floor(v vs)` is even, baked at 8 texels per check.
fn checkerboard(a: Vec3, b: Vec3, us: f64, vs: f64) -> Tint {
    let checks = |s: f64| s.abs().round().clamp(1.0, f64::from(MAX_BAKED_SIDE / 8)) as u32;
    let (cu, cv) = (checks(us), checks(vs));
    let (w, h) = (cu * 8, cv * 8);
    let mut texels = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        // Row 0 is the top (v = 1).
        let v_check = (h - 1 - y) / 8;
        for x in 0..w {
            let even = (x / 8 + v_check) % 2 == 0;
            texels.push(if even { a } else { b });
        }
    }
    Tint {
        color: Vec3::ONE,
        image: Some(Arc::new(Texture::new(w, h, texels))),
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
    }
}
