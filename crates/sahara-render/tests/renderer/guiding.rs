//! Path guiding: a guided `path` renders the image unguided `path`
//! renders (within the noise), the same bits at any thread count, and a
//! farm's part refuses it.

use crate::common::{run, settings};
use sahara_render::{builtin, render, Guiding, Integrator, PixelWindow, RenderSettings, Scene};

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

#[test]
fn guided_renders_are_the_same_bits_at_any_thread_count() {
    let scene = builtin::cornell_box();
    let mut s = settings(24, 24, 16, Integrator::default());
    s.pass_spp = 4;
    s.tile_size = 5;
    s.guiding = Guiding::On;
    let one = bits(1, &scene, &s);
    let two = bits(2, &scene, &s);
    assert!(one == two, "guided images differ between 1 and 2 threads");
    s.guiding = Guiding::Off;
    assert!(bits(2, &scene, &s) != one, "guiding changed nothing");
}

/// Mean of each channel over the image.
fn mean(scene: &Scene, s: &RenderSettings) -> [f64; 3] {
    let r = run(scene, s);
    let mut m = [0.0f64; 3];
    for p in &r.film.pixels {
        for (c, v) in m.iter_mut().enumerate() {
            *v += p[c] as f64;
        }
    }
    m.map(|v| v / r.film.pixels.len() as f64)
}

/// The image's mean, guided and not, over several seeds: the two agree
/// within five standard errors measured from the seeds' spread.
#[test]
fn guided_path_agrees_with_unguided_path() {
    let scene = builtin::cornell_box();
    let seeds = 8u64;
    let mut per = [Vec::new(), Vec::new()];
    for (k, guiding) in [Guiding::Off, Guiding::On].into_iter().enumerate() {
        for seed in 0..seeds {
            let mut s = settings(16, 16, 64, Integrator::default());
            s.pass_spp = 8;
            s.seed = seed + 10;
            s.guiding = guiding;
            per[k].push(mean(&scene, &s));
        }
    }
    for c in 0..3 {
        let stats = |v: &[[f64; 3]]| {
            let n = v.len() as f64;
            let m = v.iter().map(|x| x[c]).sum::<f64>() / n;
            let var = v.iter().map(|x| (x[c] - m).powi(2)).sum::<f64>() / (n - 1.0);
            (m, var / n)
        };
        let (mu, vu) = stats(&per[0]);
        let (mg, vg) = stats(&per[1]);
        let se = (vu + vg).sqrt();
        assert!(
            se > 0.0 && se < 0.02 * mu,
            "channel {c}: standard error {se} of {mu}"
        );
        assert!(
            (mg - mu).abs() < 5.0 * se,
            "channel {c}: guided {mg} vs unguided {mu} (standard error {se})"
        );
    }
}

#[test]
fn a_farms_part_refuses_guiding_in_one_line_and_auto_renders_it_unguided() {
    let scene = builtin::cornell_box();
    let mut s = settings(16, 16, 8, Integrator::default());
    s.guiding = Guiding::On;
    s.part = true;
    s.window = Some(PixelWindow {
        x0: 0,
        x1: 16,
        y0: 0,
        y1: 8,
    });
    let e = render(&scene, &s, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("part") && !e.contains('\n'), "{e}");
    s.window = None;
    s.samples = Some(0..4);
    let e = render(&scene, &s, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("part"), "{e}");
    // Another integrator: refused too.
    let mut b = settings(8, 8, 4, Integrator::Bdpt { max_depth: 4 });
    b.guiding = Guiding::On;
    assert!(render(&scene, &b, &|_| {}).is_err());
    // Auto: a part renders as unguided parts do.
    s.guiding = Guiding::Auto;
    let auto = render(&scene, &s, &|_| {}).unwrap();
    s.guiding = Guiding::Off;
    let off = render(&scene, &s, &|_| {}).unwrap();
    assert_eq!(auto.sums, off.sums);
}
