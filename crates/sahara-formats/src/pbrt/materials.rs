//! pbrt materials as Sahara materials: the one table that decides what
//! each pbrt-v4 and pbrt-v3 material becomes.
//!
//! | pbrt | Sahara | lost (warned) |
//! |---|---|---|
//! | `diffuse`, v3 `matte` | diffuse | v3 `sigma` (Oren-Nayar) |
//! | `conductor`, v3 `metal` (`eta`, `k`) | complex-IOR conductor, exact Fresnel | anisotropy; textured `eta` / `k` (their means) |
//! | `conductor` with `reflectance` | complex-IOR conductor of `eta = 1`, `k = 2 sqrt(r / (1 - r))` (pbrt-v4's own conversion) | for a textured reflectance: Schlick's Fresnel from it |
//! | `coatedconductor` | the conductor with `eta / eta_coat`, `k / eta_coat` (as pbrt-v4 sees it through the coat) | the coat's own reflection |
//! | `coateddiffuse` | coated diffuse | an absorbing coat (`albedo`, `thickness`, `g`) |
//! | `dielectric`, v3 `glass` | glass / rough glass | dispersion, v3 `Kr`/`Kt` tints |
//! | `thindielectric` | thin dielectric | |
//! | v3 `mirror` | a smooth conductor reflecting `Kr` at every angle | |
//! | v3 `plastic`, `uber` | glTF-style specular layer (`Ks`, index 1.5) over a diffuse base (`Kd`) | the base loses what the layer reflects; `uber`'s `Kr`, `Kt` |
//! | v3 `substrate` | the same, the layer's normal reflectance `Ks` | Ashikhmin-Shirley's coupling |
//! | `diffusetransmission`, v3 `translucent` | diffuse (or layered) reflection | transmission |
//! | `mix` | the blend when exact (two diffuse colours, or the same material), else the material of larger weight | the blend |
//! | `subsurface` | a dielectric boundary around a homogeneous medium (`media.rs`); diffuse inside a `mix` | the `reflectance` form |
//! | `measured`, `hair`, v3 `kdsubsurface`, `fourier`, `disney` | diffuse | the model |
//! | `interface`, `""`, `none` | no surface (the shape is skipped) | |
//!
//! Roughness: Sahara's is perceptual (`alpha = roughness^2`). pbrt-v4 maps
//! `roughness` r to `alpha = sqrt(r)` with `remaproughness` (the default)
//! and `alpha = r` without; pbrt-v3 remaps with its polynomial in `ln r`.
//! pbrt-v3's `opacity` (uber) becomes stochastic transparency.

use glam::Vec3;
use sahara_readers::FormatError;
use sahara_render::{
    isotropic_mean, roughness_from_alpha, AlphaMode, Bsdf, Distribution, Material,
};

use super::declarations::Entity;
use super::params::SpectrumParam;
use super::textures::{rgb_of, spectral_samples, Textures};
use crate::common::spectrum::{self, Use};
use crate::common::tint::Tint;
use crate::common::warnings::Warnings;

/// pbrt's one microfacet distribution, Trowbridge-Reitz (GGX).
const TROWBRIDGE_REITZ: Distribution = Distribution::Ggx;

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
    roughness_from_alpha(alpha)
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
    let (mean, anisotropic) = isotropic_mean(u, v);
    if anisotropic {
        w.add(
            format!(
                "material '{}': anisotropic roughness replaced by the mean of u and v",
                e.kind
            ),
            &e.loc,
        );
    }
    let remap = e.params.bool("remaproughness", true)?;
    Ok(sahara_roughness(mean, remap, v3))
}

/// The material of shapes declared before any `Material` directive:
/// pbrt-v4's default, diffuse of reflectance 0.5.
pub(crate) fn default_material() -> Material {
    Material::diffuse(Vec3::splat(0.5))
}

/// pbrt's dielectric of index `eta` and Sahara roughness `roughness`
/// (a material's, or a `subsurface` boundary's): smooth glass at most
/// 1e-3, rough glass above.
pub(super) fn glass(eta: f32, roughness: f32) -> Material {
    if roughness <= 1e-3 {
        Material::glass(eta)
    } else {
        Material::rough_glass(eta, roughness)
    }
}

/// A diffuse material of reflectance `tint`.
fn diffuse(tint: Tint) -> Material {
    let mut m = Material::diffuse(tint.color.clamp(Vec3::ZERO, Vec3::ONE));
    m.textures.base_color = tint.image_map();
    m
}

/// A material of `bsdf` whose base colour is multiplied by `tint`.
fn tinted(bsdf: Bsdf, tint: &Tint) -> Material {
    let mut m = Material::new(bsdf);
    m.textures.base_color = tint.map();
    m
}

/// Copper: pbrt's default conductor.
fn copper() -> (Vec3, Vec3) {
    let part = |p: &str| match spectrum::named(&format!("metal-Cu-{p}")) {
        Some(spectrum::Named::Rgb(c)) => v3(c),
        _ => unreachable!("copper is tabulated"),
    };
    (part("eta"), part("k"))
}

fn v3(c: [f64; 3]) -> Vec3 {
    Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)
}

/// What a conductor's colour is given as.
enum Metal {
    /// Complex index per channel.
    Index(Vec3, Vec3),
    /// A textured reflectance (Schlick's Fresnel from it).
    Reflectance(Tint),
}

/// `eta` and `k` for a normal reflectance `r` (pbrt-v4's conversion of a
/// conductor's `reflectance`: `eta = 1`, whose normal reflectance is
/// `k^2 / (4 + k^2)`).
fn k_of_reflectance(r: Vec3) -> Vec3 {
    let r = r.clamp(Vec3::ZERO, Vec3::splat(0.9999));
    2.0 * (r / (Vec3::ONE - r)).powf(0.5)
}

/// The colour of a conductor (`prefix` is `conductor.` in a
/// `coatedconductor`): `reflectance` if given, else `eta` and `k`
/// (default copper). Two spectra are fitted together
/// ([`spectrum::fit_conductor`]); a texture gives its mean.
fn conductor_metal(
    e: &Entity,
    prefix: &str,
    tex: &mut Textures,
    w: &mut Warnings,
) -> Result<Metal, FormatError> {
    let refl = format!("{prefix}reflectance");
    if e.params.has(&refl) {
        let r = tex.spectrum(e, &refl, Vec3::ONE, Use::Reflectance, w)?;
        return Ok(match r.image {
            None => Metal::Index(Vec3::ONE, k_of_reflectance(r.color)),
            Some(_) => {
                w.add(
                    format!(
                        "material '{}': a textured 'reflectance' uses Schlick's Fresnel from it",
                        e.kind
                    ),
                    &e.loc,
                );
                Metal::Reflectance(r)
            }
        });
    }
    let (eta_name, k_name) = (format!("{prefix}eta"), format!("{prefix}k"));
    let (pe, pk) = (
        e.params.spectrum(&eta_name, true)?,
        e.params.spectrum(&k_name, true)?,
    );
    if let (Some(se), Some(sk)) = (&pe, &pk) {
        if let (Some(a), Some(b)) = (
            spectral_samples(se, &e.folders),
            spectral_samples(sk, &e.folders),
        ) {
            let (fe, fk) = spectrum::fit_conductor(
                |l| spectrum::piecewise_linear(&a, l),
                |l| spectrum::piecewise_linear(&b, l),
            );
            return Ok(Metal::Index(v3(fe), v3(fk)));
        }
    }
    let (cu_eta, cu_k) = copper();
    let mut part = |p: &Option<SpectrumParam>, name: &str, default: Vec3| match p {
        None => Ok(default),
        Some(SpectrumParam::Texture(_)) => {
            let t = tex.spectrum(e, name, default, Use::Unbounded, w)?;
            w.add(
                format!(
                    "material '{}': textured 'eta' / 'k' replaced by their means",
                    e.kind
                ),
                &e.loc,
            );
            Ok(t.mean())
        }
        Some(p) => rgb_of(p, Use::Unbounded, &e.folders, w),
    };
    let eta = part(&pe, &eta_name, cu_eta)?;
    let k = part(&pk, &k_name, cu_k)?;
    Ok(Metal::Index(eta, k))
}

/// A conductor of colour `metal` and `roughness`.
fn conductor(metal: Metal, roughness: f32) -> Material {
    match metal {
        // pbrt-v4's conductor scatters once between microfacets.
        Metal::Index(eta, k) => Material::new(Bsdf::ComplexConductor {
            eta: eta.max(Vec3::ZERO),
            k: k.max(Vec3::ZERO),
            roughness,
            distribution: TROWBRIDGE_REITZ,
            multiple_scattering: false,
        }),
        Metal::Reflectance(r) => tinted(
            Bsdf::Conductor {
                color: Vec3::ONE,
                roughness,
                distribution: TROWBRIDGE_REITZ,
            },
            &r,
        ),
    }
}

/// The index of refraction of a dielectric (`eta`, pbrt-v3 `index`): a
/// spectrum is taken at the d line (a named glass is its `n_d`).
fn ior(
    e: &Entity,
    names: &[&str],
    tex: &mut Textures,
    w: &mut Warnings,
) -> Result<f32, FormatError> {
    let Some(name) = names.iter().copied().find(|n| e.params.has(n)) else {
        return Ok(1.5);
    };
    if e.params.get(name).map(|p| p.ty) == Some("float") {
        return Ok(e.params.float(name, 1.5)? as f32);
    }
    let p = e.params.spectrum(name, true)?.expect("present");
    let eta = match &p {
        SpectrumParam::Texture(_) => {
            tex.spectrum(e, name, Vec3::splat(1.5), Use::Unbounded, w)?
                .mean()
                .y
        }
        other => match spectral_samples(other, &e.folders) {
            Some(s) => spectrum::piecewise_linear(&s, spectrum::D_LINE) as f32,
            None => rgb_of(other, Use::Unbounded, &e.folders, w)?.y,
        },
    };
    let dispersive = match &p {
        SpectrumParam::Named(n, _) => n.starts_with("glass-"),
        SpectrumParam::Sampled(s) => s.windows(2).any(|p| p[0].1 != p[1].1),
        _ => false,
    };
    if dispersive {
        w.add(
            format!(
                "material '{}': dispersion is lost (the index n_d at 587.56 nm is used)",
                e.kind
            ),
            &e.loc,
        );
    }
    Ok(eta)
}

/// The glTF-style layered reflector Sahara gives pbrt-v3's `plastic`,
/// `uber`, `substrate` and `translucent`: a specular layer of roughness `r`
/// whose reflectance at normal incidence is `f0` (grazing: `f90`, grey)
/// over a diffuse base `kd`.
fn layered(kd: &Tint, f0: Vec3, f90: f32, r: f32) -> Material {
    // glTF's dielectric layer: f0 = min(0.04 specular_color, 1) specular,
    // f90 = specular (index 1.5).
    let specular = f90.max(0.0);
    let specular_color = if specular > 0.0 {
        f0 / (0.04 * specular)
    } else {
        Vec3::ZERO
    };
    tinted(
        Bsdf::MetallicRoughness {
            base_color: kd.color.clamp(Vec3::ZERO, Vec3::ONE),
            metallic: 0.0,
            roughness: r,
            ior: 1.5,
            specular,
            specular_color,
        },
        &Tint {
            color: Vec3::ONE,
            ..kd.clone()
        },
    )
}

/// The one mapping from a pbrt material to Sahara's: see the module's table.
///
/// `e.kind` is the material type (for `MakeNamedMaterial`, the caller has
/// put its `"string type"` there). Approximations are counted in `w`,
/// one kind per material type.
///
/// One piece on purpose: it is pbrt's one mapping of its materials onto
/// Sahara's material kinds, an arm per pbrt type, read as a table;
/// a new kind is an arm here.
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
    // A texture's mean for a colour that Sahara holds as a constant.
    let constant = |tex: &mut Textures, w: &mut Warnings, name: &str, default: f32| {
        let t = tex.spectrum(e, name, grey(default), Use::Reflectance, w)?;
        if t.image.is_some() {
            w.add(
                format!(
                    "material '{}': a textured '{name}' is replaced by its mean",
                    e.kind
                ),
                &e.loc,
            );
        }
        Ok::<_, FormatError>(t.mean())
    };
    let m = match e.kind.as_str() {
        "diffuse" => diffuse(tex.spectrum(e, "reflectance", grey(0.5), Use::Reflectance, w)?),
        "matte" => {
            if tex.float(e, "sigma", 0.0, w)? != 0.0 {
                approx(w, "Oren-Nayar 'sigma' is not supported; Lambertian");
            }
            diffuse(tex.spectrum(e, "Kd", grey(0.5), Use::Reflectance, w)?)
        }
        "conductor" | "metal" => {
            let v3 = e.kind == "metal";
            let metal = conductor_metal(e, "", tex, w)?;
            let r = roughness(e, "", if v3 { 0.01 } else { 0.0 }, v3, tex, w)?;
            conductor(metal, r)
        }
        "coatedconductor" => {
            let metal = conductor_metal(e, "conductor.", tex, w)?;
            let r = roughness(e, "conductor.", 0.0, false, tex, w)?;
            let coat = ior(e, &["interface.eta"], tex, w)?.max(1e-3);
            roughness(e, "interface.", 0.0, false, tex, w)?;
            for p in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                e.params.get(p);
            }
            approx(
                w,
                "the coat's own reflection is left out (the conductor as seen through the coat)",
            );
            conductor(
                match metal {
                    Metal::Index(eta, k) => Metal::Index(eta / coat, k / coat),
                    other => other,
                },
                r,
            )
        }
        "dielectric" | "glass" | "thindielectric" => {
            let v3 = e.kind == "glass";
            let eta = ior(e, &["index", "eta"], tex, w)?;
            if v3 {
                let kr = constant(tex, w, "Kr", 1.0)?;
                let kt = constant(tex, w, "Kt", 1.0)?;
                if kr != Vec3::ONE || kt != Vec3::ONE {
                    approx(w, "'Kr' / 'Kt' tints are not supported; clear glass");
                }
            }
            if (eta - 1.0).abs() < 1e-6 {
                // Index-matched: pbrt lets light pass straight through.
                return Ok(Mapped::Interface);
            }
            if e.kind == "thindielectric" {
                Material::new(Bsdf::ThinDielectric { ior: eta })
            } else {
                glass(eta, roughness(e, "", 0.0, v3, tex, w)?)
            }
        }
        "mirror" => {
            // pbrt-v3's mirror reflects Kr at every angle: a conductor whose
            // Fresnel term is 1 (eta = 1, k large), tinted by Kr.
            let kr = tex.spectrum(e, "Kr", grey(0.9), Use::Reflectance, w)?;
            tinted(
                Bsdf::ComplexConductor {
                    eta: Vec3::ONE,
                    k: Vec3::splat(1e4),
                    roughness: 0.0,
                    distribution: TROWBRIDGE_REITZ,
                    multiple_scattering: false,
                },
                &kr,
            )
        }
        "coateddiffuse" => {
            let base = tex.spectrum(e, "reflectance", grey(0.5), Use::Reflectance, w)?;
            let r = roughness(e, "", 0.0, false, tex, w)?;
            let eta = ior(e, &["eta"], tex, w)?;
            let albedo = constant(tex, w, "albedo", 0.0)?;
            tex.float(e, "thickness", 0.01, w)?;
            tex.float(e, "g", 0.0, w)?;
            for p in ["maxdepth", "nsamples"] {
                e.params.get(p);
            }
            if albedo != Vec3::ZERO {
                approx(
                    w,
                    "a scattering coat ('albedo') is not supported; a clear coat",
                );
            }
            tinted(
                Bsdf::CoatedDiffuse {
                    albedo: base.color.clamp(Vec3::ZERO, Vec3::ONE),
                    ior: eta.max(1.0),
                    roughness: r,
                    distribution: TROWBRIDGE_REITZ,
                },
                &Tint {
                    color: Vec3::ONE,
                    ..base
                },
            )
        }
        "plastic" | "uber" => {
            let kd = tex.spectrum(e, "Kd", grey(0.25), Use::Reflectance, w)?;
            let ks = constant(tex, w, "Ks", 0.25)?;
            let r = roughness(e, "", 0.1, true, tex, w)?;
            let eta = if e.kind == "uber" {
                ior(e, &["index", "eta"], tex, w)?
            } else {
                1.5
            };
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            let f90 = ks.max_element();
            let mut m = layered(&kd, ks * r0, f90, r);
            approx(
                w,
                "the diffuse base loses the light the specular layer reflects (an energy-conserving layering)",
            );
            if e.kind == "uber" {
                let kr = constant(tex, w, "Kr", 0.0)?;
                let kt = constant(tex, w, "Kt", 0.0)?;
                if kr != Vec3::ZERO || kt != Vec3::ZERO {
                    approx(
                        w,
                        "its specular reflection 'Kr' and transmission 'Kt' are left out",
                    );
                }
                let opacity = constant(tex, w, "opacity", 1.0)?;
                let a = opacity.min_element().clamp(0.0, 1.0);
                if a < 1.0 {
                    m = m.with_alpha(AlphaMode::Blend, a);
                }
            }
            m
        }
        "substrate" => {
            let kd = tex.spectrum(e, "Kd", grey(0.5), Use::Reflectance, w)?;
            let ks = constant(tex, w, "Ks", 0.5)?;
            let r = roughness(e, "", 0.1, true, tex, w)?;
            approx(
                w,
                "Ashikhmin-Shirley's coupling of the layers is replaced by an energy-conserving layering",
            );
            layered(&kd, ks, 1.0, r)
        }
        "diffusetransmission" => {
            let base = tex.spectrum(e, "reflectance", grey(0.25), Use::Reflectance, w)?;
            let t = constant(tex, w, "transmittance", 0.25)?;
            let scale = tex.float(e, "scale", 1.0, w)? as f32;
            if t != Vec3::ZERO {
                approx(w, "transmission is left out (diffuse reflection alone)");
            }
            diffuse(Tint {
                color: base.color * scale,
                ..base
            })
        }
        "translucent" => {
            let kd = tex.spectrum(e, "Kd", grey(0.25), Use::Reflectance, w)?;
            let ks = constant(tex, w, "Ks", 0.25)?;
            let reflect = constant(tex, w, "reflect", 0.5)?;
            let transmit = constant(tex, w, "transmit", 0.5)?;
            let r = roughness(e, "", 0.1, true, tex, w)?;
            if transmit != Vec3::ZERO {
                approx(w, "transmission is left out (reflection alone)");
            }
            let kd = Tint {
                color: kd.color * reflect,
                ..kd
            };
            let ks = ks * reflect;
            layered(&kd, ks * 0.04, ks.max_element(), r)
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

    /// The material of the one sphere of a scene made of `decl`, and the
    /// warnings.
    fn material_of(decl: &str) -> (Material, Vec<String>) {
        let text = format!("{decl}\nShape \"sphere\"\n");
        let s = crate::parse_pbrt(
            text.as_bytes(),
            "m.pbrt",
            std::path::Path::new("/nonexistent"),
        )
        .unwrap_or_else(|e| panic!("{decl}: {e}"));
        let scene = &s.scene;
        let id = scene.instances[0].material.expect("a material") as usize;
        (scene.materials[id].clone(), s.warnings)
    }

    /// Reflectance (mean sample weight) from `cos` to the normal, seen by
    /// a smooth (delta) BSDF.
    fn delta_reflectance(m: &Material, cos: f32) -> Vec3 {
        let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        let uv = glam::Vec2::splat(0.5);
        let tint = m
            .at(&[uv, uv], &sahara_render::UvFootprint::POINT)
            .bsdf
            .tint;
        let s = m
            .bsdf
            .sample(tint, wo, 0.0, glam::Vec2::splat(0.5))
            .expect("a sample");
        assert!(s.delta);
        s.weight
    }

    #[test]
    fn a_conductor_of_given_reflectance_has_it_at_normal_incidence() {
        let (m, w) = material_of("Material \"conductor\" \"rgb reflectance\" [0.9 0.5 0.1]");
        assert!(w.is_empty(), "{w:?}");
        let Bsdf::ComplexConductor {
            eta,
            k,
            roughness,
            multiple_scattering: false,
            ..
        } = m.bsdf
        else {
            panic!("{:?}", m.bsdf)
        };
        assert_eq!((eta, roughness), (Vec3::ONE, 0.0));
        let f0 = sahara_render::fresnel::conductor(1.0, eta, k);
        assert!(
            (f0 - Vec3::new(0.9, 0.5, 0.1)).abs().max_element() < 1e-5,
            "{f0}"
        );
        // Brighter at grazing angles, as every conductor.
        assert!(delta_reflectance(&m, 0.1).min_element() > 0.3);
    }

    #[test]
    fn the_v4_layered_and_thin_materials_are_sahara_s() {
        let (m, w) = material_of(
            "Material \"coateddiffuse\" \"rgb reflectance\" [0.6 0.3 0.2] \"float roughness\" 0.0625 \"float eta\" 1.4",
        );
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(
            m.bsdf,
            Bsdf::CoatedDiffuse {
                albedo: Vec3::new(0.6, 0.3, 0.2),
                ior: 1.4,
                roughness: 0.5,
                distribution: TROWBRIDGE_REITZ,
            }
        );
        let (m, _) = material_of("Material \"thindielectric\" \"float eta\" 1.33");
        assert_eq!(m.bsdf, Bsdf::ThinDielectric { ior: 1.33 });
        let (m, w) = material_of(
            "Material \"coatedconductor\" \"float interface.eta\" 2 \"rgb conductor.eta\" [0.4 0.6 0.8] \"rgb conductor.k\" [4 3 2]",
        );
        assert_eq!(
            m.bsdf,
            Bsdf::ComplexConductor {
                eta: Vec3::new(0.2, 0.3, 0.4),
                k: Vec3::new(2.0, 1.5, 1.0),
                roughness: 0.0,
                distribution: TROWBRIDGE_REITZ,
                multiple_scattering: false,
            }
        );
        assert!(
            w.iter()
                .any(|l| l.contains("the coat's own reflection is left out")),
            "{w:?}"
        );
    }

    #[test]
    fn the_v3_mirror_reflects_kr_at_every_angle() {
        let (m, w) = material_of("Material \"mirror\" \"rgb Kr\" [0.8 0.5 0.25]");
        assert!(w.is_empty(), "{w:?}");
        for cos in [1.0, 0.5, 0.05] {
            let r = delta_reflectance(&m, cos);
            assert!(
                (r - Vec3::new(0.8, 0.5, 0.25)).abs().max_element() < 1e-4,
                "cos {cos}: {r}"
            );
        }
    }

    #[test]
    fn the_v3_plastics_are_a_specular_layer_over_their_kd() {
        let (m, w) = material_of("Material \"plastic\" \"rgb Kd\" [0.5 0.4 0.3] \"rgb Ks\" [0.5 0.5 0.5] \"float roughness\" 0.1");
        let Bsdf::MetallicRoughness {
            base_color,
            metallic,
            ior,
            specular,
            specular_color,
            ..
        } = m.bsdf
        else {
            panic!("{:?}", m.bsdf)
        };
        assert_eq!(
            (base_color, metallic, ior),
            (Vec3::new(0.5, 0.4, 0.3), 0.0, 1.5)
        );
        // Normal reflectance 0.04 Ks, grazing Ks.
        assert_eq!(specular, 0.5);
        assert!(
            (specular_color * 0.04 * specular - Vec3::splat(0.02))
                .abs()
                .max_element()
                < 1e-7
        );
        assert!(w
            .iter()
            .any(|l| l.contains("material 'plastic': the diffuse base loses")));
        // substrate: the layer's normal reflectance is Ks.
        let (m, _) = material_of("Material \"substrate\" \"rgb Ks\" [0.1 0.2 0.3]");
        let Bsdf::MetallicRoughness {
            specular,
            specular_color,
            ..
        } = m.bsdf
        else {
            panic!()
        };
        assert_eq!(specular, 1.0);
        assert!(
            (specular_color * 0.04 - Vec3::new(0.1, 0.2, 0.3))
                .abs()
                .max_element()
                < 1e-7
        );
        // uber's opacity is stochastic transparency.
        let (m, _) = material_of("Material \"uber\" \"rgb opacity\" [0.25 0.25 0.25]");
        assert_eq!((m.alpha_mode, m.alpha), (AlphaMode::Blend, 0.25));
    }

    #[test]
    fn a_mix_of_diffuse_colours_is_their_blend_else_the_heavier_material() {
        let named = "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"rgb reflectance\" [1 0 0]\n\
                     MakeNamedMaterial \"b\" \"string type\" \"diffuse\" \"rgb reflectance\" [0 0 1]\n\
                     MakeNamedMaterial \"c\" \"string type\" \"dielectric\"\n";
        let (m, w) = material_of(&format!(
            "{named}MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"a\" \"b\"] \"float amount\" 0.25\nNamedMaterial \"m\""
        ));
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(
            m.bsdf,
            Bsdf::Diffuse {
                albedo: Vec3::new(0.75, 0.0, 0.25)
            }
        );
        let (m, w) = material_of(&format!(
            "{named}MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"a\" \"c\"] \"float amount\" 0.75\nNamedMaterial \"m\""
        ));
        assert_eq!(m.bsdf, Bsdf::Dielectric { ior: 1.5 });
        assert!(w
            .iter()
            .any(|l| l.contains("the blend is replaced by the material with the larger weight")));
    }
}
