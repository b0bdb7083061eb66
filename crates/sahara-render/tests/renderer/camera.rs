//! Camera effects against geometry: depth of field, motion blur,
//! antialiasing of an edge.

use crate::common::{path, run, settings};
use glam::{Affine3A, Vec3};
use sahara_render::{Camera, Instance, Material, SamplerKind, Scene, Shape, Srt};

/// Pixels per world unit at distance `z` for a camera of vertical field of
/// view `vfov` and `h` rows.
fn px_per_unit(h: u32, vfov_deg: f32, z: f32) -> f32 {
    h as f32 / (2.0 * z * (vfov_deg.to_radians() / 2.0).tan())
}

/// A small emissive square of side `s` facing the camera at depth `z`,
/// centred on the centre of pixel (32, 32) of a 64 x 64 image. The camera
/// looks down +Z, so world +X is image left and +Y image up.
fn point_scene(cam: Camera, z: f32, s: f32) -> Scene {
    let k = px_per_unit(64, cam.vfov_deg, z);
    let c = Vec3::new(-0.5 / k, -0.5 / k, z);
    let mut scene = Scene::new(cam);
    let mut m = Material::emitter(Vec3::ONE);
    m.two_sided_emission = true;
    let m = scene.add_material(m);
    scene.add_shape(
        Shape::Quad {
            corner: c - Vec3::new(s / 2.0, s / 2.0, 0.0),
            edge_u: Vec3::new(0.0, s, 0.0),
            edge_v: Vec3::new(s, 0.0, 0.0),
        },
        m,
    );
    scene
}

#[test]
fn depth_of_field_follows_the_thin_lens() {
    let (aperture, focus) = (0.5f32, 10.0f32);
    let cam =
        Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 20.0, 1.0).with_thin_lens(aperture, focus);
    // 0.73 px on the focal plane: large enough that 256 samples resolve
    // its area to 1/256 / 0.53 = 0.7%, small enough to sit in one pixel.
    let s = 0.04;
    // On the focal plane: all the energy in one pixel.
    let r = run(&point_scene(cam, focus, s), &settings(64, 64, 256, path(0)));
    let total: f32 = r.film.pixels.iter().map(|p| p.x).sum();
    let k = px_per_unit(64, 20.0, focus);
    assert!(
        (total / (s * k).powi(2) - 1.0).abs() < 0.01,
        "energy {total}"
    );
    assert!(
        r.film.get(32, 32).x / total > 0.999,
        "focused point spread out"
    );

    // At half the focus distance: a disc of radius A |z - f| / z on the
    // focal plane, i.e. A * k(f) pixels for z = f / 2.
    let z = focus / 2.0;
    let r = run(&point_scene(cam, z, s), &settings(64, 64, 256, path(0)));
    let expected_r = aperture * (focus - z) / z * k;
    let mut sum = 0.0f64;
    let mut m2 = 0.0f64;
    let mut outside = 0.0f64;
    for y in 0..64 {
        for x in 0..64 {
            let v = r.film.get(x, y).x as f64;
            let d2 = (x as f64 - 32.0).powi(2) + (y as f64 - 32.0).powi(2);
            sum += v;
            m2 += v * d2;
            if d2.sqrt() > expected_r as f64 + 1.5 {
                outside += v;
            }
        }
    }
    let ks = (s * px_per_unit(64, 20.0, z)) as f64;
    assert!(
        (sum / (ks * ks) - 1.0).abs() < 0.02,
        "defocused energy {sum}"
    );
    // A uniform disc of radius R has E[r^2] = R^2 / 2; the square's own
    // extent and the pixel grid add side^2 / 6 and 1 / 6.
    let r2 = m2 / sum - ks * ks / 6.0 - 1.0 / 6.0;
    let radius = (2.0 * r2).sqrt();
    assert!(
        (radius / expected_r as f64 - 1.0).abs() < 0.02,
        "circle of confusion {radius} px, thin lens says {expected_r}"
    );
    assert!(
        outside / sum < 0.005,
        "energy beyond the circle: {}",
        outside / sum
    );
}

#[test]
fn motion_blur_leaves_the_coverage_ramp() {
    // A unit square moving from world x = +2 to -2 (image left to right)
    // at depth 10 while the shutter is open.
    let (w, h, vfov) = (64u32, 16u32, 20.0f32);
    let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, vfov, w as f32 / h as f32)
        .with_shutter(0.0, 1.0);
    let mut scene = Scene::new(cam);
    let mut m = Material::emitter(Vec3::ONE);
    m.two_sided_emission = true;
    let m = scene.add_material(m);
    let quad = Shape::Quad {
        corner: Vec3::new(-0.5, -0.5, 0.0),
        edge_u: Vec3::Y,
        edge_v: Vec3::X,
    };
    let mesh = scene.add_mesh(quad.to_mesh());
    let (x0, x1) = (2.0f32, -2.0f32);
    scene.add_instance(Instance::moving(
        mesh,
        Srt::translation(Vec3::new(x0, 0.0, 10.0)),
        Srt::translation(Vec3::new(x1, 0.0, 10.0)),
        Some(m),
    ));
    let spp = 1024;
    let r = run(&scene, &settings(w, h, spp, path(0)));
    let k = px_per_unit(h, vfov, 10.0);
    // Image interval of the square at shutter fraction t: [lo(t), lo(t) + k]
    // with lo(t) = w/2 - (x(t) + 1/2) k.
    let lo0 = w as f32 / 2.0 - (x0 + 0.5) * k;
    let v = (x0 - x1) * k;
    let coverage = |x: f32| {
        // Times with lo(t) <= x <= lo(t) + k.
        let (t0, t1) = ((x - k - lo0) / v, (x - lo0) / v);
        (t1.min(1.0) - t0.max(0.0)).max(0.0)
    };
    for y in 6..10 {
        for px in 0..w {
            let n = 200;
            let expected: f32 = (0..n)
                .map(|i| coverage(px as f32 + (i as f32 + 0.5) / n as f32))
                .sum::<f32>()
                / n as f32;
            let got = r.film.get(px, y).x;
            assert!(
                (got - expected).abs() < 0.02,
                "pixel ({px},{y}): {got} vs {expected}"
            );
        }
    }
}

/// Area of the part of pixel [px, px+1] x [py, py+1] where
/// a x + b y + c >= 0 (Sutherland-Hodgman clipping, then the shoelace).
fn covered_area(px: f64, py: f64, a: f64, b: f64, c: f64) -> f64 {
    let poly = [
        (px, py),
        (px + 1.0, py),
        (px + 1.0, py + 1.0),
        (px, py + 1.0),
    ];
    let f = |p: (f64, f64)| a * p.0 + b * p.1 + c;
    let mut out = Vec::new();
    for i in 0..4 {
        let (p, q) = (poly[i], poly[(i + 1) % 4]);
        let (fp, fq) = (f(p), f(q));
        if fp >= 0.0 {
            out.push(p);
        }
        if (fp >= 0.0) != (fq >= 0.0) {
            let t = fp / (fp - fq);
            out.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
        }
    }
    let mut area = 0.0;
    for i in 0..out.len() {
        let (p, q) = (out[i], out[(i + 1) % out.len()]);
        area += p.0 * q.1 - q.0 * p.1;
    }
    0.5 * area.abs()
}

#[test]
fn antialiased_edge_matches_exact_coverage() {
    let (w, h, vfov) = (32u32, 32u32, 30.0f32);
    let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, vfov, 1.0);
    let mut scene = Scene::new(cam);
    let mut m = Material::emitter(Vec3::ONE);
    m.two_sided_emission = true;
    let m = scene.add_material(m);
    // The half-plane X cos(th) - Y sin(th) >= 0 of the plane z = 10, as a
    // large quad whose one edge passes through the optical axis.
    let th = 0.35f32;
    let d = Vec3::new(th.sin(), th.cos(), 0.0);
    let n = Vec3::new(th.cos(), -th.sin(), 0.0);
    let big = 100.0;
    scene.add_object(
        Shape::Quad {
            corner: Vec3::new(0.0, 0.0, 10.0) - big * d,
            edge_u: 2.0 * big * d,
            edge_v: big * n,
        }
        .to_mesh(),
        Affine3A::IDENTITY,
        m,
    );
    // In raster space X = (w/2 - x) / k and Y = (h/2 - y) / k, so the
    // covered side is (w/2 - x) cos(th) - (h/2 - y) sin(th) >= 0.
    let (a, b) = (-(th.cos() as f64), th.sin() as f64);
    let c = (w as f64 / 2.0) * th.cos() as f64 - (h as f64 / 2.0) * th.sin() as f64;
    let spp = 256;
    for (sampler, tol) in [
        (SamplerKind::Sobol, 0.02),
        (SamplerKind::Stratified, 0.03),
        // Independent samples: 5 standard deviations of a Bernoulli mean.
        (SamplerKind::Independent, 5.0 * 0.5 / (spp as f64).sqrt()),
    ] {
        let mut s = settings(w, h, spp, path(0));
        s.sampler = sampler;
        let r = run(&scene, &s);
        let mut worst = 0.0f64;
        let mut edge_pixels = 0;
        for y in 0..h {
            for x in 0..w {
                let exact = covered_area(x as f64, y as f64, a, b, c);
                if exact > 0.0 && exact < 1.0 {
                    edge_pixels += 1;
                }
                let got = r.film.get(x, y).x as f64;
                worst = worst.max((got - exact).abs());
            }
        }
        assert!(edge_pixels > 30);
        assert!(
            worst < tol,
            "{sampler:?}: worst coverage error {worst} (tolerance {tol})"
        );
    }
}
