//! Helpers shared by the integration tests.
#![allow(dead_code)]

use glam::Vec3;
use sahara_render::{
    render, Filter, FilterKind, Integrator, RenderResult, RenderSettings, SamplerKind, Scene,
};

/// Settings for a small test render with a one-pixel box filter, its
/// samples in one pass.
pub fn settings(width: u32, height: u32, spp: u32, integrator: Integrator) -> RenderSettings {
    RenderSettings {
        width,
        height,
        spp,
        pass_spp: spp,
        integrator,
        filter: Filter::from(FilterKind::Box),
        sampler: SamplerKind::Sobol,
        tile_size: 16,
        seed: 1,
        ..Default::default()
    }
}

/// Renders and checks the image is free of NaN and negative values.
pub fn run(scene: &Scene, s: &RenderSettings) -> RenderResult {
    let r = render(scene, s, &|_| {});
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
