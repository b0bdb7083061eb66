//! Scene files as renderer scenes: a [`SceneFile`] becomes a
//! [`sahara_render::Scene`] plus the file's render settings.
//!
//! - Mesh files are loaded once each by a [`MeshLibrary`], however many
//!   objects use them: objects only add instances (glTF nodes add one
//!   instance per node, placed by the object's transform times the node's).
//! - An object with `material = "name"` overrides a mesh's own materials;
//!   without it a mesh keeps its MTL / glTF materials (mapped as
//!   [`crate::material_map`] describes) and a PLY or a built-in shape gets
//!   the grey default.
//! - `motion` gives a moving instance (`Placement::Moving`) interpolated
//!   over the shutter interval.
//! - Built-in shapes and area lights go through [`Scene::add_shape`] where
//!   possible, so emissive quads, discs and spheres are sampled
//!   analytically (see [`shapes`]).
//! - Problems that still allow rendering (a missing MTL file or texture)
//!   are warnings in [`LoadedScene::warnings`].

mod placement;
pub mod settings;
pub mod shapes;

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec3};
use sahara_render::Encoding;
use sahara_render::{
    Bsdf, Camera, Environment, Instance, Light, Material, Scene, Texture, TextureMap,
};

use crate::gltf_scene::gltf_light;
use crate::image_in::load_rgb_f32;
use crate::material_map::TextureCache;
use crate::mesh_library::{file_key, MeshLibrary};
use crate::scene_file::{
    load_scene_file, CameraSpec, EnvironmentSpec, LightSpec, MaterialKind, MaterialSpec,
    Placement as PlacementSpec, SceneFile, ShapeSpec,
};
use crate::sky::Sky;
use crate::FormatError;

pub use placement::{placement, srt};
pub use settings::{FileCrop, FileSettings};

/// A scene ready to render, with how its file asks for it to be rendered.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene (camera aspect from the film size).
    pub scene: Scene,
    /// Integrator, sampler, filter and film of the file.
    pub settings: FileSettings,
    /// Problems that did not stop loading, one line each, naming the file.
    pub warnings: Vec<String>,
}

/// Reads a scene file and builds its scene (meshes, textures and maps read relative to it).
pub fn load_scene(path: &Path) -> Result<LoadedScene, FormatError> {
    load_scene_with_sky(path, None)
}

/// Reads a scene file as [`load_scene`] does, lit by `sky` instead of the
/// file's `sky` key if given.
pub fn load_scene_with_sky(path: &Path, sky: Option<&Sky>) -> Result<LoadedScene, FormatError> {
    let mut file = load_scene_file(path)?;
    if let Some(sky) = sky {
        file.sky = sky.clone();
    }
    build_scene(&file, &path.display().to_string())
}

/// Builds the scene of a parsed scene file; `name` (the scene file) is used in messages.
pub fn build_scene(file: &SceneFile, name: &str) -> Result<LoadedScene, FormatError> {
    let settings =
        FileSettings::from_specs(&file.integrator, &file.sampler, &file.filter, &file.film);
    let aspect = settings.width as f32 / settings.height as f32;
    let mut scene = Scene::new(camera_of(&file.camera, aspect));
    let mut library = MeshLibrary::new();

    let mut named = HashMap::new();
    let mut textures = TextureCache::new();
    for m in &file.materials {
        let id = scene.add_material(material_of(m, &mut textures, &mut library.warnings, name));
        named.insert(m.name.as_str(), id);
    }
    // Files some object shows with their own materials.
    let own: HashSet<_> = file
        .objects
        .iter()
        .filter(|o| o.material.is_none())
        .filter_map(|o| match &o.shape {
            ShapeSpec::Mesh { path } => Some(file_key(path)),
            _ => None,
        })
        .collect();
    let mut moving_emitters = 0;
    for (k, o) in file.objects.iter().enumerate() {
        // The resolver checked that the name exists.
        let material = o.material.as_deref().and_then(|n| named.get(n).copied());
        match &o.shape {
            ShapeSpec::Mesh { path } => {
                let f = library
                    .load(&mut scene, path, own.contains(&file_key(path)))
                    .map_err(|e| FormatError::in_file(name, format!("object {}: {e}", k + 1)))?;
                for part in &f.parts {
                    scene.add_instance(Instance {
                        mesh: part.mesh,
                        placement: placement(&o.placement, part.transform),
                        material: material.or(f.material),
                    });
                }
                // A glTF file's lights, where the object puts the file
                // (where it starts, if it moves).
                let at = placement(&o.placement, Mat4::IDENTITY).at(0.0);
                for l in &f.lights {
                    scene.add_light(gltf_light(l, Mat4::from(at)));
                }
                if matches!(o.placement, PlacementSpec::Motion { .. })
                    && material.map_or(f.emissive, |m| is_emissive(&scene, m))
                {
                    moving_emitters += 1;
                }
            }
            spec => {
                let shape = shapes::shape_of(spec).expect("not a mesh");
                let material = match material {
                    Some(m) => m,
                    None => library.default_material(&mut scene),
                };
                if matches!(o.placement, PlacementSpec::Motion { .. })
                    && is_emissive(&scene, material)
                {
                    moving_emitters += 1;
                }
                shapes::add_placed_shape(
                    &mut scene,
                    shape,
                    placement(&o.placement, Mat4::IDENTITY),
                    material,
                );
            }
        }
    }
    if moving_emitters > 0 {
        library.warnings.push(format!(
            "{name}: {moving_emitters} moving object(s) emit light: they are seen, but not sampled as lights"
        ));
    }
    for l in &file.lights {
        add_light(&mut scene, l, &named, name)?;
    }
    scene.generate_tangents();
    crate::sky::apply(&mut scene, &file.sky)
        .map_err(|e| FormatError::in_file(name, format!("sky: {e}")))?;
    // A scene without light is reported by `Scene::diagnostics`, with the
    // other problems of the finished scene.
    let warnings = std::mem::take(&mut library.warnings);
    Ok(LoadedScene {
        scene,
        settings,
        warnings,
    })
}

/// True if material `id` of `scene` emits.
fn is_emissive(scene: &Scene, id: u32) -> bool {
    scene.materials[id as usize].is_emissive()
}

/// The thin-lens camera of `[camera]`.
pub fn camera_of(c: &CameraSpec, aspect: f32) -> Camera {
    Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, aspect)
        .with_thin_lens(c.aperture_radius, c.focus_distance)
        .with_shutter(c.shutter_open, c.shutter_close)
}

/// The renderer material of a `[[material]]` (a texture that cannot be
/// read is a warning); its texture's alpha channel, if any, cuts out
/// holes when the material's alpha mode says so.
fn material_of(
    m: &MaterialSpec,
    textures: &mut TextureCache,
    warnings: &mut Vec<String>,
    name: &str,
) -> Material {
    let mut out = material_kind_of(m)
        .with_two_sided(m.two_sided)
        .with_alpha(m.alpha_mode, m.alpha);
    let file = match &m.kind {
        MaterialKind::Diffuse { texture, .. }
        | MaterialKind::MetallicRoughness { texture, .. }
        | MaterialKind::CoatedDiffuse { texture, .. } => texture.as_deref(),
        _ => None,
    };
    if let Some(path) = file {
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

fn material_kind_of(m: &MaterialSpec) -> Material {
    match &m.kind {
        MaterialKind::ComplexConductor {
            eta,
            k,
            roughness,
            multiple_scattering,
        } => Material::new(Bsdf::ComplexConductor {
            eta: *eta,
            k: *k,
            roughness: *roughness,
            multiple_scattering: *multiple_scattering,
        }),
        MaterialKind::MetallicRoughness {
            base_color,
            metallic,
            roughness,
            ior,
            specular,
            specular_color,
            ..
        } => Material::new(Bsdf::MetallicRoughness {
            base_color: *base_color,
            metallic: *metallic,
            roughness: *roughness,
            ior: *ior,
            specular: *specular,
            specular_color: *specular_color,
        }),
        MaterialKind::CoatedDiffuse {
            albedo,
            ior,
            roughness,
            ..
        } => Material::new(Bsdf::CoatedDiffuse {
            albedo: *albedo,
            ior: *ior,
            roughness: *roughness,
        }),
        MaterialKind::ThinDielectric { ior } => Material::new(Bsdf::ThinDielectric { ior: *ior }),
        MaterialKind::Diffuse { albedo, .. } => Material::diffuse(*albedo),
        MaterialKind::Conductor { color, roughness } => Material::conductor(*color, *roughness),
        MaterialKind::Mirror { color } => Material::mirror(*color),
        MaterialKind::Dielectric { ior } => Material::glass(*ior),
        MaterialKind::RoughDielectric { ior, roughness } => Material::rough_glass(*ior, *roughness),
        MaterialKind::Emission {
            radiance,
            two_sided,
            albedo,
        } => {
            let mut out = Material::diffuse(*albedo).with_emission(*radiance);
            out.two_sided_emission = *two_sided;
            out
        }
    }
}

/// Adds a `[[light]]`: explicit lights, emissive shapes, or the environment.
///
/// An area light with a `material` scatters light with that material's BSDF
/// (and texture) besides emitting its own radiance; without one its surface
/// is black but for the emission.
fn add_light(
    scene: &mut Scene,
    l: &LightSpec,
    named: &HashMap<&str, u32>,
    name: &str,
) -> Result<(), FormatError> {
    match l {
        LightSpec::Point {
            position,
            intensity,
        } => scene.add_light(Light::point(*position, *intensity)),
        LightSpec::Spot {
            position,
            target,
            intensity,
            inner_deg,
            outer_deg,
        } => scene.add_light(Light::spot(
            *position, *target, *intensity, *inner_deg, *outer_deg,
        )),
        LightSpec::Directional {
            direction,
            irradiance,
        } => scene.add_light(Light::directional(*direction, *irradiance)),
        LightSpec::Area {
            shape,
            radiance,
            two_sided,
            material,
        } => {
            // The resolver checked that the name exists.
            let surface = material.as_deref().and_then(|n| named.get(n));
            let mut m = match surface {
                Some(&id) => scene.materials[id as usize]
                    .clone()
                    .with_emission(*radiance),
                None => Material::emitter(*radiance),
            };
            m.two_sided_emission = *two_sided;
            let m = scene.add_material(m);
            let shape = shapes::shape_of(shape).ok_or_else(|| {
                FormatError::in_file(name, "an area light's shape is quad, disc or sphere")
            })?;
            scene.add_shape(shape, m);
        }
        LightSpec::Environment(EnvironmentSpec::Constant(c)) => {
            scene.environment = Some(Environment::Constant(*c));
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
            scene.environment = Some(Environment::Map {
                texture: Arc::new(Texture::new(w, h, texels)),
                scale: *scale,
            });
        }
    }
    Ok(())
}
