//! Thin wrappers of librate_core::ephemeris::attitude (rigid-body attitude along an ephemeris
//! orbit), its placement from the CR3BP, its multiple-shooting correction and the eclipse
//! fraction.

use librate_core::attitude::{Facet, FacetBody, RigidBody, Sun};
use librate_core::ephemeris::attitude::{self as att, AttitudeModel, Srp, DIM};
use librate_core::ephemeris::eclipse;
use librate_core::ephemeris::RotatingFrame;
use librate_core::integrate::Options;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::ephemeris::EphemerisCore;
use crate::errors::to_py;

type FacetSpec = (f64, [f64; 3], [f64; 3], f64, f64, f64);

fn rows<const N: usize>(name: &str, a: &PyReadonlyArray2<'_, f64>, n: usize) -> PyResult<Vec<[f64; N]>> {
    let v = a.as_array();
    if v.ncols() != N || v.nrows() != n {
        return Err(PyValueError::new_err(format!("invalid argument `{name}`: must have shape ({n}, {N}), got {:?}", v.shape())));
    }
    Ok((0..n).map(|i| std::array::from_fn(|k| v[(i, k)])).collect())
}

fn to_2d<'py, const N: usize>(py: Python<'py>, v: &[[f64; N]]) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((v.len(), N), |(i, k)| v[i][k]).into_pyarray(py)
}

/// The attitude model along an ephemeris orbit: body (principal moments), gravity gradient of
/// [Earth, Moon, Sun], optional SRP facets (area m^2, normal, centre m, ca, cs, cd) with the
/// pressure at 1 AU (N/m^2) and the eclipses.
#[pyclass(module = "librate._core", frozen)]
pub struct EphemerisAttitudeModel {
    inner: AttitudeModel,
}

fn nodes(epochs: &PyReadonlyArray1<'_, f64>, orbits: &PyReadonlyArray2<'_, f64>, q: &PyReadonlyArray2<'_, f64>, w: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<librate_core::ephemeris::attitude_shooting::Node>> {
    let e = epochs.as_slice()?;
    let n = e.len();
    let (o, q, w) = (rows::<6>("orbits", orbits, n)?, rows::<4>("q", q, n)?, rows::<3>("w", w, n)?);
    Ok((0..n).map(|i| librate_core::ephemeris::attitude_shooting::Node { epoch: e[i], orbit: o[i], q: q[i], w: w[i] }).collect())
}

fn shooting_dict<'py>(py: Python<'py>, s: &librate_core::ephemeris::attitude_shooting::Shooting) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("q", to_2d(py, &s.q[..]))?;
    d.set_item("w", to_2d(py, &s.w[..]))?;
    d.set_item("defects", to_2d(py, &s.defects[..]))?;
    d.set_item("monodromy", to_2d(py, &s.monodromy[..]))?;
    d.set_item("iterations", s.iterations)?;
    d.set_item("reason", s.reason.clone())?;
    d.set_item("converged", s.converged)?;
    Ok(d)
}

#[pymethods]
impl EphemerisAttitudeModel {
    #[new]
    #[pyo3(signature = (ephemeris, inertia, gravity_gradient=[true, true, true], facets=None, pressure=librate_core::constants::SOLAR_PRESSURE_1AU, eclipses=true))]
    fn new(ephemeris: &EphemerisCore, inertia: [f64; 3], gravity_gradient: [bool; 3], facets: Option<Vec<FacetSpec>>, pressure: f64, eclipses: bool) -> PyResult<Self> {
        let body = RigidBody::new(inertia[0], inertia[1], inertia[2]).map_err(to_py)?;
        let srp = match facets {
            None => None,
            Some(fs) => {
                if !(pressure.is_finite() && pressure >= 0.0) {
                    return Err(PyValueError::new_err(format!("invalid argument `pressure`: must be finite and >= 0 N/m^2, got {pressure}")));
                }
                let facets = fs.into_iter().map(|(a, n, c, ca, cs, cd)| Facet::new(a, n, c, ca, cs, cd)).collect::<Result<Vec<_>, _>>().map_err(to_py)?;
                Some(Srp { facets: FacetBody { facets, sun: Sun { pressure, ..Sun::default() }, tu_s: 1.0 }, eclipses })
            }
        };
        Ok(Self { inner: AttitudeModel::new(ephemeris.inner.clone(), body, gravity_gradient, srp).map_err(to_py)? })
    }

    /// Propagate the 13-state (orbit km, km/s; q; w rad/s) from `epoch` for `duration_s`;
    /// returns (t_tdb, states (n, 13), 7x7 attitude STM or None). `t_eval`: offsets (s).
    #[pyo3(signature = (state, epoch, duration_s, stm=false, t_eval=None, rtol=1e-12, atol=1e-15))]
    fn propagate<'py>(
        &self,
        py: Python<'py>,
        state: PyReadonlyArray1<'_, f64>,
        epoch: f64,
        duration_s: f64,
        stm: bool,
        t_eval: Option<PyReadonlyArray1<'_, f64>>,
        rtol: f64,
        atol: f64,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray2<f64>>>)> {
        let s: [f64; DIM] = state.as_slice()?.try_into().map_err(|_| PyValueError::new_err("invalid argument `state`: must have 13 components (orbit 6, q 4, w 3)"))?;
        let te: Option<Vec<f64>> = match &t_eval {
            Some(a) => Some(a.as_slice()?.to_vec()),
            None => None,
        };
        let opts = Options::with_tolerances(rtol, atol);
        let model = &self.inner;
        let tr = py.detach(|| att::propagate_attitude(model, epoch, &s, duration_s, stm, te.as_deref(), &opts)).map_err(to_py)?;
        let n = tr.t_tdb.len();
        let states = Array2::from_shape_vec((n, DIM), tr.states).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?.into_pyarray(py);
        Ok((tr.t_tdb.into_pyarray(py), states, tr.stm.map(|p| to_2d(py, &p[..]))))
    }

    /// The total external torque in body axes (inertia units / s^2) at `epoch` and `state` (13).
    fn torque<'py>(&self, py: Python<'py>, epoch: f64, state: PyReadonlyArray1<'_, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let s: [f64; DIM] = state.as_slice()?.try_into().map_err(|_| PyValueError::new_err("invalid argument `state`: must have 13 components"))?;
        self.inner.eph.check_epoch("epoch", epoch).map_err(to_py)?;
        let sys = self.inner.at(epoch).map_err(to_py)?;
        Ok(sys.torque(0.0, &s).to_vec().into_pyarray(py))
    }

    /// CR3BP attitudes (q relative to synodic, w 1/TU) at `epochs` -> ICRF (q, w rad/s); with
    /// `inverse`, the other way.
    #[pyo3(signature = (epochs, q, w, inverse=false))]
    fn place<'py>(&self, py: Python<'py>, epochs: PyReadonlyArray1<'_, f64>, q: PyReadonlyArray2<'_, f64>, w: PyReadonlyArray2<'_, f64>, inverse: bool) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let e = epochs.as_slice()?;
        let (qs, ws) = (rows::<4>("q", &q, e.len())?, rows::<3>("w", &w, e.len())?);
        let mut qo = Vec::with_capacity(e.len());
        let mut wo = Vec::with_capacity(e.len());
        for i in 0..e.len() {
            let f = RotatingFrame::at(&self.inner.eph, e[i]).map_err(to_py)?;
            let (a, b) = if inverse { att::synodic_attitude(&f, &qs[i], &ws[i]) } else { att::place_attitude(&f, &qs[i], &ws[i]) }.map_err(to_py)?;
            qo.push(a);
            wo.push(b);
        }
        Ok((to_2d(py, &qo[..]), to_2d(py, &wo[..])))
    }

    /// The defects (n-1, 6: rotation rad, rate rad/s) and span monodromy of the motion through
    /// the nodes as given.
    #[pyo3(signature = (epochs, orbits, q, w, rtol=1e-12, atol=1e-15))]
    fn legs<'py>(&self, py: Python<'py>, epochs: PyReadonlyArray1<'_, f64>, orbits: PyReadonlyArray2<'_, f64>, q: PyReadonlyArray2<'_, f64>, w: PyReadonlyArray2<'_, f64>, rtol: f64, atol: f64) -> PyResult<Bound<'py, PyDict>> {
        let nodes = nodes(&epochs, &orbits, &q, &w)?;
        let opts = Options::with_tolerances(rtol, atol);
        let model = &self.inner;
        let s = py.detach(|| librate_core::ephemeris::attitude_shooting::evaluate_attitude_legs(model, &nodes, &opts)).map_err(to_py)?;
        shooting_dict(py, &s)
    }

    /// Multiple-shooting correction through the nodes (q, w the guess); a dict with q, w,
    /// defects, monodromy, iterations, reason, converged.
    #[pyo3(signature = (epochs, orbits, q, w, tol=1e-9, max_iter=30, tolerances=(1e-12, 1e-15)))]
    fn correct<'py>(
        &self,
        py: Python<'py>,
        epochs: PyReadonlyArray1<'_, f64>,
        orbits: PyReadonlyArray2<'_, f64>,
        q: PyReadonlyArray2<'_, f64>,
        w: PyReadonlyArray2<'_, f64>,
        tol: f64,
        max_iter: usize,
        tolerances: (f64, f64),
    ) -> PyResult<Bound<'py, PyDict>> {
        use librate_core::ephemeris::attitude_shooting::{correct_attitude, ShootingOptions};
        let nodes = nodes(&epochs, &orbits, &q, &w)?;
        let opts = ShootingOptions { tol, max_iter, integration: Options::with_tolerances(tolerances.0, tolerances.1) };
        let model = &self.inner;
        let s = py.detach(|| correct_attitude(model, &nodes, &opts)).map_err(to_py)?;
        shooting_dict(py, &s)
    }
}

/// The sunlit fraction of the solar disc at `r` with the Sun at `sun` and a sphere of
/// `radius_km` at `body` (any common origin, km).
#[pyfunction]
fn eclipse_fraction(r: [f64; 3], sun: [f64; 3], body: [f64; 3], radius_km: f64) -> f64 {
    eclipse::sunlit_fraction(&r, &sun, &body, radius_km)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<EphemerisAttitudeModel>()?;
    m.add_function(wrap_pyfunction!(eclipse_fraction, m)?)?;
    m.add("R_SUN_KM", eclipse::R_SUN_KM)?;
    m.add("R_EARTH_KM", eclipse::R_EARTH_KM)?;
    m.add("R_MOON_KM", eclipse::R_MOON_KM)?;
    m.add("AU_KM", eclipse::AU_KM)?;
    Ok(())
}
