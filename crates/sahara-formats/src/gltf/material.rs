//! glTF materials as renderer [`Material`]s, with their textures.
//!
//! The renderer has one BSDF per material, so a file material becomes the
//! BSDF its parameters say it mostly is:
//!
//! **glTF**: the metallic-roughness BSDF (`Bsdf::MetallicRoughness`) with
//! the material's base colour, metallic and roughness factors, its
//! `KHR_materials_ior` index and `KHR_materials_specular` strength and
//! colour. A material with `KHR_materials_transmission` of at least 0.5 is
//! glass instead: a thin pane (`ThinDielectric`) when it has no
//! `KHR_materials_volume` thickness (glTF's thin-walled default), else a
//! solid of the material's index, rough when its roughness is. `emissive`
//! times `KHR_materials_emissive_strength` is emitted (from both faces
//! when the material is double-sided), and a material that is not
//! double-sided is black from behind. `alphaMode` `MASK` (with
//! `alphaCutoff`) and `BLEND` cut the surface by the base colour's alpha
//! factor times the base colour texture's alpha channel.
//! `KHR_materials_clearcoat` is a coat over the material, with its own
//! normal map (without one the coat follows the surface's normal, not the
//! base's normal map).
//!
//! Every glTF texture is read with its sampler's wrap modes, its uv set
//! (`TEXCOORD_0` or `_1`) and its `KHR_texture_transform`: the base colour
//! (sRGB; alpha linear), metallic (blue) and roughness (green) of the
//! metallic-roughness texture, the normal map with its `scale`, occlusion
//! (red) with its `strength`, the emissive texture (sRGB), and the clear
//! coat's strength (red), roughness (green) and normal map; every data
//! texture is linear.
//!
//! A texture that cannot be read is a warning and the material goes
//! without it. Each image is decoded once per encoding
//! ([`TextureCache`]).

use std::sync::Arc;

use glam::{Affine2, Vec2};
use sahara_readers::gltf::{GltfAlphaMode, GltfImage, GltfMaterial, GltfTexture, GltfWrap};
use sahara_render::{AlphaMode, Bsdf, Distribution, Material, Texture};
use sahara_render::{Channel, Encoding, ScalarMap, TextureMap, Wrap};
use sahara_render::{Clearcoat, NormalMap, OcclusionMap};

use crate::common::image::decode_texture;
use crate::common::materials::{emission, unit, Source, TextureCache};

impl TextureCache {
    /// The image of a glTF texture of the file `name`, read as `encoding`.
    fn gltf(
        &mut self,
        t: &GltfTexture,
        name: &str,
        encoding: Encoding,
        warnings: &mut Vec<String>,
    ) -> Option<Arc<Texture>> {
        match &t.image {
            GltfImage::File(path) => self.file(path, encoding, warnings),
            GltfImage::Embedded { bytes, .. } => self.get(
                Source::Embedded(name.to_owned(), t.image_index),
                encoding,
                warnings,
                || {
                    decode_texture(
                        bytes,
                        &format!("{name} (embedded image {})", t.image_index),
                        encoding,
                    )
                },
            ),
        }
    }
}

/// A glTF `alphaMode` as the renderer's.
fn alpha_mode(a: GltfAlphaMode) -> AlphaMode {
    match a {
        GltfAlphaMode::Opaque => AlphaMode::Opaque,
        GltfAlphaMode::Mask { cutoff } => AlphaMode::Mask { cutoff },
        GltfAlphaMode::Blend => AlphaMode::Blend,
    }
}

/// A glTF sampler's wrap mode as the renderer's.
fn wrap(w: GltfWrap) -> Wrap {
    match w {
        GltfWrap::Repeat => Wrap::Repeat,
        GltfWrap::Clamp => Wrap::Clamp,
        GltfWrap::MirroredRepeat => Wrap::MirroredRepeat,
    }
}

/// The BSDF a glTF material stands for (rules in the module documentation).
pub fn gltf_bsdf(m: &GltfMaterial) -> Bsdf {
    let base = unit([m.base_color[0], m.base_color[1], m.base_color[2]]);
    let factor = |x: f32, default: f32| {
        if x.is_finite() {
            x.clamp(0.0, 1.0)
        } else {
            default
        }
    };
    let roughness = factor(m.roughness, 1.0);
    // glTF allows an ior of 0 to mean "infinitely dense"; anything below 1
    // is taken as the default.
    let ior = if m.ior.is_finite() && m.ior >= 1.0 {
        m.ior
    } else {
        1.5
    };
    if factor(m.transmission, 0.0) >= 0.5 && factor(m.metallic, 1.0) < 0.5 {
        return if m.thickness.is_nan() || m.thickness <= 0.0 {
            Bsdf::ThinDielectric { ior }
        } else if roughness > 0.0 {
            Bsdf::RoughDielectric {
                ior,
                roughness,
                distribution: Distribution::Ggx,
            }
        } else {
            Bsdf::Dielectric { ior }
        };
    }
    Bsdf::MetallicRoughness {
        base_color: base,
        metallic: factor(m.metallic, 1.0),
        roughness,
        ior,
        specular: factor(m.specular, 1.0),
        specular_color: unit(m.specular_color),
    }
}

/// glTF's uv space (v down the image) to Sahara's (v up) and back: the
/// flip `(u, v) -> (u, 1 - v)`.
const FLIP_V: Affine2 = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);

/// A glTF material as a renderer material; `name` (the glTF file) is used in warnings.
pub fn gltf_material(
    m: &GltfMaterial,
    name: &str,
    textures: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Material {
    let mut out = Material::new(gltf_bsdf(m))
        .with_emission(emission(m.emissive))
        .with_two_sided(m.double_sided)
        .with_alpha(alpha_mode(m.alpha_mode), m.base_color[3].clamp(0.0, 1.0));
    out.two_sided_emission = m.double_sided;
    let label = m.name.as_deref().unwrap_or("(unnamed)");
    let mut map = |t: Option<&GltfTexture>, role: &str, encoding: Encoding| {
        let t = t?;
        if t.tex_coord > 1 {
            warnings.push(format!(
                "{name}: material '{label}': {role} uses TEXCOORD_{}, which is not loaded; the material goes without it",
                t.tex_coord
            ));
            return None;
        }
        let texture = textures.gltf(t, name, encoding, warnings)?;
        Some(
            TextureMap::new(texture)
                .with_wrap(wrap(t.wrap[0]), wrap(t.wrap[1]))
                .with_uv_set(t.tex_coord as u8)
                .with_transform(FLIP_V * t.transform * FLIP_V),
        )
    };
    let tex = &mut out.textures;
    tex.base_color = map(
        m.base_color_texture.as_ref(),
        "base colour texture",
        Encoding::Srgb,
    );
    if let Some(mr) = map(
        m.metallic_roughness_texture.as_ref(),
        "metallic-roughness texture",
        Encoding::Linear,
    ) {
        tex.metallic = Some(ScalarMap::new(mr.clone(), Channel::B));
        tex.roughness = Some(ScalarMap::new(mr, Channel::G));
    }
    if let Some((t, scale)) = &m.normal_texture {
        tex.normal = map(Some(t), "normal texture", Encoding::Linear).map(|map| NormalMap {
            map,
            scale: if scale.is_finite() { *scale } else { 1.0 },
        });
    }
    if let Some((t, strength)) = &m.occlusion_texture {
        tex.occlusion =
            map(Some(t), "occlusion texture", Encoding::Linear).map(|map| OcclusionMap {
                map: ScalarMap::new(map, Channel::R),
                strength: if strength.is_finite() {
                    strength.clamp(0.0, 1.0)
                } else {
                    1.0
                },
            });
    }
    tex.emission = map(
        m.emissive_texture.as_ref(),
        "emissive texture",
        Encoding::Srgb,
    );
    if let Some(c) = &m.clearcoat {
        let unit = |x: f32| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                0.0
            }
        };
        out.clearcoat = Some(Box::new(Clearcoat {
            factor: unit(c.factor),
            roughness: unit(c.roughness),
            ior: 1.5,
            factor_map: map(c.texture.as_ref(), "clearcoat texture", Encoding::Linear)
                .map(|m| ScalarMap::new(m, Channel::R)),
            roughness_map: map(
                c.roughness_texture.as_ref(),
                "clearcoat roughness texture",
                Encoding::Linear,
            )
            .map(|m| ScalarMap::new(m, Channel::G)),
            normal_map: c.normal_texture.as_ref().and_then(|(t, scale)| {
                map(Some(t), "clearcoat normal texture", Encoding::Linear).map(|map| NormalMap {
                    map,
                    scale: if scale.is_finite() { *scale } else { 1.0 },
                })
            }),
        }))
        .filter(|c| c.factor > 0.0);
    }
    out
}
