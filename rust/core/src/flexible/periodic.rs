//! Periodic motions of the flexible spacecraft (thesis ch. 5; docs/physics.md, flexible spacecraft): the coupled
//! state x = (phi0, wz0, q0, qdot0) that repeats after one orbit period T (phi advanced by
//! 2 pi turns), found by a globalised Newton method in Rust.
//!
//! Residual (scaled per component by `scale`, e.g. the quasi-static amplitudes of q and qdot):
//!   r(x) = (y(T; x) - x - (2 pi turns, 0, ...)) / scale.
//! Jacobian: central differences of the flow, one column per unknown, integrated in parallel
//! (rayon; each column independent, so the result does not depend on the thread count).
//! The project's dense Newton driver ([`crate::newton`]): Newton step by SVD, backtracking line
//! search on |r|_2 (Armijo). Stops with a reason ([`StopReason`]). The monodromy of the coupled
//! model, d y(T) / d x, is the unscaled Jacobian plus the identity at the last point.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::body::FlexibleBody;
use super::propagate::propagate_flexible;
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::integrate::{Options, Output};
use crate::newton::{self, Problem, Settings, StopReason};
use crate::propagation::with_threads_rounds;

/// The outcome of [`correct_flexible_periodic`].
#[derive(Debug, Clone, PartialEq)]
pub struct FlexiblePeriodic {
    /// (phi0, wz0, q0 (n), qdot0 (n)) at the last accepted point.
    pub x: Vec<f64>,
    /// Max-norm of the scaled residual there.
    pub residual: f64,
    pub iterations: usize,
    pub reason: StopReason,
    /// d y(T) / d x, row-major m x m (m = 2 + 2n), from the last Jacobian.
    pub monodromy: Vec<f64>,
}

/// Correct `x0` = (phi0, wz0, q0, qdot0) to a periodic motion of the coupled model along the
/// planar orbit `orbit0` of period `period` (see the module documentation).
pub fn correct_flexible_periodic(
    mu: f64,
    body: &FlexibleBody,
    primaries: [bool; 2],
    orbit0: &[f64; 6],
    period: f64,
    x0: &[f64],
    turns: f64,
    scale: &[f64],
    opts: &Options,
    tol: f64,
    max_iter: usize,
    threads: Option<usize>,
) -> Result<FlexiblePeriodic> {
    let m = 2 + 2 * body.n();
    if x0.len() != m || scale.len() != m {
        return Err(invalid("x0", format!("need (phi0, wz0, q0, qdot0) and scales of length 2 + 2n = {m}, got {} and {}", x0.len(), scale.len())));
    }
    check_finite("x0", x0)?;
    check_positive("period", period)?;
    check_positive("tol", tol)?;
    if !scale.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(invalid("scale", "every scale must be finite and > 0"));
    }
    if !turns.is_finite() {
        return Err(invalid("turns", format!("must be finite, got {turns}")));
    }
    if max_iter == 0 {
        return Err(invalid("max_iter", "must be >= 1"));
    }
    let n = body.n();
    let flow = |x: &[f64]| -> Result<Vec<f64>> {
        let tr = propagate_flexible(mu, body, primaries, false, orbit0, x[0], x[1], &x[2..2 + n], &x[2 + n..], 0.0, period, opts, Output::Final)?;
        let k = tr.phi.len() - 1;
        let mut y = vec![tr.phi[k], tr.wz[k]];
        y.extend_from_slice(&tr.q[k * n..(k + 1) * n]);
        y.extend_from_slice(&tr.qdot[k * n..(k + 1) * n]);
        match y.iter().all(|v| v.is_finite()) {
            true => Ok(y),
            false => Err(invalid("x0", "the flexible motion's final state is not finite")),
        }
    };
    // the driver's unknowns are the scaled ones, u = x / scale
    let residual = |u: &DVector<f64>| -> Result<DVector<f64>> {
        let x: Vec<f64> = (0..m).map(|i| u[i] * scale[i]).collect();
        let y = flow(&x)?;
        Ok(DVector::from_fn(m, |i, _| (y[i] - x[i] - if i == 0 { 2.0 * std::f64::consts::PI * turns } else { 0.0 }) / scale[i]))
    };
    with_threads_rounds(threads, || -> Result<FlexiblePeriodic> {
        let mut problem = Closure {
            residual: &residual,
            jacobian: &|u: &DVector<f64>| -> Result<DMatrix<f64>> {
                // central differences, one column per unknown, in parallel
                let cols: Vec<Result<DVector<f64>>> = (0..m)
                    .into_par_iter()
                    .map(|j| {
                        let (mut up, mut um) = (u.clone(), u.clone());
                        up[j] += 1e-6;
                        um[j] -= 1e-6;
                        Ok((residual(&up)? - residual(&um)?) / 2e-6)
                    })
                    .collect();
                let mut jac = DMatrix::<f64>::zeros(m, m);
                for (j, c) in cols.into_iter().enumerate() {
                    jac.set_column(j, &c?);
                }
                Ok(jac)
            },
        };
        let u0 = DVector::from_fn(m, |i, _| x0[i] / scale[i]);
        let settings = Settings { tol, max_iter, max_halvings: 9 };
        let out = match newton::solve(&mut problem, u0, &settings) {
            Ok(o) => o,
            Err(crate::Error::Integration(_)) | Err(crate::Error::InvalidArgument { name: "x0", .. }) => {
                return Ok(FlexiblePeriodic { x: x0.to_vec(), residual: f64::NAN, iterations: 0, reason: StopReason::IntegrationFailed, monodromy: vec![f64::NAN; m * m] });
            }
            Err(e) => return Err(e),
        };
        let x: Vec<f64> = (0..m).map(|i| out.x[i] * scale[i]).collect();
        // unscaled: d y / d x = (scale_i / scale_j) dr_i/du_j + I
        let mono = match &out.jac {
            Some(jac) => (0..m * m).map(|k| {
                let (i, j) = (k / m, k % m);
                jac[(i, j)] * scale[i] / scale[j] + if i == j { 1.0 } else { 0.0 }
            }).collect(),
            None => vec![f64::NAN; m * m],
        };
        Ok(FlexiblePeriodic { residual: out.norm, x, iterations: out.iterations, reason: out.reason, monodromy: mono })
    })?
}

/// A problem of the Newton driver given by two closures.
struct Closure<'a, R, J> {
    residual: &'a R,
    jacobian: &'a J,
}

impl<R, J> Problem for Closure<'_, R, J>
where
    R: Fn(&DVector<f64>) -> Result<DVector<f64>>,
    J: Fn(&DVector<f64>) -> Result<DMatrix<f64>>,
{
    fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
        (self.residual)(x)
    }
    fn jacobian(&mut self, x: &DVector<f64>) -> Result<DMatrix<f64>> {
        (self.jacobian)(x)
    }
}
