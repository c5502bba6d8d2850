//! Periodic planar attitude motions along a periodic orbit (thesis sec. 3.3; docs/physics.md,
//! "Periodic attitude motions" and "Solar radiation pressure"): a batched, globalised Newton
//! corrector on the periodicity-map engine, and a batched independent verifier on the scalar
//! model.
//!
//! Along an orbit of period T, the planar motion (phi0, wz0) is periodic over K revolutions
//! when phi(KT) = phi0 + 2 pi N and wz(KT) = wz0 (N net body turns; N + 1/2 for the half-turn
//! motions, which repeat too since the inertia is symmetric under a half turn). Three problem
//! forms share one driver ([`correct_planar_attitudes`]):
//!
//! - [`Closure::Half`]: symmetric half-period shooting. On an x-symmetric orbit started on the x
//!   axis, with phi0 a multiple of pi/2 and no SRP, the motion is symmetric and periodic when
//!   g(wz0) = phi(KT/2) - phi0 - pi N = 0 (one unknown, g' = d phi / d wz0 from the STM).
//! - [`Closure::Full`] with [`Free::Phi0`]: unknowns (phi0, wz0), residuals
//!   F = (phi(KT) - phi0 - 2 pi N, wz(KT) - wz0), Jacobian Phi(KT) - I (the correct Newton form;
//!   thesis eq. 53 omits the identity).
//! - [`Closure::Full`] with [`Free::SunPhase`]: phi0 kept, unknowns (theta_sun0, wz0) for a flat
//!   plate with SRP; dF/dtheta_sun0 by central differences, from two extra trajectories
//!   integrated in the same batch as the point itself; dF/dwz0 from the STM.
//!
//! Every Newton iteration integrates every still-active candidate of the batch in ONE
//! [`map::sweep`] call with the STM (SIMD lanes, all cores). Newton is globalised per candidate:
//! the steps in wz0 and in the angle unknown are capped, and a backtracking line search (Armijo-type sufficient decrease
//! of the residual's 2-norm, step halved up to `max_halvings` times) evaluates the trial
//! points of all candidates together in the next sweep (the driver, [`super::newton`], is shared
//! with the 3-D corrector, [`super::periodic3d`]). Each candidate reports why it stopped
//! ([`StopReason`]); nothing panics and a non-finite result is never labelled converged.
//!
//! Determinism: candidates keep their order; the sweep of each iteration is bit-identical for
//! any thread count and chunk size, so the results are too. The lane engine integrates eight
//! trajectories in lock step with a shared step size, however, so a candidate's last bits
//! (~1e-14 relative, the integration tolerance's noise) can depend on its batch companions:
//! correcting it alone, or in another batch, can differ at that level (never in the outcome).

use rayon::prelude::*;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use super::newton::{self, Eval, Problem, Settings, Track};
use crate::orbit::{Constraint, SymmetricOrbit, SymmetricShooting, Var};
use crate::attitude::{FlatPlate, OMEGA_SUN};
use crate::cr3bp::check_mu;
use crate::error::{check_finite, check_positive, invalid, Error, IntegrationError, Result};
use crate::integrate::Options;
use crate::integrate::forcing::OrbitForcing;
use crate::integrate::lanes::{integrate_along, Case, LaneOptions, LaneStatus, Outcome, Sensitivity, LANES};
use crate::map;
use crate::propagation::{with_threads, with_threads_rounds};

use std::f64::consts::{FRAC_PI_2, PI};

/// The full closure's residuals (phi(KT) - phi0 - 2 pi turns, wz(KT) - wz0) of a motion started
/// at (phi0, wz0) that ends at (phi_t, wz_t): zero for a periodic motion with `turns` net body
/// turns (N + 1/2 for a half-turn motion).
pub fn full_closure_residual(phi0: f64, wz0: f64, turns: f64, phi_t: f64, wz_t: f64) -> [f64; 2] {
    [phi_t - phi0 - 2.0 * PI * turns, wz_t - wz0]
}

/// How the periodicity condition is closed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Closure {
    /// Symmetric half-period shooting: `t_final` = K T / 2, unknown wz0, residual
    /// phi(t_final) - phi0 - pi turns. Needs an x-symmetric orbit started on the x axis,
    /// phi0 a multiple of pi/2 and no SRP; `free` must be [`Free::Phi0`] (phi0 itself is kept).
    Half,
    /// Full closure over `t_final` = K T: residuals (phi - phi0 - 2 pi turns, wz - wz0).
    Full,
}

/// The unknown corrected with wz0 in the [`Closure::Full`] form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Free {
    /// (phi0, wz0).
    Phi0,
    /// (theta_sun0, wz0) with phi0 kept: SRP candidates only (eps != 0).
    SunPhase,
}

pub use super::newton::StopReason;

/// One starting point: the trajectory's parameters (its `phi0`, `wz0`, `theta_sun0` are the
/// initial guesses of the unknowns) and its target number of turns per `t_final` closure
/// (N, or N + 1/2 for half-turn motions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    pub case: Case,
    pub turns: f64,
    /// The starting orbit's x0 for [`correct_across_family`] (NaN otherwise).
    pub x0: f64,
    /// This candidate's linear condition (a, b) of a bordered correction, replacing the
    /// [`Bordered`]'s own: candidates of different branches corrected in one batch.
    pub condition: Option<([f64; 3], f64)>,
    /// The search window (lo, hi) of wz0 (None: unbounded; infinite bounds allowed): a Newton
    /// step whose target leaves it stops the candidate ([`StopReason::LeftWindow`]). A map's
    /// crossing is refined in its neighbourhood: a solution there converges in a few steps, and
    /// a candidate whose Newton step leaves the neighbourhood has none nearby (it would find,
    /// far away, a solution that has a crossing of its own, or none).
    pub window: Option<(f64, f64)>,
}

impl Candidate {
    /// A gravity-gradient-only candidate.
    pub fn new(phi0: f64, wz0: f64, kz: f64, turns: f64) -> Self {
        Self { case: Case::new(phi0, wz0, kz), turns, x0: f64::NAN, condition: None, window: None }
    }

    /// The same candidate searched for only in lo <= wz0 <= hi ([`Candidate::window`]).
    pub fn with_window(self, lo: f64, hi: f64) -> Self {
        Self { window: Some((lo, hi)), ..self }
    }

    /// The same candidate started on the orbit of the family member at `x0`
    /// ([`correct_across_family`]).
    pub fn with_x0(self, x0: f64) -> Self {
        Self { x0, ..self }
    }

    /// The same candidate closed by its own linear condition `a . (angle, wz0, parameter) = b`
    /// in a bordered correction (each branch of a lock-step continuation has its own).
    pub fn with_condition(self, a: [f64; 3], b: f64) -> Self {
        Self { condition: Some((a, b)), ..self }
    }

    /// The same candidate with a flat plate (SRP amplitude `eps`, coefficients, Sun phase).
    pub fn with_plate(self, eps: f64, cs: f64, cd: f64, theta_sun0: f64) -> Self {
        Self { case: Case { eps, cs, cd, theta_sun0, ..self.case }, ..self }
    }
}

/// The parameter freed by a bordered correction (continuation in Kz or in the SRP amplitude).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameter {
    /// Kz = (Iy - Ix) / Iz, kept in [-1, 1] (one-sided differences at the ends).
    Kz,
    /// The flat-plate SRP amplitude eps.
    Eps,
    /// The x0 of a member of a planar symmetric orbit family ([`correct_across_family`]): each
    /// value is its own orbit, corrected and tabulated on demand.
    OrbitX0,
}

/// A bordered correction, the corrector of pseudo-arclength (or natural-parameter)
/// continuation: the parameter becomes an unknown and one linear condition closes the system,
///   a[0] angle + a[1] wz0 + a[2] parameter = b,
/// with "angle" the second unknown of the form (phi0, or theta_sun0; a[0] must be 0 for the
/// half-period closure, which has no angle unknown). d F / d parameter by central differences
/// (`step`), from two extra trajectories integrated in the same sweep as the point itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bordered {
    pub parameter: Parameter,
    pub a: [f64; 3],
    pub b: f64,
    /// Central-difference step in the parameter.
    pub step: f64,
    /// Largest |Newton step| in the parameter (the step is scaled down, direction kept).
    pub max_step: f64,
}

impl Bordered {
    /// The natural-parameter condition: the parameter fixed at `value`.
    pub fn fixed(parameter: Parameter, value: f64) -> Self {
        Self { parameter, a: [0.0, 0.0, 1.0], b: value, step: 1e-6, max_step: 0.5 }
    }
}

/// Settings of [`correct_planar_attitudes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectorOptions {
    /// Convergence: residual max-norm <= tol.
    pub tol: f64,
    /// Most Newton steps per candidate.
    pub max_iter: usize,
    /// Lane integrator tolerances and step limit.
    pub rtol: f64,
    pub atol: f64,
    pub max_steps: u32,
    /// Largest |step| in wz0 (1/TU) and in the angle unknown (phi0 or theta_sun0, rad): the
    /// Newton step is scaled down (direction kept) until both hold.
    pub max_wz_step: f64,
    pub max_angle_step: f64,
    /// Step halvings of the line search before giving up ([`StopReason::NoDescent`]).
    pub max_halvings: u32,
    /// The largest ratio of the residual's 2-norm after an accepted Newton step to before it
    /// (above the noise floor) before the candidate stops ([`StopReason::SlowConvergence`]):
    /// for a continuation's steps; infinite (the default): no test.
    pub max_contraction: f64,
    /// Central-difference step in theta_sun0 ([`Free::SunPhase`]), rad.
    pub phase_step: f64,
    /// Rate of the Sun direction in the synodic frame (1/TU), for SRP candidates.
    pub sun_omega: f64,
    /// Worker threads (None: all cores) and cases per task of the sweeps.
    pub threads: Option<usize>,
    pub chunk: usize,
    /// Compute the full-period monodromy of half-closure corrections (one more sweep over the
    /// full period); when false their `monodromy` is NaN (e.g. when every solution is
    /// re-propagated independently with its STM anyway).
    pub monodromy: bool,
}

impl Default for CorrectorOptions {
    fn default() -> Self {
        Self {
            tol: 1e-12,
            max_iter: 40,
            rtol: 1e-13,
            atol: 1e-13,
            max_steps: 200_000,
            max_wz_step: 0.5,
            max_angle_step: 0.5,
            max_halvings: 10,
            max_contraction: f64::INFINITY,
            phase_step: 1e-6,
            sun_omega: OMEGA_SUN,
            threads: None,
            chunk: 64,
            monodromy: true,
        }
    }
}

/// The outcome of one candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correction {
    /// Final unknowns (the last accepted point; the start when nothing was accepted). Angles
    /// are not wrapped (the residual is exactly the one of these values).
    pub phi0: f64,
    pub wz0: f64,
    pub theta_sun0: f64,
    /// Full: (phi(KT) - phi0 - 2 pi turns, wz(KT) - wz0). Half: (phi(KT/2) - phi0 - pi turns,
    /// NaN). NaN when the starting point could not be integrated.
    pub residual: [f64; 2],
    /// Max-norm of the residual (NaN when it could not be evaluated).
    pub residual_norm: f64,
    /// Accepted Newton steps.
    pub iterations: usize,
    pub reason: StopReason,
    /// Full-period (K T) monodromy d(phi, wz)(KT)/d(phi0, wz0), row-major, at the final point
    /// (for Half from one extra batched sweep over 2 `t_final`); NaN when not available.
    pub monodromy: [f64; 4],
    /// The freed parameter's final value ([`correct_bordered`]; the candidate's Kz or eps
    /// otherwise).
    pub parameter: f64,
    /// d F / d (angle, wz0, parameter) at the final point, rows F = (phi closure, wz closure)
    /// (Half: the first row only, d g / d wz0 and d g / d parameter); NaN where not computed
    /// (the angle column of Half, the parameter column without a bordered correction, the
    /// second row of Half). The continuation driver takes the family's tangent from it.
    pub jacobian: [[f64; 3]; 2],
}

impl Correction {
    pub fn converged(&self) -> bool {
        self.reason == StopReason::Converged
    }
}

#[derive(Clone, Copy)]
struct Form {
    closure: Closure,
    free: Free,
    h: f64,
    bordered: Option<Bordered>,
    /// The freed parameter's range (Kz: [-1, 1]; the orbit's x0: the family's members).
    bounds: (f64, f64),
    /// Step caps in wz0 and in the angle unknown (from the options).
    max_wz_step: f64,
    max_angle_step: f64,
}

const ANGLE: usize = 0;
const WZ: usize = 1;
const PARAM: usize = 2;

impl Form {
    fn cases_per_point(&self) -> usize {
        1 + if self.closure == Closure::Full && self.free == Free::SunPhase { 2 } else { 0 } + if self.differences() { 2 } else { 0 }
    }

    /// Whether d F / d parameter comes from central differences (two more trajectories per
    /// point: the orbit's x0, each value its own orbit); Kz and eps enter the torques linearly,
    /// and their derivative is integrated with the trajectory ([`Sensitivity`]).
    fn differences(&self) -> bool {
        self.bordered.is_some_and(|b| b.parameter == Parameter::OrbitX0)
    }

    /// The lanes' parameter sensitivity this form needs.
    fn sensitivity(&self) -> Sensitivity {
        match self.bordered.map(|b| b.parameter) {
            Some(Parameter::Kz) => Sensitivity::Kz,
            Some(Parameter::Eps) => Sensitivity::Eps,
            _ => Sensitivity::None,
        }
    }

    /// The residual rows and unknown columns in use.
    fn rows(&self) -> &'static [usize] {
        match (self.closure, self.bordered.is_some()) {
            (Closure::Half, false) => &[0],
            (Closure::Half, true) => &[0, 2],
            (Closure::Full, false) => &[0, 1],
            (Closure::Full, true) => &[0, 1, 2],
        }
    }

    fn cols(&self) -> &'static [usize] {
        match (self.closure, self.bordered.is_some()) {
            (Closure::Half, false) => &[WZ],
            (Closure::Half, true) => &[WZ, PARAM],
            (Closure::Full, false) => &[ANGLE, WZ],
            (Closure::Full, true) => &[ANGLE, WZ, PARAM],
        }
    }

    fn initial(&self, c: &Candidate) -> [f64; 3] {
        let angle = if self.closure == Closure::Full && self.free == Free::SunPhase { c.case.theta_sun0 } else { c.case.phi0 };
        let p = match self.bordered.map(|b| b.parameter) {
            Some(Parameter::Eps) => c.case.eps,
            Some(Parameter::OrbitX0) => c.x0,
            _ => c.case.kz,
        };
        [angle, c.case.wz0, p]
    }

    /// The trajectory of the point x; None when the parameter leaves its range.
    fn case_at(&self, c: &Candidate, x: [f64; 3]) -> Option<Case> {
        let mut k = Case { wz0: x[WZ], ..c.case };
        if self.closure == Closure::Full {
            match self.free {
                Free::Phi0 => k.phi0 = x[ANGLE],
                Free::SunPhase => k.theta_sun0 = x[ANGLE],
            }
        }
        if self.bordered.is_some() && !(self.bounds.0 <= x[PARAM] && x[PARAM] <= self.bounds.1) {
            return None;
        }
        match self.bordered.map(|b| b.parameter) {
            Some(Parameter::Kz) => k.kz = x[PARAM],
            Some(Parameter::Eps) => k.eps = x[PARAM],
            Some(Parameter::OrbitX0) | None => {}
        }
        Some(k)
    }

    /// The parameter values of the central difference (one-sided at the ends of its range).
    fn parameter_pair(&self, p: f64) -> (f64, f64) {
        let step = self.bordered.map_or(1e-6, |b| b.step);
        ((p + step).min(self.bounds.1), (p - step).max(self.bounds.0))
    }

    /// Push the point's trajectories with the parameter value each one runs at (the orbit's x0
    /// for [`Parameter::OrbitX0`]); false when it cannot be integrated (parameter out of range).
    fn push_cases(&self, c: &Candidate, x: [f64; 3], out: &mut Vec<(Case, f64)>) -> bool {
        let Some(k) = self.case_at(c, x) else { return false };
        out.push((k, x[PARAM]));
        if self.closure == Closure::Full && self.free == Free::SunPhase {
            for th in [x[ANGLE] + self.h, x[ANGLE] - self.h] {
                out.push((Case { theta_sun0: th, ..k }, x[PARAM]));
            }
        }
        if self.differences() {
            let (pp, pm) = self.parameter_pair(x[PARAM]);
            for v in [pp, pm] {
                out.push((k, v));
            }
        }
        true
    }

    /// The closure residuals (phi, wz) of one trajectory.
    fn closure_residual(&self, c: &Candidate, x: [f64; 3], o: &Outcome) -> [f64; 2] {
        match self.closure {
            Closure::Half => [o.phi_t - c.case.phi0 - PI * c.turns, f64::NAN],
            Closure::Full => full_closure_residual(if self.free == Free::Phi0 { x[ANGLE] } else { c.case.phi0 }, x[WZ], c.turns, o.phi_t, o.wz_t),
        }
    }

    /// The residual and Jacobian from the point's trajectories; None when any failed or is
    /// non-finite.
    fn eval(&self, c: &Candidate, x: [f64; 3], o: &[Outcome]) -> Option<Eval<3>> {
        let ok = |o: &Outcome| o.status == LaneStatus::Ok && o.phi_t.is_finite() && o.wz_t.is_finite() && o.stm.iter().all(|v| v.is_finite());
        if o.len() != self.cases_per_point() || !o.iter().all(ok) {
            return None;
        }
        let m = o[0].stm;
        let r = self.closure_residual(c, x, &o[0]);
        let mut f = [r[0], r[1], f64::NAN];
        let mut jac = [[f64::NAN; 3]; 3];
        match self.closure {
            Closure::Half => {
                jac[0][ANGLE] = 0.0;
                jac[0][WZ] = m[1];
            }
            Closure::Full => {
                if self.free == Free::Phi0 {
                    jac[0][ANGLE] = m[0] - 1.0;
                    jac[1][ANGLE] = m[2];
                } else {
                    let k = 0.5 / self.h;
                    jac[0][ANGLE] = (o[1].phi_t - o[2].phi_t) * k;
                    jac[1][ANGLE] = (o[1].wz_t - o[2].wz_t) * k;
                }
                jac[0][WZ] = m[1];
                jac[1][WZ] = m[3] - 1.0;
            }
        }
        if let Some(b) = self.bordered {
            if self.differences() {
                let j = self.cases_per_point() - 2;
                let (pp, pm) = self.parameter_pair(x[PARAM]);
                let (rp, rm) = (self.closure_residual(c, x, &o[j]), self.closure_residual(c, x, &o[j + 1]));
                jac[0][PARAM] = (rp[0] - rm[0]) / (pp - pm);
                jac[1][PARAM] = (rp[1] - rm[1]) / (pp - pm);
            } else {
                // the closure residuals' derivatives are those of phi(T) and wz(T)
                let d = o[0].dparam;
                if !(d[0].is_finite() && d[1].is_finite()) {
                    return None;
                }
                jac[0][PARAM] = d[0];
                jac[1][PARAM] = if self.closure == Closure::Full { d[1] } else { f64::NAN };
            }
            let (a, rhs) = c.condition.unwrap_or((b.a, b.b));
            f[2] = a[0] * x[0] + a[1] * x[1] + a[2] * x[2] - rhs;
            jac[2] = a;
        }
        Some(Eval { f, jac, keep: m.to_vec() })
    }
}

impl Problem<3> for Form {
    type Cand = Candidate;
    type Traj = (Case, f64);
    type Out = Outcome;
    fn initial(&self, c: &Candidate) -> [f64; 3] {
        Form::initial(self, c)
    }
    fn push(&self, c: &Candidate, x: &[f64; 3], out: &mut Vec<(Case, f64)>) -> bool {
        self.push_cases(c, *x, out)
    }
    fn per_point(&self) -> usize {
        self.cases_per_point()
    }
    fn evaluate(&self, c: &Candidate, x: &[f64; 3], o: &[Outcome]) -> Option<Eval<3>> {
        self.eval(c, *x, o)
    }
    fn rows(&self) -> &[usize] {
        Form::rows(self)
    }
    fn closure_rows(&self) -> &[usize] {
        let r = Form::rows(self);
        if self.bordered.is_some() {
            &r[..r.len() - 1]
        } else {
            r
        }
    }
    fn cols(&self) -> &[usize] {
        Form::cols(self)
    }
    fn admits(&self, c: &Candidate, x: &[f64; 3]) -> bool {
        c.window.is_none_or(|(lo, hi)| (lo..=hi).contains(&x[WZ]))
    }
    fn step_scale(&self, d: &[f64; 3]) -> f64 {
        let cap = |v: f64, m: f64| if v.abs() > m { m / v.abs() } else { 1.0 };
        let mut scale = cap(d[WZ], self.max_wz_step).min(cap(d[ANGLE], self.max_angle_step));
        if let Some(b) = self.bordered {
            scale = scale.min(cap(d[PARAM], b.max_step));
        }
        scale
    }
}

/// The [`Correction`] of a candidate's track.
fn result(form: &Form, cand: &Candidate, track: &Track<3>, monodromy: [f64; 4]) -> Correction {
    let x = track.x();
    let c = &cand.case;
    let (phi0, theta_sun0) = match (form.closure, form.free) {
        (Closure::Half, _) => (c.phi0, c.theta_sun0),
        (Closure::Full, Free::Phi0) => (x[ANGLE], c.theta_sun0),
        (Closure::Full, Free::SunPhase) => (c.phi0, x[ANGLE]),
    };
    let jac = track.cur.as_ref().map_or([[f64::NAN; 3]; 3], |p| p.jac);
    let mut jacobian = [jac[0], jac[1]];
    if form.closure == Closure::Half {
        jacobian[0][ANGLE] = f64::NAN;
        jacobian[1] = [f64::NAN; 3];
    }
    Correction {
        phi0,
        wz0: x[WZ],
        theta_sun0,
        residual: track.cur.as_ref().map_or([f64::NAN; 2], |p| [p.f[0], p.f[1]]),
        residual_norm: track.cur.as_ref().map_or(f64::NAN, |p| p.norm),
        iterations: track.iterations,
        reason: track.reason(),
        monodromy,
        parameter: x[PARAM],
        jacobian,
    }
}

/// Whether the table's S(T - t) = -S(t), C(T - t) = C(t) (an x-symmetric orbit started on the
/// x axis), to 1e-8 of max(|S|, |C|) at 16 interior times; the largest deviation otherwise.
fn forcing_asymmetry(f: &OrbitForcing) -> f64 {
    (0..16)
        .map(|k| {
            let t = f.period * (k as f64 + 0.37) / 16.0;
            let (s1, c1) = f.sc(t);
            let (s2, c2) = f.sc(f.period - t);
            (s1 + s2).abs().max((c1 - c2).abs()) / f.scale.max(f64::MIN_POSITIVE)
        })
        .fold(0.0, f64::max)
}

/// Whether `t` is a whole multiple (>= 1) of `unit`, to 1e-9 relative.
fn is_multiple(t: f64, unit: f64) -> bool {
    let k = (t / unit).round();
    k >= 1.0 && (t - k * unit).abs() <= 1e-9 * t
}

fn validate_options(opts: &CorrectorOptions) -> Result<()> {
    check_positive("tol", opts.tol)?;
    crate::integrate::check_tolerances(opts.rtol, opts.atol)?;
    check_positive("max_wz_step", opts.max_wz_step)?;
    check_positive("max_angle_step", opts.max_angle_step)?;
    check_positive("phase_step", opts.phase_step)?;
    if !opts.sun_omega.is_finite() {
        return Err(invalid("sun_omega", format!("must be finite, got {}", opts.sun_omega)));
    }
    if opts.max_iter == 0 {
        return Err(invalid("max_iter", "must be >= 1"));
    }
    if opts.max_steps == 0 {
        return Err(invalid("max_steps", "must be >= 1"));
    }
    if opts.max_halvings > 60 {
        return Err(invalid("max_halvings", format!("must be in [0, 60], got {}", opts.max_halvings)));
    }
    if !(opts.max_contraction > 0.0) {
        return Err(invalid("max_contraction", format!("must be > 0 (infinite: no test), got {}", opts.max_contraction)));
    }
    if opts.chunk == 0 {
        return Err(invalid("chunk", "must be >= 1"));
    }
    if opts.threads == Some(0) {
        return Err(invalid("threads", "must be >= 1 (or None for all cores)"));
    }
    Ok(())
}

fn validate(forcing: &OrbitForcing, t_final: f64, closure: Closure, free: Free, candidates: &[Candidate], opts: &CorrectorOptions) -> Result<()> {
    check_positive("t_final", t_final)?;
    validate_options(opts)?;
    match closure {
        Closure::Half => {
            if free != Free::Phi0 {
                return Err(invalid("free", "the half-period closure corrects wz0 only: use Free::Phi0 (phi0 is kept), or Closure::Full for the Sun phase"));
            }
            if !is_multiple(t_final, 0.5 * forcing.period) {
                return Err(invalid("t_final", format!("the half-period closure needs t_final = K T / 2 (K >= 1, T = {}), got {t_final}", forcing.period)));
            }
            let a = forcing_asymmetry(forcing);
            if !(a <= 1e-8) {
                return Err(invalid(
                    "closure",
                    format!("the half-period closure needs an x-symmetric orbit started on the x axis: S(T - t) = -S(t), C(T - t) = C(t) fail by {a:.2e} relative (use Closure::Full)"),
                ));
            }
        }
        Closure::Full => {
            if !is_multiple(t_final, forcing.period) {
                return Err(invalid("t_final", format!("the full closure needs t_final = K T (K >= 1, T = {}), got {t_final}", forcing.period)));
            }
        }
    }
    validate_candidates(closure, free, candidates)
}

fn validate_candidates(closure: Closure, free: Free, candidates: &[Candidate]) -> Result<()> {
    for (i, c) in candidates.iter().enumerate() {
        let k = &c.case;
        if !(k.phi0.is_finite() && k.wz0.is_finite()) {
            return Err(invalid("wz0", format!("candidate {i}: phi0 and wz0 must be finite, got ({}, {})", k.phi0, k.wz0)));
        }
        if !(k.kz.is_finite() && (-1.0..=1.0).contains(&k.kz)) {
            return Err(invalid("kz", format!("candidate {i}: must be in [-1, 1], got {}", k.kz)));
        }
        if !c.turns.is_finite() {
            return Err(invalid("turns", format!("candidate {i}: must be finite, got {}", c.turns)));
        }
        if let Some((lo, hi)) = c.window {
            if !(lo <= k.wz0 && k.wz0 <= hi) {
                return Err(invalid("window", format!("candidate {i}: need lo <= wz0 <= hi (infinite bounds allowed), got ({lo}, {hi}) with wz0 = {}", k.wz0)));
            }
        }
        if !(k.eps.is_finite() && k.theta_sun0.is_finite()) {
            return Err(invalid("eps", format!("candidate {i}: eps and theta_sun0 must be finite, got ({}, {})", k.eps, k.theta_sun0)));
        }
        if !(k.cs >= 0.0 && k.cd >= 0.0 && k.cs + k.cd <= 1.0 + 1e-12) {
            return Err(invalid("cs", format!("candidate {i}: need cs, cd >= 0 and cs + cd <= 1, got ({}, {})", k.cs, k.cd)));
        }
        if closure == Closure::Half {
            if k.eps != 0.0 {
                return Err(invalid("eps", format!("candidate {i}: the half-period closure needs no SRP (eps = 0), got {} (use Closure::Full)", k.eps)));
            }
            let m = k.phi0 / FRAC_PI_2;
            if (m - m.round()).abs() > 1e-12 {
                return Err(invalid("phi0", format!("candidate {i}: the half-period closure needs phi0 a multiple of pi/2, got {} (use Closure::Full)", k.phi0)));
            }
        }
        if free == Free::SunPhase && k.eps == 0.0 {
            return Err(invalid("free", format!("candidate {i}: Free::SunPhase needs an SRP plate (eps != 0)")));
        }
    }
    Ok(())
}

/// Correct many candidates at once to periodic planar attitude motions along the orbit of
/// `forcing` (see the module documentation for the three forms). `t_final` is the closure time:
/// K T for [`Closure::Full`], K T / 2 for [`Closure::Half`] (the monodromy is then over K T).
///
/// Returns one [`Correction`] per candidate, in order; `Err` only for invalid arguments (each
/// naming the parameter and its allowed range, candidate index included). Results do not depend
/// on `threads` or `chunk`; a candidate's last bits (~1e-14) can depend on its batch companions
/// (lock-step lanes share their step size).
pub fn correct_planar_attitudes(
    forcing: &OrbitForcing,
    t_final: f64,
    closure: Closure,
    free: Free,
    candidates: &[Candidate],
    opts: &CorrectorOptions,
) -> Result<Vec<Correction>> {
    validate(forcing, t_final, closure, free, candidates, opts)?;
    let form = Form { closure, free, h: opts.phase_step, bordered: None, bounds: (f64::NEG_INFINITY, f64::INFINITY), max_wz_step: opts.max_wz_step, max_angle_step: opts.max_angle_step };
    run(form, candidates, opts, &on_table(forcing, t_final, opts, Sensitivity::None), LANES)
}

/// The bordered correction of continuation: as [`correct_planar_attitudes`], with the
/// parameter of `bordered` (Kz or eps) an unknown too and its linear condition closing the
/// system (pseudo-arclength: the tangent's components and the step; natural: the parameter
/// fixed). Every candidate starts from its own parameter value (its case's Kz or eps).
/// [`Correction::parameter`] is the final value and [`Correction::jacobian`] holds d F / d
/// parameter, from which the driver takes the family's tangent.
pub fn correct_bordered(
    forcing: &OrbitForcing,
    t_final: f64,
    closure: Closure,
    free: Free,
    bordered: &Bordered,
    candidates: &[Candidate],
    opts: &CorrectorOptions,
) -> Result<Vec<Correction>> {
    validate_bordered(bordered, closure, candidates)?;
    if bordered.parameter == Parameter::OrbitX0 {
        return Err(invalid("parameter", "the orbit's x0 is freed by correct_across_family"));
    }
    validate(forcing, t_final, closure, free, candidates, opts)?;
    let bounds = if bordered.parameter == Parameter::Kz { (-1.0, 1.0) } else { (f64::NEG_INFINITY, f64::INFINITY) };
    let form = Form { closure, free, h: opts.phase_step, bordered: Some(*bordered), bounds, max_wz_step: opts.max_wz_step, max_angle_step: opts.max_angle_step };
    run(form, candidates, opts, &on_table(forcing, t_final, opts, form.sensitivity()), LANES)
}

fn validate_condition(a: &[f64; 3], b: f64, closure: Closure, whose: &str) -> Result<()> {
    if let Some(i) = a.iter().position(|v| !v.is_finite()) {
        return Err(invalid("a", format!("{whose}must be finite, component {i} is {}", a[i])));
    }
    if !b.is_finite() {
        return Err(invalid("b", format!("{whose}must be finite, got {b}")));
    }
    if closure == Closure::Half && a[0] != 0.0 {
        return Err(invalid("a", format!("{whose}the half-period closure has no angle unknown: a[0] must be 0")));
    }
    if a.iter().all(|&v| v == 0.0) {
        return Err(invalid("a", format!("{whose}the linear condition needs a non-zero row")));
    }
    Ok(())
}

fn validate_bordered(bordered: &Bordered, closure: Closure, candidates: &[Candidate]) -> Result<()> {
    validate_condition(&bordered.a, bordered.b, closure, "")?;
    for (i, c) in candidates.iter().enumerate() {
        if let Some((a, b)) = c.condition {
            validate_condition(&a, b, closure, &format!("candidate {i}: "))?;
        }
    }
    check_positive("step", bordered.step)?;
    check_positive("max_step", bordered.max_step)?;
    if bordered.parameter == Parameter::Eps && closure == Closure::Half {
        return Err(invalid("parameter", "eps breaks the mirror symmetry: continue in eps with Closure::Full"));
    }
    Ok(())
}

/// Integrates a batch of trajectories: (cases, the parameter value of each, full period?) ->
/// outcomes in order.
type Integrate<'a> = dyn Fn(&[Case], &[f64], bool) -> Result<Vec<Outcome>> + Sync + 'a;

/// All trajectories on one orbit's forcing table, in one sweep (over `t_final`, or twice it for
/// the half closure's full-period monodromy).
fn on_table<'a>(forcing: &'a OrbitForcing, t_final: f64, opts: &CorrectorOptions, sensitivity: Sensitivity) -> impl Fn(&[Case], &[f64], bool) -> Result<Vec<Outcome>> + Sync + 'a {
    let lane = LaneOptions { rtol: opts.rtol, atol: opts.atol, max_steps: opts.max_steps, sun_omega: opts.sun_omega, sensitivity, ..LaneOptions::default() };
    let chunk = opts.chunk;
    move |cases: &[Case], _: &[f64], full: bool| {
        // small batches (a few branches of a lock-step continuation) still spread over every
        // worker: no more than an even share per task (results do not depend on the chunk)
        let share = cases.len().div_ceil(rayon::current_num_threads()).max(1);
        map::sweep(forcing, if full { 2.0 * t_final } else { t_final }, cases, &lane, true, chunk.min(share), None)
    }
}

const FAILED: Outcome = Outcome { phi_t: f64::NAN, wz_t: f64::NAN, stm: [f64::NAN; 4], dparam: [f64::NAN; 2], accepted: 0, rejected: 0, status: LaneStatus::Failed };

/// The planar forms on the one Newton driver ([`super::newton::solve`]): all pending points of
/// all candidates integrated in one call of `integrate` per iteration, a line search per
/// candidate; then the full-period monodromy of half-closure corrections.
/// `group`: the lock-step group of `integrate`'s batches ([`Settings::group`]).
fn run(form: Form, candidates: &[Candidate], opts: &CorrectorOptions, integrate: &Integrate<'_>, group: usize) -> Result<Vec<Correction>> {
    let settings = Settings { tol: opts.tol, max_iter: opts.max_iter, max_halvings: opts.max_halvings, group, max_contraction: opts.max_contraction };
    with_threads_rounds(opts.threads, || -> Result<Vec<Correction>> {
        let tracks = newton::solve(&form, candidates, &settings, &|b: &[(Case, f64)]| integrate_batch(integrate, b, false))?;
        let stm = |t: &Track<3>| t.cur.as_ref().map_or([f64::NAN; 4], |p| [p.keep[0], p.keep[1], p.keep[2], p.keep[3]]);
        let mut mono: Vec<[f64; 4]> = tracks.iter().map(stm).collect();
        if form.closure == Closure::Half && !opts.monodromy {
            mono.fill([f64::NAN; 4]);
        } else if form.closure == Closure::Half {
            // The full-period monodromy: one more batch over K T at the final points.
            let full: Vec<(usize, (Case, f64))> = (0..tracks.len())
                .filter_map(|i| tracks[i].cur.as_ref().and_then(|p| form.case_at(&candidates[i], p.x).map(|k| (i, (k, p.x[PARAM])))))
                .collect();
            let cases: Vec<(Case, f64)> = full.iter().map(|&(_, k)| k).collect();
            let out = integrate_batch(integrate, &cases, true)?;
            for (&(i, _), o) in full.iter().zip(&out) {
                mono[i] = if o.status == LaneStatus::Ok { o.stm } else { [f64::NAN; 4] };
            }
        }
        Ok(tracks.iter().zip(candidates).zip(mono).map(|((t, c), m)| result(&form, c, t, m)).collect())
    })?
}

fn integrate_batch(integrate: &Integrate<'_>, batch: &[(Case, f64)], full: bool) -> Result<Vec<Outcome>> {
    if batch.is_empty() {
        return Ok(Vec::new());
    }
    let cases: Vec<Case> = batch.iter().map(|b| b.0).collect();
    let values: Vec<f64> = batch.iter().map(|b| b.1).collect();
    integrate(&cases, &values, full)
}

/// Members of a planar x-z-symmetric orbit family (DROs, planar Lyapunov orbits), as the
/// guesses from which the orbit through any x0 in their range is corrected on demand (half-period
/// single shooting with x0 fixed, the ydot0 guess interpolated between members), with its
/// forcing table; both kept in a cache (the continuation comes back to the same x0 when it
/// locates folds). Thread-safe.
pub struct PlanarFamily {
    mu: f64,
    x0: Vec<f64>,
    vy0: Vec<f64>,
    cache: Mutex<HashMap<u64, Arc<(SymmetricOrbit, OrbitForcing)>>>,
}

impl PlanarFamily {
    /// `x0`, `vy0`: the members' initial states (any order; at least two, distinct x0).
    pub fn new(mu: f64, x0: &[f64], vy0: &[f64]) -> Result<Self> {
        check_mu(mu)?;
        if x0.len() != vy0.len() || x0.len() < 2 {
            return Err(invalid("x0", format!("need at least two members with x0 and vy0 of one length, got {} and {}", x0.len(), vy0.len())));
        }
        check_finite("x0", x0)?;
        check_finite("vy0", vy0)?;
        let mut idx: Vec<usize> = (0..x0.len()).collect();
        idx.sort_by(|&a, &b| x0[a].total_cmp(&x0[b]));
        let (xs, vs): (Vec<f64>, Vec<f64>) = idx.iter().map(|&i| (x0[i], vy0[i])).unzip();
        if xs.windows(2).any(|w| w[0] == w[1]) {
            return Err(invalid("x0", "members must have distinct x0"));
        }
        Ok(Self { mu, x0: xs, vy0: vs, cache: Mutex::new(HashMap::new()) })
    }

    /// The members' x0 range.
    pub fn range(&self) -> (f64, f64) {
        (self.x0[0], self.x0[self.x0.len() - 1])
    }

    /// The orbit through (x0, 0, 0) of the family and its forcing table.
    pub fn orbit_at(&self, x0: f64) -> Result<Arc<(SymmetricOrbit, OrbitForcing)>> {
        let (lo, hi) = self.range();
        if !(x0.is_finite() && lo <= x0 && x0 <= hi) {
            return Err(invalid("x0", format!("must be within the family's members, [{lo}, {hi}], got {x0}")));
        }
        if let Some(o) = self.cache.lock().map_err(|_| invalid("family", "cache poisoned"))?.get(&x0.to_bits()) {
            return Ok(o.clone());
        }
        let j = self.x0.partition_point(|&v| v < x0).clamp(1, self.x0.len() - 1);
        let w = (x0 - self.x0[j - 1]) / (self.x0[j] - self.x0[j - 1]);
        let guess = self.vy0[j - 1] + w * (self.vy0[j] - self.vy0[j - 1]);
        let mut sh = SymmetricShooting::new(self.mu, false, Options::with_tolerances(1e-13, 1e-13));
        sh.tol = 1e-12;
        let orbit = sh.correct([x0, 0.0, guess], Constraint::Fix(Var::X0, x0))?;
        let forcing = OrbitForcing::new(self.mu, &orbit.state0, orbit.period, [true, true], 1e-12)?;
        let out = Arc::new((orbit, forcing));
        let mut c = self.cache.lock().map_err(|_| invalid("family", "cache poisoned"))?;
        if c.len() > 4096 {
            c.clear();
        }
        c.insert(x0.to_bits(), out.clone());
        Ok(out)
    }

    /// The family's orbit through (x, 0, 0) to first order from the corrected member `near`:
    /// along the family's tangent there (d vy0 / d x0 from the half-period condition
    /// xdot_c(x0, vy0) = 0, and d T / d x0), with its forcing table: (period, table). For the
    /// central differences in x0 of [`correct_across_family`]: the linearisation's O(dx^2)
    /// error is the same on both sides and cancels in the difference quotient, and no Newton
    /// correction is needed for the two neighbours.
    pub fn linearised(&self, near: &SymmetricOrbit, x: f64) -> Result<(f64, OrbitForcing)> {
        let e = &near.evaluation;
        let v = e.tangent(false, [1.0, 0.0, 0.0]).ok_or_else(|| invalid("x0", "the family has no tangent in x0 at this member (a fold in x0)"))?;
        let dhalf = e.dhalf[0] * v[0] + e.dhalf[2] * v[2];
        let dx = x - near.state0[0];
        let state0 = [x, 0.0, 0.0, 0.0, near.state0[4] + v[2] * dx, 0.0];
        let period = near.period + 2.0 * dhalf * dx;
        check_finite("x0", &state0)?;
        check_positive("period", period)?;
        Ok((period, OrbitForcing::new(self.mu, &state0, period, [true, true], 1e-12)?))
    }
}

/// The bordered half-period correction across a planar orbit family: unknowns (wz0, x0) of
/// the symmetric motion phi(T(x0)/2) = phi0 + pi turns (K = 1), the orbit's x0 freed and closed
/// by the linear condition a[1] wz0 + a[2] x0 = b (a[0] must be 0); d g / d x0 by central
/// differences over the orbits at x0 +- `bordered.step` (the point's orbit corrected, its two
/// neighbours linearised from it with [`PlanarFamily::linearised`]; every table and trajectory
/// group in parallel). Returns [`Correction`]s as [`correct_bordered`]
/// (`parameter` = x0; the monodromy over the orbit's full period).
pub fn correct_across_family(family: &PlanarFamily, bordered: &Bordered, candidates: &[Candidate], opts: &CorrectorOptions) -> Result<Vec<Correction>> {
    if bordered.parameter != Parameter::OrbitX0 {
        return Err(invalid("parameter", "correct_across_family frees the orbit's x0 (Parameter::OrbitX0)"));
    }
    validate_bordered(bordered, Closure::Half, candidates)?;
    validate_options(opts)?;
    validate_candidates(Closure::Half, Free::Phi0, candidates)?;
    let form = Form { closure: Closure::Half, free: Free::Phi0, h: opts.phase_step, bordered: Some(*bordered), bounds: family.range(), max_wz_step: opts.max_wz_step, max_angle_step: opts.max_angle_step };
    let lane = LaneOptions { rtol: opts.rtol, atol: opts.atol, max_steps: opts.max_steps, sun_omega: opts.sun_omega, ..LaneOptions::default() };
    let integrate = |cases: &[Case], values: &[f64], full: bool| -> Result<Vec<Outcome>> {
        // The Newton iterations push each point as a triple (x0, x0 + h, x0 - h)
        // (`Form::push_cases`); the full-period monodromy batch pushes the points alone. Each
        // point's orbit is corrected (cached); its two neighbours are linearised from it.
        if !full && values.len() % 3 != 0 {
            return Err(invalid("values", "correct_across_family: the iterations' trajectories must come in (x0, x0 + h, x0 - h) triples"));
        }
        let centre_of = |i: usize| if full { values[i] } else { values[i - i % 3] };
        let mut centres: Vec<f64> = (0..values.len()).map(centre_of).collect();
        centres.sort_by(f64::total_cmp);
        centres.dedup();
        let orbits: Vec<Option<Arc<(SymmetricOrbit, OrbitForcing)>>> = centres.par_iter().map(|&x| family.orbit_at(x).ok()).collect();
        // one job per distinct (centre, value): its table and its trajectories, in parallel
        let mut jobs: Vec<(usize, f64, Vec<usize>)> = Vec::new();
        for (i, &v) in values.iter().enumerate() {
            let k = centres.binary_search_by(|c| c.total_cmp(&centre_of(i))).map_err(|_| invalid("values", "centre not found"))?;
            match jobs.iter_mut().find(|j| j.0 == k && j.1.to_bits() == v.to_bits()) {
                Some(j) => j.2.push(i),
                None => jobs.push((k, v, vec![i])),
            }
        }
        let swept: Vec<Result<Option<Vec<Outcome>>>> = jobs
            .par_iter()
            .map(|(k, v, idx)| {
                let Some(o) = &orbits[*k] else { return Ok(None) };
                let near;
                let (period, table) = if v.to_bits() == centres[*k].to_bits() {
                    (o.0.period, &o.1)
                } else {
                    match family.linearised(&o.0, *v) {
                        Ok(n) => {
                            near = n;
                            (near.0, &near.1)
                        }
                        Err(_) => return Ok(None),
                    }
                };
                let group: Vec<Case> = idx.iter().map(|&i| cases[i]).collect();
                let t = if full { period } else { 0.5 * period };
                map::sweep(table, t, &group, &lane, true, opts.chunk, None).map(Some)
            })
            .collect();
        let mut out = vec![FAILED; cases.len()];
        for ((_, _, idx), r) in jobs.iter().zip(swept) {
            if let Some(r) = r? {
                for (&i, v) in idx.iter().zip(r) {
                    out[i] = v;
                }
            }
        }
        Ok(out)
    };
    // each (orbit, value) is its own sweep: the batch's groups are not its consecutive blocks
    run(form, candidates, opts, &integrate, 1)
}

/// One trajectory to re-propagate with [`verify_planar_attitudes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarStart {
    pub kz: f64,
    pub phi0: f64,
    pub wz0: f64,
    /// Optional flat plate (SRP); its Sun carries the phase and rate.
    pub plate: Option<FlatPlate>,
}

/// The end of one re-propagated trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarEnd {
    pub phi_t: f64,
    pub wz_t: f64,
    /// d(phi, wz)(t_final) / d(phi0, wz0), row-major.
    pub stm: [f64; 4],
    /// The integration error of this item (then the values are NaN).
    pub error: Option<Error>,
}

/// Independent re-propagation of many planar attitude motions along the orbit `orbit_state0`:
/// the orbit integrated alongside (not the forcing table), rtol = atol = 1e-14 (the correctors
/// integrate at 1e-13 on the table), with the 2x2 STM, a step never spanning a plate's
/// terminator crossing: the SIMD lanes with the orbit's CR3BP states
/// ([`crate::integrate::lanes::integrate_along`]), in lock-step groups of eight taken in item
/// order, the groups in parallel on rayon (`threads`; None: all cores). An item's result
/// depends on its group (the shared steps), never on the thread count. A group whose run fails
/// is run again one item at a time, so that only the items that fail alone carry their error
/// (and NaN values). `Err` for invalid arguments, or plates whose Suns turn at different rates.
pub fn verify_planar_attitudes(
    mu: f64,
    orbit_state0: &[f64; 6],
    t_final: f64,
    items: &[PlanarStart],
    primaries: [bool; 2],
    threads: Option<usize>,
) -> Result<Vec<PlanarEnd>> {
    check_mu(mu)?;
    check_finite("orbit_state0", orbit_state0)?;
    check_positive("t_final", t_final)?;
    if orbit_state0[2] != 0.0 || orbit_state0[5] != 0.0 {
        return Err(invalid("orbit_state0", format!("the planar model needs a planar orbit (z = zd = 0), got z = {}, zd = {}", orbit_state0[2], orbit_state0[5])));
    }
    if threads == Some(0) {
        return Err(invalid("threads", "must be >= 1 (or None for all cores)"));
    }
    for (i, it) in items.iter().enumerate() {
        if !(it.kz.is_finite() && (-1.0..=1.0).contains(&it.kz)) {
            return Err(invalid("kz", format!("item {i}: must be in [-1, 1], got {}", it.kz)));
        }
        if !(it.phi0.is_finite() && it.wz0.is_finite()) {
            return Err(invalid("wz0", format!("item {i}: phi0 and wz0 must be finite, got ({}, {})", it.phi0, it.wz0)));
        }
        if let Some(p) = &it.plate {
            let ok = p.eps.is_finite() && p.sun.theta0.is_finite() && p.sun.omega.is_finite() && p.cs >= 0.0 && p.cd >= 0.0 && p.cs + p.cd <= 1.0 + 1e-12;
            if !ok {
                return Err(invalid("plate", format!("item {i}: eps, the Sun phase and rate must be finite, cs, cd >= 0 with cs + cd <= 1; got {p:?}")));
            }
        }
    }
    let omega = items.iter().find_map(|it| it.plate.map(|p| p.sun.omega)).unwrap_or(OMEGA_SUN);
    if let Some(i) = items.iter().position(|it| it.plate.is_some_and(|p| p.sun.omega != omega)) {
        return Err(invalid("plate", format!("item {i}: every plate's Sun must turn at one rate ({omega}), got {:?}", items[i].plate)));
    }
    let cases: Vec<Case> = items
        .iter()
        .map(|it| match it.plate {
            Some(p) => Case { phi0: it.phi0, wz0: it.wz0, kz: it.kz, eps: p.eps, cs: p.cs, cd: p.cd, theta_sun0: p.sun.theta0 },
            None => Case::new(it.phi0, it.wz0, it.kz),
        })
        .collect();
    let opts = LaneOptions { rtol: 1e-14, atol: 1e-14, sun_omega: omega, ..LaneOptions::default() };
    let srp = cases.iter().any(|c| c.eps != 0.0);
    let level = crate::simd::active()?;
    let run = |part: &[Case]| -> Result<Vec<(Outcome, Option<IntegrationError>)>> {
        crate::interrupt::check()?;
        if srp {
            integrate_along::<true>(level, mu, primaries, orbit_state0, t_final, part, &opts)
        } else {
            integrate_along::<false>(level, mu, primaries, orbit_state0, t_final, part, &opts)
        }
    };
    let group = |part: &[Case]| -> Result<Vec<(Outcome, Option<IntegrationError>)>> {
        let out = run(part)?;
        if part.len() > 1 && out.iter().any(|o| o.1.is_some()) {
            // a lane that fails fails its group: each item alone
            return Ok(part.chunks(1).map(run).collect::<Result<Vec<_>>>()?.concat());
        }
        Ok(out)
    };
    let parts = with_threads(threads, || cases.par_chunks(LANES).map(group).collect::<Result<Vec<_>>>())??;
    Ok(parts
        .concat()
        .into_iter()
        .map(|(o, error)| match error {
            None => PlanarEnd { phi_t: o.phi_t, wz_t: o.wz_t, stm: o.stm, error: None },
            Some(e) => PlanarEnd { phi_t: f64::NAN, wz_t: f64::NAN, stm: [f64::NAN; 4], error: Some(e.into()) },
        })
        .collect())
}
