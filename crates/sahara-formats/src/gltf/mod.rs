//! A glTF file's cameras, lights and materials as the renderer's (the file
//! is read by [`sahara_readers::gltf`]; its meshes are loaded by
//! [`crate::mesh::library`], its materials mapped by [`material`], the
//! media inside its glass by [`volume`]).

pub(crate) mod material;
pub(crate) mod volume;

use glam::{Mat4, Vec3};
use sahara_readers::gltf::{GltfCamera, GltfLight, GltfLightKind};
use sahara_render::{Camera, Light};

/// Luminous efficacy taken for `KHR_lights_punctual` lights: 683 lm/W,
/// the efficacy at 555 nm that defines the candela.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The camera as the renderer's (aspect 1: the caller sets it from the
/// image size, keeping the vertical field of view).
pub fn gltf_camera(c: &GltfCamera) -> Camera {
    let eye = c.transform.transform_point3(Vec3::ZERO);
    let forward = c.transform.transform_vector3(Vec3::NEG_Z);
    let up = c.transform.transform_vector3(Vec3::Y);
    Camera::look_at(eye, eye + forward, up, c.yfov.to_degrees(), 1.0)
}

/// The light as the renderer's, placed by `placement` times the node's
/// transform. glTF's photometric intensity becomes radiometric at
/// [`LUMENS_PER_WATT`] (candela to W/sr, lux to W/m²), as Blender reads
/// and writes it, while emission (`emissiveFactor` times its strength)
/// is radiance as it stands (docs/lighting.md says why). `range` is
/// not used: light falls off with the square of the distance, as the
/// glTF specification asks of renderers that ignore it.
pub fn gltf_light(l: &GltfLight, placement: Mat4) -> Light {
    let xf = placement * l.transform;
    let power = Vec3::from_array(l.color).max(Vec3::ZERO) * l.intensity.max(0.0) / LUMENS_PER_WATT;
    let position = xf.transform_point3(Vec3::ZERO);
    let axis = xf.transform_vector3(Vec3::NEG_Z).normalize_or(Vec3::NEG_Z);
    match l.kind {
        GltfLightKind::Point => Light::point(position, power),
        GltfLightKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => Light::spot(
            position,
            position + axis,
            power,
            inner_cone_angle.to_degrees(),
            outer_cone_angle.to_degrees(),
        ),
        GltfLightKind::Directional => Light::directional(axis, power),
    }
}
