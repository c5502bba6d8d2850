//! Bindings of the linearised and periodic 3-D attitude: convert, call the core with the GIL
//! released, convert.

use librate_core::attitude::{collinear_equilibrium, RigidBody};
use librate_core::periodic::{correct_attitudes_3d, Options3d, Start3d};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
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

/// Batched 3-D periodic-attitude corrector: guesses q (n x 4, scalar last) and w (n x 3) along
/// the orbit started at `orbit0`, closure over `t_final` (K T; `half`: the mirror-symmetric
/// half-period form). dict of arrays (q0, w0, residual,
/// residual_norm, iterations, reason, monodromy n x 6 x 6).
#[pyfunction]
#[pyo3(signature = (mu, inertia, orbit0, t_final, q, w, *, tol, max_iter, rtol, atol, max_halvings=10, primaries=[true, true], threads=None, half=false))]
fn attitude_correct_3d<'py>(
    py: Python<'py>,
    mu: f64,
    inertia: [f64; 3],
    orbit0: [f64; 6],
    t_final: f64,
    q: PyReadonlyArray2<'py, f64>,
    w: PyReadonlyArray2<'py, f64>,
    tol: f64,
    max_iter: usize,
    rtol: f64,
    atol: f64,
    max_halvings: u32,
    primaries: [bool; 2],
    threads: Option<usize>,
    half: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let (qa, wa) = (q.as_array(), w.as_array());
    if qa.ncols() != 4 || wa.ncols() != 3 || qa.nrows() != wa.nrows() {
        return Err(PyValueError::new_err(format!("invalid argument `guess`: need q of shape (n, 4) and w of shape (n, 3), got {:?} and {:?}", qa.shape(), wa.shape())));
    }
    let starts: Vec<Start3d> = (0..qa.nrows()).map(|i| Start3d { q: std::array::from_fn(|k| qa[(i, k)]), w: std::array::from_fn(|k| wa[(i, k)]) }).collect();
    let opts = Options3d { tol, max_iter, max_halvings, rtol, atol, threads, primaries, half, ..Options3d::default() };
    let out = py.detach(|| correct_attitudes_3d(mu, body, &orbit0, t_final, &starts, &opts)).map_err(to_py)?;
    let n = out.len();
    let d = PyDict::new(py);
    d.set_item("q0", Array2::from_shape_fn((n, 4), |(i, k)| out[i].q0[k]).into_pyarray(py))?;
    d.set_item("w0", Array2::from_shape_fn((n, 3), |(i, k)| out[i].w0[k]).into_pyarray(py))?;
    d.set_item("residual", Array2::from_shape_fn((n, 6), |(i, k)| out[i].residual[k]).into_pyarray(py))?;
    d.set_item("residual_norm", out.iter().map(|c| c.residual_norm).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("iterations", out.iter().map(|c| c.iterations as i64).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("reason", out.iter().map(|c| c.reason.as_str()).collect::<Vec<_>>())?;
    d.set_item("monodromy", Array3::from_shape_fn((n, 6, 6), |(i, r, c)| out[i].monodromy[r][c]).into_pyarray(py))?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(attitude_correct_3d, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_equilibrium, m)?)?;
    Ok(())
}
