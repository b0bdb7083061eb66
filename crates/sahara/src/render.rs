//! `sahara render`: a scene to a PNG or EXR, with a progress bar, Ctrl-C
//! handling and a summary.
//!
//! [`run`] is a handful of steps, each the request's but the log's: the
//! options are checked before anything is loaded ([`check_args`]); the
//! scene is loaded ([`load_input`]); the request plans the frame and
//! checks everything the render needs before it starts
//! ([`Request::plan`]); the frame is rendered with progress on stderr
//! ([`render_frame`]); the plan denoises it and writes the image or part
//! file, and the log says what was written ([`save`]). An interrupted
//! render comes back as [`Finish::Interrupted`], which `main` turns into
//! exit code 130.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use sahara_formats::{existing_part_differs, Denoised, Note, Plan, Request, RequestError};
use sahara_formats::{Spelling, Written};
use sahara_render::internals::{render_world, World};
use sahara_render::UNLIMITED_SPP;
use sahara_render::{Preview, Progress, RenderResult, RenderSettings};

use crate::cli::RenderArgs;
use crate::scene_input::load_input;

/// How a render ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Finish {
    /// Rendered (or already there, with `--skip-existing`) and written.
    Done,
    /// Stopped by a signal; what was done is written, marked partial.
    Interrupted,
}

/// Seconds between the plain progress lines printed when stderr is not a
/// terminal (a farm's log, `2> log`), where no progress bar is drawn;
/// `SAHARA_PROGRESS_EVERY` (seconds) sets another interval.
const PLAIN_PROGRESS_EVERY: Duration = Duration::from_secs(10);

/// The interval of plain progress lines: `SAHARA_PROGRESS_EVERY` if it is a
/// number of seconds >= 0, else [`PLAIN_PROGRESS_EVERY`].
fn plain_progress_every() -> Duration {
    std::env::var("SAHARA_PROGRESS_EVERY")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| *s >= 0.0 && s.is_finite())
        .map_or(PLAIN_PROGRESS_EVERY, Duration::from_secs_f64)
}

/// A request's refusal as the command line spells it.
fn refused(e: RequestError) -> anyhow::Error {
    anyhow!(e.message(Spelling::CommandLine))
}

/// `sahara render ...` (and `sahara` with no subcommand).
pub fn run(args: &RenderArgs) -> Result<Finish> {
    let request = Request {
        caller: args.settings.0.clone(),
        write_by_default: true,
    };
    check_args(args, &request)?;
    let input = load_input(
        args.scene.as_deref(),
        args.camera.as_deref(),
        args.sky.as_deref(),
        &args.define,
    )?;
    let plan = request.plan(input).map_err(refused)?;
    crate::warnings::print(&plan.warnings);
    for note in &plan.notes {
        match note {
            Note::Said(line) => eprintln!("{line}"),
            Note::Warning(line) => eprintln!("warning: {line}"),
        }
    }
    if args.skip_existing && already_rendered(&plan) {
        return Ok(Finish::Done);
    }
    let mut result = render_frame(args, &plan)?;
    let denoising = plan
        .denoiser
        .is_some()
        .then(|| crate::status::Step::start("denoising"));
    let denoised = plan.denoise(&mut result);
    drop(denoising);
    let denoised = denoised.map_err(refused)?;
    match &denoised {
        Some(Denoised::Skipped) => eprintln!(
            "denoise: skipped, the first pass was stopped before every pixel was finished"
        ),
        Some(Denoised::Done { seconds, .. }) => {
            if let Some(d) = &plan.denoiser {
                eprintln!(
                    "denoised with Open Image Denoise {} in {seconds:.2} s, from {}",
                    d.version(),
                    d.location()
                );
            }
        }
        None => {}
    }
    save(&plan, &result, denoised.as_ref())
}

/// Checks the options before anything is loaded: the request's settings
/// alone, and the command line's own options. A mistake found after a
/// long load (or a render) would cost the user that time.
fn check_args(args: &RenderArgs, request: &Request) -> Result<()> {
    if let Some(t) = args.preview_every {
        if !(t >= 0.0 && t.is_finite()) {
            bail!("--preview-every must be a number of seconds >= 0");
        }
    }
    let piece = request.caller.piece.is_piece();
    if piece && args.preview_every.is_some() {
        bail!("--preview-every does not apply to a part");
    }
    if !piece && args.skip_existing {
        bail!("--skip-existing applies to parts (--part, --crop or --samples)");
    }
    request.check().map_err(refused)
}

/// True if the part's file already holds this part of this frame,
/// complete (`--skip-existing`): said, and not rendered again.
fn already_rendered(plan: &Plan) -> bool {
    let (Some((piece, digest)), Some(path)) = (&plan.piece, &plan.path) else {
        return false;
    };
    match existing_part_differs(path, digest, piece) {
        None => {
            eprintln!(
                "{}: already holds this part, complete: not rendered again",
                path.display()
            );
            true
        }
        Some(why) => {
            eprintln!("{}: rendering the part: {why}", path.display());
            false
        }
    }
}

/// Renders the frame on `--threads` threads with progress on stderr,
/// stopping early on SIGINT, SIGTERM or SIGHUP.
fn render_frame(args: &RenderArgs, plan: &Plan) -> Result<RenderResult> {
    let settings = &plan.settings;
    let cancel = settings
        .cancel
        .clone()
        .expect("the plan sets a cancel flag");
    // SIGINT, SIGTERM and SIGHUP (ctrlc's `termination` feature): a batch
    // system's kill is handled like Ctrl-C.
    ctrlc::set_handler(move || {
        // A second signal leaves at once.
        if cancel.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!(
            "\nstopping: finishing the tiles under way, then writing what is done \
             (a second signal stops at once, writing nothing)"
        );
    })
    .context("cannot install the SIGINT/SIGTERM handler")?;

    let threads = args.threads.map_or(0, usize::from);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the render threads")?;
    say_what_renders(plan, pool.current_num_threads());
    // The trees and light tables, built before the bar is drawn so that a
    // long build is said as such (a scene of millions of triangles takes
    // seconds).
    let start = Instant::now();
    let mut world = pool.install(|| {
        let _building = crate::status::Step::start("building the trees and light tables");
        World::with_light_sampler(&plan.scene, &settings.build, settings.light_sampler)
    });
    let build_time = start.elapsed();
    // Started after the lines above, so that it does not draw over them.
    let bar = progress_bar(settings);
    let said_progress = AtomicBool::new(false);
    let on_progress = progress_reporter(&bar, settings, &said_progress);
    let preview_path = plan.path_for(true);
    let mut show_preview = |r: &RenderResult| {
        // A preview that cannot be written is a warning: the render goes on.
        if let Some(path) = &preview_path {
            if let Err(e) = plan.image(path.clone(), None).write(r, true) {
                bar.suspend(|| eprintln!("warning: preview not written: {e}"));
            }
        }
    };
    let preview = args.preview_every.map(|t| Preview {
        every: Duration::from_secs_f64(t),
        show: &mut show_preview,
    });
    let result = pool.install(|| {
        render_world(
            &mut world,
            settings,
            &on_progress,
            preview,
            start,
            build_time,
        )
    });
    bar.finish_and_clear();
    if let (true, Ok(r)) = (said_progress.load(Ordering::Relaxed), &result) {
        // The lines come every few seconds: the last of them may be short
        // of the end, and a log should not end on `95.8% done`.
        eprintln!(
            "{}",
            plain_closing_line(r.stats.passes, start.elapsed(), interrupted(plan, r))
        );
    }
    // The settings were checked by the plan.
    Ok(result?)
}

/// The log's line of what is rendered, and how: the part, the size, the
/// integrator and sampler, the samples, adaptive sampling, the threads.
fn say_what_renders(plan: &Plan, threads: usize) {
    let settings = &plan.settings;
    if let Some((p, _)) = &plan.piece {
        eprintln!(
            "part{}: pixels {} ({} of them), samples {}..{}",
            if p.label.is_empty() {
                String::new()
            } else {
                format!(" {}", p.label)
            },
            p.window,
            p.window.pixels(),
            p.samples.start,
            p.samples.end
        );
    }
    eprintln!(
        "rendering {} at {}x{}, {} ({}), {} spp in passes of {}{}, {threads} thread{}",
        plan.description,
        settings.width,
        settings.height,
        settings.integrator.name(),
        settings.sampler,
        if settings.spp == UNLIMITED_SPP {
            "unlimited".to_string()
        } else {
            settings.spp.to_string()
        },
        settings.pass_size(),
        settings
            .adaptive
            .map(|a| format!(
                " (adaptive: noise threshold {}, at least {} spp)",
                a.threshold, a.min_spp
            ))
            .unwrap_or_default(),
        plural(threads as u64),
    );
}

/// What the render calls after each tile: the bar moved, and where stderr
/// is not a terminal (no bar is drawn there) a plain line now and then;
/// `said` becomes true once one is printed.
fn progress_reporter<'a>(
    bar: &'a ProgressBar,
    settings: &'a RenderSettings,
    said: &'a AtomicBool,
) -> impl Fn(Progress) + Sync + 'a {
    let unlimited = settings.spp == UNLIMITED_SPP;
    let plain = !std::io::stderr().is_terminal();
    let every = plain_progress_every();
    let last_line = Mutex::new(Instant::now());
    move |p: Progress| {
        if !unlimited {
            bar.set_length(u64::from(p.passes) * u64::from(p.tiles));
        }
        bar.set_position((p.pass as u64) * p.tiles as u64 + p.tiles_done as u64);
        let mrays = p.rays as f64 / p.elapsed.as_secs_f64().max(1e-9) / 1e6;
        let of = if unlimited {
            String::new()
        } else {
            format!("/{}", p.passes)
        };
        let message = format!("pass {}{of} {mrays:.1} Mrays/s", p.pass + 1);
        if plain {
            let mut last = last_line.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() >= every {
                *last = Instant::now();
                said.store(true, Ordering::Relaxed);
                eprintln!(
                    "{}",
                    plain_progress_line(&p, unlimited, settings.time_limit)
                );
            }
        }
        bar.set_message(message);
    }
}

/// True if a signal stopped the render.
fn interrupted(plan: &Plan, result: &RenderResult) -> bool {
    result.stats.stopped_early
        && plan
            .settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::SeqCst))
}

/// Writes the image (or the part file) and says what was written.
fn save(plan: &Plan, result: &RenderResult, denoised: Option<&Denoised>) -> Result<Finish> {
    let s = &result.stats;
    let partial = interrupted(plan, result);
    let finish = if partial {
        Finish::Interrupted
    } else {
        Finish::Done
    };
    let output = plan.path.clone().unwrap_or_default();
    if plan.piece.is_none() && s.passes == 0 && s.first_pass_pixels == 0 {
        if partial {
            // Stopped by a signal: the exit code says interrupted (130), as
            // for any stopped render, not failed.
            eprintln!(
                "interrupted before the first pixel was finished: no image written{}",
                if plan.path_existed {
                    format!(" ({} left as it was)", output.display())
                } else {
                    String::new()
                }
            );
            return Ok(finish);
        }
        bail!("stopped before the first pixel was finished: no image written");
    }
    match plan.write(result, denoised, partial).map_err(refused)? {
        Written::Nothing => {}
        Written::Part(path, done) => {
            let p = &plan.piece.as_ref().expect("a part has a piece").0;
            eprintln!(
                "{} {}: samples {}..{} of {}..{}, {:.2} s render (+{:.0} ms tree builds), {}, {} rays",
                if partial {
                    "wrote PARTIAL part"
                } else {
                    "wrote part"
                },
                where_is(&path).display(),
                done.start,
                done.end,
                p.samples.start,
                p.samples.end,
                s.render_time.as_secs_f64(),
                s.build_time.as_secs_f64() * 1e3,
                s.layout,
                s.rays()
            );
            return Ok(finish);
        }
        Written::Image(path, said) => {
            if let Some(said) = said {
                eprintln!("{said}");
            }
            say_what_was_written(&path, result, partial);
        }
    }
    if partial && plan.path_existed {
        eprintln!(
            "{}: left as it was (the partial image is beside it)",
            output.display()
        );
    }
    Ok(finish)
}

/// The log's lines of an image written: where, its passes, samples,
/// times and rays; what adaptive sampling did.
fn say_what_was_written(path: &std::path::Path, result: &RenderResult, partial: bool) {
    let s = &result.stats;
    let secs = s.render_time.as_secs_f64();
    let pixels = u64::from(result.film.width) * u64::from(result.film.height);
    eprintln!(
        "{} {}: {}, {} spp, {:.2} s render (+{:.0} ms tree builds), {}, {:.3} CPU s, {} rays, {:.2} Mrays/s{}{}",
        if partial {
            "wrote PARTIAL image"
        } else {
            "wrote"
        },
        where_is(path).display(),
        if s.passes == 0 {
            format!(
                "first pass interrupted, {} of {pixels} pixels finished (the rest black)",
                s.first_pass_pixels
            )
        } else {
            format!("{} pass{}", s.passes, plural_es(u64::from(s.passes)))
        },
        s.spp,
        secs,
        s.build_time.as_secs_f64() * 1e3,
        s.layout,
        s.render_cpu_time.as_secs_f64(),
        s.rays(),
        s.rays() as f64 / secs.max(1e-9) / 1e6,
        s.time_split
            .shares()
            .map(|s| format!(
                " (tracing {:.0}%, shading {:.0}%, film {:.0}%, the rest {:.0}%)",
                s.tracing * 100.0,
                s.shading * 100.0,
                s.film * 100.0,
                s.rest * 100.0
            ))
            .unwrap_or_default(),
        if s.nan_samples > 0 {
            format!(", {} NaN samples dropped", s.nan_samples)
        } else {
            String::new()
        }
    );
    let lanes = s.trace.lanes;
    let vertices = lanes.lane_bounces + lanes.misses + lanes.scalar_material + lanes.scalar_other;
    if vertices > 0 {
        let share = |n: u64| 100.0 * n as f64 / vertices as f64;
        eprintln!(
            "path loop lanes: {:.1}% of path vertices shaded in the lanes, {:.1}% misses, {:.1}% \
             by the scalar code under a clear coat, {:.1}% with holes or normal maps; lanes busy \
             {:.1}% of the rounds",
            share(lanes.lane_bounces),
            share(lanes.misses),
            share(lanes.scalar_material),
            share(lanes.scalar_other),
            100.0 * lanes.busy_lanes as f64 / lanes.lane_slots.max(1) as f64
        );
    }
    if let Some(a) = &s.adaptive {
        eprintln!(
            "adaptive: {} samples, {:.1}% of the {} spp budget; {} of {} pixels ({:.1}%) \
             stopped early, below the noise threshold",
            a.samples,
            100.0 * a.samples as f64 / a.budget.max(1) as f64,
            s.spp,
            a.converged,
            a.pixels,
            100.0 * a.converged as f64 / a.pixels.max(1) as f64
        );
    }
}

/// Where `path` is, for the log: a relative path with the working folder
/// in front, so the log says where the file went.
fn where_is(path: &std::path::Path) -> PathBuf {
    match std::env::current_dir() {
        Ok(dir) if path.is_relative() => dir.join(path),
        _ => path.to_path_buf(),
    }
}

/// `"s"` unless `n` is 1.
fn plural(n: u64) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// `"es"` unless `n` is 1.
fn plural_es(n: u64) -> &'static str {
    if n == 1 {
        ""
    } else {
        "es"
    }
}

/// The progress bar: as wide as the terminal, from 0% (a spinner with a
/// time limit, where the total is unknown).
fn progress_bar(settings: &RenderSettings) -> ProgressBar {
    let ts = settings.tile_size.max(1);
    let tiles = u64::from(settings.width.div_ceil(ts)) * u64::from(settings.height.div_ceil(ts));
    let (len, template) = if settings.time_limit.is_some() {
        (None, "{spinner} {elapsed_precise} {msg} tiles {pos}")
    } else {
        (
            Some(u64::from(settings.passes()) * tiles),
            "{wide_bar} {percent:>3}% {msg} {elapsed_precise} eta {eta_precise}",
        )
    };
    let bar = match len {
        Some(n) => ProgressBar::new(n),
        None => ProgressBar::no_length(),
    };
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style.with_key(
            "eta_precise",
            |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&eta_text(s.pos(), s.len(), s.elapsed()));
            },
        ));
    }
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// A progress line for a log that is not a terminal: the whole render's
/// share done, the time elapsed and left, the pass and its tiles, and the
/// rays per second so far, e.g. `progress: 37.5% done, 00:00:12 elapsed,
/// eta 00:00:20, 3.2 Mrays/s (pass 2/4, tile 53/260 of this pass)`. With
/// only a time limit the share and the time left are the limit's.
fn plain_progress_line(p: &Progress, unlimited: bool, time_limit: Option<Duration>) -> String {
    let hms = |d: Duration| {
        let s = d.as_secs_f64().round() as u64;
        format!("{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
    };
    let mrays = p.rays as f64 / p.elapsed.as_secs_f64().max(1e-9) / 1e6;
    let (percent, eta, pass) = match time_limit.filter(|_| unlimited) {
        Some(limit) => (
            100.0 * (p.elapsed.as_secs_f64() / limit.as_secs_f64().max(1e-9)).min(1.0),
            hms(limit.saturating_sub(p.elapsed)),
            format!("pass {}", p.pass + 1),
        ),
        None => {
            let len = u64::from(p.passes) * u64::from(p.tiles);
            let pos = u64::from(p.pass) * u64::from(p.tiles) + u64::from(p.tiles_done);
            (
                100.0 * pos as f64 / len.max(1) as f64,
                eta_text(pos, Some(len), p.elapsed),
                format!("pass {}/{}", p.pass + 1, p.passes),
            )
        }
    };
    format!(
        "progress: {percent:.1}% done, {} elapsed, eta {eta}, {mrays:.1} Mrays/s \
         ({pass}, tile {}/{} of this pass)",
        hms(p.elapsed),
        p.tiles_done,
        p.tiles
    )
}

/// The plain progress line that closes a render's plain lines: `progress:
/// 100.0% done, 00:01:05 elapsed, finished (4 passes)`, or for a render a
/// signal stopped, `progress: stopped, 00:00:40 elapsed, 2 passes complete`.
fn plain_closing_line(passes: u32, elapsed: Duration, interrupted: bool) -> String {
    let s = elapsed.as_secs_f64().round() as u64;
    let hms = format!("{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
    let passes_word = if passes == 1 { "pass" } else { "passes" };
    if interrupted {
        format!("progress: stopped, {hms} elapsed, {passes} {passes_word} complete")
    } else {
        format!("progress: 100.0% done, {hms} elapsed, finished ({passes} {passes_word})")
    }
}

/// The time left, from the average rate since the start (`HH:MM:SS`), or
/// `--:--:--` until 5% of the work or 3 seconds have passed. indicatif's
/// own estimate follows the rate of the last few tiles, and the first
/// tiles (page faults, cold caches, the sky's and the lights' set-up, an
/// empty corner of the image) made it say minutes for a render of seconds.
fn eta_text(pos: u64, len: Option<u64>, elapsed: Duration) -> String {
    let Some(len) = len.filter(|&l| l > 0) else {
        return "--:--:--".to_string();
    };
    if pos == 0 || (pos * 20 < len && elapsed < Duration::from_secs(3)) {
        return "--:--:--".to_string();
    }
    let left = elapsed.as_secs_f64() * (len.saturating_sub(pos)) as f64 / pos as f64;
    let s = left.round() as u64;
    format!("{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

#[cfg(test)]
mod tests {
    use super::{eta_text, plain_closing_line, plain_progress_line};
    use sahara_render::Progress;
    use std::time::Duration;

    #[test]
    fn a_plain_progress_line_gives_the_whole_renders_share_and_time_left() {
        // Pass 2 of 4, 130 of its 260 tiles: 3/8 of the render in 12 s.
        let p = Progress {
            pass: 1,
            passes: 4,
            tiles_done: 130,
            tiles: 260,
            elapsed: Duration::from_secs(12),
            rays: 36_000_000,
        };
        assert_eq!(
            plain_progress_line(&p, false, None),
            "progress: 37.5% done, 00:00:12 elapsed, eta 00:00:20, 3.0 Mrays/s \
             (pass 2/4, tile 130/260 of this pass)"
        );
        // Bounded by a time limit alone: the limit's share and the time left.
        let p = Progress {
            passes: u32::MAX,
            ..p
        };
        assert_eq!(
            plain_progress_line(&p, true, Some(Duration::from_secs(60))),
            "progress: 20.0% done, 00:00:12 elapsed, eta 00:00:48, 3.0 Mrays/s \
             (pass 2, tile 130/260 of this pass)"
        );
    }

    #[test]
    fn the_plain_lines_close_with_the_whole_render_done_or_stopped() {
        assert_eq!(
            plain_closing_line(4, Duration::from_secs(65), false),
            "progress: 100.0% done, 00:01:05 elapsed, finished (4 passes)"
        );
        assert_eq!(
            plain_closing_line(1, Duration::from_secs(40), true),
            "progress: stopped, 00:00:40 elapsed, 1 pass complete"
        );
    }

    #[test]
    fn the_eta_waits_for_enough_work_then_follows_the_average_rate() {
        let secs = Duration::from_secs_f64;
        // One tile of 400 done in a fraction of a second: no guess yet.
        assert_eq!(eta_text(1, Some(400), secs(0.2)), "--:--:--");
        assert_eq!(eta_text(0, Some(400), secs(10.0)), "--:--:--");
        assert_eq!(eta_text(5, None, secs(10.0)), "--:--:--");
        // A tenth done in 9 s: 81 s left.
        assert_eq!(eta_text(40, Some(400), secs(9.0)), "00:01:21");
        // Few tiles, but time enough to judge.
        assert_eq!(eta_text(1, Some(400), secs(4.0)), "00:26:36");
        assert_eq!(eta_text(400, Some(400), secs(9.0)), "00:00:00");
    }
}
