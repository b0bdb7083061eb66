//! pbrt's participating media: `MakeNamedMedium` (homogeneous media,
//! density grids, grids of colours per voxel, NanoVDB grids and the
//! procedural cloud), the media a `MediumInterface` puts on either side of
//! the shapes after it and around the camera, and the `subsurface`
//! material (a dielectric boundary around a homogeneous medium).
//!
//! Coefficients are per unit length of the scene, as in pbrt (the
//! measured presets per millimetre, so a scene in metres scales them
//! with `"float scale"`).

use std::collections::HashMap;

use glam::{Affine3A, DMat4, DVec3, Vec3};
use sahara_readers::vdb::VdbGrid;
use sahara_readers::FormatError;
use sahara_render::{isotropic_mean, roughness_from_alpha};
use sahara_render::{
    CloudMedium, ColourGrid, ColourVolume, DensityGrid, GridCoefficients, GridMedium,
    HenyeyGreenstein, Material, Medium,
};

use super::declarations::{Entity, MediaDecl, MediumDecl};
use super::measured_media::{measured, names};
use super::textures::rgb_of;
use crate::common::spectrum::{blackbody_radiance_rgb, Use};
use crate::common::warnings::Warnings;
use crate::description::SceneDescription;

/// Default `sigma_a` and `sigma_s` of the `subsurface` material (per mm):
/// pbrt's, whole milk's coefficients.
const SUBSURFACE_SIGMA_A: [f32; 3] = [0.0011, 0.0024, 0.014];
const SUBSURFACE_SIGMA_S: [f32; 3] = [2.55, 3.21, 3.77];

/// The file's named media, added to the scene: each name to its index
/// in [`SceneDescription::media`] (a later definition of a name replaces
/// an earlier one, with a warning).
pub(crate) fn add_media(
    decls: &[MediumDecl],
    scene: &mut SceneDescription,
    w: &mut Warnings,
) -> Result<HashMap<String, u32>, FormatError> {
    let mut index = HashMap::new();
    for d in decls {
        let m = named_medium(d, w)?;
        scene.media.push(m);
        let i = scene.media.len() as u32 - 1;
        if index.insert(d.name.clone(), i).is_some() {
            w.add(
                format!(
                    "medium \"{}\" defined again; the last definition is used",
                    d.name
                ),
                &d.entity.loc,
            );
        }
    }
    Ok(index)
}

/// The media a `MediumInterface` names, inside and outside (`None`:
/// vacuum); an error naming the directive for a name no
/// `MakeNamedMedium` defines.
pub(crate) fn interface(
    media: &HashMap<String, u32>,
    d: &MediaDecl,
) -> Result<(Option<u32>, Option<u32>), FormatError> {
    let look = |name: &str| -> Result<Option<u32>, FormatError> {
        if name.is_empty() {
            return Ok(None);
        }
        media.get(name).copied().map(Some).ok_or_else(|| {
            d.loc.error(format!(
                "MediumInterface: no MakeNamedMedium defines \"{name}\""
            ))
        })
    };
    Ok((look(&d.inside)?, look(&d.outside)?))
}

/// One `MakeNamedMedium` as a medium.
fn named_medium(d: &MediumDecl, w: &mut Warnings) -> Result<Medium, FormatError> {
    let e = &d.entity;
    let what = format!("MakeNamedMedium \"{}\"", d.name);
    let Some(kind) = e.params.string("type")? else {
        return Err(e.loc.error(format!("{what} has no \"string type\"")));
    };
    let medium = match kind {
        "homogeneous" => {
            let c = coefficients(e, &what, w)?;
            let le = emission(e, w)? * scalar_lescale(e, &what)?;
            Medium::homogeneous(c.sigma_a, c.sigma_s, c.g).with_emission(le)
        }
        "uniformgrid" => {
            let c = coefficients(e, &what, w)?;
            let grid = density_grid(e, &what)?;
            let size = grid.size();
            // A temperature grid takes the place of `Le` (as in pbrt-v4).
            let temperature = temperature_grid(e, &what, size)?;
            let le = if temperature.is_some() {
                e.params.get("Le");
                Vec3::ONE
            } else {
                emission(e, w)?
            };
            let to_world = grid_to_world(e, &d.xform.m[0])?;
            let mut m = GridMedium::new(
                grid,
                c.sigma_a,
                c.sigma_s,
                HenyeyGreenstein::new(c.g),
                to_world,
            );
            if le != Vec3::ZERO {
                let scale = lescale_grid(e, &what, size)?;
                m = m.with_emission_scale(scale);
            } else {
                e.params.get("Lescale");
            }
            if let Some(colours) = temperature {
                m = m.with_emission_colour(colours);
            }
            Medium::Grid(Box::new(m)).with_emission(le)
        }
        "rgbgrid" => rgb_grid(e, &what, &d.xform.m[0])?,
        "cloud" => {
            let c = coefficients(e, &what, w)?;
            let density = e.params.float("density", 1.0)? as f32;
            let wispiness = e.params.float("wispiness", 1.0)? as f32;
            let frequency = e.params.float("frequency", 5.0)? as f32;
            let p0 = Vec3::from_array(e.params.triple("p0", [0.0; 3])?.map(|v| v as f32));
            let p1 = Vec3::from_array(e.params.triple("p1", [1.0; 3])?.map(|v| v as f32));
            if (p1 - p0).min_element() <= 0.0 {
                return Err(e.loc.error(format!(
                    "{what}: bounds p0 {p0} to p1 {p1}: p1 must be above p0 on every axis"
                )));
            }
            let to_world = Affine3A::from_mat4(d.xform.m[0].as_mat4());
            Medium::Cloud(Box::new(CloudMedium::new(
                c.sigma_a,
                c.sigma_s,
                HenyeyGreenstein::new(c.g),
                density,
                wispiness,
                frequency,
                (p0, p1),
                to_world,
            )))
        }
        "nanovdb" => nano_vdb(e, &what, &d.xform.m[0], w)?,
        other => {
            return Err(e
                .loc
                .error(format!("{what}: unknown medium type '{other}'")))
        }
    };
    if let Some(problem) = medium.problem() {
        return Err(e.loc.error(format!("{what}: {problem}")));
    }
    super::declarations::unknown_params(e, "medium", w);
    Ok(medium)
}

/// A medium's coefficients (scale applied) and phase asymmetry.
struct Coefficients {
    sigma_a: Vec3,
    sigma_s: Vec3,
    g: f32,
}

/// `sigma_a`, `sigma_s` (default 1 each) or a `preset`, times `scale`,
/// and `g`.
fn coefficients(e: &Entity, what: &str, w: &mut Warnings) -> Result<Coefficients, FormatError> {
    let (sigma_a, sigma_s) = match e.params.string("preset")? {
        Some(name) => {
            let (s, a) = preset(e, name, what)?;
            e.params.get("sigma_a");
            e.params.get("sigma_s");
            (a, s)
        }
        None => (
            spectrum(e, "sigma_a", Vec3::ONE, w)?,
            spectrum(e, "sigma_s", Vec3::ONE, w)?,
        ),
    };
    let scale = non_negative(e, what, "scale")?;
    let g = e.params.float("g", 0.0)? as f32;
    Ok(Coefficients {
        sigma_a: sigma_a * scale,
        sigma_s: sigma_s * scale,
        g,
    })
}

/// A measured medium's (scattering, absorption), or an error naming it.
fn preset(e: &Entity, name: &str, what: &str) -> Result<(Vec3, Vec3), FormatError> {
    match measured(name) {
        Some((s, a)) => Ok((Vec3::from_array(s), Vec3::from_array(a))),
        None => Err(e.loc.error(format!(
            "{what}: no measured medium is named \"{name}\" (known: {})",
            names().collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// A spectrum parameter as RGB (an unbounded quantity), or `default`.
fn spectrum(e: &Entity, name: &str, default: Vec3, w: &mut Warnings) -> Result<Vec3, FormatError> {
    match e.params.spectrum(name, false)? {
        Some(p) => rgb_of(&p, Use::Unbounded, &e.folders, w),
        None => Ok(default),
    }
}

/// The radiance a medium emits per unit of absorption: `Le` (an
/// illuminant, normalised as pbrt normalises emitted spectra; default 0).
fn emission(e: &Entity, w: &mut Warnings) -> Result<Vec3, FormatError> {
    match e.params.spectrum("Le", false)? {
        Some(p) => rgb_of(&p, Use::Illuminant, &e.folders, w),
        None => Ok(Vec3::ZERO),
    }
}

/// A homogeneous medium's `Lescale` (default 1): one number.
fn scalar_lescale(e: &Entity, what: &str) -> Result<f32, FormatError> {
    non_negative(e, what, "Lescale")
}

/// The float parameter `name` (default 1), finite and not negative.
fn non_negative(e: &Entity, what: &str, name: &str) -> Result<f32, FormatError> {
    let v = e.params.float(name, 1.0)? as f32;
    if !(v.is_finite() && v >= 0.0) {
        return Err(e.loc.error(format!(
            "{what}: {name} {v} must be finite and not negative"
        )));
    }
    Ok(v)
}

/// A `uniformgrid`'s `Lescale`: the emission's scale over the grid, one
/// value per density value. Without it (or with one value), pbrt-v4
/// scales by a grid of one cell, which like any of its grids is
/// interpolated from the cell's centre towards zero half a cell beyond
/// it: full at the box's centre, half at its faces. So does Sahara.
fn lescale_grid(e: &Entity, what: &str, size: [u32; 3]) -> Result<DensityGrid, FormatError> {
    let values = e.params.floats("Lescale")?.unwrap_or(&[1.0]);
    let want = size.iter().map(|&v| u64::from(v)).product::<u64>();
    let n = if values.len() == 1 {
        [1, 1, 1]
    } else if values.len() as u64 == want {
        size
    } else {
        return Err(e.loc.error(format!(
            "{what}: grid size {}x{}x{} needs {want} \"Lescale\" values (or one) but {} are given",
            size[0],
            size[1],
            size[2],
            values.len()
        )));
    };
    DensityGrid::new(n, values.iter().map(|&v| v as f32).collect())
        .map_err(|m| e.loc.error(format!("{what}: Lescale {m}")))
}

/// A `uniformgrid`'s density: `nx` x `ny` x `nz` values, x fastest; the
/// sizes checked against the values given.
fn density_grid(e: &Entity, what: &str) -> Result<DensityGrid, FormatError> {
    let n = grid_size(e, what)?;
    let Some(values) = e.params.floats("density")? else {
        return Err(e
            .loc
            .error(format!("{what}: a 'uniformgrid' needs \"float density\"")));
    };
    let want = n.iter().map(|&v| u64::from(v)).product::<u64>();
    if want != values.len() as u64 {
        return Err(e.loc.error(format!(
            "{what}: grid size {}x{}x{} needs {want} density values but {} are given",
            n[0],
            n[1],
            n[2],
            values.len()
        )));
    }
    DensityGrid::new(n, values.iter().map(|&v| v as f32).collect())
        .map_err(|m| e.loc.error(format!("{what}: {m}")))
}

/// An `rgbgrid`: `sigma_a` and `sigma_s` per voxel (either may be left
/// out, and is then 1 throughout, as in pbrt-v4), times `scale`; an
/// optional `Le` per voxel (which needs `sigma_a`) times `Lescale`.
fn rgb_grid(e: &Entity, what: &str, ctm: &DMat4) -> Result<Medium, FormatError> {
    let n = grid_size(e, what)?;
    let grid = |name: &str| -> Result<Option<ColourGrid>, FormatError> {
        let Some(values) = e.params.rgbs(name)? else {
            return Ok(None);
        };
        let want = n.iter().map(|&v| u64::from(v)).product::<u64>();
        if want != values.len() as u64 {
            return Err(e.loc.error(format!(
                "{what}: grid size {}x{}x{} needs {want} \"{name}\" colours but {} are given",
                n[0],
                n[1],
                n[2],
                values.len()
            )));
        }
        let values: Vec<Vec3> = values
            .iter()
            .map(|c| DVec3::from_array(*c).as_vec3())
            .collect();
        ColourGrid::new(n, values)
            .map(Some)
            .map_err(|m| e.loc.error(format!("{what}: \"{name}\" {m}")))
    };
    let (sigma_a, sigma_s, le) = (grid("sigma_a")?, grid("sigma_s")?, grid("Le")?);
    if sigma_a.is_none() && sigma_s.is_none() {
        return Err(e.loc.error(format!(
            "{what}: an 'rgbgrid' needs \"rgb sigma_a\" or \"rgb sigma_s\" (or both)"
        )));
    }
    if le.is_some() && sigma_a.is_none() {
        return Err(e.loc.error(format!(
            "{what}: an 'rgbgrid' with \"Le\" needs \"rgb sigma_a\" (it emits as it absorbs)"
        )));
    }
    let volume =
        |g: Option<ColourGrid>| g.map_or(ColourVolume::Constant(Vec3::ONE), ColourVolume::Grid);
    let scale = non_negative(e, what, "scale")?;
    let g = e.params.float("g", 0.0)? as f32;
    let lescale = scalar_lescale(e, what)?;
    let coefficients =
        GridCoefficients::absorption_scattering(volume(sigma_a), volume(sigma_s), scale);
    let mut m = GridMedium::with_coefficients(
        coefficients,
        HenyeyGreenstein::new(g),
        grid_to_world(e, ctm)?,
    );
    let mut emission = Vec3::ZERO;
    if let Some(le) = le {
        m = m.with_emission_colour(le);
        emission = Vec3::splat(lescale);
    }
    Ok(Medium::Grid(Box::new(m)).with_emission(emission))
}

/// A grid's size: `nx`, `ny`, `nz` (default 1 each), each positive.
fn grid_size(e: &Entity, what: &str) -> Result<[u32; 3], FormatError> {
    let size = ["nx", "ny", "nz"].map(|k| e.params.int(k, 1));
    let mut n = [0u32; 3];
    for (i, s) in size.into_iter().enumerate() {
        let s = s?;
        n[i] = u32::try_from(s).ok().filter(|&v| v > 0).ok_or_else(|| {
            e.loc.error(format!(
                "{what}: grid size {} = {s} must be a positive integer",
                ["nx", "ny", "nz"][i]
            ))
        })?;
    }
    Ok(n)
}

/// A `nanovdb` medium: the float grid `gridname` (default `density`) of
/// the `.nvdb` file `filename`, placed where the file's map puts it and
/// then by the transform in effect, times `sigma_a` and `sigma_s` (default
/// 1 each) times `scale`. Blackbody emission from a temperature grid is
/// not rendered (warned when the file holds one).
fn nano_vdb(e: &Entity, what: &str, ctm: &DMat4, w: &mut Warnings) -> Result<Medium, FormatError> {
    let c = coefficients(e, what, w)?;
    let Some(file) = e.params.string("filename")? else {
        return Err(e.loc.error(format!(
            "{what}: a 'nanovdb' medium needs \"string filename\""
        )));
    };
    let path = super::parser::resolve(&e.folders, file);
    let grid_name = e.params.string("gridname")?.unwrap_or("density");
    let nvdb = sahara_readers::nanovdb::NanoVdbFile::open(&path)?;
    let grid = nvdb.grid(grid_name)?;
    let temperature_name = e.params.string("temperaturename")?.unwrap_or("temperature");
    let (offset, scale) = temperature_map(e, what)?;
    // pbrt-v4 first spelled it `LeScale` here, and pbrt-v4-scenes'
    // explosion.pbrt still does.
    let lescale = if e.params.has("LeScale") {
        e.params.get("Lescale");
        non_negative(e, what, "LeScale")?
    } else {
        scalar_lescale(e, what)?
    };
    // The temperature grid, if the file holds one, over the density's
    // voxels (pbrt-v4 emits from it only; without it, nothing is emitted).
    let unrendered = |why: String, w: &mut Warnings| {
        w.add(
            format!(
                "medium 'nanovdb': the '{temperature_name}' grid of {file} {why}; \
                 its blackbody emission is not rendered"
            ),
            &e.loc,
        );
        None
    };
    let temperature = match nvdb
        .has(temperature_name)
        .then(|| nvdb.grid(temperature_name))
    {
        None => None,
        Some(Ok(t)) if t.voxel_size == grid.voxel_size && t.translation == grid.translation => {
            Some(blackbody_colours(
                &over_box(&t, &grid),
                offset,
                scale,
                grid.size,
            ))
        }
        Some(Ok(_)) => unrendered("is placed unlike the density's".into(), w),
        Some(Err(err)) => unrendered(format!("is not read ({err})"), w),
    };
    let to_world = Affine3A::from_mat4(ctm.as_mat4()) * grid.to_world();
    let density = DensityGrid::new(grid.size, grid.values)
        .map_err(|m| e.loc.error(format!("{what}: {file}: {m}")))?;
    let mut m = GridMedium::new(
        density,
        c.sigma_a,
        c.sigma_s,
        HenyeyGreenstein::new(c.g),
        to_world,
    );
    let mut le = Vec3::ZERO;
    if let Some(colours) = temperature {
        m = m.with_emission_colour(colours);
        le = Vec3::splat(lescale);
    }
    Ok(Medium::Grid(Box::new(m)).with_emission(le))
}

/// The values of grid `g` at the voxels of `like`'s box (both of one
/// index space), zero outside `g`'s own box.
fn over_box(g: &VdbGrid, like: &VdbGrid) -> Vec<f32> {
    let n = g.size.map(i64::from);
    let at = |i: [i64; 3]| {
        let d = [0, 1, 2].map(|a| i[a] - i64::from(g.index_min[a]));
        if (0..3).any(|a| d[a] < 0 || d[a] >= n[a]) {
            0.0
        } else {
            g.values[((d[2] * n[1] + d[1]) * n[0] + d[0]) as usize]
        }
    };
    let [nx, ny, nz] = like.size.map(i64::from);
    let lo = like.index_min.map(i64::from);
    let mut out = Vec::with_capacity(like.values.len());
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                out.push(at([lo[0] + x, lo[1] + y, lo[2] + z]));
            }
        }
    }
    out
}

/// pbrt-v4's map of grid values to kelvin, `(value - offset) * scale`:
/// `temperatureoffset` (or the older `temperaturecutoff`; default 0) and
/// `temperaturescale` (default 1).
fn temperature_map(e: &Entity, what: &str) -> Result<(f32, f32), FormatError> {
    let cutoff = e.params.float("temperaturecutoff", 0.0)?;
    let offset = e.params.float("temperatureoffset", cutoff)? as f32;
    let scale = e.params.float("temperaturescale", 1.0)? as f32;
    if !(offset.is_finite() && scale.is_finite()) {
        return Err(e.loc.error(format!(
            "{what}: temperature offset {offset} and scale {scale} must be finite"
        )));
    }
    Ok((offset, scale))
}

/// A `uniformgrid`'s `temperature` grid (one value per density value) as
/// the colours of its blackbody emission, if given.
fn temperature_grid(
    e: &Entity,
    what: &str,
    size: [u32; 3],
) -> Result<Option<ColourGrid>, FormatError> {
    let (offset, scale) = temperature_map(e, what)?;
    let Some(values) = e.params.floats("temperature")? else {
        return Ok(None);
    };
    let want = size.iter().map(|&v| u64::from(v)).product::<u64>();
    if values.len() as u64 != want {
        return Err(e.loc.error(format!(
            "{what}: grid size {}x{}x{} needs {want} \"temperature\" values but {} are given",
            size[0],
            size[1],
            size[2],
            values.len()
        )));
    }
    let kelvin: Vec<f32> = values.iter().map(|&v| v as f32).collect();
    Ok(Some(blackbody_colours(&kelvin, offset, scale, size)))
}

/// The colour each voxel of temperature `t` emits per unit of absorption:
/// pbrt-v4's normalised black body at `(t - offset) * scale` kelvin,
/// nothing at 100 K or below. Temperatures are rounded to the kelvin for
/// the conversion (a spectral integral, done once per kelvin seen). pbrt
/// converts the interpolated temperature; Sahara interpolates the voxels'
/// colours, which differs where neighbouring voxels' temperatures differ.
fn blackbody_colours(t: &[f32], offset: f32, scale: f32, size: [u32; 3]) -> ColourGrid {
    let mut cache: HashMap<u32, Vec3> = HashMap::new();
    let colours: Vec<Vec3> = t
        .iter()
        .map(|&v| {
            let kelvin = (v - offset) * scale;
            // (NaN as well as cold voxels emit nothing.)
            if kelvin.is_nan() || kelvin <= 100.0 {
                return Vec3::ZERO;
            }
            let k = kelvin.round().min(1e6) as u32;
            *cache.entry(k).or_insert_with(|| {
                DVec3::from_array(blackbody_radiance_rgb(f64::from(k))).as_vec3()
            })
        })
        .collect();
    ColourGrid::new(size, colours).expect("blackbody colours are finite and not negative")
}

/// The grid's box `p0` to `p1` (default the unit cube) in the medium's
/// space, placed by `ctm`: the unit cube to world.
fn grid_to_world(e: &Entity, ctm: &DMat4) -> Result<Affine3A, FormatError> {
    let p0 = DVec3::from_array(e.params.triple("p0", [0.0; 3])?);
    let p1 = DVec3::from_array(e.params.triple("p1", [1.0; 3])?);
    if (p1 - p0).min_element() <= 0.0 {
        return Err(e.loc.error(format!(
            "medium grid bounds p0 {p0} to p1 {p1}: p1 must be above p0 on every axis"
        )));
    }
    let m = *ctm * DMat4::from_translation(p0) * DMat4::from_scale(p1 - p0);
    Ok(Affine3A::from_mat4(m.as_mat4()))
}

/// The `subsurface` material: its boundary (a dielectric of `eta`,
/// default 1.33, smooth or rough) and the homogeneous medium inside,
/// from a measured medium's `name`, or `sigma_a` and `sigma_s` (default
/// whole milk's, per mm), times `scale`, with asymmetry `g`. The
/// `reflectance` form (coefficients found from a colour and a mean free
/// path) is refused.
pub(crate) fn subsurface(e: &Entity, w: &mut Warnings) -> Result<(Material, Medium), FormatError> {
    let what = "material 'subsurface'";
    if e.params.has("reflectance") {
        return Err(e.loc.error(format!(
            "{what}: the \"reflectance\" form (coefficients from a colour and \"mfp\") is not \
             supported; give \"string name\" or \"sigma_a\" and \"sigma_s\""
        )));
    }
    let (sigma_s, sigma_a) = match e.params.string("name")? {
        Some(name) => preset(e, name, what)?,
        None => (
            spectrum(e, "sigma_s", Vec3::from_array(SUBSURFACE_SIGMA_S), w)?,
            spectrum(e, "sigma_a", Vec3::from_array(SUBSURFACE_SIGMA_A), w)?,
        ),
    };
    let scale = e.params.float("scale", 1.0)? as f32;
    let g = e.params.float("g", 0.0)? as f32;
    let medium = Medium::homogeneous(sigma_a * scale, sigma_s * scale, g);
    if let Some(problem) = medium.problem() {
        return Err(e.loc.error(format!("{what}: {problem}")));
    }
    let eta = e.params.float("eta", 1.33)? as f32;
    if !(eta.is_finite() && eta > 0.0) {
        return Err(e.loc.error(format!("{what}: eta {eta} must be positive")));
    }
    let remap = e.params.bool("remaproughness", true)?;
    let r = match e.params.float_opt("roughness")? {
        Some(r) => r,
        None => {
            let u = e.params.float("uroughness", 0.0)?;
            let v = e.params.float("vroughness", u)?;
            let (mean, anisotropic) = isotropic_mean(u, v);
            if anisotropic {
                w.add(
                    format!("{what}: anisotropic roughness is rendered isotropic (the mean)"),
                    &e.loc,
                );
            }
            mean
        }
    };
    // pbrt-v4 remaps roughness to alpha = sqrt(r).
    let alpha = if remap { r.max(0.0).sqrt() } else { r };
    let roughness = roughness_from_alpha(alpha);
    let boundary = super::materials::glass(eta, roughness);
    for k in ["mfp", "displacement", "normalmap"] {
        if e.params.get(k).is_some() {
            w.add(format!("{what}: '{k}' is ignored"), &e.loc);
        }
    }
    Ok((boundary, medium))
}
