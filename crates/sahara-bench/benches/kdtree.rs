//! Criterion benchmarks of the accelerator's hot paths on the Stanford bunny
//! (read in place from the shared scenes, `$SAHARA_SCENES` to override):
//! building each kind of tree, tracing the protocol's ray sets on one
//! thread (closest hit for primary / diffuse / random, any hit for shadow)
//! ray by ray and as batches (interleaved over the wide nodes, and over
//! the binary nodes one by one), primary rays in 4x2 tiles as single rays and as packets, in 4x4 tiles
//! as 16-ray packets, and the
//! leaf tests alone (eight triangles against one ray, one triangle against
//! eight rays, eight triangles against a packet's frustum; portable builds,
//! as the benchmark binary is compiled, and the frustum cull's AVX2 form).
//!
//! `cargo bench -p sahara-bench --bench kdtree`

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sahara_bench::protocol::{random_rays, secondary_rays, ImageSize};
use sahara_bench::runner::PacketSize;
use sahara_bench::{HitRecord, ProtocolCamera, SceneFrame};
use sahara_kd::internals::{BatchWalk, Frustum, IndexedBlocks, PacketShear, RayShear, BLOCK_WIDTH};
use sahara_kd::Mesh;
use sahara_kd::{BuildParams, Builder, KdTree, Ray, TriangleBlock};

/// The shared scene folder: `$SAHARA_SCENES` if set, else `shared/scenes`
/// beside the workspace.
fn scenes_dir() -> PathBuf {
    match std::env::var_os("SAHARA_SCENES") {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    }
}

/// Rays per traced batch: enough to leave the caches' warm-up behind.
const BATCH: usize = 1 << 16;

fn bunny() -> Option<Mesh> {
    let path = scenes_dir().join("bunny/bunny.ply");
    match sahara_formats::load_mesh(&path) {
        Ok(m) => Some(m),
        Err(e) => {
            eprintln!("skipping the kd-tree benchmarks: {e}");
            None
        }
    }
}

fn build(c: &mut Criterion) {
    let Some(mesh) = bunny() else { return };
    let tris = mesh.triangles();
    let mut g = c.benchmark_group("build_bunny");
    g.sample_size(10);
    g.throughput(Throughput::Elements(tris.len() as u64));
    for b in [
        Builder::Sah,
        Builder::Binned { bins: 16 },
        Builder::parse("largest-middle").unwrap(),
    ] {
        g.bench_function(BenchmarkId::from_parameter(b.name()), |bench| {
            bench.iter(|| KdTree::build(tris.clone(), &BuildParams::new(b)))
        });
    }
    g.finish();
}

/// Every `step`-th ray, so that a batch samples the whole image.
fn spread(rays: &[Ray], n: usize) -> Vec<Ray> {
    let step = (rays.len() / n).max(1);
    rays.iter().step_by(step).take(n).copied().collect()
}

fn trace(c: &mut Criterion) {
    let Some(mesh) = bunny() else { return };
    let frame = SceneFrame::from_mesh(&mesh).expect("bunny is a valid mesh");
    let sidecar =
        sahara_readers::camera::read_sidecar(&scenes_dir().join("bunny/bunny.camera.json"));
    let camera = match sidecar {
        Ok(s) => ProtocolCamera {
            eye: s.eye,
            target: s.target,
            up: s.up,
            vfov_deg: s.vfov_deg,
        },
        Err(_) => ProtocolCamera::auto(&frame),
    };
    let tree = KdTree::build(mesh.triangles(), &BuildParams::new(Builder::Sah));
    let primary = camera.primary_rays(ImageSize::PROTOCOL);
    let hits: Vec<HitRecord> = primary
        .iter()
        .map(|r| HitRecord::from_closest(tree.closest_hit(r)))
        .collect();
    let secondary = secondary_rays(&mesh, &frame, &primary, &hits).expect("consistent hits");
    let sets = [
        ("primary", spread(&primary, BATCH), false),
        ("shadow", spread(&secondary.shadow, BATCH), true),
        ("diffuse", spread(&secondary.diffuse, BATCH), false),
        ("random", spread(&random_rays(&frame, BATCH), BATCH), false),
    ];
    let mut g = c.benchmark_group("trace_bunny_1t");
    g.sample_size(20);
    for (name, rays, any) in &sets {
        g.throughput(Throughput::Elements(rays.len() as u64));
        g.bench_function(*name, |bench| {
            bench.iter(|| {
                if *any {
                    rays.iter().filter(|r| tree.any_hit(r)).count()
                } else {
                    rays.iter()
                        .filter(|r| tree.closest_hit(r).is_some())
                        .count()
                }
            })
        });
    }
    // Batches on this thread: the interleaved wide walk and the binary walk
    // ray by ray, on every set (whatever the batch's coherence).
    for (name, rays, any) in &sets {
        g.throughput(Throughput::Elements(rays.len() as u64));
        for walk in [BatchWalk::Wide, BatchWalk::Binary] {
            let label = format!("{name}_batch_{}", format!("{walk:?}").to_lowercase());
            let mut hits = vec![None; rays.len()];
            let mut occluded = vec![false; rays.len()];
            g.bench_function(label, |bench| {
                bench.iter(|| {
                    if *any {
                        tree.any_hits_walked(rays, &mut occluded, walk);
                        occluded.iter().filter(|&&o| o).count()
                    } else {
                        tree.closest_hits_walked(rays, &mut hits, walk);
                        hits.iter().filter(|h| h.is_some()).count()
                    }
                })
            });
        }
    }
    // The packet path on primary rays: whole 4x2 tiles spread over the image.
    let tiled = spread_tiles(&primary, PacketSize::Eight);
    let mut out = vec![None; tiled.len()];
    g.throughput(Throughput::Elements(tiled.len() as u64));
    g.bench_function("primary_tiles_single", |bench| {
        bench.iter(|| {
            tiled
                .iter()
                .filter(|r| tree.closest_hit(r).is_some())
                .count()
        })
    });
    g.bench_function("primary_tiles_packets", |bench| {
        bench.iter(|| {
            tree.closest_hits_packets(&tiled, &mut out);
            out.iter().filter(|h| h.is_some()).count()
        })
    });
    // The 16-ray packets on as many whole 4x4 tiles, spread the same way.
    let tiled16 = spread_tiles(&primary, PacketSize::Sixteen);
    let mut out16 = vec![None; tiled16.len()];
    g.throughput(Throughput::Elements(tiled16.len() as u64));
    g.bench_function("primary_tiles_packets16", |bench| {
        bench.iter(|| {
            tree.closest_hits_packets16(&tiled16, &mut out16);
            out16.iter().filter(|h| h.is_some()).count()
        })
    });
    g.finish();

    // The leaf block filter alone: eight bunny triangles against rays aimed
    // at them (the hot loop of every leaf visit).
    let tris = mesh.triangles();
    let block = TriangleBlock::pack(&tris[..BLOCK_WIDTH]);
    let centre = tris[0].v[0];
    let shears: Vec<RayShear> = spread(&primary, 1024)
        .iter()
        .map(|r| {
            RayShear::new(
                r.origin,
                centre - r.origin + (r.dir - r.dir.normalize()) * 0.01,
            )
        })
        .collect();
    let mut g = c.benchmark_group("leaf_block");
    g.throughput(Throughput::Elements((shears.len() * BLOCK_WIDTH) as u64));
    g.bench_function("block_candidates_8", |bench| {
        bench.iter(|| {
            shears
                .iter()
                .map(|s| {
                    s.block_candidates(std::hint::black_box(&block), BLOCK_WIDTH)
                        .count_ones()
                })
                .sum::<u32>()
        })
    });
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        g.bench_function("block_candidates_8_avx2", |bench| {
            bench.iter(|| {
                let block = std::hint::black_box(&block);
                shears
                    .iter()
                    // SAFETY: the CPU has AVX2 (checked above).
                    .map(|s| {
                        unsafe { s.block_edges_avx2(block, BLOCK_WIDTH) }
                            .0
                            .count_ones()
                    })
                    .sum::<u32>()
            })
        });
    }
    // The same filter on the compact layout's block (`--compact-leaves`):
    // the eight triangles' distinct vertices sheared once, the lanes
    // gathered from them (portable, and the AVX2 intrinsics form).
    let run: Vec<u32> = (0..BLOCK_WIDTH as u32).collect();
    let (pool, starts) = IndexedBlocks::pack(&tris[..BLOCK_WIDTH], &run);
    let indexed = pool.checked_block(starts[0] as usize).expect("one block");
    g.bench_function("block_candidates_8_compact", |bench| {
        bench.iter(|| {
            let block = std::hint::black_box(indexed);
            shears
                .iter()
                .map(|s| s.indexed_edges(block, BLOCK_WIDTH).0.count_ones())
                .sum::<u32>()
        })
    });
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        g.bench_function("block_candidates_8_compact_avx2", |bench| {
            bench.iter(|| {
                let block = std::hint::black_box(indexed);
                shears
                    .iter()
                    // SAFETY: the CPU has AVX2 (checked above).
                    .map(|s| {
                        unsafe { s.indexed_edges_avx2(block, BLOCK_WIDTH) }
                            .0
                            .count_ones()
                    })
                    .sum::<u32>()
            })
        });
    }
    // The packet leaf test: the same rays eight at a time against each
    // triangle of the block (the ray-parallel form of the filter above).
    let packets: Vec<PacketShear> = shears.chunks(8).filter_map(PacketShear::new).collect();
    assert_eq!(
        packets.len() * 8,
        shears.len(),
        "rays aimed alike share a permutation"
    );
    g.bench_function("triangle_packet_8", |bench| {
        bench.iter(|| {
            let block = std::hint::black_box(&block);
            packets
                .iter()
                .map(|p| {
                    (0..BLOCK_WIDTH)
                        .map(|j| p.triangle_edges(&block.triangle(j)).0.count_ones())
                        .sum::<u32>()
                })
                .sum::<u32>()
        })
    });
    // The packet's frustum cull: the same packets' frusta against the
    // block's eight triangles at once (what runs before the test above).
    let frusta: Vec<Frustum> = shears
        .chunks(8)
        .filter_map(|s| Frustum::new(s, 0xff))
        .collect();
    assert_eq!(frusta.len(), packets.len(), "camera rays share an origin");
    g.bench_function("frustum_cull_8", |bench| {
        bench.iter(|| {
            let block = std::hint::black_box(&block);
            frusta
                .iter()
                .map(|f| f.survivors(block, BLOCK_WIDTH).count_ones())
                .sum::<u32>()
        })
    });
    // The same cull in AVX2 intrinsics (what the packet path runs on such
    // CPUs).
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        g.bench_function("frustum_cull_8_avx2", |bench| {
            bench.iter(|| {
                let block = std::hint::black_box(&block);
                frusta
                    .iter()
                    // SAFETY: the CPU has AVX2 (checked above).
                    .map(|f| unsafe { f.survivors_avx2(block, BLOCK_WIDTH) }.count_ones())
                    .sum::<u32>()
            })
        });
    }
    g.finish();
}

/// The rays of `BATCH / size.rays()` whole tiles of the protocol image,
/// evenly spread over it, tile after tile.
fn spread_tiles(primary: &[Ray], size: PacketSize) -> Vec<Ray> {
    let order = sahara_bench::runner::packets::tile_order(ImageSize::PROTOCOL, size);
    let n = size.rays();
    let tiles: Vec<&[u32]> = order.chunks(n).collect();
    let step = (tiles.len() / (BATCH / n)).max(1);
    tiles
        .iter()
        .step_by(step)
        .take(BATCH / n)
        .flat_map(|t| t.iter().map(|&i| primary[i as usize]))
        .collect()
}

criterion_group!(benches, build, trace);
criterion_main!(benches);
