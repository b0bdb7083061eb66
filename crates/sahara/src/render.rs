//! `sahara render`: a scene to a PNG or EXR, with a progress bar, Ctrl-C
//! handling and a summary.
//!
//! [`run`] is a handful of steps: every option that can be checked alone is
//! checked before anything is loaded ([`check_args`]); the scene is loaded
//! ([`load_input`]); the frame is planned and everything the render needs
//! is checked before it starts ([`plan`]); the frame is rendered
//! ([`render_frame`]); the image or part file is written ([`save`]). An
//! interrupted render comes back as [`Finish::Interrupted`], which `main`
//! turns into exit code 130.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use sahara_render::internals::{render_world, World};
use sahara_render::UNLIMITED_SPP;
use sahara_render::{
    Aov, Feature, Filter, FilterKind, Preview, Progress, RenderResult, RenderSettings,
    SettingsError, ToneMap,
};

use crate::cli::RenderArgs;
use crate::memory;
use crate::output::{check_output, partial_path, Output};
use crate::part::{self, Piece};
use crate::render_options::{resolve, RenderOptions};
use crate::scene_input::{load_input, Input};

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

/// `sahara render ...` (and `sahara` with no subcommand).
pub fn run(args: &RenderArgs) -> Result<Finish> {
    check_args(args)?;
    let input = load_input(
        args.scene.as_deref(),
        args.camera.as_deref(),
        args.sky.as_deref(),
        &args.define,
    )?;
    let Some(job) = plan(args, input)? else {
        return Ok(Finish::Done);
    };
    let mut result = render_frame(args, &job)?;
    let noisy = match &job.denoiser {
        Some(d) => {
            let noisy_guides = crate::denoise::guides_are_noisy(&job.scene);
            crate::denoise::apply(d, &mut result, noisy_guides)?
        }
        None => None,
    };
    save(&job, &result, noisy.as_deref())
}

/// Checks the options that need no scene, before anything is loaded: a
/// mistake found after a long load (or a render) would cost the user that
/// time.
fn check_args(args: &RenderArgs) -> Result<()> {
    if let Some(t) = args.time_limit {
        if !(t > 0.0 && t.is_finite()) {
            bail!("--time-limit must be a positive number of seconds");
        }
    }
    if let Some(t) = args.preview_every {
        if !(t >= 0.0 && t.is_finite()) {
            bail!("--preview-every must be a number of seconds >= 0");
        }
    }
    if args.exposure.is_some_and(|e| !e.is_finite()) {
        bail!("--exposure must be a finite number of stops");
    }
    if let Some(t) = args.noise_threshold {
        if !(t > 0.0 && t.is_finite()) {
            bail!("--noise-threshold must be a positive number (0.01 is a good start)");
        }
    }
    part::check_args(args)?;
    if let Some(output) = &args.output {
        check_output(output, part::is_part(args))?;
        check_aov_output(args, output)?;
    }
    Ok(())
}

/// The renderer's refusal of settings the integrator cannot honour in
/// `scene` ([`RenderSettings::check_for`]; `sahara_render::IntegratorKind::supports`
/// declares what each integrator supports), as one line naming the option
/// or scene-file key that asked for it. `denoise`: the render is to be
/// denoised.
fn check_settings(
    args: &RenderArgs,
    scene: &sahara_render::Scene,
    settings: &RenderSettings,
    denoise: bool,
) -> Result<()> {
    let asked_by = |e: &SettingsError| -> &'static str {
        match e {
            SettingsError::Unsupported {
                feature: Feature::Denoise,
                ..
            } if args.denoise => "--denoise",
            SettingsError::Unsupported {
                feature: Feature::Denoise,
                ..
            } => "the scene file's `denoise`",
            SettingsError::Unsupported {
                feature: Feature::Aovs,
                ..
            } => "--aov",
            SettingsError::Unsupported {
                feature: Feature::Adaptive,
                ..
            }
            | SettingsError::AdaptiveSampleRange { .. }
                if args.noise_threshold.is_some() =>
            {
                "--noise-threshold"
            }
            SettingsError::Unsupported {
                feature: Feature::Adaptive,
                ..
            }
            | SettingsError::AdaptiveSampleRange { .. } => "the scene file's noise_threshold",
            SettingsError::Unsupported {
                feature: Feature::PixelParts,
                ..
            } if args.crop.is_some() => "--crop",
            SettingsError::Unsupported {
                feature: Feature::PixelParts,
                ..
            } if args.part.is_some() && args.split != Some(crate::cli::Split::Samples) => {
                "--split tiles"
            }
            SettingsError::Unsupported {
                feature: Feature::PixelParts,
                ..
            } => "the scene file's crop window",
            SettingsError::Unsupported {
                feature: Feature::SampleRanges,
                ..
            } if args.samples.is_some() => "--samples",
            SettingsError::Unsupported {
                feature: Feature::SampleRanges,
                ..
            } => "--split samples",
            SettingsError::Unsupported {
                feature: Feature::Media,
                ..
            } if args.integrator.is_some() => "--integrator (the scene has participating media)",
            SettingsError::Unsupported {
                feature: Feature::Media,
                ..
            } => "the scene's integrator (the scene has participating media)",
        }
    };
    let named = |e: SettingsError| anyhow!("{}: {e}", asked_by(&e));
    if denoise {
        settings
            .integrator
            .kind()
            .require(Feature::Denoise)
            .map_err(named)?;
    }
    settings.check_for(scene).map_err(named)
}

/// Render passes are layers of an EXR: refused for any other output.
fn check_aov_output(args: &RenderArgs, output: &std::path::Path) -> Result<()> {
    if !args.aov.is_empty()
        && !output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        bail!(
            "--aov writes render passes as layers of an EXR file: the output {} is not one \
             (use -o NAME.exr)",
            output.display()
        );
    }
    Ok(())
}

/// A frame ready to render: the scene, its settings and where it goes.
struct Job {
    scene: sahara_render::Scene,
    description: String,
    settings: RenderSettings,
    exposure: f32,
    tonemap: ToneMap,
    output: PathBuf,
    /// Whether a file was at `output` before the render: a partial image
    /// then goes beside it.
    output_existed: bool,
    /// The piece of the frame a part renders, with the frame's digest.
    piece: Option<(Piece, String)>,
    /// Render passes written beside the beauty.
    aovs: Vec<sahara_render::Aov>,
    /// True with `--denoise` (or the scene file's `denoise`).
    denoise: bool,
    /// The list of names of the object and material passes (JSON), if
    /// asked for.
    names: Option<String>,
    /// The denoiser, with `--denoise` (None for a part: `merge` denoises).
    denoiser: Option<sahara_denoise::Denoiser>,
}

/// Settles the settings (command line over scene file over defaults) and
/// checks everything the render needs: the output, the crop, the part, the
/// memory, the scene. `None`: nothing to render (`--skip-existing` found
/// the part done).
fn plan(args: &RenderArgs, input: Input) -> Result<Option<Job>> {
    let Input {
        mut scene,
        settings: file,
        name,
        description,
        warnings,
        names,
        ..
    } = input;
    crate::warnings::print(&warnings);
    let RenderOptions {
        mut settings,
        exposure,
        tonemap,
        output,
    } = resolve(args, file.as_ref(), &name)?;
    // The scene file's crop (pbrt's film `cropwindow` / `pixelbounds`):
    // a plain render is an image of those pixels, as pbrt writes it.
    let file_window = file
        .as_ref()
        .and_then(|f| f.crop)
        .map(|c| c.window(settings.width, settings.height));
    if file_window.is_some_and(|w| w.is_empty()) {
        bail!(
            "the scene file's crop window holds no pixel of the {}x{} image",
            settings.width,
            settings.height
        );
    }
    let piece = part::plan(args, &settings, file_window)?;
    if piece.is_none() {
        settings.window = file_window;
    }
    // The output named by the scene file (the command line's was checked
    // by `check_args`).
    if args.output.is_none() {
        check_output(&output, piece.is_some())?;
        check_aov_output(args, &output)?;
    }
    // The scene file may ask for adaptive sampling and denoising too.
    let file_denoise = !args.denoise && file.as_ref().is_some_and(|f| f.denoise);
    let denoise = args.denoise || file_denoise;
    settings.aovs = args.aov.clone();
    if denoise {
        settings.aovs.extend([Aov::Albedo, Aov::Normal]);
    }
    settings.aovs.sort();
    settings.aovs.dedup();
    if let Some(p) = &piece {
        settings.part = true;
        settings.window = Some(p.window);
        settings.samples = Some(p.samples.clone());
    }
    check_settings(args, &scene, &settings, denoise)?;
    // A filter wider than a pixel shares each sample between neighbours:
    // their noise is then correlated, which the denoiser (trained on
    // independent pixels) takes for detail and keeps. Figures in
    // docs/clean-image.md.
    if denoise {
        match args.filter {
            None => {
                settings.filter = Filter::from(FilterKind::Box);
                eprintln!(
                    "denoise: box filter (a wider one correlates the noise of neighbouring \
                     pixels, which the denoiser then keeps; --filter chooses another)"
                );
            }
            Some(kind) if kind != FilterKind::Box => eprintln!(
                "warning: --denoise with the {kind} filter: its noise is correlated between \
                 pixels, which the denoiser keeps (the box filter denoises best)"
            ),
            Some(_) => {}
        }
    }
    // The library is found before the render, not after it. A part is
    // never denoised alone: it carries the albedo and normal, and `merge`
    // denoises the whole frame (so a farm's nodes need no denoiser).
    let denoiser = if denoise && piece.is_none() {
        Some(crate::denoise::load()?)
    } else {
        None
    };
    // Refuse a render that would not fit, with what it would need.
    let triangles: u64 = scene
        .meshes
        .iter()
        .map(|m| m.mesh.indices.len() as u64)
        .sum();
    let (film_w, film_h) = match (&piece, settings.window) {
        (Some(p), _) => (p.window.width().max(1), p.window.height().max(1)),
        (None, Some(w)) => (w.width(), w.height()),
        (None, None) => (settings.width, settings.height),
    };
    memory::check_fits(triangles, film_w, film_h, memory::available_bytes())?;
    // Any aspect ratio: the vertical field of view is kept.
    scene.camera.aspect = settings.width as f32 / settings.height as f32;
    scene.validate().map_err(|e| match &args.scene {
        Some(p) => anyhow!("{}: invalid scene: {e}", p.display()),
        None => anyhow!("invalid scene: {e}"),
    })?;
    let piece = match piece {
        None => None,
        Some(p) => {
            let digest = sahara_render::frame_digest(&scene, &settings);
            if args.skip_existing {
                match part::existing_differs(&output, &digest, &p) {
                    None => {
                        eprintln!(
                            "{}: already holds this part, complete: not rendered again",
                            output.display()
                        );
                        return Ok(None);
                    }
                    Some(why) => eprintln!("{}: rendering the part: {why}", output.display()),
                }
            }
            Some((p, digest))
        }
    };
    Ok(Some(Job {
        scene,
        description,
        settings,
        exposure,
        tonemap,
        output_existed: output.exists(),
        output,
        piece,
        names: crate::id_names::json(&names, &args.aov),
        aovs: args.aov.clone(),
        denoise,
        denoiser,
    }))
}

/// Renders the frame on `--threads` threads with progress on stderr,
/// stopping early on SIGINT, SIGTERM or SIGHUP.
fn render_frame(args: &RenderArgs, job: &Job) -> Result<RenderResult> {
    let settings = &job.settings;
    let cancel = settings.cancel.clone().expect("settings set a cancel flag");
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
    if let Some((p, _)) = &job.piece {
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
    if let (None, Some(w)) = (&job.piece, settings.window) {
        eprintln!(
            "crop window of the scene file: pixels {w}, written as a {}x{} image",
            w.width(),
            w.height()
        );
    }
    let threads = pool.current_num_threads();
    eprintln!(
        "rendering {} at {}x{}, {} ({}), {} spp in passes of {}{}, {threads} thread{}",
        job.description,
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
    if let Some(a) = settings.adaptive {
        if settings.spp != UNLIMITED_SPP && a.min_spp >= settings.spp {
            eprintln!(
                "warning: adaptive: every pixel takes all {spp} samples, as at least {min} are \
                 taken before the noise is tested; raise --spp (the cap) above {min}, or lower \
                 --min-spp, for pixels to stop early",
                spp = settings.spp,
                min = a.min_spp
            );
        }
    }
    // The trees and light tables, built before the bar is drawn so that a
    // long build is said as such (a scene of millions of triangles takes
    // seconds).
    let start = Instant::now();
    let mut world = pool.install(|| {
        let _building = crate::status::Step::start("building the trees and light tables");
        World::new(&job.scene, &settings.build)
    });
    let build_time = start.elapsed();
    // Started after the line above, so that it does not draw over it.
    let bar = progress_bar(settings);
    let unlimited = settings.spp == UNLIMITED_SPP;
    let plain = !std::io::stderr().is_terminal();
    let every = plain_progress_every();
    // When the last plain line was printed, and whether one was.
    let last_line = Mutex::new((Instant::now(), false));
    let on_progress = |p: Progress| {
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
            // No bar is drawn where stderr is not a terminal: a line now and then.
            let mut last = last_line.lock().unwrap_or_else(|e| e.into_inner());
            if last.0.elapsed() >= every {
                *last = (Instant::now(), true);
                eprintln!(
                    "{}",
                    plain_progress_line(&p, unlimited, settings.time_limit)
                );
            }
        }
        bar.set_message(message);
    };
    let preview_output = job.output_at(true);
    let mut show_preview = |r: &RenderResult| {
        // A preview that cannot be written is a warning: the render goes on.
        if let Err(e) = preview_output.write(r, true, false) {
            bar.suspend(|| eprintln!("warning: preview not written: {e:#}"));
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
    let said_progress = last_line.lock().unwrap_or_else(|e| e.into_inner()).1;
    if let (true, Ok(r)) = (said_progress, &result) {
        // The lines come every few seconds: the last of them may be short
        // of the end, and a log should not end on `95.8% done`.
        eprintln!(
            "{}",
            plain_closing_line(r.stats.passes, start.elapsed(), job.interrupted(r))
        );
    }
    // The settings were checked before the render (`check_settings`).
    Ok(result?)
}

impl Job {
    /// Where the image goes: the output, or beside it for a partial image
    /// when a file was there before the render.
    fn output_at(&self, partial: bool) -> Output<'_> {
        let path = if partial {
            partial_path(&self.output, self.output_existed)
        } else {
            self.output.clone()
        };
        Output {
            path,
            settings: &self.settings,
            exposure: self.exposure,
            tonemap: self.tonemap,
            aovs: &self.aovs,
            noisy: None,
        }
    }

    /// True if a signal stopped the render.
    fn interrupted(&self, result: &RenderResult) -> bool {
        result.stats.stopped_early
            && self
                .settings
                .cancel
                .as_ref()
                .is_some_and(|c| c.load(Ordering::SeqCst))
    }
}

/// Writes the image (or the part file) and says what was written.
fn save(job: &Job, result: &RenderResult, noisy: Option<&[f32]>) -> Result<Finish> {
    let s = &result.stats;
    let partial = job.interrupted(result);
    let finish = if partial {
        Finish::Interrupted
    } else {
        Finish::Done
    };
    if let Some((p, digest)) = &job.piece {
        let record = part::PartRecord {
            piece: p,
            digest,
            exposure: job.exposure,
            tonemap: job.tonemap,
            aovs: &job.aovs,
            denoise: job.denoise,
            noisy_guides: crate::denoise::guides_are_noisy(&job.scene),
            names: job.names.as_deref(),
            interrupted: partial,
        };
        let path = if partial {
            partial_path(&job.output, job.output_existed)
        } else {
            job.output.clone()
        };
        let done = part::write(&path, &record, &job.settings, result)?;
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
    if s.passes == 0 && s.first_pass_pixels == 0 {
        if partial {
            // Stopped by a signal: the exit code says interrupted (130), as
            // for any stopped render, not failed.
            eprintln!(
                "interrupted before the first pixel was finished: no image written{}",
                if job.output_existed {
                    format!(" ({} left as it was)", job.output.display())
                } else {
                    String::new()
                }
            );
            return Ok(finish);
        }
        bail!("stopped before the first pixel was finished: no image written");
    }
    let mut output = job.output_at(partial);
    output.noisy = noisy;
    output.write(result, partial, true)?;
    if let Some(names) = &job.names {
        crate::id_names::write_beside(&output.path, names)?;
    }
    if !partial {
        // A preview written beside the earlier image is stale now.
        let beside = partial_path(&job.output, job.output_existed);
        if beside != job.output && beside.exists() {
            let _ = std::fs::remove_file(&beside);
        }
    }
    let secs = s.render_time.as_secs_f64();
    let pixels = u64::from(result.film.width) * u64::from(result.film.height);
    eprintln!(
        "{} {}: {}, {} spp, {:.2} s render (+{:.0} ms tree builds), {}, {:.3} CPU s, {} rays, {:.2} Mrays/s{}{}",
        if partial {
            "wrote PARTIAL image"
        } else {
            "wrote"
        },
        where_is(&output.path).display(),
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
    let vertices = lanes.lane_bounces + lanes.scalar_material + lanes.scalar_other;
    if vertices > 0 {
        let share = |n: u64| 100.0 * n as f64 / vertices as f64;
        eprintln!(
            "path loop lanes: {:.1}% of path vertices shaded in the lanes, {:.1}% by the scalar \
             code for want of a lane BSDF, {:.1}% for other reasons (misses, holes, normal \
             maps); lanes busy {:.1}% of the rounds",
            share(lanes.lane_bounces),
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
    if partial && job.output_existed {
        eprintln!(
            "{}: left as it was (the partial image is beside it)",
            job.output.display()
        );
    }
    Ok(finish)
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
