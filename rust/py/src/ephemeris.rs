//! Thin wrappers of librate_core::ephemeris: an `EphemerisCore` built from SPK type-2 segments
//! (read in Python), its states, rotating frame, synodic maps and propagation.

use librate_core::ephemeris::{self as eph, Ephemeris, EphemerisDynamics, RotatingFrame, Segment, TransitionSettings};
use librate_core::integrate::Options;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{fixed, rows};
use crate::errors::{invalid, to_py};

/// The ephemeris (Chebyshev segments evaluated in Rust).
#[pyclass(module = "librate._core", frozen)]
pub struct EphemerisCore {
    pub(crate) inner: Ephemeris,
}

#[pymethods]
impl EphemerisCore {
    /// segments: list of (target, center, start_s, end_s, init_s, intlen_s, coefficients (n, 3, k)).
    #[new]
    fn new(segments: Vec<(i32, i32, f64, f64, f64, f64, PyReadonlyArray3<'_, f64>)>) -> PyResult<Self> {
        let mut out = Vec::with_capacity(segments.len());
        for (t, c, s, e, i, l, coef) in segments {
            let sh = coef.shape();
            if sh[1] != 3 {
                return Err(invalid(format!("`coefficients` must have shape (n_records, 3, n_coef), got {sh:?}")));
            }
            let v: Vec<f64> = coef.as_array().iter().copied().collect();
            out.push(Segment::new(t, c, s, e, i, l, sh[0], sh[2], v).map_err(to_py)?);
        }
        Ok(Self { inner: Ephemeris::new(out).map_err(to_py)? })
    }

    /// (start, end) TDB s past J2000.
    fn span(&self) -> (f64, f64) {
        self.inner.span()
    }

    /// State of target relative to center at t (km, km/s).
    fn state<'py>(&self, py: Python<'py>, target: i32, center: i32, t: f64) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(self.inner.state(target, center, t).map_err(to_py)?.to_vec().into_pyarray(py))
    }

    /// The rotating frame at t: dict distance_km, distance_rate_km_s, rate_rad_s, axes (3x3 rows), omega.
    fn frame<'py>(&self, py: Python<'py>, t: f64) -> PyResult<Bound<'py, PyDict>> {
        let f = RotatingFrame::at(&self.inner, t).map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("distance_km", f.distance_km)?;
        d.set_item("distance_rate_km_s", f.distance_rate_km_s)?;
        d.set_item("rate_rad_s", f.rate_rad_s)?;
        d.set_item("axes", f.axes.iter().flatten().copied().collect::<Vec<f64>>().into_pyarray(py).reshape([3, 3])?)?;
        d.set_item("omega", f.omega.to_vec().into_pyarray(py))?;
        Ok(d)
    }

    /// Synodic (nondimensional) state -> Moon-centred ICRF state at t.
    fn synodic_to_ephemeris<'py>(&self, py: Python<'py>, t: f64, mu: f64, state: PyReadonlyArray1<'_, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let f = RotatingFrame::at(&self.inner, t).map_err(to_py)?;
        let s = fixed::<6>("state", state.as_slice()?)?;
        Ok(eph::synodic_to_ephemeris(&f, mu, &s).map_err(to_py)?.to_vec().into_pyarray(py))
    }

    /// Moon-centred ICRF state at t -> synodic state.
    fn ephemeris_to_synodic<'py>(&self, py: Python<'py>, t: f64, mu: f64, state_km: PyReadonlyArray1<'_, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let f = RotatingFrame::at(&self.inner, t).map_err(to_py)?;
        let s = fixed::<6>("state_km", state_km.as_slice()?)?;
        Ok(eph::ephemeris_to_synodic(&f, mu, &s).map_err(to_py)?.to_vec().into_pyarray(py))
    }

    /// Propagate; returns (t_tdb, states (n, 6), stm (6, 6) or None). `t_eval` are offsets (s)
    /// from the epoch; None records every step. `gm` (Earth, Moon, Sun) defaults to DE440's.
    #[pyo3(signature = (state_km, epoch, duration_s, stm=false, t_eval=None, rtol=1e-13, atol=1e-9, gm=None))]
    fn propagate<'py>(
        &self,
        py: Python<'py>,
        state_km: PyReadonlyArray1<'_, f64>,
        epoch: f64,
        duration_s: f64,
        stm: bool,
        t_eval: Option<PyReadonlyArray1<'_, f64>>,
        rtol: f64,
        atol: f64,
        gm: Option<[f64; 3]>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray2<f64>>>)> {
        let s = fixed::<6>("state_km", state_km.as_slice()?)?;
        let te: Option<Vec<f64>> = match &t_eval {
            Some(a) => Some(a.as_slice()?.to_vec()),
            None => None,
        };
        let dynamics = EphemerisDynamics::with_gm(self.inner.clone(), epoch, gm.unwrap_or([eph::GM_EARTH, eph::GM_MOON, eph::GM_SUN])).map_err(to_py)?;
        let opts = Options::with_tolerances(rtol, atol);
        let tr = py.detach(|| eph::propagate_ephemeris(&dynamics, &s, duration_s, stm, te.as_deref(), &opts)).map_err(to_py)?;
        let n = tr.t_tdb.len();
        let states = Array2::from_shape_vec((n, 6), tr.states).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?.into_pyarray(py);
        let phi = match tr.stm {
            Some(p) => Some(Array2::from_shape_vec((6, 6), p.to_vec()).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?.into_pyarray(py)),
            None => None,
        };
        Ok((tr.t_tdb.into_pyarray(py), states, phi))
    }
    /// Propagate many legs, `states_km` (n, 6) from `epochs` (n,) for `durations_s` (n,), on all
    /// cores (each leg alone: the results do not depend on the thread count); only the final
    /// states (and STMs) are kept. Returns (finals (n, 6), stms (n, 6, 6) or None, errors
    /// {index: exception}): a failed leg's rows are NaN and its typed error is in `errors`.
    #[pyo3(signature = (states_km, epochs, durations_s, stm=false, integration=(1e-13, 1e-9)))]
    fn propagate_batch<'py>(
        &self,
        py: Python<'py>,
        states_km: PyReadonlyArray2<'_, f64>,
        epochs: PyReadonlyArray1<'_, f64>,
        durations_s: PyReadonlyArray1<'_, f64>,
        stm: bool,
        integration: (f64, f64),
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray3<f64>>>, Bound<'py, PyDict>)> {
        let states = rows::<6>(&states_km, "states_km", None)?;
        let n = states.len();
        let epochs = epochs.as_slice()?.to_vec();
        let durations = durations_s.as_slice()?.to_vec();
        if epochs.len() != n || durations.len() != n {
            return Err(invalid(format!("invalid argument `epochs`, `durations_s`: one per state ({n}), got {} and {}", epochs.len(), durations.len())));
        }
        let legs: Vec<([f64; 6], f64, f64)> = (0..n).map(|i| (states[i], epochs[i], durations[i])).collect();
        let opts = Options::with_tolerances(integration.0, integration.1);
        let gm = [eph::GM_EARTH, eph::GM_MOON, eph::GM_SUN];
        let results = py.detach(|| eph::propagate_ephemeris_batch(&self.inner, gm, &legs, stm, &opts));
        let mut finals = Vec::with_capacity(n * 6);
        let mut phis = Vec::with_capacity(if stm { n * 36 } else { 0 });
        let errors = PyDict::new(py);
        for (i, r) in results.into_iter().enumerate() {
            match r {
                Ok(tr) => {
                    finals.extend_from_slice(&tr.state_final);
                    if stm {
                        phis.extend_from_slice(&tr.stm.unwrap_or([f64::NAN; 36]));
                    }
                }
                Err(e) => {
                    finals.extend([f64::NAN; 6]);
                    if stm {
                        phis.extend([f64::NAN; 36]);
                    }
                    errors.set_item(i, to_py(e).into_value(py))?;
                }
            }
        }
        let shape_err = |e: numpy::ndarray::ShapeError| pyo3::exceptions::PyRuntimeError::new_err(e.to_string());
        let finals = Array2::from_shape_vec((n, 6), finals).map_err(shape_err)?.into_pyarray(py);
        let phis = if stm { Some(Array3::from_shape_vec((n, 6, 6), phis).map_err(shape_err)?.into_pyarray(py)) } else { None };
        Ok((finals, phis, errors))
    }
    /// The multiple-shooting transition of guess nodes (n, 6) at `epochs` (n,) to a continuous
    /// trajectory of the model. `tol` = (km, km/s) per leg; `scales` = (length km, time s) of
    /// the unknowns; `integration` = (rtol, atol). Returns a dict: states_km, epochs_tdb,
    /// iterations, reason, defects_km, defects_km_s, history.
    #[pyo3(signature = (states_km, epochs, tol, scales, epoch_free=false, max_iter=30, integration=(1e-13, 1e-9), gm=None))]
    fn transition<'py>(
        &self,
        py: Python<'py>,
        states_km: PyReadonlyArray2<'_, f64>,
        epochs: PyReadonlyArray1<'_, f64>,
        tol: (f64, f64),
        scales: (f64, f64),
        epoch_free: bool,
        max_iter: usize,
        integration: (f64, f64),
        gm: Option<[f64; 3]>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let a = states_km.as_array();
        if a.ncols() != 6 {
            return Err(pyo3::exceptions::PyValueError::new_err(format!("`states_km` must have shape (n, 6), got {:?}", a.shape())));
        }
        let states: Vec<[f64; 6]> = a.rows().into_iter().map(|r| std::array::from_fn(|j| r[j])).collect();
        let epochs = epochs.as_slice()?.to_vec();
        let settings = TransitionSettings { tol_km: tol.0, tol_km_s: tol.1, max_iter, epoch_free, length_km: scales.0, time_s: scales.1 };
        let opts = Options::with_tolerances(integration.0, integration.1);
        let gm = gm.unwrap_or([eph::GM_EARTH, eph::GM_MOON, eph::GM_SUN]);
        let tr = py.detach(|| eph::transition(&self.inner, gm, &states, &epochs, &settings, &opts)).map_err(to_py)?;
        let n = tr.states.len();
        let flat: Vec<f64> = tr.states.iter().flatten().copied().collect();
        let d = PyDict::new(py);
        d.set_item("states_km", Array2::from_shape_vec((n, 6), flat).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?.into_pyarray(py))?;
        d.set_item("epochs_tdb", tr.epochs.into_pyarray(py))?;
        d.set_item("iterations", tr.iterations)?;
        d.set_item("reason", tr.reason.as_str())?;
        d.set_item("defects_km", tr.defects_km.into_pyarray(py))?;
        d.set_item("defects_km_s", tr.defects_km_s.into_pyarray(py))?;
        d.set_item("history", tr.history.into_pyarray(py))?;
        Ok(d)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<EphemerisCore>()?;
    m.add("GM_EARTH", eph::GM_EARTH)?;
    m.add("GM_MOON", eph::GM_MOON)?;
    m.add("GM_SUN", eph::GM_SUN)?;
    Ok(())
}
