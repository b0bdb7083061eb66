//! File materials (MTL, glTF) as renderer [`Material`]s, and their textures.
//!
//! The renderer has one BSDF per material, so a file material becomes the
//! BSDF its parameters say it mostly is:
//!
//! **MTL** (first rule that applies):
//!
//! 1. `illum` 4, 6 or 7, or `d` < 1: smooth glass (`Dielectric`) with
//!    `ior = Ni` (1.5 when `Ni` <= 1, the MTL default of 1 meaning "not given").
//! 2. `illum` 3 or 5: a mirror tinted by `Ks` (white when `Ks` is black).
//! 3. `illum` >= 2 with `Ks` brighter than `Kd` (largest component): a
//!    glossy conductor of colour `Ks` whose GGX width is the Beckmann width
//!    matching Phong exponent `Ns` (Walter et al. 2007):
//!    `alpha = sqrt(2 / (Ns + 2))`, so perceptual `roughness = sqrt(alpha)`
//!    (the renderer squares it).
//! 4. Otherwise Lambertian with albedo `Kd` (`illum` 0 and 1 have no
//!    specular term; a `Ks` weaker than `Kd` is dropped).
//!
//! `Ke` > 0 adds front-face emission of radiance `Ke` to any of these;
//! `map_Kd` multiplies the diffuse or conductor colour (sRGB images are
//! linearised). Colours are clamped to [0, 1].
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
//! without it. Each image is decoded once per encoding ([`TextureCache`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Affine2, Vec2, Vec3};
use sahara_render::{AlphaMode, Bsdf, Distribution, Material, Texture};
use sahara_render::{Channel, Encoding, ScalarMap, TextureMap, Wrap};
use sahara_render::{Clearcoat, NormalMap, OcclusionMap};

use crate::image_in::{decode_texture, load_texture};
use sahara_readers::gltf::{GltfAlphaMode, GltfImage, GltfMaterial, GltfTexture, GltfWrap};
use sahara_readers::mtl::MtlMaterial;

/// IOR used for MTL glass that gives none (`Ni` <= 1).
pub const DEFAULT_GLASS_IOR: f32 = 1.5;

/// Where a texture's image came from, as the cache knows it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Source {
    /// A file.
    File(PathBuf),
    /// Image `index` embedded in the glTF file `file`.
    Embedded(String, usize),
}

/// Decoded textures by image and encoding, so that an image used by many
/// materials is read once.
#[derive(Debug, Default)]
pub struct TextureCache {
    images: HashMap<(Source, Encoding), Option<Arc<Texture>>>,
}

impl TextureCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The texture in `path` read as `encoding`, decoded on first use;
    /// `None` (and a warning) if it cannot be read.
    pub fn file(
        &mut self,
        path: &Path,
        encoding: Encoding,
        warnings: &mut Vec<String>,
    ) -> Option<Arc<Texture>> {
        self.get(Source::File(path.to_path_buf()), encoding, warnings, || {
            load_texture(path, encoding)
        })
    }

    fn get(
        &mut self,
        source: Source,
        encoding: Encoding,
        warnings: &mut Vec<String>,
        decode: impl FnOnce() -> Result<Texture, crate::FormatError>,
    ) -> Option<Arc<Texture>> {
        self.images
            .entry((source, encoding))
            .or_insert_with(|| match decode() {
                Ok(t) => Some(Arc::new(t)),
                Err(e) => {
                    warnings.push(format!("{e}; the material goes without this texture"));
                    None
                }
            })
            .clone()
    }

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

    /// Number of distinct images decoded (or tried), per encoding.
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// True if no texture was asked for.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
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

/// Clamps every component to [0, 1] (NaN becomes 0).
fn unit(c: [f32; 3]) -> Vec3 {
    Vec3::from_array(c.map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }))
}

/// GGX perceptual roughness matching the Phong exponent `ns`: `sqrt(sqrt(2 / (ns + 2)))`.
pub fn phong_roughness(ns: f32) -> f32 {
    let ns = if ns.is_finite() { ns.max(0.0) } else { 0.0 };
    (2.0 / (ns + 2.0)).sqrt().sqrt().clamp(0.0, 1.0)
}

/// The BSDF an MTL material stands for (rules in the module documentation).
pub fn mtl_bsdf(m: &MtlMaterial) -> Bsdf {
    let (kd, ks) = (unit(m.kd), unit(m.ks));
    if matches!(m.illum, 4 | 6 | 7) || m.d < 1.0 {
        let ior = if m.ni > 1.0 && m.ni.is_finite() {
            m.ni
        } else {
            DEFAULT_GLASS_IOR
        };
        Bsdf::Dielectric { ior }
    } else if matches!(m.illum, 3 | 5) {
        let color = if ks.max_element() > 0.0 {
            ks
        } else {
            Vec3::ONE
        };
        Bsdf::Mirror { color }
    } else if m.illum >= 2 && ks.max_element() > kd.max_element() {
        Bsdf::Conductor {
            color: ks,
            roughness: phong_roughness(m.ns),
            distribution: Distribution::Ggx,
        }
    } else {
        Bsdf::Diffuse { albedo: kd }
    }
}

/// An MTL material as a renderer material (texture from `textures`; problems go to `warnings`).
pub fn mtl_material(
    m: &MtlMaterial,
    textures: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Material {
    let bsdf = mtl_bsdf(m);
    let mut out = Material::new(bsdf).with_emission(emission(m.ke));
    if let Some(path) = &m.map_kd {
        if matches!(bsdf, Bsdf::Diffuse { .. } | Bsdf::Conductor { .. }) {
            out.textures.base_color = textures
                .file(path, Encoding::Srgb, warnings)
                .map(TextureMap::new);
        }
    }
    out
}

/// Non-negative finite emission.
fn emission(c: [f32; 3]) -> Vec3 {
    Vec3::from_array(c.map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 }))
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
