//! A [`Declarations`] of a pbrt file as a [`SceneDescription`] with its
//! render settings.
//!
//! - Each shape outside an object is an object of its own, placed by its
//!   transform (moving when the transforms at the two `TransformTimes`
//!   differ): a full sphere or disc that does not move is a built-in
//!   shape (kept exact under a similarity transform, so that as an
//!   emitter it is sampled analytically), anything else a mesh.
//! - Each object (`ObjectBegin`) is one mesh holding all its shapes (their
//!   transforms applied, a material per triangle), built once; each
//!   `ObjectInstance` is an object showing it: one kd-tree per object
//!   instanced more than once, one over the instances (the renderer puts
//!   an object used once, as the rest of the static geometry, into its
//!   world tree).
//! - Materials are mapped on first use, in that order.
//! - Camera: pbrt's camera space has +x to the image's right, +y up and +z
//!   forward; the camera's transform is used as it is, so mirroring
//!   transforms (`Scale -1 1 1`) mirror the image as in pbrt.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Affine3A, DMat3, DMat4, DVec3, Mat4, Vec3};
use sahara_readers::FormatError;
use sahara_render::SceneMesh;
use sahara_render::{
    AlphaMode, Camera, Filter, FrameLayer, Integrator, Material, MediumInterface, Pick,
    SamplerKind, Shape, Srt, TextureMap,
};

use super::declarations::{unknown_params, Declarations, Entity, MaterialRef, ShapeDecl, Xform};
use super::lights::{add_light, area_emission};
use super::materials::{default_material, map_material, Mapped};
use super::media::{add_media, interface};
use super::shapes::shape_geometry;
use super::textures::Textures;
use crate::common::mesh::smooth_normals;
use crate::common::tint::with_opacity;
use crate::common::warnings::Warnings;
use crate::description::{
    CameraRequest, FileCrop, Geometry, Object, ObjectPlacement, SceneDescription, SettingsLayer,
};
use crate::output::frame::OutputLayer;

/// Deepest chain of `mix` materials followed.
const MAX_MIX_DEPTH: usize = 16;

/// The materials of the file, mapped on first use.
struct Materials<'a> {
    desc: &'a Declarations,
    textures: Textures<'a>,
    anonymous: HashMap<usize, Option<u32>>,
    named: HashMap<String, Option<u32>>,
    default: Option<u32>,
    /// Materials cut by a shape's `alpha`: (material, alpha) to the cut one.
    cut: HashMap<(u32, String), u32>,
    /// `subsurface` materials (their boundaries) to the media inside them.
    subsurface: HashMap<u32, u32>,
}

impl Materials<'_> {
    /// `material` cut by shape `e`'s `alpha`, pbrt-v4's stochastic
    /// transparency (a ray meets the surface with probability `alpha`);
    /// `None` if the shape is not there at all (alpha 0).
    fn cut(
        &mut self,
        scene: &mut SceneDescription,
        material: u32,
        e: &Entity,
        w: &mut Warnings,
    ) -> Result<Option<u32>, FormatError> {
        let Some(p) = e.params.get("alpha") else {
            return Ok(Some(material));
        };
        let key = (material, format!("{:?}", p.values));
        if let Some(&m) = self.cut.get(&key) {
            e.params.get("alpha");
            return Ok(Some(m));
        }
        let alpha = self.textures.float_tint(e, "alpha", 1.0, w)?;
        let factor = alpha.color.x.clamp(0.0, 1.0);
        if alpha.image.is_none() && factor >= 1.0 {
            return Ok(Some(material));
        }
        if alpha.image.is_none() && factor <= 0.0 {
            return Ok(None);
        }
        let mut m = scene.materials[material as usize].clone();
        if let Some(img) = &alpha.image {
            // The opacity joins the base colour's image, read as that image
            // is read (the alpha texture's own as a fallback).
            let old = m.textures.base_color.take();
            let texture = with_opacity(old.as_ref().map(|t| &t.texture), img);
            m.textures.base_color = Some(match old {
                Some(o) => TextureMap { texture, ..o },
                None => alpha.sampling.map(texture),
            });
        }
        let id = scene.add_material(m.with_alpha(AlphaMode::Blend, factor));
        self.cut.insert(key, id);
        Ok(Some(id))
    }

    /// The Sahara material of `r`, or `None` for pbrt's `interface`.
    fn resolve(
        &mut self,
        scene: &mut SceneDescription,
        r: &MaterialRef,
        w: &mut Warnings,
    ) -> Result<Option<u32>, FormatError> {
        match r {
            MaterialRef::Default => {
                Ok(Some(*self.default.get_or_insert_with(|| {
                    scene.add_material(default_material())
                })))
            }
            MaterialRef::Anonymous(i) => {
                if let Some(m) = self.anonymous.get(i) {
                    return Ok(*m);
                }
                let e = self.desc.materials[*i].clone();
                let m = self.map(scene, &e, w, 0)?;
                self.anonymous.insert(*i, m);
                Ok(m)
            }
            MaterialRef::Named(name, loc) => self.named(scene, name, loc, w, 0),
        }
    }

    fn named(
        &mut self,
        scene: &mut SceneDescription,
        name: &str,
        loc: &crate::common::position::Loc,
        w: &mut Warnings,
        depth: usize,
    ) -> Result<Option<u32>, FormatError> {
        if let Some(m) = self.named.get(name) {
            return Ok(*m);
        }
        let Some(decl) = self.desc.named_materials.get(name) else {
            return Err(loc.error(format!("unknown named material \"{name}\"")));
        };
        let mut e = decl.clone();
        e.kind = match e.params.string("type")? {
            Some(t) => t.to_owned(),
            None => {
                return Err(e.loc.error(format!(
                    "MakeNamedMaterial \"{name}\" has no \"string type\""
                )))
            }
        };
        let m = self.map(scene, &e, w, depth)?;
        if let Some(id) = m {
            scene
                .material_names
                .entry(id)
                .or_insert_with(|| name.to_owned());
        }
        self.named.insert(name.to_owned(), m);
        Ok(m)
    }

    fn map(
        &mut self,
        scene: &mut SceneDescription,
        e: &Entity,
        w: &mut Warnings,
        depth: usize,
    ) -> Result<Option<u32>, FormatError> {
        if e.kind == "subsurface" {
            let (boundary, medium) = super::media::subsurface(e, w)?;
            unknown_params(e, "material", w);
            let id = scene.add_material(boundary);
            scene.media.push(medium);
            self.subsurface.insert(id, scene.media.len() as u32 - 1);
            return Ok(Some(id));
        }
        let mapped = map_material(e, &mut self.textures, w)?;
        unknown_params(e, "material", w);
        match mapped {
            Mapped::Surface(m) => Ok(Some(scene.add_material(m))),
            Mapped::Interface => Ok(None),
            Mapped::Mix(names, amount) => {
                if depth >= MAX_MIX_DEPTH {
                    return Err(e.loc.error("mix materials nest too deep (a cycle?)"));
                }
                let a = self.named(scene, &names[0], &e.loc, w, depth + 1)?;
                let b = self.named(scene, &names[1], &e.loc, w, depth + 1)?;
                let t = amount.clamp(0.0, 1.0) as f32;
                if let (Some(a), Some(b)) = (a, b) {
                    let (ma, mb) = (&scene.materials[a as usize], &scene.materials[b as usize]);
                    if let Some(m) = Material::blend(ma, mb, t) {
                        return Ok(Some(scene.add_material(m)));
                    }
                }
                if t > 0.0 && t < 1.0 && a != b {
                    w.add(
                        "material 'mix': the blend is replaced by the material with the larger weight",
                        &e.loc,
                    );
                }
                Ok(if t < 0.5 { a } else { b })
            }
        }
    }
}

/// True if `m` mirrors (its linear part has a negative determinant).
fn swaps_handedness(m: &DMat4) -> bool {
    DMat3::from_mat4(*m).determinant() < 0.0
}

/// Winds the triangles of `mesh` so that their fronts are pbrt's surface
/// normals: the shading normals' side when the mesh has normals (negated
/// by `ReverseOrientation`), else the winding flipped by
/// `ReverseOrientation`; both flipped again by a mirroring transform,
/// which Sahara's winding rule would otherwise flip.
fn orient(mesh: &mut SceneMesh, reverse: bool, mirror: bool) {
    if reverse {
        if let Some(n) = &mut mesh.normals {
            n.iter_mut().for_each(|v| *v = -*v);
        }
    }
    let p = &mesh.mesh.positions;
    for t in &mut mesh.mesh.indices {
        let flip = match &mesh.normals {
            Some(n) => {
                let [a, b, c] = t.map(|i| p[i as usize]);
                let ns = n[t[0] as usize] + n[t[1] as usize] + n[t[2] as usize];
                ((b - a).cross(c - a).dot(ns) < 0.0) != mirror
            }
            None => reverse != mirror,
        };
        if flip {
            t.swap(1, 2);
        }
    }
}

/// The world-space area of `mesh` under `m`.
fn world_area(mesh: &SceneMesh, m: &DMat4) -> f64 {
    let p: Vec<DVec3> = mesh
        .mesh
        .positions
        .iter()
        .map(|v| m.transform_point3(v.as_dvec3()))
        .collect();
    mesh.mesh
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// The scale, rotation and translation of `m` (a shear is lost).
fn srt(m: &DMat4) -> Srt {
    let (scale, rotation, translation) = m.as_mat4().to_scale_rotation_translation();
    Srt {
        scale,
        rotation,
        translation,
    }
}

/// Where something with transform `x` is over the shutter `[open, close]`,
/// given `TransformTimes` `times`.
fn placement(x: &Xform, times: (f64, f64), shutter: (f64, f64)) -> ObjectPlacement {
    if !x.is_animated() {
        return ObjectPlacement::Static(Affine3A::from_mat4(x.m[0].as_mat4()));
    }
    let (a, b) = (srt(&x.m[0]), srt(&x.m[1]));
    let span = times.1 - times.0;
    let at = |t: f64| {
        let s = if span > 0.0 {
            (t - times.0) / span
        } else {
            0.0
        };
        a.interpolate(&b, s as f32)
    };
    ObjectPlacement::Moving {
        open: at(shutter.0),
        close: at(shutter.1),
    }
}

/// The camera, and the shutter interval.
fn camera(
    desc: &Declarations,
    aspect: f64,
    w: &mut Warnings,
) -> Result<(Camera, (f64, f64)), FormatError> {
    let (e, x) = match &desc.camera {
        Some((e, x)) => (e.clone(), *x),
        None => (
            Entity {
                kind: "perspective".into(),
                params: Default::default(),
                loc: crate::common::position::Loc {
                    file: "".into(),
                    line: 0,
                    col: 0,
                },
                folders: Vec::new(),
            },
            Xform {
                m: [DMat4::IDENTITY; 2],
            },
        ),
    };
    match e.kind.as_str() {
        "perspective" => {}
        "orthographic" | "realistic" | "spherical" | "environment" => {
            return Err(e.loc.error(format!(
                "the '{}' camera is not supported (Sahara has perspective cameras only)",
                e.kind
            )))
        }
        other => return Err(e.loc.error(format!("unknown camera type '{other}'"))),
    }
    if x.is_animated() {
        w.add(
            "a moving camera is not supported; its start transform is used",
            &e.loc,
        );
    }
    let world_from_camera = x.m[0].inverse();
    if !world_from_camera.is_finite() {
        return Err(e.loc.error("the camera transform is singular"));
    }
    let eye = world_from_camera.transform_point3(DVec3::ZERO);
    let fwd = world_from_camera
        .transform_vector3(DVec3::Z)
        .normalize_or_zero();
    let right = world_from_camera.transform_vector3(DVec3::X);
    let up = world_from_camera.transform_vector3(DVec3::Y);
    let right = (right - fwd * right.dot(fwd)).normalize_or_zero();
    let up = (up - fwd * up.dot(fwd) - right * up.dot(right)).normalize_or_zero();
    if fwd == DVec3::ZERO || right == DVec3::ZERO || up == DVec3::ZERO {
        return Err(e.loc.error("the camera transform is degenerate"));
    }
    let p = &e.params;
    let fov = p.float("fov", 90.0)?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(p.get("fov").map_or_else(
            || e.loc.error("bad fov"),
            |q| q.error("must be in (0, 180)"),
        ));
    }
    let aspect = p.float("frameaspectratio", aspect)?;
    let default_half_height = if aspect >= 1.0 { 1.0 } else { 1.0 / aspect };
    let half_height = match p.floats("screenwindow")? {
        None => default_half_height,
        Some(&[x0, x1, y0, y1]) => {
            if (x0 + x1).abs() > 1e-6 || (y0 + y1).abs() > 1e-6 {
                w.add(
                    "an off-centre 'screenwindow' is not supported; centred",
                    &e.loc,
                );
            }
            let (hw, hh) = (0.5 * (x1 - x0), 0.5 * (y1 - y0));
            if hh <= 0.0 || hw <= 0.0 {
                return Err(p
                    .get("screenwindow")
                    .expect("present")
                    .error("the window is empty"));
            }
            if (hw / hh - aspect).abs() > 1e-3 * aspect {
                w.add(
                    "a 'screenwindow' of another aspect ratio than the image: its height is kept",
                    &e.loc,
                );
            }
            hh
        }
        Some(v) => {
            return Err(p
                .get("screenwindow")
                .expect("present")
                .error(format!("expected 4 values, found {}", v.len())))
        }
    };
    // pbrt's fov spans the shorter image axis, which the screen window's
    // unit spans.
    let tan_half = (fov.to_radians() * 0.5).tan() * half_height;
    let vfov = (2.0 * tan_half.atan()).to_degrees();
    let lens = p.float("lensradius", 0.0)?;
    let focus = p.float("focaldistance", 1e6)?;
    let open = p.float("shutteropen", 0.0)?;
    let close = p.float("shutterclose", 1.0)?;
    if close < open {
        return Err(e.loc.error("shutterclose is before shutteropen"));
    }
    unknown_params(&e, "camera", w);
    let f = |v: DVec3| v.as_vec3();
    let mut c = Camera::look_at(f(eye), f(eye + fwd), f(up), vfov as f32, aspect as f32)
        .with_thin_lens(lens.max(0.0) as f32, focus as f32)
        .with_shutter(open as f32, close as f32);
    c.right = f(right);
    c.up = f(up);
    c.forward = f(fwd);
    Ok((c, (open, close)))
}

/// The error of film parameter `name` holding `found` values, not 4.
fn not_four(f: &Entity, name: &str, found: usize) -> FormatError {
    let p = f.params.get(name).expect("present");
    p.error(format!("expected 4 values, found {found}"))
}

/// The part of the image a film renders: its `cropwindow` (clamped to
/// [0, 1], each pair in either order) or else its `pixelbounds` (clipped
/// to the image), as pbrt-v4 decides; an empty one is an error.
fn film_crop(
    f: &Entity,
    width: i64,
    height: i64,
    w: &mut Warnings,
) -> Result<Option<FileCrop>, FormatError> {
    let crop = match f.params.floats("cropwindow")? {
        Some(&[a, b, c, d]) => {
            if f.params.has("pixelbounds") {
                w.add(
                    "film: both 'cropwindow' and 'pixelbounds' given; the crop window is used",
                    &f.loc,
                );
                f.params.get("pixelbounds");
            }
            let outside = [a, b, c, d].iter().any(|v| !(0.0..=1.0).contains(v));
            if outside {
                w.add("film 'cropwindow' reaches outside [0, 1]; clamped", &f.loc);
            }
            let c01 = |v: f64| v.clamp(0.0, 1.0);
            Some(FileCrop::Fractions([
                c01(a.min(b)),
                c01(a.max(b)),
                c01(c.min(d)),
                c01(c.max(d)),
            ]))
        }
        Some(v) => return Err(not_four(f, "cropwindow", v.len())),
        None => match f.params.ints("pixelbounds")? {
            Some(&[x0, x1, y0, y1]) => {
                let b = [x0 as i64, x1 as i64, y0 as i64, y1 as i64];
                if b[0] < 0 || b[2] < 0 || b[1] > width || b[3] > height {
                    w.add(
                        "film 'pixelbounds' reach outside the image; clipped",
                        &f.loc,
                    );
                }
                Some(FileCrop::Pixels(b))
            }
            Some(v) => return Err(not_four(f, "pixelbounds", v.len())),
            None => None,
        },
    };
    if let Some(c) = crop {
        if c.window(width as u32, height as u32).is_empty() {
            let name = if matches!(c, FileCrop::Fractions(_)) {
                "cropwindow"
            } else {
                "pixelbounds"
            };
            return Err(f
                .params
                .get(name)
                .expect("present")
                .error(format!("holds no pixel of the {width}x{height} image")));
        }
    }
    Ok(crop)
}

/// The render settings of `Film`, `Sampler`, `PixelFilter` and `Integrator`.
fn settings(
    desc: &Declarations,
    folder: &Path,
    w: &mut Warnings,
) -> Result<SettingsLayer, FormatError> {
    let film = film(desc, folder, w)?;
    let (mut spp, sampler, seed) = sampler(desc, w)?;
    let filter = pixel_filter(desc, w)?;
    let integrator = integrator(desc, &mut spp, w)?;
    // pbrt's defaults are what a file without a directive says: every
    // frame setting is given.
    Ok(SettingsLayer {
        frame: FrameLayer {
            width: Some(film.width as u32),
            height: Some(film.height as u32),
            spp: Some(spp as u32),
            seed: Some(seed),
            sampler: Some(sampler),
            filter: Some(Pick::Value(filter)),
            integrator: Some(Pick::Value(integrator)),
            ..Default::default()
        },
        output: OutputLayer {
            exposure: Some(film.exposure),
            ..Default::default()
        },
        path: film.output,
        crop_window: film.crop,
        ..Default::default()
    })
}

/// What `Film` sets: the image size, the output file, the exposure and the crop.
struct Film {
    width: i64,
    height: i64,
    output: Option<PathBuf>,
    exposure: f32,
    crop: Option<FileCrop>,
}

/// The settings of `Film` (pbrt's defaults without one).
fn film(desc: &Declarations, folder: &Path, w: &mut Warnings) -> Result<Film, FormatError> {
    let mut width = 1280i64;
    let mut height = 720i64;
    let mut output = None;
    let mut exposure = 0.0f32;
    let mut crop = None;
    if let Some(f) = &desc.film {
        if !["rgb", "gbuffer", "spectral", "image"].contains(&f.kind.as_str()) {
            return Err(f.loc.error(format!("unknown film type '{}'", f.kind)));
        }
        width = f.params.int("xresolution", 1280)?;
        height = f.params.int("yresolution", 720)?;
        for (k, v) in [("xresolution", width), ("yresolution", height)] {
            if !(1..=65536).contains(&v) {
                return Err(f
                    .params
                    .get(k)
                    .expect("present")
                    .error("must be in 1..=65536"));
            }
        }
        if let Some(name) = f.params.string("filename")? {
            let mut p = folder.join(name);
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase());
            if !matches!(ext.as_deref(), Some("png" | "exr")) {
                w.add(
                    format!("film filename \"{name}\": Sahara writes .png or .exr; .exr used"),
                    &f.loc,
                );
                p.set_extension("exr");
            }
            output = Some(p);
        }
        crop = film_crop(f, width, height, w)?;
        let iso = f.params.float("iso", 100.0)?;
        if iso > 0.0 {
            exposure = (iso / 100.0).log2() as f32;
        }
        let ev = f.params.float("exposure", 0.0)?;
        exposure += ev as f32;
        for k in [
            "diagonal",
            "maxcomponentvalue",
            "savefp16",
            "sensor",
            "whitebalance",
            "writefp16",
            "scale",
        ] {
            if f.params.get(k).is_some() && k != "diagonal" && k != "savefp16" && k != "writefp16" {
                w.add(format!("film '{k}' is not supported; ignored"), &f.loc);
            }
        }
        unknown_params(f, "film", w);
    }
    Ok(Film {
        width,
        height,
        output,
        exposure,
        crop,
    })
}

/// The settings of `Sampler`: samples per pixel, the sampler and its seed.
fn sampler(desc: &Declarations, w: &mut Warnings) -> Result<(i64, SamplerKind, u64), FormatError> {
    let mut spp = 16i64;
    let mut sampler = SamplerKind::Sobol;
    let mut seed = 0u64;
    if let Some(s) = &desc.sampler {
        spp = s.params.int("pixelsamples", 16)?;
        sampler = match s.kind.as_str() {
            "independent" | "random" => SamplerKind::Independent,
            "stratified" => {
                let (x, y) = (s.params.int("xsamples", 4)?, s.params.int("ysamples", 4)?);
                s.params.bool("jitter", true)?;
                spp = x.saturating_mul(y);
                SamplerKind::Stratified
            }
            "sobol" | "zsobol" | "paddedsobol" | "halton" | "pmj02bn" | "lowdiscrepancy"
            | "02sequence" | "maxmindist" => SamplerKind::Sobol,
            other => return Err(s.loc.error(format!("unknown sampler type '{other}'"))),
        };
        if !matches!(
            s.kind.as_str(),
            "independent" | "random" | "stratified" | "sobol" | "zsobol" | "paddedsobol"
        ) {
            w.add(
                format!(
                    "sampler '{}' is replaced by Sahara's Owen-scrambled Sobol sampler",
                    s.kind
                ),
                &s.loc,
            );
        }
        seed = s.params.int("seed", 0)?.max(0) as u64;
        s.params.get("randomization");
        unknown_params(s, "sampler", w);
    }
    if !(1..=1 << 24).contains(&spp) {
        return Err(desc.sampler.as_ref().map_or_else(
            || FormatError::in_file("", "bad spp"),
            |s| s.loc.error("pixel samples must be in 1..=16777216"),
        ));
    }
    Ok((spp, sampler, seed))
}

/// The `PixelFilter` (pbrt's Gaussian without one).
fn pixel_filter(desc: &Declarations, w: &mut Warnings) -> Result<Filter, FormatError> {
    let filter = match &desc.filter {
        None => Filter::Gaussian {
            radius: 1.5,
            sigma: 0.5,
        },
        Some(f) => {
            let mut radius = |d: f64| -> Result<f32, FormatError> {
                // pbrt-v3 calls the radii xwidth and ywidth.
                let x = f.params.float("xwidth", d)?;
                let y = f.params.float("ywidth", d)?;
                let x = f.params.float("xradius", x)?;
                let y = f.params.float("yradius", y)?;
                let r = f.params.float("radius", x.max(y))?;
                if (x - y).abs() > 1e-9 {
                    w.add(
                        "a filter with different x and y radii uses the larger",
                        &f.loc,
                    );
                }
                if r <= 0.0 {
                    return Err(f.loc.error("filter radius must be > 0"));
                }
                Ok(r as f32)
            };
            let out = match f.kind.as_str() {
                "box" => Filter::Box {
                    radius: radius(0.5)?,
                },
                "triangle" => Filter::Tent {
                    radius: radius(2.0)?,
                },
                "gaussian" => {
                    let r = radius(1.5)?;
                    let sigma = match f.params.float_opt("alpha")? {
                        // pbrt-v3: exp(-alpha x^2), alpha = 1 / (2 sigma^2).
                        Some(a) if a > 0.0 => (1.0 / (2.0 * a)).sqrt(),
                        _ => f.params.float("sigma", 0.5)?,
                    };
                    Filter::Gaussian {
                        radius: r,
                        sigma: sigma.max(1e-3) as f32,
                    }
                }
                "mitchell" => Filter::Mitchell {
                    radius: radius(2.0)?,
                    b: f.params.float("B", 1.0 / 3.0)? as f32,
                    c: f.params.float("C", 1.0 / 3.0)? as f32,
                },
                "sinc" | "lanczos" => {
                    for k in ["tau", "xradius", "yradius"] {
                        f.params.get(k);
                    }
                    w.add(
                        format!("pixel filter '{}' is replaced by a Gaussian", f.kind),
                        &f.loc,
                    );
                    Filter::Gaussian {
                        radius: 1.5,
                        sigma: 0.5,
                    }
                }
                other => return Err(f.loc.error(format!("unknown pixel filter '{other}'"))),
            };
            unknown_params(f, "pixel filter", w);
            out
        }
    };
    Ok(filter)
}

/// The `Integrator` (pbrt's path tracer without one); SPPM's
/// `iterations` replace `spp`.
fn integrator(
    desc: &Declarations,
    spp: &mut i64,
    w: &mut Warnings,
) -> Result<Integrator, FormatError> {
    let integrator = match &desc.integrator {
        None => Integrator::Path {
            max_depth: 5,
            rr_depth: 3,
        },
        Some(i) => {
            let depth = i.params.int("maxdepth", 5)?;
            if depth < 1 {
                w.add("integrator maxdepth < 1 (emission only) is rendered with maxdepth 1 (direct light)", &i.loc);
            }
            let max_depth = depth.clamp(1, 1 << 16) as u32;
            for k in [
                "regularize",
                "lightsampler",
                "samplelights",
                "samplebsdf",
                "clamp",
                "maxcomponentvalue",
            ] {
                i.params.get(k);
            }
            let out = match i.kind.as_str() {
                "path" | "volpath" => Integrator::Path {
                    max_depth,
                    rr_depth: 3,
                },
                "bdpt" => {
                    for k in ["visualizestrategies", "visualizeweights"] {
                        if i.params.bool(k, false)? {
                            w.add(format!("integrator 'bdpt' {k} is not drawn"), &i.loc);
                        }
                    }
                    Integrator::Bdpt { max_depth }
                }
                "lightpath" => Integrator::LightPath { max_depth },
                "mlt" => {
                    w.add(
                        "integrator 'mlt' is rendered by bidirectional path tracing (bdpt), \
                         which converges to the same image",
                        &i.loc,
                    );
                    i.params.mark_all_used();
                    Integrator::Bdpt { max_depth }
                }
                "sppm" => {
                    // pbrt-v4's SPPM takes its iteration count from here,
                    // not from the sampler.
                    let iterations = i.params.int("iterations", *spp)?;
                    if iterations < 1 {
                        return Err(i
                            .loc
                            .error("integrator 'sppm': iterations must be at least 1"));
                    }
                    *spp = iterations;
                    let radius = i.params.float("radius", 1.0)?;
                    if !(radius.is_finite() && radius > 0.0) {
                        return Err(i
                            .loc
                            .error("integrator 'sppm': radius must be a positive number"));
                    }
                    let photons = i.params.int("photonsperiteration", -1)?;
                    for k in ["seed", "imagewritefrequency"] {
                        i.params.get(k);
                    }
                    Integrator::Sppm {
                        max_depth,
                        radius: radius as f32,
                        photons: photons.clamp(0, u32::MAX as i64) as u32,
                    }
                }
                "simplepath" | "simplevolpath" | "randomwalk" => {
                    w.add(
                        format!(
                            "integrator '{}' is replaced by Sahara's path tracer",
                            i.kind
                        ),
                        &i.loc,
                    );
                    i.params.mark_all_used();
                    Integrator::Path {
                        max_depth,
                        rr_depth: 3,
                    }
                }
                "directlighting" | "whitted" => Integrator::Distribution {
                    max_depth,
                    light_samples: 4,
                },
                "ambientocclusion" => {
                    let d = i.params.float("maxdistance", 0.0)?;
                    i.params.bool("cossample", true)?;
                    Integrator::Ao {
                        samples: 4,
                        distance: if d.is_finite() && d > 0.0 {
                            d as f32
                        } else {
                            0.0
                        },
                    }
                }
                other => return Err(i.loc.error(format!("unknown integrator '{other}'"))),
            };
            unknown_params(i, "integrator", w);
            out
        }
    };
    Ok(integrator)
}

/// One shape's mesh in object space, oriented, or `None` if it is not rendered.
fn oriented_geometry(
    s: &ShapeDecl,
    m: &DMat4,
    w: &mut Warnings,
) -> Result<Option<(SceneMesh, Option<Shape>)>, FormatError> {
    let Some(g) = shape_geometry(&s.entity, w)? else {
        unknown_params(&s.entity, "shape", w);
        return Ok(None);
    };
    unknown_params(&s.entity, "shape", w);
    let mut mesh = g.mesh;
    let mirror = swaps_handedness(m);
    orient(&mut mesh, s.reverse, mirror);
    let flipped = s.reverse != mirror;
    let exact = match g.exact {
        Some(Shape::Disc {
            center,
            normal,
            radius,
        }) => Some(Shape::Disc {
            center,
            normal: if s.reverse { -normal } else { normal },
            radius,
        }),
        Some(Shape::Sphere { .. }) if flipped => None,
        other => other,
    };
    Ok(Some((mesh, exact)))
}

/// The scene description of `desc`, read from the file `name` in `folder`:
/// settings and camera, media, shapes, object instances, lights.
pub(crate) fn build(
    desc: &Declarations,
    name: &str,
    folder: &Path,
    w: &mut Warnings,
) -> Result<SceneDescription, FormatError> {
    let settings = settings(desc, folder, w)?;
    let size = |side: Option<u32>| f64::from(side.unwrap_or(1));
    let aspect = size(settings.frame.width) / size(settings.frame.height);
    let (camera, shutter) = camera(desc, aspect, w)?;
    let mut scene = SceneDescription::new(name);
    scene.camera = CameraRequest::Given {
        camera,
        source: String::new(),
    };
    scene.settings = Some(settings);
    let mut materials = Materials {
        desc,
        textures: Textures::new(&desc.textures),
        anonymous: HashMap::new(),
        named: HashMap::new(),
        default: None,
        cut: HashMap::new(),
        subsurface: HashMap::new(),
    };
    for (what, loc) in &desc.ignored {
        w.add(format!("{what} is not supported; ignored"), loc);
    }
    let media = add_media(&desc.media, &mut scene, w)?;
    if let Some(d) = &desc.camera_medium {
        scene.camera_medium = interface(&media, d)?.1;
    }
    let timing = (desc.transform_times, shutter);
    for s in &desc.shapes {
        add_shape(s, &media, timing, &mut scene, &mut materials, w)?;
    }
    add_instances(desc, timing, &mut scene, &mut materials, w)?;
    for l in &desc.lights {
        add_light(&mut scene, l, w)?;
        unknown_params(&l.entity, "light", w);
    }
    Ok(scene)
}

/// The transform times of a file and the camera's shutter interval, which
/// place moving things.
type Timing = ((f64, f64), (f64, f64));

/// Adds shape `s` to `scene` as an object with its material, area light
/// and medium interface (`media`: the file's media by name); nothing for a
/// shape that is not rendered.
fn add_shape(
    s: &ShapeDecl,
    media: &HashMap<String, u32>,
    (times, shutter): Timing,
    scene: &mut SceneDescription,
    materials: &mut Materials,
    w: &mut Warnings,
) -> Result<(), FormatError> {
    let m = s.xform.m[0];
    let Some((material, medium_interface)) = surface(s, media, scene, materials, w)? else {
        return Ok(());
    };
    let Some((mesh, exact)) = oriented_geometry(s, &m, w)? else {
        return Ok(());
    };
    let material = match (&s.area_light, material) {
        (None, material) => material,
        (Some(a), None) => {
            w.add(
                "area lights on shapes with an 'interface' material do not emit",
                &a.loc,
            );
            a.params.mark_all_used();
            None
        }
        (Some(a), Some(material)) => Some(emitting(a, material, &mesh, &m, scene, w)?),
    };
    let placement = placement(&s.xform, times, shutter);
    let geometry = match (exact, placement) {
        (Some(shape), ObjectPlacement::Static(_)) => Geometry::Shape(shape),
        _ if mesh.mesh.indices.is_empty() => return Ok(()),
        _ => Geometry::Mesh(scene.add_mesh(mesh)),
    };
    scene.objects.push(Object {
        geometry,
        placement,
        material,
        name: None,
    });
    if let Some(mi) = medium_interface {
        let k = scene.objects.len() as u32 - 1;
        scene.medium_interfaces.push((k, mi));
    }
    Ok(())
}

/// A shape's material (`None`: no surface) and the media on its sides.
type Surface = (Option<u32>, Option<MediumInterface>);

/// What shape `s` is made of: its material (`None`: no surface, an
/// index-matched boundary between two media) and the media on its sides.
/// `None` when the shape is not rendered (its geometry is still read, for
/// its warnings).
fn surface(
    s: &ShapeDecl,
    media: &HashMap<String, u32>,
    scene: &mut SceneDescription,
    materials: &mut Materials,
    w: &mut Warnings,
) -> Result<Option<Surface>, FormatError> {
    // pbrt's media on the shape's sides; equal sides are no boundary.
    let sides = match &s.media {
        Some(d) => Some(interface(media, d)?),
        None => None,
    };
    let transition = sides.filter(|(inside, outside)| inside != outside);
    Ok(match materials.resolve(scene, &s.material, w)? {
        None => match transition {
            // No surface between two media: an index-matched boundary.
            Some((inside, outside)) => Some((
                None,
                Some(MediumInterface {
                    inside,
                    outside,
                    index_matched: true,
                }),
            )),
            None => {
                w.add(
                    "shapes with an 'interface' material (no surface) and no media \
                         to bound are not rendered",
                    &s.entity.loc,
                );
                shape_geometry(&s.entity, w)?;
                None
            }
        },
        Some(material) => {
            let inner = materials.subsurface.get(&material).copied();
            let Some(material) = materials.cut(scene, material, &s.entity, w)? else {
                shape_geometry(&s.entity, w)?;
                return Ok(None);
            };
            let mi = match inner {
                Some(inner) => Some(MediumInterface {
                    inside: Some(inner),
                    outside: sides.and_then(|(_, outside)| outside),
                    index_matched: false,
                }),
                None => transition.map(|(inside, outside)| MediumInterface {
                    inside,
                    outside,
                    index_matched: false,
                }),
            };
            Some((Some(material), mi))
        }
    })
}

/// `material` emitting as area light `a` says, on `mesh` under transform
/// `m` (a power is spread over the mesh's area in the world): the index of
/// the emitting copy added to `scene`.
fn emitting(
    a: &Entity,
    material: u32,
    mesh: &SceneMesh,
    m: &DMat4,
    scene: &mut SceneDescription,
    w: &mut Warnings,
) -> Result<u32, FormatError> {
    let em = area_emission(a, w)?;
    unknown_params(a, "area light", w);
    let mut radiance = em.radiance;
    if let Some(power) = em.power {
        let sides = if em.two_sided { 2.0 } else { 1.0 };
        let area = world_area(mesh, m);
        if area > 0.0 {
            radiance *= (power / (std::f64::consts::PI * area * sides)) as f32;
        }
    }
    let mut mat = scene.materials[material as usize]
        .clone()
        .with_emission(radiance);
    mat.two_sided_emission = em.two_sided;
    Ok(scene.add_material(mat))
}

/// Adds the file's object instances to `scene`, each object's shapes made
/// one mesh on first use; warns of objects never instanced.
fn add_instances(
    desc: &Declarations,
    (times, shutter): Timing,
    scene: &mut SceneDescription,
    materials: &mut Materials,
    w: &mut Warnings,
) -> Result<(), FormatError> {
    let mut objects: HashMap<&str, Option<u32>> = HashMap::new();
    for inst in &desc.instances {
        let mesh = match objects.get(inst.name.as_str()) {
            Some(m) => *m,
            None => {
                let Some((shapes, _)) = desc.objects.get(&inst.name) else {
                    return Err(inst.loc.error(format!(
                        "ObjectInstance of unknown object \"{}\"",
                        inst.name
                    )));
                };
                let m = object_mesh(scene, shapes, materials, w)?;
                objects.insert(inst.name.as_str(), m);
                m
            }
        };
        let Some(mesh) = mesh else { continue };
        scene.objects.push(Object {
            geometry: Geometry::Mesh(mesh),
            placement: placement(&inst.xform, times, shutter),
            material: None,
            name: Some(inst.name.clone()),
        });
    }
    for (name, (_, loc)) in &desc.objects {
        if !objects.contains_key(name.as_str()) {
            w.add(format!("object \"{name}\" is never instanced"), loc);
        }
    }
    Ok(())
}

/// The one mesh of an object: its shapes with their transforms applied,
/// a material per triangle; `None` if nothing in it is rendered.
fn object_mesh(
    scene: &mut SceneDescription,
    shapes: &[ShapeDecl],
    materials: &mut Materials,
    w: &mut Warnings,
) -> Result<Option<u32>, FormatError> {
    let mut out = SceneMesh::default();
    let mut ids = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut uvs: Vec<glam::Vec2> = Vec::new();
    let (mut any_normals, mut any_uvs) = (false, false);
    for s in shapes {
        if s.xform.is_animated() {
            w.add(
                "moving shapes inside an object definition use their start transform",
                &s.entity.loc,
            );
        }
        if s.media.is_some() {
            w.add(
                "media on shapes inside an object definition are not supported; \
                 the shapes bound no media",
                &s.entity.loc,
            );
        }
        if s.area_light.is_some() {
            w.add("area lights inside an object definition are not supported (as in pbrt); they do not emit", &s.entity.loc);
        }
        let m = s.xform.m[0];
        let Some(material) = materials.resolve(scene, &s.material, w)? else {
            w.add(
                "shapes with an 'interface' material (no surface) are not rendered",
                &s.entity.loc,
            );
            shape_geometry(&s.entity, w)?;
            continue;
        };
        let Some(material) = materials.cut(scene, material, &s.entity, w)? else {
            shape_geometry(&s.entity, w)?;
            continue;
        };
        let Some((mesh, _)) = oriented_geometry(s, &m, w)? else {
            continue;
        };
        let base = out.mesh.positions.len();
        let Ok(base32) = u32::try_from(base) else {
            return Err(s.entity.loc.error("the object has more than 2^32 vertices"));
        };
        let mf: Mat4 = m.as_mat4();
        let normal_m = glam::Mat3::from_mat4(mf).inverse().transpose();
        out.mesh
            .positions
            .extend(mesh.mesh.positions.iter().map(|&p| mf.transform_point3(p)));
        out.mesh
            .indices
            .extend(mesh.mesh.indices.iter().map(|t| t.map(|i| i + base32)));
        ids.extend(std::iter::repeat_n(material, mesh.mesh.indices.len()));
        // Shapes without normals get smooth ones from their faces and
        // shapes without uvs get zeros, so the arrays stay parallel.
        normals.resize(base, Vec3::ZERO);
        uvs.resize(base, glam::Vec2::ZERO);
        match &mesh.normals {
            Some(n) => {
                any_normals = true;
                normals.extend(n.iter().map(|&v| (normal_m * v).normalize_or_zero()));
            }
            None => normals.extend(
                smooth_normals(&mesh.mesh.positions, &mesh.mesh.indices)
                    .into_iter()
                    .map(|v| (normal_m * v).normalize_or_zero()),
            ),
        }
        match &mesh.uvs {
            Some(u) => {
                any_uvs = true;
                uvs.extend(u.iter().copied());
            }
            None => uvs.extend(std::iter::repeat_n(
                glam::Vec2::ZERO,
                mesh.mesh.positions.len(),
            )),
        }
    }
    if out.mesh.indices.is_empty() {
        return Ok(None);
    }
    out.normals = any_normals.then_some(normals);
    out.uvs = any_uvs.then_some(uvs);
    out.material_ids = Some(ids);
    Ok(Some(scene.add_mesh(out)))
}
