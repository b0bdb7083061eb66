//! A frame rendered as windows and sample ranges, its sums added up, is the
//! whole frame's render bit for bit.

use glam::Vec3;
use proptest::prelude::*;
use sahara_render::{
    builtin, render, Filter, FilterKind, FrameSettings, Integrator, Material, PathLoop,
    RenderSettings, SamplerKind, Scene, Shape, SumBuffer,
};
use sahara_render::{tile, PixelWindow};

/// The Cornell box with one more sphere of a chosen material.
fn scene(material: u8, centre: (f32, f32), radius: f32) -> Scene {
    let mut s = builtin::cornell_box();
    let m = s.add_material(match material % 5 {
        0 => Material::diffuse(Vec3::new(0.2, 0.5, 0.8)),
        1 => Material::mirror(Vec3::splat(0.9)),
        2 => Material::glass(1.5),
        3 => Material::conductor(Vec3::new(0.9, 0.6, 0.3), 0.3),
        _ => Material::emitter(Vec3::splat(4.0)),
    });
    s.add_shape(
        Shape::Sphere {
            center: Vec3::new(centre.0, radius, centre.1),
            radius,
        },
        m,
    );
    s
}

fn integrator(i: u8) -> Integrator {
    match i % 5 {
        0 => Integrator::default(),
        1 => Integrator::named("distribution").unwrap(),
        2 => Integrator::named("ao").unwrap(),
        3 => Integrator::named("normals").unwrap(),
        _ => Integrator::named("cost").unwrap(),
    }
}

fn filter(f: u8) -> Filter {
    match f % 4 {
        0 => Filter::from(FilterKind::Box),
        1 => Filter::from(FilterKind::Tent),
        2 => Filter::default(),
        _ => Filter::from(FilterKind::Mitchell),
    }
}

/// The path loops of the whole render and of its parts: the scalar one
/// for both, or the lanes, refilled in one and not in the other (a
/// sample's result does not depend on its packet).
fn path_loops(l: u8) -> (PathLoop, PathLoop) {
    match l % 3 {
        0 => (PathLoop::Scalar, PathLoop::Scalar),
        1 => (PathLoop::Lanes, PathLoop::LanesNoRefill),
        _ => (PathLoop::LanesNoRefill, PathLoop::Lanes),
    }
}

fn sampler(s: u8) -> SamplerKind {
    match s % 3 {
        0 => SamplerKind::Independent,
        1 => SamplerKind::Stratified,
        _ => SamplerKind::Sobol,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn split_sums_add_up_to_the_whole_render(
        (w, h) in (1u32..=20, 1u32..=16),
        (spp_total, pass_frac) in (1u32..=10, 0.0f64..1.0),
        (material, cx, cz, radius) in (0u8..5, 100.0f32..450.0, 100.0f32..450.0, 30.0f32..120.0),
        (integ, filt, samp, seed) in (0u8..5, 0u8..4, 0u8..3, 0u64..1000),
        tiles in 1u32..=7,
        cuts in proptest::collection::vec(0.0f64..=1.0, 0..=4),
        threads in 1usize..=2,
        lanes in 0u8..3,
    ) {
        let scene = scene(material, (cx, cz), radius);
        let pass_spp = 1 + ((spp_total - 1) as f64 * pass_frac) as u32;
        let settings = RenderSettings {
            frame: FrameSettings {
                width: w,
                height: h,
                spp: spp_total,
                pass_spp,
                seed,
                sampler: sampler(samp),
                filter: filter(filt),
                integrator: integrator(integ),
                ..Default::default()
            },
            tile_size: 8,
            path_loop: path_loops(lanes).0,
            ..Default::default()
        };
        let total = settings.spp;
        let whole = render(&scene, &settings, &|_| {}).unwrap();
        // Sample ranges at random cut points (some empty).
        let mut bounds: Vec<u32> = cuts.iter().map(|c| (c * total as f64) as u32).collect();
        bounds.push(0);
        bounds.push(total);
        bounds.sort_unstable();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut merged = SumBuffer::new(0, 0, w, h);
        for i in 0..tiles {
            let window = tile(&PixelWindow::full(w, h), i, tiles);
            for r in bounds.windows(2) {
                let part = RenderSettings {
                    window: Some(window),
                    samples: Some(r[0]..r[1]),
                    tile_size: 4,
                    path_loop: path_loops(lanes).1,
                    ..settings.clone()
                };
                let out = pool.install(|| render(&scene, &part, &|_| {}).unwrap());
                prop_assert_eq!(out.stats.spp, r[1] - r[0]);
                prop_assert_eq!(out.sums.sums.len() as u64, window.pixels());
                if !window.is_empty() {
                    prop_assert_eq!(
                        (out.sums.x0, out.sums.y0, out.sums.width, out.sums.height),
                        (window.x0, window.y0, window.width(), window.height())
                    );
                }
                merged.add(&out.sums);
            }
        }
        prop_assert!(merged == whole.sums, "the sums differ");
        if !matches!(settings.integrator, Integrator::Cost) {
            for (k, s) in merged.sums.iter().enumerate() {
                prop_assert_eq!(s.value().to_array().map(f32::to_bits),
                    whole.film.pixels[k].to_array().map(f32::to_bits));
            }
        }
    }
}
