//! Stochastic progressive photon mapping, held to the path tracer where
//! both converge, to an analytic caustic seen directly and through glass
//! (where no other integrator finds it), and to itself across thread
//! counts and windows.

use crate::common::{run, settings};
use glam::Vec3;
use sahara_render::{builtin, render, Integrator, PixelWindow, RenderSettings, Scene};

fn sppm(max_depth: u32, photons: u32) -> Integrator {
    Integrator::Sppm {
        max_depth,
        radius: 0.0,
        photons,
    }
}

/// On the Cornell box every method converges to the same image: SPPM
/// against the path tracer, in the mean and in every 8 x 8 block (photon
/// mapping's noise is blotchy, and its blur fades as the radius shrinks).
#[test]
fn sppm_agrees_with_the_path_tracer_on_a_diffuse_box() {
    let scene = builtin::cornell_box();
    let reference = run(&scene, &settings(32, 32, 1024, crate::common::path(6)));
    let s = run(&scene, &settings(32, 32, 64, sppm(6, 10_000)));
    let (ma, mb) = (reference.film.mean(0, 0, 32, 32), s.film.mean(0, 0, 32, 32));
    let rel = ((mb - ma).abs() / ma).max_element();
    assert!(rel < 0.015, "image mean {mb} vs {ma} ({rel})");
    for by in (0..32).step_by(8) {
        for bx in (0..32).step_by(8) {
            let a = reference.film.mean(bx, by, bx + 8, by + 8);
            let b = s.film.mean(bx, by, bx + 8, by + 8);
            let e = ((b - a).abs() / (a + Vec3::splat(0.1 * ma.max_element()))).max_element();
            assert!(e < 0.06, "block ({bx}, {by}): {b} vs {a} ({e})");
        }
    }
}

/// The slab's caustic, seen directly and through the slab itself
/// (specular, diffuse, specular: a point light's caustic that neither the
/// path tracer nor bidirectional path tracing can see), matches the
/// analytic estimate (see `crate::common::glass_slab`).
#[test]
fn sppm_sees_the_slab_caustic_directly_and_through_the_glass() {
    for from_above in [false, true] {
        let (scene, expected) = crate::common::glass_slab(from_above);
        // Enough depth for the photons' two refractions and the camera's
        // two, and none for light bouncing inside the slab.
        let mut s = settings(32, 32, 32, sppm(3, 100_000));
        s.tile_size = 32;
        let img = run(&scene, &s);
        let centre = img.film.mean(12, 12, 20, 20);
        for c in centre.to_array() {
            assert!(
                (c / expected - 1.0).abs() < 0.03,
                "from above {from_above}: {centre}, expected {expected}"
            );
        }
        if from_above {
            let b = run(
                &scene,
                &settings(32, 32, 16, Integrator::Bdpt { max_depth: 5 }),
            );
            assert!(b.film.mean(12, 12, 20, 20).max_element() < 0.01 * expected);
        }
    }
}

fn bits(threads: usize, scene: &Scene, s: &RenderSettings) -> Vec<u32> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let r = pool.install(|| render(scene, s, &|_| {}).unwrap());
    r.film
        .pixels
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

/// The same seed gives the same bits with one thread or two, and a window
/// of the frame rendered alone gives the whole frame's bits over it (so
/// a frame splits by tiles exactly).
#[test]
fn sppm_is_deterministic_across_threads_and_windows() {
    let (scene, _) = crate::common::glass_slab(false);
    let s = settings(24, 20, 6, sppm(5, 3000));
    let one = bits(1, &scene, &s);
    assert!(one == bits(2, &scene, &s), "1 and 2 threads differ");
    let window = PixelWindow {
        x0: 5,
        y0: 3,
        x1: 17,
        y1: 11,
    };
    let mut w = s.clone();
    w.window = Some(window);
    let part = bits(2, &scene, &w);
    let mut k = 0;
    for y in window.y0..window.y1 {
        for x in window.x0..window.x1 {
            let i = ((y * 24 + x) * 3) as usize;
            assert_eq!(&part[k..k + 3], &one[i..i + 3], "pixel ({x}, {y})");
            k += 3;
        }
    }
}
