//! Helpers shared by the integration tests.
#![allow(dead_code)]

use glam::Vec3;
use sahara_render::{
    render, Camera, Filter, FilterKind, FrameSettings, Integrator, Light, Material, RenderResult,
    RenderSettings, SamplerKind, Scene, Shape,
};

/// Settings for a small test render with a one-pixel box filter, its
/// samples in one pass.
pub fn settings(width: u32, height: u32, spp: u32, integrator: Integrator) -> RenderSettings {
    RenderSettings {
        frame: FrameSettings {
            width,
            height,
            spp,
            pass_spp: spp,
            integrator,
            filter: Filter::from(FilterKind::Box),
            sampler: SamplerKind::Sobol,
            seed: 1,
            ..Default::default()
        },
        tile_size: 16,
        ..Default::default()
    }
}

/// Renders and checks the image is free of NaN and negative values.
pub fn run(scene: &Scene, s: &RenderSettings) -> RenderResult {
    let r = render(scene, s, &|_| {}).unwrap();
    assert_eq!(r.stats.nan_samples, 0, "NaN samples");
    assert_eq!(r.stats.negative_samples, 0, "negative samples");
    for p in &r.film.pixels {
        assert!(p.is_finite() && p.min_element() >= 0.0, "bad pixel {p}");
    }
    r
}

/// The path tracer without Russian roulette.
pub fn path(max_depth: u32) -> Integrator {
    Integrator::Path {
        max_depth,
        rr_depth: u32::MAX,
    }
}

/// Mean of one channel over the pixels for which `keep(x, y)` holds.
pub fn masked_mean(r: &RenderResult, keep: impl Fn(u32, u32) -> bool) -> (f64, usize) {
    let f = &r.film;
    let mut sum = 0.0f64;
    let mut n = 0;
    for y in 0..f.height {
        for x in 0..f.width {
            if keep(x, y) {
                sum += f.get(x, y).x as f64;
                n += 1;
            }
        }
    }
    (sum / n.max(1) as f64, n)
}

/// True if the ray through the centre of pixel (x, y) passes within
/// `frac * radius` of the sphere's centre (so the pixel lies well inside the
/// sphere's image).
pub fn pixel_inside_sphere(
    scene: &Scene,
    size: (u32, u32),
    x: u32,
    y: u32,
    c: Vec3,
    radius: f32,
    frac: f32,
) -> bool {
    let film = glam::Vec2::new(
        (x as f32 + 0.5) / size.0 as f32,
        (y as f32 + 0.5) / size.1 as f32,
    );
    let (ray, _) = scene.camera.generate_ray(film, glam::Vec2::splat(0.5), 0.0);
    let oc = c - ray.origin;
    let t = oc.dot(ray.dir);
    (oc - ray.dir * t).length() < frac * radius
}

/// A spot light shining straight down through a glass slab onto a white
/// floor, and a camera looking at the lit floor either from the side or
/// from straight above, through the slab; with the radiance the camera
/// sees on the axis. There the slab of thickness `d` and index `n` makes
/// the light seem `d (1 - 1/n)` closer and passes `(1 - R)^2` of it at
/// normal incidence (`R = ((n - 1) / (n + 1))^2`; with three scattering
/// events at most, no light bounces inside the slab), so the floor's
/// radiance is `rho / pi * I (1 - R)^2 / (h - d (1 - 1/n))^2`; seen
/// through the slab, `(1 - R)^2` of that.
pub fn glass_slab(from_above: bool) -> (Scene, f32) {
    let (h, d, n, rho, intensity) = (3.0f32, 1.5f32, 1.5f32, 0.8f32, 1.0f32);
    let camera = if from_above {
        Camera::look_at(Vec3::new(0.0, 4.0, 0.0), Vec3::ZERO, Vec3::Z, 4.0, 1.0)
    } else {
        Camera::look_at(Vec3::new(0.0, 1.0, -4.0), Vec3::ZERO, Vec3::Y, 4.0, 1.0)
    };
    let mut scene = Scene::new(camera);
    let white = scene.add_material(Material::diffuse(Vec3::splat(rho)));
    let glass = scene.add_material(Material::glass(n));
    scene.add_shape(
        Shape::Quad {
            corner: Vec3::new(-10.0, 0.0, -10.0),
            edge_u: Vec3::new(0.0, 0.0, 20.0),
            edge_v: Vec3::new(20.0, 0.0, 0.0),
        },
        white,
    );
    scene.add_shape(
        Shape::Box {
            min: Vec3::new(-1.0, 0.5, -1.0),
            max: Vec3::new(1.0, 0.5 + d, 1.0),
        },
        glass,
    );
    scene.add_light(Light::spot(
        Vec3::new(0.0, h, 0.0),
        Vec3::ZERO,
        Vec3::splat(intensity),
        10.0,
        10.0,
    ));
    let r = ((n - 1.0) / (n + 1.0)).powi(2);
    let floor = rho / std::f32::consts::PI * intensity * (1.0 - r) * (1.0 - r)
        / (h - d * (1.0 - 1.0 / n)).powi(2);
    let seen = if from_above {
        floor * (1.0 - r) * (1.0 - r)
    } else {
        floor
    };
    (scene, seen)
}
