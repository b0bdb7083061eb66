use std::sync::Arc;

use super::footprint::{CameraSpread, UvFootprint};
use super::pyramid::box_weights;
use super::*;
use glam::Affine2;

fn close(a: Vec4, b: Vec4, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

#[test]
fn bilinear_interpolates_and_wraps() {
    let t = Texture::new(2, 1, vec![Vec3::ZERO, Vec3::ONE]);
    // Texel centres at u = 0.25 and 0.75.
    assert!((t.bilinear(Vec2::new(0.25, 0.5)) - Vec3::ZERO).length() < 1e-6);
    assert!((t.bilinear(Vec2::new(0.5, 0.5)) - Vec3::splat(0.5)).length() < 1e-6);
    // u = 0 lies halfway between the last texel and the first (wrap).
    assert!((t.bilinear(Vec2::new(0.0, 0.5)) - Vec3::splat(0.5)).length() < 1e-6);
    assert!((t.bilinear(Vec2::new(1.75, 0.5)) - Vec3::ONE).length() < 1e-6);
}

/// A 4x1 row 0, 1, 2, 3 (red channel, float).
fn ramp() -> Texture {
    Texture::new(
        4,
        1,
        (0..4).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect(),
    )
}

#[test]
fn wrap_modes_fold_indices_as_opengl_does() {
    let n = 4;
    let all = |w: Wrap| (-6..10).map(|i| w.apply(i, n)).collect::<Vec<_>>();
    assert_eq!(
        all(Wrap::Repeat),
        [2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1]
    );
    assert_eq!(
        all(Wrap::Clamp),
        [0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3, 3]
    );
    // Mirrored: 0 1 2 3 | 3 2 1 0 | 0 1 2 3, and backwards 0 1 2 3 before
    // index 0 reversed.
    assert_eq!(
        all(Wrap::MirroredRepeat),
        [2, 3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0, 1]
    );
}

#[test]
fn wrap_modes_at_lookups_outside_the_unit_square() {
    let t = ramp();
    let at = |u: f32, wrap: Wrap| t.bilinear_level(0, Vec2::new(u, 0.5), [wrap; 2]).x;
    // u = 1.125 is texel 4.5 - 0.5 = 4: the fifth texel's centre.
    assert_eq!(at(1.125, Wrap::Repeat), 0.0);
    assert_eq!(at(1.125, Wrap::Clamp), 3.0);
    assert_eq!(at(1.125, Wrap::MirroredRepeat), 3.0);
    assert_eq!(at(1.375, Wrap::MirroredRepeat), 2.0);
    assert_eq!(at(-0.125, Wrap::MirroredRepeat), 0.0);
    assert_eq!(at(-0.375, Wrap::MirroredRepeat), 1.0);
    assert_eq!(at(-0.375, Wrap::Repeat), 2.0);
    assert_eq!(at(-0.375, Wrap::Clamp), 0.0);
    // Between texels at the edge: clamp holds the edge value, repeat
    // blends with the far side.
    assert_eq!(at(0.0, Wrap::Clamp), 0.0);
    assert_eq!(at(0.0, Wrap::Repeat), 1.5);
}

#[test]
fn srgb_decodes_only_colour_roles() {
    let texel = [[128u8, 64, 255, 200]];
    let srgb = Texture::from_rgba8(1, 1, texel.to_vec(), Encoding::Srgb, true);
    let linear = Texture::from_rgba8(1, 1, texel.to_vec(), Encoding::Linear, true);
    let uv = Vec2::splat(0.5);
    let s = srgb.bilinear_level(0, uv, [Wrap::Repeat; 2]);
    let l = linear.bilinear_level(0, uv, [Wrap::Repeat; 2]);
    // IEC 61966-2-1: code 128 is 0.2158605, 64 is 0.0512695.
    assert!(close(
        s,
        Vec4::new(0.215_860_5, 0.051_269_5, 1.0, 200.0 / 255.0),
        1e-6
    ));
    assert!(close(
        l,
        Vec4::new(128.0 / 255.0, 64.0 / 255.0, 1.0, 200.0 / 255.0),
        1e-7
    ));
    // Alpha reads 1 when the image has none.
    let opaque = Texture::from_rgba8(1, 1, texel.to_vec(), Encoding::Srgb, false);
    assert_eq!(opaque.bilinear_level(0, uv, [Wrap::Repeat; 2]).w, 1.0);
    // The table agrees with the formula at every code, and round-trips.
    for c in 0..=255u8 {
        let v = c as f32 / 255.0;
        let f = if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        };
        assert_eq!(srgb8_to_linear(c), f);
        assert_eq!(linear_to_srgb8(f), c);
    }
}

#[test]
fn box_weights_cover_each_source_texel_once() {
    for n_in in 1..40u32 {
        let n_out = (n_in / 2).max(1);
        let mut cover = vec![0.0f32; n_in as usize];
        for i in 0..n_out {
            let w = box_weights(n_in, n_out, i);
            let sum: f32 = w.iter().map(|x| x.1).sum();
            assert!((sum - 1.0).abs() < 1e-5, "{n_in}: {w:?}");
            for (j, x) in w {
                cover[j as usize] += x * n_in as f32 / n_out as f32;
            }
        }
        assert!(
            cover.iter().all(|c| (c - 1.0).abs() < 1e-4),
            "{n_in}: {cover:?}"
        );
    }
}

#[test]
fn pyramid_levels_halve_and_keep_the_mean() {
    // A 6x3 image of distinct values: levels 3x1 and 1x1.
    let texels: Vec<Vec3> = (0..18).map(|i| Vec3::splat(i as f32)).collect();
    let t = Texture::new(6, 3, texels);
    assert_eq!(t.levels(), 3);
    assert_eq!(t.level_size(1), (3, 1));
    assert_eq!(t.level_size(2), (1, 1));
    let mean = 8.5;
    let l1: Vec<f32> = (0..3)
        .map(|x| t.texel_rgba(1, x, 0, [Wrap::Clamp; 2]).x)
        .collect();
    // Column pairs {0,1}, {2,3}, {4,5} over all three rows.
    for (a, b) in l1.iter().zip([6.5, 8.5, 10.5]) {
        assert!((a - b).abs() < 1e-5, "{l1:?}");
    }
    assert!((t.texel_rgba(2, 0, 0, [Wrap::Clamp; 2]).x - mean).abs() < 1e-5);
    // An odd width: 5 -> 2 texels of 2.5 source texels each.
    let t = Texture::new(5, 1, (0..5).map(|i| Vec3::splat(i as f32)).collect());
    let a = t.texel_rgba(1, 0, 0, [Wrap::Clamp; 2]).x;
    let b = t.texel_rgba(1, 1, 0, [Wrap::Clamp; 2]).x;
    assert!((a - (0.0 + 1.0 + 0.5 * 2.0) / 2.5).abs() < 1e-5, "{a}");
    assert!((b - (0.5 * 2.0 + 3.0 + 4.0) / 2.5).abs() < 1e-5, "{b}");
    // 8-bit sRGB levels average light, not codes: black and white give
    // linear 0.5 (code 188), not code 128.
    let t = Texture::from_rgba8(
        2,
        1,
        vec![[0, 0, 0, 255], [255, 255, 255, 255]],
        Encoding::Srgb,
        false,
    );
    let l = t.texel_rgba(1, 0, 0, [Wrap::Clamp; 2]);
    assert!((l.x - 0.5).abs() < 0.005, "{l}");
}

/// A 64x64 checkerboard of 1-texel squares (0 and 1).
fn checker() -> Texture {
    let texels = (0..64 * 64)
        .map(|i| Vec3::splat(((i % 64 + i / 64) % 2) as f32))
        .collect();
    Texture::new(64, 64, texels)
}

#[test]
fn mip_level_follows_the_footprint() {
    let t = checker();
    let uv = Vec2::new(0.3, 0.6);
    let wrap = [Wrap::Repeat; 2];
    // Footprints of a texel or less read level 0 exactly.
    let centre = Vec2::new(10.5 / 64.0, 1.0 - 20.5 / 64.0);
    for w in [0.0, 0.5, 1.0] {
        assert_eq!(
            t.filtered(centre, w, wrap),
            t.bilinear_level(0, centre, wrap)
        );
    }
    // Width 2^k is level k exactly; the checker averages to 0.5 from
    // level 1 on.
    for k in 1..t.levels() {
        let w = (1u32 << k) as f32;
        assert_eq!(t.filtered(uv, w, wrap), t.bilinear_level(k, uv, wrap));
        assert!((t.filtered(uv, w, wrap).x - 0.5).abs() < 1e-6);
    }
    // Between levels: the blend of the two, by log2 of the width.
    let a = t.bilinear_level(0, centre, wrap);
    let b = t.bilinear_level(1, centre, wrap);
    let mid = t.filtered(centre, 2f32.sqrt(), wrap);
    assert!(close(mid, a.lerp(b, 0.5), 1e-6), "{mid} {a} {b}");
    // Beyond the last level: the last level (the mean).
    assert!((t.filtered(uv, 1e6, wrap).x - 0.5).abs() < 1e-6);
}

#[test]
fn footprint_of_a_surface_facing_the_camera() {
    // A camera 10 units from a plane facing it, 0.001 rad between
    // lookups: neighbouring lookups land 0.01 apart on the plane.
    let spread = CameraSpread {
        eye: Vec3::new(0.0, 0.0, 10.0),
        angle: 1e-3,
    };
    let offsets = spread.surface_offsets(Vec3::ZERO, Vec3::Z).unwrap();
    for o in offsets {
        assert!((o.length() - 0.01).abs() < 1e-6, "{o}");
        assert!(o.z.abs() < 1e-9);
    }
    // Tilted 60 degrees: one axis stretches by 1 / cos 60 = 2.
    let n = Vec3::new(0.0, (60f32).to_radians().sin(), (60f32).to_radians().cos());
    let o = spread.surface_offsets(Vec3::ZERO, n).unwrap();
    let mut l = [o[0].length(), o[1].length()];
    l.sort_by(f32::total_cmp);
    assert!(
        (l[0] - 0.01).abs() < 1e-5 && (l[1] - 0.02).abs() < 2e-4,
        "{l:?}"
    );
    // The uv footprint of a unit quad (uv = xy) carrying a 100x100 texture:
    // 0.01 in uv is one texel.
    let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
    let fp = UvFootprint::on_triangle(p, [uv, uv], offsets);
    let tex = Texture::new(100, 100, vec![Vec3::ONE; 100 * 100]);
    let w = fp.texels(0, &Affine2::IDENTITY, &tex);
    assert!((w - 1.0).abs() < 1e-4, "{w}");
    // A transform scaling uv by 4 (a texture repeated 4 times) reads 4
    // texels per lookup: two levels coarser.
    let scaled = Affine2::from_scale(Vec2::splat(4.0));
    assert!((fp.texels(0, &scaled, &tex) - 4.0).abs() < 1e-3);
    // The second uv set, twice as dense.
    let fp = UvFootprint::on_triangle(p, [uv, uv.map(|t| t * 2.0)], offsets);
    assert!((fp.texels(1, &Affine2::IDENTITY, &tex) - 2.0).abs() < 1e-3);
}

#[test]
fn anisotropy_is_capped() {
    let fp = UvFootprint {
        d: [[Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.01)]; 2],
    };
    let tex = Texture::new(1, 1, vec![Vec3::ONE]);
    // Major 1, minor 0.01: the width is the major axis over 8.
    assert!((fp.texels(0, &Affine2::IDENTITY, &tex) - 1.0 / MAX_ANISOTROPY_FOR_TEST).abs() < 1e-6);
}

const MAX_ANISOTROPY_FOR_TEST: f32 = super::footprint::MAX_ANISOTROPY;

#[test]
fn texture_map_applies_uv_set_and_transform() {
    let t = Arc::new(ramp());
    // glTF's KHR_texture_transform of offset 0.5 along u.
    let map = TextureMap::new(t.clone())
        .with_uv_set(1)
        .with_transform(Affine2::from_translation(Vec2::new(0.5, 0.0)))
        .with_wrap(Wrap::Clamp, Wrap::Clamp);
    let uvs = [Vec2::new(0.9, 0.5), Vec2::new(0.125, 0.5)];
    // Set 1 at 0.125 + 0.5 = 0.625: texel 2's centre.
    assert_eq!(map.lookup(&uvs, &UvFootprint::POINT).x, 2.0);
    assert_eq!(map.lookup_sharp(&uvs).x, 2.0);
    // Set 0 at 0.9, repeating: texel 3.1, between texel 3 and texel 0.
    let plain = TextureMap::new(t);
    assert!((plain.lookup(&uvs, &UvFootprint::POINT).x - 2.7).abs() < 1e-5);
}
