//! Bindings of the linearised and periodic 3-D attitude: convert, call the core with the GIL
//! released, convert.

use librate_core::attitude::{collinear_equilibrium, RigidBody};
use librate_core::attitude::{correct_attitudes_3d, correct_attitudes_3d_across, Start3d, StartAcross3d};
use numpy::ndarray::{Array2, Array3};
use numpy::IntoPyArray;
use pyo3::prelude::*;

use crate::convert::matrix;
use crate::errors::invalid;
use crate::options::{AttitudeCases3D, CorrectorOptions3D};
use crate::interrupt::interruptible;
use crate::to_py;

/// The linearised attitude at a collinear point (librate_core::attitude::collinear_equilibrium).
#[pyclass(frozen, get_all, name = "LinearisedEquilibrium", module = "librate._core")]
pub struct PyLinearisedEquilibrium {
    /// The 13-state equilibrium (orbit, quaternion scalar last, rate), (13,).
    pub state: Py<PyAny>,
    /// d(theta, dw)/dt of the small rotation theta and the rate change dw, (6, 6).
    pub matrix: Py<PyAny>,
    /// The tidal coefficient sigma = (1 - mu)/r1^3 + mu/r2^3 at the point.
    pub sigma: f64,
    /// Max |d state / dt| at the equilibrium (zero up to rounding).
    pub residual: f64,
}

#[pymethods]
impl PyLinearisedEquilibrium {
    fn __repr__(&self) -> String {
        format!("LinearisedEquilibrium(sigma={}, residual={:e})", self.sigma, self.residual)
    }
}

/// The outcome of a batch of 3-D periodic-attitude corrections, one row per candidate
/// (librate_core::attitude::correct_attitudes_3d).
#[pyclass(frozen, get_all, name = "CorrectionBatch3D", module = "librate._core")]
pub struct PyCorrectionBatch3D {
    /// Initial attitude relative to the synodic frame, scalar last, (n, 4).
    pub q0: Py<PyAny>,
    /// Initial inertial rate in body axes (rad/TU), (n, 3).
    pub w0: Py<PyAny>,
    /// (rotation vector of R(0)^T R(KT), w(KT) - w0), (n, 6).
    pub residual: Py<PyAny>,
    pub residual_norm: Py<PyAny>,
    pub iterations: Py<PyAny>,
    /// Why each candidate stopped ("converged", "max_iterations", ...).
    pub reason: Vec<&'static str>,
    /// The 6x6 attitude monodromy, (n, 6, 6).
    pub monodromy: Py<PyAny>,
}

#[pymethods]
impl PyCorrectionBatch3D {
    fn __len__(&self) -> usize {
        self.reason.len()
    }
    fn __repr__(&self) -> String {
        let c = self.reason.iter().filter(|r| **r == "converged").count();
        format!("CorrectionBatch3D(n={}, converged={c})", self.reason.len())
    }
}

/// The linearised attitude of a body held at a collinear point with its principal axes on the
/// synodic axes.
#[pyfunction]
fn attitude_equilibrium(py: Python<'_>, mu: f64, inertia: [f64; 3], point: u8, q0: [f64; 4]) -> PyResult<PyLinearisedEquilibrium> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let e = py.detach(|| collinear_equilibrium(mu, body, point, &q0)).map_err(to_py)?;
    Ok(PyLinearisedEquilibrium {
        state: e.state.to_vec().into_pyarray(py).into_any().unbind(),
        matrix: matrix(py, &e.matrix).unbind(),
        sigma: e.sigma,
        residual: e.residual,
    })
}

/// Batched 3-D periodic-attitude corrector: the cases' guesses q (n x 4, scalar last) and w
/// (n x 3) along the orbit started at `orbit0`, closure over `t_final` (K T; options.half: the
/// mirror-symmetric half-period form).
#[pyfunction]
#[pyo3(signature = (mu, inertia, orbit0, t_final, cases, *, options))]
fn attitude_correct_3d<'py>(
    py: Python<'py>,
    mu: f64,
    inertia: [f64; 3],
    orbit0: [f64; 6],
    t_final: f64,
    cases: PyRef<'py, AttitudeCases3D>,
    options: PyRef<'py, CorrectorOptions3D>,
) -> PyResult<PyCorrectionBatch3D> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let starts: Vec<Start3d> = cases.q.iter().zip(&cases.w).map(|(&q, &w)| Start3d { q, w }).collect();
    let opts = options.core();
    let out = interruptible(py, || correct_attitudes_3d(mu, body, &orbit0, t_final, &starts, &opts))?;
    let n = out.len();
    Ok(PyCorrectionBatch3D {
        q0: Array2::from_shape_fn((n, 4), |(i, k)| out[i].q0[k]).into_pyarray(py).into_any().unbind(),
        w0: Array2::from_shape_fn((n, 3), |(i, k)| out[i].w0[k]).into_pyarray(py).into_any().unbind(),
        residual: Array2::from_shape_fn((n, 6), |(i, k)| out[i].residual[k]).into_pyarray(py).into_any().unbind(),
        residual_norm: out.iter().map(|c| c.residual_norm).collect::<Vec<_>>().into_pyarray(py).into_any().unbind(),
        iterations: out.iter().map(|c| c.iterations as i64).collect::<Vec<_>>().into_pyarray(py).into_any().unbind(),
        reason: out.iter().map(|c| c.reason.as_str()).collect(),
        monodromy: Array3::from_shape_fn((n, 6, 6), |(i, r, c)| out[i].monodromy[r][c]).into_pyarray(py).into_any().unbind(),
    })
}

/// The outcome of a batch of bordered 3-D corrections across an orbit family, one row per
/// candidate (librate_core::attitude::correct_attitudes_3d_across).
#[pyclass(frozen, get_all, name = "CorrectionAcross3D", module = "librate._core")]
pub struct PyCorrectionAcross3D {
    /// Initial attitude (n, 4), scalar last, and inertial rate in body axes (n, 3).
    pub q0: Py<PyAny>,
    pub w0: Py<PyAny>,
    /// The family member at the final point: initial state (n, 6) and period (n,), TU.
    pub orbit0: Py<PyAny>,
    pub period: Py<PyAny>,
    /// (rotation vector of R(0)^T R(KT), w(KT) - w0, a . x - b), (n, 7).
    pub residual: Py<PyAny>,
    pub residual_norm: Py<PyAny>,
    pub iterations: Py<PyAny>,
    pub reason: Vec<&'static str>,
    /// The 6x6 attitude monodromy, (n, 6, 6), and d F / d T of the six closure rows, (n, 6).
    pub monodromy: Py<PyAny>,
    pub dparam: Py<PyAny>,
}

#[pymethods]
impl PyCorrectionAcross3D {
    fn __len__(&self) -> usize {
        self.reason.len()
    }
    fn __repr__(&self) -> String {
        let c = self.reason.iter().filter(|r| **r == "converged").count();
        format!("CorrectionAcross3D(n={}, converged={c})", self.reason.len())
    }
}

/// Bordered 3-D periodic-attitude corrector across an x-z-symmetric orbit family (the orbit
/// period freed): the cases' guesses q (n x 4), w (n x 3), periods (n,) and conditions a (n x 7)
/// . (theta, w0, T) = b (n,); the family through the member `member0` of period `period0`.
#[pyfunction]
#[pyo3(signature = (mu, inertia, member0, period0, n_periods, cases, *, options))]
fn attitude_correct_3d_across<'py>(
    py: Python<'py>,
    mu: f64,
    inertia: [f64; 3],
    member0: [f64; 6],
    period0: f64,
    n_periods: usize,
    cases: PyRef<'py, AttitudeCases3D>,
    options: PyRef<'py, CorrectorOptions3D>,
) -> PyResult<PyCorrectionAcross3D> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let Some((period, a, b)) = &cases.across else {
        return Err(invalid("invalid argument `cases`: the correction across a family needs each case's period, a and b"));
    };
    let n = cases.q.len();
    let starts: Vec<StartAcross3d> = (0..n).map(|i| StartAcross3d { q: cases.q[i], w: cases.w[i], period: period[i], a: a[i], b: b[i] }).collect();
    let (opts, max_period_step) = (options.core(), options.max_period_step);
    let out = interruptible(py, || correct_attitudes_3d_across(mu, body, &member0, period0, n_periods, &starts, max_period_step, &opts))?;
    Ok(PyCorrectionAcross3D {
        q0: Array2::from_shape_fn((n, 4), |(i, k)| out[i].q0[k]).into_pyarray(py).into_any().unbind(),
        w0: Array2::from_shape_fn((n, 3), |(i, k)| out[i].w0[k]).into_pyarray(py).into_any().unbind(),
        orbit0: Array2::from_shape_fn((n, 6), |(i, k)| out[i].orbit0[k]).into_pyarray(py).into_any().unbind(),
        period: out.iter().map(|c| c.period).collect::<Vec<_>>().into_pyarray(py).into_any().unbind(),
        residual: Array2::from_shape_fn((n, 7), |(i, k)| out[i].residual[k]).into_pyarray(py).into_any().unbind(),
        residual_norm: out.iter().map(|c| c.residual_norm).collect::<Vec<_>>().into_pyarray(py).into_any().unbind(),
        iterations: out.iter().map(|c| c.iterations as i64).collect::<Vec<_>>().into_pyarray(py).into_any().unbind(),
        reason: out.iter().map(|c| c.reason.as_str()).collect(),
        monodromy: Array3::from_shape_fn((n, 6, 6), |(i, r, c)| out[i].monodromy[r][c]).into_pyarray(py).into_any().unbind(),
        dparam: Array2::from_shape_fn((n, 6), |(i, k)| out[i].dparam[k]).into_pyarray(py).into_any().unbind(),
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLinearisedEquilibrium>()?;
    m.add_class::<PyCorrectionBatch3D>()?;
    m.add_class::<PyCorrectionAcross3D>()?;
    m.add_function(wrap_pyfunction!(attitude_correct_3d, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_correct_3d_across, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_equilibrium, m)?)?;
    Ok(())
}
