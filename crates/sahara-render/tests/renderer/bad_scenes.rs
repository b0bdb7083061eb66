//! Defined outcomes for bad geometry and unlit scenes.

use glam::{Affine3A, Vec3};
use sahara_render::{
    render, Camera, Environment, FrameSettings, Material, Mesh, RenderSettings, Scene,
};

fn quad_with_junk() -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(0.0, f32::INFINITY, 0.0),
        ],
        // Two good triangles, one with a NaN vertex, one with an infinite
        // vertex, one with zero area (a repeated vertex).
        indices: vec![[0, 1, 2], [0, 2, 3], [0, 1, 4], [5, 1, 2], [0, 0, 2]],
    }
}

fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 60.0, 1.0)
}

#[test]
fn unhittable_triangles_are_skipped_and_counted() {
    let mut scene = Scene::new(camera());
    let m = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
    scene.add_object(quad_with_junk(), Affine3A::IDENTITY, m);
    scene.environment = Some(Environment::Constant(Vec3::ONE));
    let d = scene.diagnostics();
    assert_eq!(
        d,
        vec![
            "3 of 5 triangles skipped (2 with a NaN or infinite corner, 1 of zero area)"
                .to_string()
        ]
    );
    // Bounds ignore the triangles with a non-finite corner.
    let b = scene.meshes[0].mesh.bounds();
    assert_eq!(
        (b.min, b.max),
        (Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0))
    );
    // The good part still renders, with no NaN: the quad covers the image
    // centre and, lit by a white sky, reflects albedo 0.5 there.
    let r = render(
        &scene,
        &RenderSettings::from(FrameSettings {
            width: 16,
            height: 16,
            spp: 64,
            ..Default::default()
        }),
        &|_| {},
    )
    .unwrap();
    assert_eq!(r.stats.nan_samples, 0);
    let c = r.film.mean(6, 6, 10, 10);
    assert!(
        (c - Vec3::splat(0.5)).abs().max_element() < 0.05,
        "centre {c}"
    );
    assert!(r
        .film
        .pixels
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
}

#[test]
fn an_unlit_scene_is_reported_and_renders_black() {
    let mut scene = Scene::new(camera());
    let m = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
    scene.add_object(quad_with_junk(), Affine3A::IDENTITY, m);
    assert!(scene.diagnostics().iter().any(|w| w.contains("no light")));
    let r = render(
        &scene,
        &RenderSettings::from(FrameSettings {
            width: 8,
            height: 8,
            spp: 4,
            ..Default::default()
        }),
        &|_| {},
    )
    .unwrap();
    assert!(r.film.pixels.iter().all(|p| *p == Vec3::ZERO));
}

#[test]
fn a_camera_inside_a_closed_box_sees_its_walls() {
    // Defined outcome for a camera inside geometry: it renders what it sees
    // (here the inside of a box emitting radiance 1 from both sides of its
    // walls; emitters are one-sided by default and its faces point out).
    let mut scene = Scene::new(Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0, 1.0));
    let mut emitter = Material::emitter(Vec3::ONE);
    emitter.two_sided_emission = true;
    let glow = scene.add_material(emitter);
    scene.add_shape(
        sahara_render::Shape::Box {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        },
        glow,
    );
    let r = render(
        &scene,
        &RenderSettings::from(FrameSettings {
            width: 8,
            height: 8,
            spp: 4,
            ..Default::default()
        }),
        &|_| {},
    )
    .unwrap();
    for p in &r.film.pixels {
        assert!((*p - Vec3::ONE).abs().max_element() < 1e-3, "{p}");
    }
}
