//! Scenes loaded as the command line loads them, rendered with its
//! settings rules (keyword arguments over the file's settings over the
//! defaults), interruptible from Python, and images written by its writer.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

use glam::Vec3;
use numpy::{PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sahara_formats::FileSettings;
use sahara_formats::{write_image, Pixels};
use sahara_formats::{LoadOptions, Loaded};
use sahara_kd::{BuildParams, Builder};
use sahara_render::{
    defaults, render_watched, Aov, AuxImages, Feature, Film, Filter, FilterKind, FrameSettings,
    Integrator, IntegratorKind, Named, PixelSum, Progress, RenderResult, RenderSettings,
    SamplerKind, Scene as RenderScene, SettingsError, ToneMap,
};

use crate::pool::pool;

pyo3::create_exception!(
    _sahara,
    FormatError,
    pyo3::exceptions::PyValueError,
    "A file Sahara cannot read or write; the message names the file and the line or byte."
);

/// A `sahara_formats::FormatError` as a Python exception.
fn format_error(e: sahara_formats::FormatError) -> PyErr {
    FormatError::new_err(e.to_string())
}

/// A scene loaded from a file (or the built-in Cornell box), ready to render.
#[pyclass(module = "sahara._sahara", frozen)]
pub struct Scene {
    scene: Arc<RenderScene>,
    settings: Option<FileSettings>,
    /// The scene's name (the file name without its extension).
    #[pyo3(get)]
    name: String,
    /// The file's path, or `the built-in Cornell box`.
    #[pyo3(get)]
    description: String,
    /// Problems that did not stop loading, one line each, naming the file.
    #[pyo3(get)]
    warnings: Vec<String>,
    /// What the scene's objects are called, by id - 1 (the `object` pass).
    #[pyo3(get)]
    object_names: Vec<String>,
    /// What the scene's materials are called, by id - 1 (the `material` pass).
    #[pyo3(get)]
    material_names: Vec<String>,
    /// Where a mesh file's camera and light came from (None for a scene file).
    #[pyo3(get)]
    framing: Option<String>,
}

impl Scene {
    /// The loaded scene; its problems named after the file they come
    /// from (`from_file`), as the command line names them.
    fn from_loaded(l: Loaded, from_file: bool) -> Self {
        let mut warnings = l.warnings;
        let from = l.description.clone();
        warnings.extend(l.scene.diagnostics().into_iter().map(|d| {
            if from_file {
                format!("{from}: {d}")
            } else {
                d
            }
        }));
        Scene {
            scene: Arc::new(l.scene),
            settings: l.settings,
            name: l.name,
            description: l.description,
            warnings,
            object_names: l.names.objects,
            material_names: l.names.materials,
            framing: l.framing,
        }
    }
}

#[pymethods]
impl Scene {
    /// The render settings the file asks for (a dict), or None (a mesh
    /// file, the built-in scene).
    #[getter]
    fn file_settings<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(f) = &self.settings else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("integrator", f.integrator.name())?;
        d.set_item("sampler", f.sampler.name())?;
        d.set_item("spp", f.spp)?;
        d.set_item("seed", f.seed)?;
        d.set_item("filter", f.filter.kind().name())?;
        d.set_item("width", f.width)?;
        d.set_item("height", f.height)?;
        d.set_item("exposure", f.exposure)?;
        d.set_item("tonemap", f.tonemap.name())?;
        d.set_item("output", f.output.as_ref().map(|p| p.display().to_string()))?;
        d.set_item("denoise", f.denoise)?;
        Ok(Some(d))
    }

    /// The number of triangles over the scene's meshes.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.scene.meshes.iter().map(|m| m.mesh.indices.len()).sum()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({:?}, {} triangles, {} instances)",
            self.description,
            self.triangle_count(),
            self.scene.instances.len()
        )
    }
}

/// Loads a scene or mesh file as `sahara render` does, the reader chosen
/// by the extension: `.toml`, `.pbrt`, `.pbrt.gz`, `.xml` (Mitsuba, its
/// `$name` parameters from `defines`), `.obj`, `.ply`, `.gltf`, `.glb`.
/// `camera` (a sidecar file or a glTF camera's name) and `sky` (`auto`,
/// `default`, `none`, or an environment image) as the command line's
/// `--camera` and `--sky`.
#[pyfunction]
#[pyo3(signature = (path, *, camera=None, sky=None, defines=None))]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    camera: Option<String>,
    sky: Option<String>,
    defines: Option<Vec<(String, String)>>,
) -> PyResult<Scene> {
    if !path.exists() {
        return Err(PyFileNotFoundError::new_err(format!(
            "{}: not found",
            path.display()
        )));
    }
    let options = LoadOptions {
        camera,
        sky,
        defines: defines.unwrap_or_default(),
    };
    let loaded = py
        .detach(|| sahara_formats::load(&path, &options))
        .map_err(format_error)?;
    Ok(Scene::from_loaded(loaded, true))
}

/// The built-in Cornell box, seen by `camera` (a sidecar file) and lit as
/// `sky` says.
#[pyfunction]
#[pyo3(signature = (*, camera=None, sky=None))]
pub fn cornell_box(camera: Option<String>, sky: Option<String>) -> PyResult<Scene> {
    let options = LoadOptions {
        camera,
        sky,
        defines: Vec::new(),
    };
    let loaded = sahara_formats::load_builtin(&options).map_err(format_error)?;
    Ok(Scene::from_loaded(loaded, false))
}

/// A name of a setting table, or a ValueError listing the names.
fn named<T: Named>(value: &str) -> PyResult<T> {
    T::from_name(value).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Renders `scene` as `sahara render` does with the same settings:
/// keyword arguments over the file's settings over the defaults, the
/// same image for the same seed. Releases the GIL; Ctrl-C (or any
/// exception a signal handler raises) stops the render after the tiles
/// under way and re-raises. `progress(done, total)` is called now and then
/// from the calling thread. Returns the linear RGB image (height, width, 3)
/// float32 and a dict of the `aovs` asked for.
#[pyfunction]
#[pyo3(signature = (scene, *, spp=None, width=None, height=None, integrator=None, seed=None,
    threads=None, aovs=None, denoise=false, sampler=None, filter=None, pass_spp=None,
    builder=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    spp: Option<u32>,
    width: Option<u32>,
    height: Option<u32>,
    integrator: Option<String>,
    seed: Option<u64>,
    threads: Option<usize>,
    aovs: Option<Vec<String>>,
    denoise: bool,
    sampler: Option<String>,
    filter: Option<String>,
    pass_spp: Option<u32>,
    builder: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyDict>)> {
    let file = scene.settings.as_ref();
    check_sizes(spp, width, height, pass_spp)?;
    let integrator = Integrator::chosen(
        integrator
            .as_deref()
            .map(named::<IntegratorKind>)
            .transpose()?,
        file.map(|f| f.integrator),
    );
    let sampler = match sampler {
        Some(s) => named::<SamplerKind>(&s)?,
        None => file.map(|f| f.sampler).unwrap_or_default(),
    };
    let filter_kind = filter.as_deref().map(named::<FilterKind>).transpose()?;
    let mut filter = match (filter_kind, file) {
        (Some(kind), Some(f)) if f.filter.kind() == kind => f.filter,
        (Some(kind), _) => Filter::from(kind),
        (None, Some(f)) => f.filter,
        (None, None) => Filter::default(),
    };
    let build = match builder {
        None => BuildParams::default(),
        Some(b) => BuildParams::new(
            Builder::parse(&b)
                .ok_or_else(|| PyValueError::new_err(format!("builder: unknown builder '{b}'")))?,
        ),
    };
    let spp = spp.or(file.map(|f| f.spp)).unwrap_or(defaults::SPP);
    let width = width.or(file.map(|f| f.width)).unwrap_or(512);
    let height = height.or(file.map(|f| f.height)).unwrap_or(512);
    let mut passes: Vec<Aov> = aovs
        .unwrap_or_default()
        .iter()
        .map(|a| named::<Aov>(a))
        .collect::<PyResult<_>>()?;
    let asked = passes.clone();
    let denoise = denoise || file.is_some_and(|f| f.denoise);
    if denoise {
        passes.extend([Aov::Albedo, Aov::Normal]);
        if filter_kind.is_none() {
            // As the command line: a wider filter correlates the noise of
            // neighbouring pixels, which the denoiser keeps.
            filter = Filter::from(FilterKind::Box);
        }
    }
    passes.sort();
    passes.dedup();
    if denoise {
        integrator
            .kind()
            .require(Feature::Denoise)
            .map_err(|e| PyValueError::new_err(format!("denoise: {e}")))?;
    }
    let cancel = Arc::new(AtomicBool::new(false));
    let mut settings = RenderSettings {
        frame: FrameSettings {
            width,
            height,
            spp,
            pass_spp: pass_spp.unwrap_or(defaults::PASS_SPP).min(spp),
            seed: seed.or(file.map(|f| f.seed)).unwrap_or(0),
            sampler,
            filter,
            integrator,
            adaptive: file.and_then(|f| f.adaptive),
        },
        cancel: Some(cancel.clone()),
        build,
        aovs: passes,
        ..Default::default()
    };
    if let Some(c) = file.and_then(|f| f.crop) {
        let w = c.window(width, height);
        if w.is_empty() {
            return Err(PyValueError::new_err(format!(
                "the scene file's crop window holds no pixel of the {width}x{height} image"
            )));
        }
        settings.window = Some(w);
    }
    // What the integrator cannot honour (the renderer's rules), named by
    // the argument or scene-file key that asked for it.
    settings.check().map_err(|e| {
        let asked = match &e {
            SettingsError::Unsupported {
                feature: Feature::Aovs,
                ..
            } => "aovs",
            _ => "noise_threshold",
        };
        PyValueError::new_err(format!("{asked}: {e}"))
    })?;
    check_memory(width, height, settings.aovs.len())?;
    let denoiser = if denoise {
        Some(
            sahara_denoise::Denoiser::load()
                .map_err(|e| PyRuntimeError::new_err(format!("denoise: {e}")))?,
        )
    } else {
        None
    };
    let mut render_scene = (*scene.scene).clone();
    render_scene.camera.aspect = width as f32 / height as f32;
    render_scene
        .validate()
        .map_err(|e| PyValueError::new_err(format!("{}: invalid scene: {e}", scene.description)))?;
    let mut result = run(py, render_scene, settings, threads, &cancel, progress)?;
    if let Some(d) = &denoiser {
        denoise_result(d, &mut result, &scene.scene)?;
    }
    let (w, h) = (result.film.width as usize, result.film.height as usize);
    let image = PyArray3::<f32>::zeros(py, [h, w, 3], false);
    // SAFETY: made here, held by no one else.
    unsafe { image.as_slice_mut()? }.copy_from_slice(&result.film.to_rgb_f32());
    let out = match &result.aux {
        Some(aux) => pass_arrays(py, &aux.images, &asked, w, h)?,
        None => PyDict::new(py),
    };
    Ok((image, out))
}

/// Refuses a zero size or sample count, and sides beyond 65536.
fn check_sizes(
    spp: Option<u32>,
    width: Option<u32>,
    height: Option<u32>,
    pass_spp: Option<u32>,
) -> PyResult<()> {
    for (what, v) in [
        ("spp", spp),
        ("width", width),
        ("height", height),
        ("pass_spp", pass_spp),
    ] {
        if v == Some(0) || v.is_some_and(|v| v > 65536 && what != "spp") {
            return Err(PyValueError::new_err(format!(
                "{what} must be {}",
                if what == "spp" {
                    "at least 1"
                } else {
                    "1..=65536"
                }
            )));
        }
    }
    Ok(())
}

/// A MemoryError for a render beyond the machine. The film's sums, its
/// image and the passes are allocated in the render's threads, where a
/// failed allocation aborts the process: the memory is asked for here
/// first.
fn check_memory(width: u32, height: u32, passes: usize) -> PyResult<()> {
    let pixels = width as usize * height as usize;
    let per_pixel = std::mem::size_of::<PixelSum>() + 16 * (2 + passes);
    let bytes = pixels.saturating_mul(per_pixel);
    if Vec::<u8>::new().try_reserve_exact(bytes).is_err() {
        return Err(PyMemoryError::new_err(format!(
            "a {width}x{height} render needs about {:.1} GB, more than this machine gives",
            bytes as f64 / 1e9
        )));
    }
    Ok(())
}

/// The render passes `asked` for as numpy arrays of `h` x `w` pixels, by
/// name.
fn pass_arrays<'py>(
    py: Python<'py>,
    im: &AuxImages,
    asked: &[Aov],
    w: usize,
    h: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let v3 = |v: &[Vec3]| -> PyResult<Bound<'py, PyArray3<f32>>> {
        let a = PyArray3::<f32>::zeros(py, [h, w, 3], false);
        // SAFETY: made here, held by no one else.
        let s = unsafe { a.as_slice_mut()? };
        for (o, p) in s.chunks_exact_mut(3).zip(v) {
            o.copy_from_slice(&p.to_array());
        }
        Ok(a)
    };
    for aov in asked {
        match aov {
            Aov::Albedo => out.set_item("albedo", v3(&im.albedo)?)?,
            Aov::Normal => out.set_item("normal", v3(&im.normal)?)?,
            Aov::Position => out.set_item("position", v3(&im.position)?)?,
            Aov::Variance => out.set_item("variance", v3(&im.variance)?)?,
            Aov::Depth => {
                let a = PyArray2::<f32>::zeros(py, [h, w], false);
                // SAFETY: made here, held by no one else.
                unsafe { a.as_slice_mut()? }.copy_from_slice(&im.depth);
                out.set_item("depth", a)?
            }
            Aov::Uv => {
                let a = PyArray3::<f32>::zeros(py, [h, w, 2], false);
                // SAFETY: made here, held by no one else.
                let s = unsafe { a.as_slice_mut()? };
                for (o, p) in s.chunks_exact_mut(2).zip(&im.uv) {
                    o.copy_from_slice(&p.to_array());
                }
                out.set_item("uv", a)?
            }
            Aov::Object | Aov::Material => {
                let ids = if *aov == Aov::Object {
                    &im.object
                } else {
                    &im.material
                };
                let a = PyArray2::<u32>::zeros(py, [h, w], false);
                // SAFETY: made here, held by no one else.
                unsafe { a.as_slice_mut()? }.copy_from_slice(ids);
                out.set_item(aov.name(), a)?
            }
        }
    }
    Ok(out)
}

/// Runs the render on its own thread (in the pool of `threads`), while
/// this one waits without the GIL, checks for signals and reports
/// progress. An exception from a signal handler (KeyboardInterrupt) stops
/// the render at the next tile, waits for its threads and is returned.
fn run(
    py: Python<'_>,
    scene: RenderScene,
    settings: RenderSettings,
    threads: Option<usize>,
    cancel: &Arc<AtomicBool>,
    progress: Option<Bound<'_, PyAny>>,
) -> PyResult<RenderResult> {
    let threads = threads.filter(|&t| t > 0).unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let pool = pool(threads)?;
    let done = Arc::new(AtomicU64::new(0));
    let total = Arc::new(AtomicU64::new(0));
    let (tx, mut rx) = mpsc::channel();
    let (d, t) = (done.clone(), total.clone());
    let worker = std::thread::Builder::new()
        .name("sahara-render".into())
        .spawn(move || {
            let on_progress = |p: Progress| {
                t.store(u64::from(p.passes) * p.tiles as u64, Ordering::Relaxed);
                d.store(
                    p.pass as u64 * p.tiles as u64 + p.tiles_done as u64,
                    Ordering::Relaxed,
                );
            };
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| render_watched(&scene, &settings, &on_progress, None))
            }));
            let _ = tx.send(r);
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the render thread: {e}")))?;
    let mut shown = (u64::MAX, u64::MAX);
    let result = loop {
        // The receiver goes into the wait and comes back (it is not Sync).
        let (got, back) = py.detach(move || (rx.recv_timeout(Duration::from_millis(100)), rx));
        rx = back;
        let now = (done.load(Ordering::Relaxed), total.load(Ordering::Relaxed));
        if let Some(cb) = &progress {
            if now != shown && now.1 > 0 {
                shown = now;
                if let Err(e) = cb.call1(now) {
                    cancel.store(true, Ordering::SeqCst);
                    py.detach(|| worker.join()).ok();
                    return Err(e);
                }
            }
        }
        match got {
            Ok(r) => break r,
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err("the render thread stopped"))
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        if let Err(e) = py.check_signals() {
            cancel.store(true, Ordering::SeqCst);
            py.detach(|| worker.join()).ok();
            return Err(e);
        }
    };
    py.detach(|| worker.join()).ok();
    let result = result
        .map_err(|_| PyRuntimeError::new_err("the render failed (a panic)"))?
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    if let Some(cb) = &progress {
        let t = total.load(Ordering::Relaxed);
        if t > 0 && shown != (t, t) {
            cb.call1((t, t))?;
        }
    }
    Ok(result)
}

/// Denoises the image in place, as `sahara render --denoise` does.
fn denoise_result(
    denoiser: &sahara_denoise::Denoiser,
    result: &mut RenderResult,
    scene: &RenderScene,
) -> PyResult<()> {
    let aux = result
        .aux
        .as_ref()
        .ok_or_else(|| PyRuntimeError::new_err("denoise: the render made no albedo and normal"))?;
    let flat = |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.to_array()).collect() };
    let (albedo, normal) = (flat(&aux.images.albedo), flat(&aux.images.normal));
    let noisy = result.film.to_rgb_f32();
    let c = &scene.camera;
    let noisy_guides = c.lens_radius > 0.0
        || (c.shutter_close > c.shutter_open
            && scene.instances.iter().any(|i| i.placement.is_moving()));
    let image = sahara_denoise::Image {
        width: result.film.width as usize,
        height: result.film.height as usize,
        color: &noisy,
        hdr: true,
    };
    let guide = sahara_denoise::Aux {
        prefilter_aux: noisy_guides,
        ..sahara_denoise::Aux::albedo_normal(&albedo, &normal)
    };
    let clean = denoiser
        .denoise(&image, guide)
        .map_err(|e| PyRuntimeError::new_err(format!("denoise: {e}")))?;
    for (p, c) in result.film.pixels.iter_mut().zip(clean.chunks_exact(3)) {
        *p = Vec3::new(c[0], c[1], c[2]).max(Vec3::ZERO);
    }
    Ok(())
}

/// Writes a linear RGB image, (height, width, 3) float32, as the command
/// line writes a render: `.exr` as linear 32-bit floats, `.png` as 8-bit
/// sRGB after `exposure` (stops) and `tonemap` (`clamp` or `filmic`);
/// `metadata` as the file's text attributes. Written beside the target and
/// renamed over it.
#[pyfunction]
#[pyo3(signature = (path, image, *, exposure=0.0, tonemap="clamp", metadata=None))]
pub fn write(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    exposure: f32,
    tonemap: &str,
    metadata: Option<Vec<(String, String)>>,
) -> PyResult<()> {
    let tonemap = named::<ToneMap>(tonemap)?;
    if !exposure.is_finite() {
        return Err(PyValueError::new_err(
            "exposure must be a finite number of stops",
        ));
    }
    let a = crate::arrays::ndarray(image, "image")?;
    let a = a.call_method1("astype", ("float32",))?;
    let a: PyReadonlyArray3<f32> = a.extract().map_err(|_| {
        PyValueError::new_err("image: expected an array of shape (height, width, 3) of floats")
    })?;
    let shape = a.shape().to_vec();
    if shape[2] != 3 || shape[0] == 0 || shape[1] == 0 {
        return Err(PyValueError::new_err(format!(
            "image: expected an array of shape (height, width, 3), got shape {shape:?}"
        )));
    }
    let (h, w) = (shape[0] as u32, shape[1] as u32);
    let rgb: Vec<f32> = a.as_array().iter().copied().collect();
    let metadata = metadata.unwrap_or_default();
    py.detach(|| write_rgb(&path, w, h, &rgb, exposure, tonemap, &metadata))
}

/// [`write`] once the array is read.
fn write_rgb(
    path: &Path,
    w: u32,
    h: u32,
    rgb: &[f32],
    exposure: f32,
    tonemap: ToneMap,
    metadata: &[(String, String)],
) -> PyResult<()> {
    let exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let written = if exr {
        write_image(path, w, h, Pixels::LinearRgbF32(rgb), metadata)
    } else {
        let film = Film {
            width: w,
            height: h,
            pixels: rgb
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect(),
        };
        write_image(
            path,
            w,
            h,
            Pixels::Rgb8(&film.to_srgb8(exposure, tonemap)),
            metadata,
        )
    };
    written.map_err(format_error)
}

/// The names each setting takes: integrators, samplers, filters, render
/// passes, tone maps and builders.
#[pyfunction]
pub fn names(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("integrator", PyList::new(py, IntegratorKind::names())?)?;
    d.set_item("sampler", PyList::new(py, SamplerKind::names())?)?;
    d.set_item("filter", PyList::new(py, FilterKind::names())?)?;
    d.set_item("aov", PyList::new(py, Aov::names())?)?;
    d.set_item("tonemap", PyList::new(py, ToneMap::names())?)?;
    Ok(d)
}

/// Vertices and faces as numpy arrays.
type MeshArrays<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<u32>>);

/// A mesh file's triangles as the command line reads them (`.obj`,
/// `.ply`, `.gltf`, `.glb`; a glTF file's meshes merged in scene order,
/// polygons fan-triangulated): (N, 3) float32 vertices and (M, 3) uint32
/// faces, for `RayScene`.
#[pyfunction]
pub fn read_mesh<'py>(py: Python<'py>, path: PathBuf) -> PyResult<MeshArrays<'py>> {
    if !path.exists() {
        return Err(PyFileNotFoundError::new_err(format!(
            "{}: not found",
            path.display()
        )));
    }
    let mesh = py
        .detach(|| sahara_formats::load_mesh(&path))
        .map_err(format_error)?;
    let v = PyArray2::<f32>::zeros(py, [mesh.positions.len(), 3], false);
    let f = PyArray2::<u32>::zeros(py, [mesh.indices.len(), 3], false);
    // SAFETY: made here, held by no one else.
    let (vs, fs) = unsafe { (v.as_slice_mut()?, f.as_slice_mut()?) };
    for (o, p) in vs.chunks_exact_mut(3).zip(&mesh.positions) {
        o.copy_from_slice(&p.to_array());
    }
    for (o, t) in fs.chunks_exact_mut(3).zip(&mesh.indices) {
        o.copy_from_slice(t);
    }
    Ok((v, f))
}
