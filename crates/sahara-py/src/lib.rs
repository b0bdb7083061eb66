//! `sahara._sahara`: the native half of the `sahara` Python package
//! (`python/sahara/` is the other). Ray queries over triangle meshes on
//! numpy arrays ([`rays`]), and scenes loaded, rendered and written as the
//! command line does ([`render`]). Every query and render releases the GIL
//! and runs on Sahara's threads; every error is a Python exception.

mod arrays;
mod pool;
mod rays;
mod render;

use pyo3::prelude::*;

/// The native module: `RayScene`; `Scene`, `load`, `cornell_box`,
/// `render`, `write`, `names`, `read_mesh`, `FormatError`; the version.
#[pymodule]
fn _sahara(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<rays::RayScene>()?;
    m.add_class::<render::Scene>()?;
    m.add_function(wrap_pyfunction!(render::load, m)?)?;
    m.add_function(wrap_pyfunction!(render::cornell_box, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::write, m)?)?;
    m.add_function(wrap_pyfunction!(render::names, m)?)?;
    m.add_function(wrap_pyfunction!(render::read_mesh, m)?)?;
    m.add("FormatError", m.py().get_type::<render::FormatError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
