//! What lights a scene besides its own lights, as the description's
//! [`Sky`] asks (`--sky`, a scene file's `sky` key):
//!
//! - `default`: Sahara's default sky (a constant blue-grey environment)
//!   and sun (a directional light from above and in front);
//! - `none`: nothing; the scene's own lights only;
//! - `auto`: the default sky and sun if the scene's own lights are weak
//!   (the rule: [`own_share`] below [`WEAK_FRACTION`]), else nothing.
//!   Mesh files render with `auto` unless told otherwise; scene files (TOML, pbrt) with `none`,
//!   since they describe their lighting;
//! - a file (`.exr`, `.hdr`, `.png`, `.jpg`): an equirectangular
//!   environment map lights the scene instead, and no sun.
//!
//! The rule and the units are documented for users in docs/lighting.md.

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;
use sahara_readers::FormatError;
use sahara_render::luminance;
use sahara_render::{Environment, Light, Scene, Texture};

use crate::common::image::load_rgb_f32;
use crate::description::Sky;

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

/// What lights a scene besides its own lights, as the sky rule decided.
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
/// (radiance times area times pi, per emitting face), point, spot and
/// directional lights (their power as the renderer chooses lights by it,
/// [`Light::power`]: a directional light's is what it sheds on the
/// bounding sphere of radius `radius`) and the environment (likewise).
/// An emissive ground (a flat object many times the
/// size of the rest, such as glowing water or a lit floor: see the
/// automatic camera's `grounds`) does not count: it is context, lighting
/// the subject from below, and cannot stand in for a sky above it.
pub fn own_power(scene: &Scene, radius: f32) -> f32 {
    own_power_by(scene, radius, &mut |t| luminance(t.mean()))
}

/// [`own_power`], with `texture_luminance` giving an emission texture's
/// mean luminance. It is asked once per emissive material with a texture,
/// whatever the number of triangles wearing it: the work is linear in the
/// scene's triangles plus its emission textures' texels (the tests count
/// the asking).
fn own_power_by(
    scene: &Scene,
    radius: f32,
    texture_luminance: &mut dyn FnMut(&Texture) -> f32,
) -> f32 {
    let grounds = super::camera::grounds(scene);
    // Per material, its emission texture's mean luminance (1 without one),
    // found when a triangle first wears it.
    let mut texture_means: Vec<Option<f32>> = vec![None; scene.materials.len()];
    let mut power = 0.0f64;
    for (i, inst) in scene.instances.iter().enumerate() {
        if grounds.is_ground(i) {
            continue;
        }
        let mesh = &scene.meshes[inst.mesh as usize];
        let xf = inst.placement.at(0.0);
        for (t, idx) in mesh.mesh.indices.iter().enumerate() {
            let id = scene.material_of(i as u32, t as u32) as usize;
            let Some(m) = scene.materials.get(id) else {
                continue;
            };
            if !m.is_emissive() {
                continue;
            }
            let [a, b, c] = idx.map(|k| xf.transform_point3(mesh.mesh.positions[k as usize]));
            let area = 0.5 * (b - a).cross(c - a).length();
            if area.is_finite() {
                let faces = if m.two_sided_emission { 2.0 } else { 1.0 };
                let texture = *texture_means[id].get_or_insert_with(|| {
                    m.textures
                        .emission
                        .as_ref()
                        .map_or(1.0, |t| texture_luminance(&t.texture))
                });
                power +=
                    (area * std::f32::consts::PI * luminance(m.emission) * texture * faces) as f64;
            }
        }
    }
    let sphere = std::f32::consts::PI * radius * radius;
    for l in &scene.lights {
        power += l.power(radius) as f64;
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

/// The measure of the `auto` rule: the scene's own lights' power as a
/// share of what the default sky and sun would shed on it (below
/// [`WEAK_FRACTION`], they are weak).
///
/// Both are measured on the bounding sphere of what is not ground (as the
/// automatic camera frames it): a large ground plane does not make the
/// default sky and sun seem stronger than the lights of what stands on it.
pub fn own_share(scene: &Scene) -> f32 {
    let g = super::camera::grounds(scene);
    let r = match g.subject {
        Some((lo, hi)) if g.context.contains(&true) => (0.5 * (hi - lo).length()).max(1e-6),
        _ => scene_radius(scene),
    };
    own_power(scene, r) / default_power(r)
}

/// Lights `scene` as `sky` says; an environment map that cannot be read
/// is an error naming it. With `auto`, also the rule's measure
/// ([`own_share`]) that decided.
pub fn apply(scene: &mut Scene, sky: &Sky) -> Result<(SkyUsed, Option<f32>), FormatError> {
    let add_default = |scene: &mut Scene| {
        scene.environment = Some(Environment::Constant(DEFAULT_SKY));
        scene.add_light(Light::directional(DEFAULT_SUN_DIRECTION, DEFAULT_SUN));
        SkyUsed::Default
    };
    Ok(match sky {
        Sky::Auto => {
            let share = own_share(scene);
            let used = if share < WEAK_FRACTION {
                add_default(scene)
            } else {
                SkyUsed::Own
            };
            (used, Some(share))
        }
        Sky::None => (SkyUsed::Own, None),
        Sky::Default => (add_default(scene), None),
        Sky::Map(path) => {
            let (w, h, rgb) = load_rgb_f32(path)?;
            let texels = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
            scene.environment = Some(Environment::Map {
                texture: Arc::new(Texture::new(w, h, texels)),
                scale: 1.0,
            });
            (SkyUsed::Map(path.clone()), None)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sahara_render::{Camera, Material, Shape};

    /// A unit sphere on a square ground of side 1000 (emitting `ground`,
    /// upwards), with `lights`.
    fn sphere_on_a_sea(ground: Vec3, lights: &[Light]) -> Scene {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        let grey = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
        let sea = scene.add_material(
            Material::diffuse(Vec3::splat(0.5))
                .with_emission(ground)
                .with_two_sided(false),
        );
        scene.add_shape(
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            grey,
        );
        let side = 1000.0;
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-side / 2.0, -1.0, side / 2.0),
                edge_u: Vec3::new(side, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, -side),
            },
            sea,
        );
        for l in lights {
            scene.add_light(*l);
        }
        scene
    }

    /// A strip of `n` emissive triangles (each of area 1/2) wearing
    /// material 0, which has a `side` x `side` emission texture, and as
    /// many wearing material 1, with another.
    fn glowing_strips(n: u32, side: u32) -> Scene {
        let mut scene = Scene::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0));
        for grey in [0.5, 0.25] {
            let texels = vec![Vec3::splat(grey); (side * side) as usize];
            let map = sahara_render::TextureMap::new(Arc::new(Texture::new(side, side, texels)));
            let mut m = Material::diffuse(Vec3::splat(0.5)).with_emission(Vec3::ONE);
            m.textures.emission = Some(map);
            let id = scene.add_material(m);
            let y = id as f32 * 2.0;
            let positions = (0..=n)
                .flat_map(|i| {
                    [
                        Vec3::new(i as f32, y, 0.0),
                        Vec3::new(i as f32, y + 1.0, 0.0),
                    ]
                })
                .collect();
            let indices = (0..n).map(|i| [2 * i, 2 * i + 2, 2 * i + 1]).collect();
            scene.add_object(
                sahara_render::Mesh { positions, indices },
                glam::Affine3A::IDENTITY,
                id,
            );
        }
        scene
    }

    #[test]
    fn each_emission_texture_is_averaged_once_however_many_triangles_wear_it() {
        // The work counted: texels averaged. It was once a pass over the
        // whole texture per emissive triangle (a glTF model of 15,452
        // triangles with a 2048 x 2048 emission map took minutes).
        for n in [10, 10_000] {
            let scene = glowing_strips(n, 256);
            let (mut asked, mut texels) = (0, 0u64);
            let power = own_power_by(&scene, 1.0, &mut |t| {
                asked += 1;
                texels += u64::from(t.width * t.height);
                luminance(t.mean())
            });
            assert_eq!(asked, 2, "{n} triangles");
            assert_eq!(texels, 2 * 256 * 256, "{n} triangles");
            // Radiance 1 times the texture's grey, over n triangles of
            // area 1/2 each, pi per unit, one face each.
            let want = std::f32::consts::PI * 0.5 * n as f32 * (0.5 + 0.25);
            assert!((power - want).abs() <= 1e-4 * want, "{power} vs {want}");
            assert_eq!(power, own_power(&scene, 1.0));
        }
    }

    #[test]
    fn a_glowing_sea_does_not_switch_the_sky_off() {
        // Radiance 0.05, and 1 (a glTF emissive factor of [1, 1, 1]) over
        // a million square units: as power, 3000 and 60000 times the
        // default sky and sun's on the sphere. The sea is context: it does
        // not count, and the sky stays on.
        for glow in [0.05, 1.0] {
            let mut scene = sphere_on_a_sea(Vec3::splat(glow), &[]);
            let (used, share) = apply(&mut scene, &Sky::Auto).unwrap();
            assert_eq!(used, SkyUsed::Default, "glow {glow}: share {share:?}");
            assert_eq!(share, Some(0.0), "glow {glow}");
        }
        // With a sun of its own the scene keeps its own light.
        let sun = Light::directional(Vec3::NEG_Y, Vec3::splat(1.0));
        let mut scene = sphere_on_a_sea(Vec3::ONE, &[sun]);
        assert_eq!(apply(&mut scene, &Sky::Auto).unwrap().0, SkyUsed::Own);
    }

    #[test]
    fn a_lamp_by_the_subject_is_weighed_against_the_sky_on_the_subject_not_on_the_ground() {
        // A 0.5 W/sr point light: 6.7 % of what the default sky and sun shed
        // on the sphere's bounds, but a ten-millionth of what they would
        // shed on the whole ground.
        let lamp = Light::point(Vec3::new(0.0, 2.0, 2.0), Vec3::splat(0.5));
        let mut scene = sphere_on_a_sea(Vec3::ZERO, &[lamp]);
        let (used, share) = apply(&mut scene, &Sky::Auto).unwrap();
        assert_eq!(used, SkyUsed::Own, "{share:?}");
        assert!((share.unwrap() - 0.067).abs() < 0.005, "{share:?}");
    }
}
