//! General periodic-orbit correction by multiple shooting (single shooting is N = 1), for
//! orbits without the x-z mirror symmetry and for long or strongly unstable orbits.
//!
//! Unknowns: N patch states X_0..X_{N-1} (6 each) and the period T; segment i runs from X_i for
//! T/N. Conditions: continuity phi(X_i, T/N) = X_{i+1}, closure phi(X_{N-1}, T/N) = X_0, the
//! Poincare phase condition f(X_ref) . (X_0 - X_ref) = 0 (removes the shift along the orbit),
//! and either a target Jacobi constant C(X_0) = C* or a fixed period T = T* (selects the member
//! of the family). The system has 6N + 2 equations in 6N + 1 unknowns and is consistent (the
//! Jacobi constant is conserved, so one closure equation is redundant); Newton steps solve it
//! in the least-squares sense by SVD, with the project's dense Newton driver ([`crate::newton`]). Segments are propagated in parallel on rayon.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::cr3bp::{check_mu, jacobi, potential_gradient, Cr3bp};
use crate::error::{check_finite, check_positive, invalid, Error, Result};
use crate::newton::{self, Problem, Settings, StopReason};
use crate::integrate::{Options, Output, System};
use crate::propagation::propagate;

/// Which member of the family to converge to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MemberCondition {
    /// Jacobi constant equal to this value (the period is free).
    Jacobi(f64),
    /// Period fixed at this value (the Jacobi constant is free).
    Period(f64),
}

/// A periodic orbit corrected by multiple shooting.
#[derive(Debug, Clone, PartialEq)]
pub struct ShotOrbit {
    /// Patch states (N x 6); the first is the orbit's initial state.
    pub patches: Vec<[f64; 6]>,
    pub period: f64,
    pub jacobi: f64,
    pub iterations: usize,
    /// Max-norm of the continuity, closure and member conditions at the end.
    pub residual: f64,
}

/// Correct a periodic orbit from patch states (N >= 1) and a period guess.
pub fn correct_multiple_shooting(
    mu: f64,
    patches: &[[f64; 6]],
    period: f64,
    condition: MemberCondition,
    tol: f64,
    max_iter: usize,
    opts: &Options,
) -> Result<ShotOrbit> {
    check_mu(mu)?;
    opts.validate()?;
    check_positive("period", period)?;
    check_positive("tol", tol)?;
    if patches.is_empty() {
        return Err(invalid("states", "at least one patch state is needed"));
    }
    for p in patches {
        check_finite("states", p)?;
    }
    match condition {
        MemberCondition::Jacobi(c) => check_finite("jacobi", &[c])?,
        MemberCondition::Period(t) => check_positive("period", t)?,
    }
    let n = patches.len();
    let nu = 6 * n + 1;
    let x_ref: [f64; 6] = patches[0];
    let mut f_ref = [0.0; 6];
    Cr3bp { mu }.derivative(0.0, &x_ref, &mut f_ref);
    let x0 = DVector::from_fn(nu, |k, _| if k < 6 * n { patches[k / 6][k % 6] } else { period });
    let mut problem = Shooting { mu, n, x_ref, f_ref, condition, opts, jac: None };
    let settings = Settings { tol, max_iter, max_halvings: 7 };
    let out = newton::solve(&mut problem, x0, &settings)?;
    match out.reason {
        StopReason::Converged => {
            let x = out.x;
            let patches = (0..n).map(|i| std::array::from_fn(|j| x[6 * i + j])).collect::<Vec<[f64; 6]>>();
            let jc = jacobi(mu, &patches[0]);
            Ok(ShotOrbit { patches, period: x[6 * n], jacobi: jc, iterations: out.iterations, residual: out.norm })
        }
        StopReason::IntegrationFailed if out.last_error.is_some() => Err(out.last_error.expect("checked")),
        reason => Err(Error::Convergence { what: stop_what(reason), iterations: out.iterations, residual: out.norm, tolerance: tol }),
    }
}

fn stop_what(reason: StopReason) -> &'static str {
    match reason {
        StopReason::NoDescent => "multiple shooting (no step reduces the residual)",
        StopReason::SingularJacobian => "multiple shooting (least-squares Newton step failed)",
        _ => "multiple shooting",
    }
}

/// The multiple-shooting conditions as a problem of the Newton driver: the residual and its
/// Jacobian come from one propagation of the segments with their STMs.
struct Shooting<'a> {
    mu: f64,
    n: usize,
    x_ref: [f64; 6],
    f_ref: [f64; 6],
    condition: MemberCondition,
    opts: &'a Options,
    jac: Option<DMatrix<f64>>,
}

impl Problem for Shooting<'_> {
    fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
        let (r, j) = self.residual_and_jacobian(x)?;
        self.jac = Some(j);
        Ok(r)
    }
    fn jacobian(&mut self, _: &DVector<f64>) -> Result<DMatrix<f64>> {
        self.jac.clone().ok_or_else(|| invalid("x", "no residual evaluated"))
    }
}

impl Shooting<'_> {
    fn residual_and_jacobian(&self, x: &DVector<f64>) -> Result<(DVector<f64>, DMatrix<f64>)> {
        let (mu, n, opts, condition) = (self.mu, self.n, self.opts, self.condition);
        let (f_ref, x_ref) = (&self.f_ref, &self.x_ref);
        let (nu, ne) = (6 * n + 1, 6 * n + 2);
        if !(x[6 * n] > 0.0) {
            return Err(invalid("period", format!("must stay > 0, got {}", x[6 * n])));
        }
        let sys = Cr3bp { mu };
        let t_seg = x[6 * n] / n as f64;
        let segs: Vec<Result<([f64; 6], [[f64; 6]; 6])>> = (0..n)
            .into_par_iter()
            .map(|i| {
                let s: [f64; 6] = std::array::from_fn(|j| x[6 * i + j]);
                let tr = propagate(mu, &s, 0.0, t_seg, opts, true, Output::Final, &[])?;
                Ok((tr.state_final, tr.stm_final.expect("with STM")))
            })
            .collect();
        let mut r = DVector::zeros(ne);
        let mut jm = DMatrix::zeros(ne, nu);
        for (i, seg) in segs.into_iter().enumerate() {
            let (end, phi) = seg?;
            let next = (i + 1) % n;
            let mut fe = [0.0; 6];
            sys.derivative(0.0, &end, &mut fe);
            for a in 0..6 {
                r[6 * i + a] = end[a] - x[6 * next + a];
                for b in 0..6 {
                    jm[(6 * i + a, 6 * i + b)] += phi[a][b];
                }
                jm[(6 * i + a, 6 * next + a)] -= 1.0;
                jm[(6 * i + a, 6 * n)] = fe[a] / n as f64;
            }
        }
        // Phase condition.
        let row = 6 * n;
        r[row] = (0..6).map(|a| f_ref[a] * (x[a] - x_ref[a])).sum();
        for a in 0..6 {
            jm[(row, a)] = f_ref[a];
        }
        // Member condition.
        let row = 6 * n + 1;
        match condition {
            MemberCondition::Jacobi(c) => {
                let s0: [f64; 6] = std::array::from_fn(|a| x[a]);
                r[row] = jacobi(mu, &s0) - c;
                let g = potential_gradient(mu, &s0);
                for a in 0..3 {
                    jm[(row, a)] = 2.0 * g[a];
                    jm[(row, 3 + a)] = -2.0 * s0[3 + a];
                }
            }
            MemberCondition::Period(t) => {
                r[row] = x[6 * n] - t;
                jm[(row, 6 * n)] = 1.0;
            }
        }
        Ok((r, jm))
    }
}
