//! Bindings of the flexible model: convert, call the core with the GIL released, convert.
//! Bodies arrive as (hub_mass, [ix, iy, iz], [(m, [bx, by], [tx, ty], k, c), ...]) with k in
//! mass / TU^2 and c in mass / TU (the Python facade converts SI with the system's TU).

use librate_core::flexible::{self, Appendage, FlexibleBody};
use librate_core::integrate::Options;
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyComplex;

use crate::convert::{array, output, table as rows, times};
use crate::options::{IntegrationOptions, NewtonOptions};
use crate::records::PyStats;
use crate::interrupt::interruptible;
use crate::to_py;

type AppendageArg = (f64, [f64; 2], [f64; 2], f64, f64);
type BodyArg = (f64, [f64; 3], Vec<AppendageArg>);

fn body(b: BodyArg) -> PyResult<FlexibleBody> {
    let apps: Vec<Appendage> = b.2.into_iter().map(|(mass, position, direction, stiffness, damping)| Appendage { mass, position, direction, stiffness, damping }).collect();
    FlexibleBody::new(b.0, b.1, &apps).map_err(to_py)
}

/// The planar flexible model: mu, the body (validated here), the enabled primaries [larger,
/// smaller] and the orbit held (or integrated).
#[pyclass(frozen, name = "FlexibleModel", module = "librate._core")]
pub struct PyFlexibleModel {
    mu: f64,
    body: FlexibleBody,
    primaries: [bool; 2],
    held: bool,
}

#[pymethods]
impl PyFlexibleModel {
    #[new]
    #[pyo3(signature = (mu, body_arg, *, primaries=[true, true], held=false))]
    fn new(mu: f64, body_arg: BodyArg, primaries: [bool; 2], held: bool) -> PyResult<Self> {
        Ok(Self { mu, body: body(body_arg)?, primaries, held })
    }
}

/// The derived constants of a validated flexible body (`flexible_body_check`), in the units of
/// its arguments.
#[pyclass(frozen, get_all, name = "FlexibleBodyConstants", module = "librate._core")]
pub struct PyFlexibleBodyConstants {
    /// Hub plus appendage masses.
    total_mass: f64,
    /// Hub centre relative to the undeformed system's centre of mass, [x, y].
    hub_position: [f64; 2],
    /// Composite moment of inertia about z of the undeformed body.
    inertia: f64,
    /// Z0 = (Qxx - Qyy) + 2i Qxy (Q the in-plane second moments of mass): |Z0| = Iy - Ix about
    /// the composite principal axes, arg(Z0) / 2 the principal x axis from the body x axis.
    asymmetry: Py<PyComplex>,
    /// Kz = (Iy - Ix) / Iz of the rigid composite body (principal axes).
    kz: f64,
    /// Angle of the composite principal x axis from the body x axis (rad).
    principal_angle: f64,
    /// Mass matrix of the deflections, (n, n).
    mass_matrix: Py<PyAny>,
    /// Unit deflection direction of each appendage, [tx, ty].
    directions: Vec<[f64; 2]>,
}

#[pymethods]
impl PyFlexibleBodyConstants {
    fn __repr__(&self) -> String {
        format!("FlexibleBodyConstants(n={}, total_mass={}, inertia={}, kz={})", self.directions.len(), self.total_mass, self.inertia, self.kz)
    }
}

/// The outcome of `flexible_propagate`.
#[pyclass(frozen, get_all, name = "FlexibleTrajectory", module = "librate._core")]
pub struct PyFlexibleTrajectory {
    /// Output times, (m,).
    t: Py<PyAny>,
    /// Orbit states, (m, 6).
    orbit: Py<PyAny>,
    /// Attitude angle of the body axes (unwrapped), (m,).
    phi: Py<PyAny>,
    /// Inertial angular rate, (m,).
    wz: Py<PyAny>,
    /// Deflections, (m, n).
    q: Py<PyAny>,
    /// Deflection rates, (m, n).
    qdot: Py<PyAny>,
    /// Integrator counters.
    stats: PyStats,
}

#[pymethods]
impl PyFlexibleTrajectory {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.t.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("FlexibleTrajectory(m={})", self.__len__(py)?))
    }
}

/// The outcome of `flexible_quasi_static`: the rigid composite solution, the closed-form
/// deflections along it and the first-order attitude perturbation.
#[pyclass(frozen, get_all, name = "QuasiStaticTrajectory", module = "librate._core")]
pub struct PyQuasiStaticTrajectory {
    /// Output times, (m,).
    t: Py<PyAny>,
    /// Orbit states, (m, 6).
    orbit: Py<PyAny>,
    /// Rigid composite attitude angle of the body axes (unwrapped), (m,).
    phi: Py<PyAny>,
    /// Rigid composite inertial angular rate, (m,).
    wz: Py<PyAny>,
    /// First-order attitude perturbation, (m,).
    dphi: Py<PyAny>,
    /// First-order rate perturbation, (m,).
    dwz: Py<PyAny>,
    /// Quasi-static deflections, (m, n).
    q: Py<PyAny>,
    /// Their rates, (m, n).
    qdot: Py<PyAny>,
    /// Their accelerations, (m, n).
    qddot: Py<PyAny>,
    /// Torque perturbation (mass LU^2 / TU^2), (m,).
    dtau: Py<PyAny>,
    /// Integrator counters.
    stats: PyStats,
}

#[pymethods]
impl PyQuasiStaticTrajectory {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.t.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("QuasiStaticTrajectory(m={})", self.__len__(py)?))
    }
}

/// The outcome of `flexible_energies`: per state, in the units of the body argument and TU.
#[pyclass(frozen, get_all, name = "FlexibleEnergies", module = "librate._core")]
pub struct PyFlexibleEnergies {
    /// Kinetic energy of the motion relative to the centre of mass (inertial rates), (m,).
    kinetic: Py<PyAny>,
    /// Elastic energy sum k_j q_j^2 / 2, (m,).
    elastic: Py<PyAny>,
    /// Second-order gravity potential of the enabled primaries, (m,).
    tidal: Py<PyAny>,
    /// Inertial angular momentum about the centre of mass, (m,).
    momentum: Py<PyAny>,
    /// kinetic + elastic - momentum^2 / (2 I(q)), (m,).
    structural: Py<PyAny>,
    /// Tidal torque on the deformed body, (m,).
    torque: Py<PyAny>,
    /// Moment of inertia I(q), (m,).
    inertia: Py<PyAny>,
}

#[pymethods]
impl PyFlexibleEnergies {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.kinetic.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("FlexibleEnergies(m={})", self.__len__(py)?))
    }
}

/// Validate a body; its derived constants.
#[pyfunction]
fn flexible_body_check(py: Python<'_>, body_arg: BodyArg) -> PyResult<PyFlexibleBodyConstants> {
    let b = body(body_arg)?;
    let n = b.n();
    Ok(PyFlexibleBodyConstants {
        total_mass: b.total_mass(),
        hub_position: b.hub_position(),
        inertia: b.inertia(),
        asymmetry: PyComplex::from_doubles(py, b.asymmetry().re, b.asymmetry().im).unbind(),
        kz: b.kz(),
        principal_angle: b.principal_angle(),
        mass_matrix: rows(py, b.mass_matrix(), n, n)?,
        directions: b.appendages().iter().map(|a| a.direction).collect(),
    })
}

/// Coupled flexible propagation along an integrated (or held) orbit.
#[pyfunction]
#[pyo3(signature = (model, orbit0, attitude0, q0, qdot0, t_span, *, options, t_eval))]
fn flexible_propagate<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyFlexibleModel>,
    orbit0: [f64; 6],
    attitude0: (f64, f64),
    q0: Vec<f64>,
    qdot0: Vec<f64>,
    t_span: (f64, f64),
    options: PyRef<'py, IntegrationOptions>,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<PyFlexibleTrajectory> {
    let (m, b) = (&*model, &model.body);
    let opts = Options::from(&*options);
    let times = times(t_eval);
    let ((phi0, wz0), (t0, tf)) = (attitude0, t_span);
    let tr = py
        .detach(|| flexible::propagate_flexible(m.mu, b, m.primaries, m.held, &orbit0, phi0, wz0, &q0, &qdot0, t0, tf, &opts, output(&times)))
        .map_err(to_py)?;
    let (m, n) = (tr.t.len(), b.n());
    Ok(PyFlexibleTrajectory {
        t: array(py, tr.t),
        orbit: rows(py, tr.orbit, m, 6)?,
        phi: array(py, tr.phi),
        wz: array(py, tr.wz),
        q: rows(py, tr.q, m, n)?,
        qdot: rows(py, tr.qdot, m, n)?,
        stats: PyStats::from(tr.stats),
    })
}

/// Rigid composite solution, closed-form deflections along it and the first-order attitude perturbation.
#[pyfunction]
#[pyo3(signature = (model, orbit0, attitude0, t_span, *, options, t_eval))]
fn flexible_quasi_static<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyFlexibleModel>,
    orbit0: [f64; 6],
    attitude0: (f64, f64),
    t_span: (f64, f64),
    options: PyRef<'py, IntegrationOptions>,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<PyQuasiStaticTrajectory> {
    let (m, b) = (&*model, &model.body);
    let opts = Options::from(&*options);
    let times = times(t_eval);
    let ((phi0, wz0), (t0, tf)) = (attitude0, t_span);
    let tr = py
        .detach(|| flexible::propagate_quasi_static(m.mu, b, m.primaries, m.held, &orbit0, phi0, wz0, t0, tf, &opts, output(&times)))
        .map_err(to_py)?;
    let (m, n) = (tr.t.len(), b.n());
    Ok(PyQuasiStaticTrajectory {
        t: array(py, tr.t),
        orbit: rows(py, tr.orbit, m, 6)?,
        phi: array(py, tr.phi),
        wz: array(py, tr.wz),
        dphi: array(py, tr.dphi),
        dwz: array(py, tr.dwz),
        q: rows(py, tr.q, m, n)?,
        qdot: rows(py, tr.qdot, m, n)?,
        qddot: rows(py, tr.qddot, m, n)?,
        dtau: array(py, tr.dtau),
        stats: PyStats::from(tr.stats),
    })
}

/// The outcome of `flexible_quasi_static_point`: the closed form at one state.
#[pyclass(frozen, get_all, name = "QuasiStaticPoint", module = "librate._core")]
pub struct PyQuasiStaticPoint {
    /// Quasi-static deflections, (n,).
    q: Vec<f64>,
    /// Their rates, (n,).
    qdot: Vec<f64>,
    /// Their accelerations, (n,).
    qddot: Vec<f64>,
    /// wzdot of the rigid composite model.
    wzdot: f64,
    /// The first-order torque perturbation.
    dtau: f64,
}

#[pymethods]
impl PyQuasiStaticPoint {
    fn __repr__(&self) -> String {
        format!("QuasiStaticPoint(n={}, wzdot={}, dtau={})", self.q.len(), self.wzdot, self.dtau)
    }
}

/// The closed form at one state.
#[pyfunction]
fn flexible_quasi_static_point(model: PyRef<'_, PyFlexibleModel>, orbit: [f64; 6], phi: f64, wz: f64) -> PyResult<PyQuasiStaticPoint> {
    let p = flexible::quasi_static_point(model.mu, &model.body, model.primaries, model.held, &orbit, phi, wz).map_err(to_py)?;
    Ok(PyQuasiStaticPoint { q: p.q, qdot: p.qdot, qddot: p.qddot, wzdot: p.wzdot, dtau: p.dtau })
}

/// Energies, momentum, torque and inertia of states (orbit (m, 6), phi, wz (m,), q, qdot (m, n)).
#[pyfunction]
fn flexible_energies<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyFlexibleModel>,
    orbit: PyReadonlyArray2<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
    wz: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    qdot: PyReadonlyArray2<'py, f64>,
) -> PyResult<PyFlexibleEnergies> {
    let (mu, b, primaries) = (model.mu, &model.body, model.primaries);
    let flat = |a: &PyReadonlyArray2<'py, f64>| -> Vec<f64> { a.as_array().iter().copied().collect() };
    if q.shape()[1] != b.n() || qdot.shape()[1] != b.n() || orbit.shape()[1] != 6 {
        return Err(PyValueError::new_err(format!("invalid argument `states`: orbit must be (m, 6) and q, qdot (m, {})", b.n())));
    }
    let e = flexible::evaluate_energies(mu, b, primaries, &flat(&orbit), phi.as_slice()?, wz.as_slice()?, &flat(&q), &flat(&qdot)).map_err(to_py)?;
    let col = |f: fn(&flexible::Energies) -> f64| array(py, e.iter().map(f).collect());
    Ok(PyFlexibleEnergies {
        kinetic: col(|e| e.kinetic),
        elastic: col(|e| e.elastic),
        tidal: col(|e| e.tidal),
        momentum: col(|e| e.momentum),
        structural: col(|e| e.structural),
        torque: col(|e| e.torque),
        inertia: col(|e| e.inertia),
    })
}

/// The right-hand side at one state (orbit held): (wzdot, qddot).
#[pyfunction]
fn flexible_rates(model: PyRef<'_, PyFlexibleModel>, orbit: [f64; 6], phi: f64, wz: f64, q: Vec<f64>, qdot: Vec<f64>) -> PyResult<(f64, Vec<f64>)> {
    let (mu, b, primaries) = (model.mu, &model.body, model.primaries);
    if q.len() != b.n() || qdot.len() != b.n() {
        return Err(PyValueError::new_err(format!("invalid argument `q`: need {} values", b.n())));
    }
    Ok(flexible::flexible_rates(mu, b, primaries, &orbit, phi, wz, &q, &qdot))
}

/// The outcome of `flexible_correct_periodic`.
#[pyclass(frozen, get_all, name = "FlexiblePeriodicCorrection", module = "librate._core")]
pub struct PyFlexiblePeriodicCorrection {
    /// (phi0, wz0, q0 (n), qdot0 (n)) at the last accepted point, (m,) with m = 2 + 2n.
    x: Py<PyAny>,
    /// Max-norm of the scaled residual there.
    residual: f64,
    /// Newton iterations taken.
    iterations: usize,
    /// Why the corrector stopped ("converged", "max_iterations", ...).
    reason: &'static str,
    /// d y(T) / d x from the last Jacobian, (m, m).
    monodromy: Py<PyAny>,
}

#[pymethods]
impl PyFlexiblePeriodicCorrection {
    fn __repr__(&self) -> String {
        format!("FlexiblePeriodicCorrection(reason='{}', iterations={}, residual={:e})", self.reason, self.iterations, self.residual)
    }
}

/// Correct (phi0, wz0, q0, qdot0) to a periodic motion of the coupled flexible model over one
/// orbit period (librate_core::flexible::correct_flexible_periodic).
#[pyfunction]
#[pyo3(signature = (model, orbit, x0, turns, scale, *, options, newton, threads=None))]
fn flexible_correct_periodic<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyFlexibleModel>,
    orbit: ([f64; 6], f64),
    x0: Vec<f64>,
    turns: f64,
    scale: Vec<f64>,
    options: PyRef<'py, IntegrationOptions>,
    newton: PyRef<'py, NewtonOptions>,
    threads: Option<usize>,
) -> PyResult<PyFlexiblePeriodicCorrection> {
    let (m, b) = (&*model, &model.body);
    let ((orbit0, period), opts, tol, max_iter) = (orbit, Options::from(&*options), newton.tol, newton.max_iter);
    let r = interruptible(py, || flexible::correct_flexible_periodic(m.mu, b, m.primaries, &orbit0, period, &x0, turns, &scale, &opts, tol, max_iter, threads))?;
    let m = r.x.len();
    Ok(PyFlexiblePeriodicCorrection { x: array(py, r.x), residual: r.residual, iterations: r.iterations, reason: r.reason.as_str(), monodromy: rows(py, r.monodromy, m, m)? })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyFlexibleModel>()?;
    m.add_class::<PyFlexibleBodyConstants>()?;
    m.add_class::<PyFlexibleTrajectory>()?;
    m.add_class::<PyQuasiStaticTrajectory>()?;
    m.add_class::<PyFlexibleEnergies>()?;
    m.add_class::<PyQuasiStaticPoint>()?;
    m.add_class::<PyFlexiblePeriodicCorrection>()?;
    m.add_function(wrap_pyfunction!(flexible_correct_periodic, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_body_check, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_quasi_static, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_quasi_static_point, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_energies, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_rates, m)?)?;
    Ok(())
}
