//! Bidirectional path tracing and light tracing, held to the path tracer
//! where both converge, to an analytic caustic where the path tracer
//! cannot, and to themselves across thread counts.

use crate::common::{run, settings};
use glam::Vec3;
use sahara_render::{
    builtin, render, Camera, Environment, Filter, FilterKind, Integrator, Light, Material,
    RenderResult, Scene, Shape,
};

fn bdpt(max_depth: u32) -> Integrator {
    Integrator::Bdpt { max_depth }
}

/// The path tracer without Russian roulette (which the bidirectional
/// integrators do not use either; both are then cut at the same depth).
fn path(max_depth: u32) -> Integrator {
    crate::common::path(max_depth)
}

/// Mean of each `b x b` block of pixels, per channel.
fn blocks(r: &RenderResult, b: u32) -> Vec<Vec3> {
    let (w, h) = (r.film.width, r.film.height);
    let mut out = Vec::new();
    for by in (0..h).step_by(b as usize) {
        for bx in (0..w).step_by(b as usize) {
            out.push(r.film.mean(bx, by, (bx + b).min(w), (by + b).min(h)));
        }
    }
    out
}

/// Asserts `a` and `b` agree in the image mean within `mean_tol` and in
/// every block within `block_tol` (relative, with `floor` added to the
/// reference so black blocks do not divide by zero).
fn assert_agree(what: &str, a: &RenderResult, b: &RenderResult, mean_tol: f32, block_tol: f32) {
    let (w, h) = (a.film.width, a.film.height);
    let (ma, mb) = (a.film.mean(0, 0, w, h), b.film.mean(0, 0, w, h));
    let rel = ((mb - ma).abs() / ma.max(Vec3::splat(1e-6))).max_element();
    assert!(rel < mean_tol, "{what}: image mean {mb} vs {ma} ({rel})");
    let floor = 0.1 * ma.max_element();
    for (i, (x, y)) in blocks(a, 8).into_iter().zip(blocks(b, 8)).enumerate() {
        let e = ((y - x).abs() / (x + Vec3::splat(floor))).max_element();
        assert!(e < block_tol, "{what}: block {i}: {y} vs {x} ({e})");
    }
}

/// On the Cornell box (diffuse walls, an area light) every method
/// converges to the same image: bidirectional path tracing and light
/// tracing alone against the path tracer, in the mean and block by block.
#[test]
fn bdpt_and_light_tracing_agree_with_the_path_tracer_on_a_diffuse_box() {
    let scene = builtin::cornell_box();
    let reference = run(&scene, &settings(32, 32, 1024, path(6)));
    let b = run(&scene, &settings(32, 32, 256, bdpt(6)));
    assert_agree("bdpt", &reference, &b, 0.01, 0.06);
    let l = run(
        &scene,
        &settings(32, 32, 256, Integrator::LightPath { max_depth: 6 }),
    );
    assert_agree("lightpath", &reference, &l, 0.01, 0.08);
}

/// The Cornell box with a rough gold sphere, a glass sphere, a point
/// light and a spot light besides its area light: glossy and specular
/// vertices, delta lights, and refraction in light subpaths.
fn glossy_box() -> Scene {
    let mut scene = builtin::cornell_box();
    let gold = scene.add_material(Material::conductor(Vec3::new(0.95, 0.75, 0.35), 0.3));
    let glass = scene.add_material(Material::glass(1.5));
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(186.0, 225.0, 169.0),
            radius: 60.0,
        },
        gold,
    );
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(400.0, 80.0, 150.0),
            radius: 80.0,
        },
        glass,
    );
    scene.add_light(Light::point(
        Vec3::new(100.0, 450.0, 300.0),
        Vec3::splat(8000.0),
    ));
    scene.add_light(Light::spot(
        Vec3::new(450.0, 500.0, 400.0),
        Vec3::new(300.0, 0.0, 200.0),
        Vec3::new(20000.0, 15000.0, 10000.0),
        15.0,
        25.0,
    ));
    scene
}

/// Where every method converges but the paths are glossy and specular:
/// bidirectional path tracing against the path tracer.
#[test]
fn bdpt_agrees_with_the_path_tracer_on_a_glossy_box_with_glass_and_delta_lights() {
    let scene = glossy_box();
    let reference = run(&scene, &settings(32, 32, 2048, path(6)));
    let b = run(&scene, &settings(32, 32, 512, bdpt(6)));
    assert_agree("bdpt", &reference, &b, 0.015, 0.1);
}

/// A red diffuse sphere on a ground plane of `ground`, seen from above
/// and in front, with no light yet.
fn red_sphere_on(ground: Material) -> Scene {
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.5, -4.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        45.0,
        1.0,
    );
    let mut scene = Scene::new(camera);
    let ground = scene.add_material(ground);
    let red = scene.add_material(Material::diffuse(Vec3::new(0.7, 0.2, 0.1)));
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-3.0, 0.0, -3.0),
            edge_u: Vec3::new(0.0, 0.0, 6.0),
            edge_v: Vec3::new(6.0, 0.0, 0.0),
        },
        ground,
    );
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.7, 0.0),
            radius: 0.7,
        },
        red,
    );
    scene
}

/// Lights at infinity: a constant sky and a sun over a diffuse sphere on
/// a ground plane, seen by bidirectional path tracing and by the path
/// tracer.
#[test]
fn bdpt_agrees_with_the_path_tracer_under_a_sky_and_a_sun() {
    let mut scene = red_sphere_on(Material::diffuse(Vec3::splat(0.7)));
    scene.environment = Some(Environment::Constant(Vec3::new(0.3, 0.4, 0.6)));
    scene.add_light(Light::directional(
        Vec3::new(0.4, -1.0, 0.3),
        Vec3::splat(2.0),
    ));
    let reference = run(&scene, &settings(32, 32, 1024, path(5)));
    let b = run(&scene, &settings(32, 32, 256, bdpt(5)));
    assert_agree("bdpt", &reference, &b, 0.01, 0.06);
}

/// A spot light shining down through a thick glass slab onto a white
/// floor ([`crate::common::glass_slab`]): the path tracer cannot find this light
/// (a point light seen through glass), light tracing can, with the
/// energy the analytic estimate gives.
#[test]
fn light_through_a_glass_slab_casts_the_caustic_an_analytic_estimate_gives() {
    let (scene, expected) = crate::common::glass_slab(false);
    let mut s = settings(64, 64, 256, bdpt(3));
    s.tile_size = 64;
    let img = run(&scene, &s);
    let centre = img.film.mean(28, 28, 36, 36);
    for c in centre.to_array() {
        assert!(
            (c / expected - 1.0).abs() < 0.05,
            "caustic {centre}, expected {expected}"
        );
    }
    // The path tracer leaves it black: the light only arrives through
    // the glass, from a point.
    let p = run(&scene, &settings(64, 64, 16, path(3)));
    assert!(p.film.mean(28, 28, 36, 36).max_element() < 0.01 * expected);
}

/// The same seed gives the same bits with one thread or two, with light
/// tracing contributions landing across tiles and a filter wider than a
/// pixel.
#[test]
fn bdpt_is_deterministic_across_thread_counts() {
    let scene = glossy_box();
    let mut s = settings(24, 24, 8, bdpt(5));
    s.filter = Filter::from(FilterKind::Mitchell);
    s.tile_size = 5;
    let bits = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let r = pool.install(|| render(&scene, &s, &|_| {}).unwrap());
        r.film
            .pixels
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect::<Vec<u32>>()
    };
    let one = bits(1);
    assert!(one == bits(2), "images differ between 1 and 2 threads");
}

/// An environment map with a small bright sun over a dim sky, lighting a
/// diffuse sphere and a rough metal ground: the path tracer samples the
/// map with MIS compensation (the texels above the mean only), the
/// bidirectional tracer with the whole map; both converge to one image.
#[test]
fn bdpt_agrees_with_the_compensated_path_tracer_under_a_sky_map_with_a_sun() {
    use sahara_render::Texture;
    use std::sync::Arc;
    let mut scene = red_sphere_on(Material::conductor(Vec3::new(0.9, 0.7, 0.4), 0.4));
    // A sky brighter towards the zenith, and a sun of 2x2 texels.
    let (w, h) = (64u32, 32u32);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (20..22).contains(&x) && (9..11).contains(&y) {
                Vec3::new(400.0, 380.0, 340.0)
            } else {
                Vec3::new(0.2, 0.3, 0.5) * (1.0 - y as f32 / h as f32)
            }
        })
        .collect();
    scene.environment = Some(Environment::Map {
        texture: Arc::new(Texture::new(w, h, texels)),
        scale: 1.0,
    });
    let reference = run(&scene, &settings(32, 32, 1024, path(5)));
    let b = run(&scene, &settings(32, 32, 256, bdpt(5)));
    assert_agree("bdpt", &reference, &b, 0.01, 0.06);
}
