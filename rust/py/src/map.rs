//! Bindings of the periodicity-map engine.

use librate_core::attitude::{FlatPlate, Sun};
use librate_core::integrate::forcing::OrbitForcing;
use librate_core::integrate::lanes::{Case, LaneOptions, Method};
use librate_core::map;
use librate_core::attitude::{
    correct_across_family, correct_bordered, correct_planar_attitudes, verify_planar_attitudes, Bordered, Candidate, Closure, CorrectorOptions, Free, Parameter, PlanarFamily,
    PlanarStart,
};
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;

use crate::to_py;

/// Gravity-gradient forcing S(t), C(t) of one planar periodic orbit, tabulated once (piecewise
/// Chebyshev) and shared by every attitude trajectory on that orbit.
#[pyclass(frozen, name = "OrbitForcing", module = "librate._core")]
pub struct PyOrbitForcing {
    inner: OrbitForcing,
}

#[pymethods]
impl PyOrbitForcing {
    #[new]
    #[pyo3(signature = (mu, state0, period, *, primaries=[true, true], tol=1e-12))]
    fn new(py: Python<'_>, mu: f64, state0: [f64; 6], period: f64, primaries: [bool; 2], tol: f64) -> PyResult<Self> {
        let inner = py.detach(|| OrbitForcing::new(mu, &state0, period, primaries, tol)).map_err(to_py)?;
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

/// The outcome of `map_sweep`: arrays over the cases (also readable as `r["phi_t"]`).
#[pyclass(frozen, name = "SweepResult", module = "librate._core")]
pub struct PySweepResult {
    phi_t: Py<PyAny>,
    wz_t: Py<PyAny>,
    dwz: Py<PyAny>,
    dphi: Py<PyAny>,
    stm: Option<Py<PyAny>>,
    status: Py<PyAny>,
    steps: Py<PyAny>,
}

const SWEEP_FIELDS: [&str; 7] = ["phi_t", "wz_t", "dwz", "dphi", "stm", "status", "steps"];

#[pymethods]
impl PySweepResult {
    /// Unwrapped phi at t_final, (n,).
    #[getter]
    fn phi_t(&self, py: Python<'_>) -> Py<PyAny> {
        self.phi_t.clone_ref(py)
    }
    /// wz at t_final, (n,).
    #[getter]
    fn wz_t(&self, py: Python<'_>) -> Py<PyAny> {
        self.wz_t.clone_ref(py)
    }
    /// wz(t_final) - wz0, (n,).
    #[getter]
    fn dwz(&self, py: Python<'_>) -> Py<PyAny> {
        self.dwz.clone_ref(py)
    }
    /// phi(t_final) - phi0 wrapped to (-pi, pi], (n,).
    #[getter]
    fn dphi(&self, py: Python<'_>) -> Py<PyAny> {
        self.dphi.clone_ref(py)
    }
    /// The 2x2 STMs (n, 2, 2), or None when not asked.
    #[getter]
    fn stm(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.stm.as_ref().map(|m| m.clone_ref(py))
    }
    /// Lane status per case (0 ok, 1 max steps, 2 failed), uint8 (n,).
    #[getter]
    fn status(&self, py: Python<'_>) -> Py<PyAny> {
        self.status.clone_ref(py)
    }
    /// Accepted and rejected steps per case, (n, 2).
    #[getter]
    fn steps(&self, py: Python<'_>) -> Py<PyAny> {
        self.steps.clone_ref(py)
    }
    /// `r[name]` is `r.name` (the fields of the former dict result).
    fn __getitem__(&self, py: Python<'_>, name: &str) -> PyResult<Option<Py<PyAny>>> {
        Ok(match name {
            "phi_t" => Some(self.phi_t(py)),
            "wz_t" => Some(self.wz_t(py)),
            "dwz" => Some(self.dwz(py)),
            "dphi" => Some(self.dphi(py)),
            "stm" => self.stm(py),
            "status" => Some(self.status(py)),
            "steps" => Some(self.steps(py)),
            _ => return Err(PyKeyError::new_err(format!("{name:?}: SweepResult has {}", SWEEP_FIELDS.join(", ")))),
        })
    }
    fn keys(&self) -> Vec<&'static str> {
        SWEEP_FIELDS.to_vec()
    }
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.phi_t.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("SweepResult(n={}, stm={})", self.__len__(py)?, if self.stm.is_some() { "True" } else { "False" }))
    }
}

/// A per-case float array: the given one (length checked) or zeros.
fn per_case(a: &Option<PyReadonlyArray1<'_, f64>>, name: &str, n: usize) -> PyResult<Vec<f64>> {
    match a {
        None => Ok(vec![0.0; n]),
        Some(v) if v.as_array().len() == n => Ok(v.as_array().to_vec()),
        Some(v) => Err(PyValueError::new_err(format!("invalid argument `{name}`: must have the length of wz0 ({n}), got {}", v.as_array().len()))),
    }
}

/// Integrate planar attitude trajectories (phi0, wz0, kz arrays of one length) over t_final.
#[pyfunction]
#[pyo3(signature = (forcing, t_final, phi0, wz0, kz, *, rtol, atol, max_steps, stm, chunk, threads, eps=None, cs=None, cd=None, theta_sun0=None, method="rkf78"))]
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
    method: &str,
) -> PyResult<PySweepResult> {
    let method = Method::parse(method).ok_or_else(|| PyValueError::new_err(format!("invalid argument `method`: must be 'rkf78', 'rkn86' or 'dp87', got {method:?}")))?;
    let (p, w, k) = (phi0.as_array(), wz0.as_array(), kz.as_array());
    if p.len() != w.len() || k.len() != w.len() {
        return Err(PyValueError::new_err(format!("invalid argument: phi0, wz0 and kz must have one length, got {}, {}, {}", p.len(), w.len(), k.len())));
    }
    let n = w.len();
    let (e, s, d, th) = (per_case(&eps, "eps", n)?, per_case(&cs, "cs", n)?, per_case(&cd, "cd", n)?, per_case(&theta_sun0, "theta_sun0", n)?);
    let cases: Vec<Case> = (0..n).map(|i| Case { eps: e[i], cs: s[i], cd: d[i], theta_sun0: th[i], ..Case::new(p[i], w[i], k[i]) }).collect();
    let opts = LaneOptions { rtol, atol, max_steps, method, ..LaneOptions::default() };
    let f = &forcing.inner;
    let out = py.detach(|| map::sweep(f, t_final, &cases, &opts, stm, chunk, threads)).map_err(to_py)?;
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
    Ok(PySweepResult {
        phi_t: phi_t.into_pyarray(py).into_any().unbind(),
        wz_t: wz_t.into_pyarray(py).into_any().unbind(),
        dwz: dwz.into_pyarray(py).into_any().unbind(),
        dphi: dphi.into_pyarray(py).into_any().unbind(),
        stm: if stm { Some(m.into_pyarray(py).reshape([n, 2, 2])?.into_any().unbind()) } else { None },
        status: status.into_pyarray(py).into_any().unbind(),
        steps: steps.into_pyarray(py).reshape([n, 2])?.into_any().unbind(),
    })
}

/// The outcome of `attitude_correct`: arrays over the candidates.
#[pyclass(frozen, name = "CorrectionBatch", module = "librate._core")]
pub struct PyCorrectionBatch {
    phi0: Py<PyAny>,
    wz0: Py<PyAny>,
    theta_sun0: Py<PyAny>,
    residual: Py<PyAny>,
    residual_norm: Py<PyAny>,
    iterations: Py<PyAny>,
    converged: Py<PyAny>,
    reason: Vec<&'static str>,
    monodromy: Py<PyAny>,
    parameter: Py<PyAny>,
    jacobian: Py<PyAny>,
}

#[pymethods]
impl PyCorrectionBatch {
    /// Final phi0 (kept unless free="phi0" with closure="full"), (n,).
    #[getter]
    fn phi0(&self, py: Python<'_>) -> Py<PyAny> {
        self.phi0.clone_ref(py)
    }
    /// Final inertial wz0, (n,).
    #[getter]
    fn wz0(&self, py: Python<'_>) -> Py<PyAny> {
        self.wz0.clone_ref(py)
    }
    /// Final Sun phase (kept unless free="sun_phase"; not wrapped), (n,).
    #[getter]
    fn theta_sun0(&self, py: Python<'_>) -> Py<PyAny> {
        self.theta_sun0.clone_ref(py)
    }
    /// Residuals (n, 2): full (dphi, dwz); half (phi(KT/2) - phi0 - pi turns, NaN).
    #[getter]
    fn residual(&self, py: Python<'_>) -> Py<PyAny> {
        self.residual.clone_ref(py)
    }
    /// Max-norm of the residual, (n,) (NaN when the start could not be integrated).
    #[getter]
    fn residual_norm(&self, py: Python<'_>) -> Py<PyAny> {
        self.residual_norm.clone_ref(py)
    }
    /// Accepted Newton steps, int64 (n,).
    #[getter]
    fn iterations(&self, py: Python<'_>) -> Py<PyAny> {
        self.iterations.clone_ref(py)
    }
    /// reason == "converged", bool (n,).
    #[getter]
    fn converged(&self, py: Python<'_>) -> Py<PyAny> {
        self.converged.clone_ref(py)
    }
    /// Why each candidate stopped: "converged", "max_iterations", "singular_jacobian",
    /// "no_descent" or "integration_failed".
    #[getter]
    fn reason(&self) -> Vec<&'static str> {
        self.reason.clone()
    }
    /// Full-period (K T) 2x2 monodromy at the final point, (n, 2, 2).
    #[getter]
    fn monodromy(&self, py: Python<'_>) -> Py<PyAny> {
        self.monodromy.clone_ref(py)
    }
    /// The freed parameter's final value (bordered corrections; else each candidate's Kz), (n,).
    #[getter]
    fn parameter(&self, py: Python<'_>) -> Py<PyAny> {
        self.parameter.clone_ref(py)
    }
    /// d F / d (angle, wz0, parameter) at the final point, (n, 2, 3); NaN where not computed.
    #[getter]
    fn jacobian(&self, py: Python<'_>) -> Py<PyAny> {
        self.jacobian.clone_ref(py)
    }
    fn __len__(&self) -> usize {
        self.reason.len()
    }
    fn __repr__(&self) -> String {
        let c = self.reason.iter().filter(|r| **r == "converged").count();
        format!("CorrectionBatch(n={}, converged={c})", self.reason.len())
    }
}

/// Correct many candidates at once to periodic planar attitude motions along the forcing's orbit
/// (one Rust call for all Newton iterations; see librate_core::attitude::correct_planar_attitudes).
#[pyfunction]
#[pyo3(signature = (forcing, phi0, wz0, kz, turns, *, t_final, closure, free="phi0", eps=None, cs=None, cd=None, theta_sun0=None,
    tol=1e-12, max_iter=40, rtol=1e-13, atol=1e-13, max_steps=200_000, max_wz_step=0.5, max_angle_step=0.5, threads=None, chunk=64,
    parameter=None, condition=None, parameter_step=1e-6, max_parameter_step=0.5, monodromy=true, max_halvings=10, conditions=None))]
fn attitude_correct<'py>(
    py: Python<'py>,
    forcing: PyRef<'py, PyOrbitForcing>,
    phi0: PyReadonlyArray1<'py, f64>,
    wz0: PyReadonlyArray1<'py, f64>,
    kz: PyReadonlyArray1<'py, f64>,
    turns: PyReadonlyArray1<'py, f64>,
    t_final: f64,
    closure: &str,
    free: &str,
    eps: Option<PyReadonlyArray1<'py, f64>>,
    cs: Option<PyReadonlyArray1<'py, f64>>,
    cd: Option<PyReadonlyArray1<'py, f64>>,
    theta_sun0: Option<PyReadonlyArray1<'py, f64>>,
    tol: f64,
    max_iter: usize,
    rtol: f64,
    atol: f64,
    max_steps: u32,
    max_wz_step: f64,
    max_angle_step: f64,
    threads: Option<usize>,
    chunk: usize,
    parameter: Option<&str>,
    condition: Option<(f64, f64, f64, f64)>,
    parameter_step: f64,
    max_parameter_step: f64,
    monodromy: bool,
    max_halvings: u32,
    conditions: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<PyCorrectionBatch> {
    let bordered = match (parameter, condition) {
        (None, None) => None,
        (Some(name), Some((a0, a1, a2, b))) => {
            let parameter = match name {
                "kz" => Parameter::Kz,
                "eps" => Parameter::Eps,
                other => return Err(PyValueError::new_err(format!("invalid argument `parameter`: must be 'kz' or 'eps', got {other:?}"))),
            };
            Some(Bordered { parameter, a: [a0, a1, a2], b, step: parameter_step, max_step: max_parameter_step })
        }
        _ => return Err(PyValueError::new_err("invalid argument `condition`: `parameter` and `condition` (a_angle, a_wz0, a_parameter, b) go together")),
    };
    let closure = match closure {
        "half" => Closure::Half,
        "full" => Closure::Full,
        other => return Err(PyValueError::new_err(format!("invalid argument `closure`: must be 'half' or 'full', got {other:?}"))),
    };
    let free = match free {
        "phi0" => Free::Phi0,
        "sun_phase" => Free::SunPhase,
        other => return Err(PyValueError::new_err(format!("invalid argument `free`: must be 'phi0' or 'sun_phase', got {other:?}"))),
    };
    let (p, w, k, tu) = (phi0.as_array(), wz0.as_array(), kz.as_array(), turns.as_array());
    let n = w.len();
    if p.len() != n || k.len() != n || tu.len() != n {
        return Err(PyValueError::new_err(format!("invalid argument: phi0, wz0, kz and turns must have one length, got {}, {}, {}, {}", p.len(), n, k.len(), tu.len())));
    }
    let (e, s, d, th) = (per_case(&eps, "eps", n)?, per_case(&cs, "cs", n)?, per_case(&cd, "cd", n)?, per_case(&theta_sun0, "theta_sun0", n)?);
    let mut cands: Vec<Candidate> = (0..n).map(|i| Candidate::new(p[i], w[i], k[i], tu[i]).with_plate(e[i], s[i], d[i], th[i])).collect();
    if let Some(c) = &conditions {
        let c = c.as_array();
        if bordered.is_none() || c.shape() != [n, 4] {
            return Err(PyValueError::new_err(format!(
                "invalid argument `conditions`: one row (a_angle, a_wz0, a_parameter, b) per candidate, shape ({n}, 4), with `parameter` and `condition`; got shape {:?}",
                c.shape()
            )));
        }
        for (i, cand) in cands.iter_mut().enumerate() {
            *cand = cand.with_condition([c[[i, 0]], c[[i, 1]], c[[i, 2]]], c[[i, 3]]);
        }
    }
    let opts = CorrectorOptions { tol, max_iter, rtol, atol, max_steps, max_wz_step, max_angle_step, threads, chunk, monodromy, max_halvings, ..CorrectorOptions::default() };
    let f = &forcing.inner;
    let out = py
        .detach(|| match &bordered {
            None => correct_planar_attitudes(f, t_final, closure, free, &cands, &opts),
            Some(b) => correct_bordered(f, t_final, closure, free, b, &cands, &opts),
        })
        .map_err(to_py)?;
    batch_from(py, &out)
}

fn batch_from(py: Python<'_>, out: &[librate_core::attitude::Correction]) -> PyResult<PyCorrectionBatch> {
    let n = out.len();
    let col = |g: &dyn Fn(&librate_core::attitude::Correction) -> f64| out.iter().map(g).collect::<Vec<f64>>();
    Ok(PyCorrectionBatch {
        phi0: col(&|c| c.phi0).into_pyarray(py).into_any().unbind(),
        wz0: col(&|c| c.wz0).into_pyarray(py).into_any().unbind(),
        theta_sun0: col(&|c| c.theta_sun0).into_pyarray(py).into_any().unbind(),
        residual: out.iter().flat_map(|c| c.residual).collect::<Vec<f64>>().into_pyarray(py).reshape([n, 2])?.into_any().unbind(),
        residual_norm: col(&|c| c.residual_norm).into_pyarray(py).into_any().unbind(),
        iterations: out.iter().map(|c| c.iterations as i64).collect::<Vec<i64>>().into_pyarray(py).into_any().unbind(),
        converged: out.iter().map(|c| c.converged()).collect::<Vec<bool>>().into_pyarray(py).into_any().unbind(),
        reason: out.iter().map(|c| c.reason.as_str()).collect(),
        monodromy: out.iter().flat_map(|c| c.monodromy).collect::<Vec<f64>>().into_pyarray(py).reshape([n, 2, 2])?.into_any().unbind(),
        parameter: col(&|c| c.parameter).into_pyarray(py).into_any().unbind(),
        jacobian: out.iter().flat_map(|c| c.jacobian.into_iter().flatten()).collect::<Vec<f64>>().into_pyarray(py).reshape([n, 2, 3])?.into_any().unbind(),
    })
}

/// A planar symmetric orbit family (members' x0 and vy0) from which the orbit through any x0 in
/// range is corrected and tabulated on demand (cached): the data of `attitude_correct_across`.
#[pyclass(frozen, name = "PlanarFamily", module = "librate._core")]
pub struct PyPlanarFamily {
    inner: PlanarFamily,
}

#[pymethods]
impl PyPlanarFamily {
    #[new]
    fn new(mu: f64, x0: Vec<f64>, vy0: Vec<f64>) -> PyResult<Self> {
        Ok(Self { inner: PlanarFamily::new(mu, &x0, &vy0).map_err(to_py)? })
    }
    /// The members' x0 range (lo, hi).
    #[getter]
    fn range(&self) -> (f64, f64) {
        self.inner.range()
    }
    /// (state0, period) of the family's orbit through x0 (corrected, cached).
    fn orbit_at(&self, py: Python<'_>, x0: f64) -> PyResult<([f64; 6], f64)> {
        let o = py.detach(|| self.inner.orbit_at(x0)).map_err(to_py)?;
        Ok((o.0.state0, o.0.period))
    }
}

/// The half-period correction with the orbit's x0 freed across a planar family, closed by the
/// linear condition a_wz0 wz0 + a_x0 x0 = b (librate_core::attitude::correct_across_family).
#[pyfunction]
#[pyo3(signature = (family, wz0, kz, turns, x0, *, condition, phi0=0.0, tol=1e-12, max_iter=40, rtol=1e-13, atol=1e-13, max_steps=200_000,
    max_wz_step=0.5, parameter_step=1e-6, max_parameter_step=0.05, threads=None, max_halvings=10))]
fn attitude_correct_across<'py>(
    py: Python<'py>,
    family: PyRef<'py, PyPlanarFamily>,
    wz0: PyReadonlyArray1<'py, f64>,
    kz: PyReadonlyArray1<'py, f64>,
    turns: PyReadonlyArray1<'py, f64>,
    x0: PyReadonlyArray1<'py, f64>,
    condition: (f64, f64, f64),
    phi0: f64,
    tol: f64,
    max_iter: usize,
    rtol: f64,
    atol: f64,
    max_steps: u32,
    max_wz_step: f64,
    parameter_step: f64,
    max_parameter_step: f64,
    threads: Option<usize>,
    max_halvings: u32,
) -> PyResult<PyCorrectionBatch> {
    let (w, k, tu, x) = (wz0.as_array(), kz.as_array(), turns.as_array(), x0.as_array());
    let n = w.len();
    if k.len() != n || tu.len() != n || x.len() != n {
        return Err(PyValueError::new_err(format!("invalid argument: wz0, kz, turns and x0 must have one length, got {}, {}, {}, {}", n, k.len(), tu.len(), x.len())));
    }
    let cands: Vec<Candidate> = (0..n).map(|i| Candidate::new(phi0, w[i], k[i], tu[i]).with_x0(x[i])).collect();
    let bordered = Bordered { parameter: Parameter::OrbitX0, a: [0.0, condition.0, condition.1], b: condition.2, step: parameter_step, max_step: max_parameter_step };
    let opts = CorrectorOptions { tol, max_iter, rtol, atol, max_steps, max_wz_step, threads, max_halvings, ..CorrectorOptions::default() };
    let fam = &family.inner;
    let out = py.detach(|| correct_across_family(fam, &bordered, &cands, &opts)).map_err(to_py)?;
    batch_from(py, &out)
}

/// The outcome of `planar_verify`: arrays over the items.
#[pyclass(frozen, name = "PlanarVerification", module = "librate._core")]
pub struct PyPlanarVerification {
    phi_t: Py<PyAny>,
    wz_t: Py<PyAny>,
    stm: Py<PyAny>,
    error: Vec<Option<String>>,
}

#[pymethods]
impl PyPlanarVerification {
    /// Unwrapped phi at t_final, (n,) (NaN where the integration failed).
    #[getter]
    fn phi_t(&self, py: Python<'_>) -> Py<PyAny> {
        self.phi_t.clone_ref(py)
    }
    /// wz at t_final, (n,).
    #[getter]
    fn wz_t(&self, py: Python<'_>) -> Py<PyAny> {
        self.wz_t.clone_ref(py)
    }
    /// d(phi, wz)(t_final) / d(phi0, wz0), (n, 2, 2).
    #[getter]
    fn stm(&self, py: Python<'_>) -> Py<PyAny> {
        self.stm.clone_ref(py)
    }
    /// The integration error message per item, or None.
    #[getter]
    fn error(&self) -> Vec<Option<String>> {
        self.error.clone()
    }
    fn __len__(&self) -> usize {
        self.error.len()
    }
    fn __repr__(&self) -> String {
        format!("PlanarVerification(n={}, failed={})", self.error.len(), self.error.iter().filter(|e| e.is_some()).count())
    }
}

/// Independent re-propagation of planar attitude motions (scalar model, orbit integrated
/// alongside, rtol = atol = 1e-14) in parallel; a plate where eps is given and non-zero.
#[pyfunction]
#[pyo3(signature = (mu, orbit_state0, t_final, kz, phi0, wz0, *, eps=None, cs=None, cd=None, theta_sun0=None, primaries=[true, true], threads=None))]
fn planar_verify<'py>(
    py: Python<'py>,
    mu: f64,
    orbit_state0: [f64; 6],
    t_final: f64,
    kz: PyReadonlyArray1<'py, f64>,
    phi0: PyReadonlyArray1<'py, f64>,
    wz0: PyReadonlyArray1<'py, f64>,
    eps: Option<PyReadonlyArray1<'py, f64>>,
    cs: Option<PyReadonlyArray1<'py, f64>>,
    cd: Option<PyReadonlyArray1<'py, f64>>,
    theta_sun0: Option<PyReadonlyArray1<'py, f64>>,
    primaries: [bool; 2],
    threads: Option<usize>,
) -> PyResult<PyPlanarVerification> {
    let (p, w, k) = (phi0.as_array(), wz0.as_array(), kz.as_array());
    let n = w.len();
    if p.len() != n || k.len() != n {
        return Err(PyValueError::new_err(format!("invalid argument: kz, phi0 and wz0 must have one length, got {}, {}, {}", k.len(), p.len(), n)));
    }
    let (e, s, d, th) = (per_case(&eps, "eps", n)?, per_case(&cs, "cs", n)?, per_case(&cd, "cd", n)?, per_case(&theta_sun0, "theta_sun0", n)?);
    let items = (0..n)
        .map(|i| {
            let plate = if e[i] != 0.0 { Some(FlatPlate::new(e[i], s[i], d[i], Sun { theta0: th[i], ..Sun::default() }).map_err(to_py)?) } else { None };
            Ok(PlanarStart { kz: k[i], phi0: p[i], wz0: w[i], plate })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let out = py.detach(|| verify_planar_attitudes(mu, &orbit_state0, t_final, &items, primaries, threads)).map_err(to_py)?;
    Ok(PyPlanarVerification {
        phi_t: out.iter().map(|o| o.phi_t).collect::<Vec<f64>>().into_pyarray(py).into_any().unbind(),
        wz_t: out.iter().map(|o| o.wz_t).collect::<Vec<f64>>().into_pyarray(py).into_any().unbind(),
        stm: out.iter().flat_map(|o| o.stm).collect::<Vec<f64>>().into_pyarray(py).reshape([n, 2, 2])?.into_any().unbind(),
        error: out.iter().map(|o| o.error.as_ref().map(|e| e.to_string())).collect(),
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOrbitForcing>()?;
    m.add_class::<PySweepResult>()?;
    m.add_class::<PyCorrectionBatch>()?;
    m.add_class::<PyPlanarVerification>()?;
    m.add_function(wrap_pyfunction!(map_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(attitude_correct, m)?)?;
    m.add_class::<PyPlanarFamily>()?;
    m.add_function(wrap_pyfunction!(attitude_correct_across, m)?)?;
    m.add_function(wrap_pyfunction!(planar_verify, m)?)?;
    Ok(())
}
