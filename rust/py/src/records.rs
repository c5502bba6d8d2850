//! Typed records returned by the CR3BP bindings of `lib.rs` (propagation, symmetric and multiple
//! shooting): frozen classes holding NumPy arrays (moved from Rust without copies) and scalars.

use librate_core::orbit::Evaluation;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;

/// Integrator counters of one run.
#[pyclass(frozen, get_all, name = "Stats", module = "librate._core")]
#[derive(Clone, Copy)]
pub struct PyStats {
    /// Steps accepted.
    pub accepted: usize,
    /// Steps rejected by the error controller.
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
}

impl From<librate_core::integrate::Stats> for PyStats {
    fn from(s: librate_core::integrate::Stats) -> Self {
        Self { accepted: s.accepted, rejected: s.rejected, rhs_evals: s.rhs_evals }
    }
}

#[pymethods]
impl PyStats {
    fn __repr__(&self) -> String {
        format!("Stats(accepted={}, rejected={}, rhs_evals={})", self.accepted, self.rejected, self.rhs_evals)
    }
}

/// One located event of `propagate`.
#[pyclass(frozen, get_all, name = "EventHit", module = "librate._core")]
pub struct PyEventHit {
    /// Index of the event in the `events` list.
    pub index: usize,
    /// Time of the hit.
    pub t: f64,
    /// State at the hit, (6,).
    pub y: Py<PyAny>,
    /// STM from t0 to the hit (6, 6), or None when not propagated.
    pub stm: Option<Py<PyAny>>,
}

#[pymethods]
impl PyEventHit {
    fn __repr__(&self) -> String {
        format!("EventHit(index={}, t={})", self.index, self.t)
    }
}

/// The outcome of `propagate`.
#[pyclass(frozen, get_all, name = "Trajectory", module = "librate._core")]
pub struct PyTrajectory {
    /// Output times, (n,).
    pub t: Py<PyAny>,
    /// States at the output times, (n, 6).
    pub y: Py<PyAny>,
    /// Time the integration stopped at.
    pub t_final: f64,
    /// State at `t_final`, (6,).
    pub y_final: Py<PyAny>,
    /// STM from t0 to `t_final` (6, 6), or None when not asked.
    pub stm: Option<Py<PyAny>>,
    /// The located events, in time order.
    pub events: Py<pyo3::types::PyTuple>,
    /// "completed", "event" (a terminal event stopped it) or "collision".
    pub status: &'static str,
    /// Index of the terminal event when status == "event", else None.
    pub event_index: Option<usize>,
    /// The CollisionError when status == "collision", else None.
    pub collision: Option<Py<PyAny>>,
    /// Integrator counters.
    pub stats: PyStats,
}

#[pymethods]
impl PyTrajectory {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.t.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Trajectory(n={}, t_final={}, status='{}', events={}, stm={})",
            self.__len__(py)?,
            self.t_final,
            self.status,
            self.events.bind(py).len(),
            if self.stm.is_some() { "True" } else { "False" }
        ))
    }
}

/// The outcome of `propagate_many`: arrays over the members; failed members have NaN rows.
#[pyclass(frozen, get_all, name = "BatchResult", module = "librate._core")]
pub struct PyBatchResult {
    /// Final states, (n, 6).
    pub y: Py<PyAny>,
    /// Final STMs (n, 6, 6), or None when not asked.
    pub stm: Option<Py<PyAny>>,
    /// The member completed, bool (n,).
    pub ok: Py<PyAny>,
    /// Per member: 0 completed, 1 / 2 collision with primary 1 / 2, 3 another error; uint8 (n,).
    pub status: Py<PyAny>,
    /// The error of each failed member (IntegrationError, CollisionError, ...), by index.
    pub errors: Py<pyo3::types::PyDict>,
    /// Accepted, rejected steps and RHS evaluations per member, uint64 (n, 3).
    pub stats: Py<PyAny>,
}

#[pymethods]
impl PyBatchResult {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.ok.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "BatchResult(n={}, failed={}, stm={})",
            self.__len__(py)?,
            self.errors.bind(py).len(),
            if self.stm.is_some() { "True" } else { "False" }
        ))
    }
}

/// The half-period shooting functions of an x-z-symmetric orbit at p = (x0, z0, vy0) and their
/// derivatives (librate_core::orbit::Evaluation).
#[pyclass(frozen, get_all, name = "ShootingEvaluation", module = "librate._core")]
pub struct PyShootingEvaluation {
    /// The unknowns (x0, z0, vy0), (3,).
    pub p: Py<PyAny>,
    /// (xdot, zdot) at the half-period crossing, (2,).
    pub cond: Py<PyAny>,
    /// d cond / d p, (2, 3) (rows xdot, zdot; columns x0, z0, vy0).
    pub dcond: Py<PyAny>,
    /// Time of the half-period crossing.
    pub half_period: f64,
    /// d (T/2) / d p, (3,).
    pub dhalf: Py<PyAny>,
    /// Jacobi constant.
    pub jacobi: f64,
    /// d C / d p, (3,).
    pub djacobi: Py<PyAny>,
    /// State at the half-period crossing, (6,).
    pub crossing: Py<PyAny>,
    /// The monodromy from the half-period STM, S Phi(T/2)^-1 S Phi(T/2) (6, 6) (exact at a
    /// periodic orbit); None when Phi(T/2) is singular.
    pub monodromy: Option<Py<PyAny>>,
}

impl PyShootingEvaluation {
    pub fn new(py: Python<'_>, e: &Evaluation) -> Self {
        let arr = |v: &[f64]| v.to_vec().into_pyarray(py).into_any().unbind();
        Self {
            p: arr(&e.p),
            cond: arr(&e.cond),
            dcond: Array2::from_shape_fn((2, 3), |(i, j)| e.dcond[i][j]).into_pyarray(py).into_any().unbind(),
            half_period: e.half_period,
            dhalf: arr(&e.dhalf),
            jacobi: e.jacobi,
            djacobi: arr(&e.djacobi),
            crossing: arr(&e.crossing),
            monodromy: e.monodromy().map(|m| Array2::from_shape_fn((6, 6), |(i, j)| m[i][j]).into_pyarray(py).into_any().unbind()),
        }
    }
}

#[pymethods]
impl PyShootingEvaluation {
    fn __repr__(&self) -> String {
        format!("ShootingEvaluation(half_period={}, jacobi={})", self.half_period, self.jacobi)
    }
}

/// The outcome of `symmetric_correct`: a corrected x-z-symmetric periodic orbit.
#[pyclass(frozen, get_all, name = "SymmetricOrbit", module = "librate._core")]
pub struct PySymmetricOrbit {
    /// Initial state on the x-z plane, (6,).
    pub state0: Py<PyAny>,
    /// Period.
    pub period: f64,
    /// Jacobi constant.
    pub jacobi: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// Max-norm of the residual after the last iteration.
    pub residual: f64,
    /// The shooting functions at the solution.
    pub evaluation: Py<PyShootingEvaluation>,
}

#[pymethods]
impl PySymmetricOrbit {
    fn __repr__(&self) -> String {
        format!("SymmetricOrbit(period={}, jacobi={}, iterations={}, residual={:e})", self.period, self.jacobi, self.iterations, self.residual)
    }
}

/// The outcome of `multiple_shooting`: a corrected periodic orbit as its patch states.
#[pyclass(frozen, get_all, name = "MultipleShooting", module = "librate._core")]
pub struct PyMultipleShooting {
    /// Corrected patch states, (n, 6), equally spaced in time over the period.
    pub patches: Py<PyAny>,
    /// Period.
    pub period: f64,
    /// Jacobi constant.
    pub jacobi: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// Max-norm of the residual after the last iteration.
    pub residual: f64,
}

#[pymethods]
impl PyMultipleShooting {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "MultipleShooting(patches={}, period={}, jacobi={}, iterations={}, residual={:e})",
            self.patches.bind(py).len()?,
            self.period,
            self.jacobi,
            self.iterations,
            self.residual
        ))
    }
}

/// The constants of a CR3BP system (`system_preset`, `system_validate`), validated by the core.
#[pyclass(frozen, get_all, name = "SystemConstants", module = "librate._core")]
pub struct PySystemConstants {
    /// The system's name.
    pub name: String,
    /// Mass ratio m2 / (m1 + m2).
    pub mu: f64,
    /// Length unit (km): the primaries' distance.
    pub lu_km: f64,
    /// Time unit (s): 1 / mean motion.
    pub tu_s: f64,
    /// Radius of the larger primary (km; 0 for a point).
    pub r1_km: f64,
    /// Radius of the smaller primary (km; 0 for a point).
    pub r2_km: f64,
}

impl From<librate_core::cr3bp::SystemConstants> for PySystemConstants {
    fn from(s: librate_core::cr3bp::SystemConstants) -> Self {
        Self { name: s.name, mu: s.mu, lu_km: s.lu_km, tu_s: s.tu_s, r1_km: s.r1_km, r2_km: s.r2_km }
    }
}

#[pymethods]
impl PySystemConstants {
    fn __repr__(&self) -> String {
        format!("SystemConstants(name='{}', mu={}, lu_km={}, tu_s={}, r1_km={}, r2_km={})", self.name, self.mu, self.lu_km, self.tu_s, self.r1_km, self.r2_km)
    }
}

/// Add the record classes to `librate._core`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyStats>()?;
    m.add_class::<PyEventHit>()?;
    m.add_class::<PyTrajectory>()?;
    m.add_class::<PyBatchResult>()?;
    m.add_class::<PyShootingEvaluation>()?;
    m.add_class::<PySymmetricOrbit>()?;
    m.add_class::<PyMultipleShooting>()?;
    m.add_class::<PySystemConstants>()?;
    Ok(())
}
