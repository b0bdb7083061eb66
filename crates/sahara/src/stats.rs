//! `sahara stats`: a tree's statistics and build time; for a scene file,
//! the trees and instances its acceleration structure was built from.

use std::fmt::Write;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use sahara_bench::report::{StatsReport, StructureRow, StructureStats};
use sahara_bench::runner::{build_timed, Pools};
use sahara_formats::is_scene_file;
use sahara_kd::{AccelParams, BvhBuilder, BvhParams, TriangleAccel};
use sahara_render::internals::World;
use serde::Serialize;

use crate::cli::StatsArgs;
use crate::human;
use crate::input::load_mesh;

/// `sahara stats MESH ...`, or `sahara stats SCENE ...`.
pub fn run(args: &StatsArgs) -> Result<()> {
    if is_scene_file(&args.mesh) {
        return run_scene(args);
    }
    let mesh = args.tree.select(load_mesh(&args.mesh)?);
    let skipped_triangles = mesh.unhittable_count();
    let threads = args
        .threads
        .map_or_else(Pools::available_threads, usize::from);
    let pools = Pools::new(threads).context("cannot start the thread pool")?;
    eprintln!(
        "building the {} over {} triangles ({})...",
        args.tree.structure_name(),
        mesh.triangle_count(),
        human::count(args.runs, "build")
    );
    let params = args.tree.accel_params();
    let tris = mesh.triangles();
    let (tree, build_ms) = build_timed(&tris, args.runs, &pools.all, |t| {
        TriangleAccel::build(t, &params)
    });
    let structures = if args.all {
        every_structure(&tris, &args.tree, args.runs, &pools)
    } else {
        Vec::new()
    };
    let report = StatsReport {
        mesh: args.mesh.display().to_string(),
        accel: params.kind.name().to_owned(),
        builder: params.builder_name(),
        build_ms,
        build_runs: args.runs,
        skipped_triangles,
        tree: match &tree {
            TriangleAccel::Kd(t) => StructureStats::Kd(t.stats()),
            TriangleAccel::Bvh(b) => StructureStats::Bvh(b.stats()),
        },
        structures,
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).context("cannot format the report")?
        );
    } else {
        print!("{}", human::stats_report(&report));
    }
    Ok(())
}

/// `sahara stats --all`: the kd-tree and the hierarchy by each of its
/// builders, over the same triangles, each built `runs` times.
fn every_structure(
    tris: &[sahara_kd::Triangle],
    tree: &crate::cli::TreeOptions,
    runs: usize,
    pools: &Pools,
) -> Vec<StructureRow> {
    let kd = AccelParams::kd(tree.params());
    let bvh = [BvhBuilder::Spatial, BvhBuilder::Binned, BvhBuilder::FromKd].map(|b| AccelParams {
        bvh: BvhParams {
            kd: tree.params(),
            ..BvhParams::new(b)
        },
        ..AccelParams::bvh(b)
    });
    std::iter::once(kd)
        .chain(bvh)
        .map(|p| {
            let (t, build_ms) =
                build_timed(tris, runs, &pools.all, |t| TriangleAccel::build(t, &p));
            let summary = t.summary();
            eprintln!("  {}: {build_ms:.1} ms", summary.structure);
            StructureRow {
                structure: summary.structure.clone(),
                build_ms,
                summary: (&summary).into(),
            }
        })
        .collect()
}

/// What `sahara stats` says of a scene: how its acceleration structure
/// was organised (see `docs/accelerator.md`).
#[derive(Debug, Serialize)]
pub struct SceneStatsReport {
    /// The scene file.
    pub scene: String,
    /// Builder name.
    pub builder: String,
    /// Best time to build the trees and the lights, milliseconds.
    pub build_ms: f64,
    /// Builds timed.
    pub build_runs: usize,
    /// Instances in all.
    pub instances: usize,
    /// Instances whose triangles went into the one world-space tree.
    pub merged_instances: usize,
    /// Instances traced in two levels (shared meshes, moving instances,
    /// analytic emitters).
    pub two_level_instances: usize,
    /// Trees built: the world tree, if any, and one per mesh of the
    /// two-level instances.
    pub trees: usize,
    /// Triangles in the world tree.
    pub world_triangles: usize,
    /// Triangles of all instances (an instanced mesh counted once per
    /// instance).
    pub instanced_triangles: u64,
    /// Of those, the ones no ray can hit (a non-finite corner or zero
    /// area), which the trees leave out.
    pub skipped_triangles: u64,
    /// Bytes held by the trees.
    pub memory_bytes: usize,
}

/// `sahara stats SCENE ...`: builds the scene's trees as a render does.
fn run_scene(args: &StatsArgs) -> Result<()> {
    if args.tree.subset.is_some() {
        bail!("--subset applies to meshes, not to scene files");
    }
    let input = crate::scene_input::load_input(Some(&args.mesh), None, None, &[])?;
    crate::warnings::print(&input.problems());
    let threads = args
        .threads
        .map_or_else(Pools::available_threads, usize::from);
    let pools = Pools::new(threads).context("cannot start the thread pool")?;
    let params = args.tree.accel_params();
    let scene = &input.scene;
    eprintln!(
        "building the {} trees of {} ({})...",
        args.tree.structure_name(),
        input.description,
        human::count(args.runs, "build")
    );
    let mut best = f64::INFINITY;
    let mut world = None;
    for _ in 0..args.runs.max(1) {
        let start = Instant::now();
        let w = pools.all.install(|| World::new(scene, &params));
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
        world = Some(w);
    }
    let world = world.expect("at least one build");
    let accel = &world.accel;
    let layout = accel.layout();
    let report = SceneStatsReport {
        scene: args.mesh.display().to_string(),
        builder: args.tree.structure_name(),
        build_ms: best,
        build_runs: args.runs.max(1),
        instances: layout.instances,
        merged_instances: layout.merged,
        two_level_instances: accel.two_level_count(),
        trees: layout.trees,
        world_triangles: accel.world_triangles(),
        instanced_triangles: scene
            .instances
            .iter()
            .map(|i| scene.meshes[i.mesh as usize].mesh.triangle_count() as u64)
            .sum(),
        skipped_triangles: {
            // Counted once per mesh, however many instances show it.
            let skipped: Vec<u64> = scene
                .meshes
                .iter()
                .map(|m| m.mesh.unhittable_count() as u64)
                .collect();
            scene
                .instances
                .iter()
                .map(|i| skipped[i.mesh as usize])
                .sum()
        },
        memory_bytes: accel.tree_bytes(),
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).context("cannot format the report")?
        );
    } else {
        print!("{}", scene_stats_report(&report, threads));
    }
    Ok(())
}

/// `sahara stats` of a scene, as text.
fn scene_stats_report(r: &SceneStatsReport, threads: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "scene      {}", r.scene);
    let _ = writeln!(
        s,
        "instances  {}: {} merged into the world tree, {} two-level",
        human::thousands(r.instances as u64),
        human::thousands(r.merged_instances as u64),
        human::thousands(r.two_level_instances as u64)
    );
    let world = usize::from(r.world_triangles > 0);
    let meshes = format!(
        "{} of two-level meshes",
        human::thousands((r.trees - world) as u64)
    );
    let _ = if world > 0 {
        writeln!(
            s,
            "trees      {}: the world tree ({} triangles) and {meshes}",
            human::thousands(r.trees as u64),
            human::thousands(r.world_triangles as u64),
        )
    } else {
        writeln!(
            s,
            "trees      {}: {meshes}",
            human::thousands(r.trees as u64)
        )
    };
    let _ = writeln!(
        s,
        "triangles  {}",
        human::kept_triangles(r.instanced_triangles, r.skipped_triangles, " instanced")
    );
    let _ = writeln!(s, "builder    {}", r.builder);
    let _ = writeln!(
        s,
        "build      {:.1} ms, trees and lights (best of {} on {})",
        r.build_ms,
        r.build_runs,
        human::count(threads, "thread")
    );
    let _ = writeln!(s, "memory     {}", human::bytes(r.memory_bytes));
    s
}
