//! Energy tests with closed-form answers: furnaces, mirror and glass.

use crate::common::{masked_mean, path, pixel_inside_sphere, run, settings};
use glam::Vec3;
use sahara_render::{Camera, Environment, Integrator, Material, Scene, Shape};

fn sphere_in_environment(material: Material) -> Scene {
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, -4.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0);
    let mut scene = Scene::new(cam);
    let m = scene.add_material(material);
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        m,
    );
    scene.environment = Some(Environment::Constant(Vec3::ONE));
    scene
}

/// White furnace: a convex diffuse object of albedo a in a uniform
/// environment of radiance 1 reflects exactly a (light leaving it never
/// meets it again), and the background is 1.
#[test]
fn white_furnace_sphere_in_uniform_environment() {
    for albedo in [1.0f32, 0.5] {
        let scene = sphere_in_environment(Material::diffuse(Vec3::splat(albedo)));
        let s = settings(32, 32, 64, Integrator::default());
        let r = run(&scene, &s);
        let inside = |x, y| pixel_inside_sphere(&scene, (32, 32), x, y, Vec3::ZERO, 1.0, 0.95);
        let (m_in, n_in) = masked_mean(&r, inside);
        assert!(n_in > 100);
        assert!(
            (m_in - albedo as f64).abs() < 0.005 * albedo as f64,
            "albedo {albedo}: sphere mean {m_in}"
        );
        let (m_out, _) = masked_mean(&r, |x, y| {
            !pixel_inside_sphere(&scene, (32, 32), x, y, Vec3::ZERO, 1.0, 1.15)
        });
        assert!((m_out - 1.0).abs() < 1e-6, "background {m_out}");
        for y in 0..32 {
            for x in 0..32 {
                if inside(x, y) {
                    let v = r.film.get(x, y).x;
                    assert!((v - albedo).abs() < 0.06 * albedo, "pixel ({x},{y}) = {v}");
                }
            }
        }
    }
}

/// Inside a closed diffuse enclosure of albedo rho emitting Le everywhere,
/// radiance after at most N bounces is Le (1 + rho + ... + rho^N)
/// (L = Le + rho L, truncated); without truncation Le / (1 - rho).
#[test]
fn interior_furnace_geometric_series() {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0, 1.0);
    let (le, rho) = (0.5f32, 0.5f32);
    let mut scene = Scene::new(cam);
    let mut m = Material::diffuse(Vec3::splat(rho)).with_emission(Vec3::splat(le));
    m.two_sided_emission = true;
    let m = scene.add_material(m);
    scene.add_shape(
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        m,
    );
    for (integrator, expected) in [
        (path(0), 0.5),
        (path(1), 0.75),
        (path(3), 0.9375),
        (
            Integrator::Path {
                max_depth: 40,
                rr_depth: 2,
            },
            1.0,
        ),
    ] {
        let r = run(&scene, &settings(16, 16, 64, integrator));
        let (mean, _) = masked_mean(&r, |_, _| true);
        assert!(
            (mean - expected).abs() < 0.01 * expected,
            "{integrator:?}: {mean} vs {expected}"
        );
    }
}

/// A mirror of reflectance 1 in a uniform environment shows exactly 1,
/// with either integrator; smooth glass, which only redistributes energy,
/// also shows 1 (the 1/eta^2 radiance scale on entering cancels on leaving).
#[test]
fn mirror_and_glass_conserve_energy() {
    for integrator in [
        path(64),
        Integrator::Distribution {
            max_depth: 64,
            light_samples: 1,
        },
    ] {
        let scene = sphere_in_environment(Material::mirror(Vec3::ONE));
        let r = run(&scene, &settings(24, 24, 4, integrator));
        for p in &r.film.pixels {
            assert!((p.x - 1.0).abs() < 1e-5, "mirror {integrator:?}: {p}");
        }
        let scene = sphere_in_environment(Material::glass(1.5));
        let r = run(&scene, &settings(24, 24, 16, integrator));
        let (mean, _) = masked_mean(&r, |_, _| true);
        assert!(
            (mean - 1.0).abs() < 2e-3,
            "glass {integrator:?}: mean {mean}"
        );
        for p in &r.film.pixels {
            assert!((p.x - 1.0).abs() < 0.07, "glass {integrator:?}: {p}");
        }
    }
    // With Russian roulette the estimate stays unbiased.
    let scene = sphere_in_environment(Material::glass(1.5));
    let r = run(&scene, &settings(24, 24, 64, Integrator::default()));
    let (mean, _) = masked_mean(&r, |_, _| true);
    assert!((mean - 1.0).abs() < 0.02, "glass with roulette: {mean}");
}

/// Rough microfacet surfaces lose a little energy (single scattering) but
/// never create any.
#[test]
fn rough_surfaces_do_not_create_energy() {
    for (m, lo) in [
        (Material::conductor(Vec3::ONE, 0.3), 0.95),
        // Single-scattering GGX at alpha = 0.64 loses about 40% of the light
        // at grazing views (Kulla and Conty 2017); the sphere's image
        // averages over all view angles.
        (Material::conductor(Vec3::ONE, 0.8), 0.5),
        (Material::rough_glass(1.5, 0.3), 0.9),
    ] {
        let scene = sphere_in_environment(m.clone());
        let r = run(&scene, &settings(24, 24, 64, path(32)));
        let inside = |x, y| pixel_inside_sphere(&scene, (24, 24), x, y, Vec3::ZERO, 1.0, 0.95);
        let (mean, _) = masked_mean(&r, inside);
        assert!(mean <= 1.005 && mean >= lo, "{:?}: {mean}", m.bsdf);
    }
}
