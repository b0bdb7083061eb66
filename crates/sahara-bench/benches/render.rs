//! Criterion benchmark of the render loop on the built-in Cornell box: one
//! 64x64 pass on one thread (tree build included: 32 triangles) with the
//! path tracer and the distribution ray tracer, which the loop traces in
//! batches (camera packets, octant-grouped bounce and shadow rays), and
//! with ambient occlusion, which it traces one path at a time; and the
//! render loop alone on the Mitsuba comparison kit's two scenes
//! (`dragon_glossy`, `sponza_sun`): one 64x64 pass of the file's
//! integrator, sampler and filter on one thread, the scene's trees built
//! once outside the timing. The kit's scene files are those
//! `../shared/compare/mitsuba/scenes.py OUTDIR` (or its `compare.sh`)
//! writes; the benchmark reads them from `SAHARA_KIT` (default
//! `${TMPDIR:-/tmp}/sahara-mitsuba-compare/scenes`) and says which it
//! skips.
//!
//! `cargo bench -p sahara-bench --bench render`

use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sahara_formats::load_scene;
use sahara_render::internals::{render_world, World};
use sahara_render::{builtin, render, FrameSettings, Integrator, RenderSettings};

const SIZE: u32 = 64;
const SPP: u32 = 4;

fn cornell(c: &mut Criterion) {
    let scene = builtin::cornell_box();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let mut g = c.benchmark_group("render_cornell_64px_4spp");
    g.throughput(Throughput::Elements(u64::from(SIZE * SIZE * SPP)));
    g.sample_size(10);
    for name in ["path", "distribution", "ao"] {
        let settings = RenderSettings::from(FrameSettings {
            width: SIZE,
            height: SIZE,
            spp: SPP,
            integrator: Integrator::named(name).expect("a known integrator"),
            ..Default::default()
        });
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| pool.install(|| black_box(render(&scene, &settings, &|_| {}).unwrap())))
        });
    }
    g.finish();
}

/// Where the kit's scene files are.
fn kit_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("SAHARA_KIT") {
        return dir.into();
    }
    std::env::temp_dir().join("sahara-mitsuba-compare/scenes")
}

fn kit(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let dir = kit_dir();
    let mut g = c.benchmark_group("render_kit_64px");
    g.sample_size(10);
    for name in ["dragon_glossy", "sponza_sun"] {
        let path = dir.join(format!("{name}.toml"));
        let assembled = match load_scene(&path) {
            Ok(a) => a,
            Err(e) => {
                eprintln!(
                    "SKIPPED: render_kit_64px/{name}: {e} (write the kit's scenes with \
                     ../shared/compare/mitsuba/scenes.py DIR and set SAHARA_KIT=DIR)"
                );
                continue;
            }
        };
        let file = assembled
            .settings
            .expect("a scene file's settings")
            .frame_settings();
        let mut scene = assembled.scene;
        scene.camera.aspect = 1.0;
        let settings = RenderSettings::from(FrameSettings {
            width: SIZE,
            height: SIZE,
            spp: file.spp,
            integrator: file.integrator,
            sampler: file.sampler,
            filter: file.filter,
            seed: file.seed,
            ..Default::default()
        });
        let mut world = World::new(&scene, &settings.build);
        g.throughput(Throughput::Elements(u64::from(SIZE * SIZE * file.spp)));
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                pool.install(|| {
                    black_box(
                        render_world(
                            &mut world,
                            &settings,
                            &|_| {},
                            None,
                            Instant::now(),
                            Duration::ZERO,
                        )
                        .unwrap(),
                    )
                })
            })
        });
    }
    g.finish();
}

criterion_group!(benches, cornell, kit);
criterion_main!(benches);
