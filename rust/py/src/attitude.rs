//! Bindings of the attitude models: convert, call the core with the GIL released, convert.

use librate_core::attitude::{self, gravity_gradient_by_name, Facet, FacetBody, FlatPlate, GravityGradient, OrbitMode, RigidBody, Sun, Torque};
use librate_core::integrate::{Options, Output};
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

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

/// Coupled 3-D orbit-attitude propagation.
#[pyfunction]
#[pyo3(signature = (mu, inertia, torques, orbit_mode, state0, t0, tf, *, options, stm, t_eval, inertia_nd=None, facets=None, sun=(0.0, librate_core::constants::OMEGA_SUN, librate_core::constants::SOLAR_PRESSURE_1AU), tu_s=1.0, srp_force=None))]
#[allow(clippy::too_many_arguments)]
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
) -> PyResult<Bound<'py, PyDict>> {
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
    let d = PyDict::new(py);
    d.set_item("t", tr.t.into_pyarray(py))?;
    d.set_item("states", tr.states.into_pyarray(py).reshape([n, 13])?)?;
    d.set_item("stm", match tr.stm_final { Some(m) => Some(m.into_pyarray(py).reshape([13, 13])?), None => None })?;
    d.set_item("stats", (tr.stats.accepted, tr.stats.rejected, tr.stats.rhs_evals))?;
    Ok(d)
}

/// Planar reduced attitude model along an integrated (or held) orbit.
#[pyfunction]
#[pyo3(signature = (mu, kz, primaries, held, orbit0, phi0, wz0, t0, tf, *, options, stm, t_eval, plate=None))]
#[allow(clippy::too_many_arguments)]
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
) -> PyResult<Bound<'py, PyDict>> {
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
    let d = PyDict::new(py);
    d.set_item("t", tr.t.into_pyarray(py))?;
    d.set_item("orbit", tr.orbit.into_pyarray(py).reshape([n, 6])?)?;
    d.set_item("phi", tr.phi.into_pyarray(py))?;
    d.set_item("wz", tr.wz.into_pyarray(py))?;
    d.set_item("stm", match tr.stm_final { Some(m) => Some(m.to_vec().into_pyarray(py).reshape([2, 2])?), None => None })?;
    d.set_item("stats", (tr.stats.accepted, tr.stats.rejected, tr.stats.rhs_evals))?;
    Ok(d)
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

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(attitude_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(planar_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_body_kz, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_torques, m)?)?;
    m.add_function(wrap_pyfunction!(facets_force_torque, m)?)?;
    Ok(())
}
