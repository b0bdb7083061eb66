//! Mitsuba textures as what a Sahara material holds: a colour times at
//! most one image ([`Tint`]).
//!
//! - `bitmap` (`filename`, `raw`, `wrap_mode` `repeat` / `mirror` /
//!   `clamp`, `to_uv`): the image, read as every Sahara texture is
//!   (trilinear MIP-mapping; `filter_type` `nearest` is warned); an 8-bit
//!   image is sRGB unless `raw` is true.
//! - `checkerboard` (`color0`, `color1`, `to_uv`): baked at 32 texels a
//!   check, two checks a side per unit of uv.
//! - `mesh_attribute`, `volume`: grey 0.5 (warned).
//! - A texture where Sahara holds a number (roughness, opacity's constant
//!   part, an emitter's radiance) is its mean, warned.
//!
//! Mitsuba reads `v = 0` at an image's top row and Sahara at its bottom,
//! so every map here reads `(u, 1 - v)` after `to_uv`.

use std::sync::Arc;

use glam::{Affine2, DMat4, Vec2, Vec3};
use sahara_readers::FormatError;
use sahara_render::{Encoding, Texture, Wrap};

use super::builder::{key, Builder};
use super::properties::Object;
use super::spectra::Usage;
use super::xml::Node;
use crate::common::image::load_texture;
use crate::common::tint::{Sampling, Tint};

/// Texels per check side of a baked checkerboard.
const CHECK_TEXELS: u32 = 32;

/// Mitsuba's `to_uv` (a 4x4 transform of which the 2D affine part acts
/// on uv), then the flip of `v` between the two conventions.
fn uv_transform(m: &DMat4) -> Affine2 {
    let a = Affine2::from_cols_array(&[
        m.x_axis.x as f32,
        m.x_axis.y as f32,
        m.y_axis.x as f32,
        m.y_axis.y as f32,
        m.w_axis.x as f32,
        m.w_axis.y as f32,
    ]);
    let flip = Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y);
    flip * a
}

impl<'a> Builder<'a> {
    /// The colour parameter `name` of `o`: a value, a nested texture or
    /// a reference to one; `default` if not given.
    pub(crate) fn tint(
        &mut self,
        o: &Object<'a>,
        name: &str,
        default: Vec3,
        usage: Usage,
    ) -> Result<Tint, FormatError> {
        if let Some(c) = o.color(name)? {
            if matches!(c, super::spectra::Color::Blackbody(_)) {
                self.w.add(
                    "blackbody: normalised to luminance 1 (Mitsuba's is in absolute units)",
                    &o.get(name).expect("given").loc,
                );
            }
            return Ok(Tint::constant(c.rgb(usage)));
        }
        let Some(e) = o.named(name) else {
            return Ok(Tint::constant(default));
        };
        let node = self.resolve(e.child, &["texture", "spectrum"], "a <texture>")?;
        if node.tag == "spectrum" {
            // `<spectrum type="blackbody" name=...>` and the like.
            let o = self.object(node)?;
            let c = match o.ty {
                "blackbody" => {
                    let t = o.float("temperature", 6504.0)?;
                    super::spectra::Color::Blackbody(t)
                }
                "uniform" => super::spectra::Color::Uniform(o.float("value", 1.0)?),
                other => return Err(o.error(format!("unknown spectrum type '{other}'"))),
            };
            o.warn_unused(&mut self.w);
            if matches!(c, super::spectra::Color::Blackbody(_)) {
                self.w.add(
                    "blackbody: normalised to luminance 1 (Mitsuba's is in absolute units)",
                    &node.loc,
                );
            }
            return Ok(Tint::constant(c.rgb(usage)));
        }
        self.texture(node)
    }

    /// The number parameter `name` of `o` (a float, or a texture's mean,
    /// warned).
    pub(crate) fn number(
        &mut self,
        o: &Object<'a>,
        name: &str,
        default: f64,
    ) -> Result<f64, FormatError> {
        if let Some(v) = o.float_opt(name)? {
            return Ok(v);
        }
        if o.named(name).is_none() && !o.has(name) {
            return Ok(default);
        }
        let t = self.tint(o, name, Vec3::splat(default as f32), Usage::Reflectance)?;
        if t.image.is_some() {
            self.w.add(
                format!(
                    "{}: a texture for '{name}' is replaced by its mean",
                    o.what()
                ),
                &o.node.loc,
            );
        }
        Ok(f64::from(t.mean().element_sum() / 3.0))
    }

    /// The tint of a `<texture>` element (read once).
    pub(crate) fn texture(&mut self, node: &'a Node) -> Result<Tint, FormatError> {
        if let Some(t) = self.textures.get(&key(node)) {
            return Ok(t.clone());
        }
        let o = self.object(node)?;
        let to_uv = uv_transform(&o.transform("to_uv")?);
        let tint = match o.ty {
            "bitmap" => {
                let Some(path) = o.file("filename", &self.main)? else {
                    return Err(o.error("texture 'bitmap' needs a 'filename' string"));
                };
                let raw = o.bool("raw", false)?;
                let wrap = match o.string("wrap_mode")?.unwrap_or("repeat") {
                    "repeat" => Wrap::Repeat,
                    "mirror" => Wrap::MirroredRepeat,
                    "clamp" => Wrap::Clamp,
                    other => {
                        return Err(o.error(format!(
                            "bitmap: unknown wrap_mode '{other}' (expected repeat, mirror or clamp)"
                        )))
                    }
                };
                match o.string("filter_type")?.unwrap_or("bilinear") {
                    "bilinear" => {}
                    "nearest" => self.w.add(
                        "bitmap filter_type 'nearest': Sahara filters every texture (trilinear MIP-mapping)",
                        &node.loc,
                    ),
                    other => {
                        return Err(o.error(format!(
                            "bitmap: unknown filter_type '{other}' (expected bilinear or nearest)"
                        )))
                    }
                }
                for k in ["format", "accel"] {
                    o.get(k);
                }
                let encoding = if raw {
                    Encoding::Linear
                } else {
                    Encoding::Srgb
                };
                let img = load_texture(&path, encoding).map_err(|e| o.error(e))?;
                Tint {
                    color: Vec3::ONE,
                    image: Some(Arc::new(img)),
                    sampling: Sampling {
                        wrap,
                        transform: to_uv,
                    },
                }
            }
            "checkerboard" => {
                let c0 = self.tint(&o, "color0", Vec3::splat(0.4), Usage::Reflectance)?;
                let c1 = self.tint(&o, "color1", Vec3::splat(0.2), Usage::Reflectance)?;
                if c0.image.is_some() || c1.image.is_some() {
                    self.w.add(
                        "checkerboard: textured colours are replaced by their means",
                        &node.loc,
                    );
                }
                let (a, b) = (c0.mean(), c1.mean());
                let n = 2 * CHECK_TEXELS;
                let mut texels = Vec::with_capacity((n * n) as usize);
                // Row 0 is v = 0 here (Mitsuba's top row), as for a bitmap.
                for y in 0..n {
                    for x in 0..n {
                        let same = (x < CHECK_TEXELS) == (y < CHECK_TEXELS);
                        texels.push(if same { a } else { b });
                    }
                }
                Tint {
                    color: Vec3::ONE,
                    image: Some(Arc::new(Texture::new(n, n, texels))),
                    sampling: Sampling {
                        wrap: Wrap::Repeat,
                        transform: to_uv,
                    },
                }
            }
            "mesh_attribute" | "volume" => {
                self.w.add(
                    format!("texture '{}' is not supported; grey 0.5", o.ty),
                    &node.loc,
                );
                o.mark_all_used();
                Tint::constant(Vec3::splat(0.5))
            }
            other => return Err(o.error(format!("unknown texture type '{other}'"))),
        };
        o.warn_unused(&mut self.w);
        self.textures.insert(key(node), tint.clone());
        Ok(tint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn to_uv_then_flip_v() {
        let m = DMat4::from_scale(glam::DVec3::new(2.0, 4.0, 1.0));
        let a = uv_transform(&m);
        assert_eq!(
            a.transform_point2(Vec2::new(0.25, 0.25)),
            Vec2::new(0.5, 0.0)
        );
        assert_eq!(
            uv_transform(&DMat4::IDENTITY).transform_point2(Vec2::new(0.3, 0.0)),
            Vec2::new(0.3, 1.0)
        );
    }
}
