//! Environment maps of pbrt as Sahara's latitude-longitude maps.
//!
//! pbrt-v4 stores an infinite light's image as a square in the equal-area
//! octahedral mapping of C. Clarberg, "Fast Equal-Area Mapping of the
//! (Hemi)Sphere using SIMD", JGT 13(3), 2008; pbrt-v3 as a lat-long map with
//! +z at the top row and `u = phi / 2 pi`, `phi = atan2(y, x)`. Both are
//! written in the light's own space. A square image is read as the
//! former, any other as the latter. The map is resampled once, texel by
//! texel (nearest), onto a lat-long map in Sahara's world convention (Y up,
//! see `sahara_render::environment_direction`) through the light's transform.

use glam::{DMat3, DVec3, Vec2, Vec3};
use sahara_render::environment_direction;
use sahara_render::Texture;

/// Clarberg's equal-area map: the square point in [0, 1]^2 of unit direction `d`.
pub(crate) fn equal_area_square(d: DVec3) -> (f64, f64) {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let a = x.max(y);
    let b = x.min(y);
    let mut phi = if a == 0.0 {
        0.0
    } else {
        (b / a).atan() * 2.0 / std::f64::consts::PI
    };
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    let u = u.copysign(d.x);
    let v = v.copysign(d.y);
    ((u + 1.0) * 0.5, (v + 1.0) * 0.5)
}

/// The texel of `img` at `(s, t)` in [0, 1]^2 from the top-left corner (nearest).
fn texel(img: &Texture, s: f64, t: f64) -> Vec3 {
    let x = ((s * img.width as f64) as i64).clamp(0, img.width as i64 - 1);
    let y = ((t * img.height as f64) as i64).clamp(0, img.height as i64 - 1);
    img.texel(x, y)
}

/// `img`, written in the light's space whose axes in world space are the
/// columns of `light_to_world` (rotation part), as a Sahara lat-long map.
pub(crate) fn to_lat_long(img: &Texture, light_to_world: DMat3) -> Texture {
    let world_to_light = light_to_world.inverse();
    let octahedral = img.width == img.height;
    let height = if octahedral {
        img.height
    } else {
        img.height.max(2)
    };
    let width = if octahedral {
        2 * img.width
    } else {
        img.width.max(2)
    };
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let uv = Vec2::new(
                (x as f32 + 0.5) / width as f32,
                (y as f32 + 0.5) / height as f32,
            );
            let (w, _) = environment_direction(uv);
            let d = (world_to_light * w.as_dvec3()).normalize_or_zero();
            texels.push(if octahedral {
                let (s, t) = equal_area_square(d);
                texel(img, s, t)
            } else {
                let theta = d.z.clamp(-1.0, 1.0).acos();
                let mut phi = d.y.atan2(d.x);
                if phi < 0.0 {
                    phi += 2.0 * std::f64::consts::PI;
                }
                texel(
                    img,
                    phi / (2.0 * std::f64::consts::PI),
                    theta / std::f64::consts::PI,
                )
            });
        }
    }
    Texture::new(width, height, texels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_area_map_corners_and_poles() {
        let (u, v) = equal_area_square(DVec3::Z);
        assert!((u - 0.5).abs() < 1e-12 && (v - 0.5).abs() < 1e-12);
        // Every corner of the square is the -z pole.
        let (u, v) = equal_area_square(DVec3::new(0.0, 0.0, -1.0));
        assert!((u - 1.0).abs() < 1e-12 && (v - 1.0).abs() < 1e-12);
        let (u, v) = equal_area_square(DVec3::X);
        assert!((u - 1.0).abs() < 1e-12 && (v - 0.5).abs() < 1e-12);
        let (u, v) = equal_area_square(DVec3::Y);
        assert!((u - 0.5).abs() < 1e-12 && (v - 1.0).abs() < 1e-12);
    }

    #[test]
    fn equal_area_map_preserves_area() {
        // Uniform directions land uniformly: each quadrant of the square
        // gets a quarter of them.
        let n = 20_000;
        let mut counts = [0u32; 4];
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let phi = i as f64 * 2.399_963_229_728_653;
            let r = (1.0 - z * z).sqrt();
            let (u, v) = equal_area_square(DVec3::new(r * phi.cos(), r * phi.sin(), z));
            let q = (u > 0.5) as usize + 2 * (v > 0.5) as usize;
            counts[q] += 1;
        }
        for c in counts {
            assert!((c as f64 / n as f64 - 0.25).abs() < 0.01, "{counts:?}");
        }
    }

    #[test]
    fn lat_long_v3_map_puts_light_z_up_when_rotated() {
        // A 4x2 lat-long map, top row bright: in light space +z is bright.
        // With pbrt's usual "Rotate -90 1 0 0" light z becomes world +y.
        let img = Texture::new(
            4,
            2,
            vec![
                Vec3::ONE,
                Vec3::ONE,
                Vec3::ONE,
                Vec3::ONE,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
                Vec3::ZERO,
            ],
        );
        let rot = DMat3::from_axis_angle(DVec3::X, (-90f64).to_radians());
        let out = to_lat_long(&img, rot);
        // Sahara's row 0 is the zenith +Y.
        assert_eq!(out.texel(0, 0), Vec3::ONE);
        assert_eq!(out.texel(0, out.height as i64 - 1), Vec3::ZERO);
    }
}
