//! Textures in renders: a normal map tilts shading as tilted geometry
//! does, in both tangent-frame handednesses and whether the tangents come
//! from MikkTSpace or from the triangle; painted occlusion darkens only
//! indirect light; emission textures light the scene where they are
//! bright.

use std::sync::Arc;

use crate::common::{path, run, settings};
use glam::{Affine3A, Vec2, Vec3};
use sahara_render::{Camera, Light, Material, Scene, Texture, TextureMap};
use sahara_render::{Channel, ScalarMap};
use sahara_render::{Mesh, SceneMesh};
use sahara_render::{NormalMap, OcclusionMap};
use std::f32::consts::PI;

/// A 2x2 quad in the plane z = 0 facing +z, uv running along `u_dir` and
/// `v_dir` (each +-1 times x or y), with normals.
fn quad(u_dir: Vec3, v_dir: Vec3) -> SceneMesh {
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let uvs = positions
        .iter()
        .map(|p| Vec2::new(p.dot(u_dir), p.dot(v_dir)) * 0.5 + Vec2::splat(0.5))
        .collect();
    SceneMesh {
        mesh: Mesh {
            positions,
            indices: vec![[0, 1, 2], [0, 2, 3]],
        },
        normals: Some(vec![Vec3::Z; 4]),
        uvs: Some(uvs),
        ..Default::default()
    }
}

/// A one-texel normal map holding tangent-space normal `m`.
fn normal_texture(m: Vec3) -> Arc<Texture> {
    Arc::new(Texture::new(1, 1, vec![(m + Vec3::ONE) * 0.5]))
}

const ALBEDO: f32 = 0.7;
const LIGHT: Vec3 = Vec3::new(-0.3, -0.4, -1.0);

/// The mean radiance a camera on the +z axis sees of `mesh` with
/// `material` placed by `xf`, lit by one directional light of unit
/// irradiance.
fn seen(mesh: SceneMesh, xf: Affine3A, material: Material, tangents: bool) -> Vec3 {
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, Vec3::Y, 5.0, 1.0);
    let mut scene = Scene::new(cam);
    let m = scene.add_material(material);
    scene.add_object(mesh, xf, m);
    scene.add_light(Light::directional(LIGHT, Vec3::ONE));
    if tangents {
        assert_eq!(scene.generate_tangents(), 1);
        assert!(scene.meshes[0].tangents.is_some());
    }
    let r = run(&scene, &settings(4, 4, 1, path(1)));
    let sum: Vec3 = r.film.pixels.iter().copied().sum();
    sum / r.film.pixels.len() as f32
}

fn lambert(n: Vec3) -> f32 {
    ALBEDO / PI * n.dot(-LIGHT.normalize()).max(0.0)
}

#[test]
fn a_flat_quad_with_a_tilted_normal_map_shades_as_the_tilted_quad() {
    let theta = 35f32.to_radians();
    let (s, c) = theta.sin_cos();
    // Tilts towards +u, towards +v, and (mirrored uv) towards +u again.
    for (u_dir, v_dir, m, expected) in [
        (Vec3::X, Vec3::Y, Vec3::new(s, 0.0, c), Vec3::new(s, 0.0, c)),
        (Vec3::X, Vec3::Y, Vec3::new(0.0, s, c), Vec3::new(0.0, s, c)),
        // u runs along -x: the tangent is -x, the frame left-handed.
        (
            -Vec3::X,
            Vec3::Y,
            Vec3::new(s, 0.0, c),
            Vec3::new(-s, 0.0, c),
        ),
        (
            -Vec3::X,
            Vec3::Y,
            Vec3::new(0.0, s, c),
            Vec3::new(0.0, s, c),
        ),
        // v runs along -y: the bitangent is -y.
        (
            Vec3::X,
            -Vec3::Y,
            Vec3::new(0.0, s, c),
            Vec3::new(0.0, -s, c),
        ),
    ] {
        let material = {
            let mut m0 = Material::diffuse(Vec3::splat(ALBEDO));
            m0.textures.normal = Some(NormalMap {
                map: TextureMap::new(normal_texture(m)),
                scale: 1.0,
            });
            m0
        };
        let want = lambert(expected);
        for tangents in [true, false] {
            let got = seen(
                quad(u_dir, v_dir),
                Affine3A::IDENTITY,
                material.clone(),
                tangents,
            );
            assert!(
                (got - Vec3::splat(want)).abs().max_element() < 1e-4 * want.max(1.0),
                "u {u_dir} v {v_dir} m {m} mikktspace {tangents}: {got}, want {want}"
            );
        }
        // The quad itself tilted so its normal is `expected`, without the
        // map: the same radiance.
        let tilt = Affine3A::from_quat(glam::Quat::from_rotation_arc(Vec3::Z, expected));
        let plain = Material::diffuse(Vec3::splat(ALBEDO));
        let got = seen(quad(u_dir, v_dir), tilt, plain, false);
        assert!(
            (got - Vec3::splat(want)).abs().max_element() < 1e-4,
            "tilted geometry {expected}: {got}, want {want}"
        );
    }
}

#[test]
fn normal_map_scale_and_a_flat_map_change_nothing_they_should_not() {
    let theta = 35f32.to_radians();
    let (s, c) = theta.sin_cos();
    let with = |m: Vec3, scale: f32| {
        let mut mat = Material::diffuse(Vec3::splat(ALBEDO));
        mat.textures.normal = Some(NormalMap {
            map: TextureMap::new(normal_texture(m)),
            scale,
        });
        seen(quad(Vec3::X, Vec3::Y), Affine3A::IDENTITY, mat, true).x
    };
    // A map of (0, 0, 1) is the surface's own normal.
    assert!((with(Vec3::Z, 1.0) - lambert(Vec3::Z)).abs() < 1e-5);
    // Scale 0 flattens any map.
    assert!((with(Vec3::new(s, 0.0, c), 0.0) - lambert(Vec3::Z)).abs() < 1e-5);
    // Scale 2 doubles the tangent-plane part before normalising.
    let n = Vec3::new(2.0 * s, 0.0, c).normalize();
    assert!((with(Vec3::new(s, 0.0, c), 2.0) - lambert(n)).abs() < 1e-4);
}

/// A floor with a wall beside it, lit by a directional light that only
/// reaches the floor; the floor's painted occlusion `occlusion`.
fn floor_and_wall(occlusion: Option<f32>) -> (Vec3, Vec3) {
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, Vec3::Y, 5.0, 1.0);
    let mut scene = Scene::new(cam);
    let mut floor = Material::diffuse(Vec3::splat(ALBEDO));
    if let Some(o) = occlusion {
        let t = Arc::new(Texture::new(1, 1, vec![Vec3::splat(o)]));
        floor.textures.occlusion = Some(OcclusionMap {
            map: ScalarMap::new(TextureMap::new(t), Channel::R),
            strength: 1.0,
        });
    }
    let floor = scene.add_material(floor);
    let wall = scene.add_material(Material::diffuse(Vec3::ONE));
    scene.add_object(quad(Vec3::X, Vec3::Y), Affine3A::IDENTITY, floor);
    // A wall at x = 1.2 facing -x, to the side of the view.
    let wall_xf =
        Affine3A::from_translation(Vec3::new(1.2, 0.0, 1.0)) * Affine3A::from_rotation_y(-PI / 2.0);
    scene.add_object(quad(Vec3::X, Vec3::Y), wall_xf, wall);
    scene.add_light(Light::directional(Vec3::new(0.0, 0.0, -1.0), Vec3::ONE));
    let direct = run(&scene, &settings(4, 4, 16, path(1)));
    let all = run(&scene, &settings(4, 4, 16, path(3)));
    let mean = |r: &sahara_render::RenderResult| {
        r.film.pixels.iter().copied().sum::<Vec3>() / r.film.pixels.len() as f32
    };
    (mean(&direct), mean(&all))
}

#[test]
fn painted_occlusion_darkens_indirect_light_only() {
    let (direct, all) = floor_and_wall(None);
    let (direct_o, all_o) = floor_and_wall(Some(0.25));
    // Direct light is the same with and without the map.
    assert_eq!(direct, direct_o);
    // The light the wall sends back is a quarter as strong.
    let (bounce, bounce_o) = (all - direct, all_o - direct_o);
    assert!(bounce.x > 1e-3, "{bounce}");
    assert!(
        (bounce_o.x - 0.25 * bounce.x).abs() < 0.02 * bounce.x,
        "{bounce_o} vs {bounce}"
    );
}

#[test]
fn an_emission_texture_lights_where_it_is_bright() {
    // An emitting quad whose texture is white on its left half (u < 0.5)
    // and black on its right: the left half glows, the right is black.
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, Vec3::Y, 20.0, 1.0);
    let mut scene = Scene::new(cam);
    let t = Arc::new(Texture::new(2, 1, vec![Vec3::ONE, Vec3::ZERO]));
    let mut lamp = Material::emitter(Vec3::splat(3.0));
    lamp.textures.emission =
        Some(TextureMap::new(t).with_wrap(sahara_render::Wrap::Clamp, Default::default()));
    let lamp = scene.add_material(lamp);
    scene.add_object(quad(Vec3::X, Vec3::Y), Affine3A::IDENTITY, lamp);
    let r = run(&scene, &settings(8, 8, 4, path(2)));
    let left = r.film.get(1, 4);
    let right = r.film.get(7, 4);
    assert!(
        (left - Vec3::splat(3.0)).abs().max_element() < 1e-4,
        "{left}"
    );
    assert_eq!(right, Vec3::ZERO);
}
