//! Bindings of the periodicity-map engine.

use librate_core::attitude::{FlatPlate, Sun};
use librate_core::integrate::forcing::OrbitForcing;
use librate_core::integrate::lanes::Case;
use librate_core::map;
use std::sync::{Arc, Mutex};

use librate_core::attitude::{correct_across_family, correct_bordered, correct_planar_attitudes, distinct, full_closure_residual, refine_planar_attitudes, verify_planar_attitudes, Candidate, Parameter, PlanarFamily, PlanarOrbit, PlanarStart, Refined, SolutionKey};
use librate_core::threads::Pending;
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyRuntimeError;
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;

use crate::convert::vector;
use crate::errors::invalid;
use crate::options::{Bordered, Closure, CorrectorOptions, Free, LaneOptions, PlanarCases};
use crate::interrupt::{interruptible, join, start};
use crate::to_py;

/// Gravity-gradient forcing S(t), C(t) of one planar periodic orbit, tabulated once (piecewise
/// Chebyshev) and shared by every attitude trajectory on that orbit.
#[pyclass(frozen, name = "OrbitForcing", module = "librate._core")]
pub struct PyOrbitForcing {
    inner: Arc<OrbitForcing>,
    /// The orbit tabulated, for the independent re-propagations of `attitude_refine`.
    mu: f64,
    state0: [f64; 6],
    primaries: [bool; 2],
}

#[pymethods]
impl PyOrbitForcing {
    #[new]
    #[pyo3(signature = (mu, state0, period, *, primaries=[true, true], tol=1e-12))]
    fn new(py: Python<'_>, mu: f64, state0: [f64; 6], period: f64, primaries: [bool; 2], tol: f64) -> PyResult<Self> {
        let inner = py.detach(|| OrbitForcing::new(mu, &state0, period, primaries, tol)).map_err(to_py)?;
        Ok(Self { inner: Arc::new(inner), mu, state0, primaries })
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
#[pyclass(frozen, get_all, name = "SweepResult", module = "librate._core")]
pub struct PySweepResult {
    /// Unwrapped phi at t_final, (n,).
    phi_t: Py<PyAny>,
    /// wz at t_final, (n,).
    wz_t: Py<PyAny>,
    /// wz(t_final) - wz0, (n,).
    dwz: Py<PyAny>,
    /// phi(t_final) - phi0 wrapped to (-pi, pi], (n,).
    dphi: Py<PyAny>,
    /// The 2x2 STMs (n, 2, 2), or None when not asked.
    stm: Option<Py<PyAny>>,
    /// Lane status per case (0 ok, 1 max steps, 2 failed), uint8 (n,).
    status: Py<PyAny>,
    /// Accepted and rejected steps per case, (n, 2).
    steps: Py<PyAny>,
}

const SWEEP_FIELDS: [&str; 7] = ["phi_t", "wz_t", "dwz", "dphi", "stm", "status", "steps"];

#[pymethods]
impl PySweepResult {
    /// `r[name]` is `r.name` (the fields of the former dict result).
    fn __getitem__(&self, py: Python<'_>, name: &str) -> PyResult<Option<Py<PyAny>>> {
        let field = match name {
            "phi_t" => &self.phi_t,
            "wz_t" => &self.wz_t,
            "dwz" => &self.dwz,
            "dphi" => &self.dphi,
            "stm" => return Ok(self.stm.as_ref().map(|m| m.clone_ref(py))),
            "status" => &self.status,
            "steps" => &self.steps,
            _ => return Err(PyKeyError::new_err(format!("{name:?}: SweepResult has {}", SWEEP_FIELDS.join(", ")))),
        };
        Ok(Some(field.clone_ref(py)))
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

/// The lane cases of planar cases.
fn lane_cases(c: &PlanarCases) -> Vec<Case> {
    (0..c.wz0.len()).map(|i| Case { eps: c.eps[i], cs: c.cs[i], cd: c.cd[i], theta_sun0: c.theta_sun0[i], ..Case::new(c.phi0[i], c.wz0[i], c.kz[i]) }).collect()
}

/// Integrate planar attitude trajectories (the cases' phi0, wz0, kz and plates) over t_final.
#[pyfunction]
#[pyo3(signature = (forcing, t_final, cases, *, lanes, stm))]
fn map_sweep<'py>(py: Python<'py>, forcing: PyRef<'py, PyOrbitForcing>, t_final: f64, cases: PyRef<'py, PlanarCases>, lanes: PyRef<'py, LaneOptions>, stm: bool) -> PyResult<PySweepResult> {
    let cases = lane_cases(&cases);
    let n = cases.len();
    let (opts, chunk, threads) = (lanes.core(), lanes.chunk, lanes.threads);
    let f = &forcing.inner;
    let out = interruptible(py, || map::sweep(f, t_final, &cases, &opts, stm, chunk, threads))?;
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
#[pyclass(frozen, get_all, name = "CorrectionBatch", module = "librate._core")]
pub struct PyCorrectionBatch {
    /// Final phi0 (kept unless free=PHI0 with closure=FULL), (n,).
    phi0: Py<PyAny>,
    /// Final inertial wz0, (n,).
    wz0: Py<PyAny>,
    /// Final Sun phase (kept unless free=SUN_PHASE; not wrapped), (n,).
    theta_sun0: Py<PyAny>,
    /// Residuals (n, 2): full (dphi, dwz); half (phi(KT/2) - phi0 - pi turns, NaN).
    residual: Py<PyAny>,
    /// Max-norm of the residual, (n,) (NaN when the start could not be integrated).
    residual_norm: Py<PyAny>,
    /// Accepted Newton steps, int64 (n,).
    iterations: Py<PyAny>,
    /// reason == "converged", bool (n,).
    converged: Py<PyAny>,
    /// Why each candidate stopped: "converged", "max_iterations", "singular_jacobian",
    /// "no_descent", "integration_failed", "left_window" or "slow_convergence".
    reason: Vec<&'static str>,
    /// Full-period (K T) 2x2 monodromy at the final point, (n, 2, 2).
    monodromy: Py<PyAny>,
    /// The freed parameter's final value (bordered corrections; else each candidate's Kz), (n,).
    parameter: Py<PyAny>,
    /// d F / d (angle, wz0, parameter) at the final point, (n, 2, 3); NaN where not computed.
    jacobian: Py<PyAny>,
}

#[pymethods]
impl PyCorrectionBatch {
    fn __len__(&self) -> usize {
        self.reason.len()
    }
    fn __repr__(&self) -> String {
        let c = self.reason.iter().filter(|r| **r == "converged").count();
        format!("CorrectionBatch(n={}, converged={c})", self.reason.len())
    }
}

/// The corrector's candidates of planar cases (their turns and plates), with the bordered
/// conditions per candidate and the cases' wz0 search windows when given.
fn candidates(c: &PlanarCases, bordered: Option<&Bordered>) -> PyResult<Vec<Candidate>> {
    let n = c.wz0.len();
    let mut cands: Vec<Candidate> = (0..n).map(|i| Candidate::new(c.phi0[i], c.wz0[i], c.kz[i], c.turns[i]).with_plate(c.eps[i], c.cs[i], c.cd[i], c.theta_sun0[i])).collect();
    if let Some(rows) = bordered.and_then(|b| b.conditions.as_ref()) {
        if rows.len() != n {
            return Err(invalid(format!("invalid argument `conditions`: one row (a_angle, a_wz0, a_parameter, b) per candidate, shape ({n}, 4); got shape ({}, 4)", rows.len())));
        }
        for (cand, r) in cands.iter_mut().zip(rows) {
            *cand = cand.with_condition([r[0], r[1], r[2]], r[3]);
        }
    }
    if let Some(w) = &c.window {
        for (cand, [lo, hi]) in cands.iter_mut().zip(w) {
            *cand = cand.with_window(*lo, *hi);
        }
    }
    Ok(cands)
}

/// Correct many candidates at once to periodic planar attitude motions along the forcing's orbit
/// (one Rust call for all Newton iterations; see librate_core::attitude::correct_planar_attitudes);
/// `bordered`: the parameter freed with its condition(s).
#[pyfunction]
#[pyo3(signature = (forcing, cases, *, t_final, closure, free, options, bordered=None))]
fn attitude_correct<'py>(
    py: Python<'py>,
    forcing: PyRef<'py, PyOrbitForcing>,
    cases: PyRef<'py, PlanarCases>,
    t_final: f64,
    closure: Closure,
    free: Free,
    options: PyRef<'py, CorrectorOptions>,
    bordered: Option<PyRef<'py, Bordered>>,
) -> PyResult<PyCorrectionBatch> {
    if bordered.as_ref().is_some_and(|b| b.inner.parameter == Parameter::OrbitX0) {
        return Err(invalid("invalid argument `bordered`: the orbit's x0 is freed by attitude_correct_across"));
    }
    let cands = candidates(&cases, bordered.as_deref())?;
    let (closure, free, opts) = (closure.into(), free.into(), options.core());
    let border = bordered.as_ref().map(|b| b.inner);
    let f = &forcing.inner;
    let out = interruptible(py, || match &border {
        None => correct_planar_attitudes(f, t_final, closure, free, &cands, &opts),
        Some(b) => correct_bordered(f, t_final, closure, free, b, &cands, &opts),
    })?;
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

/// The half-period correction with the orbit's x0 freed across a planar family (the cases'
/// phi0, wz0, kz and turns, the orbits' x0 guesses), closed by the bordered condition
/// (parameter ORBIT_X0) a_wz0 wz0 + a_x0 x0 = b (librate_core::attitude::correct_across_family).
#[pyfunction]
#[pyo3(signature = (family, cases, x0, *, bordered, options))]
fn attitude_correct_across<'py>(
    py: Python<'py>,
    family: PyRef<'py, PyPlanarFamily>,
    cases: PyRef<'py, PlanarCases>,
    x0: PyReadonlyArray1<'py, f64>,
    bordered: PyRef<'py, Bordered>,
    options: PyRef<'py, CorrectorOptions>,
) -> PyResult<PyCorrectionBatch> {
    if bordered.inner.parameter != Parameter::OrbitX0 || bordered.conditions.is_some() {
        return Err(invalid("invalid argument `bordered`: the correction across a family frees ORBIT_X0 under one condition"));
    }
    let n = cases.wz0.len();
    let x = vector(&x0, "x0", Some(n))?;
    let cands: Vec<Candidate> = (0..n).map(|i| Candidate::new(cases.phi0[i], cases.wz0[i], cases.kz[i], cases.turns[i]).with_x0(x[i])).collect();
    let (border, opts) = (bordered.inner, options.core());
    let fam = &family.inner;
    let out = interruptible(py, || correct_across_family(fam, &border, &cands, &opts))?;
    batch_from(py, &out)
}

/// The outcome of `planar_verify`: arrays over the items.
#[pyclass(frozen, get_all, name = "PlanarVerification", module = "librate._core")]
pub struct PyPlanarVerification {
    /// Unwrapped phi at t_final, (n,) (NaN where the integration failed).
    phi_t: Py<PyAny>,
    /// wz at t_final, (n,).
    wz_t: Py<PyAny>,
    /// d(phi, wz)(t_final) / d(phi0, wz0), (n, 2, 2).
    stm: Py<PyAny>,
    /// The full closure's residuals (phi(t_final) - phi0 - 2 pi turns, wz(t_final) - wz0) with
    /// the cases' turns, (n, 2).
    residual: Py<PyAny>,
    /// The integration error message per item, or None.
    error: Vec<Option<String>>,
}

#[pymethods]
impl PyPlanarVerification {
    fn __len__(&self) -> usize {
        self.error.len()
    }
    fn __repr__(&self) -> String {
        format!("PlanarVerification(n={}, failed={})", self.error.len(), self.error.iter().filter(|e| e.is_some()).count())
    }
}

/// Independent re-propagation of planar attitude motions (the orbit integrated alongside, no
/// forcing table, rtol = atol = 1e-14; the SIMD lanes in groups of eight in case order, the
/// groups in parallel); a plate where the case's eps is non-zero.
#[pyfunction]
#[pyo3(signature = (mu, orbit_state0, t_final, cases, *, primaries=[true, true], threads=None))]
fn planar_verify<'py>(
    py: Python<'py>,
    mu: f64,
    orbit_state0: [f64; 6],
    t_final: f64,
    cases: PyRef<'py, PlanarCases>,
    primaries: [bool; 2],
    threads: Option<usize>,
) -> PyResult<PyPlanarVerification> {
    let c = &*cases;
    let n = c.wz0.len();
    let items = (0..n)
        .map(|i| {
            let plate = if c.eps[i] != 0.0 { Some(FlatPlate::new(c.eps[i], c.cs[i], c.cd[i], Sun { theta0: c.theta_sun0[i], ..Sun::default() }).map_err(to_py)?) } else { None };
            Ok(PlanarStart { kz: c.kz[i], phi0: c.phi0[i], wz0: c.wz0[i], plate })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let out = interruptible(py, || verify_planar_attitudes(mu, &orbit_state0, t_final, &items, primaries, threads))?;
    Ok(PyPlanarVerification {
        phi_t: out.iter().map(|o| o.phi_t).collect::<Vec<f64>>().into_pyarray(py).into_any().unbind(),
        wz_t: out.iter().map(|o| o.wz_t).collect::<Vec<f64>>().into_pyarray(py).into_any().unbind(),
        stm: out.iter().flat_map(|o| o.stm).collect::<Vec<f64>>().into_pyarray(py).reshape([n, 2, 2])?.into_any().unbind(),
        residual: out.iter().zip(&items).zip(&c.turns).flat_map(|((o, it), &turns)| full_closure_residual(it.phi0, it.wz0, turns, o.phi_t, o.wz_t)).collect::<Vec<f64>>().into_pyarray(py).reshape([n, 2])?.into_any().unbind(),
        error: out.iter().map(|o| o.error.as_ref().map(|e| e.to_string())).collect(),
    })
}

/// The solutions of `attitude_refine`: arrays over the kept solutions.
#[pyclass(frozen, get_all, name = "PlanarRefinement", module = "librate._core")]
pub struct PyPlanarRefinement {
    /// Each solution's candidate index in the batch, int64 (m,).
    index: Py<PyAny>,
    /// The corrected phi0 and inertial wz0, (m,).
    phi0: Py<PyAny>,
    wz0: Py<PyAny>,
    /// The corrector's accepted Newton steps, int64 (m,).
    iterations: Py<PyAny>,
    /// The independent re-propagation over the full closure time K T: phi and wz at its end,
    /// (m,), and d(phi, wz)(KT) / d(phi0, wz0), (m, 2, 2).
    phi_t: Py<PyAny>,
    wz_t: Py<PyAny>,
    stm: Py<PyAny>,
    /// Its full closure's residuals (phi(KT) - phi0 - 2 pi turns, wz(KT) - wz0), (m, 2).
    residual: Py<PyAny>,
}

#[pymethods]
impl PyPlanarRefinement {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.index.bind(py).len()
    }
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("PlanarRefinement(solutions={})", self.__len__(py)?))
    }
}

fn refinement_from(py: Python<'_>, out: &[Refined]) -> PyResult<PyPlanarRefinement> {
    let m = out.len();
    let col = |g: &dyn Fn(&Refined) -> f64| out.iter().map(g).collect::<Vec<f64>>().into_pyarray(py).into_any().unbind();
    Ok(PyPlanarRefinement {
        index: out.iter().map(|r| r.index as i64).collect::<Vec<i64>>().into_pyarray(py).into_any().unbind(),
        phi0: col(&|r| r.correction.phi0),
        wz0: col(&|r| r.correction.wz0),
        iterations: out.iter().map(|r| r.correction.iterations as i64).collect::<Vec<i64>>().into_pyarray(py).into_any().unbind(),
        phi_t: col(&|r| r.end.phi_t),
        wz_t: col(&|r| r.end.wz_t),
        stm: out.iter().flat_map(|r| r.end.stm).collect::<Vec<f64>>().into_pyarray(py).reshape([m, 2, 2])?.into_any().unbind(),
        residual: out.iter().flat_map(|r| r.residual).collect::<Vec<f64>>().into_pyarray(py).reshape([m, 2])?.into_any().unbind(),
    })
}

/// A refinement started by `attitude_refine`, running on the pool: `join()` waits for it (with
/// the GIL released, Ctrl-C stopping it) and returns its PlanarRefinement, once. Dropped
/// unjoined, it runs to its end and its result is discarded.
#[pyclass(frozen, name = "PendingRefinement", module = "librate._core")]
pub struct PyPendingRefinement {
    pending: Mutex<Option<Pending<librate_core::Result<Vec<Refined>>>>>,
}

#[pymethods]
impl PyPendingRefinement {
    fn join(&self, py: Python<'_>) -> PyResult<PyPlanarRefinement> {
        let pending = self.pending.lock().map_err(|_| PyRuntimeError::new_err("PendingRefinement: a join panicked"))?.take();
        let Some(pending) = pending else {
            return Err(PyRuntimeError::new_err("PendingRefinement: already joined"));
        };
        let out = join(py, pending)?;
        refinement_from(py, &out)
    }
    fn __repr__(&self) -> String {
        let joined = self.pending.lock().map(|p| p.is_none()).unwrap_or(true);
        format!("PendingRefinement({})", if joined { "joined" } else { "pending" })
    }
}

/// Refine candidates into verified solutions in one core call, started on the pool at once
/// (librate_core::attitude::refine_planar_attitudes): the cases' phi0, wz0, Kz, turns, plates
/// and wz0 search windows corrected over `t_final` (`closure`; phi0 the free angle of the full
/// closure), the converged ones inside `keep` = (lo, hi) kept once per (group, Kz, turns),
/// re-propagated independently over K T, and kept when that residual is at most 1e-8.
/// `groups`: one integer label per case (default: all one group). Returns a PendingRefinement.
#[pyfunction]
#[pyo3(signature = (forcing, cases, *, t_final, closure, options, keep, groups=None))]
fn attitude_refine<'py>(
    forcing: PyRef<'py, PyOrbitForcing>,
    cases: PyRef<'py, PlanarCases>,
    t_final: f64,
    closure: Closure,
    options: PyRef<'py, CorrectorOptions>,
    keep: (f64, f64),
    groups: Option<PyReadonlyArray1<'py, i64>>,
) -> PyResult<PyPendingRefinement> {
    let cands = candidates(&cases, None)?;
    let groups = match &groups {
        Some(g) => vector(g, "groups", Some(cands.len()))?,
        None => vec![0; cands.len()],
    };
    let (closure, opts) = (closure.into(), options.core());
    let (table, mu, state0, primaries) = (Arc::clone(&forcing.inner), forcing.mu, forcing.state0, forcing.primaries);
    let pending = start(move || {
        let orbit = PlanarOrbit { mu, state0, primaries, forcing: &table };
        refine_planar_attitudes(&orbit, t_final, closure, &cands, &groups, &opts, keep)
    })?;
    Ok(PyPendingRefinement { pending: Mutex::new(Some(pending)) })
}

/// The indices of the first of each distinct solution, in order (librate_core::attitude::distinct,
/// the rule `attitude_refine` merges by): solutions of one group with the same Kz and turns and
/// wz0 within 1e-8 are one.
#[pyfunction]
#[pyo3(signature = (groups, kz, turns, wz0))]
fn distinct_solutions<'py>(
    py: Python<'py>,
    groups: PyReadonlyArray1<'py, i64>,
    kz: PyReadonlyArray1<'py, f64>,
    turns: PyReadonlyArray1<'py, f64>,
    wz0: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let g = vector(&groups, "groups", None)?;
    let n = g.len();
    let (k, t, w) = (vector(&kz, "kz", Some(n))?, vector(&turns, "turns", Some(n))?, vector(&wz0, "wz0", Some(n))?);
    let keys: Vec<SolutionKey> = (0..n).map(|i| SolutionKey { group: g[i], kz: k[i], turns: t[i], wz0: w[i] }).collect();
    Ok(distinct(&keys).into_iter().map(|i| i as i64).collect::<Vec<i64>>().into_pyarray(py).into_any())
}

/// The crossings of one map row (`row_crossings`): arrays over them.
#[pyclass(frozen, get_all, name = "RowCrossings", module = "librate._core")]
pub struct PyRowCrossings {
    /// The multiple of the level crossed, int64 (m,).
    k: Py<PyAny>,
    /// The crossing's rate by linear interpolation, (m,).
    wz0: Py<PyAny>,
    /// The rate interval holding it (between wz0[i] and wz0[i + 1]), int64 (m,).
    interval: Py<PyAny>,
    /// Each crossing's search window (lo, hi) of wz0, (m, 2) ((-inf, inf) where the row is not
    /// resolved there), or None when not asked.
    window: Option<Py<PyAny>>,
    /// Intervals left out for crossing more than `max_crossings` levels (0 without a limit).
    unresolved: usize,
}

/// Where one row's unwrapped final angle phi_t - phi0 crosses a multiple of `level`
/// (librate_core::map::crossings): an interval with a non-finite end, equal ends, or more than
/// `max_crossings` levels crossed is left out; `window` = (quick, resolved) adds each crossing's
/// search window (librate_core::map::windows).
#[pyfunction]
#[pyo3(signature = (phi_t, wz0, *, phi0, level, max_crossings=None, window=None))]
fn row_crossings<'py>(
    py: Python<'py>,
    phi_t: PyReadonlyArray1<'py, f64>,
    wz0: PyReadonlyArray1<'py, f64>,
    phi0: f64,
    level: f64,
    max_crossings: Option<usize>,
    window: Option<(usize, f64)>,
) -> PyResult<PyRowCrossings> {
    let w = vector(&wz0, "wz0", None)?;
    let p = vector(&phi_t, "phi_t", Some(w.len()))?;
    if !(level.is_finite() && level > 0.0 && phi0.is_finite()) {
        return Err(invalid(format!("invalid argument `level`/`phi0`: level must be finite and > 0, phi0 finite; got {level}, {phi0}")));
    }
    let u = map::levels(&p, phi0, level);
    let c = map::crossings(&u, &w, max_crossings);
    let m = c.len();
    let win = window.map(|(quick, resolved)| map::windows(&u, &w, &c, quick, resolved));
    Ok(PyRowCrossings {
        k: c.iter().map(|c| c.k).collect::<Vec<i64>>().into_pyarray(py).into_any().unbind(),
        wz0: c.iter().map(|c| c.wz0).collect::<Vec<f64>>().into_pyarray(py).into_any().unbind(),
        interval: c.iter().map(|c| c.interval as i64).collect::<Vec<i64>>().into_pyarray(py).into_any().unbind(),
        window: match win {
            Some(v) => Some(v.into_iter().flat_map(|(lo, hi)| [lo, hi]).collect::<Vec<f64>>().into_pyarray(py).reshape([m, 2])?.into_any().unbind()),
            None => None,
        },
        unresolved: max_crossings.map_or(0, |mc| map::unresolved(&u, mc)),
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPlanarRefinement>()?;
    m.add_class::<PyPendingRefinement>()?;
    m.add_class::<PyRowCrossings>()?;
    m.add_function(wrap_pyfunction!(attitude_refine, m)?)?;
    m.add_function(wrap_pyfunction!(row_crossings, m)?)?;
    m.add_function(wrap_pyfunction!(distinct_solutions, m)?)?;
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
