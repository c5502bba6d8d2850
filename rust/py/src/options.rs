//! The typed arguments of the bindings: option objects (integrator, Newton driver, lane engine,
//! correctors), the enums that select a variant, and the per-case containers (plates,
//! planar cases, 3-D cases). Each is converted and checked once, where it enters (its
//! constructor), so the functions that take it have short signatures.

use librate_core::attitude::{Bordered as CoreBordered, Closure as CoreClosure, CorrectorOptions as CoreCorrectorOptions, Free as CoreFree, Options3d, Parameter};
use librate_core::integrate::lanes::{LaneOptions as CoreLaneOptions, Method};
use librate_core::integrate::Options;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{per_case, rows, vector};
use crate::errors::invalid;

/// Integrator settings of the adaptive (or fixed-step) propagations (librate_core::integrate::Options).
#[pyclass(frozen, get_all, name = "IntegrationOptions", module = "librate._core")]
#[derive(Clone, Copy)]
pub struct IntegrationOptions {
    pub rtol: f64,
    pub atol: f64,
    /// First step (None: chosen by the driver).
    pub h0: Option<f64>,
    pub h_min: f64,
    pub h_max: f64,
    pub max_steps: usize,
    pub safety: f64,
    /// A fixed step instead of the error control, or None.
    pub fixed_step: Option<f64>,
}

#[pymethods]
impl IntegrationOptions {
    #[new]
    #[pyo3(signature = (*, rtol=1e-12, atol=1e-12, h0=None, h_min=0.0, h_max=f64::INFINITY, max_steps=1_000_000, safety=None, fixed_step=None))]
    fn new(rtol: f64, atol: f64, h0: Option<f64>, h_min: f64, h_max: f64, max_steps: usize, safety: Option<f64>, fixed_step: Option<f64>) -> Self {
        Self { rtol, atol, h0, h_min, h_max, max_steps, safety: safety.unwrap_or(Options::default().safety), fixed_step }
    }
    fn __repr__(&self) -> String {
        format!("IntegrationOptions(rtol={:e}, atol={:e}, max_steps={})", self.rtol, self.atol, self.max_steps)
    }
}

impl From<&IntegrationOptions> for Options {
    fn from(o: &IntegrationOptions) -> Self {
        Options { rtol: o.rtol, atol: o.atol, h0: o.h0, h_min: o.h_min, h_max: o.h_max, max_steps: o.max_steps, safety: o.safety, fixed_step: o.fixed_step, ..Options::default() }
    }
}

/// Settings of the globalised Newton drivers: convergence when the residual max-norm <= tol,
/// at most max_iter steps, max_halvings line-search halvings, steps scaled down to
/// |angle step| <= max_angle_step (rad) and |rate step| <= max_rate_step (1/TU); with
/// max_contraction, a candidate stops ("slow_convergence") when an accepted step leaves the
/// residual's 2-norm above that fraction of its value before the step (planar attitude
/// correctors, for a continuation's steps; None: no test). The correctors without a line
/// search (orbits, flexible) read tol and max_iter only.
#[pyclass(frozen, get_all, from_py_object, name = "NewtonOptions", module = "librate._core")]
#[derive(Clone, Copy)]
pub struct NewtonOptions {
    pub tol: f64,
    pub max_iter: usize,
    pub max_halvings: u32,
    pub max_angle_step: f64,
    pub max_rate_step: f64,
    pub max_contraction: Option<f64>,
}

#[pymethods]
impl NewtonOptions {
    #[new]
    #[pyo3(signature = (*, tol=1e-12, max_iter=40, max_halvings=10, max_angle_step=0.5, max_rate_step=0.5, max_contraction=None))]
    fn new(tol: f64, max_iter: usize, max_halvings: u32, max_angle_step: f64, max_rate_step: f64, max_contraction: Option<f64>) -> Self {
        Self { tol, max_iter, max_halvings, max_angle_step, max_rate_step, max_contraction }
    }
    fn __repr__(&self) -> String {
        let contraction = self.max_contraction.map_or(String::new(), |c| format!(", max_contraction={c}"));
        format!("NewtonOptions(tol={:e}, max_iter={}, max_halvings={}{contraction})", self.tol, self.max_iter, self.max_halvings)
    }
}

/// The lane engine's integration method (librate_core::integrate::lanes::Method).
#[pyclass(eq, eq_int, frozen, hash, from_py_object, name = "LaneMethod", module = "librate._core")]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub enum LaneMethod {
    /// Runge-Kutta-Fehlberg 7(8), the reference.
    #[pyo3(name = "RKF78")]
    Rkf78,
    /// Runge-Kutta-Nyström 8(6).
    #[pyo3(name = "RKN86")]
    Rkn86,
    /// Prince and Dormand's RK8(7)13M.
    #[pyo3(name = "DP87")]
    Dp87,
}

impl From<LaneMethod> for Method {
    fn from(m: LaneMethod) -> Self {
        match m {
            LaneMethod::Rkf78 => Method::Rkf78,
            LaneMethod::Rkn86 => Method::Rkn86,
            LaneMethod::Dp87 => Method::Dp87,
        }
    }
}

/// Settings of the SIMD lane engine (maps and the planar correctors): tolerances, step limit
/// per case, method, cases per task and worker threads (None: all cores).
#[pyclass(frozen, get_all, from_py_object, name = "LaneOptions", module = "librate._core")]
#[derive(Clone, Copy)]
pub struct LaneOptions {
    pub rtol: f64,
    pub atol: f64,
    pub max_steps: u32,
    pub method: LaneMethod,
    pub chunk: usize,
    pub threads: Option<usize>,
}

#[pymethods]
impl LaneOptions {
    #[new]
    #[pyo3(signature = (*, rtol=1e-12, atol=1e-12, max_steps=200_000, method=LaneMethod::Rkf78, chunk=64, threads=None))]
    fn new(rtol: f64, atol: f64, max_steps: u32, method: LaneMethod, chunk: usize, threads: Option<usize>) -> Self {
        Self { rtol, atol, max_steps, method, chunk, threads }
    }
    fn __repr__(&self) -> String {
        format!("LaneOptions(rtol={:e}, atol={:e}, max_steps={})", self.rtol, self.atol, self.max_steps)
    }
}

impl LaneOptions {
    pub(crate) fn core(&self) -> CoreLaneOptions {
        CoreLaneOptions { rtol: self.rtol, atol: self.atol, max_steps: self.max_steps, method: self.method.into(), ..CoreLaneOptions::default() }
    }
}

/// Settings of the planar periodic-attitude correctors (librate_core::attitude::CorrectorOptions):
/// the Newton driver, the lanes it integrates on, and whether the half-closure corrections also
/// compute their full-period monodromy.
#[pyclass(frozen, get_all, name = "CorrectorOptions", module = "librate._core")]
#[derive(Clone, Copy)]
pub struct CorrectorOptions {
    pub newton: NewtonOptions,
    pub lanes: LaneOptions,
    pub monodromy: bool,
}

#[pymethods]
impl CorrectorOptions {
    #[new]
    #[pyo3(signature = (newton, lanes, *, monodromy=true))]
    fn new(newton: NewtonOptions, lanes: LaneOptions, monodromy: bool) -> PyResult<Self> {
        if lanes.method != LaneMethod::Rkf78 {
            return Err(invalid("invalid argument `lanes`: the planar correctors integrate with LaneMethod.RKF78"));
        }
        Ok(Self { newton, lanes, monodromy })
    }
}

impl CorrectorOptions {
    pub(crate) fn core(&self) -> CoreCorrectorOptions {
        let (n, l) = (&self.newton, &self.lanes);
        CoreCorrectorOptions {
            tol: n.tol,
            max_iter: n.max_iter,
            rtol: l.rtol,
            atol: l.atol,
            max_steps: l.max_steps,
            max_wz_step: n.max_rate_step,
            max_angle_step: n.max_angle_step,
            max_halvings: n.max_halvings,
            max_contraction: n.max_contraction.unwrap_or(f64::INFINITY),
            threads: l.threads,
            chunk: l.chunk,
            monodromy: self.monodromy,
            ..CoreCorrectorOptions::default()
        }
    }
}

/// Settings of the 3-D periodic-attitude correctors (librate_core::attitude::Options3d): the
/// Newton driver, the trajectories' tolerances, the enabled primaries, the half-period form,
/// the largest period step across a family (TU) and the worker threads.
#[pyclass(frozen, get_all, name = "CorrectorOptions3D", module = "librate._core")]
#[derive(Clone, Copy)]
pub struct CorrectorOptions3D {
    pub newton: NewtonOptions,
    pub rtol: f64,
    pub atol: f64,
    pub primaries: [bool; 2],
    pub half: bool,
    pub max_period_step: f64,
    pub threads: Option<usize>,
}

#[pymethods]
impl CorrectorOptions3D {
    #[new]
    #[pyo3(signature = (newton, *, rtol=1e-13, atol=1e-13, primaries=[true, true], half=false, max_period_step=0.5, threads=None))]
    fn new(newton: NewtonOptions, rtol: f64, atol: f64, primaries: [bool; 2], half: bool, max_period_step: f64, threads: Option<usize>) -> Self {
        Self { newton, rtol, atol, primaries, half, max_period_step, threads }
    }
}

impl CorrectorOptions3D {
    pub(crate) fn core(&self) -> Options3d {
        let n = &self.newton;
        Options3d {
            tol: n.tol,
            max_iter: n.max_iter,
            max_halvings: n.max_halvings,
            rtol: self.rtol,
            atol: self.atol,
            max_angle_step: n.max_angle_step,
            max_rate_step: n.max_rate_step,
            threads: self.threads,
            primaries: self.primaries,
            half: self.half,
        }
    }
}

/// The closure of a planar periodic-attitude correction (librate_core::attitude::Closure).
#[pyclass(eq, eq_int, frozen, hash, from_py_object, name = "Closure", module = "librate._core")]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub enum Closure {
    /// Symmetric half-period shooting over K T / 2.
    #[pyo3(name = "HALF")]
    Half,
    /// Full closure over K T.
    #[pyo3(name = "FULL")]
    Full,
}

impl From<Closure> for CoreClosure {
    fn from(c: Closure) -> Self {
        match c {
            Closure::Half => CoreClosure::Half,
            Closure::Full => CoreClosure::Full,
        }
    }
}

/// The angle unknown of a planar correction (librate_core::attitude::Free).
#[pyclass(eq, eq_int, frozen, hash, from_py_object, name = "Free", module = "librate._core")]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub enum Free {
    /// (phi0, wz0).
    #[pyo3(name = "PHI0")]
    Phi0,
    /// (theta_sun0, wz0), phi0 kept: SRP candidates only.
    #[pyo3(name = "SUN_PHASE")]
    SunPhase,
}

impl From<Free> for CoreFree {
    fn from(f: Free) -> Self {
        match f {
            Free::Phi0 => CoreFree::Phi0,
            Free::SunPhase => CoreFree::SunPhase,
        }
    }
}

/// The parameter freed by a bordered correction (librate_core::attitude::Parameter).
#[pyclass(eq, eq_int, frozen, hash, from_py_object, name = "BorderedParameter", module = "librate._core")]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub enum BorderedParameter {
    /// Kz = (Iy - Ix) / Iz.
    #[pyo3(name = "KZ")]
    Kz,
    /// The flat-plate SRP amplitude eps.
    #[pyo3(name = "EPS")]
    Eps,
    /// The x0 of a member of a planar symmetric orbit family.
    #[pyo3(name = "ORBIT_X0")]
    OrbitX0,
}

/// A bordered correction: `parameter` freed and closed by the linear condition
/// a_angle angle + a_wz0 wz0 + a_parameter parameter = b (`condition`, or one row per candidate
/// in `conditions` (n, 4)); `step` the central-difference step and `max_step` the largest Newton
/// step in the parameter.
#[pyclass(frozen, name = "Bordered", module = "librate._core")]
pub struct Bordered {
    pub(crate) inner: CoreBordered,
    pub(crate) conditions: Option<Vec<[f64; 4]>>,
}

#[pymethods]
impl Bordered {
    #[new]
    #[pyo3(signature = (parameter, condition, *, step=1e-6, max_step=0.5, conditions=None))]
    fn new(parameter: BorderedParameter, condition: [f64; 4], step: f64, max_step: f64, conditions: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Self> {
        let parameter = match parameter {
            BorderedParameter::Kz => Parameter::Kz,
            BorderedParameter::Eps => Parameter::Eps,
            BorderedParameter::OrbitX0 => Parameter::OrbitX0,
        };
        let conditions = conditions.map(|c| rows::<4>(&c, "conditions", None)).transpose()?;
        let [a0, a1, a2, b] = condition;
        Ok(Self { inner: CoreBordered { parameter, a: [a0, a1, a2], b, step, max_step }, conditions })
    }
}

/// Flat-plate SRP parameters per case: amplitude eps, specular and diffuse coefficients cs, cd
/// and the Sun's phase theta_sun0 (arrays of one length; eps = 0 is no plate).
#[pyclass(frozen, name = "Plates", module = "librate._core")]
pub struct Plates {
    pub(crate) eps: Vec<f64>,
    pub(crate) cs: Vec<f64>,
    pub(crate) cd: Vec<f64>,
    pub(crate) theta_sun0: Vec<f64>,
}

#[pymethods]
impl Plates {
    #[new]
    fn new(eps: PyReadonlyArray1<'_, f64>, cs: PyReadonlyArray1<'_, f64>, cd: PyReadonlyArray1<'_, f64>, theta_sun0: PyReadonlyArray1<'_, f64>) -> PyResult<Self> {
        let eps = vector(&eps, "eps", None)?;
        let n = Some(eps.len());
        Ok(Self { cs: vector(&cs, "cs", n)?, cd: vector(&cd, "cd", n)?, theta_sun0: vector(&theta_sun0, "theta_sun0", n)?, eps })
    }
    fn __len__(&self) -> usize {
        self.eps.len()
    }
}

/// Planar attitude cases (arrays of one length): phi0, wz0, kz, the closure's turns (correctors),
/// their plates (zeros when None) and the correctors' search windows (lo, hi) of wz0, shape (n, 2)
/// (none when None; a Newton step leaving its window stops the candidate, "left_window").
#[pyclass(frozen, name = "PlanarCases", module = "librate._core")]
pub struct PlanarCases {
    pub(crate) phi0: Vec<f64>,
    pub(crate) wz0: Vec<f64>,
    pub(crate) kz: Vec<f64>,
    pub(crate) turns: Vec<f64>,
    pub(crate) eps: Vec<f64>,
    pub(crate) cs: Vec<f64>,
    pub(crate) cd: Vec<f64>,
    pub(crate) theta_sun0: Vec<f64>,
    pub(crate) window: Option<Vec<[f64; 2]>>,
}

#[pymethods]
impl PlanarCases {
    #[new]
    #[pyo3(signature = (phi0, wz0, kz, *, turns=None, plates=None, window=None))]
    fn new(
        phi0: PyReadonlyArray1<'_, f64>,
        wz0: PyReadonlyArray1<'_, f64>,
        kz: PyReadonlyArray1<'_, f64>,
        turns: Option<PyReadonlyArray1<'_, f64>>,
        plates: Option<PyRef<'_, Plates>>,
        window: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<Self> {
        let wz0 = vector(&wz0, "wz0", None)?;
        let n = wz0.len();
        let (phi0, kz) = (vector(&phi0, "phi0", Some(n))?, vector(&kz, "kz", Some(n))?);
        let turns = per_case(turns.as_ref(), "turns", n)?;
        let (eps, cs, cd, theta_sun0) = match plates {
            Some(p) if p.eps.len() == n => (p.eps.clone(), p.cs.clone(), p.cd.clone(), p.theta_sun0.clone()),
            Some(p) => return Err(invalid(format!("invalid argument `plates`: must have the length of wz0 ({n}), got {}", p.eps.len()))),
            None => (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]),
        };
        let window = window.map(|w| rows::<2>(&w, "window", Some(n))).transpose()?;
        Ok(Self { phi0, wz0, kz, turns, eps, cs, cd, theta_sun0, window })
    }
    fn __len__(&self) -> usize {
        self.wz0.len()
    }
}

/// 3-D attitude cases: attitudes q (n, 4) scalar last and inertial rates w (n, 3); across an
/// orbit family also the period guesses (n,) and the conditions a (n, 7) . (theta, w0, T) = b (n,).
#[pyclass(frozen, name = "AttitudeCases3D", module = "librate._core")]
pub struct AttitudeCases3D {
    pub(crate) q: Vec<[f64; 4]>,
    pub(crate) w: Vec<[f64; 3]>,
    pub(crate) across: Option<(Vec<f64>, Vec<[f64; 7]>, Vec<f64>)>,
}

#[pymethods]
impl AttitudeCases3D {
    #[new]
    #[pyo3(signature = (q, w, *, period=None, a=None, b=None))]
    fn new(q: PyReadonlyArray2<'_, f64>, w: PyReadonlyArray2<'_, f64>, period: Option<PyReadonlyArray1<'_, f64>>, a: Option<PyReadonlyArray2<'_, f64>>, b: Option<PyReadonlyArray1<'_, f64>>) -> PyResult<Self> {
        let q = rows::<4>(&q, "q", None)?;
        let n = q.len();
        let w = rows::<3>(&w, "w", Some(n))?;
        let across = match (period, a, b) {
            (None, None, None) => None,
            (Some(p), Some(a), Some(b)) => Some((vector(&p, "period", Some(n))?, rows::<7>(&a, "a", Some(n))?, vector(&b, "b", Some(n))?)),
            _ => return Err(invalid("invalid argument `period`: period, a and b go together")),
        };
        Ok(Self { q, w, across })
    }
    fn __len__(&self) -> usize {
        self.q.len()
    }
}

/// Add the option, enum and case classes to `librate._core`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<IntegrationOptions>()?;
    m.add_class::<NewtonOptions>()?;
    m.add_class::<LaneMethod>()?;
    m.add_class::<LaneOptions>()?;
    m.add_class::<CorrectorOptions>()?;
    m.add_class::<CorrectorOptions3D>()?;
    m.add_class::<Closure>()?;
    m.add_class::<Free>()?;
    m.add_class::<BorderedParameter>()?;
    m.add_class::<Bordered>()?;
    m.add_class::<Plates>()?;
    m.add_class::<PlanarCases>()?;
    m.add_class::<AttitudeCases3D>()?;
    Ok(())
}
