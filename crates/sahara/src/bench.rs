//! `sahara bench`: the benchmark protocol on a mesh file or the built-in scene.

use std::fs::File;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use sahara_bench::files::{read_hits, read_rays, write_hits, write_rays};
use sahara_bench::protocol::{random_rays, secondary_rays, ImageSize, RANDOM_RAYS};
use sahara_bench::report::{BenchReport, CameraReport, SetReport, SetReports};
use sahara_bench::runner::{Bench, PacketSize, Pools};
use sahara_bench::{HitRecord, ProtocolCamera, Query, SceneFrame, SetKind};
use sahara_kd::Ray;
use sahara_render::Mesh;

use crate::cli::{BenchArgs, BenchOptions};
use crate::demo_scene::demo_scene;
use crate::human;
use crate::input::{camera_for, load_mesh};

/// The name of the set traced from `--rays FILE`.
const FILE_SET: &str = "file";

/// `sahara bench MESH ...`.
pub fn run_file(args: &BenchArgs) -> Result<()> {
    let Some(path) = &args.mesh else {
        return run_builtin(&args.opts);
    };
    let mesh = args.opts.tree.select(load_mesh(path)?);
    run(&path.display().to_string(), Some(path), &mesh, &args.opts)
}

/// `sahara bench` without a mesh: the benchmark on the built-in scene.
fn run_builtin(opts: &BenchOptions) -> Result<()> {
    let mesh = opts.tree.select(demo_scene());
    eprintln!(
        "no mesh: benchmarking the built-in scene ({} triangles)",
        mesh.triangle_count()
    );
    run(
        "built-in: sphere and torus on a ground plane",
        None,
        &mesh,
        opts,
    )
}

/// A `--dump` or `--dump-rays` request: which set, which file.
struct Dump {
    set: String,
    path: PathBuf,
}

/// Pairs `SET FILE` from a flattened option list, checking the set names and
/// creating the files now so that a bad path fails before the long runs.
fn dumps(flat: &[String], option: &str, allowed: &[&str]) -> Result<Vec<Dump>> {
    let mut out = Vec::new();
    for pair in flat.chunks(2) {
        let [set, path] = pair else {
            bail!("{option} takes SET FILE");
        };
        if !allowed.contains(&set.as_str()) {
            bail!(
                "{option} {set}: the set must be one of: {} (those being traced)",
                allowed.join(", ")
            );
        }
        let path = PathBuf::from(path);
        File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        out.push(Dump {
            set: set.clone(),
            path,
        });
    }
    Ok(out)
}

/// Write the hit records of `set` wherever `--dump` asked for them.
fn dump_hits(dumps: &[Dump], set: &str, records: &[HitRecord]) -> Result<()> {
    for d in dumps.iter().filter(|d| d.set == set) {
        write_hits(&d.path, records)?;
        eprintln!(
            "wrote {} hit records of {set} to {}",
            records.len(),
            d.path.display()
        );
    }
    Ok(())
}

/// Write the rays of `set` wherever `--dump-rays` asked for them.
fn dump_rays(dumps: &[Dump], set: &str, rays: &[Ray]) -> Result<()> {
    for d in dumps.iter().filter(|d| d.set == set) {
        write_rays(&d.path, rays)?;
        eprintln!("wrote {} rays of {set} to {}", rays.len(), d.path.display());
    }
    Ok(())
}

/// What is traced: a ray file, or the protocol's sets seen by a camera.
enum Work {
    /// `--rays FILE`.
    RayFile(Vec<Ray>),
    /// The generated sets.
    Protocol {
        /// The camera of the primary rays.
        camera: ProtocolCamera,
        /// The camera and where it came from, for the report.
        report: CameraReport,
    },
}

/// The benchmark on a loaded (and checked) mesh.
fn run(label: &str, mesh_path: Option<&Path>, mesh: &Mesh, opts: &BenchOptions) -> Result<()> {
    let frame = SceneFrame::from_mesh(mesh).with_context(|| format!("mesh {label}"))?;
    let threads = opts
        .threads
        .map_or_else(Pools::available_threads, usize::from);

    // Check every file argument before the long part.
    let (hit_dumps, ray_dumps) = if opts.rays.is_some() {
        (dumps(&opts.dump, "--dump", &[FILE_SET])?, Vec::new())
    } else {
        let traced: Vec<&str> = opts.sets.iter().map(|s| s.name()).collect();
        let all: Vec<&str> = SetKind::ALL.iter().map(|s| s.name()).collect();
        (
            dumps(&opts.dump, "--dump", &traced)?,
            dumps(&opts.dump_rays, "--dump-rays", &all)?,
        )
    };
    let foreign_primary = match &opts.primary_hits {
        Some(p) => {
            let hits = read_hits(p).context("cannot read the primary hit file")?;
            let want = ImageSize::PROTOCOL.pixels();
            if hits.len() != want {
                bail!(
                    "{}: {} hit records, but the primary set has {want} rays",
                    p.display(),
                    hits.len()
                );
            }
            Some(hits)
        }
        None => None,
    };
    let work = match &opts.rays {
        Some(p) => Work::RayFile(read_rays(p).context("cannot read the ray file")?),
        None => {
            let (camera, report) = camera_for(mesh_path, opts.camera.as_deref(), &frame)?;
            Work::Protocol { camera, report }
        }
    };

    eprintln!(
        "building the {} over {} triangles ({}, {})...",
        opts.tree.structure_name(),
        mesh.triangle_count(),
        human::count(sahara_bench::runner::BUILD_RUNS, "build"),
        human::count(threads, "thread")
    );
    let bench = Bench::new(mesh, &opts.tree.accel_params(), threads, opts.runs)
        .context("cannot start the thread pools")?;
    eprintln!("built in {:.1} ms (best)", bench.build_ms());

    let mut sets = SetReports::default();
    let camera_report = match work {
        Work::RayFile(rays) => {
            let query = if opts.any_hit {
                Query::AnyHit
            } else {
                Query::ClosestHit
            };
            sets.file = Some(measure(&bench, FILE_SET, &rays, query, opts, &hit_dumps)?);
            None
        }
        Work::Protocol { camera, report } => {
            let plan = Plan {
                hit_dumps,
                ray_dumps,
                foreign_primary,
            };
            protocol_sets(&bench, mesh, &frame, &camera, opts, plan, &mut sets)?;
            Some(report)
        }
    };

    let report = bench.report(label, camera_report, sets);
    print(&report, opts.json)
}

/// What to write, and whose primary hits seed the secondary sets.
struct Plan {
    /// `--dump` requests.
    hit_dumps: Vec<Dump>,
    /// `--dump-rays` requests.
    ray_dumps: Vec<Dump>,
    /// `--primary-hits`: another tracer's primary hits.
    foreign_primary: Option<Vec<HitRecord>>,
}

/// Generate, dump and measure the protocol's sets.
fn protocol_sets(
    bench: &Bench,
    mesh: &Mesh,
    frame: &SceneFrame,
    camera: &ProtocolCamera,
    opts: &BenchOptions,
    plan: Plan,
    sets: &mut SetReports,
) -> Result<()> {
    let (hit_dumps, ray_dumps) = (&plan.hit_dumps[..], &plan.ray_dumps[..]);
    let wanted = |k: SetKind| opts.sets.contains(&k) || ray_dumps.iter().any(|d| d.set == k.name());
    let need_secondary = wanted(SetKind::Shadow) || wanted(SetKind::Diffuse);

    if wanted(SetKind::Primary) || need_secondary {
        let primary = camera.primary_rays(ImageSize::PROTOCOL);
        dump_rays(ray_dumps, "primary", &primary)?;
        let own_hits = if opts.sets.contains(&SetKind::Primary) {
            let (mut report, records) =
                measure_records(bench, "primary", &primary, Query::ClosestHit, opts);
            for size in [PacketSize::Eight, PacketSize::Sixteen] {
                let (w, h) = size.tile();
                let n = size.rays();
                eprintln!("tracing primary in packets of {n} ({w}x{h} tiles) on 1 thread...");
                let p = bench.measure_packets(&primary, ImageSize::PROTOCOL, &records, size);
                if !p.agrees {
                    bail!(
                        "primary: the {n}-ray packet path's hits differ from the single-ray \
                         path's (a bug)"
                    );
                }
                let figures = (Some(p.mrays_1t), Some(p.mrays_1t_cpu));
                match size {
                    PacketSize::Eight => {
                        (report.mrays_packet_1t, report.mrays_packet_1t_cpu) = figures
                    }
                    PacketSize::Sixteen => {
                        (report.mrays_packet16_1t, report.mrays_packet16_1t_cpu) = figures
                    }
                }
            }
            dump_hits(hit_dumps, "primary", &records)?;
            sets.primary = Some(report);
            Some(records)
        } else {
            None
        };
        if need_secondary {
            let primary_hits = match (plan.foreign_primary, own_hits) {
                (Some(hits), _) => {
                    eprintln!("secondary sets from the primary hits of --primary-hits");
                    hits
                }
                (None, Some(hits)) => hits,
                (None, None) => {
                    eprintln!("tracing primary rays for the secondary sets (untimed)...");
                    bench.trace(&primary, Query::ClosestHit)
                }
            };
            let secondary = secondary_rays(mesh, frame, &primary, &primary_hits)
                .context("cannot generate the secondary sets")?;
            drop(primary);
            for (kind, rays) in [
                (SetKind::Shadow, &secondary.shadow),
                (SetKind::Diffuse, &secondary.diffuse),
            ] {
                dump_rays(ray_dumps, kind.name(), rays)?;
                if opts.sets.contains(&kind) {
                    *sets.slot(kind) = Some(measure(
                        bench,
                        kind.name(),
                        rays,
                        kind.query(),
                        opts,
                        hit_dumps,
                    )?);
                }
            }
        }
    }
    if wanted(SetKind::Random) {
        let rays = random_rays(frame, RANDOM_RAYS);
        dump_rays(ray_dumps, "random", &rays)?;
        if opts.sets.contains(&SetKind::Random) {
            sets.random = Some(measure(
                bench,
                "random",
                &rays,
                Query::ClosestHit,
                opts,
                hit_dumps,
            )?);
        }
    }
    Ok(())
}

/// Measure a set and dump its hits if asked.
fn measure(
    bench: &Bench,
    name: &str,
    rays: &[Ray],
    query: Query,
    opts: &BenchOptions,
    hit_dumps: &[Dump],
) -> Result<SetReport> {
    let (report, records) = measure_records(bench, name, rays, query, opts);
    dump_hits(hit_dumps, name, &records)?;
    Ok(report)
}

/// Measure a set, returning its report and records.
fn measure_records(
    bench: &Bench,
    name: &str,
    rays: &[Ray],
    query: Query,
    opts: &BenchOptions,
) -> (SetReport, Vec<HitRecord>) {
    eprintln!(
        "tracing {name}: {} rays, 1 warm-up + {} on 1 thread and on {}...",
        rays.len(),
        human::count(bench.runs(), "run"),
        human::count(bench.threads(), "thread")
    );
    let (report, m) = bench.measure(rays, query, opts.counters);
    if !m.batch_agrees {
        eprintln!("WARNING: {name}: the batch query and single rays give different results");
    }
    if !m.threads_agree {
        eprintln!(
            "WARNING: {name}: the 1-thread and {}-thread results differ",
            bench.threads()
        );
    }
    (report, m.records)
}

/// Print the report as JSON or as tables.
fn print(report: &BenchReport, json: bool) -> Result<()> {
    if json {
        let text = serde_json::to_string_pretty(report).context("cannot format the report")?;
        println!("{text}");
    } else {
        print!("{}", human::bench_report(report));
    }
    Ok(())
}
