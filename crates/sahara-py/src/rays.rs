//! `RayScene`: triangle meshes in one kd-tree, queried with numpy arrays of
//! rays, without the GIL, on Sahara's threads.

use std::sync::{Arc, Mutex};

use glam::Vec3;
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadwriteArray1, PyReadwriteArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use sahara_kd::{AccelParams, Hit, Ray, Triangle, TriangleAccel};

use crate::arrays::{PerRay, PerRayView, Rows3, Rows3View};
use crate::pool::run_on;

/// Rays per work item: the batch size of `sahara-kd`'s parallel queries.
const CHUNK: usize = 256;

/// The meshes and the tree built over them.
struct Geometry {
    /// Every mesh's vertices, one after the other.
    positions: Vec<Vec3>,
    /// Every mesh's faces, with indices into `positions`.
    faces: Vec<[u32; 3]>,
    /// The first face of each mesh, and the face count at the end.
    starts: Vec<u32>,
}

impl Geometry {
    /// The mesh of global face `f` and its index within that mesh.
    #[inline(always)]
    fn locate(starts: &[u32], f: u32) -> (i32, i32) {
        if starts.len() == 2 {
            return (0, f as i32);
        }
        let mesh = starts.partition_point(|&s| s <= f) - 1;
        (mesh as i32, (f - starts[mesh]) as i32)
    }
}

/// What a query needs, shared with the threads that answer it: made with
/// the tree, kept while the meshes do not change.
#[derive(Clone)]
struct Snapshot {
    tree: Arc<TriangleAccel>,
    /// The unit geometric normal of each face (one load per hit, rather
    /// than three vertices found through the face).
    normals: Arc<[Vec3]>,
    /// The first face of each mesh, and the face count at the end.
    starts: Arc<[u32]>,
}

/// Triangle meshes in one acceleration structure (the eight-wide BVH, or
/// a kd-tree), for ray queries on numpy arrays.
///
/// `RayScene(vertices, faces, accel="bvh", builder=None, threads=None)`
/// holds one mesh;
/// `add_mesh` adds more (each with its id: 0, 1, ...), and the tree over
/// all of them is built at the next query. Every query releases the GIL
/// and runs on `threads` threads (None: all of the machine's).
#[pyclass(module = "sahara._sahara", frozen)]
pub struct RayScene {
    geometry: Mutex<GeometryState>,
    params: AccelParams,
    threads: Option<usize>,
}

/// The geometry, and the tree over it once a query has built it.
struct GeometryState {
    geometry: Geometry,
    shared: Option<Snapshot>,
}

#[pymethods]
impl RayScene {
    #[new]
    #[pyo3(signature = (vertices=None, faces=None, *, accel="bvh", builder=None, threads=None))]
    fn new(
        py: Python<'_>,
        vertices: Option<&Bound<'_, PyAny>>,
        faces: Option<&Bound<'_, PyAny>>,
        accel: &str,
        builder: Option<&str>,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let params = AccelParams::from_names(accel, builder).map_err(PyValueError::new_err)?;
        let scene = RayScene {
            geometry: Mutex::new(GeometryState {
                geometry: Geometry {
                    positions: Vec::new(),
                    faces: Vec::new(),
                    starts: vec![0],
                },
                shared: None,
            }),
            params,
            threads: threads.filter(|&t| t > 0),
        };
        match (vertices, faces) {
            (Some(v), Some(f)) => {
                scene.add_mesh(py, v, f)?;
            }
            (None, None) => {}
            _ => {
                return Err(PyValueError::new_err(
                    "give both vertices and faces, or neither (then add meshes with add_mesh)",
                ))
            }
        }
        Ok(scene)
    }

    /// Adds a mesh: (N, 3) float32/float64 vertices and (M, 3) integer
    /// faces. Returns its id, the `mesh` of its hits (0 for the first).
    fn add_mesh(
        &self,
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        let v = crate::arrays::vertices(vertices)?;
        let f = crate::arrays::faces(faces, v.len())?;
        let _ = py;
        let mut state = self.lock()?;
        let g = &mut state.geometry;
        let base = g.positions.len();
        let total_faces = g.faces.len() + f.len();
        if base + v.len() > u32::MAX as usize || total_faces >= u32::MAX as usize {
            return Err(PyValueError::new_err(
                "the scene would hold more than 2^32 - 1 vertices or faces",
            ));
        }
        g.positions.extend(v);
        g.faces
            .extend(f.into_iter().map(|t| t.map(|i| i + base as u32)));
        g.starts.push(total_faces as u32);
        state.shared = None;
        Ok(state.geometry.starts.len() - 2)
    }

    /// The number of meshes.
    #[getter]
    fn mesh_count(&self) -> PyResult<usize> {
        Ok(self.lock()?.geometry.starts.len() - 1)
    }

    /// The number of triangles, over all meshes.
    #[getter]
    fn triangle_count(&self) -> PyResult<usize> {
        Ok(self.lock()?.geometry.faces.len())
    }

    /// Closest hits. `origins` and `directions` are (N, 3) float32/float64
    /// arrays (or one (3,) row for all rays); `tmin` and `tmax` a number or
    /// one per ray; a hit has `t` in `(tmin, tmax]`, `t` in units of the
    /// direction's length. Returns a dict of arrays of N: `t` (float32,
    /// inf on a miss), `triangle` and `mesh` (int32, -1 on a miss), `u`,
    /// `v` (float32 barycentrics: the point is `(1-u-v) v0 + u v1 + v v2`)
    /// and `normal` (N, 3) (float32, the unit geometric normal
    /// `(v1-v0) x (v2-v0)`, 0 on a miss). `out`: the dict an earlier call
    /// with as many rays returned, whose arrays are written over and which
    /// is returned (no new memory: for queries in a loop).
    #[pyo3(signature = (origins, directions, tmin=None, tmax=None, *, out=None, threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn cast_rays<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let rays = RayArgs::extract(origins, directions, tmin, tmax)?;
        let snap = self.snapshot(py, threads)?;
        let n = rays.n;
        let (dict, arrays) = match out {
            Some(o) if !o.is_none() => {
                let d = o.cast::<PyDict>().map_err(|_| {
                    PyTypeError::new_err("out: expected the dict of arrays cast_rays returned")
                })?;
                (d.clone(), HitArrays::from_dict(d, n)?)
            }
            _ => {
                let a = HitArrays::new(py, n);
                (a.dict(py)?, a)
            }
        };
        {
            let mut w = arrays.borrow()?;
            let (ts, tris, meshes, us, vs, ns) = w.slices()?;
            let view = rays.view();
            let chunks = (
                ts.par_chunks_mut(CHUNK),
                tris.par_chunks_mut(CHUNK),
                meshes.par_chunks_mut(CHUNK),
                us.par_chunks_mut(CHUNK),
                vs.par_chunks_mut(CHUNK),
                ns.par_chunks_mut(3 * CHUNK),
            )
                .into_par_iter();
            self.in_chunks(py, threads, chunks, |first, (t, tri, mesh, u, v, nrm)| {
                let mut rays = [Ray::new(Vec3::ZERO, Vec3::ZERO); CHUNK];
                let mut hits = [None; CHUNK];
                let k = t.len();
                view.fill(first, &mut rays[..k]);
                snap.tree.closest_hits_serial(&rays[..k], &mut hits[..k]);
                for (j, h) in hits[..k].iter().enumerate() {
                    match h {
                        Some(h) => {
                            let (m, local) = Geometry::locate(&snap.starts, h.tri);
                            t[j] = h.t;
                            tri[j] = local;
                            mesh[j] = m;
                            u[j] = h.u;
                            v[j] = h.v;
                        }
                        None => {
                            t[j] = f32::INFINITY;
                            tri[j] = -1;
                            mesh[j] = -1;
                            u[j] = 0.0;
                            v[j] = 0.0;
                        }
                    }
                }
                // The normals in a loop of their own: its loads,
                // scattered over the mesh, overlap.
                for (h, n) in hits[..k].iter().zip(nrm.chunks_exact_mut(3)) {
                    let v = h.map_or(Vec3::ZERO, |h| snap.normal(h.tri));
                    n.copy_from_slice(&v.to_array());
                }
            })?;
        }
        Ok(dict)
    }

    /// Occlusion: True where a triangle is hit with `t` in `(tmin, tmax]`
    /// (arguments as for `cast_rays`). Returns a bool array of N.
    #[pyo3(signature = (origins, directions, tmin=None, tmax=None, *, threads=None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let rays = RayArgs::extract(origins, directions, tmin, tmax)?;
        let snap = self.snapshot(py, threads)?;
        let out = PyArray1::<bool>::zeros(py, rays.n, false);
        {
            // SAFETY: as in `cast_rays`.
            let o = unsafe { out.as_slice_mut()? };
            let view = rays.view();
            self.in_chunks(py, threads, o.par_chunks_mut(CHUNK), |first, o| {
                let mut rays = [Ray::new(Vec3::ZERO, Vec3::ZERO); CHUNK];
                let k = o.len();
                view.fill(first, &mut rays[..k]);
                snap.tree.any_hits_serial(&rays[..k], o);
            })?;
        }
        Ok(out)
    }

    /// The number of triangles each ray crosses with `t` in `(tmin, tmax]`
    /// (arguments as for `cast_rays`): every triangle once, however many
    /// leaves hold it. Returns an int32 array of N.
    #[pyo3(signature = (origins, directions, tmin=None, tmax=None, *, threads=None))]
    fn count_intersections<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<i32>>> {
        let rays = RayArgs::extract(origins, directions, tmin, tmax)?;
        let snap = self.snapshot(py, threads)?;
        let out = PyArray1::<i32>::zeros(py, rays.n, false);
        {
            // SAFETY: as in `cast_rays`.
            let o = unsafe { out.as_slice_mut()? };
            let view = rays.view();
            self.in_chunks(py, threads, o.par_chunks_mut(CHUNK), |first, o| {
                let mut hits = Vec::new();
                for (j, slot) in o.iter_mut().enumerate() {
                    snap.tree.all_hits(&view.ray(first + j), &mut hits);
                    *slot = hits.len().min(i32::MAX as usize) as i32;
                }
            })?;
        }
        Ok(out)
    }

    /// Every hit along each ray with `t` in `(tmin, tmax]` (arguments as
    /// for `cast_rays`), each triangle once, in order of `t` along each ray,
    /// at most `max_hits` per ray (the nearest; None: all). Returns a dict
    /// of arrays of the H hits, ray by ray: `ray` (int64, the ray's index),
    /// `t`, `triangle`, `mesh`, `u`, `v`.
    #[pyo3(signature = (origins, directions, tmin=None, tmax=None, *, max_hits=None, threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn all_hits<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        max_hits: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let max_hits = whole("max_hits", max_hits)?;
        let rays = RayArgs::extract(origins, directions, tmin, tmax)?;
        let snap = self.snapshot(py, threads)?;
        let cap = max_hits.unwrap_or(usize::MAX);
        let view = rays.view();
        let n = rays.n;
        let chunks = (0..n.div_ceil(CHUNK)).into_par_iter();
        let parts: Vec<Vec<(u32, Hit)>> = self.in_chunks(py, threads, chunks, |first, _| {
            let mut hits = Vec::new();
            let mut out = Vec::new();
            for i in first..(first + CHUNK).min(n) {
                snap.tree.all_hits(&view.ray(i), &mut hits);
                out.extend(hits.iter().take(cap).map(|h| (i as u32, *h)));
            }
            out
        })?;
        let total: usize = parts.iter().map(Vec::len).sum();
        let ray = PyArray1::<i64>::zeros(py, total, false);
        let t = PyArray1::<f32>::zeros(py, total, false);
        let tri = PyArray1::<i32>::zeros(py, total, false);
        let mesh = PyArray1::<i32>::zeros(py, total, false);
        let u = PyArray1::<f32>::zeros(py, total, false);
        let v = PyArray1::<f32>::zeros(py, total, false);
        {
            // SAFETY: as in `cast_rays`.
            let (rs, ts, tris, meshes, us, vs) = unsafe {
                (
                    ray.as_slice_mut()?,
                    t.as_slice_mut()?,
                    tri.as_slice_mut()?,
                    mesh.as_slice_mut()?,
                    u.as_slice_mut()?,
                    v.as_slice_mut()?,
                )
            };
            for (k, (i, h)) in parts.iter().flatten().enumerate() {
                let (m, local) = Geometry::locate(&snap.starts, h.tri);
                rs[k] = i64::from(*i);
                ts[k] = h.t;
                tris[k] = local;
                meshes[k] = m;
                us[k] = h.u;
                vs[k] = h.v;
            }
        }
        let d = PyDict::new(py);
        d.set_item("ray", ray)?;
        d.set_item("t", t)?;
        d.set_item("triangle", tri)?;
        d.set_item("mesh", mesh)?;
        d.set_item("u", u)?;
        d.set_item("v", v)?;
        Ok(d)
    }

    /// Inside tests by ray parity, as Open3D's occupancy: from each point,
    /// `samples` rays in fixed directions count the triangles they cross;
    /// a point is inside when most counts are odd. Meant for closed
    /// meshes; a point on the surface may go either way. Returns a bool
    /// array of N.
    #[pyo3(signature = (points, *, samples=3, threads=None))]
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        samples: usize,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        if samples == 0 || samples > DIRECTIONS.len() {
            return Err(PyValueError::new_err(format!(
                "samples: expected 1..={} rays per point, got {samples}",
                DIRECTIONS.len()
            )));
        }
        let points = Rows3::extract(points, "points", false)?;
        let snap = self.snapshot(py, threads)?;
        let out = PyArray1::<bool>::zeros(py, points.len(), false);
        {
            // SAFETY: as in `cast_rays`.
            let o = unsafe { out.as_slice_mut()? };
            let view = points.view();
            let bounds = snap.tree.bounds();
            self.in_chunks(py, threads, o.par_chunks_mut(CHUNK), |first, o| {
                let mut hits = Vec::new();
                for (j, slot) in o.iter_mut().enumerate() {
                    let p = view.get(first + j);
                    // Outside the root cell: outside the mesh.
                    if !(p.cmpge(bounds.min).all() && p.cmple(bounds.max).all()) {
                        continue;
                    }
                    let odd = DIRECTIONS[..samples]
                        .iter()
                        .filter(|&&d| {
                            snap.tree.all_hits(&Ray::new(p, Vec3::from(d)), &mut hits);
                            hits.len() % 2 == 1
                        })
                        .count();
                    *slot = 2 * odd > samples;
                }
            })?;
        }
        Ok(out)
    }

    /// The tree's statistics (built first if needed): node, leaf and
    /// reference counts, depths, memory in bytes, the SAH cost, the
    /// traversal work it predicts, and the builder.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let snap = self.snapshot(py, None)?;
        let value = py.detach(|| match &*snap.tree {
            TriangleAccel::Kd(t) => serde_json::to_value(t.stats()),
            TriangleAccel::Bvh(b) => serde_json::to_value(b.stats()),
        });
        let value = value.map_err(|e| PyRuntimeError::new_err(format!("statistics: {e}")))?;
        let d = PyDict::new(py);
        if let serde_json::Value::Object(map) = value {
            for (k, v) in map {
                match v {
                    serde_json::Value::Number(n) if n.is_u64() => {
                        d.set_item(k, n.as_u64())?;
                    }
                    serde_json::Value::Number(n) => d.set_item(k, n.as_f64())?,
                    other => d.set_item(k, other.to_string())?,
                }
            }
        }
        d.set_item("accel", self.params.kind.name())?;
        d.set_item("builder", self.params.builder_name())?;
        Ok(d)
    }

    fn __repr__(&self) -> PyResult<String> {
        let s = self.lock()?;
        Ok(format!(
            "RayScene({} meshes, {} triangles, accel '{}', builder '{}')",
            s.geometry.starts.len() - 1,
            s.geometry.faces.len(),
            self.params.kind.name(),
            self.params.builder_name()
        ))
    }
}

/// Directions of the inside test's rays: fixed, far from the axes and from
/// each other (no ray along a mesh's grid lines or planes).
const DIRECTIONS: [[f32; 3]; 7] = [
    [0.439_506_45, 0.617_598_6, 0.652_231_6],
    [-0.771_034_4, 0.208_913_9, 0.601_570_9],
    [0.227_461_8, -0.902_128_5, 0.366_675_3],
    [0.581_412_6, 0.393_816_6, -0.711_895_9],
    [-0.284_137_8, -0.470_532_1, -0.835_384_2],
    [0.913_220_5, -0.153_074_8, 0.377_573_7],
    [-0.535_901_8, 0.755_121_5, -0.377_688_4],
];

impl RayScene {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, GeometryState>> {
        self.geometry
            .lock()
            .map_err(|_| PyRuntimeError::new_err("the scene was left broken by an earlier error"))
    }

    /// `each(first, chunk)` for every chunk of a query of [`CHUNK`] rays
    /// (`first`: the index of its first ray), every chunk its own job, on
    /// the scene's threads (or `threads`) without the GIL; the results in
    /// the chunks' order.
    fn in_chunks<C, R>(
        &self,
        py: Python<'_>,
        threads: Option<usize>,
        chunks: C,
        each: impl Fn(usize, C::Item) -> R + Sync + Send,
    ) -> PyResult<Vec<R>>
    where
        C: IndexedParallelIterator,
        R: Send,
    {
        py.detach(|| {
            run_on(threads.or(self.threads), || {
                chunks
                    .with_max_len(1)
                    .enumerate()
                    .map(|(c, chunk)| each(c * CHUNK, chunk))
                    .collect()
            })
        })
    }

    /// The tree (built now, without the GIL, if the meshes changed) and
    /// the arrays a query reads.
    fn snapshot(&self, py: Python<'_>, threads: Option<usize>) -> PyResult<Snapshot> {
        let threads = threads.or(self.threads);
        py.detach(|| {
            let mut state = self.lock()?;
            if let Some(snap) = &state.shared {
                return Ok(snap.clone());
            }
            let g = &state.geometry;
            let tris = Triangle::from_indexed(&g.positions, &g.faces);
            let normals: Arc<[Vec3]> = tris
                .iter()
                .map(|t| t.normal().normalize_or_zero())
                .collect();
            let params = &self.params;
            let tree = Arc::new(run_on(threads, || TriangleAccel::build(tris, params))?);
            let snap = Snapshot {
                tree,
                normals,
                starts: g.starts.as_slice().into(),
            };
            state.shared = Some(snap.clone());
            Ok(snap)
        })
    }
}

impl Snapshot {
    /// The unit geometric normal of global face `f`.
    #[inline(always)]
    fn normal(&self, f: u32) -> Vec3 {
        self.normals[f as usize]
    }
}

/// The arrays of `cast_rays`'s answers.
struct HitArrays<'py> {
    t: Bound<'py, PyArray1<f32>>,
    triangle: Bound<'py, PyArray1<i32>>,
    mesh: Bound<'py, PyArray1<i32>>,
    u: Bound<'py, PyArray1<f32>>,
    v: Bound<'py, PyArray1<f32>>,
    normal: Bound<'py, PyArray2<f32>>,
}

/// [`HitArrays`] held for writing.
struct HitWriter<'py> {
    t: PyReadwriteArray1<'py, f32>,
    triangle: PyReadwriteArray1<'py, i32>,
    mesh: PyReadwriteArray1<'py, i32>,
    u: PyReadwriteArray1<'py, f32>,
    v: PyReadwriteArray1<'py, f32>,
    normal: PyReadwriteArray2<'py, f32>,
}

/// The slices of a [`HitWriter`]: t, triangle, mesh, u, v, normal.
type HitSlices<'a> = (
    &'a mut [f32],
    &'a mut [i32],
    &'a mut [i32],
    &'a mut [f32],
    &'a mut [f32],
    &'a mut [f32],
);

impl<'py> HitArrays<'py> {
    /// New arrays for `n` rays.
    fn new(py: Python<'py>, n: usize) -> Self {
        // Uninitialised: every element is written by the query, and zeroed
        // arrays would be written twice.
        // SAFETY: the arrays are written in full before they are returned.
        unsafe {
            HitArrays {
                t: PyArray1::new(py, n, false),
                triangle: PyArray1::new(py, n, false),
                mesh: PyArray1::new(py, n, false),
                u: PyArray1::new(py, n, false),
                v: PyArray1::new(py, n, false),
                normal: PyArray2::new(py, [n, 3], false),
            }
        }
    }

    /// The arrays of `d` (a dict `cast_rays` returned), checked to answer
    /// `n` rays.
    fn from_dict(d: &Bound<'py, PyDict>, n: usize) -> PyResult<Self> {
        fn get<'py, A: pyo3::PyTypeCheck>(
            d: &Bound<'py, PyDict>,
            key: &str,
            what: &str,
        ) -> PyResult<Bound<'py, A>> {
            let item = d
                .get_item(key)?
                .ok_or_else(|| PyValueError::new_err(format!("out: no '{key}' array")))?;
            item.cast_into::<A>()
                .map_err(|_| PyValueError::new_err(format!("out['{key}']: expected {what}")))
        }
        let a = HitArrays {
            t: get(d, "t", "a float32 array")?,
            triangle: get(d, "triangle", "an int32 array")?,
            mesh: get(d, "mesh", "an int32 array")?,
            u: get(d, "u", "a float32 array")?,
            v: get(d, "v", "a float32 array")?,
            normal: get(d, "normal", "a float32 array of shape (N, 3)")?,
        };
        for (key, shape) in [
            ("t", a.t.shape()),
            ("triangle", a.triangle.shape()),
            ("mesh", a.mesh.shape()),
            ("u", a.u.shape()),
            ("v", a.v.shape()),
            ("normal", a.normal.shape()),
        ] {
            let (want, got) = if key == "normal" {
                (format!("({n}, 3)"), format!("({}, {})", shape[0], shape[1]))
            } else {
                (format!("({n},)"), format!("({},)", shape[0]))
            };
            if want != got {
                return Err(PyValueError::new_err(format!(
                    "out['{key}']: expected shape {want} (the rays of this call), got {got}"
                )));
            }
        }
        Ok(a)
    }

    /// A dict of the arrays, by name.
    fn dict(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("t", &self.t)?;
        d.set_item("triangle", &self.triangle)?;
        d.set_item("mesh", &self.mesh)?;
        d.set_item("u", &self.u)?;
        d.set_item("v", &self.v)?;
        d.set_item("normal", &self.normal)?;
        Ok(d)
    }

    /// The arrays held for writing: refused if one is read-only, or in
    /// use elsewhere (an input of the same call, another of the arrays).
    fn borrow(&self) -> PyResult<HitWriter<'py>> {
        fn w<A>(r: Result<A, numpy::BorrowError>, key: &str) -> PyResult<A> {
            r.map_err(|e| PyValueError::new_err(format!("out['{key}']: cannot be written ({e})")))
        }
        Ok(HitWriter {
            t: w(self.t.try_readwrite(), "t")?,
            triangle: w(self.triangle.try_readwrite(), "triangle")?,
            mesh: w(self.mesh.try_readwrite(), "mesh")?,
            u: w(self.u.try_readwrite(), "u")?,
            v: w(self.v.try_readwrite(), "v")?,
            normal: w(self.normal.try_readwrite(), "normal")?,
        })
    }
}

impl HitWriter<'_> {
    /// The arrays as slices: refused unless each is C-contiguous.
    fn slices(&mut self) -> PyResult<HitSlices<'_>> {
        fn s<'a, T>(
            r: Result<&'a mut [T], numpy::AsSliceError>,
            key: &str,
        ) -> PyResult<&'a mut [T]> {
            r.map_err(|_| {
                PyValueError::new_err(format!("out['{key}']: expected a C-contiguous array"))
            })
        }
        if !self.normal.is_c_contiguous() {
            return Err(PyValueError::new_err(
                "out['normal']: expected a C-contiguous array",
            ));
        }
        let normal = s(self.normal.as_slice_mut(), "normal")?;
        Ok((
            s(self.t.as_slice_mut(), "t")?,
            s(self.triangle.as_slice_mut(), "triangle")?,
            s(self.mesh.as_slice_mut(), "mesh")?,
            s(self.u.as_slice_mut(), "u")?,
            s(self.v.as_slice_mut(), "v")?,
            normal,
        ))
    }
}

/// The rays of a query, as given.
struct RayArgs<'py> {
    origins: Rows3<'py>,
    directions: Rows3<'py>,
    tmin: PerRay<'py>,
    tmax: PerRay<'py>,
    n: usize,
}

impl<'py> RayArgs<'py> {
    fn extract(
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let origins = Rows3::extract(origins, "origins", true)?;
        let directions = Rows3::extract(directions, "directions", true)?;
        let (no, nd) = (origins.len(), directions.len());
        let n = match (no, nd) {
            _ if no == nd => no,
            (1, _) => nd,
            (_, 1) => no,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "origins and directions: {no} and {nd} rows (give as many of each, or one of either)"
                )))
            }
        };
        let per_ray = |obj: Option<&Bound<'py, PyAny>>, name, default| match obj {
            None => Ok(PerRay::One(default)),
            Some(o) if o.is_none() => Ok(PerRay::One(default)),
            Some(o) => PerRay::extract(o, name, n),
        };
        let tmin = per_ray(tmin, "tmin", 0.0)?;
        let tmax = per_ray(tmax, "tmax", f32::INFINITY)?;
        Ok(RayArgs {
            origins,
            directions,
            tmin,
            tmax,
            n,
        })
    }

    fn view(&self) -> RayView<'_> {
        RayView {
            origins: self.origins.view(),
            directions: self.directions.view(),
            one_origin: self.origins.len() == 1,
            one_direction: self.directions.len() == 1,
            tmin: self.tmin.view(),
            tmax: self.tmax.view(),
        }
    }
}

/// The rays of a query, readable from any thread.
#[derive(Clone, Copy)]
struct RayView<'a> {
    origins: Rows3View<'a>,
    directions: Rows3View<'a>,
    one_origin: bool,
    one_direction: bool,
    tmin: PerRayView<'a>,
    tmax: PerRayView<'a>,
}

impl RayView<'_> {
    /// Ray `i`. A negative or NaN `tmin`, or a NaN `tmax`, makes a ray
    /// that hits nothing, as a zero or non-finite direction does.
    #[inline(always)]
    fn ray(&self, i: usize) -> Ray {
        Ray::with_interval(
            self.origins.get(if self.one_origin { 0 } else { i }),
            self.directions.get(if self.one_direction { 0 } else { i }),
            self.tmin.get(i),
            self.tmax.get(i),
        )
    }

    /// Rays `start..start + out.len()`.
    #[inline(always)]
    fn fill(&self, start: usize, out: &mut [Ray]) {
        let k = out.len();
        // The common case, C-contiguous float32 rows and intervals (one
        // for all rays or contiguous float32 arrays), read without a
        // branch per ray.
        if let (Rows3View::Flat(o), Rows3View::Flat(d), false, false, Some(tmin), Some(tmax)) = (
            self.origins,
            self.directions,
            self.one_origin,
            self.one_direction,
            self.tmin.run(start, k),
            self.tmax.run(start, k),
        ) {
            let o = &o[3 * start..3 * (start + k)];
            let d = &d[3 * start..3 * (start + k)];
            let rays = out.iter_mut().zip(o.chunks_exact(3)).zip(d.chunks_exact(3));
            let at = |r: Result<f32, &[f32]>, j: usize| match r {
                Ok(v) => v,
                Err(s) => s[j],
            };
            match (tmin, tmax) {
                (Ok(tmin), Ok(tmax)) => {
                    for ((r, o), d) in rays {
                        *r = Ray::with_interval(
                            Vec3::from_slice(o),
                            Vec3::from_slice(d),
                            tmin,
                            tmax,
                        );
                    }
                }
                (tmin, tmax) => {
                    for (j, ((r, o), d)) in rays.enumerate() {
                        *r = Ray::with_interval(
                            Vec3::from_slice(o),
                            Vec3::from_slice(d),
                            at(tmin, j),
                            at(tmax, j),
                        );
                    }
                }
            }
            return;
        }
        for (j, r) in out.iter_mut().enumerate() {
            *r = self.ray(start + j);
        }
    }
}

/// `value` as a count (None stays None): what is not a whole number is a
/// `TypeError`, a negative or too large one a `ValueError`, each naming
/// the argument `name` (rather than the conversion's `OverflowError`).
fn whole(name: &str, value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(v) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if v.is_instance_of::<pyo3::types::PyBool>() || !v.hasattr("__index__")? {
        return Err(PyTypeError::new_err(format!(
            "{name} must be a whole number, not {}",
            v.get_type().name()?
        )));
    }
    let n = v.call_method0("__index__")?;
    if n.lt(0)? {
        return Err(PyValueError::new_err(format!(
            "{name} must be at least 0, not {n}"
        )));
    }
    n.extract::<usize>().map(Some).map_err(|_| {
        PyValueError::new_err(format!("{name} must be at most {}, not {n}", usize::MAX))
    })
}
