//! numpy arrays in: shapes and dtypes checked with messages that name the
//! argument, read in place where the layout allows (no copy of a
//! C-contiguous float32 array), and numpy arrays out.

use glam::Vec3;
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::{
    PyArray1, PyArray2, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArray1,
    PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyFloat;

/// `obj` as a numpy array: itself if it is one, else `numpy.asarray(obj)`.
pub(crate) fn ndarray<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let np = obj.py().import("numpy")?;
    let a = np.call_method1("asarray", (obj,)).map_err(|e| {
        PyTypeError::new_err(format!(
            "{name}: not an array or a sequence of numbers ({e})"
        ))
    })?;
    Ok(a.cast::<PyUntypedArray>()?.clone())
}

/// The shape and dtype of `a`, for messages: `shape (5, 2), dtype int64`.
fn described(a: &Bound<'_, PyUntypedArray>) -> String {
    let dtype = a
        .dtype()
        .str()
        .map(|s| s.to_string())
        .unwrap_or_else(|_| "?".into());
    let dims: Vec<String> = a.shape().iter().map(|d| d.to_string()).collect();
    let comma = if dims.len() == 1 { "," } else { "" };
    format!("shape ({}{comma}), dtype {dtype}", dims.join(", "))
}

/// The element type of a float array.
enum FloatKind {
    F32,
    F64,
}

/// `a` itself if it holds float32 or float64, else (integers, float16)
/// `a` as float64; other arrays are returned as they are, to be refused.
fn floats<'py>(a: Bound<'py, PyUntypedArray>) -> PyResult<Bound<'py, PyUntypedArray>> {
    let kind = a.dtype().kind();
    if float_kind(&a).is_none() && matches!(kind, b'i' | b'u' | b'f') {
        Ok(a.call_method1("astype", ("float64",))?
            .cast::<PyUntypedArray>()?
            .clone())
    } else {
        Ok(a)
    }
}

fn float_kind(a: &Bound<'_, PyUntypedArray>) -> Option<FloatKind> {
    let py = a.py();
    let d = a.dtype();
    if d.is_equiv_to(&numpy::dtype::<f32>(py)) {
        Some(FloatKind::F32)
    } else if d.is_equiv_to(&numpy::dtype::<f64>(py)) {
        Some(FloatKind::F64)
    } else {
        None
    }
}

/// A float32 or float64 array of shape (N, 3), held for reading.
pub(crate) enum Rows3<'py> {
    /// float32.
    F32(PyReadonlyArray2<'py, f32>),
    /// float64 (rounded to float32 as read).
    F64(PyReadonlyArray2<'py, f64>),
}

impl<'py> Rows3<'py> {
    /// `obj` as rows of three floats; with `single`, one point of shape
    /// (3,) is taken as one row (to be broadcast by the caller).
    pub(crate) fn extract(obj: &Bound<'py, PyAny>, name: &str, single: bool) -> PyResult<Self> {
        let a = floats(ndarray(obj, name)?)?;
        let a = if single && a.ndim() == 1 && a.shape() == [3] {
            a.call_method1("reshape", (1, 3))?
                .cast::<PyUntypedArray>()?
                .clone()
        } else {
            a
        };
        let shape_ok = a.ndim() == 2 && a.shape()[1] == 3;
        let kind = float_kind(&a);
        match (shape_ok, kind) {
            (true, Some(FloatKind::F32)) => Ok(Rows3::F32(
                a.cast::<PyArray2<f32>>()?
                    .try_readonly()
                    .map_err(busy(name))?,
            )),
            (true, Some(FloatKind::F64)) => Ok(Rows3::F64(
                a.cast::<PyArray2<f64>>()?
                    .try_readonly()
                    .map_err(busy(name))?,
            )),
            _ => Err(PyValueError::new_err(format!(
                "{name}: expected an array of shape (N, 3){} of numbers, got {}",
                if single { " or (3,)" } else { "" },
                described(&a)
            ))),
        }
    }

    /// Number of rows.
    pub(crate) fn len(&self) -> usize {
        match self {
            Rows3::F32(a) => a.shape()[0],
            Rows3::F64(a) => a.shape()[0],
        }
    }

    /// A view for reading without the GIL.
    pub(crate) fn view(&self) -> Rows3View<'_> {
        match self {
            // `as_slice` takes Fortran order too: only C order is read flat.
            Rows3::F32(a) => match a.as_slice() {
                Ok(s) if a.is_c_contiguous() => Rows3View::Flat(s),
                _ => Rows3View::F32(a.as_array()),
            },
            Rows3::F64(a) => Rows3View::F64(a.as_array()),
        }
    }
}

/// Rows of three floats, readable from any thread.
#[derive(Clone, Copy)]
pub(crate) enum Rows3View<'a> {
    /// C-contiguous float32, read in place.
    Flat(&'a [f32]),
    /// Strided float32.
    F32(ArrayView2<'a, f32>),
    /// float64.
    F64(ArrayView2<'a, f64>),
}

impl Rows3View<'_> {
    /// Row `i` as float32.
    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> Vec3 {
        match self {
            Rows3View::Flat(s) => Vec3::new(s[3 * i], s[3 * i + 1], s[3 * i + 2]),
            Rows3View::F32(a) => Vec3::new(a[[i, 0]], a[[i, 1]], a[[i, 2]]),
            Rows3View::F64(a) => Vec3::new(a[[i, 0]] as f32, a[[i, 1]] as f32, a[[i, 2]] as f32),
        }
    }
}

/// A per-ray float: one value for every ray, or an array of N.
pub(crate) enum PerRay<'py> {
    /// The same value for every ray.
    One(f32),
    /// float32 values, one per ray.
    F32(PyReadonlyArray1<'py, f32>),
    /// float64 values, one per ray.
    F64(PyReadonlyArray1<'py, f64>),
}

impl<'py> PerRay<'py> {
    /// `obj` as a number or an array of `n` floats.
    pub(crate) fn extract(obj: &Bound<'py, PyAny>, name: &str, n: usize) -> PyResult<Self> {
        if obj.is_instance_of::<PyFloat>() || obj.extract::<i64>().is_ok() {
            return Ok(PerRay::One(obj.extract::<f64>()? as f32));
        }
        let a = floats(ndarray(obj, name)?)?;
        if a.ndim() == 0 {
            return Ok(PerRay::One(a.call_method0("item")?.extract::<f64>()? as f32));
        }
        let kind = float_kind(&a);
        if a.ndim() != 1 || a.shape()[0] != n || kind.is_none() {
            return Err(PyValueError::new_err(format!(
                "{name}: expected a number or an array of shape ({n},) of float32 or float64, got {}",
                described(&a)
            )));
        }
        Ok(match kind {
            Some(FloatKind::F32) => PerRay::F32(
                a.cast::<PyArray1<f32>>()?
                    .try_readonly()
                    .map_err(busy(name))?,
            ),
            _ => PerRay::F64(
                a.cast::<PyArray1<f64>>()?
                    .try_readonly()
                    .map_err(busy(name))?,
            ),
        })
    }

    /// A view for reading without the GIL.
    pub(crate) fn view(&self) -> PerRayView<'_> {
        match self {
            PerRay::One(v) => PerRayView::One(*v),
            PerRay::F32(a) => match a.as_slice() {
                Ok(s) => PerRayView::Flat(s),
                Err(_) => PerRayView::F32(a.as_array()),
            },
            PerRay::F64(a) => PerRayView::F64(a.as_array()),
        }
    }
}

/// Per-ray floats, readable from any thread.
#[derive(Clone, Copy)]
pub(crate) enum PerRayView<'a> {
    One(f32),
    /// Contiguous float32, read in place.
    Flat(&'a [f32]),
    F32(ArrayView1<'a, f32>),
    F64(ArrayView1<'a, f64>),
}

impl PerRayView<'_> {
    /// The value of ray `i`.
    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> f32 {
        match self {
            PerRayView::One(v) => *v,
            PerRayView::Flat(s) => s[i],
            PerRayView::F32(a) => a[i],
            PerRayView::F64(a) => a[i] as f32,
        }
    }

    /// The values of rays `start..start + len`, if they can be read
    /// without a branch per ray: `Ok` for one value for all, `Err` for a
    /// slice.
    #[inline(always)]
    pub(crate) fn run(&self, start: usize, len: usize) -> Option<Result<f32, &[f32]>> {
        match self {
            PerRayView::One(v) => Some(Ok(*v)),
            PerRayView::Flat(s) => Some(Err(&s[start..start + len])),
            _ => None,
        }
    }
}

/// The error of an array that Rust code elsewhere holds for writing.
fn busy(name: &str) -> impl FnOnce(numpy::BorrowError) -> PyErr + '_ {
    move |e| PyValueError::new_err(format!("{name}: cannot be read now ({e})"))
}

/// Vertices: an (N, 3) float32 or float64 array of finite coordinates.
pub(crate) fn vertices(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Vec3>> {
    let rows = Rows3::extract(obj, "vertices", false)?;
    let view = rows.view();
    let out: Vec<Vec3> = (0..rows.len()).map(|i| view.get(i)).collect();
    // float64 values beyond float32's range become infinite: refused too.
    if let Some(i) = out.iter().position(|p| !p.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "vertices: row {i} holds a NaN or infinite coordinate (or one beyond float32's range)"
        )));
    }
    Ok(out)
}

/// Faces: an (M, 3) integer array of vertex indices in `0..vertex_count`.
pub(crate) fn faces(obj: &Bound<'_, PyAny>, vertex_count: usize) -> PyResult<Vec<[u32; 3]>> {
    let a = ndarray(obj, "faces")?;
    let py = a.py();
    let d = a.dtype();
    let integer = d.kind() == b'i' || d.kind() == b'u';
    // A (0,) array is taken as no faces (numpy makes float64 of an empty list).
    if a.ndim() == 1 && a.shape()[0] == 0 {
        return Ok(Vec::new());
    }
    if a.ndim() != 2 || a.shape()[1] != 3 || !integer {
        return Err(PyValueError::new_err(format!(
            "faces: expected an array of shape (M, 3) of integers (vertex indices), got {}",
            described(&a)
        )));
    }
    // Any integer type, read as int64 (a copy only where it is not int64).
    let a = if d.is_equiv_to(&numpy::dtype::<i64>(py)) {
        a
    } else if d.is_equiv_to(&numpy::dtype::<u64>(py)) {
        // Values past i64::MAX are out of range anyway: clamp them there.
        let np = py.import("numpy")?;
        np.call_method1("minimum", (&a, i64::MAX as u64))?
            .call_method1("astype", ("int64",))?
            .cast::<PyUntypedArray>()?
            .clone()
    } else {
        a.call_method1("astype", ("int64",))?
            .cast::<PyUntypedArray>()?
            .clone()
    };
    let a = a
        .cast::<PyArrayDyn<i64>>()?
        .try_readonly()
        .map_err(busy("faces"))?;
    let v = a.as_array();
    let m = v.shape()[0];
    let mut out = Vec::with_capacity(m);
    for f in 0..m {
        let mut tri = [0u32; 3];
        for (k, slot) in tri.iter_mut().enumerate() {
            let i = v[[f, k]];
            if i < 0 || i as u64 >= vertex_count as u64 {
                return Err(PyValueError::new_err(format!(
                    "faces: row {f} refers to vertex {i}, out of range for {vertex_count} vertices"
                )));
            }
            *slot = i as u32;
        }
        out.push(tri);
    }
    Ok(out)
}
