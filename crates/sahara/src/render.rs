//! `sahara render`: a scene to a PNG or EXR, with a progress bar, Ctrl-C
//! handling and a summary.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use sahara_formats::camera::{read_sidecar, sidecar_path};
use sahara_formats::image_out::{write_image, Pixels};
use sahara_render::{
    builtin, render, Camera, Environment, Filter, Integrator, Light, Material, Progress,
    RenderSettings, SamplerKind, Scene, ToneMap,
};

use crate::cli::RenderArgs;
use crate::input::load_mesh;

/// `sahara render ...` (and `sahara` with no subcommand).
pub fn run(args: &RenderArgs) -> Result<()> {
    let (scene, name) = match &args.scene {
        None => (builtin::cornell_box(), "cornell_box".to_string()),
        Some(path) => (scene_from_file(path, args)?, stem(path)),
    };
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{name}.png")));
    // Refuse an unwritable output now, not after the render.
    sahara_formats::atomic::check_writable(&output)
        .map_err(|e| anyhow!("{e}"))
        .context("cannot write the output image")?;
    let mut scene = scene;
    // Any aspect ratio: the vertical field of view is kept.
    scene.camera.aspect = args.width as f32 / args.height as f32;
    scene
        .validate()
        .map_err(|e| anyhow!("invalid scene: {e}"))?;

    let settings = settings(args)?;
    let cancel = settings.cancel.clone().expect("settings set a cancel flag");
    ctrlc::set_handler(move || {
        // A second Ctrl-C leaves the default way.
        if cancel.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    })
    .context("cannot install the Ctrl-C handler")?;

    let bar = progress_bar(&settings);
    let threads = args.threads.map_or(0, usize::from);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the render threads")?;
    eprintln!(
        "rendering {} at {}x{}, {} ({}), {} spp in passes of {}, {} threads",
        args.scene
            .as_deref()
            .map_or("the built-in Cornell box".into(), |p| p
                .display()
                .to_string()),
        args.width,
        args.height,
        settings.integrator.name(),
        args.sampler,
        if args.time_limit.is_some() {
            "unlimited".to_string()
        } else {
            (settings.spp * settings.passes).to_string()
        },
        settings.spp,
        pool.current_num_threads()
    );
    let on_progress = |p: Progress| {
        bar.set_position((p.pass as u64) * p.tiles as u64 + p.tiles_done as u64);
        if p.tiles_done == 1 {
            bar.set_length(p.passes as u64 * p.tiles as u64);
            bar.set_message(format!("pass {}/{}", p.pass + 1, p.passes));
        }
    };
    let result = pool.install(|| render(&scene, &settings, &on_progress));
    bar.finish_and_clear();

    let s = &result.stats;
    let partial = s.stopped_early
        && settings
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::SeqCst));
    if s.passes == 0 {
        bail!("stopped before the first pass completed: no image written");
    }
    let rgb = result.film.to_rgb_f32();
    let tone = match args.tonemap.as_str() {
        "filmic" => ToneMap::Filmic,
        _ => ToneMap::Clamp,
    };
    let rgb8 = if is_exr(&output) {
        Vec::new()
    } else {
        result.film.to_srgb8(args.exposure, tone)
    };
    let pixels = if is_exr(&output) {
        Pixels::LinearRgbF32(&rgb)
    } else {
        Pixels::Rgb8(&rgb8)
    };
    let metadata = vec![
        (
            "sahara:integrator".to_string(),
            settings.integrator.name().to_string(),
        ),
        ("sahara:spp".to_string(), s.spp.to_string()),
        ("sahara:seed".to_string(), settings.seed.to_string()),
        ("sahara:partial".to_string(), partial.to_string()),
    ];
    write_image(&output, args.width, args.height, pixels, &metadata)
        .map_err(|e| anyhow!("{e}"))
        .context("cannot write the output image")?;
    let secs = s.render_time.as_secs_f64();
    eprintln!(
        "{} {}: {} passes, {} spp, {:.2} s render (+{:.0} ms tree builds), {} rays, {:.2} Mrays/s{}",
        if partial { "wrote PARTIAL image" } else { "wrote" },
        output.display(),
        s.passes,
        s.spp,
        secs,
        s.build_time.as_secs_f64() * 1e3,
        s.rays(),
        s.rays() as f64 / secs.max(1e-9) / 1e6,
        if s.nan_samples > 0 { format!(", {} NaN samples dropped", s.nan_samples) } else { String::new() }
    );
    if partial {
        // Interrupted: the image of the completed passes is on disk.
        std::process::exit(130);
    }
    Ok(())
}

/// Render settings from the command line.
fn settings(args: &RenderArgs) -> Result<RenderSettings> {
    let integrator = Integrator::from_name(&args.integrator).ok_or_else(|| {
        anyhow!(
            "unknown integrator '{}'; expected path, distribution, normals, depth, ao or cost",
            args.integrator
        )
    })?;
    let sampler = match args.sampler.as_str() {
        "independent" => SamplerKind::Independent,
        "stratified" => SamplerKind::Stratified,
        "sobol" => SamplerKind::Sobol,
        s => bail!("unknown sampler '{s}'; expected independent, stratified or sobol"),
    };
    let filter = match args.filter.as_str() {
        "box" => Filter::Box { radius: 0.5 },
        "tent" => Filter::Tent { radius: 1.0 },
        "gaussian" => Filter::default(),
        "mitchell" => Filter::Mitchell {
            radius: 2.0,
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        },
        f => bail!("unknown filter '{f}'; expected box, tent, gaussian or mitchell"),
    };
    if !matches!(args.tonemap.as_str(), "clamp" | "filmic") {
        bail!(
            "unknown tone map '{}'; expected clamp or filmic",
            args.tonemap
        );
    }
    let (spp, passes, time_limit) = match args.time_limit {
        Some(t) if !(t > 0.0 && t.is_finite()) => {
            bail!("--time-limit must be a positive number of seconds")
        }
        Some(t) => (args.spp, u32::MAX, Some(Duration::from_secs_f64(t))),
        None => {
            let per_pass = args.pass_spp.unwrap_or(args.spp.min(8)).min(args.spp);
            (per_pass, args.spp.div_ceil(per_pass), None)
        }
    };
    Ok(RenderSettings {
        width: args.width,
        height: args.height,
        spp,
        passes,
        time_limit,
        cancel: Some(Arc::new(AtomicBool::new(false))),
        seed: args.seed,
        sampler,
        filter,
        integrator,
        ..Default::default()
    })
}

fn progress_bar(settings: &RenderSettings) -> ProgressBar {
    let bar = ProgressBar::new(0);
    let template = if settings.time_limit.is_some() {
        "{spinner} {elapsed_precise} {msg} tiles {pos}"
    } else {
        "{bar:40} {percent:>3}% {msg} elapsed {elapsed_precise} eta {eta_precise}"
    };
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// A scene from a file: a mesh (OBJ, PLY) with its camera sidecar or an
/// automatic camera, a grey diffuse material, a sky and a sun.
fn scene_from_file(path: &Path, args: &RenderArgs) -> Result<Scene> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !matches!(ext.as_str(), "obj" | "ply") {
        bail!(
            "{}: cannot render .{ext} files; expected a mesh (.obj, .ply)",
            path.display()
        );
    }
    let mesh = load_mesh(path)?;
    let bounds = mesh.bounds();
    let aspect = args.width as f32 / args.height as f32;
    let sidecar = sidecar_path(path);
    let camera = if sidecar.exists() {
        let c = read_sidecar(&sidecar).map_err(|e| anyhow!("{e}"))?;
        Camera::look_at(c.eye, c.target, c.up, c.vfov_deg, aspect)
    } else {
        // Framed like the benchmark protocol's automatic camera.
        let c = bounds.center();
        let r = 0.5 * bounds.extent().length();
        let vfov: f32 = 45.0;
        let eye = c + Vec3::new(0.3, 0.5, 1.0).normalize() * (r / (0.5 * vfov.to_radians()).sin());
        Camera::look_at(eye, c, Vec3::Y, vfov, aspect)
    };
    let mut scene = Scene::new(camera);
    let grey = scene.add_material(Material::diffuse(Vec3::splat(0.7)));
    scene.add_object(mesh, glam::Affine3A::IDENTITY, grey);
    scene.environment = Some(Environment::Constant(Vec3::new(0.55, 0.6, 0.7)));
    scene.add_light(Light::directional(
        Vec3::new(-0.4, -1.0, -0.3),
        Vec3::splat(2.5),
    ));
    Ok(scene)
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map_or("render".into(), |s| s.to_string_lossy().into_owned())
}

fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}
