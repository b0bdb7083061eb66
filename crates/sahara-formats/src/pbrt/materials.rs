//! pbrt materials as Sahara materials: the one table that decides what
//! each pbrt-v4 and pbrt-v3 material becomes.
//!
//! | pbrt | Sahara | lost (warned) |
//! |---|---|---|
//! | `diffuse`, v3 `matte` | diffuse | v3 `sigma` (Oren-Nayar) |
//! | `conductor`, v3 `metal` | conductor of colour F0 from eta, k (or `reflectance`); mirror when smooth | complex Fresnel (Schlick from F0), anisotropy |
//! | `coatedconductor` | conductor (the base) | the coating |
//! | `dielectric`, v3 `glass` | glass / rough glass | dispersion, v3 `Kr`/`Kt` tints |
//! | `thindielectric` | glass | thinness (refracts as a solid) |
//! | v3 `mirror` | mirror | |
//! | `coateddiffuse`, v3 `plastic`, `substrate`, `uber` | diffuse (the base) | the coating / specular lobe |
//! | `diffusetransmission`, v3 `translucent` | diffuse (reflectance) | transmission |
//! | `mix` | the material with the larger weight | the blend |
//! | `measured`, `hair`, `subsurface`, v3 `kdsubsurface`, `fourier`, `disney` | diffuse | the model |
//! | `interface`, `""`, `none` | no surface (the shape is skipped) | |
//!
//! Roughness: Sahara's is perceptual (`alpha = roughness^2`). pbrt-v4 maps
//! `roughness` r to `alpha = sqrt(r)` with `remaproughness` (the default)
//! and `alpha = r` without; pbrt-v3 remaps with its polynomial in `ln r`.

use glam::Vec3;
use sahara_render::{Material, TextureMap};

use super::description::Entity;
use super::spectrum::{self, Use};
use super::textures::{Textures, Tint};
use super::warnings::Warnings;
use crate::error::FormatError;

/// What a pbrt material becomes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Mapped {
    /// A surface.
    Surface(Material),
    /// No surface: the shapes are not rendered (pbrt's `interface`).
    Interface,
    /// `mix`: the two named materials and the weight of the second.
    Mix([String; 2], f64),
}

/// pbrt-v3's roughness remapping (a polynomial in `ln r`), giving alpha.
fn v3_alpha(r: f64) -> f64 {
    let x = r.max(1e-3).ln();
    1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x.powi(3) + 0.000640711 * x.powi(4)
}

/// Sahara's perceptual roughness for a pbrt roughness.
fn sahara_roughness(r: f64, remap: bool, v3: bool) -> f32 {
    let alpha = match (remap, v3) {
        (false, _) => r,
        (true, false) => r.max(0.0).sqrt(),
        (true, true) => v3_alpha(r),
    };
    alpha.clamp(0.0, 1.0).sqrt() as f32
}

/// The roughness of `e` (`roughness`, or the mean of `uroughness` and
/// `vroughness`; different ones are a warning), with `prefix` for
/// `coatedconductor`'s `conductor.` parameters.
fn roughness(
    e: &Entity,
    prefix: &str,
    default: f64,
    v3: bool,
    tex: &mut Textures,
    w: &mut Warnings,
) -> Result<f32, FormatError> {
    let r = tex.float(e, &format!("{prefix}roughness"), default, w)?;
    let u = tex.float(e, &format!("{prefix}uroughness"), r, w)?;
    let v = tex.float(e, &format!("{prefix}vroughness"), r, w)?;
    if (u - v).abs() > 1e-6 {
        w.add(
            format!(
                "material '{}': anisotropic roughness replaced by the mean of u and v",
                e.kind
            ),
            &e.loc,
        );
    }
    let remap = e.params.bool("remaproughness", true)?;
    Ok(sahara_roughness(0.5 * (u + v), remap, v3))
}

/// A diffuse material of reflectance `tint`.
fn diffuse(tint: Tint) -> Material {
    let mut m = Material::diffuse(tint.color.clamp(Vec3::ZERO, Vec3::ONE));
    m.textures.base_color = tint.image.map(TextureMap::new);
    m
}

/// The conductor colour: `reflectance` if given, else F0 of `eta`, `k`
/// (default copper).
fn conductor_color(
    e: &Entity,
    prefix: &str,
    tex: &mut Textures,
    w: &mut Warnings,
) -> Result<Tint, FormatError> {
    let refl = format!("{prefix}reflectance");
    if e.params.has(&refl) || e.params.has("reflectance") {
        let name = if e.params.has(&refl) {
            refl
        } else {
            "reflectance".into()
        };
        return tex.spectrum(e, &name, Vec3::ONE, Use::Reflectance, w);
    }
    let cu_eta = match spectrum::named("metal-Cu-eta") {
        Some(spectrum::Named::Rgb(c)) => c,
        _ => unreachable!("copper is tabulated"),
    };
    let cu_k = match spectrum::named("metal-Cu-k") {
        Some(spectrum::Named::Rgb(c)) => c,
        _ => unreachable!("copper is tabulated"),
    };
    let v = |c: [f64; 3]| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
    let eta = tex.spectrum(e, &format!("{prefix}eta"), v(cu_eta), Use::Unbounded, w)?;
    let k = tex.spectrum(e, &format!("{prefix}k"), v(cu_k), Use::Unbounded, w)?;
    if eta.image.is_some() || k.image.is_some() {
        w.add("conductor eta / k textures replaced by their means", &e.loc);
    }
    let (eta, k) = (eta.mean(), k.mean());
    let f0 = Vec3::from_array(std::array::from_fn(|i| {
        spectrum::conductor_f0(f64::from(eta[i]), f64::from(k[i])) as f32
    }));
    Ok(Tint::constant(f0))
}

/// The index of refraction of a dielectric (`eta`, pbrt-v3 `index`; a
/// spectrum is taken at 532 nm, green).
fn ior(e: &Entity, tex: &mut Textures, w: &mut Warnings) -> Result<f32, FormatError> {
    let name = if e.params.has("index") {
        "index"
    } else {
        "eta"
    };
    let eta = match e.params.get(name).map(|p| p.ty) {
        Some("float") => e.params.float(name, 1.5)? as f32,
        Some(_) => {
            let t = tex.spectrum(e, name, Vec3::splat(1.5), Use::Unbounded, w)?;
            if (t.color.x - t.color.z).abs() > 1e-4 {
                w.add(
                    "dielectric: dispersion is lost (the index at 532 nm is used)",
                    &e.loc,
                );
            }
            t.mean().y
        }
        None => 1.5,
    };
    Ok(eta)
}

/// The one mapping from a pbrt material to Sahara's: see the module's table.
///
/// `e.kind` is the material type (for `MakeNamedMaterial`, the caller has
/// put its `"string type"` there). Approximations are counted in `w`,
/// one kind per material type.
pub(crate) fn map_material(
    e: &Entity,
    tex: &mut Textures,
    w: &mut Warnings,
) -> Result<Mapped, FormatError> {
    let approx = |w: &mut Warnings, what: &str| {
        w.add(format!("material '{}': {what}", e.kind), &e.loc);
    };
    for p in ["displacement", "normalmap", "bumpmap"] {
        if e.params.get(p).is_some() {
            w.add(
                format!("material parameter '{p}' is not supported; ignored"),
                &e.loc,
            );
        }
    }
    let grey = |v: f32| Vec3::splat(v);
    let m = match e.kind.as_str() {
        "diffuse" => diffuse(tex.spectrum(e, "reflectance", grey(0.5), Use::Reflectance, w)?),
        "matte" => {
            if tex.float(e, "sigma", 0.0, w)? != 0.0 {
                approx(w, "Oren-Nayar 'sigma' is not supported; Lambertian");
            }
            diffuse(tex.spectrum(e, "Kd", grey(0.5), Use::Reflectance, w)?)
        }
        "conductor" | "metal" | "coatedconductor" => {
            let v3 = e.kind == "metal";
            let prefix = if e.kind == "coatedconductor" {
                "conductor."
            } else {
                ""
            };
            let color = conductor_color(e, prefix, tex, w)?;
            let r = roughness(e, prefix, if v3 { 0.01 } else { 0.0 }, v3, tex, w)?;
            if e.kind == "coatedconductor" {
                approx(
                    w,
                    "the dielectric coating is left out (the conductor alone)",
                );
                for p in [
                    "interface.roughness",
                    "interface.uroughness",
                    "interface.vroughness",
                    "interface.eta",
                    "thickness",
                    "albedo",
                    "g",
                    "maxdepth",
                    "nsamples",
                ] {
                    e.params.get(p);
                }
            }
            approx(
                w,
                "complex Fresnel approximated by Schlick's from the normal reflectance",
            );
            let mut m = if r <= 1e-3 {
                Material::mirror(color.color)
            } else {
                Material::conductor(color.color, r)
            };
            m.textures.base_color = color.image.map(TextureMap::new);
            m
        }
        "dielectric" | "glass" | "thindielectric" => {
            let v3 = e.kind == "glass";
            let eta = ior(e, tex, w)?;
            if v3 {
                let kr = tex
                    .spectrum(e, "Kr", Vec3::ONE, Use::Reflectance, w)?
                    .mean();
                let kt = tex
                    .spectrum(e, "Kt", Vec3::ONE, Use::Reflectance, w)?
                    .mean();
                if kr != Vec3::ONE || kt != Vec3::ONE {
                    approx(w, "'Kr' / 'Kt' tints are not supported; clear glass");
                }
            }
            if e.kind == "thindielectric" {
                approx(w, "rendered as solid glass (refracting), not a thin sheet");
            }
            if (eta - 1.0).abs() < 1e-6 {
                // Index-matched: pbrt lets light pass straight through.
                return Ok(Mapped::Interface);
            }
            let r = if e.kind == "thindielectric" {
                0.0
            } else {
                roughness(e, "", 0.0, v3, tex, w)?
            };
            if r <= 1e-3 {
                Material::glass(eta)
            } else {
                Material::rough_glass(eta, r)
            }
        }
        "mirror" => {
            let kr = tex.spectrum(e, "Kr", grey(0.9), Use::Reflectance, w)?;
            let mut m = Material::mirror(kr.color);
            m.textures.base_color = kr.image.map(TextureMap::new);
            m
        }
        "coateddiffuse" | "plastic" | "substrate" | "uber" => {
            let name = if e.kind == "coateddiffuse" {
                "reflectance"
            } else {
                "Kd"
            };
            let default = match e.kind.as_str() {
                "plastic" | "uber" => 0.25,
                _ => 0.5,
            };
            let base = tex.spectrum(e, name, grey(default), Use::Reflectance, w)?;
            for p in [
                "roughness",
                "uroughness",
                "vroughness",
                "thickness",
                "eta",
                "albedo",
                "g",
                "maxdepth",
                "nsamples",
                "Ks",
                "Kr",
                "Kt",
                "opacity",
                "index",
                "remaproughness",
            ] {
                e.params.get(p);
            }
            approx(
                w,
                "the coating / specular layer is left out (the diffuse base alone)",
            );
            diffuse(base)
        }
        "diffusetransmission" | "translucent" => {
            let name = if e.kind == "translucent" {
                "Kd"
            } else {
                "reflectance"
            };
            let base = tex.spectrum(e, name, grey(0.25), Use::Reflectance, w)?;
            for p in [
                "transmittance",
                "Ks",
                "reflect",
                "transmit",
                "roughness",
                "remaproughness",
                "scale",
            ] {
                e.params.get(p);
            }
            approx(w, "transmission is left out (diffuse reflection alone)");
            diffuse(base)
        }
        "mix" => {
            let Some(names) = e.params.strings("materials")? else {
                return Err(e
                    .loc
                    .error("material 'mix' needs \"string materials\" [\"a\" \"b\"]"));
            };
            let [a, b] = names else {
                return Err(e.loc.error(format!(
                    "material 'mix': \"string materials\" must name 2 materials, not {}",
                    names.len()
                )));
            };
            let amount = tex.float(e, "amount", 0.5, w)?;
            approx(
                w,
                "the blend is replaced by the material with the larger weight",
            );
            return Ok(Mapped::Mix([a.clone(), b.clone()], amount));
        }
        "interface" | "" | "none" => return Ok(Mapped::Interface),
        "measured" | "hair" | "subsurface" | "kdsubsurface" | "fourier" | "disney" => {
            let name = if e.params.has("reflectance") {
                "reflectance"
            } else {
                "Kd"
            };
            let base = tex.spectrum(e, name, grey(0.5), Use::Reflectance, w)?;
            e.params.mark_all_used();
            approx(w, "not supported; replaced by a diffuse material");
            diffuse(base)
        }
        other => {
            w.add(
                format!("unknown material type '{other}'; replaced by diffuse grey 0.5"),
                &e.loc,
            );
            e.params.mark_all_used();
            diffuse(Tint::constant(grey(0.5)))
        }
    };
    Ok(Mapped::Surface(m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_remapping_follows_each_version() {
        // pbrt-v4: alpha = sqrt(r) when remapped; Sahara's roughness is sqrt(alpha).
        assert!((sahara_roughness(0.0625, true, false) - 0.5).abs() < 1e-6);
        assert!((sahara_roughness(0.25, false, false) - 0.5).abs() < 1e-6);
        // pbrt-v3 at r = 1: alpha = 1.62142.. clamps to 1.
        assert_eq!(sahara_roughness(1.0, true, true), 1.0);
        assert!(sahara_roughness(0.01, true, true) < sahara_roughness(0.1, true, true));
    }
}
