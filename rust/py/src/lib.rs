#![deny(clippy::too_many_arguments)] // no binding takes more than 8 parameters (rust/py/clippy.toml, tests/test_boundary.py)
//! `librate._core`: thin PyO3 bindings over librate-core. Each function converts its arguments,
//! calls the core with the GIL released, and converts the result; no numerics live here.
//! The public, documented API is the `librate` Python package, which wraps these. Errors map
//! to Python in `errors`, arrays convert in `convert`, and the typed arguments (options,
//! enums, case containers) are the classes of `options`.

use librate_core::cr3bp::{self, SystemConstants, PRESETS};
use librate_core::error::Error;
use librate_core::integrate::{Options, Status};
use librate_core::orbit::{correct_multiple_shooting, MemberCondition, Constraint, Stability, SymmetricShooting, Var};
use numpy::Complex64;
use librate_core::propagation::{self, Collision, EventKind, EventSpec};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

mod attitude;
mod attitude3d;
mod build;
mod convert;
mod ephemeris;
mod ephemeris_attitude;
mod errors;
mod flexible;
mod fourier;
mod interrupt;
mod map;
mod map3d;
mod options;
mod records;

pub(crate) use errors::to_py;
use interrupt::interruptible;
use convert::{output, rows, state6, times};
use options::{IntegrationOptions, NewtonOptions};
use records::{PyBatchResult, PyEventHit, PyMultipleShooting, PyShootingEvaluation, PyStats, PySystemConstants, PySymmetricOrbit, PyTrajectory};

fn mat6<'py>(py: Python<'py>, m: &[[f64; 6]; 6]) -> Bound<'py, PyAny> {
    convert::matrix(py, m)
}

fn event_specs(events: Vec<(String, Vec<f64>, i8, bool)>) -> PyResult<Vec<EventSpec>> {
    events
        .into_iter()
        .enumerate()
        .map(|(i, (kind, p, direction, terminal))| {
            let kind = match (kind.as_str(), p.as_slice()) {
                ("crossing", &[index, value]) if index >= 0.0 && index.fract() == 0.0 => EventKind::Crossing { index: index as usize, value },
                ("distance", &[cx, cy, cz, radius]) => EventKind::Distance { center: [cx, cy, cz], radius },
                _ => return Err(PyValueError::new_err(format!("invalid argument `events`: event {i} has kind {kind:?} with parameters {p:?}; expected ('crossing', [index, value]) or ('distance', [cx, cy, cz, radius])"))),
            };
            Ok(EventSpec { kind, direction, terminal })
        })
        .collect()
}

/// Propagate one CR3BP state (see `librate.propagate`).
#[pyfunction]
#[pyo3(signature = (mu, state, t_span, *, options, stm, t_eval, events, collision=None))]
fn propagate<'py>(
    py: Python<'py>,
    mu: f64,
    state: PyReadonlyArray1<'py, f64>,
    t_span: (f64, f64),
    options: PyRef<'py, IntegrationOptions>,
    stm: bool,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
    events: Vec<(String, Vec<f64>, i8, bool)>,
    collision: Option<(f64, f64)>,
) -> PyResult<PyTrajectory> {
    let s = state6("state", state.as_slice()?)?;
    let (t0, tf) = t_span;
    let opts = Options::from(&*options);
    let specs = event_specs(events)?;
    let spheres = collision.map(|(a, b)| Collision::new([a, b])).transpose().map_err(to_py)?;
    let times = times(t_eval);
    let tr = py
        .detach(|| {
            let output = output(&times);
            match &spheres {
                Some(c) => propagation::propagate_checked(mu, &s, t0, tf, &opts, stm, output, &specs, c),
                None => propagation::propagate(mu, &s, t0, tf, &opts, stm, output, &specs),
            }
        })
        .map_err(to_py)?;
    let n = tr.t.len();
    let events = tr
        .events
        .iter()
        .map(|e| Py::new(py, PyEventHit { index: e.index, t: e.t, y: e.state.to_vec().into_pyarray(py).into_any().unbind(), stm: e.stm.as_ref().map(|m| mat6(py, m).unbind()) }))
        .collect::<PyResult<Vec<_>>>()?;
    let (status, event_index) = match (tr.status, tr.collision) {
        (_, Some(_)) => ("collision", None),
        (Status::Completed, None) => ("completed", None),
        (Status::Terminated { event }, None) => ("event", Some(event)),
    };
    Ok(PyTrajectory {
        t: tr.t.into_pyarray(py).into_any().unbind(),
        y: tr.states.into_pyarray(py).reshape([n, 6])?.into_any().unbind(),
        t_final: tr.t_final,
        y_final: tr.state_final.to_vec().into_pyarray(py).into_any().unbind(),
        stm: tr.stm_final.as_ref().map(|m| mat6(py, m).unbind()),
        events: PyTuple::new(py, events)?.unbind(),
        status,
        event_index,
        collision: tr.collision.map(|h| to_py(h.error(tr.stats.steps())).into_value(py).into_any()),
        stats: PyStats::from(tr.stats),
    })
}

/// Propagate many states to their final times on all cores; failed members are reported, not raised.
#[pyfunction]
#[pyo3(signature = (mu, states, t0, t_final, *, options, stm, threads, collision=None))]
fn propagate_many<'py>(
    py: Python<'py>,
    mu: f64,
    states: PyReadonlyArray2<'py, f64>,
    t0: f64,
    t_final: PyReadonlyArray1<'py, f64>,
    options: PyRef<'py, IntegrationOptions>,
    stm: bool,
    threads: Option<usize>,
    collision: Option<(f64, f64)>,
) -> PyResult<PyBatchResult> {
    let spheres = collision.map(|(a, b)| Collision::new([a, b])).transpose().map_err(to_py)?;
    let rows = rows::<6>(&states, "states", None)?;
    let tf: Vec<f64> = t_final.as_array().to_vec();
    let opts = Options::from(&*options);
    let results = interruptible(py, || propagation::propagate_many(mu, &rows, t0, &tf, &opts, stm, threads, spheres.as_ref()))?;
    let n = results.len();
    let mut y = Vec::with_capacity(n * 6);
    let mut m = Vec::with_capacity(if stm { n * 36 } else { 0 });
    let mut ok = Vec::with_capacity(n);
    let mut stats = Vec::with_capacity(n * 3);
    // per member: 0 completed, 1 / 2 collision with primary 1 / 2, 3 another integration error
    let mut status: Vec<u8> = Vec::with_capacity(n);
    let errors = PyDict::new(py);
    for (i, r) in results.iter().enumerate() {
        match r {
            Ok(f) => {
                y.extend_from_slice(&f.state);
                if let Some(p) = &f.stm {
                    m.extend(p.iter().flatten());
                }
                ok.push(true);
                status.push(0);
                stats.extend([f.stats.accepted as u64, f.stats.rejected as u64, f.stats.rhs_evals as u64]);
            }
            Err(e) => {
                y.extend([f64::NAN; 6]);
                if stm {
                    m.extend([f64::NAN; 36]);
                }
                ok.push(false);
                status.push(match e {
                    Error::Integration(librate_core::IntegrationError::Collision { primary, .. }) => *primary,
                    _ => 3,
                });
                stats.extend([0u64; 3]);
                errors.set_item(i, to_py(e.clone()).into_value(py))?;
            }
        }
    }
    Ok(PyBatchResult {
        y: y.into_pyarray(py).reshape([n, 6])?.into_any().unbind(),
        stm: if stm { Some(m.into_pyarray(py).reshape([n, 6, 6])?.into_any().unbind()) } else { None },
        ok: ok.into_pyarray(py).into_any().unbind(),
        status: status.into_pyarray(py).into_any().unbind(),
        errors: errors.unbind(),
        stats: stats.into_pyarray(py).reshape([n, 3])?.into_any().unbind(),
    })
}

/// Jacobi constant of each row of an (n, 6) array.
#[pyfunction]
fn jacobi<'py>(py: Python<'py>, mu: f64, states: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    cr3bp::check_mu(mu).map_err(to_py)?;
    if states.shape()[1] != 6 {
        return Err(PyValueError::new_err(format!("invalid argument `states`: must have shape (n, 6) or (6,), got {:?}", states.shape())));
    }
    let a = states.as_array();
    let c: Vec<f64> = a.rows().into_iter().map(|r| cr3bp::jacobi(mu, &[r[0], r[1], r[2], r[3], r[4], r[5]])).collect();
    Ok(c.into_pyarray(py))
}

/// L1..L5 as a (5, 3) array.
#[pyfunction]
fn lagrange_points<'py>(py: Python<'py>, mu: f64) -> PyResult<Bound<'py, PyAny>> {
    let lp = cr3bp::lagrange_points(mu).map_err(to_py)?;
    Ok(Array2::from_shape_fn((5, 3), |(i, j)| lp[i][j]).into_pyarray(py).into_any())
}

/// The constants of a preset.
#[pyfunction]
fn system_preset(name: &str) -> PyResult<PySystemConstants> {
    SystemConstants::preset(name).map(PySystemConstants::from).map_err(to_py)
}

/// Validate user-defined system constants (raises ValueError naming the bad one).
#[pyfunction]
fn system_validate(name: String, mu: f64, lu_km: f64, tu_s: f64, r1_km: f64, r2_km: f64) -> PyResult<PySystemConstants> {
    SystemConstants::new(name, mu, lu_km, tu_s, r1_km, r2_km).map(PySystemConstants::from).map_err(to_py)
}

/// Names of the system presets.
#[pyfunction]
fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.0).collect()
}

fn constraint(kind: &str, v: &[f64]) -> PyResult<Constraint> {
    Ok(match (kind, v) {
        ("fix", &[var, value]) => {
            let var = match var as i64 {
                0 => Var::X0,
                1 => Var::Z0,
                2 => Var::Vy0,
                _ => return Err(PyValueError::new_err("invalid argument `constraint`: fixed unknown must be 0 (x0), 1 (z0) or 2 (vy0)")),
            };
            Constraint::Fix(var, value)
        }
        ("period", &[t]) => Constraint::Period(t),
        ("jacobi", &[c]) => Constraint::Jacobi(c),
        ("arclength", &[p0, p1, p2, t0, t1, t2, ds]) => Constraint::Arclength { prev: [p0, p1, p2], tangent: [t0, t1, t2], ds },
        _ => return Err(PyValueError::new_err(format!("invalid argument `constraint`: unknown kind {kind:?} with values {v:?}"))),
    })
}


/// Newton correction of an x-z-symmetric orbit from p = (x0, z0, vy0) under one extra constraint.
#[pyfunction]
#[pyo3(signature = (mu, p, *, spatial, constraint, values, t_max, newton, options))]
fn symmetric_correct<'py>(
    py: Python<'py>,
    mu: f64,
    p: [f64; 3],
    spatial: bool,
    constraint: &str,
    values: Vec<f64>,
    t_max: f64,
    newton: PyRef<'py, NewtonOptions>,
    options: PyRef<'py, IntegrationOptions>,
) -> PyResult<PySymmetricOrbit> {
    let c = self::constraint(constraint, &values)?;
    let mut sh = SymmetricShooting::new(mu, spatial, Options::from(&*options));
    sh.tol = newton.tol;
    sh.max_iter = newton.max_iter;
    sh.t_max = t_max;
    let o = interruptible(py, || sh.correct(p, c))?;
    Ok(PySymmetricOrbit {
        state0: o.state0.to_vec().into_pyarray(py).into_any().unbind(),
        period: o.period,
        jacobi: o.jacobi,
        iterations: o.iterations,
        residual: o.residual,
        evaluation: Py::new(py, PyShootingEvaluation::new(py, &o.evaluation))?,
    })
}

/// Eigenvalues (6,) and the two stability indices (2,) of a monodromy matrix, both complex.
#[pyfunction]
fn stability<'py>(py: Python<'py>, m: PyReadonlyArray2<'py, f64>, planar: bool) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    if m.shape() != [6, 6] {
        return Err(PyValueError::new_err(format!("invalid argument `monodromy`: must have shape (6, 6), got {:?}", m.shape())));
    }
    let a = m.as_array();
    librate_core::error::check_finite("monodromy", a.as_slice().unwrap_or(&a.iter().copied().collect::<Vec<_>>())).map_err(to_py)?;
    let mat = nalgebra::Matrix6::from_fn(|i, j| a[(i, j)]);
    let st = Stability::new(&mat, planar);
    let ev: Vec<Complex64> = st.eigenvalues.iter().map(|z| Complex64::new(z.re, z.im)).collect();
    let nu: Vec<Complex64> = st.indices.iter().map(|z| Complex64::new(z.re, z.im)).collect();
    Ok((ev.into_pyarray(py).into_any(), nu.into_pyarray(py).into_any()))
}

/// Multiple shooting: patches (n, 6), period guess, member condition ("jacobi" or "period", value).
#[pyfunction]
#[pyo3(signature = (mu, patches, period, *, condition, value, newton, options))]
fn multiple_shooting<'py>(
    py: Python<'py>,
    mu: f64,
    patches: PyReadonlyArray2<'py, f64>,
    period: f64,
    condition: &str,
    value: f64,
    newton: PyRef<'py, NewtonOptions>,
    options: PyRef<'py, IntegrationOptions>,
) -> PyResult<PyMultipleShooting> {
    if patches.shape()[1] != 6 || patches.shape()[0] == 0 {
        return Err(PyValueError::new_err(format!("invalid argument `states`: must have shape (n, 6) with n >= 1, got {:?}", patches.shape())));
    }
    let rows = rows::<6>(&patches, "states", None)?;
    let cond = match condition {
        "jacobi" => MemberCondition::Jacobi(value),
        "period" => MemberCondition::Period(value),
        _ => return Err(PyValueError::new_err(format!("invalid argument `condition`: must be 'jacobi' or 'period', got {condition:?}"))),
    };
    let (opts, tol, max_iter) = (Options::from(&*options), newton.tol, newton.max_iter);
    let o = interruptible(py, || correct_multiple_shooting(mu, &rows, period, cond, tol, max_iter, &opts))?;
    let n = o.patches.len();
    let flat: Vec<f64> = o.patches.iter().flatten().copied().collect();
    Ok(PyMultipleShooting { patches: flat.into_pyarray(py).reshape([n, 6])?.into_any().unbind(), period: o.period, jacobi: o.jacobi, iterations: o.iterations, residual: o.residual })
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // LIBRATE_BIND_THREADS checked (an invalid value fails the import, naming it); the worker pool
    // itself starts with the first parallel work (librate_core::threads), so a fork after the import is safe
    librate_core::threads::binding_from_env().map_err(to_py)?;
    errors::register(m)?;
    options::register(m)?;
    m.add_function(wrap_pyfunction!(propagate, m)?)?;
    m.add_function(wrap_pyfunction!(propagate_many, m)?)?;
    m.add_function(wrap_pyfunction!(jacobi, m)?)?;
    m.add_function(wrap_pyfunction!(lagrange_points, m)?)?;
    m.add_function(wrap_pyfunction!(system_preset, m)?)?;
    m.add_function(wrap_pyfunction!(system_validate, m)?)?;
    m.add_function(wrap_pyfunction!(preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(symmetric_correct, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(multiple_shooting, m)?)?;
    fourier::register(m)?;
    ephemeris::register(m)?;
    ephemeris_attitude::register(m)?;
    attitude::register(m)?;
    map::register(m)?;
    flexible::register(m)?;
    attitude3d::register(m)?;
    map3d::register(m)?;
    records::register(m)?;
    build::register(m)?;
    // Physical constants, read from the core (one definition: librate_core::constants).
    m.add("N_SUN", librate_core::constants::N_SUN)?;
    m.add("OMEGA_SUN", librate_core::constants::OMEGA_SUN)?;
    m.add("SOLAR_PRESSURE_1AU", librate_core::constants::SOLAR_PRESSURE_1AU)?;
    m.add("SUN_SYNODIC_PERIOD", librate_core::constants::SUN_SYNODIC_PERIOD)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
