//! Bindings of the attitude models: convert, call the core with the GIL released, convert.

use librate_core::attitude::{self, gravity_gradient_by_name, Facet, FacetBody, FlatPlate, GravityGradient, OrbitMode, RigidBody, Sun, Torque};
use librate_core::integrate::{Options, Output};
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::records::PyStats;
use crate::{to_py, OptionsArg};

fn output<'a>(t_eval: &'a Option<Vec<f64>>) -> Output<'a> {
    match t_eval {
        Some(t) => Output::At(t),
        None => Output::Steps,
    }
}

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

/// Coupled 3-D orbit-attitude propagation.
#[pyfunction]
#[pyo3(signature = (mu, inertia, torques, orbit_mode, state0, t0, tf, *, options, stm, t_eval, inertia_nd=None, facets=None, sun=(0.0, librate_core::constants::OMEGA_SUN, librate_core::constants::SOLAR_PRESSURE_1AU), tu_s=1.0, srp_force=None))]
fn attitude_propagate<'py>(
    py: Python<'py>,
    mu: f64,
    inertia: [f64; 3],
    torques: Vec<String>,
    orbit_mode: &str,
    state0: [f64; 13],
    t0: f64,
    tf: f64,
    options: OptionsArg,
    stm: bool,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
    inertia_nd: Option<[f64; 3]>,
    facets: Option<Vec<FacetTuple>>,
    sun: (f64, f64, f64),
    tu_s: f64,
    srp_force: Option<(f64, f64)>,
) -> PyResult<PyAttitudeTrajectory> {
    let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
    let gg_names: Vec<&String> = torques.iter().filter(|n| n.as_str() != "srp").collect();
    let models: Vec<GravityGradient> = gg_names.iter().map(|n| gravity_gradient_by_name(n)).collect::<Result<_, _>>().map_err(to_py)?;
    let srp_model = match facets {
        Some(f) => Some(facet_model(f, sun, tu_s)?),
        None => None,
    };
    let srp_torque = torques.iter().any(|n| n == "srp");
    if (srp_torque || srp_force.is_some()) && srp_model.is_none() {
        return Err(PyValueError::new_err("invalid argument `srp`: the SRP torque or force needs the body's facets"));
    }
    let mode = match (orbit_mode, inertia_nd) {
        ("integrate", _) => OrbitMode::Integrate,
        ("held", _) => OrbitMode::Held,
        ("coupled", Some(i)) => OrbitMode::Coupled { inertia_nd: i },
        _ => return Err(PyValueError::new_err(format!("invalid argument `orbit`: {orbit_mode:?} (coupling needs the body's mass)"))),
    };
    let opts = Options::from(options);
    let times = t_eval.map(|a| a.as_array().to_vec());
    let tr = py
        .detach(|| {
            let mut refs: Vec<&dyn Torque> = models.iter().map(|m| m as &dyn Torque).collect();
            if let (true, Some(m)) = (srp_torque, &srp_model) {
                refs.push(m as &dyn Torque);
            }
            let force = match (srp_force, &srp_model) {
                (Some((mass, lu_m)), Some(m)) => Some((m, mass, lu_m)),
                _ => None,
            };
            attitude::propagate_attitude(mu, body, &refs, mode, &state0, t0, tf, &opts, stm, output(&times), force, srp_model.as_ref().filter(|_| srp_torque))
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

/// Planar reduced attitude model along an integrated (or held) orbit.
#[pyfunction]
#[pyo3(signature = (mu, kz, primaries, held, orbit0, phi0, wz0, t0, tf, *, options, stm, t_eval, plate=None))]
fn planar_propagate<'py>(
    py: Python<'py>,
    mu: f64,
    kz: f64,
    primaries: [bool; 2],
    held: bool,
    orbit0: [f64; 6],
    phi0: f64,
    wz0: f64,
    t0: f64,
    tf: f64,
    options: OptionsArg,
    stm: bool,
    t_eval: Option<PyReadonlyArray1<'py, f64>>,
    plate: Option<(f64, f64, f64, f64, f64)>,
) -> PyResult<PyPlanarTrajectory> {
    let opts = Options::from(options);
    let times = t_eval.map(|a| a.as_array().to_vec());
    let srp = match plate {
        Some((eps, cs, cd, theta0, omega)) => Some(FlatPlate::new(eps, cs, cd, Sun { theta0, omega, pressure: librate_core::constants::SOLAR_PRESSURE_1AU }).map_err(to_py)?),
        None => None,
    };
    let tr = py
        .detach(|| attitude::propagate_planar(mu, kz, primaries, held, &orbit0, phi0, wz0, t0, tf, &opts, stm, output(&times), srp))
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
