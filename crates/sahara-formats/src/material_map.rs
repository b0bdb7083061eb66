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
//! colour; the base colour texture multiplies the base colour. A material
//! with `KHR_materials_transmission` of at least 0.5 is glass instead: a
//! thin pane (`ThinDielectric`) when it has no `KHR_materials_volume`
//! thickness (glTF's thin-walled default), else a solid of the material's
//! index, rough when its roughness is. `emissive` is emitted (from both
//! faces when the material is double-sided), and a material that is not
//! double-sided is black from behind. `alphaMode` `MASK` (with
//! `alphaCutoff`) and `BLEND` cut the surface by the base colour's alpha
//! factor times the base colour texture's alpha channel (PNG). Metallic /
//! roughness textures, normal maps and occlusion are ignored.
//!
//! A texture that cannot be read is a warning and the material is
//! untextured. Each texture file is decoded once ([`TextureCache`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use sahara_render::{Bsdf, Material, Texture};

use crate::gltf::{GltfImage, GltfMaterial};
use crate::image_in::{decode_png_alpha, decode_rgb_f32, load_rgb_f32, RgbF32Image};
use crate::mtl::MtlMaterial;

/// IOR used for MTL glass that gives none (`Ni` <= 1).
pub const DEFAULT_GLASS_IOR: f32 = 1.5;

/// Decoded textures by file, so that a file used by many materials is read once.
#[derive(Debug, Default)]
pub struct TextureCache {
    files: HashMap<PathBuf, Option<Arc<Texture>>>,
}

impl TextureCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// The texture in `path`, decoded on first use; `None` (and a warning) if it cannot be read.
    pub fn file(&mut self, path: &Path, warnings: &mut Vec<String>) -> Option<Arc<Texture>> {
        if let Some(t) = self.files.get(path) {
            return t.clone();
        }
        let t = to_texture(load_rgb_f32(path), warnings);
        self.files.insert(path.to_path_buf(), t.clone());
        t
    }

    /// Number of distinct texture files decoded (or tried).
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// True if no texture was asked for.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }
}

/// A decoded image as a texture, or a warning.
fn to_texture(
    image: Result<RgbF32Image, crate::FormatError>,
    warnings: &mut Vec<String>,
) -> Option<Arc<Texture>> {
    match image {
        Ok((w, h, rgb)) if w > 0 && h > 0 && rgb.len() == w as usize * h as usize * 3 => {
            let texels = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
            Some(Arc::new(Texture::new(w, h, texels)))
        }
        Ok((w, h, _)) => {
            warnings.push(format!(
                "a {w}x{h} texture has no usable texels; the material is untextured"
            ));
            None
        }
        Err(e) => {
            warnings.push(format!("{e}; the material is untextured"));
            None
        }
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
            out.texture = textures.file(path, warnings);
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
            Bsdf::RoughDielectric { ior, roughness }
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

/// A glTF material as a renderer material; `name` (the glTF file) is used in warnings about embedded images.
pub fn gltf_material(
    m: &GltfMaterial,
    name: &str,
    textures: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Material {
    let mut out = Material::new(gltf_bsdf(m))
        .with_emission(emission(m.emissive))
        .with_two_sided(m.double_sided)
        .with_alpha(m.alpha_mode, m.base_color[3].clamp(0.0, 1.0));
    out.two_sided_emission = m.double_sided;
    if let Some(t) = &m.base_color_texture {
        if t.tex_coord != 0 {
            warnings.push(format!(
                "{name}: material '{}': base colour texture uses TEXCOORD_{}, which is not loaded; the material is untextured",
                m.name.as_deref().unwrap_or("(unnamed)"),
                t.tex_coord
            ));
        } else {
            out.texture = match &t.image {
                GltfImage::File(path) => textures.file(path, warnings),
                GltfImage::Embedded { bytes, .. } => to_texture(
                    decode_rgb_f32(bytes, &format!("{name} (embedded image)")),
                    warnings,
                ),
            };
            // Cut-outs and transparency read the texture's alpha channel.
            if out.has_holes() {
                let bytes = match &t.image {
                    GltfImage::File(path) => std::fs::read(path).ok(),
                    GltfImage::Embedded { bytes, .. } => Some(bytes.clone()),
                };
                let alpha = bytes.as_deref().and_then(decode_png_alpha);
                if let (Some(tex), Some(alpha)) = (&out.texture, alpha) {
                    if alpha.len() == tex.texels.len() {
                        out.texture = Some(Arc::new((**tex).clone().with_alpha(alpha)));
                    }
                }
            }
        }
    }
    out
}
