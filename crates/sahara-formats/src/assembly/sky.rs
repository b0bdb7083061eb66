//! What lights a scene besides its own lights, as the description's
//! [`Sky`] asks (`--sky`, a scene file's `sky` key):
//!
//! - `default`: Sahara's default sky (a constant blue-grey environment)
//!   and sun (a directional light from above and in front);
//! - `none`: nothing; the scene's own lights only;
//! - `auto`: the default sky and sun if the scene's own lights are weak
//!   (the rule in [`needs_default`]), else nothing. Mesh files render with
//!   `auto` unless told otherwise; scene files (TOML, pbrt) with `none`,
//!   since they describe their lighting;
//! - a file (`.exr`, `.hdr`, `.png`, `.jpg`): an equirectangular
//!   environment map lights the scene instead, and no sun.
//!
//! The rule and the units are documented for users in docs/lighting.md.

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;
use sahara_render::luminance;
use sahara_render::{Environment, Light, Scene, Texture};

use crate::description::Sky;
use crate::image_in::load_rgb_f32;
use crate::FormatError;

/// Radiance of the default sky.
pub const DEFAULT_SKY: Vec3 = Vec3::new(0.55, 0.6, 0.7);
/// Direction the default sun's light travels.
pub const DEFAULT_SUN_DIRECTION: Vec3 = Vec3::new(-0.4, -1.0, -0.3);
/// Irradiance of the default sun.
pub const DEFAULT_SUN: Vec3 = Vec3::splat(2.5);

/// A scene's own lights are weak (`auto` adds the default sky and sun)
/// when their power is below this fraction of what the default sun and
/// sky shed on the scene's bounding sphere.
pub const WEAK_FRACTION: f32 = 0.05;

/// What [`apply`] did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SkyUsed {
    /// The scene's own lights only.
    Own,
    /// The default sky and sun were added.
    Default,
    /// An environment map.
    Map(PathBuf),
}

impl std::fmt::Display for SkyUsed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SkyUsed::Own => write!(f, "the scene's own lights"),
            SkyUsed::Default => write!(f, "default sky and sun"),
            SkyUsed::Map(p) => write!(f, "environment map {}", p.display()),
        }
    }
}

/// Power (luminance) of the scene's own lights: emitting triangles
/// (radiance times area times pi, per emitting face), point and spot
/// lights (intensity times the solid angle they light), directional
/// lights and the environment (what they shed on the bounding sphere of
/// radius `radius`).
pub fn own_power(scene: &Scene, radius: f32) -> f32 {
    let mut power = 0.0f64;
    for (i, inst) in scene.instances.iter().enumerate() {
        let mesh = &scene.meshes[inst.mesh as usize];
        let xf = inst.placement.at(0.0);
        for (t, idx) in mesh.mesh.indices.iter().enumerate() {
            let Some(m) = scene
                .materials
                .get(scene.material_of(i as u32, t as u32) as usize)
            else {
                continue;
            };
            if !m.is_emissive() {
                continue;
            }
            let [a, b, c] = idx.map(|k| xf.transform_point3(mesh.mesh.positions[k as usize]));
            let area = 0.5 * (b - a).cross(c - a).length();
            if area.is_finite() {
                let faces = if m.two_sided_emission { 2.0 } else { 1.0 };
                let texture = m
                    .textures
                    .emission
                    .as_ref()
                    .map_or(1.0, |t| luminance(t.texture.mean()));
                power +=
                    (area * std::f32::consts::PI * luminance(m.emission) * texture * faces) as f64;
            }
        }
    }
    let sphere = std::f32::consts::PI * radius * radius;
    for l in &scene.lights {
        power += match *l {
            Light::Point { intensity, .. } => 4.0 * std::f32::consts::PI * luminance(intensity),
            Light::Spot {
                intensity,
                cos_outer,
                ..
            } => 2.0 * std::f32::consts::PI * (1.0 - cos_outer) * luminance(intensity),
            Light::Directional { irradiance, .. } => sphere * luminance(irradiance),
        } as f64;
    }
    if let Some(env) = &scene.environment {
        let mean = match env {
            Environment::Constant(c) => luminance(*c),
            Environment::Map { texture, scale } => luminance(texture.mean()) * scale,
        };
        power += (4.0 * std::f32::consts::PI * sphere * mean) as f64;
    }
    power as f32
}

/// Power the default sky and sun shed on a bounding sphere of `radius`.
pub fn default_power(radius: f32) -> f32 {
    let sphere = std::f32::consts::PI * radius * radius;
    sphere * (luminance(DEFAULT_SUN) + 4.0 * std::f32::consts::PI * luminance(DEFAULT_SKY))
}

/// True if a scene of bounding radius `radius` needs the default sky and
/// sun to look lit: its own lights shed less than [`WEAK_FRACTION`] of
/// what those would.
pub fn needs_default(scene: &Scene, radius: f32) -> bool {
    own_power(scene, radius) < WEAK_FRACTION * default_power(radius)
}

/// The bounding radius of the scene's instances (1 if it has none with
/// finite bounds).
pub fn scene_radius(scene: &Scene) -> f32 {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for inst in &scene.instances {
        let b = inst
            .placement
            .world_bounds(scene.meshes[inst.mesh as usize].mesh.bounds());
        if !b.is_empty() {
            lo = lo.min(b.min);
            hi = hi.max(b.max);
        }
    }
    let r = 0.5 * (hi - lo).length();
    if r.is_finite() && r > 0.0 {
        r
    } else {
        1.0
    }
}

/// Lights `scene` as `sky` says; an environment map that cannot be read
/// is an error naming it.
pub fn apply(scene: &mut Scene, sky: &Sky) -> Result<SkyUsed, FormatError> {
    let add_default = |scene: &mut Scene| {
        scene.environment = Some(Environment::Constant(DEFAULT_SKY));
        scene.add_light(Light::directional(DEFAULT_SUN_DIRECTION, DEFAULT_SUN));
        SkyUsed::Default
    };
    Ok(match sky {
        Sky::Auto if needs_default(scene, scene_radius(scene)) => add_default(scene),
        Sky::Auto | Sky::None => SkyUsed::Own,
        Sky::Default => add_default(scene),
        Sky::Map(path) => {
            let (w, h, rgb) = load_rgb_f32(path)?;
            let texels = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
            scene.environment = Some(Environment::Map {
                texture: Arc::new(Texture::new(w, h, texels)),
                scale: 1.0,
            });
            SkyUsed::Map(path.clone())
        }
    })
}
