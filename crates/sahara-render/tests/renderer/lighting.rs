//! Direct lighting against closed forms: area-light irradiance (Lambert's
//! polygon formula), the inverse-square law, and grazing light far from the
//! origin (no self-shadowing acne).

use crate::common::{path, run, settings};
use glam::{DVec3, Vec2, Vec3};
use sahara_render::{Camera, Integrator, Light, Material, Scene, Shape};
use std::f64::consts::PI;

/// The mean of `f` over the floor points seen through pixel (x, y): what a
/// one-pixel box filter estimates. An 8 x 8 midpoint rule over the pixel
/// (the closed forms are smooth at this scale); `None` if any sub-ray
/// misses the floor.
fn pixel_mean(
    cam: &Camera,
    w: u32,
    h: u32,
    x: u32,
    y: u32,
    f: impl Fn(DVec3) -> f64,
) -> Option<f64> {
    let n = 8;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let fx = x as f32 + (i as f32 + 0.5) / n as f32;
            let fy = y as f32 + (j as f32 + 0.5) / n as f32;
            sum += f(floor_point(cam, w, h, fx, fy)?);
        }
    }
    Some(sum / (n * n) as f64)
}

/// Irradiance at `x` (normal `n`) from a Lambertian polygon of radiance 1
/// (Lambert 1760): E = 1/2 |sum_i theta_i n . (R_i x R_i+1)/|R_i x R_i+1||.
fn polygon_irradiance(x: DVec3, n: DVec3, verts: &[DVec3]) -> f64 {
    let mut sum = 0.0;
    for i in 0..verts.len() {
        let a = (verts[i] - x).normalize();
        let b = (verts[(i + 1) % verts.len()] - x).normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * sum.abs()
}

/// The floor point seen through film position (x, y) in pixels.
fn floor_point(cam: &Camera, w: u32, h: u32, x: f32, y: f32) -> Option<DVec3> {
    let film = Vec2::new(x / w as f32, y / h as f32);
    let (ray, _) = cam.generate_ray(film, Vec2::ZERO, 0.0);
    if ray.dir.y >= 0.0 {
        return None;
    }
    let t = -ray.origin.y / ray.dir.y;
    Some(ray.at(t).as_dvec3())
}

#[test]
fn area_light_irradiance_matches_polygon_formula() {
    // A white floor under a 1 x 1 light at height 1 facing down, seen from
    // below the light's plane (the light itself is out of view).
    let cam = Camera::look_at(Vec3::new(0.0, 0.9, -3.0), Vec3::ZERO, Vec3::Y, 24.0, 1.0);
    let mut scene = Scene::new(cam);
    let white = scene.add_material(Material::diffuse(Vec3::ONE));
    let light = scene.add_material(Material::emitter(Vec3::ONE));
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-10.0, 0.0, -10.0),
            edge_u: Vec3::new(0.0, 0.0, 20.0),
            edge_v: Vec3::new(20.0, 0.0, 0.0),
        },
        white,
    );
    let corner = Vec3::new(-0.5, 1.0, -0.5);
    let (eu, ev) = (Vec3::X, Vec3::Z);
    scene.add_shape(
        Shape::Quad {
            corner,
            edge_u: eu,
            edge_v: ev,
        },
        light,
    );
    let verts: Vec<DVec3> = [corner, corner + eu, corner + eu + ev, corner + ev]
        .iter()
        .map(|v| v.as_dvec3())
        .collect();
    let (w, h) = (24, 24);
    for integrator in [
        path(1),
        Integrator::Distribution {
            max_depth: 0,
            light_samples: 4,
        },
    ] {
        let r = run(&scene, &settings(w, h, 1024, integrator));
        let mut checked = 0;
        for y in 0..h {
            for x in 0..w {
                // Radiance of a white Lambertian floor: E / pi.
                let Some(expected) = pixel_mean(&scene.camera, w, h, x, y, |p| {
                    polygon_irradiance(p, DVec3::Y, &verts) / PI
                }) else {
                    continue;
                };
                let got = r.film.get(x, y).x as f64;
                assert!(
                    (got - expected).abs() < 0.01 * expected + 1e-4,
                    "{integrator:?} pixel ({x},{y}): {got} vs {expected}"
                );
                checked += 1;
            }
        }
        assert!(checked > 400);
    }
}

#[test]
fn point_and_spot_lights_follow_the_inverse_square_law() {
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, -3.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0);
    let (w, h) = (16, 16);
    let pos = Vec3::new(0.3, 2.0, 0.2);
    let intensity = 5.0f32;
    for light in [
        Light::point(pos, Vec3::splat(intensity)),
        // A spot whose inner cone covers the whole view: same answer.
        Light::spot(
            pos,
            Vec3::new(0.3, 0.0, 0.2),
            Vec3::splat(intensity),
            80.0,
            85.0,
        ),
    ] {
        let mut scene = Scene::new(cam);
        let white = scene.add_material(Material::diffuse(Vec3::splat(0.5)));
        scene.add_shape(
            Shape::Quad {
                corner: Vec3::new(-10.0, 0.0, -10.0),
                edge_u: Vec3::new(0.0, 0.0, 20.0),
                edge_v: Vec3::new(20.0, 0.0, 0.0),
            },
            white,
        );
        scene.add_light(light);
        let r = run(&scene, &settings(w, h, 64, path(1)));
        for y in 0..h {
            for x in 0..w {
                let expected = pixel_mean(&cam, w, h, x, y, |p| {
                    let d = pos.as_dvec3() - p;
                    0.5 / PI * intensity as f64 * d.normalize().y / d.length_squared()
                })
                .unwrap();
                let got = r.film.get(x, y).x as f64;
                // 64 stratified samples over the pixel's footprint.
                assert!(
                    (got - expected).abs() < 0.01 * expected,
                    "{light:?} ({x},{y}): {got} vs {expected}"
                );
            }
        }
    }
}

/// Grazing sunlight on a plane 10^4 units from the origin: a self-shadowed
/// ray origin would leave black pixels (acne); every pixel must show
/// exactly rho E cos / pi.
#[test]
fn no_self_intersection_far_from_origin() {
    let base = Vec3::new(1.0e4, 3.0e3, -2.0e4);
    let cam = Camera::look_at(base + Vec3::new(0.0, 5.0, -5.0), base, Vec3::Y, 30.0, 1.0);
    let mut scene = Scene::new(cam);
    let m = scene.add_material(Material::diffuse(Vec3::splat(0.8)));
    // A slightly tilted plane, so that no coordinate is exact.
    let n = Vec3::new(0.1, 1.0, 0.05).normalize();
    let t1 = n.cross(Vec3::X).normalize();
    let t2 = t1.cross(n);
    scene.add_shape(
        Shape::Quad {
            corner: base - 50.0 * t1 - 50.0 * t2,
            edge_u: 100.0 * t2,
            edge_v: 100.0 * t1,
        },
        m,
    );
    let cos = 0.1f32;
    let sin = (1.0 - cos * cos).sqrt();
    let dir = -(n * cos + t1 * sin);
    scene.add_light(Light::directional(dir, Vec3::splat(2.0)));
    let r = run(&scene, &settings(32, 32, 2, path(1)));
    let expected = 0.8 / std::f32::consts::PI * 2.0 * cos;
    for p in &r.film.pixels {
        assert!(
            (p.x - expected).abs() < 1e-3 * expected,
            "{p} vs {expected}"
        );
    }
}
