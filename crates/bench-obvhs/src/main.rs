//! `bench-obvhs MESH RAYS [--any-hit] [--layout cwbvh|bvh2] [--preset NAME] [--runs N]`
//!
//! Builds one of the obvhs crate's BVHs over a mesh and traces a ray file
//! written by `sahara bench --dump-rays` on one thread, printing one JSON
//! object: the layout and preset, build time, rays, hits, the f64 sum of
//! the hits' `t`, and the best Mrays/s of `--runs` timed runs by the
//! thread's CPU time (after one warm-up run). `scripts/compare_obvhs.py`
//! runs it beside `sahara bench --rays` on the same files and checks that
//! the two agree before comparing their speeds.
//!
//! obvhs tests triangles with its own (not watertight) Möller-Trumbore
//! test, and its CWBVH traversal clamps each child's entry distance to
//! 1e-4 and ignores the ray's `tmin`: hits closer than that are lost, so
//! the comparison reports the hit counts and t-sums of both and leaves the
//! judgement of agreement to the script.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use glam::Vec3A;
use obvhs::ray::{Ray as ORay, RayHit};
use obvhs::triangle::Triangle as OTriangle;
use obvhs::BvhBuildParams;
use sahara_kd::{Ray, Triangle};

/// What to run.
struct Args {
    mesh: PathBuf,
    rays: PathBuf,
    any_hit: bool,
    layout: String,
    preset: String,
    runs: usize,
}

fn parse_args() -> Result<Args> {
    let mut it = std::env::args().skip(1);
    let mut pos = Vec::new();
    let mut a = Args {
        mesh: PathBuf::new(),
        rays: PathBuf::new(),
        any_hit: false,
        layout: "cwbvh".into(),
        preset: "slow".into(),
        runs: 3,
    };
    while let Some(s) = it.next() {
        match s.as_str() {
            "--any-hit" => a.any_hit = true,
            "--layout" => a.layout = it.next().context("--layout needs a value")?,
            "--preset" => a.preset = it.next().context("--preset needs a value")?,
            "--runs" => {
                a.runs = it
                    .next()
                    .context("--runs needs a value")?
                    .parse()
                    .context("--runs: not a number")?
            }
            "-h" | "--help" => {
                println!("usage: bench-obvhs MESH RAYS [--any-hit] [--layout cwbvh|bvh2] [--preset fast|medium|slow|very-slow] [--runs N]");
                std::process::exit(0);
            }
            _ if s.starts_with('-') => bail!("unknown option {s}"),
            _ => pos.push(PathBuf::from(s)),
        }
    }
    let [mesh, rays] = <[PathBuf; 2]>::try_from(pos)
        .map_err(|_| anyhow::anyhow!("give a mesh and a ray file (see --help)"))?;
    (a.mesh, a.rays) = (mesh, rays);
    if !matches!(a.layout.as_str(), "cwbvh" | "bvh2") {
        bail!("--layout: cwbvh or bvh2, not {}", a.layout);
    }
    a.runs = a.runs.max(1);
    Ok(a)
}

fn preset(name: &str) -> Result<BvhBuildParams> {
    Ok(match name {
        "fast" => BvhBuildParams::fast_build(),
        "medium" => BvhBuildParams::medium_build(),
        "slow" => BvhBuildParams::slow_build(),
        "very-slow" => BvhBuildParams::very_slow_build(),
        _ => bail!("--preset: fast, medium, slow or very-slow, not {name}"),
    })
}

/// CPU time of the calling thread.
fn thread_cpu_time() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec to write to.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// A Sahara ray as obvhs's.
fn to_obvhs(r: &Ray) -> ORay {
    ORay::new(Vec3A::from(r.origin), Vec3A::from(r.dir), r.tmin, r.tmax)
}

/// Traces every ray once: the hit count and the f64 sum of the hits' `t`
/// (0 for any-hit queries).
fn trace_all(rays: &[ORay], trace: &impl Fn(&ORay) -> Option<f32>) -> (usize, f64) {
    let mut hits = 0;
    let mut t_sum = 0.0f64;
    for r in rays {
        if let Some(t) = trace(r) {
            hits += 1;
            t_sum += t as f64;
        }
    }
    (hits, t_sum)
}

/// The best Mrays/s of `runs` timed runs by thread CPU time, after a
/// warm-up run whose hit count and t-sum are returned.
fn measure(rays: &[ORay], runs: usize, trace: impl Fn(&ORay) -> Option<f32>) -> (usize, f64, f64) {
    let (hits, t_sum) = trace_all(rays, &trace);
    let mut best = f64::INFINITY;
    for _ in 0..runs {
        let t0 = thread_cpu_time();
        std::hint::black_box(trace_all(rays, &trace));
        best = best.min((thread_cpu_time() - t0).as_secs_f64());
    }
    (hits, t_sum, rays.len() as f64 / best.max(1e-9) / 1e6)
}

fn main() -> Result<()> {
    let a = parse_args()?;
    let mesh = sahara_readers::load_mesh(&a.mesh)
        .with_context(|| format!("loading {}", a.mesh.display()))?;
    let tris: Vec<OTriangle> = Triangle::from_indexed(&mesh.positions, &mesh.indices)
        .iter()
        .filter(|t| t.v.iter().all(|v| v.is_finite()))
        .map(|t| OTriangle {
            v0: Vec3A::from(t.v[0]),
            v1: Vec3A::from(t.v[1]),
            v2: Vec3A::from(t.v[2]),
        })
        .collect();
    let rays: Vec<ORay> = sahara_bench::files::read_rays(&a.rays)
        .with_context(|| format!("reading {}", a.rays.display()))?
        .iter()
        .map(to_obvhs)
        .collect();
    let params = preset(&a.preset)?;
    let start = Instant::now();
    // The two layouts have the same query methods but no common trait.
    macro_rules! trace_with {
        ($bvh:expr) => {{
            let bvh = $bvh;
            eprintln!(
                "{} built in {:.1} ms",
                a.layout,
                start.elapsed().as_secs_f64() * 1e3
            );
            let prim = |id: usize| &tris[bvh.primitive_indices[id] as usize];
            if a.any_hit {
                measure(&rays, a.runs, |r| {
                    (!bvh.ray_traverse_miss(*r, |r, id| prim(id).intersect(r))).then_some(0.0)
                })
            } else {
                measure(&rays, a.runs, |r| {
                    let mut hit = RayHit::none();
                    bvh.ray_traverse(*r, &mut hit, |r, id| prim(id).intersect(r))
                        .then_some(hit.t)
                })
            }
        }};
    }
    let mut build_time = Duration::default();
    let (hits, t_sum, mrays) = if a.layout == "cwbvh" {
        trace_with!(obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &tris,
            params,
            &mut build_time
        ))
    } else {
        trace_with!(obvhs::bvh2::builder::build_bvh2_from_tris(
            &tris,
            params,
            &mut build_time
        ))
    };
    println!(
        "{{\"layout\": \"{}\", \"preset\": \"{}\", \"triangles\": {}, \"rays\": {}, \"hits\": {hits}, \"t_sum\": {t_sum:.6}, \"mrays_1t_cpu\": {mrays:.3}}}",
        a.layout,
        a.preset,
        tris.len(),
        rays.len()
    );
    Ok(())
}
