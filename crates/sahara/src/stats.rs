//! `sahara stats`: a tree's statistics and build time.

use anyhow::{Context, Result};
use sahara_bench::report::StatsReport;
use sahara_bench::runner::{build_timed, Pools};

use crate::cli::StatsArgs;
use crate::human;
use crate::input::load_mesh;

/// `sahara stats MESH ...`.
pub fn run(args: &StatsArgs) -> Result<()> {
    let mesh = args.tree.select(load_mesh(&args.mesh)?);
    let threads = args
        .threads
        .map_or_else(Pools::available_threads, usize::from);
    let pools = Pools::new(threads).context("cannot start the thread pool")?;
    eprintln!(
        "building the {} tree over {} triangles ({})...",
        args.tree.builder.name(),
        mesh.triangle_count(),
        human::count(args.runs, "build")
    );
    let (tree, build_ms) = build_timed(
        &mesh.triangles(),
        &args.tree.params(),
        args.runs,
        &pools.all,
    );
    let report = StatsReport {
        mesh: args.mesh.display().to_string(),
        builder: args.tree.builder.name(),
        build_ms,
        build_runs: args.runs,
        tree: tree.stats(),
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
