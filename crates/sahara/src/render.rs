//! `sahara render`: a scene to a PNG or EXR, with a progress bar, Ctrl-C
//! handling and a summary.

use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::Duration;

use anyhow::{anyhow, bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use sahara_formats::image_out::{write_image, Pixels};
use sahara_formats::mesh_scene::{load_mesh_scene_with, CameraChoice};
use sahara_formats::scene_load::{load_scene_with_sky, FileSettings};
use sahara_formats::sky::Sky;
use sahara_readers::camera::read_sidecar;
use sahara_render::render::UNLIMITED_SPP;
use sahara_render::{
    builtin, render_watched, Camera, Integrator, Preview, Progress, RenderResult, RenderSettings,
    Scene, ToneMap,
};

use crate::cli::RenderArgs;
use crate::memory;
use crate::part;
use crate::render_options::{resolve, RenderOptions};

/// A scene to render, with what its file says about rendering it.
struct Input {
    scene: Scene,
    file: Option<FileSettings>,
    name: String,
    description: String,
    warnings: Vec<String>,
}

/// `sahara render ...` (and `sahara` with no subcommand).
pub fn run(args: &RenderArgs) -> Result<()> {
    let Input {
        mut scene,
        file,
        name,
        description,
        warnings,
    } = load_input(
        args.scene.as_deref(),
        args.camera.as_deref(),
        args.sky.as_deref(),
    )?;
    let mut warnings = warnings;
    // The finished scene's problems, named after the file they come from.
    let from_file = args.scene.as_ref().map(|p| p.display().to_string());
    warnings.extend(scene.diagnostics().into_iter().map(|d| match &from_file {
        Some(f) => format!("{f}: {d}"),
        None => d,
    }));
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
    if piece.is_some() && !is_exr(&output) {
        bail!(
            "{}: a part (--part, --crop, --samples) is written as OpenEXR: name a .exr file",
            output.display()
        );
    }
    // Refuse an unwritable output now, not after the render.
    sahara_formats::atomic::check_writable(&output)
        .map_err(|e| anyhow!("{e}"))
        .context("cannot write the output image")?;
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
    let digest = piece
        .as_ref()
        .map(|_| sahara_render::digest::frame_digest(&scene, &settings));
    if let (Some(p), Some(d)) = (&piece, &digest) {
        settings.window = Some(p.window);
        settings.samples = Some(p.samples.clone());
        if args.skip_existing {
            match part::existing_differs(&output, d, p) {
                None => {
                    eprintln!(
                        "{}: already holds this part, complete: not rendered again",
                        output.display()
                    );
                    return Ok(());
                }
                Some(why) => eprintln!("{}: rendering the part: {why}", output.display()),
            }
        }
    }

    let cancel = settings.cancel.clone().expect("settings set a cancel flag");
    // SIGINT, SIGTERM and SIGHUP (ctrlc's `termination` feature): a batch
    // system's kill is handled like Ctrl-C.
    ctrlc::set_handler(move || {
        // A second signal leaves at once.
        if cancel.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    })
    .context("cannot install the SIGINT/SIGTERM handler")?;

    let threads = args.threads.map_or(0, usize::from);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the render threads")?;
    if let Some(p) = &piece {
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
    if let (None, Some(w)) = (&piece, settings.window) {
        eprintln!(
            "crop window of the scene file: pixels {w}, written as a {}x{} image",
            w.width(),
            w.height()
        );
    }
    eprintln!(
        "rendering {description} at {}x{}, {} ({}), {} spp in passes of {}, {} threads",
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
        pool.current_num_threads()
    );
    // Started after the line above, so that it does not draw over it.
    let bar = progress_bar(&settings);
    let unlimited = settings.spp == UNLIMITED_SPP;
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
        bar.set_message(format!("pass {}{of} {mrays:.1} Mrays/s", p.pass + 1));
    };
    let output_settings = Output {
        path: &output,
        settings: &settings,
        exposure,
        tonemap,
    };
    let mut show_preview = |r: &RenderResult| {
        // A preview that cannot be written is a warning: the render goes on.
        if let Err(e) = output_settings.write(r, true, false) {
            bar.suspend(|| eprintln!("warning: preview not written: {e:#}"));
        }
    };
    let preview = match args.preview_every {
        None => None,
        Some(t) if !(t >= 0.0 && t.is_finite()) => {
            bail!("--preview-every must be a number of seconds >= 0")
        }
        Some(t) => Some(Preview {
            every: Duration::from_secs_f64(t),
            show: &mut show_preview,
        }),
    };
    let result = pool.install(|| render_watched(&scene, &settings, &on_progress, preview));
    bar.finish_and_clear();

    let s = &result.stats;
    let partial = s.stopped_early
        && settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::SeqCst));
    if let (Some(p), Some(d)) = (&piece, &digest) {
        let record = part::PartRecord {
            piece: p,
            digest: d,
            exposure,
            tonemap,
            interrupted: partial,
        };
        let done = part::write(&output, &record, &settings, &result)?;
        eprintln!(
            "{} {}: samples {}..{} of {}..{}, {:.2} s render (+{:.0} ms tree builds), {} rays",
            if partial {
                "wrote PARTIAL part"
            } else {
                "wrote part"
            },
            output.display(),
            done.start,
            done.end,
            p.samples.start,
            p.samples.end,
            s.render_time.as_secs_f64(),
            s.build_time.as_secs_f64() * 1e3,
            s.rays()
        );
        if partial {
            std::process::exit(130);
        }
        return Ok(());
    }
    if s.passes == 0 && s.first_pass_pixels == 0 {
        bail!("stopped before the first pixel was finished: no image written");
    }
    output_settings.write(&result, partial, true)?;
    let secs = s.render_time.as_secs_f64();
    let pixels = u64::from(result.film.width) * u64::from(result.film.height);
    eprintln!(
        "{} {}: {}, {} spp, {:.2} s render (+{:.0} ms tree builds), {:.3} CPU s, {} rays, {:.2} Mrays/s{}",
        if partial {
            "wrote PARTIAL image"
        } else {
            "wrote"
        },
        output.display(),
        if s.passes == 0 {
            format!(
                "first pass interrupted, {} of {pixels} pixels finished (the rest black)",
                s.first_pass_pixels
            )
        } else {
            format!("{} passes", s.passes)
        },
        s.spp,
        secs,
        s.build_time.as_secs_f64() * 1e3,
        s.render_cpu_time.as_secs_f64(),
        s.rays(),
        s.rays() as f64 / secs.max(1e-9) / 1e6,
        if s.nan_samples > 0 {
            format!(", {} NaN samples dropped", s.nan_samples)
        } else {
            String::new()
        }
    );
    if partial {
        // Interrupted: the image of the completed passes is on disk.
        std::process::exit(130);
    }
    Ok(())
}

/// Where and how the image is written.
pub(crate) struct Output<'a> {
    pub(crate) path: &'a Path,
    pub(crate) settings: &'a RenderSettings,
    pub(crate) exposure: f32,
    pub(crate) tonemap: ToneMap,
}

impl Output<'_> {
    /// Writes `result` (atomically), marked `partial` or not; `log` prints
    /// what a debug view's colours mean.
    pub(crate) fn write(&self, result: &RenderResult, partial: bool, log: bool) -> Result<()> {
        let settings = self.settings;
        let s = &result.stats;
        let exr = is_exr(self.path);
        let rgb = result.film.to_rgb_f32();
        let rgb8 = if exr {
            Vec::new()
        } else if matches!(settings.integrator, Integrator::Depth) {
            // Raw distances would be a flat white or grey: map the nearest
            // to the farthest hit onto white to dark grey (EXR keeps them raw).
            let range = depth_range(&rgb, result.film.width, result.film.height);
            if log {
                match range {
                    Some((near, far)) => eprintln!(
                        "depth: nearest hit {near:.4} (white) to farthest {far:.4} (dark grey), \
                         no hit black; EXR output keeps the raw distances"
                    ),
                    None => eprintln!("depth: no ray hit anything"),
                }
            }
            depth_to_gray8(&rgb, range)
        } else {
            result.film.to_srgb8(self.exposure, self.tonemap)
        };
        let pixels = if exr {
            Pixels::LinearRgbF32(&rgb)
        } else {
            Pixels::Rgb8(&rgb8)
        };
        // The film is the window's when the scene file crops the image.
        let (width, height) = (result.film.width, result.film.height);
        let finished = if s.passes == 0 {
            s.first_pass_pixels
        } else {
            u64::from(width) * u64::from(height)
        };
        let metadata = vec![
            (
                "sahara:integrator".to_string(),
                settings.integrator.name().to_string(),
            ),
            ("sahara:spp".to_string(), s.spp.to_string()),
            ("sahara:seed".to_string(), settings.seed.to_string()),
            ("sahara:partial".to_string(), partial.to_string()),
            ("sahara:finished_pixels".to_string(), finished.to_string()),
        ];
        write_image(self.path, width, height, pixels, &metadata)
            .map_err(|e| anyhow!("{e}"))
            .context("cannot write the output image")
    }
}

/// The nearest and farthest distance in a depth image (0 is no hit).
///
/// The filter blends hit distances with the zeros of missed samples near
/// silhouettes, which would make them look nearest: the nearest distance
/// is taken from pixels at least [`SILHOUETTE_MARGIN`] pixels from any
/// pixel without a hit (all pixels if none is that far).
fn depth_range(rgb: &[f32], width: u32, height: u32) -> Option<(f32, f32)> {
    let (w, h) = (width as usize, height as usize);
    let d = |x: usize, y: usize| rgb[3 * (y * w + x)];
    let hit = |v: f32| v > 0.0 && v.is_finite();
    let far = (0..w * h)
        .map(|k| rgb[3 * k])
        .filter(|&v| hit(v))
        .fold(0.0f32, f32::max);
    if far <= 0.0 {
        return None;
    }
    let m = SILHOUETTE_MARGIN;
    let interior = |x: usize, y: usize| {
        (y.saturating_sub(m)..(y + m + 1).min(h))
            .all(|j| (x.saturating_sub(m)..(x + m + 1).min(w)).all(|i| hit(d(i, j))))
    };
    let nearest = |only_interior: bool| {
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| hit(d(x, y)) && (!only_interior || interior(x, y)))
            .map(|(x, y)| d(x, y))
            .fold(f32::INFINITY, f32::min)
    };
    let near = match nearest(true) {
        n if n.is_finite() => n,
        _ => nearest(false),
    };
    Some((near.min(far), far))
}

/// Pixels around a silhouette that [`depth_range`] leaves out of the nearest distance.
const SILHOUETTE_MARGIN: usize = 3;

/// A depth image as 8-bit grey: `near` white, `far` dark grey (26), no hit black.
fn depth_to_gray8(rgb: &[f32], range: Option<(f32, f32)>) -> Vec<u8> {
    let Some((near, far)) = range else {
        return vec![0; rgb.len()];
    };
    let span = (far - near).max(f32::MIN_POSITIVE);
    rgb.iter()
        .step_by(3)
        .flat_map(|&d| {
            let v = if d > 0.0 && d.is_finite() {
                let t = ((d - near) / span).clamp(0.0, 1.0);
                (255.0 * (1.0 - 0.9 * t)).round() as u8
            } else {
                0
            };
            [v; 3]
        })
        .collect()
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
        bar.set_style(style);
    }
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// The scene to render: the built-in Cornell box, a scene file or a mesh
/// file, seen by `camera` (`--camera`) and lit as `sky` (`--sky`) says.
fn load_input(path: Option<&Path>, camera: Option<&str>, sky: Option<&str>) -> Result<Input> {
    let flat = |e: sahara_formats::FormatError| anyhow!("{e}");
    let sky = sky.map(|s| Sky::parse(s, Path::new("")));
    let Some(path) = path else {
        let mut scene = builtin::cornell_box();
        if let Some(file) = camera {
            let c = read_sidecar(Path::new(file)).map_err(flat)?;
            scene.camera = Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, 1.0);
            eprintln!("camera: {file}");
        }
        if let Some(sky) = &sky {
            sahara_formats::sky::apply(&mut scene, sky).map_err(flat)?;
        }
        return Ok(Input {
            scene,
            file: None,
            name: "cornell_box".into(),
            description: "the built-in Cornell box".into(),
            warnings: Vec::new(),
        });
    };
    const EXPECTED: &str =
        "expected a scene file (.toml, .pbrt, .pbrt.gz) or a mesh (.obj, .ply, .gltf, .glb)";
    if path.is_dir() {
        bail!("{}: is a folder; {EXPECTED}", path.display());
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    // A `FormatError`'s message already names the file and place.
    let pbrt = sahara_formats::pbrt::is_pbrt_path(path);
    let (scene, file, warnings) = match ext.as_str() {
        _ if pbrt && camera.is_some() => bail!(
            "{}: --camera applies to meshes and the built-in scene; a pbrt file has its own Camera",
            path.display()
        ),
        _ if pbrt => {
            let mut p = sahara_formats::pbrt::load_pbrt(path).map_err(flat)?;
            if let Some(sky) = &sky {
                sahara_formats::sky::apply(&mut p.loaded.scene, sky).map_err(flat)?;
            }
            (p.loaded.scene, Some(p.loaded.settings), p.loaded.warnings)
        }
        "toml" if camera.is_some() => bail!(
            "{}: --camera applies to meshes and the built-in scene; a scene file has its own [camera]",
            path.display()
        ),
        "toml" => {
            let l = load_scene_with_sky(path, sky.as_ref()).map_err(flat)?;
            (l.scene, Some(l.settings), l.warnings)
        }
        "obj" | "ply" | "gltf" | "glb" => {
            let camera = camera.map_or(CameraChoice::Auto, CameraChoice::from_arg);
            let m = load_mesh_scene_with(path, &camera, sky.as_ref().unwrap_or(&Sky::Auto))
                .map_err(flat)?;
            eprintln!("camera: {}; light: {}", m.camera_source, m.sky);
            (m.scene, None, m.warnings)
        }
        "" => bail!(
            "{}: the file name has no extension; {EXPECTED}",
            path.display()
        ),
        _ => bail!("{}: cannot render .{ext} files; {EXPECTED}", path.display()),
    };
    Ok(Input {
        scene,
        file,
        name: stem(path),
        description: path.display().to_string(),
        warnings,
    })
}

fn stem(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map_or("render".into(), |s| s.to_string_lossy().into_owned());
    // `scene.pbrt.gz` is the scene `scene`.
    match stem.strip_suffix(".pbrt") {
        Some(s) if !s.is_empty() => s.to_owned(),
        _ => stem,
    }
}

fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w x h` depth image (three equal channels per pixel) from `f(x, y)`.
    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> Vec<f32> {
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| [f(x, y); 3])
            .collect()
    }

    #[test]
    fn depth_range_ignores_silhouette_blends() {
        // A 10x10 object at distance 2 to 3 on a background of misses; its
        // border pixels are blends with the misses (0.5).
        let rgb = image(20, 20, |x, y| {
            let inside = (5..15).contains(&x) && (5..15).contains(&y);
            let border = x == 5 || x == 14 || y == 5 || y == 14;
            match (inside, border) {
                (false, _) => 0.0,
                (true, true) => 0.5,
                (true, false) => 2.0 + x as f32 / 20.0,
            }
        });
        let (near, far) = depth_range(&rgb, 20, 20).unwrap();
        assert!(near >= 2.0, "near {near}");
        assert!((far - (2.0 + 13.0 / 20.0)).abs() < 1e-6, "far {far}");
        let grey = depth_to_gray8(&rgb, Some((near, far)));
        assert_eq!(grey[0], 0, "a miss is black");
        assert_eq!(grey[3 * (20 * 6 + 13)], 26, "the farthest hit is dark grey");
        // No hit at all: no range, a black image.
        let none = image(4, 4, |_, _| 0.0);
        assert_eq!(depth_range(&none, 4, 4), None);
        assert!(depth_to_gray8(&none, None).iter().all(|&v| v == 0));
    }
}
