//! Bindings of the flexible model: convert, call the core with the GIL released, convert.
//! Bodies arrive as (hub_mass, [ix, iy, iz], [(m, [bx, by], [tx, ty], k, c), ...]) with k in
//! mass / TU^2 and c in mass / TU (the Python facade converts SI with the system's TU).

use librate_core::flexible::{self, Appendage, FlexibleBody};
use librate_core::integrate::{Options, Output};
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{to_py, OptionsArg};

type AppendageArg = (f64, [f64; 2], [f64; 2], f64, f64);
type BodyArg = (f64, [f64; 3], Vec<AppendageArg>);

fn body(b: BodyArg) -> PyResult<FlexibleBody> {
    let apps: Vec<Appendage> = b.2.into_iter().map(|(mass, position, direction, stiffness, damping)| Appendage { mass, position, direction, stiffness, damping }).collect();
    FlexibleBody::new(b.0, b.1, &apps).map_err(to_py)
}

fn output<'a>(t_eval: &'a Option<Vec<f64>>) -> Output<'a> {
    match t_eval {
        Some(t) => Output::At(t),
        None => Output::Steps,
    }
}

fn rows<'py>(py: Python<'py>, v: Vec<f64>, m: usize, n: usize) -> PyResult<Bound<'py, PyAny>> {
    Ok(v.into_pyarray(py).reshape([m, n])?.into_any())
}

/// Validate a body; its derived constants.
#[pyfunction]
fn flexible_body_check<'py>(py: Python<'py>, body_arg: BodyArg) -> PyResult<Bound<'py, PyDict>> {
    let b = body(body_arg)?;
    let n = b.n();
    let d = PyDict::new(py);
    d.set_item("total_mass", b.total_mass())?;
    d.set_item("hub_position", b.hub_position().to_vec())?;
    d.set_item("inertia", b.inertia())?;
    d.set_item("asymmetry", (b.asymmetry().re, b.asymmetry().im))?;
    d.set_item("kz", b.kz())?;
    d.set_item("principal_angle", b.principal_angle())?;
    d.set_item("mass_matrix", rows(py, b.mass_matrix(), n, n)?)?;
    d.set_item("directions", b.appendages().iter().map(|a| a.direction.to_vec()).collect::<Vec<_>>())?;
    Ok(d)
}

/// Coupled flexible propagation along an integrated (or held) orbit.
#[pyfunction]
#[pyo3(signature = (mu, body_arg, primaries, held, orbit0, phi0, wz0, q0, qdot0, t0, tf, *, options, t_eval))]
#[allow(clippy::too_many_arguments)]
fn flexible_propagate<'py>(
    py: Python<'py>,
    mu: f64,
    body_arg: BodyArg,
    primaries: [bool; 2],
    held: bool,
    orbit0: [f64; 6],
    phi0: f64,
    wz0: f64,
    q0: Vec<f64>,
    qdot0: Vec<f64>,
    t0: f64,
    tf: f64,
    options: OptionsArg,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let b = body(body_arg)?;
    let opts = Options::from(options);
    let times = t_eval.map(|a| a.as_array().to_vec());
    let tr = py
        .detach(|| flexible::propagate_flexible(mu, &b, primaries, held, &orbit0, phi0, wz0, &q0, &qdot0, t0, tf, &opts, output(&times)))
        .map_err(to_py)?;
    let (m, n) = (tr.t.len(), b.n());
    let d = PyDict::new(py);
    d.set_item("t", tr.t.into_pyarray(py))?;
    d.set_item("orbit", rows(py, tr.orbit, m, 6)?)?;
    d.set_item("phi", tr.phi.into_pyarray(py))?;
    d.set_item("wz", tr.wz.into_pyarray(py))?;
    d.set_item("q", rows(py, tr.q, m, n)?)?;
    d.set_item("qdot", rows(py, tr.qdot, m, n)?)?;
    d.set_item("stats", (tr.stats.accepted, tr.stats.rejected, tr.stats.rhs_evals))?;
    Ok(d)
}

/// Rigid composite solution, closed-form deflections along it and the first-order attitude perturbation.
#[pyfunction]
#[pyo3(signature = (mu, body_arg, primaries, held, orbit0, phi0, wz0, t0, tf, *, options, t_eval))]
#[allow(clippy::too_many_arguments)]
fn flexible_quasi_static<'py>(
    py: Python<'py>,
    mu: f64,
    body_arg: BodyArg,
    primaries: [bool; 2],
    held: bool,
    orbit0: [f64; 6],
    phi0: f64,
    wz0: f64,
    t0: f64,
    tf: f64,
    options: OptionsArg,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let b = body(body_arg)?;
    let opts = Options::from(options);
    let times = t_eval.map(|a| a.as_array().to_vec());
    let tr = py
        .detach(|| flexible::propagate_quasi_static(mu, &b, primaries, held, &orbit0, phi0, wz0, t0, tf, &opts, output(&times)))
        .map_err(to_py)?;
    let (m, n) = (tr.t.len(), b.n());
    let d = PyDict::new(py);
    d.set_item("t", tr.t.into_pyarray(py))?;
    d.set_item("orbit", rows(py, tr.orbit, m, 6)?)?;
    d.set_item("phi", tr.phi.into_pyarray(py))?;
    d.set_item("wz", tr.wz.into_pyarray(py))?;
    d.set_item("dphi", tr.dphi.into_pyarray(py))?;
    d.set_item("dwz", tr.dwz.into_pyarray(py))?;
    d.set_item("q", rows(py, tr.q, m, n)?)?;
    d.set_item("qdot", rows(py, tr.qdot, m, n)?)?;
    d.set_item("qddot", rows(py, tr.qddot, m, n)?)?;
    d.set_item("dtau", tr.dtau.into_pyarray(py))?;
    d.set_item("stats", (tr.stats.accepted, tr.stats.rejected, tr.stats.rhs_evals))?;
    Ok(d)
}

/// The closed form at one state: (q, qdot, qddot, wzdot, dtau).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[allow(clippy::type_complexity)]
fn flexible_quasi_static_point(mu: f64, body_arg: BodyArg, primaries: [bool; 2], held: bool, orbit: [f64; 6], phi: f64, wz: f64) -> PyResult<(Vec<f64>, Vec<f64>, Vec<f64>, f64, f64)> {
    let b = body(body_arg)?;
    let p = flexible::quasi_static_point(mu, &b, primaries, held, &orbit, phi, wz).map_err(to_py)?;
    Ok((p.q, p.qdot, p.qddot, p.wzdot, p.dtau))
}

/// Energies, momentum, torque and inertia of states (orbit (m, 6), phi, wz (m,), q, qdot (m, n)).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn flexible_energies<'py>(
    py: Python<'py>,
    mu: f64,
    body_arg: BodyArg,
    primaries: [bool; 2],
    orbit: PyReadonlyArray2<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
    wz: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    qdot: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let b = body(body_arg)?;
    let flat = |a: &PyReadonlyArray2<'py, f64>| -> Vec<f64> { a.as_array().iter().copied().collect() };
    if q.shape()[1] != b.n() || qdot.shape()[1] != b.n() || orbit.shape()[1] != 6 {
        return Err(PyValueError::new_err(format!("invalid argument `states`: orbit must be (m, 6) and q, qdot (m, {})", b.n())));
    }
    let e = flexible::evaluate_energies(mu, &b, primaries, &flat(&orbit), phi.as_slice()?, wz.as_slice()?, &flat(&q), &flat(&qdot)).map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("kinetic", e.iter().map(|e| e.kinetic).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("elastic", e.iter().map(|e| e.elastic).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("tidal", e.iter().map(|e| e.tidal).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("momentum", e.iter().map(|e| e.momentum).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("structural", e.iter().map(|e| e.structural).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("torque", e.iter().map(|e| e.torque).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("inertia", e.iter().map(|e| e.inertia).collect::<Vec<_>>().into_pyarray(py))?;
    Ok(d)
}

/// The right-hand side at one state (orbit held): (wzdot, qddot).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn flexible_rates(mu: f64, body_arg: BodyArg, primaries: [bool; 2], orbit: [f64; 6], phi: f64, wz: f64, q: Vec<f64>, qdot: Vec<f64>) -> PyResult<(f64, Vec<f64>)> {
    let b = body(body_arg)?;
    if q.len() != b.n() || qdot.len() != b.n() {
        return Err(PyValueError::new_err(format!("invalid argument `q`: need {} values", b.n())));
    }
    Ok(flexible::flexible_rates(mu, &b, primaries, &orbit, phi, wz, &q, &qdot))
}

/// Correct (phi0, wz0, q0, qdot0) to a periodic motion of the coupled flexible model over one
/// orbit period (librate_core::flexible::correct_flexible_periodic): returns (x, scaled residual
/// max-norm, iterations, stop reason, monodromy (m, m)).
#[pyfunction]
#[pyo3(signature = (mu, body_arg, primaries, orbit0, period, x0, turns, scale, *, options, tol, max_iter, threads=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn flexible_correct_periodic<'py>(
    py: Python<'py>,
    mu: f64,
    body_arg: BodyArg,
    primaries: [bool; 2],
    orbit0: [f64; 6],
    period: f64,
    x0: Vec<f64>,
    turns: f64,
    scale: Vec<f64>,
    options: OptionsArg,
    tol: f64,
    max_iter: usize,
    threads: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, f64, usize, &'static str, Bound<'py, PyAny>)> {
    let b = body(body_arg)?;
    let opts = Options::from(options);
    let r = py
        .detach(|| flexible::correct_flexible_periodic(mu, &b, primaries, &orbit0, period, &x0, turns, &scale, &opts, tol, max_iter, threads))
        .map_err(to_py)?;
    let m = r.x.len();
    Ok((r.x.into_pyarray(py).into_any(), r.residual, r.iterations, r.reason.as_str(), r.monodromy.into_pyarray(py).reshape([m, m])?.into_any()))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(flexible_correct_periodic, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_body_check, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_quasi_static, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_quasi_static_point, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_energies, m)?)?;
    m.add_function(wrap_pyfunction!(flexible_rates, m)?)?;
    Ok(())
}
