//! Criterion benchmark of the sample generators: the draws one pixel sample
//! of a path makes (film, lens, time, then per bounce light pick, light
//! point, lobe, direction, roulette) for four bounces, over the samples of
//! a block of pixels, for each [`SamplerKind`].
//!
//! `cargo bench -p sahara-bench --bench sampler`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec2;
use sahara_render::internals::hash2;
use sahara_render::internals::{dims, PixelSampler, SampleId};
use sahara_render::SamplerKind;

const PIXELS: u64 = 256;
const SPP: u32 = 16;
const BOUNCES: u32 = 4;

/// The draws of one path sample, summed so that none is optimised away.
#[inline(always)]
fn path_draws(s: &PixelSampler) -> f32 {
    let mut acc = s.get_2d(dims::FILM) + s.get_2d(dims::LENS);
    let mut t = s.get_1d(dims::TIME);
    for depth in 0..BOUNCES {
        t += s.get_1d(dims::bounce(depth, dims::LIGHT_PICK));
        acc += s.get_2d(dims::bounce(depth, dims::LIGHT_POINT));
        t += s.get_1d(dims::bounce(depth, dims::BSDF_LOBE));
        acc += s.get_2d(dims::bounce(depth, dims::BSDF_DIR));
        t += s.get_1d(dims::bounce(depth, dims::ROULETTE));
    }
    acc.x + acc.y + t
}

fn draws(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampler_path_draws");
    g.throughput(Throughput::Elements(PIXELS * SPP as u64));
    for (name, kind) in [
        ("independent", SamplerKind::Independent),
        ("stratified", SamplerKind::Stratified),
        ("sobol", SamplerKind::Sobol),
    ] {
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                let mut sum = Vec2::ZERO;
                for pixel in 0..PIXELS {
                    let stream = hash2(black_box(0), pixel);
                    for index in 0..SPP {
                        let id = SampleId {
                            stream,
                            pass: 0,
                            index,
                            count: SPP,
                        };
                        sum.x += path_draws(&PixelSampler::new(black_box(kind), id));
                    }
                }
                sum
            })
        });
    }
    g.finish();
}

criterion_group!(benches, draws);
criterion_main!(benches);
