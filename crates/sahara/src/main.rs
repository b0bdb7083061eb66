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
mod merge;
mod render;
mod scene_input;
mod setting_args;
mod stats;
mod status;
mod warnings;

use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::Parser;

use cli::{Cli, Command, RenderArgs};
use render::Finish;

/// The exit code of a render stopped by a signal (128 + SIGINT, as shells
/// report an interrupted command).
const INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    let cli = match Cli::try_parse_from(with_render_implied(std::env::args_os())) {
        Ok(cli) => cli,
        Err(e) => return argument_error(e),
    };
    let result = match &cli.command {
        Some(Command::Bench(args)) => bench::run_file(args).map(|()| Finish::Done),
        Some(Command::Stats(args)) => stats::run(args).map(|()| Finish::Done),
        Some(Command::Render(args)) => render::run(args),
        Some(Command::Merge(args)) => merge::run(args).map(|()| Finish::Done),
        None => render::run(&RenderArgs::default()),
    };
    match result {
        Ok(Finish::Done) => ExitCode::SUCCESS,
        Ok(Finish::Interrupted) => ExitCode::from(INTERRUPTED),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// The arguments, with `render` put before them when they start with an
/// option other than help and version: the bare command takes `render`'s
/// options (`sahara -o out.png`, `sahara --spp 4`) as it renders what
/// `sahara render` renders.
fn with_render_implied(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut args: Vec<_> = args.into_iter().collect();
    let renders = args
        .get(1)
        .and_then(|a| a.to_str())
        .is_some_and(|a| a.starts_with('-') && !["-h", "--help", "-V", "--version"].contains(&a));
    if renders {
        args.insert(1, "render".into());
    }
    args
}

/// Help and version as clap prints them; any other command-line error as
/// one line (`docs/cli.md`), with exit code 1 like every other error.
fn argument_error(e: clap::Error) -> ExitCode {
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        e.exit();
    }
    let text = e.render().to_string();
    let mut lines = text.lines();
    let mut first = lines
        .next()
        .unwrap_or("error: invalid arguments")
        .to_string();
    // A first line that ends in a colon ("the following required arguments
    // were not provided:") is followed by what it names, one per line.
    if first.ends_with(':') {
        let named: Vec<&str> = lines.map(str::trim).take_while(|l| !l.is_empty()).collect();
        first = format!("{first} {}", named.join(", "));
    }
    // `sahara scene.toml`, as pbrt and Mitsuba take a scene: say how.
    // Else clap's nearest subcommand, option or value for a misspelt one
    // (`sahara rendr`, `--sp 16`), which its own tip lines would give.
    let hint = match (e.kind(), std::env::args().nth(1)) {
        (ErrorKind::InvalidSubcommand, Some(arg)) if std::path::Path::new(&arg).exists() => {
            format!(" (did you mean: sahara render {arg})")
        }
        _ => suggestion(&e)
            .map(|s| format!(" (did you mean: {s})"))
            .unwrap_or_default(),
    };
    eprintln!("{first}{hint}");
    ExitCode::FAILURE
}

/// The subcommand, option or value clap found nearest to a misspelt one:
/// `sahara render` for `rendr`, `--spp` for `--sp`.
fn suggestion(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    let first = |kind| match e.get(kind)? {
        ContextValue::String(s) => Some(s.clone()),
        ContextValue::Strings(v) => v.first().cloned(),
        _ => None,
    };
    if let Some(sub) = first(ContextKind::SuggestedSubcommand) {
        return Some(format!("sahara {sub}"));
    }
    first(ContextKind::SuggestedArg).or_else(|| first(ContextKind::SuggestedValue))
}
