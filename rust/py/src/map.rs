//! Bindings of the periodicity-map engine.

use librate_core::map::{self, Case, LaneOptions};
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::to_py;

/// Gravity-gradient forcing S(t), C(t) of one planar periodic orbit, tabulated once (piecewise
/// Chebyshev) and shared by every attitude trajectory on that orbit.
#[pyclass(frozen, name = "OrbitForcing", module = "librate._core")]
pub struct PyOrbitForcing {
    inner: map::OrbitForcing,
}

#[pymethods]
impl PyOrbitForcing {
    #[new]
    #[pyo3(signature = (mu, state0, period, *, primaries=[true, true], tol=1e-12))]
    fn new(py: Python<'_>, mu: f64, state0: [f64; 6], period: f64, primaries: [bool; 2], tol: f64) -> PyResult<Self> {
        let inner = py.detach(|| map::OrbitForcing::new(mu, &state0, period, primaries, tol)).map_err(to_py)?;
        Ok(Self { inner })
    }
    #[getter]
    fn period(&self) -> f64 {
        self.inner.period
    }
    #[getter]
    fn segments(&self) -> usize {
        self.inner.segments()
    }
    #[getter]
    fn max_error(&self) -> f64 {
        self.inner.max_error
    }
    /// (S, C) at the given times.
    fn sc<'py>(&self, py: Python<'py>, t: PyReadonlyArray1<'py, f64>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (s, c): (Vec<f64>, Vec<f64>) = t.as_array().iter().map(|&ti| self.inner.sc(ti)).unzip();
        Ok((s.into_pyarray(py).into_any(), c.into_pyarray(py).into_any()))
    }
}

/// Integrate planar attitude trajectories (phi0, wz0, kz arrays of one length) over t_final.
#[pyfunction]
#[pyo3(signature = (forcing, t_final, phi0, wz0, kz, *, rtol, atol, max_steps, stm, chunk, threads, eps=None, cs=None, cd=None, theta_sun0=None))]
#[allow(clippy::too_many_arguments)]
fn map_sweep<'py>(
    py: Python<'py>,
    forcing: PyRef<'py, PyOrbitForcing>,
    t_final: f64,
    phi0: PyReadonlyArray1<'py, f64>,
    wz0: PyReadonlyArray1<'py, f64>,
    kz: PyReadonlyArray1<'py, f64>,
    rtol: f64,
    atol: f64,
    max_steps: u32,
    stm: bool,
    chunk: usize,
    threads: Option<usize>,
    eps: Option<PyReadonlyArray1<'py, f64>>,
    cs: Option<PyReadonlyArray1<'py, f64>>,
    cd: Option<PyReadonlyArray1<'py, f64>>,
    theta_sun0: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (p, w, k) = (phi0.as_array(), wz0.as_array(), kz.as_array());
    if p.len() != w.len() || k.len() != w.len() {
        return Err(PyValueError::new_err(format!("invalid argument: phi0, wz0 and kz must have one length, got {}, {}, {}", p.len(), w.len(), k.len())));
    }
    let extra = |a: &Option<PyReadonlyArray1<'py, f64>>, name: &str| -> PyResult<Vec<f64>> {
        match a {
            None => Ok(vec![0.0; w.len()]),
            Some(v) if v.as_array().len() == w.len() => Ok(v.as_array().to_vec()),
            Some(v) => Err(PyValueError::new_err(format!("invalid argument `{name}`: must have the length of wz0 ({}), got {}", w.len(), v.as_array().len()))),
        }
    };
    let (e, s, d, th) = (extra(&eps, "eps")?, extra(&cs, "cs")?, extra(&cd, "cd")?, extra(&theta_sun0, "theta_sun0")?);
    let cases: Vec<Case> = (0..w.len()).map(|i| Case { eps: e[i], cs: s[i], cd: d[i], theta_sun0: th[i], ..Case::new(p[i], w[i], k[i]) }).collect();
    let opts = LaneOptions { rtol, atol, max_steps, ..LaneOptions::default() };
    let f = &forcing.inner;
    let out = py.detach(|| map::sweep(f, t_final, &cases, &opts, stm, chunk, threads)).map_err(to_py)?;
    let n = out.len();
    let (mut phi_t, mut wz_t, mut dwz, mut dphi) = (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
    let mut m = Vec::with_capacity(if stm { 4 * n } else { 0 });
    let mut status = Vec::with_capacity(n);
    let mut steps = Vec::with_capacity(2 * n);
    for (c, o) in cases.iter().zip(&out) {
        let (a, b) = map::residuals(c, o);
        phi_t.push(o.phi_t);
        wz_t.push(o.wz_t);
        dwz.push(a);
        dphi.push(b);
        if stm {
            m.extend_from_slice(&o.stm);
        }
        status.push(o.status as u8);
        steps.extend([o.accepted, o.rejected]);
    }
    let d = PyDict::new(py);
    d.set_item("phi_t", phi_t.into_pyarray(py))?;
    d.set_item("wz_t", wz_t.into_pyarray(py))?;
    d.set_item("dwz", dwz.into_pyarray(py))?;
    d.set_item("dphi", dphi.into_pyarray(py))?;
    d.set_item("stm", if stm { Some(m.into_pyarray(py).reshape([n, 2, 2])?) } else { None })?;
    d.set_item("status", status.into_pyarray(py))?;
    d.set_item("steps", steps.into_pyarray(py).reshape([n, 2])?)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOrbitForcing>()?;
    m.add_function(wrap_pyfunction!(map_sweep, m)?)?;
    Ok(())
}
