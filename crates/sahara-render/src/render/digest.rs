//! The identity of a frame: a digest of the scene and of every setting
//! that changes its pixels, so that pieces of one frame rendered apart can
//! be recognised as such before they are added up.

use glam::Vec3;
use sha2::{Digest, Sha256};
use std::fmt::Write;

use super::RenderSettings;
use crate::light::Environment;
use crate::scene::Scene;
use crate::texture::Texture;

/// Feeds formatted text to the hash without building the whole string.
struct HashWriter(Sha256);

impl Write for HashWriter {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

/// Hashes `tag`, the number of values and their bytes.
fn bytes(h: &mut HashWriter, tag: &str, values: &mut dyn Iterator<Item = [u8; 4]>) {
    h.0.update(tag.as_bytes());
    let mut chunk = Vec::with_capacity(4096);
    let mut n = 0u64;
    for v in values {
        chunk.extend_from_slice(&v);
        n += 1;
        if chunk.len() >= 4096 {
            h.0.update(&chunk);
            chunk.clear();
        }
    }
    h.0.update(&chunk);
    h.0.update(n.to_le_bytes());
}

/// The bytes of the floats of `v`.
fn vec3s(v: &[Vec3]) -> impl Iterator<Item = [u8; 4]> + '_ {
    v.iter().flat_map(|p| p.to_array()).map(f32::to_le_bytes)
}

/// SHA-256, in hex, of the scene and of the settings that change pixels:
/// size, samples per pixel and per pass, seed, sampler, filter, integrator
/// with its parameters, light sampler, and the cost view's scale. The tree builder, tile
/// size, threads, time limit, window and sample range are left out: they
/// do not change a pixel of the frame.
///
/// The scene's large arrays (mesh vertices, triangles, normals, texture
/// coordinates, tangents, material ids, texels) enter as their bytes; the rest of it
/// through its `Debug` form, which prints every float so that it reads
/// back to the same bits.
pub fn frame_digest(scene: &Scene, s: &RenderSettings) -> String {
    let mut h = HashWriter(Sha256::new());
    for m in &scene.meshes {
        bytes(&mut h, "positions", &mut vec3s(&m.mesh.positions));
        let mut idx = m.mesh.indices.iter().flatten().map(|i| i.to_le_bytes());
        bytes(&mut h, "indices", &mut idx);
        if let Some(n) = &m.normals {
            bytes(&mut h, "normals", &mut vec3s(n));
        }
        for (tag, uv) in [("uvs", &m.uvs), ("uvs1", &m.uvs1)] {
            if let Some(uv) = uv {
                let mut it = uv.iter().flat_map(|p| p.to_array()).map(f32::to_le_bytes);
                bytes(&mut h, tag, &mut it);
            }
        }
        if let Some(t) = &m.tangents {
            let mut it = t.iter().flat_map(|p| p.to_array()).map(f32::to_le_bytes);
            bytes(&mut h, "tangents", &mut it);
        }
        if let Some(ids) = &m.material_ids {
            bytes(
                &mut h,
                "material ids",
                &mut ids.iter().map(|i| i.to_le_bytes()),
            );
        }
    }
    // Texels of every texture, in order of use; the rest of the scene's
    // `Debug` form names textures by size and format only.
    let texture = |h: &mut HashWriter, t: &Texture| {
        let _ = write!(h, "texture {t:?}");
        let mut it = t
            .texels_rgba()
            .flat_map(|p| p.to_array())
            .map(f32::to_le_bytes);
        bytes(h, "texels", &mut it);
    };
    let rest = Scene {
        meshes: Vec::new(),
        ..scene.clone()
    };
    for m in &rest.materials {
        for map in m.texture_maps() {
            texture(&mut h, &map.texture);
        }
    }
    if let Some(Environment::Map { texture: t, .. }) = &rest.environment {
        texture(&mut h, t);
    }
    let scene = &rest;
    // Writing to a hash cannot fail.
    let _ = write!(
        h,
        "sahara frame 1\nsize {}x{}\nspp {} in passes of {}\nseed {}\nsampler {:?}\nfilter {:?}\n\
         integrator {:?}\nlight sampler {}{}\ncost scale {:?}\nscene {:?}",
        s.width,
        s.height,
        s.spp,
        s.pass_size(),
        s.seed,
        s.sampler,
        s.filter,
        s.integrator,
        s.light_sampler,
        // Named only when on, so that the digests of unguided frames
        // stay what they were before the setting existed.
        match s.guiding {
            crate::Guiding::Off => String::new(),
            g => format!("\nguiding {g}"),
        },
        s.cost_scale,
        scene
    );
    // The lane loop's images differ from the scalar loop's in rounding:
    // parts of one frame must come from one loop.
    if s.path_loop.lanes(&s.integrator, scene).is_some() {
        let _ = write!(h, "\npath loop lanes");
    }
    h.0.finalize()
        .iter()
        .fold(String::with_capacity(64), |mut out, b| {
            let _ = write!(out, "{b:02x}");
            out
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;
    use sahara_kd::{AccelParams, BuildParams, Builder};

    #[test]
    fn pixel_settings_change_it_and_speed_settings_do_not() {
        let scene = builtin::cornell_box();
        let base = RenderSettings::default();
        let d = frame_digest(&scene, &base);
        assert_eq!(d.len(), 64);
        let same = RenderSettings {
            build: AccelParams::kd(BuildParams::new(Builder::Binned { bins: 16 })),
            tile_size: 7,
            window: Some(crate::film::window::PixelWindow::full(3, 3)),
            samples: Some(1..2),
            ..base.clone()
        };
        assert_eq!(frame_digest(&scene, &same), d);
        let with = |change: fn(&mut RenderSettings)| {
            let mut s = base.clone();
            change(&mut s);
            s
        };
        for other in [
            with(|s| s.seed = 1),
            with(|s| s.width = 511),
            with(|s| s.spp = 16),
            with(|s| s.pass_spp = 4),
            with(|s| s.filter = crate::Filter::from(crate::FilterKind::Tent)),
        ] {
            assert_ne!(frame_digest(&scene, &other), d);
        }
        let mut moved = scene.clone();
        moved.camera.aspect *= 1.0 + f32::EPSILON;
        assert_ne!(frame_digest(&moved, &base), d);
        let mut nudged = scene.clone();
        nudged.meshes[0].mesh.positions[0].x += 1e-3;
        assert_ne!(frame_digest(&nudged, &base), d);
        let mut textured = scene.clone();
        let texels = |v: f32| {
            crate::TextureMap::new(std::sync::Arc::new(Texture::new(
                1,
                2,
                vec![Vec3::ONE, Vec3::splat(v)],
            )))
        };
        textured.materials[0].textures.base_color = Some(texels(0.5));
        let t = frame_digest(&textured, &base);
        textured.materials[0].textures.base_color = Some(texels(0.25));
        assert_ne!(frame_digest(&textured, &base), t);
        // The same texels in another role, or wrapped otherwise: another
        // frame.
        let mut moved = textured.clone();
        moved.materials[0].textures.emission = moved.materials[0].textures.base_color.take();
        assert_ne!(frame_digest(&moved, &base), t);
        let mut clamped = textured.clone();
        let map = clamped.materials[0].textures.base_color.as_mut().unwrap();
        map.wrap = [crate::texture::Wrap::Clamp; 2];
        assert_ne!(frame_digest(&clamped, &base), t);
    }
}
