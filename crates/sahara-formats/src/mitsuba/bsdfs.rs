//! Mitsuba bsdfs as Sahara materials: the one table that decides what
//! each becomes.
//!
//! | Mitsuba | Sahara | lost (warned) |
//! |---|---|---|
//! | `diffuse` | diffuse | |
//! | `conductor`, `roughconductor` (`material`: every preset Mitsuba ships, see [`super::metals`]; `eta`, `k`, `specular_reflectance`; `distribution` `beckmann` (the default) or `ggx`) | complex-IOR conductor, scattering once between microfacets as Mitsuba's does, tinted by `specular_reflectance` | anisotropy (the mean alpha), textured `eta` / `k` |
//! | `dielectric`, `roughdielectric` (`int_ior`, `ext_ior`, `distribution`) | glass / rough glass of index `int_ior / ext_ior` | tinted `specular_reflectance` / `specular_transmittance` |
//! | `thindielectric` | thin dielectric | |
//! | `plastic`, `roughplastic` (`distribution`) | coated diffuse: a dielectric coat of index `int_ior / ext_ior` over a base whose albedo gives Mitsuba's diffuse light (`nonlinear` false: `diffuse_reflectance / (1 - F_i)`; true: as given) | a `specular_reflectance` other than 1; a textured base read as `nonlinear` |
//! | `principled` | glTF metallic-roughness (`base_color`, `metallic`, `roughness`, `eta`), with a clear coat (`clearcoat`, `clearcoat_gloss`) | `anisotropic`, `sheen`, `spec_trans`, `spec_tint`, `flatness` |
//! | `twosided` | the nested bsdf, scattering on both faces | a different back bsdf (the front one is used) |
//! | `mask` (`opacity`) | the nested bsdf, cut by stochastic transparency | |
//! | `blendbsdf` (`weight`) | the blend where exact (two diffuse colours, or the same bsdf), else the bsdf of larger weight | the blend |
//! | `normalmap` | the nested bsdf with the normal map | |
//! | `bumpmap` (`scale`) | the nested bsdf with a normal map baked from the heights' slopes (strength: see `build::scale_bumps`) | the strength where the length a unit of uv spans varies |
//! | `null` | no surface (the shape is skipped) | |
//! | `hair`, `measured`, `measured_polarized`, `pplastic`, `polarizer`, `retarder`, `circular` | diffuse grey 0.5 | the model |
//!
//! Mitsuba's bsdfs are one-sided: a surface seen from its back is black,
//! and so it is here, unless wrapped in `twosided` (glass has two sides
//! by nature). Roughness: Mitsuba's `alpha` is the distribution's alpha
//! (GGX's or Beckmann's), Sahara's roughness its square root.

use glam::Vec3;
use std::sync::Arc;

use sahara_readers::FormatError;
use sahara_render::{
    isotropic_mean, roughness_from_alpha, AlphaMode, Bsdf, Clearcoat, Distribution, Material,
    NormalMap, Texture, TextureMap,
};

use super::builder::{key, Builder};
use super::properties::Object;
use super::spectra::{conductor_rgb, Color, Usage};
use super::xml::Node;
use crate::common::tint::{with_opacity, Tint};

/// Deepest chain of bsdfs nested in bsdfs.
const MAX_NESTING: usize = 16;

/// Mitsuba's named indices of refraction (its `dielectric` docs' table).
const IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.00004),
    ("hydrogen", 1.00013),
    ("air", 1.00028),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// Types Sahara has no model for (replaced by diffuse grey, warned).
const UNSUPPORTED: &[&str] = &[
    "hair",
    "measured",
    "measured_polarized",
    "pplastic",
    "polarizer",
    "retarder",
    "circular",
];

/// A diffuse material of reflectance `tint`.
fn diffuse(tint: &Tint) -> Material {
    let mut m = Material::diffuse(tint.color.clamp(Vec3::ZERO, Vec3::ONE));
    m.textures.base_color = tint.image_map();
    m
}

/// A material of `bsdf` whose colour is multiplied by `tint` (white: none).
fn tinted(bsdf: Bsdf, tint: &Tint) -> Material {
    let mut m = Material::new(bsdf);
    m.textures.base_color = tint.map();
    m
}

/// The tangent-space normal map of the height image `h` (texel rows
/// along Mitsuba's `v`) times `scale`: the normal of the surface lifted by
/// the height, `(-dh/du, -dh/dv, 1)`, with its slopes per unit of uv
/// (central differences, wrapping), encoded as `(n + 1) / 2`.
fn bump_normals(h: &Texture, scale: f32) -> Texture {
    let (w, ht) = (i64::from(h.width), i64::from(h.height));
    let at = |x: i64, y: i64| {
        let t = h.texel(x.rem_euclid(w), y.rem_euclid(ht));
        (t.x + t.y + t.z) / 3.0
    };
    let mut texels = Vec::with_capacity((w * ht) as usize);
    for y in 0..ht {
        for x in 0..w {
            let du = (at(x + 1, y) - at(x - 1, y)) * 0.5 * w as f32 * scale;
            let dv = (at(x, y + 1) - at(x, y - 1)) * 0.5 * ht as f32 * scale;
            let n = Vec3::new(-du, -dv, 1.0).normalize();
            texels.push((n + Vec3::ONE) * 0.5);
        }
    }
    Texture::new(h.width, h.height, texels)
}

/// Mitsuba's diffuse Fresnel reflectance of an interface of relative
/// index `eta` (Egan and Hilgeman's fit below 1, d'Eon and Irving's above).
fn diffuse_fresnel(eta: f32) -> f32 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let i = 1.0 / eta;
        0.919317 - 3.4793 * i + 6.75335 * i.powi(2) - 7.80989 * i.powi(3) + 4.98554 * i.powi(4)
            - 1.36881 * i.powi(5)
    }
}

/// The base albedo of Sahara's coated diffuse (whose base scatters the
/// light the coat reflects back down again, Mitsuba's `nonlinear` plastic)
/// that gives the diffuse light of Mitsuba's default, linear plastic of
/// diffuse reflectance `rho`: `rho / (1 - F_i)` where Sahara has
/// `a / (1 - a F_i)`, `F_i` the coat's internal diffuse reflectance.
fn linear_plastic_albedo(rho: Vec3, eta: f32) -> Vec3 {
    let fi = diffuse_fresnel(1.0 / eta);
    (rho / (Vec3::splat(1.0 - fi) + rho * fi)).clamp(Vec3::ZERO, Vec3::ONE)
}

impl<'a> Builder<'a> {
    /// The grey one-sided diffuse of shapes without a bsdf (Mitsuba's
    /// default).
    pub(crate) fn default_material(&mut self) -> u32 {
        if let Some(m) = self.default_material {
            return m;
        }
        let m = self
            .scene
            .add_material(Material::diffuse(Vec3::splat(0.5)).with_two_sided(false));
        self.default_material = Some(m);
        m
    }

    /// The black one-sided surface of emitters without a bsdf.
    pub(crate) fn black_material(&mut self) -> u32 {
        if let Some(m) = self.black_material {
            return m;
        }
        let m = self
            .scene
            .add_material(Material::diffuse(Vec3::ZERO).with_two_sided(false));
        self.black_material = Some(m);
        m
    }

    /// The material of the bsdf element `node` (made once); `None`: no
    /// surface (`null`).
    pub(crate) fn material(&mut self, node: &'a Node) -> Result<Option<u32>, FormatError> {
        if let Some(m) = self.materials.get(&key(node)) {
            return Ok(*m);
        }
        let m = self.bsdf(node, 0)?;
        let id = m.map(|m| match node.attr("id") {
            Some(name) => self.scene.add_named_material(name, m),
            None => self.scene.add_material(m),
        });
        self.materials.insert(key(node), id);
        Ok(id)
    }

    /// An index of refraction: a number or one of Mitsuba's names.
    fn ior(&mut self, o: &Object<'a>, name: &str, default: f64) -> Result<f64, FormatError> {
        let Some(p) = o.get(name) else {
            return Ok(default);
        };
        match &p.value {
            super::properties::Value::Str(s) => IORS
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(s))
                .map(|&(_, v)| v)
                .ok_or_else(|| {
                    p.error(format!(
                        "unknown index of refraction '{s}' (a number, or one of: {})",
                        IORS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
                    ))
                }),
            _ => o.float(name, default),
        }
    }

    /// The microfacet distribution and roughness of a rough bsdf
    /// (`distribution`, Beckmann by default as in Mitsuba; `alpha`, or the
    /// mean of `alpha_u` and `alpha_v`).
    fn alpha(&mut self, o: &Object<'a>, default: f64) -> Result<(Distribution, f32), FormatError> {
        let name = o.string("distribution")?.unwrap_or("beckmann");
        let distribution = Distribution::from_name(name).ok_or_else(|| {
            o.error(format!(
                "unknown microfacet distribution '{name}' (expected beckmann or ggx)"
            ))
        })?;
        o.get("sample_visible");
        let a = self.number(o, "alpha", default)?;
        let u = self.number(o, "alpha_u", a)?;
        let v = self.number(o, "alpha_v", a)?;
        let (mean, anisotropic) = isotropic_mean(u, v);
        if anisotropic {
            self.w.add(
                format!(
                    "{}: anisotropic roughness is replaced by the mean of alpha_u and alpha_v",
                    o.what()
                ),
                &o.node.loc,
            );
        }
        Ok((distribution, roughness_from_alpha(mean)))
    }

    /// The single bsdf nested in `o` (a wrapper's).
    fn inner(
        &mut self,
        o: &Object<'a>,
        depth: usize,
    ) -> Result<Vec<Option<Material>>, FormatError> {
        let mut out = Vec::new();
        for e in o.entries() {
            if e.name.is_some() && e.child.node().tag != "ref" && e.child.node().tag != "bsdf" {
                continue;
            }
            let node = self.resolve(e.child, &["bsdf", "texture"], "a <bsdf>")?;
            if node.tag != "bsdf" {
                continue;
            }
            e.take();
            out.push(self.bsdf(node, depth + 1)?);
        }
        Ok(out)
    }

    /// The material of a bsdf element; `None` for no surface.
    ///
    /// One piece on purpose: it is Mitsuba's one mapping of its bsdfs onto
    /// Sahara's material kinds, an arm per Mitsuba type, read as a table;
    /// a new kind is an arm here.
    fn bsdf(&mut self, node: &'a Node, depth: usize) -> Result<Option<Material>, FormatError> {
        if depth > MAX_NESTING {
            return Err(node.error("bsdfs nest too deep (a cycle of references?)"));
        }
        let o = self.object(node)?;
        let grey = Vec3::splat;
        let approx = |b: &mut Self, what: &str| {
            b.w.add(format!("{}: {what}", o.what()), &node.loc);
        };
        let one_sided = |m: Material| m.with_two_sided(false);
        let m = match o.ty {
            "diffuse" => one_sided(diffuse(&self.tint(
                &o,
                "reflectance",
                grey(0.5),
                Usage::Reflectance,
            )?)),
            "conductor" | "roughconductor" => {
                let (distribution, r) = if o.ty == "roughconductor" {
                    self.alpha(&o, 0.1)?
                } else {
                    (Distribution::Ggx, 0.0)
                };
                let tint = self.tint(&o, "specular_reflectance", Vec3::ONE, Usage::Reflectance)?;
                let (eta, k) = self.metal(&o)?;
                one_sided(tinted(
                    Bsdf::ComplexConductor {
                        eta: eta.max(Vec3::ZERO),
                        k: k.max(Vec3::ZERO),
                        roughness: r,
                        distribution,
                        multiple_scattering: false,
                    },
                    &tint,
                ))
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                let int = self.ior(&o, "int_ior", 1.5046)?;
                let ext = self.ior(&o, "ext_ior", 1.000277)?;
                if int <= 0.0 || ext <= 0.0 {
                    return Err(o.error("int_ior and ext_ior must be > 0"));
                }
                for k in ["specular_reflectance", "specular_transmittance"] {
                    let t = self.tint(&o, k, Vec3::ONE, Usage::Reflectance)?;
                    if t.image.is_some() || t.color != Vec3::ONE {
                        approx(self, &format!("a tinted '{k}' is not supported; clear"));
                    }
                }
                let eta = (int / ext) as f32;
                if (eta - 1.0).abs() < 1e-6 {
                    o.mark_all_used();
                    return Ok(None);
                }
                match o.ty {
                    "thindielectric" => Material::new(Bsdf::ThinDielectric { ior: eta }),
                    "dielectric" => Material::glass(eta),
                    _ => {
                        let (distribution, roughness) = self.alpha(&o, 0.1)?;
                        Material::new(Bsdf::RoughDielectric {
                            ior: eta,
                            roughness,
                            distribution,
                        })
                    }
                }
            }
            "plastic" | "roughplastic" => {
                let base = self.tint(&o, "diffuse_reflectance", grey(0.5), Usage::Reflectance)?;
                let spec = self.tint(&o, "specular_reflectance", Vec3::ONE, Usage::Reflectance)?;
                if spec.image.is_some() || spec.color != Vec3::ONE {
                    approx(
                        self,
                        "a 'specular_reflectance' other than 1 is not supported; 1",
                    );
                }
                let int = self.ior(&o, "int_ior", 1.49)?;
                let ext = self.ior(&o, "ext_ior", 1.000277)?;
                let eta = ((int / ext) as f32).max(1.0);
                let nonlinear = o.bool("nonlinear", false)?;
                let (distribution, r) = if o.ty == "roughplastic" {
                    self.alpha(&o, 0.1)?
                } else {
                    (Distribution::Ggx, 0.0)
                };
                let rho = base.color.clamp(Vec3::ZERO, Vec3::ONE);
                let albedo = if nonlinear || base.image.is_some() {
                    if !nonlinear {
                        approx(
                            self,
                            "a textured 'diffuse_reflectance' is read as with 'nonlinear' (deeper colours)",
                        );
                    }
                    rho
                } else {
                    linear_plastic_albedo(rho, eta)
                };
                one_sided(tinted(
                    Bsdf::CoatedDiffuse {
                        albedo,
                        ior: eta,
                        roughness: r,
                        distribution,
                    },
                    &Tint {
                        color: Vec3::ONE,
                        ..base
                    },
                ))
            }
            "principled" => self.principled(&o)?,
            "twosided" => {
                let inner = self.inner(&o, depth)?;
                let front = match &inner[..] {
                    [] => return Err(o.error("twosided needs a nested bsdf")),
                    [a] => a.clone(),
                    [a, b] => {
                        if a != b {
                            approx(self, "a different back bsdf is not supported; the front one is used on both sides");
                        }
                        a.clone()
                    }
                    _ => return Err(o.error("twosided takes one or two nested bsdfs")),
                };
                match front {
                    Some(m) => m.with_two_sided(true),
                    None => {
                        o.warn_unused(&mut self.w);
                        return Ok(None);
                    }
                }
            }
            "mask" => {
                let opacity = self.tint(&o, "opacity", grey(0.5), Usage::Reflectance)?;
                let inner = self.inner(&o, depth)?;
                let [Some(mut m)] = <[Option<Material>; 1]>::try_from(inner)
                    .map_err(|_| o.error("mask needs one nested bsdf"))?
                else {
                    o.warn_unused(&mut self.w);
                    return Ok(None);
                };
                let factor = opacity.color.x.clamp(0.0, 1.0);
                if let Some(img) = &opacity.image {
                    let old = m.textures.base_color.take();
                    let texture = with_opacity(old.as_ref().map(|t| &t.texture), img);
                    m.textures.base_color = Some(match old {
                        Some(o) => TextureMap { texture, ..o },
                        None => opacity.sampling.map(texture),
                    });
                } else if factor <= 0.0 {
                    o.warn_unused(&mut self.w);
                    return Ok(None);
                }
                m.with_alpha(AlphaMode::Blend, factor)
            }
            "blendbsdf" => {
                let t = self.number(&o, "weight", 0.5)? as f32;
                let inner = self.inner(&o, depth)?;
                let [a, b] = <[Option<Material>; 2]>::try_from(inner)
                    .map_err(|_| o.error("blendbsdf needs two nested bsdfs"))?;
                match (&a, &b) {
                    (Some(x), Some(y)) if Material::blend(x, y, t).is_some() => {
                        Material::blend(x, y, t).expect("checked")
                    }
                    _ => {
                        if t > 0.0 && t < 1.0 && a != b {
                            approx(self, "the blend is replaced by the bsdf of larger weight");
                        }
                        let pick = if t < 0.5 { a } else { b };
                        o.warn_unused(&mut self.w);
                        return Ok(pick);
                    }
                }
            }
            "normalmap" => {
                let Some(e) = o.named("normalmap") else {
                    return Err(o.error("normalmap needs a 'normalmap' texture"));
                };
                let tex = self.resolve(e.child, &["texture"], "a <texture>")?;
                let t = self.texture(tex)?;
                let inner = self.inner(&o, depth)?;
                let [m] = <[Option<Material>; 1]>::try_from(inner)
                    .map_err(|_| o.error("normalmap needs one nested bsdf"))?;
                let Some(mut m) = m else {
                    o.warn_unused(&mut self.w);
                    return Ok(None);
                };
                if let Some(map) = t.image_map() {
                    m.textures.normal = Some(NormalMap { map, scale: 1.0 });
                }
                m
            }
            "bumpmap" => {
                let scale = self.number(&o, "scale", 1.0)? as f32;
                let mut height = None;
                for e in o.entries() {
                    let node =
                        self.resolve(e.child, &["bsdf", "texture"], "a <bsdf> or <texture>")?;
                    if node.tag == "texture" && height.is_none() {
                        e.take();
                        height = Some(self.texture(node)?);
                    }
                }
                let Some(height) = height else {
                    return Err(o.error("bumpmap needs a nested height <texture>"));
                };
                let inner = self.inner(&o, depth)?;
                let [m] = <[Option<Material>; 1]>::try_from(inner)
                    .map_err(|_| o.error("bumpmap needs one nested bsdf"))?;
                let Some(mut m) = m else {
                    o.warn_unused(&mut self.w);
                    return Ok(None);
                };
                if let Some(img) = &height.image {
                    approx(
                        self,
                        "bumps become a normal map of the heights' slopes, scaled by the mean length a unit of uv spans on the shapes wearing it (Mitsuba uses each point's own)",
                    );
                    // Slopes per unit of uv; the scale to slopes per unit
                    // of length is set once the shapes wearing it are known.
                    let normals = Arc::new(bump_normals(img, height.color.x * scale));
                    self.bump_maps.push(normals.clone());
                    m.textures.normal = Some(NormalMap {
                        map: height.sampling.map(normals),
                        scale: 1.0,
                    });
                }
                m
            }
            "null" => {
                o.warn_unused(&mut self.w);
                return Ok(None);
            }
            t if UNSUPPORTED.contains(&t) => {
                o.mark_all_used();
                approx(self, "not supported; replaced by diffuse grey 0.5");
                Material::diffuse(grey(0.5)).with_two_sided(false)
            }
            other => return Err(o.error(format!("unknown bsdf type '{other}'"))),
        };
        o.warn_unused(&mut self.w);
        Ok(Some(m))
    }

    /// A conductor's `(eta, k)`: a `material` preset, else `eta` and `k`
    /// (Mitsuba's default, `none`, is a perfect mirror).
    fn metal(&mut self, o: &Object<'a>) -> Result<(Vec3, Vec3), FormatError> {
        if o.has("eta") || o.has("k") {
            if o.has("material") {
                return Err(o.error("give 'material' or 'eta' and 'k', not both"));
            }
            let part = |b: &mut Self, name: &str| -> Result<Color, FormatError> {
                if let Some(c) = o.color(name)? {
                    return Ok(c);
                }
                let t = b.tint(o, name, Vec3::ZERO, Usage::Index)?;
                if t.image.is_some() {
                    b.w.add(
                        format!(
                            "{}: textured 'eta' / 'k' are replaced by their means",
                            o.what()
                        ),
                        &o.node.loc,
                    );
                }
                Ok(Color::Rgb(t.mean().as_dvec3()))
            };
            let eta = part(self, "eta")?;
            let k = part(self, "k")?;
            return Ok(conductor_rgb(&eta, &k));
        }
        let name = o.string("material")?.unwrap_or("none");
        if name == "none" {
            // Fresnel 1 at every angle: eta = 1, k large.
            return Ok((Vec3::ONE, Vec3::splat(1e4)));
        }
        match super::metals::mitsuba_metal(name) {
            Some((e, k)) => Ok((
                glam::DVec3::from_array(e).as_vec3(),
                glam::DVec3::from_array(k).as_vec3(),
            )),
            None => {
                let p = o.get("material").expect("present");
                Err(p.error(format!(
                    "unknown conductor material '{name}' (Mitsuba's: none, {})",
                    super::metals::names().collect::<Vec<_>>().join(", ")
                )))
            }
        }
    }

    /// `principled` as glTF's metallic-roughness model.
    fn principled(&mut self, o: &Object<'a>) -> Result<Material, FormatError> {
        let base = self.tint(o, "base_color", Vec3::splat(0.5), Usage::Reflectance)?;
        let metallic = self.number(o, "metallic", 0.0)? as f32;
        let r = self.number(o, "roughness", 0.5)? as f32;
        let eta = match o.float_opt("eta")? {
            Some(e) => e as f32,
            None => {
                // Mitsuba: specular = ((eta - 1) / (eta + 1))^2 / 0.08.
                let s = self.number(o, "specular", 0.5)?.clamp(0.0, 1.0) as f32;
                let r0 = (0.08 * s).sqrt();
                (1.0 + r0) / (1.0 - r0).max(1e-3)
            }
        };
        let mut lost = Vec::new();
        for (k, d) in [
            ("anisotropic", 0.0),
            ("sheen", 0.0),
            ("spec_trans", 0.0),
            ("spec_tint", 0.0),
            ("flatness", 0.0),
            ("sheen_tint", 0.0),
        ] {
            if (self.number(o, k, d)? - d).abs() > 1e-6 && k != "sheen_tint" {
                lost.push(k);
            }
        }
        for k in [
            "diff_trans",
            "eta_thin",
            "main_specular_sampling_rate",
            "clearcoat_sampling_rate",
            "diffuse_reflectance_sampling_rate",
        ] {
            o.get(k);
        }
        if !lost.is_empty() {
            self.w.add(
                format!(
                    "bsdf 'principled': {} not supported; left out",
                    lost.join(", ")
                ),
                &o.node.loc,
            );
        }
        let mut m = tinted(
            Bsdf::MetallicRoughness {
                base_color: base.color.clamp(Vec3::ZERO, Vec3::ONE),
                metallic: metallic.clamp(0.0, 1.0),
                roughness: r.clamp(0.0, 1.0),
                ior: eta.max(1.0),
                specular: 1.0,
                specular_color: Vec3::ONE,
            },
            &Tint {
                color: Vec3::ONE,
                ..base
            },
        );
        let coat = self.number(o, "clearcoat", 0.0)? as f32;
        let gloss = self.number(o, "clearcoat_gloss", 0.0)? as f32;
        if coat > 0.0 {
            // Disney's coat: alpha from 0.1 (gloss 0) to 0.001 (gloss 1).
            let alpha = 0.1 + (0.001 - 0.1) * gloss.clamp(0.0, 1.0);
            m.clearcoat = Some(Box::new(Clearcoat::uniform(
                coat.clamp(0.0, 1.0),
                alpha.sqrt(),
                1.5,
            )));
        }
        Ok(m.with_two_sided(false))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_plastic_gets_the_base_that_gives_mitsubas_diffuse_light() {
        // Sahara's coat gives a / (1 - a F_i), Mitsuba's linear plastic
        // rho / (1 - F_i).
        let fi = diffuse_fresnel(1.0 / 1.5);
        assert!((fi - 0.5968).abs() < 1e-3, "{fi}");
        let rho = Vec3::new(0.1, 0.5, 0.9);
        let a = linear_plastic_albedo(rho, 1.5);
        let sahara = a / (Vec3::ONE - a * fi);
        let mitsuba = rho / (1.0 - fi);
        assert!(
            (sahara - mitsuba).abs().max_element() < 1e-5,
            "{sahara} {mitsuba}"
        );
        // The internal reflectance of a smooth interface is larger than
        // the external one.
        assert!(diffuse_fresnel(1.5) < fi);
    }
}

#[cfg(test)]
mod bump_tests {
    use super::*;

    #[test]
    fn a_height_ramp_along_u_tilts_the_normal_against_u() {
        // Heights rising by 1/8 a texel along u: slope 1 per unit of uv.
        let t: Vec<Vec3> = (0..8 * 8)
            .map(|i| Vec3::splat((i % 8) as f32 / 8.0))
            .collect();
        let n = bump_normals(&Texture::new(8, 8, t), 1.0);
        let c = n.texel(3, 3) * 2.0 - Vec3::ONE;
        let want = Vec3::new(-1.0, 0.0, 1.0).normalize();
        assert!((c - want).abs().max_element() < 1e-5, "{c}");
    }
}
