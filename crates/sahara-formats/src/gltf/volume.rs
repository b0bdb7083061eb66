//! `KHR_materials_volume`'s attenuation: the medium inside a transmissive
//! glTF surface.
//!
//! A material that is glass (`KHR_materials_transmission` of at least 0.5,
//! not metallic) and bounds a volume (a thickness above zero: not thin-
//! walled) with an `attenuationColor` other than white at a finite
//! `attenuationDistance` fills the meshes wearing it with a purely
//! absorbing homogeneous medium: light crossing `attenuationDistance`
//! keeps `attenuationColor` of itself, so `σa = -ln(colour) / distance`
//! per channel. `thicknessFactor` itself is a hint for rasterisers and
//! is not used otherwise.

use glam::Vec3;
use sahara_readers::gltf::GltfMaterial;
use sahara_render::Medium;

/// The darkest attenuation colour taken (a channel of 0 would absorb
/// everything at once: an infinite coefficient).
const MIN_COLOUR: f32 = 1e-6;

/// The medium inside the surfaces wearing `m`, if it has one.
pub fn volume_medium(m: &GltfMaterial) -> Option<Medium> {
    let glass = m.transmission >= 0.5 && m.metallic < 0.5;
    let solid = m.thickness.is_finite() && m.thickness > 0.0;
    let d = m.attenuation_distance;
    let colour = Vec3::from_array(m.attenuation_color).clamp(Vec3::splat(MIN_COLOUR), Vec3::ONE);
    if !(glass && solid && d.is_finite() && d > 0.0) || colour == Vec3::ONE {
        return None;
    }
    let sigma_a = Vec3::from_array(colour.to_array().map(|c| -c.ln() / d));
    Some(Medium::homogeneous(sigma_a, Vec3::ZERO, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attenuation_becomes_absorption_inside_solid_glass_only() {
        let mut m = GltfMaterial::default_material();
        m.metallic = 0.0;
        m.transmission = 1.0;
        m.thickness = 0.1;
        m.attenuation_color = [0.5, 0.25, 1.0];
        m.attenuation_distance = 2.0;
        let Some(Medium::Homogeneous(h)) = volume_medium(&m) else {
            panic!("no medium")
        };
        // Crossing the distance keeps the colour.
        let kept = (-h.sigma_a * 2.0).exp();
        assert!(
            (kept - Vec3::new(0.5, 0.25, 1.0)).abs().max_element() < 1e-6,
            "{kept}"
        );
        assert_eq!(h.sigma_s, Vec3::ZERO);
        let thin = GltfMaterial {
            thickness: 0.0,
            ..m.clone()
        };
        assert!(volume_medium(&thin).is_none());
        let far = GltfMaterial {
            attenuation_distance: f32::INFINITY,
            ..m.clone()
        };
        assert!(volume_medium(&far).is_none());
        let opaque = GltfMaterial {
            transmission: 0.0,
            ..m
        };
        assert!(volume_medium(&opaque).is_none());
    }
}
