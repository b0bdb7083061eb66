//! Criterion benchmark of the render loop on the built-in Cornell box: one
//! 64x64 pass on one thread (tree build included: 32 triangles) with the
//! path tracer and the distribution ray tracer, which the loop traces in
//! batches (camera packets, octant-grouped bounce and shadow rays), and
//! with ambient occlusion, which it traces one path at a time.
//!
//! `cargo bench -p sahara-bench --bench render`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sahara_render::{builtin, render, Integrator, RenderSettings};

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
        let settings = RenderSettings {
            width: SIZE,
            height: SIZE,
            spp: SPP,
            integrator: Integrator::named(name).expect("a known integrator"),
            ..Default::default()
        };
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| pool.install(|| black_box(render(&scene, &settings, &|_| {}))))
        });
    }
    g.finish();
}

criterion_group!(benches, cornell);
criterion_main!(benches);
