//! MTL materials (OBJ files' own) as renderer [`Material`]s. The renderer
//! has one BSDF per material, so a file material becomes the BSDF its
//! parameters say it mostly is.
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

use glam::Vec3;
use sahara_readers::mtl::MtlMaterial;
use sahara_render::{Bsdf, Distribution, Encoding, Material, TextureMap};

use crate::common::materials::{emission, unit, TextureCache};

/// IOR used for MTL glass that gives none (`Ni` <= 1).
pub const DEFAULT_GLASS_IOR: f32 = 1.5;

/// GGX perceptual roughness matching the Phong exponent `ns`: `sqrt(sqrt(2 / (ns + 2)))`.
pub fn phong_roughness(ns: f32) -> f32 {
    let ns = if ns.is_finite() { ns.max(0.0) } else { 0.0 };
    (2.0 / (ns + 2.0)).sqrt().sqrt().clamp(0.0, 1.0)
}

/// The BSDF an MTL material stands for (rules in the module documentation).
pub fn mtl_bsdf(m: &MtlMaterial) -> Bsdf {
    mtl_kind(m).0
}

/// The BSDF an MTL material stands for, and whether its `map_Kd` applies
/// (to a diffuse or glossy colour; not to glass or a mirror).
fn mtl_kind(m: &MtlMaterial) -> (Bsdf, bool) {
    let (kd, ks) = (unit(m.kd), unit(m.ks));
    if matches!(m.illum, 4 | 6 | 7) || m.d < 1.0 {
        let ior = if m.ni > 1.0 && m.ni.is_finite() {
            m.ni
        } else {
            DEFAULT_GLASS_IOR
        };
        (Bsdf::Dielectric { ior }, false)
    } else if matches!(m.illum, 3 | 5) {
        let color = if ks.max_element() > 0.0 {
            ks
        } else {
            Vec3::ONE
        };
        (Bsdf::Mirror { color }, false)
    } else if m.illum >= 2 && ks.max_element() > kd.max_element() {
        let bsdf = Bsdf::Conductor {
            color: ks,
            roughness: phong_roughness(m.ns),
            distribution: Distribution::Ggx,
        };
        (bsdf, true)
    } else {
        (Bsdf::Diffuse { albedo: kd }, true)
    }
}

/// An MTL material as a renderer material (texture from `textures`; problems go to `warnings`).
pub fn mtl_material(
    m: &MtlMaterial,
    textures: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Material {
    let (bsdf, textured) = mtl_kind(m);
    let mut out = Material::new(bsdf).with_emission(emission(m.ke));
    if let (Some(path), true) = (&m.map_kd, textured) {
        out.textures.base_color = textures
            .file(path, Encoding::Srgb, warnings)
            .map(TextureMap::new);
    }
    out
}
