//! `sahara._sahara`: the native half of the `sahara` Python package
//! (`python/sahara/` is the other). Ray queries over triangle meshes on
//! numpy arrays ([`rays`]), and scenes loaded, rendered and written as the
//! command line does ([`render`]). Every query and render releases the GIL
//! and runs on Sahara's threads; every error is a Python exception.

mod arrays;
mod pool;
mod rays;

use pyo3::prelude::*;

/// The native module: `RayScene`, and the version.
#[pymodule]
fn _sahara(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<rays::RayScene>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
