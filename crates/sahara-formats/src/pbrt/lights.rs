//! pbrt light sources as Sahara lights.
//!
//! | pbrt | Sahara |
//! |---|---|
//! | `point` (`I`, `from`, `scale`, `power`) | point light |
//! | `spot` (`coneangle`, `conedelta`) | spot light, falloff from `coneangle - conedelta` to `coneangle` |
//! | `distant` (`L`, `from`, `to`) | directional light of irradiance `L scale` |
//! | `infinite` (`L` or `filename`) | constant environment, or a map resampled to lat-long |
//! | area `diffuse` (`L`, `twosided`, `scale`, `power`) | the shape's material, emitting |
//! | `goniometric`, `projection` | skipped, with a warning |
//!
//! A light's `rgb` value is its radiance or intensity in linear sRGB as
//! written; a `blackbody` or other spectrum is normalised to luminance 1
//! first (see [`crate::common::spectrum`]). `power` rescales to the given radiant
//! power as pbrt-v4 does: `power / 4 pi` for a point light,
//! `power / (2 pi (1 - (cos_start + cos_end) / 2))` for a spot light,
//! `power / (pi area)` (halved when two-sided) for an area light.

use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3, Vec3};
use sahara_readers::FormatError;
use sahara_render::{Environment, Light, Texture};

use super::declarations::{Entity, LightDecl};
use super::envmap::to_lat_long;
use super::textures::rgb_of;
use crate::common::image::load_rgb_f32;
use crate::common::spectrum::Use;
use crate::common::warnings::Warnings;
use crate::description::SceneDescription;

/// A spectrum parameter of a light as RGB (default white).
fn light_rgb(e: &Entity, name: &str, w: &mut Warnings) -> Result<Vec3, FormatError> {
    match e.params.spectrum(name, false)? {
        Some(p) => rgb_of(&p, Use::Illuminant, &e.folders, w),
        None => Ok(Vec3::ONE),
    }
}

/// `scale`: a float (pbrt-v4) or a spectrum (pbrt-v3).
fn scale(e: &Entity, w: &mut Warnings) -> Result<Vec3, FormatError> {
    match e.params.get("scale").map(|p| p.ty) {
        None => Ok(Vec3::ONE),
        Some("float") => Ok(Vec3::splat(e.params.float("scale", 1.0)? as f32)),
        Some(_) => match e.params.spectrum("scale", false)? {
            Some(p) => rgb_of(&p, Use::Reflectance, &e.folders, w),
            None => Ok(Vec3::ONE),
        },
    }
}

fn v3(p: [f64; 3]) -> DVec3 {
    DVec3::from_array(p)
}

/// Adds the light `l` to `scene`.
///
/// One piece on purpose: it is pbrt's one mapping of its lights onto
/// Sahara's light kinds, an arm per pbrt type, read as a table;
/// a new kind is an arm here.
pub(crate) fn add_light(
    scene: &mut SceneDescription,
    l: &LightDecl,
    w: &mut Warnings,
) -> Result<(), FormatError> {
    let e = &l.entity;
    if l.xform.is_animated() {
        w.add(
            "moving lights are not supported; the start transform is used",
            &e.loc,
        );
    }
    let m: DMat4 = l.xform.m[0];
    let point = |p: DVec3| m.transform_point3(p).as_vec3();
    let vector = |v: DVec3| m.transform_vector3(v).as_vec3();
    match e.kind.as_str() {
        "point" => {
            let i = light_rgb(e, "I", w)? * scale(e, w)?;
            let power = e.params.float("power", -1.0)?;
            let i = if power > 0.0 {
                i * (power / (4.0 * std::f64::consts::PI)) as f32
            } else {
                i
            };
            let from = e.params.triple("from", [0.0; 3])?;
            scene.lights.push(Light::point(point(v3(from)), i));
        }
        "spot" => {
            let i = light_rgb(e, "I", w)? * scale(e, w)?;
            let from = v3(e.params.triple("from", [0.0; 3])?);
            let to = v3(e.params.triple("to", [0.0, 0.0, 1.0])?);
            let cone = e.params.float("coneangle", 30.0)?;
            let delta = e.params.float("conedelta", 5.0)?;
            let power = e.params.float("power", -1.0)?;
            let inner = (cone - delta).max(0.0);
            let i = if power > 0.0 {
                let k = 2.0
                    * std::f64::consts::PI
                    * (1.0 - 0.5 * (inner.to_radians().cos() + cone.to_radians().cos()));
                i * (power / k) as f32
            } else {
                i
            };
            if (to - from).length_squared() == 0.0 {
                return Err(e
                    .loc
                    .error("spot light: 'from' and 'to' are the same point"));
            }
            w.add(
                "spot light: pbrt's smoothstep falloff becomes Sahara's spot falloff",
                &e.loc,
            );
            scene.lights.push(Light::spot(
                point(from),
                point(to),
                i,
                inner as f32,
                cone as f32,
            ));
        }
        "distant" => {
            let l_rgb = light_rgb(e, "L", w)? * scale(e, w)?;
            let from = v3(e.params.triple("from", [0.0; 3])?);
            let to = v3(e.params.triple("to", [0.0, 0.0, 1.0])?);
            if e.params.get("illuminance").is_some() {
                w.add(
                    "distant light 'illuminance' is not supported; 'L' and 'scale' are used",
                    &e.loc,
                );
            }
            let dir = vector(to - from);
            if dir.length_squared() == 0.0 {
                return Err(e
                    .loc
                    .error("distant light: 'from' and 'to' are the same point"));
            }
            scene.lights.push(Light::directional(dir, l_rgb));
        }
        "infinite" => {
            let s = scale(e, w)?;
            if e.params.get("illuminance").is_some() {
                w.add(
                    "infinite light 'illuminance' is not supported; 'scale' is used",
                    &e.loc,
                );
            }
            if e.params.get("portal").is_some() {
                w.add("infinite light 'portal' is not supported; ignored", &e.loc);
            }
            if scene.environment.is_some() {
                w.add("more than one infinite light: the last one is used", &e.loc);
            }
            match e.params.string("filename")? {
                Some(file) => {
                    let path = super::parser::resolve(&e.folders, file);
                    let (wd, ht, rgb) = load_rgb_f32(&path).map_err(|err| e.loc.error(err))?;
                    if wd == 0 || ht == 0 {
                        return Err(e
                            .loc
                            .error(format!("{}: the environment map is empty", path.display())));
                    }
                    let texels: Vec<Vec3> = rgb
                        .chunks_exact(3)
                        .map(|c| Vec3::from_slice(c) * s)
                        .collect();
                    let img = Texture::new(wd, ht, texels);
                    let rot = DMat3::from_mat4(m);
                    if rot.determinant().abs() < 1e-12 {
                        return Err(e.loc.error("infinite light: the transform is singular"));
                    }
                    scene.environment = Some(Environment::Map {
                        texture: Arc::new(to_lat_long(&img, rot)),
                        scale: 1.0,
                    });
                }
                None => {
                    let l_rgb = light_rgb(e, "L", w)? * s;
                    scene.environment = Some(Environment::Constant(l_rgb));
                }
            }
        }
        "goniometric" | "projection" => {
            w.add(
                format!("light '{}' is not supported; skipped", e.kind),
                &e.loc,
            );
            e.params.mark_all_used();
        }
        other => return Err(e.loc.error(format!("unknown light type '{other}'"))),
    }
    Ok(())
}

/// An `AreaLightSource`: radiance, two-sidedness and the power it asks for.
pub(crate) struct AreaEmission {
    /// Radiance (before `power`).
    pub(crate) radiance: Vec3,
    /// Emits from both faces.
    pub(crate) two_sided: bool,
    /// `power`, if given (> 0).
    pub(crate) power: Option<f64>,
}

/// The emission of an area light.
pub(crate) fn area_emission(e: &Entity, w: &mut Warnings) -> Result<AreaEmission, FormatError> {
    if e.kind != "diffuse" && e.kind != "area" {
        return Err(e.loc.error(format!("unknown area light type '{}'", e.kind)));
    }
    if e.params.get("filename").is_some() {
        w.add(
            "area light 'filename' (image emission) is not supported; 'L' is used",
            &e.loc,
        );
    }
    let radiance = light_rgb(e, "L", w)? * scale(e, w)?;
    let two_sided = e.params.bool("twosided", false)?;
    let power = e.params.float("power", -1.0)?;
    Ok(AreaEmission {
        radiance,
        two_sided,
        power: (power > 0.0).then_some(power),
    })
}
