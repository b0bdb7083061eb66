//! Scene files as descriptions: a [`SceneFile`] becomes a
//! [`SceneDescription`] (with the file's render settings).
//!
//! - `[[object]]`s are objects in file order: a mesh file (its own
//!   materials unless the object names one; a PLY or a built-in shape
//!   gets the grey default), or a built-in shape; `motion` gives a moving
//!   placement, interpolated over the shutter interval.
//! - `[[material]]`s are the description's materials in file order, their
//!   textures read here (a texture that cannot be read is a warning).
//! - `[[light]]`s: point, spot and directional lights as they are; an area
//!   light is a shape in world space whose material emits (its named
//!   material's surface, or black); an environment is the description's.

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;
use sahara_readers::FormatError;
use sahara_render::Encoding;
use sahara_render::{Camera, Environment, Material, Shape, Texture, TextureMap};

use super::file::{CameraSpec, EnvironmentSpec, LightSpec, MaterialSpec, SceneFile, ShapeSpec};
use crate::common::image::load_rgb_f32;
use crate::common::materials::TextureCache;
use crate::description::{CameraRequest, Geometry, Object, ObjectPlacement, SceneDescription};

use super::placement::placement;

/// The description of a parsed scene file; `name` (the scene file) is
/// used in messages.
pub fn describe(file: &SceneFile, name: &str) -> Result<SceneDescription, FormatError> {
    let settings = file.settings.clone();
    // `[film]` gives both sides.
    let frame = &settings.frame;
    let aspect = frame.width.unwrap_or(1) as f32 / frame.height.unwrap_or(1) as f32;
    let mut desc = SceneDescription::new(name);
    desc.camera = CameraRequest::Given {
        camera: camera_of(&file.camera, aspect),
        source: String::new(),
    };
    desc.settings = Some(settings);
    desc.sky = file.sky.clone();
    let mut named = HashMap::new();
    let mut textures = TextureCache::new();
    for m in &file.materials {
        let material = material_of(m, &mut textures, &mut desc.warnings, name);
        let id = desc.add_named_material(&m.name, material);
        named.insert(m.name.as_str(), id);
    }
    for o in &file.objects {
        // The resolver checked that the name exists.
        let material = o.material.as_deref().and_then(|n| named.get(n).copied());
        let geometry = match &o.shape {
            ShapeSpec::Mesh { path } => Geometry::File(path.clone()),
            ShapeSpec::Builtin(shape) => Geometry::Shape(*shape),
        };
        if let Some(mi) = o.interface {
            desc.medium_interfaces.push((desc.objects.len() as u32, mi));
        }
        desc.objects.push(Object {
            geometry,
            placement: placement(&o.placement),
            material,
            name: o.name.clone(),
        });
    }
    desc.media = file.media.iter().map(|m| m.medium.clone()).collect();
    desc.camera_medium = file.camera_medium;
    for l in &file.lights {
        add_light(&mut desc, l, &named, name)?;
    }
    Ok(desc)
}

/// The thin-lens camera of `[camera]`.
pub fn camera_of(c: &CameraSpec, aspect: f32) -> Camera {
    Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, aspect)
        .with_thin_lens(c.aperture_radius, c.focus_distance)
        .with_shutter(c.shutter_open, c.shutter_close)
}

/// The renderer material of a `[[material]]`, with its texture if it has
/// one (a texture that cannot be read is a warning); the texture's alpha
/// channel, if any, cuts out holes when the material's alpha mode says so.
fn material_of(
    m: &MaterialSpec,
    textures: &mut TextureCache,
    warnings: &mut Vec<String>,
    name: &str,
) -> Material {
    let mut out = m.material.clone();
    if let Some(path) = &m.texture {
        let mut problems = Vec::new();
        out.textures.base_color = textures
            .file(path, Encoding::Srgb, &mut problems)
            .map(TextureMap::new);
        warnings.extend(
            problems
                .into_iter()
                .map(|p| format!("{name}: material '{}': {p}", m.name)),
        );
    }
    out
}

/// Adds a `[[light]]`: explicit lights, emissive shapes, or the environment.
///
/// An area light with a `material` scatters light with that material's BSDF
/// (and texture) besides emitting its own radiance; without one its surface
/// is black but for the emission.
fn add_light(
    desc: &mut SceneDescription,
    l: &LightSpec,
    named: &HashMap<&str, u32>,
    name: &str,
) -> Result<(), FormatError> {
    match l {
        LightSpec::Explicit(light) => desc.lights.push(*light),
        LightSpec::Area {
            shape,
            radiance,
            two_sided,
            material,
        } => {
            let shape = area_shape(shape).ok_or_else(|| {
                FormatError::in_file(name, "an area light's shape is quad, disc or sphere")
            })?;
            // The resolver checked that the name exists.
            let surface = material.as_deref().and_then(|n| named.get(n));
            let mut m = match surface {
                Some(&id) => desc.materials[id as usize].clone().with_emission(*radiance),
                None => Material::emitter(*radiance),
            };
            m.two_sided_emission = *two_sided;
            let m = desc.add_material(m);
            desc.objects.push(Object {
                geometry: Geometry::Shape(shape),
                placement: ObjectPlacement::World,
                material: Some(m),
                name: None,
            });
        }
        LightSpec::Environment(EnvironmentSpec::Constant(c)) => {
            desc.environment = Some(Environment::Constant(*c));
        }
        LightSpec::Environment(EnvironmentSpec::Map { path, scale }) => {
            let (w, h, rgb) = load_rgb_f32(path)?;
            if w == 0 || h == 0 {
                return Err(FormatError::in_file(
                    &path.display().to_string(),
                    "the environment map is empty",
                ));
            }
            let texels = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
            desc.environment = Some(Environment::Map {
                texture: Arc::new(Texture::new(w, h, texels)),
                scale: *scale,
            });
        }
    }
    Ok(())
}

/// The shape of an area light (`None` for a mesh file).
fn area_shape(spec: &ShapeSpec) -> Option<Shape> {
    match *spec {
        ShapeSpec::Mesh { .. } => None,
        ShapeSpec::Builtin(shape) => Some(shape),
    }
}
