//! Scenes loaded as the command line loads them and rendered through the
//! same request (`sahara_formats::Request`): keyword arguments are the
//! request's settings table's, over the file's settings over the
//! defaults; interruptible from Python; images written by the same
//! writer.

use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

use glam::Vec3;
use numpy::{PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{
    PyFileNotFoundError, PyMemoryError, PyRuntimeError, PyTypeError, PyUserWarning, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString};
use sahara_formats::{write_image, Pixels};
use sahara_formats::{Given, Plan, Refused, Request, RequestError, Setting, SettingsLayer};
use sahara_formats::{LoadOptions, Loaded, Note, SceneNames, Spelling, SETTINGS};
use sahara_render::{
    render_watched, Aov, AuxImages, Film, FilterKind, Guiding, IntegratorKind, LightSampler, Named,
    PathLoop, Progress, RenderResult, SamplerKind, Scene as RenderScene, ToneMap,
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

/// A refused request as the Python exception a caller expects: a
/// `MemoryError` for a render beyond the machine, a `RuntimeError` for
/// the denoiser, `sahara.FormatError` for a file, else a `ValueError`
/// naming the keyword argument.
fn request_error(e: RequestError) -> PyErr {
    let message = e.message(Spelling::Python);
    match e {
        RequestError::Memory(_) => PyMemoryError::new_err(message),
        RequestError::Denoiser { .. } => PyRuntimeError::new_err(message),
        RequestError::File(_) => FormatError::new_err(message),
        RequestError::Refused { .. } => PyValueError::new_err(message),
    }
}

/// A scene loaded from a file (or the built-in Cornell box), ready to render.
#[pyclass(module = "sahara._sahara", frozen)]
pub struct Scene {
    scene: Arc<RenderScene>,
    settings: Option<SettingsLayer>,
    path: Option<PathBuf>,
    names: SceneNames,
    /// The scene's name (the file name without its extension).
    #[pyo3(get)]
    name: String,
    /// The file's path, or `the built-in Cornell box`.
    #[pyo3(get)]
    description: String,
    /// Problems that did not stop loading, one line each, naming the file.
    #[pyo3(get)]
    warnings: Vec<String>,
    /// Where a mesh file's camera and light came from (None for a scene file).
    #[pyo3(get)]
    framing: Option<String>,
}

impl Scene {
    /// The loaded scene, with its problems as the command line says them.
    fn from_loaded(l: Loaded) -> Self {
        Scene {
            warnings: l.problems(),
            scene: Arc::new(l.scene),
            settings: l.settings,
            path: l.path,
            names: l.names,
            name: l.name,
            description: l.description,
            framing: l.framing,
        }
    }

    /// The scene as loaded, for a request (its problems were said when it
    /// was loaded).
    fn loaded(&self) -> Loaded {
        Loaded {
            scene: (*self.scene).clone(),
            settings: self.settings.clone(),
            name: self.name.clone(),
            description: self.description.clone(),
            path: self.path.clone(),
            names: self.names.clone(),
            warnings: Vec::new(),
            framing: self.framing.clone(),
        }
    }
}

#[pymethods]
impl Scene {
    /// The render settings of the file (over the defaults: what a render
    /// without arguments uses), a dict; None for a mesh file or the
    /// built-in scene.
    #[getter]
    fn file_settings<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(file) = &self.settings else {
            return Ok(None);
        };
        let layer = SettingsLayer::default().apply(file.clone());
        let (f, o) = (layer.frame_settings(), layer.output.clone().decided());
        let d = PyDict::new(py);
        d.set_item("integrator", f.integrator.name())?;
        d.set_item("sampler", f.sampler.name())?;
        d.set_item("light_sampler", f.light_sampler.name())?;
        d.set_item("guiding", f.guiding.name())?;
        d.set_item("spp", f.spp)?;
        d.set_item("seed", f.seed)?;
        d.set_item("filter", f.filter.kind().name())?;
        d.set_item("width", f.width)?;
        d.set_item("height", f.height)?;
        d.set_item("noise_threshold", f.adaptive.map(|a| a.threshold))?;
        d.set_item("min_spp", f.adaptive.map(|a| a.min_spp))?;
        d.set_item("exposure", o.exposure)?;
        d.set_item("tonemap", o.tonemap.name())?;
        d.set_item("output", layer.path.map(|p| p.display().to_string()))?;
        d.set_item("denoise", o.denoise)?;
        Ok(Some(d))
    }

    /// What the scene's objects are called, by id - 1 (the `object` pass).
    #[getter]
    fn object_names(&self) -> Vec<String> {
        self.names.objects.clone()
    }

    /// What the scene's materials are called, by id - 1 (the `material` pass).
    #[getter]
    fn material_names(&self) -> Vec<String> {
        self.names.materials.clone()
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
    Ok(Scene::from_loaded(loaded))
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
    Ok(Scene::from_loaded(loaded))
}

/// A name of a setting table, or a ValueError listing the names.
fn named<T: Named>(value: &str) -> PyResult<T> {
    T::from_name(value).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Most threads a render takes (the command line's `--threads` limit).
const MAX_THREADS: i64 = 1024;

/// Renders `scene` through the request `sahara render` makes: keyword
/// arguments (the request's settings, `SETTINGS`) over the file's
/// settings over the defaults, the same image for the same seed; with
/// `output`, the same file. Releases the GIL; Ctrl-C (or any exception a
/// signal handler raises) stops the render after the tiles under way and
/// re-raises. `progress(done, total)` is called now and then from the
/// calling thread. Returns the linear RGB image (height, width, 3)
/// float32 (of the crop or piece, if one is asked for) and a dict of the
/// `aovs` asked for.
#[pyfunction]
#[pyo3(signature = (scene, *, threads=None, progress=None, **settings))]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    threads: Option<i64>,
    progress: Option<Bound<'py, PyAny>>,
    settings: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyDict>)> {
    let threads = match threads {
        None => None,
        Some(t @ 0..=MAX_THREADS) => Some(t as usize),
        Some(t) => {
            return Err(PyValueError::new_err(format!(
                "threads: {t} is not in 0..={MAX_THREADS}"
            )))
        }
    };
    let request = Request {
        caller: caller_settings(settings)?,
        write_by_default: false,
    };
    request.check().map_err(request_error)?;
    let loaded = scene.loaded();
    let plan = py.detach(|| request.plan(loaded)).map_err(request_error)?;
    // A setting that will not do what it seems to ask is a Python warning;
    // what the plan decided goes unsaid, as a library says nothing.
    for note in &plan.notes {
        if let Note::Warning(line) = note {
            let line = CString::new(line.as_str())?;
            PyErr::warn(py, &py.get_type::<PyUserWarning>(), &line, 1)?;
        }
    }
    let mut result = run(py, &plan, threads, progress)?;
    let denoised = py
        .detach(|| plan.denoise(&mut result))
        .map_err(request_error)?;
    py.detach(|| plan.write(&result, denoised.as_ref(), false))
        .map_err(request_error)?;
    let (w, h) = (result.film.width as usize, result.film.height as usize);
    let image = PyArray3::<f32>::zeros(py, [h, w, 3], false);
    // SAFETY: made here, held by no one else.
    unsafe { image.as_slice_mut()? }.copy_from_slice(&result.film.to_rgb_f32());
    let out = match &result.aux {
        Some(aux) => pass_arrays(py, &aux.images, &plan.output.aovs, w, h)?,
        None => PyDict::new(py),
    };
    Ok((image, out))
}

/// The caller's settings layer from `render`'s keyword arguments, each
/// put by the settings table (None: not given). A keyword no setting
/// has is a `TypeError`, as Python's own; a value of the wrong kind a
/// `TypeError`, one the setting refuses a `ValueError`, both naming the
/// keyword.
fn caller_settings(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<SettingsLayer> {
    let mut layer = SettingsLayer::default();
    let Some(kwargs) = kwargs else {
        return Ok(layer);
    };
    for (key, value) in kwargs.iter() {
        let key: String = key.extract()?;
        let Some(setting) = Setting::by_keyword(&key) else {
            let known: Vec<&str> = SETTINGS.iter().map(|s| s.keyword).collect();
            return Err(PyTypeError::new_err(format!(
                "render() got an unexpected keyword argument '{key}' (it takes {} and threads, \
                 progress)",
                known.join(", ")
            )));
        };
        if value.is_none() {
            continue;
        }
        let given = given(&value)
            .map_err(|what| PyTypeError::new_err(format!("{key}: expected {what}")))?;
        setting.set(&mut layer, &given).map_err(|e| match e {
            Refused::Type(m) => PyTypeError::new_err(format!("{key}: {m}")),
            Refused::Value(m) => PyValueError::new_err(format!("{key}: {m}")),
        })?;
    }
    Ok(layer)
}

/// A Python value as the settings table takes it: `bool`, whole numbers
/// (`int` and numpy's, anything with `__index__`), other numbers, `str`
/// and paths, lists and tuples of these. Else what is expected.
fn given(v: &Bound<'_, PyAny>) -> Result<Given, &'static str> {
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(Given::Flag(b.is_true()));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(Given::Str(s.to_string()));
    }
    if let Ok(n) = v.extract::<i128>() {
        return Ok(Given::Whole(n));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(Given::Number(x));
    }
    if let Ok(p) = v.extract::<PathBuf>() {
        return Ok(Given::Str(p.display().to_string()));
    }
    if let Ok(items) = v.extract::<Vec<Bound<'_, PyAny>>>() {
        let items = items.iter().map(given).collect::<Result<_, _>>()?;
        return Ok(Given::List(items));
    }
    Err("a number, text, a path, True or False, or a list of them")
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

/// Runs the plan's render on a thread of its own (in the pool of
/// `threads`), while this one waits without the GIL, checks for signals
/// and reports progress. An exception from a signal handler
/// (KeyboardInterrupt) or from `progress` stops the render at the next
/// tile, waits for its threads and is returned.
fn run(
    py: Python<'_>,
    plan: &Plan,
    threads: Option<usize>,
    progress: Option<Bound<'_, PyAny>>,
) -> PyResult<RenderResult> {
    let threads = threads.filter(|&t| t > 0).unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let pool = pool(threads)?;
    let cancel = plan.settings.cancel.clone().unwrap_or_default();
    let done = Arc::new(AtomicU64::new(0));
    let total = Arc::new(AtomicU64::new(0));
    let (tx, mut rx) = mpsc::channel();
    let (d, t) = (done.clone(), total.clone());
    let (scene, settings) = (&plan.scene, &plan.settings);
    std::thread::scope(|s| {
        let worker = std::thread::Builder::new()
            .name("sahara-render".into())
            .spawn_scoped(s, move || {
                let on_progress = |p: Progress| {
                    t.store(u64::from(p.passes) * p.tiles as u64, Ordering::Relaxed);
                    d.store(
                        p.pass as u64 * p.tiles as u64 + p.tiles_done as u64,
                        Ordering::Relaxed,
                    );
                };
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    pool.install(|| render_watched(scene, settings, &on_progress, None))
                }));
                let _ = tx.send(r);
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the render thread: {e}")))?;
        let stop = |worker: std::thread::ScopedJoinHandle<'_, ()>, cancel: &AtomicBool| {
            cancel.store(true, Ordering::SeqCst);
            py.detach(|| worker.join()).ok();
        };
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
                        stop(worker, &cancel);
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
                stop(worker, &cancel);
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
    })
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

/// The names each setting takes: integrators, samplers, light samplers,
/// path loops, filters, render passes and tone maps; and `setting`, the
/// keyword arguments of `render` that are render settings.
#[pyfunction]
pub fn names(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    let keywords: Vec<&str> = SETTINGS.iter().map(|s| s.keyword).collect();
    d.set_item("setting", PyList::new(py, keywords)?)?;
    d.set_item("integrator", PyList::new(py, IntegratorKind::names())?)?;
    d.set_item("sampler", PyList::new(py, SamplerKind::names())?)?;
    d.set_item("light_sampler", PyList::new(py, LightSampler::names())?)?;
    d.set_item("path_loop", PyList::new(py, PathLoop::names())?)?;
    d.set_item("guiding", PyList::new(py, Guiding::names())?)?;
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
