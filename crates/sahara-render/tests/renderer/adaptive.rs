//! Adaptive sampling: flat pixels stop early, noisy ones go on to the cap;
//! the decisions do not depend on threads or on the frame being split into
//! windows; a threshold no pixel reaches renders the plain image.

use crate::common::pixel_inside_sphere;
use glam::Vec3;
use sahara_render::{
    builtin, render, tile, Adaptive, Filter, FilterKind, FrameSettings, Material, PixelWindow,
    RenderResult, RenderSettings, SamplerKind, Scene, Shape, SumBuffer,
};

const SPHERE: (Vec3, f32) = (Vec3::new(278.0, 380.0, 150.0), 90.0);

/// The Cornell box with a large sphere that only emits: pixels that see
/// it see one radiance, with no noise at all.
fn scene() -> Scene {
    let mut s = builtin::cornell_box();
    let m = s.add_material(Material::emitter(Vec3::splat(2.0)));
    s.add_shape(
        Shape::Sphere {
            center: SPHERE.0,
            radius: SPHERE.1,
        },
        m,
    );
    s
}

fn settings(threshold: f32) -> RenderSettings {
    RenderSettings {
        frame: FrameSettings {
            width: 32,
            height: 32,
            spp: 64,
            pass_spp: 8,
            seed: 3,
            sampler: SamplerKind::Independent,
            filter: Filter::from(FilterKind::Box),
            adaptive: Some(Adaptive {
                threshold,
                min_spp: 16,
            }),
            ..Default::default()
        },
        tile_size: 8,
        ..Default::default()
    }
}

fn in_pool(threads: usize, scene: &Scene, s: &RenderSettings) -> RenderResult {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| render(scene, s, &|_| {}).unwrap())
}

#[test]
fn flat_pixels_stop_at_the_minimum_and_noisy_ones_reach_the_cap() {
    let scene = scene();
    let s = settings(0.002);
    let r = render(&scene, &s, &|_| {}).unwrap();
    let samples = r.samples.as_ref().expect("a sample count per pixel");
    assert_eq!(samples.len(), 32 * 32);
    let (mut flat, mut capped) = (0, 0);
    for y in 0..32 {
        for x in 0..32 {
            let n = samples[(y * 32 + x) as usize];
            assert!((16..=64).contains(&n), "pixel ({x}, {y}) took {n}");
            assert_eq!(n % 8, 0, "whole passes only");
            // A 2x2 block of pixels (they stop together) well inside the
            // emitting sphere (their filter footprints see nothing else):
            // no noise, so the minimum.
            let block =
                [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(i, j)| (x / 2 * 2 + i, y / 2 * 2 + j));
            if block
                .iter()
                .all(|&(x, y)| pixel_inside_sphere(&scene, (32, 32), x, y, SPHERE.0, SPHERE.1, 0.8))
            {
                assert_eq!(n, 16, "pixel ({x}, {y}) sees only the emitter");
                flat += 1;
            }
            capped += (n == 64) as u32;
        }
    }
    assert!(flat > 20, "{flat} pixels inside the sphere");
    assert!(capped > 100, "only {capped} pixels reached the cap");
    let a = r.stats.adaptive.expect("adaptive statistics");
    assert_eq!(a.pixels, 32 * 32);
    assert_eq!(a.budget, 32 * 32 * 64);
    assert_eq!(
        a.samples,
        samples.iter().map(|&n| u64::from(n)).sum::<u64>()
    );
    assert!(a.samples < a.budget);
    assert_eq!(r.stats.spp, 64);
    assert_eq!(
        a.converged,
        samples.iter().filter(|&&n| n < 64).count() as u64,
        "a pixel under the cap stopped below the threshold"
    );
}

#[test]
fn the_decisions_do_not_depend_on_the_thread_count() {
    let scene = scene();
    let mut s = settings(0.02);
    s.filter = Filter::from(FilterKind::Mitchell);
    s.tile_size = 5;
    let one = in_pool(1, &scene, &s);
    let two = in_pool(2, &scene, &s);
    assert_eq!(one.samples, two.samples);
    assert!(one.sums == two.sums, "the sums differ");
    let n = one.samples.as_ref().unwrap();
    assert!(n.iter().any(|&n| n < 64) && n.iter().any(|&n| n > 16));
}

#[test]
fn windows_rendered_apart_add_up_to_the_whole_frame() {
    let scene = scene();
    // A filter wider than a pixel: samples of pixels outside a window
    // reach into it, and their decisions must be the whole frame's.
    let mut s = settings(0.02);
    s.filter = Filter::from(FilterKind::Gaussian);
    let whole = render(&scene, &s, &|_| {}).unwrap();
    let full = PixelWindow::full(32, 32);
    let mut merged = SumBuffer::new(0, 0, 32, 32);
    for i in 0..5 {
        let window = tile(&full, i, 5);
        let part = RenderSettings {
            window: Some(window),
            ..s.clone()
        };
        let out = render(&scene, &part, &|_| {}).unwrap();
        // The window's sample counts are the whole frame's there.
        let counts = out.samples.as_ref().unwrap();
        let mut k = 0;
        for y in window.y0..window.y1 {
            for x in window.x0..window.x1 {
                assert_eq!(
                    counts[k],
                    whole.samples.as_ref().unwrap()[(y * 32 + x) as usize]
                );
                k += 1;
            }
        }
        merged.add(&out.sums);
    }
    assert!(
        merged == whole.sums,
        "the merged sums differ from the whole frame's"
    );
}

#[test]
fn a_threshold_no_pixel_reaches_renders_the_plain_image() {
    let scene = scene();
    let adaptive = settings(0.0);
    let mut plain = adaptive.clone();
    plain.adaptive = None;
    let a = render(&scene, &adaptive, &|_| {}).unwrap();
    let p = render(&scene, &plain, &|_| {}).unwrap();
    assert!(a.sums == p.sums, "the images differ");
    assert!(a.samples.unwrap().iter().all(|&n| n == 64));
    assert!(p.samples.is_none() && p.stats.adaptive.is_none());
}

/// Where pixels stopped, the image is about as close to a converged one
/// as the threshold asks: the error estimate is not fooled.
#[test]
fn pixels_that_stopped_are_as_clean_as_the_threshold_asks() {
    let scene = scene();
    let threshold = 0.05;
    let s = settings(threshold);
    let r = render(&scene, &s, &|_| {}).unwrap();
    let mut long = s.clone();
    (long.spp, long.pass_spp, long.adaptive, long.seed) = (1024, 64, None, 99);
    let reference = render(&scene, &long, &|_| {}).unwrap();
    let samples = r.samples.unwrap();
    // The module's error measure, against the reference instead of the
    // other half: for a stopped pixel it should be about the threshold.
    let (mut sum, mut n) = (0.0, 0);
    for (k, &count) in samples.iter().enumerate() {
        let (i, refp) = (r.film.pixels[k], reference.film.pixels[k]);
        // Capped pixels did not stop; the emitter's pixels are exact.
        if count == 64 || i == refp {
            continue;
        }
        let e = (i - refp).abs().element_sum() / (1e-4 + refp.element_sum().sqrt());
        sum += e;
        n += 1;
    }
    assert!(n > 50, "{n} pixels stopped between the minimum and the cap");
    let mean = sum / n as f32;
    // Measured 1.2x (the reference's own noise included); a noise
    // estimate that pixels can fool (the two halves' difference, one draw
    // per channel) gave 4x.
    assert!(
        mean < 1.5 * threshold,
        "stopped pixels' mean error {mean} against a threshold of {threshold}"
    );
}
