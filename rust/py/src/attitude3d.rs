//! Bindings of the linearised and periodic 3-D attitude: convert, call the core with the GIL
//! released, convert.

use librate_core::attitude::{collinear_equilibrium, RigidBody};
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::to_py;

fn mat<'py, const R: usize, const C: usize>(py: Python<'py>, m: &[[f64; C]; R]) -> Bound<'py, PyAny> {
    Array2::from_shape_fn((R, C), |(i, j)| m[i][j]).into_pyarray(py).into_any()
}

/// The linearised attitude of a body held at a collinear point with its principal axes on the
/// synodic axes: dict(state (13), matrix (6x6, d(theta, dw)/dt), sigma, residual).
#[pyfunction]
fn attitude_equilibrium<'py>(py: Python<'py>, mu: f64, inertia: [f64; 3], point: u8, q0: [f64; 4]) -> PyResult<Bound<'py, PyDict>> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let e = py.detach(|| collinear_equilibrium(mu, body, point, &q0)).map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("state", e.state.to_vec().into_pyarray(py))?;
    d.set_item("matrix", mat(py, &e.matrix))?;
    d.set_item("sigma", e.sigma)?;
    d.set_item("residual", e.residual)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(attitude_equilibrium, m)?)?;
    Ok(())
}
