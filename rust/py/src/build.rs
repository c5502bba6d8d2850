//! What this build of the extension is and which SIMD level its kernels run at
//! (`librate.build_info()`); converts only, the choice lives in `librate_core::simd`.

use librate_core::simd;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::to_py;

/// The build and the SIMD levels: simd_known (levels of this architecture), simd_available
/// (those the CPU supports), simd_active (raises ValueError if LIBRATE_SIMD is invalid),
/// version, profile (the cargo profile built with: "dev", "release" or "dist"; rust/py/build.rs),
/// debug_assertions (on in dev builds), target_arch.
#[pyfunction]
fn build_info(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let active = simd::active().map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("simd_known", simd::known().iter().map(|l| l.name()).collect::<Vec<_>>())?;
    d.set_item("simd_available", simd::available().iter().map(|l| l.name()).collect::<Vec<_>>())?;
    d.set_item("simd_active", active.name())?;
    d.set_item("version", env!("CARGO_PKG_VERSION"))?;
    d.set_item("profile", option_env!("LIBRATE_PROFILE").unwrap_or("unknown"))?;
    d.set_item("debug_assertions", cfg!(debug_assertions))?;
    d.set_item("target_arch", std::env::consts::ARCH)?;
    let pool = librate_core::threads::pool_info().map_err(to_py)?;
    d.set_item("threads", pool.threads)?;
    d.set_item("threads_started", pool.started)?;
    d.set_item("threads_binding", pool.binding.name())?;
    d.set_item("threads_cpus", pool.cpus.clone())?;
    d.set_item("threads_bound", pool.bound())?;
    Ok(d)
}

/// Make `level` (a LIBRATE_SIMD value) the active SIMD level of this process; returns its name.
#[pyfunction]
fn simd_set_active(level: &str) -> PyResult<&'static str> {
    simd::set_active(level).map(|l| l.name()).map_err(to_py)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(build_info, m)?)?;
    m.add_function(wrap_pyfunction!(simd_set_active, m)?)?;
    Ok(())
}
