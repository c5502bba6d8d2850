//! The dense Newton driver of the correctors whose unknowns are many and whose size is known only
//! at run time: multiple shooting of CR3BP orbits ([`crate::orbit::multiple`]), the transition of
//! orbits to the ephemeris model ([`crate::ephemeris::transition`]) and periodic motions of the
//! flexible spacecraft ([`crate::flexible::periodic`]). (The batched driver of the attitude
//! correctors, [`crate::attitude::newton`], runs many small fixed-size problems in lockstep; it
//! shares [`StopReason`] with this one.)
//!
//! A problem ([`Problem`]) gives its residual F(x) and Jacobian J(x), both already scaled so that
//! the unknowns and the rows are of comparable size; the driver stops when the max-norm of F is at
//! most `tol`. Each step solves J d = -F:
//! - square or overdetermined: in the least-squares sense, by SVD (singular values below
//!   `RANK_TOL` times the largest treated as zero);
//! - underdetermined (fewer rows than unknowns, e.g. multiple shooting with free node states and
//!   epochs): the minimum-norm step d = J^T (J J^T)^-1 (-F), by Cholesky of J J^T, or by SVD when
//!   J J^T is not positive definite; or, when the problem has an anchor, the step nearest it
//!   (see [`Problem::anchor`]).
//!
//! Then a backtracking line search: the step is halved (at most `max_halvings` times) until the
//! 2-norm of F decreases sufficiently (Armijo: |F(x + l d)|_2 <= (1 - 1e-4 l) |F(x)|_2). A trial
//! point that cannot be evaluated (its integration failed) counts as a failed trial. Nothing
//! panics; a non-finite residual is never accepted.

use nalgebra::{DMatrix, DVector};

use crate::error::{Error, Result};

/// Why a corrector stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// Residual max-norm <= tol; or, where no Newton step descends any more, <= tol times the
    /// largest |d F / d x| of the closure rows (at least 1): the integration's noise floor
    /// amplified by the motion's instability (|trace| of the monodromy ~ 1e3 for some
    /// SRP-dominated motions), the unknowns then being known to about tol. (The latter only in
    /// the attitude driver.)
    Converged,
    /// `max_iter` Newton steps taken without convergence.
    MaxIterations,
    /// The Jacobian is zero or non-finite, or rank-deficient with no decrease along its
    /// minimum-norm step (e.g. a fold: trace of the monodromy = 2).
    SingularJacobian,
    /// The line search found no sufficient decrease after `max_halvings` halvings.
    NoDescent,
    /// The integration failed (lane status not Ok, or non-finite results) at the starting
    /// point, or at every trial point of the last line search.
    IntegrationFailed,
    /// The Newton step left the candidate's search window: no solution nearby (the attitude
    /// driver, for candidates given a window, e.g. a map's crossings refined in place).
    LeftWindow,
    /// An accepted Newton step left the residual's 2-norm above `max_contraction` times its
    /// value before the step, while above the noise floor (the attitude driver, where a
    /// continuation sets it: its predictor then lies outside Newton's fast convergence, and a
    /// shorter continuation step costs less than more iterations).
    SlowConvergence,
}

impl StopReason {
    /// "converged", "max_iterations", "singular_jacobian", "no_descent", "integration_failed",
    /// "left_window", "slow_convergence".
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::MaxIterations => "max_iterations",
            Self::SingularJacobian => "singular_jacobian",
            Self::NoDescent => "no_descent",
            Self::IntegrationFailed => "integration_failed",
            Self::LeftWindow => "left_window",
            Self::SlowConvergence => "slow_convergence",
        }
    }
}

/// Settings of the driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Convergence: max-norm of the (scaled) residual.
    pub tol: f64,
    /// Newton steps at most.
    pub max_iter: usize,
    /// Halvings of a step at most in the line search.
    pub max_halvings: u32,
}

/// A problem: the residual and its Jacobian at a point of the unknowns.
pub trait Problem {
    /// F(x). An error when x cannot be evaluated (its integration failed): fatal at the start,
    /// a failed trial in the line search.
    fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>>;
    /// J(x) at the point of the last successful [`Problem::residual`] call (a problem that gets
    /// the Jacobian with the residual, from an STM, keeps it from that call).
    fn jacobian(&mut self, x: &DVector<f64>) -> Result<DMatrix<f64>>;
    /// An underdetermined problem's anchor x_a: each step is then the one of least
    /// |x + d - x_a| among the solutions of J d = -F (the minimum-norm step plus the projection
    /// of x_a - x on the null space of J), so the iteration ends at the solution nearest the
    /// anchor (to first order) instead of drifting along the null space step by step. None:
    /// the plain minimum-norm step.
    fn anchor(&self) -> Option<&DVector<f64>> {
        None
    }
}

/// The outcome: the last accepted point, its residual and Jacobian, and why the driver stopped.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub x: DVector<f64>,
    pub f: DVector<f64>,
    /// J at `x` (when it could be evaluated).
    pub jac: Option<DMatrix<f64>>,
    /// Max-norm of `f`.
    pub norm: f64,
    /// Newton steps accepted.
    pub iterations: usize,
    pub reason: StopReason,
    /// Max-norm of the residual at the start and after each accepted step.
    pub history: Vec<f64>,
    /// The error of the last failed evaluation, when the driver stopped on one.
    pub last_error: Option<Error>,
}

/// Singular values below this fraction of the largest are treated as zero.
pub const RANK_TOL: f64 = 1e-12;
/// Armijo constant of the sufficient-decrease test.
const ARMIJO: f64 = 1e-4;

fn max_norm(f: &DVector<f64>) -> f64 {
    f.iter().fold(0.0f64, |a, v| if v.is_nan() { f64::NAN } else { a.max(v.abs()) })
}

/// The Newton step d solving J d = -f (minimum-norm when underdetermined, least squares
/// otherwise); with `toward` = x_a - x (underdetermined only), the solution of J d = -f nearest
/// x_a - x: d = J+ (-f) + (I - J+ J) (x_a - x). None when J is zero, non-finite or its
/// factorisation fails.
pub fn newton_step(jac: &DMatrix<f64>, f: &DVector<f64>, toward: Option<&DVector<f64>>) -> Option<DVector<f64>> {
    if !jac.iter().all(|v| v.is_finite()) || !f.iter().all(|v| v.is_finite()) {
        return None;
    }
    let (m, n) = jac.shape();
    let toward = toward.filter(|_| m < n);
    if m < n {
        let jjt = jac * jac.transpose();
        if let Some(ch) = jjt.cholesky() {
            let mut d = jac.transpose() * ch.solve(&(-f));
            if let Some(v) = toward {
                d += v - jac.transpose() * ch.solve(&(jac * v));
            }
            if d.iter().all(|v| v.is_finite()) {
                return Some(d);
            }
        }
    }
    let svd = jac.clone().try_svd(true, true, f64::EPSILON, 500)?;
    let s1 = svd.singular_values.max();
    if !(s1 > 0.0 && s1.is_finite()) {
        return None;
    }
    let mut d = svd.solve(&(-f), RANK_TOL * s1).ok()?;
    if let Some(v) = toward {
        d += v - svd.solve(&(jac * v), RANK_TOL * s1).ok()?;
    }
    d.iter().all(|v| v.is_finite()).then_some(d)
}

/// Run Newton's method from `x0`. Errors only when the starting point cannot be evaluated or
/// the settings are invalid; every other stop is an [`Outcome`] with its [`StopReason`].
pub fn solve<P: Problem>(problem: &mut P, x0: DVector<f64>, s: &Settings) -> Result<Outcome> {
    if !(s.tol > 0.0 && s.tol.is_finite()) {
        return Err(crate::error::invalid("tol", format!("must be a finite number > 0, got {}", s.tol)));
    }
    let mut x = x0;
    let mut f = problem.residual(&x)?;
    let mut norm = max_norm(&f);
    if !norm.is_finite() {
        return Err(crate::error::invalid("x0", "the residual at the starting point is not finite"));
    }
    let mut history = vec![norm];
    let mut iterations = 0;
    let mut last_error = None;
    let mut jac: Option<DMatrix<f64>>;
    let reason = loop {
        // Ctrl-C: the finished work is the caller's to keep
        crate::interrupt::check()?;
        match problem.jacobian(&x) {
            Ok(j) => jac = Some(j),
            Err(e) => {
                jac = None;
                last_error = Some(e);
                break StopReason::IntegrationFailed;
            }
        }
        if norm <= s.tol {
            break StopReason::Converged;
        }
        if iterations >= s.max_iter {
            break StopReason::MaxIterations;
        }
        let toward = problem.anchor().map(|a| a - &x);
        let Some(d) = newton_step(jac.as_ref().expect("set above"), &f, toward.as_ref()) else { break StopReason::SingularJacobian };
        let merit = f.norm();
        let mut lambda = 1.0;
        let mut accepted = None;
        let mut any_evaluated = false;
        for _ in 0..=s.max_halvings {
            let xt = &x + &d * lambda;
            match problem.residual(&xt) {
                Ok(ft) => {
                    any_evaluated = true;
                    let nt = max_norm(&ft);
                    if nt.is_finite() && ft.norm() <= (1.0 - ARMIJO * lambda) * merit {
                        accepted = Some((xt, ft, nt));
                        break;
                    }
                }
                Err(e) => last_error = Some(e),
            }
            lambda *= 0.5;
        }
        match accepted {
            Some((xt, ft, nt)) => {
                x = xt;
                f = ft;
                norm = nt;
                iterations += 1;
                history.push(norm);
            }
            None => {
                // the residual and Jacobian of the problem must again be those of x
                if let Err(e) = problem.residual(&x) {
                    last_error = Some(e);
                }
                break if any_evaluated { StopReason::NoDescent } else { StopReason::IntegrationFailed };
            }
        }
    };
    if reason != StopReason::IntegrationFailed {
        last_error = None;
    }
    Ok(Outcome { x, f, jac, norm, iterations, reason, history, last_error })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x^2 + y^2 = 4, x - y = 0: the root (sqrt 2, sqrt 2) from (1, 0.5) (analytic; tolerance 1e-14).
    struct Circle;
    impl Problem for Circle {
        fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
            Ok(DVector::from_vec(vec![x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1]]))
        }
        fn jacobian(&mut self, x: &DVector<f64>) -> Result<DMatrix<f64>> {
            Ok(DMatrix::from_row_slice(2, 2, &[2.0 * x[0], 2.0 * x[1], 1.0, -1.0]))
        }
    }

    #[test]
    fn square_system_converges_quadratically() {
        let s = Settings { tol: 1e-14, max_iter: 20, max_halvings: 10 };
        let o = solve(&mut Circle, DVector::from_vec(vec![1.0, 0.5]), &s).unwrap();
        assert_eq!(o.reason, StopReason::Converged);
        assert!((o.x[0] - 2f64.sqrt()).abs() < 1e-14 && (o.x[1] - 2f64.sqrt()).abs() < 1e-14);
        assert!(o.iterations <= 7, "{:?}", o.history);
    }

    /// One linear condition a.x = b in 3 unknowns: the minimum-norm step lands on the closest
    /// point of the plane, x0 + a (b - a.x0) / |a|^2 (analytic; tolerance 1e-14).
    struct Plane;
    impl Problem for Plane {
        fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
            Ok(DVector::from_vec(vec![x[0] + 2.0 * x[1] - 2.0 * x[2] - 3.0]))
        }
        fn jacobian(&mut self, _: &DVector<f64>) -> Result<DMatrix<f64>> {
            Ok(DMatrix::from_row_slice(1, 3, &[1.0, 2.0, -2.0]))
        }
    }

    #[test]
    fn underdetermined_step_is_minimum_norm() {
        let s = Settings { tol: 1e-14, max_iter: 5, max_halvings: 4 };
        let x0 = DVector::from_vec(vec![1.0, 1.0, 1.0]);
        let o = solve(&mut Plane, x0, &s).unwrap();
        assert_eq!(o.reason, StopReason::Converged);
        assert_eq!(o.iterations, 1);
        let k = (3.0 - (1.0 + 2.0 - 2.0)) / 9.0;
        for (i, a) in [1.0, 2.0, -2.0].iter().enumerate() {
            assert!((o.x[i] - (1.0 + k * a)).abs() < 1e-14);
        }
    }

    /// The plane again, anchored at a point off the start: the iteration ends at the anchor's
    /// projection on the plane, x_a + a (b - a.x_a) / |a|^2 (analytic; tolerance 1e-14).
    struct AnchoredPlane(DVector<f64>);
    impl Problem for AnchoredPlane {
        fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
            Plane.residual(x)
        }
        fn jacobian(&mut self, x: &DVector<f64>) -> Result<DMatrix<f64>> {
            Plane.jacobian(x)
        }
        fn anchor(&self) -> Option<&DVector<f64>> {
            Some(&self.0)
        }
    }

    #[test]
    fn anchored_step_ends_nearest_the_anchor() {
        let s = Settings { tol: 1e-14, max_iter: 5, max_halvings: 4 };
        let xa = DVector::from_vec(vec![5.0, -1.0, 2.0]);
        let o = solve(&mut AnchoredPlane(xa.clone()), DVector::from_vec(vec![1.0, 1.0, 1.0]), &s).unwrap();
        assert_eq!(o.reason, StopReason::Converged);
        let k = (3.0 - (5.0 - 2.0 - 4.0)) / 9.0;
        for (i, a) in [1.0, 2.0, -2.0].iter().enumerate() {
            assert!((o.x[i] - (xa[i] + k * a)).abs() < 1e-13, "{:?}", o.x);
        }
    }

    /// A residual that cannot be evaluated away from the start: the driver says so.
    struct Wall;
    impl Problem for Wall {
        fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
            if x[0] > 0.5 {
                Err(crate::error::invalid("x", "outside"))
            } else {
                Ok(DVector::from_vec(vec![x[0] - 1.0]))
            }
        }
        fn jacobian(&mut self, _: &DVector<f64>) -> Result<DMatrix<f64>> {
            Ok(DMatrix::from_element(1, 1, 1.0))
        }
    }

    #[test]
    fn failed_trials_stop_with_a_reason_and_keep_the_last_point() {
        let s = Settings { tol: 1e-12, max_iter: 10, max_halvings: 3 };
        let o = solve(&mut Wall, DVector::from_vec(vec![0.0]), &s).unwrap();
        assert!(matches!(o.reason, StopReason::IntegrationFailed | StopReason::NoDescent), "{:?}", o.reason);
        assert!(o.x[0] <= 0.5);
    }
}
