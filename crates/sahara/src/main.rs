//! `sahara`: the command line of the Sahara ray tracer.
//!
//! `sahara render` renders a scene file, a mesh or the built-in Cornell box
//! (also what `sahara` alone does); `sahara bench` runs the ray-casting
//! benchmark protocol (`docs/bench-protocol.md`); `sahara stats` prints a
//! tree's statistics; `sahara merge` assembles the parts of a frame
//! rendered in pieces.

mod bench;
mod cli;
mod demo_scene;
mod human;
mod input;
mod memory;
mod merge;
mod part;
mod render;
mod render_options;
mod stats;
mod warnings;

use std::process::ExitCode;

use clap::Parser;

use cli::{Cli, Command, RenderArgs};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Bench(args)) => bench::run_file(args),
        Some(Command::Stats(args)) => stats::run(args),
        Some(Command::Render(args)) => render::run(args),
        Some(Command::Merge(args)) => merge::run(args),
        None => render::run(&RenderArgs::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
