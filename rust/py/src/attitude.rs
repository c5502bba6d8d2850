//! Bindings of the attitude models: convert, call the core with the GIL released, convert.

use librate_core::attitude::{self, gravity_gradient_by_name, Facet, FacetBody, FlatPlate, GravityGradient, OrbitMode, RigidBody, Sun, Torque};
use librate_core::integrate::Options;
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{output, times};
use crate::options::IntegrationOptions;
use crate::records::PyStats;
use crate::to_py;

/// Facets as (area, normal[3], center[3], ca, cs, cd) tuples -> validated core facets.
type FacetTuple = (f64, [f64; 3], [f64; 3], f64, f64, f64);

fn facet_model(facets: Vec<FacetTuple>, sun: (f64, f64, f64), tu_s: f64) -> PyResult<FacetBody> {
    let facets = facets.into_iter().map(|(a, n, c, ca, cs, cd)| Facet::new(a, n, c, ca, cs, cd)).collect::<Result<Vec<_>, _>>().map_err(to_py)?;
    Ok(FacetBody { facets, sun: Sun { theta0: sun.0, omega: sun.1, pressure: sun.2 }, tu_s })
}

/// SRP force (N) and torque (N m) in body axes of facets for a Sun direction in body axes.
#[pyfunction]
fn facets_force_torque(facets: Vec<FacetTuple>, s_body: [f64; 3]) -> PyResult<([f64; 3], [f64; 3])> {
    let m = facet_model(facets, (0.0, 0.0, librate_core::constants::SOLAR_PRESSURE_1AU), 1.0)?;
    Ok(m.force_torque(&s_body))
}

/// The outcome of `attitude_propagate`.
#[pyclass(frozen, get_all, name = "AttitudeTrajectory", module = "librate._core")]
pub struct PyAttitudeTrajectory {
    /// Output times, (n,).
    t: Py<PyAny>,
    /// Coupled states (x, y, z, xd, yd, zd, q1, q2, q3, q4, wx, wy, wz), (n, 13); q scalar last.
    states: Py<PyAny>,
    /// The 13x13 STM from t0 to the final time, or None when not asked.
    stm: Option<Py<PyAny>>,
    /// Integrator counters.
    stats: PyStats,
}

#[pymethods]
impl PyAttitudeTrajectory {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.t.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("AttitudeTrajectory(n={}, stm={})", self.__len__(py)?, if self.stm.is_some() { "True" } else { "False" }))
    }
}

/// The outcome of `planar_propagate`.
#[pyclass(frozen, get_all, name = "PlanarTrajectory", module = "librate._core")]
pub struct PyPlanarTrajectory {
    /// Output times, (n,).
    t: Py<PyAny>,
    /// Orbit states, (n, 6).
    orbit: Py<PyAny>,
    /// Attitude angle (unwrapped), (n,).
    phi: Py<PyAny>,
    /// Inertial angular rate, (n,).
    wz: Py<PyAny>,
    /// The 2x2 STM d(phi, wz)(tf) / d(phi0, wz0), or None when not asked.
    stm: Option<Py<PyAny>>,
    /// Integrator counters.
    stats: PyStats,
}

#[pymethods]
impl PyPlanarTrajectory {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.t.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("PlanarTrajectory(n={}, stm={})", self.__len__(py)?, if self.stm.is_some() { "True" } else { "False" }))
    }
}

/// How the orbit moves under a 3-D attitude (librate_core::attitude::OrbitMode).
#[pyclass(eq, eq_int, frozen, hash, from_py_object, name = "OrbitMode", module = "librate._core")]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub enum PyOrbitMode {
    /// Integrated with the attitude (point-mass CR3BP).
    #[pyo3(name = "INTEGRATE")]
    Integrate,
    /// Held at its initial state.
    #[pyo3(name = "HELD")]
    Held,
    /// Integrated with the extended-body acceleration (needs the nondimensional inertia).
    #[pyo3(name = "COUPLED")]
    Coupled,
}

/// Solar radiation pressure on a faceted body: facets as (area, normal[3], center[3], ca, cs,
/// cd) tuples, the Sun (theta0, omega, pressure), the system's TU (s), and the SRP force on the
/// orbit as (mass_kg, lu_m) or None.
#[pyclass(frozen, name = "SrpModel", module = "librate._core")]
pub struct PySrpModel {
    body: FacetBody,
    force: Option<(f64, f64)>,
}

#[pymethods]
impl PySrpModel {
    #[new]
    #[pyo3(signature = (facets, *, sun=(0.0, librate_core::constants::OMEGA_SUN, librate_core::constants::SOLAR_PRESSURE_1AU), tu_s=1.0, force=None))]
    fn new(facets: Vec<FacetTuple>, sun: (f64, f64, f64), tu_s: f64, force: Option<(f64, f64)>) -> PyResult<Self> {
        Ok(Self { body: facet_model(facets, sun, tu_s)?, force })
    }
}

/// A coupled 3-D orbit-attitude model: mu, principal moments, torque names ("gravity_gradient",
/// "gravity_gradient_earth", "gravity_gradient_moon", "srp"), the orbit's mode (COUPLED needs
/// `inertia_nd`, the moments / (m LU^2)) and the SRP model ("srp" torque or its force).
#[pyclass(frozen, name = "AttitudeModel", module = "librate._core")]
pub struct PyAttitudeModel {
    mu: f64,
    body: RigidBody,
    gravity: Vec<GravityGradient>,
    mode: OrbitMode,
    srp: Option<FacetBody>,
    srp_torque: bool,
    srp_force: Option<(f64, f64)>,
}

#[pymethods]
impl PyAttitudeModel {
    #[new]
    #[pyo3(signature = (mu, inertia, torques, *, orbit=PyOrbitMode::Integrate, inertia_nd=None, srp=None))]
    fn new(mu: f64, inertia: [f64; 3], torques: Vec<String>, orbit: PyOrbitMode, inertia_nd: Option<[f64; 3]>, srp: Option<PyRef<'_, PySrpModel>>) -> PyResult<Self> {
        let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
        let gravity: Vec<GravityGradient> = torques.iter().filter(|n| n.as_str() != "srp").map(|n| gravity_gradient_by_name(n)).collect::<Result<_, _>>().map_err(to_py)?;
        let srp_torque = torques.iter().any(|n| n == "srp");
        let srp_force = srp.as_ref().and_then(|m| m.force);
        if (srp_torque || srp_force.is_some()) && srp.is_none() {
            return Err(PyValueError::new_err("invalid argument `srp`: the SRP torque or force needs the body's facets"));
        }
        let mode = match (orbit, inertia_nd) {
            (PyOrbitMode::Integrate, _) => OrbitMode::Integrate,
            (PyOrbitMode::Held, _) => OrbitMode::Held,
            (PyOrbitMode::Coupled, Some(i)) => OrbitMode::Coupled { inertia_nd: i },
            (PyOrbitMode::Coupled, None) => return Err(PyValueError::new_err("invalid argument `orbit`: 'coupled' (coupling needs the body's mass)")),
        };
        Ok(Self { mu, body, gravity, mode, srp: srp.map(|m| m.body.clone()), srp_torque, srp_force })
    }
}

/// Coupled 3-D orbit-attitude propagation of `model` from state0 (orbit, q scalar last, w) over
/// t_span = (t0, tf).
#[pyfunction]
#[pyo3(signature = (model, state0, t_span, *, options, stm, t_eval))]
fn attitude_propagate<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyAttitudeModel>,
    state0: [f64; 13],
    t_span: (f64, f64),
    options: PyRef<'py, IntegrationOptions>,
    stm: bool,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<PyAttitudeTrajectory> {
    let opts = Options::from(&*options);
    let times = times(t_eval);
    let m = &*model;
    let tr = py
        .detach(|| {
            let mut refs: Vec<&dyn Torque> = m.gravity.iter().map(|g| g as &dyn Torque).collect();
            if let (true, Some(s)) = (m.srp_torque, &m.srp) {
                refs.push(s as &dyn Torque);
            }
            let force = match (m.srp_force, &m.srp) {
                (Some((mass, lu_m)), Some(s)) => Some((s, mass, lu_m)),
                _ => None,
            };
            attitude::propagate_attitude(m.mu, m.body, &refs, m.mode, &state0, t_span.0, t_span.1, &opts, stm, output(&times), force, m.srp.as_ref().filter(|_| m.srp_torque))
        })
        .map_err(to_py)?;
    let n = tr.t.len();
    Ok(PyAttitudeTrajectory {
        t: tr.t.into_pyarray(py).into_any().unbind(),
        states: tr.states.into_pyarray(py).reshape([n, 13])?.into_any().unbind(),
        stm: match tr.stm_final {
            Some(m) => Some(m.into_pyarray(py).reshape([13, 13])?.into_any().unbind()),
            None => None,
        },
        stats: PyStats::from(tr.stats),
    })
}

/// The planar reduced attitude model: mu, Kz, the enabled primaries [larger, smaller], the
/// orbit held (or integrated), and a flat plate (eps, cs, cd, theta0, omega) or None.
#[pyclass(frozen, name = "PlanarModel", module = "librate._core")]
pub struct PyPlanarModel {
    mu: f64,
    kz: f64,
    primaries: [bool; 2],
    held: bool,
    plate: Option<FlatPlate>,
}

#[pymethods]
impl PyPlanarModel {
    #[new]
    #[pyo3(signature = (mu, kz, *, primaries=[true, true], held=false, plate=None))]
    fn new(mu: f64, kz: f64, primaries: [bool; 2], held: bool, plate: Option<(f64, f64, f64, f64, f64)>) -> PyResult<Self> {
        let plate = match plate {
            Some((eps, cs, cd, theta0, omega)) => Some(FlatPlate::new(eps, cs, cd, Sun { theta0, omega, pressure: librate_core::constants::SOLAR_PRESSURE_1AU }).map_err(to_py)?),
            None => None,
        };
        Ok(Self { mu, kz, primaries, held, plate })
    }
}

/// The planar reduced attitude model along an integrated (or held) orbit from orbit0 and
/// attitude0 = (phi0, wz0) over t_span = (t0, tf).
#[pyfunction]
#[pyo3(signature = (model, orbit0, attitude0, t_span, *, options, stm, t_eval))]
fn planar_propagate<'py>(
    py: Python<'py>,
    model: PyRef<'py, PyPlanarModel>,
    orbit0: [f64; 6],
    attitude0: (f64, f64),
    t_span: (f64, f64),
    options: PyRef<'py, IntegrationOptions>,
    stm: bool,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<PyPlanarTrajectory> {
    let opts = Options::from(&*options);
    let times = times(t_eval);
    let m = &*model;
    let ((phi0, wz0), (t0, tf)) = (attitude0, t_span);
    let tr = py
        .detach(|| attitude::propagate_planar(m.mu, m.kz, m.primaries, m.held, &orbit0, phi0, wz0, t0, tf, &opts, stm, output(&times), m.plate))
        .map_err(to_py)?;
    let n = tr.t.len();
    Ok(PyPlanarTrajectory {
        t: tr.t.into_pyarray(py).into_any().unbind(),
        orbit: tr.orbit.into_pyarray(py).reshape([n, 6])?.into_any().unbind(),
        phi: tr.phi.into_pyarray(py).into_any().unbind(),
        wz: tr.wz.into_pyarray(py).into_any().unbind(),
        stm: match tr.stm_final {
            Some(m) => Some(m.to_vec().into_pyarray(py).reshape([2, 2])?.into_any().unbind()),
            None => None,
        },
        stats: PyStats::from(tr.stats),
    })
}

/// Total torque (body axes, inertia units / TU^2) at coupled states (n, 13).
#[pyfunction]
fn attitude_torques<'py>(
    py: Python<'py>,
    mu: f64,
    inertia: [f64; 3],
    torques: Vec<String>,
    t: PyReadonlyArray1<'py, f64>,
    states: numpy::PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let models: Vec<GravityGradient> = torques.iter().map(|n| gravity_gradient_by_name(n)).collect::<Result<_, _>>().map_err(to_py)?;
    let refs: Vec<&dyn Torque> = models.iter().map(|m| m as &dyn Torque).collect();
    let flat: Vec<f64> = states.as_array().iter().copied().collect();
    let out = attitude::evaluate_torques(mu, body, &refs, t.as_slice()?, &flat).map_err(to_py)?;
    let n = out.len();
    Ok(out.into_iter().flatten().collect::<Vec<f64>>().into_pyarray(py).reshape([n, 3])?.into_any())
}

/// Validate principal moments (ValueError naming the bad one); returns Kz.
#[pyfunction]
fn rigid_body_kz(ix: f64, iy: f64, iz: f64) -> PyResult<f64> {
    RigidBody::new(ix, iy, iz).map(|b| b.kz()).map_err(to_py)
}

/// The planar gravity-gradient angular acceleration 1.5 Kz [S cos 2phi - C sin 2phi] (1/TU^2) for
/// forcing samples (S, C) at attitudes phi (arrays of one length).
#[pyfunction]
fn planar_gravity_gradient<'py>(
    py: Python<'py>,
    kz: f64,
    s: PyReadonlyArray1<'py, f64>,
    c: PyReadonlyArray1<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (s, c, phi) = (s.as_array(), c.as_array(), phi.as_array());
    if s.len() != phi.len() || c.len() != phi.len() {
        return Err(PyValueError::new_err(format!("invalid argument: s, c and phi must have one length, got {}, {}, {}", s.len(), c.len(), phi.len())));
    }
    let out: Vec<f64> = (0..phi.len()).map(|i| attitude::planar_gravity_gradient(kz, s[i], c[i], phi[i]).0).collect();
    Ok(out.into_pyarray(py).into_any())
}

/// The flat-plate SRP angular acceleration (1/TU^2) at times t and attitudes phi (arrays of one
/// length) for the plate (eps, cs, cd) and the Sun's phase theta_sun0.
#[pyfunction]
fn flat_plate_wzdot<'py>(
    py: Python<'py>,
    eps: f64,
    cs: f64,
    cd: f64,
    theta_sun0: f64,
    t: PyReadonlyArray1<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let plate = FlatPlate::new(eps, cs, cd, Sun { theta0: theta_sun0, ..Sun::default() }).map_err(to_py)?;
    let (t, phi) = (t.as_array(), phi.as_array());
    if t.len() != phi.len() {
        return Err(PyValueError::new_err(format!("invalid argument: t and phi must have one length, got {} and {}", t.len(), phi.len())));
    }
    let out: Vec<f64> = (0..t.len()).map(|i| plate.wzdot(t[i], phi[i]).0).collect();
    Ok(out.into_pyarray(py).into_any())
}

/// The Sun's angle from the synodic X axis (rad, unwrapped) at times t (TU), from its phase.
#[pyfunction]
fn sun_angle<'py>(py: Python<'py>, theta_sun0: f64, t: PyReadonlyArray1<'py, f64>) -> Bound<'py, PyAny> {
    let sun = Sun { theta0: theta_sun0, ..Sun::default() };
    t.as_array().iter().map(|&ti| sun.angle(ti)).collect::<Vec<f64>>().into_pyarray(py).into_any()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAttitudeTrajectory>()?;
    m.add_class::<PyPlanarTrajectory>()?;
    m.add_class::<PyOrbitMode>()?;
    m.add_class::<PySrpModel>()?;
    m.add_class::<PyAttitudeModel>()?;
    m.add_class::<PyPlanarModel>()?;
    m.add_function(wrap_pyfunction!(planar_gravity_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(flat_plate_wzdot, m)?)?;
    m.add_function(wrap_pyfunction!(sun_angle, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(planar_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_body_kz, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_torques, m)?)?;
    m.add_function(wrap_pyfunction!(facets_force_torque, m)?)?;
    Ok(())
}
