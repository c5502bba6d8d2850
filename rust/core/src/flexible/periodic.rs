//! Periodic motions of the flexible spacecraft (thesis ch. 5; docs/physics.md, flexible spacecraft): the coupled
//! state x = (phi0, wz0, q0, qdot0) that repeats after one orbit period T (phi advanced by
//! 2 pi turns), found by a globalised Newton method in Rust.
//!
//! Residual (scaled per component by `scale`, e.g. the quasi-static amplitudes of q and qdot):
//!   r(x) = (y(T; x) - x - (2 pi turns, 0, ...)) / scale.
//! Jacobian: central differences of the flow, one column per unknown, integrated in parallel
//! (rayon; each column independent, so the result does not depend on the thread count).
//! Newton step by SVD (minimum-norm where the Jacobian is rank-deficient), backtracking line
//! search on |r|_2 (Armijo). Stops with a reason ([`StopReason`]). The monodromy of the coupled
//! model, d y(T) / d x, is the unscaled Jacobian plus the identity at the last point.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::body::FlexibleBody;
use super::propagate::propagate_flexible;
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::integrate::{Options, Output};
use crate::attitude::StopReason;
use crate::propagation::with_threads;

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
    let flow = |x: &[f64]| -> Option<Vec<f64>> {
        let tr = propagate_flexible(mu, body, primaries, false, orbit0, x[0], x[1], &x[2..2 + n], &x[2 + n..], 0.0, period, opts, Output::Final).ok()?;
        let k = tr.phi.len() - 1;
        let mut y = vec![tr.phi[k], tr.wz[k]];
        y.extend_from_slice(&tr.q[k * n..(k + 1) * n]);
        y.extend_from_slice(&tr.qdot[k * n..(k + 1) * n]);
        y.iter().all(|v| v.is_finite()).then_some(y)
    };
    let residual = |x: &[f64], y: &[f64]| -> Vec<f64> {
        (0..m).map(|i| (y[i] - x[i] - if i == 0 { 2.0 * std::f64::consts::PI * turns } else { 0.0 }) / scale[i]).collect()
    };
    let norm2 = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let max_norm = |r: &[f64]| r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    with_threads(threads, || -> Result<FlexiblePeriodic> {
        let mut x = x0.to_vec();
        let Some(y) = flow(&x) else {
            return Ok(FlexiblePeriodic { x, residual: f64::NAN, iterations: 0, reason: StopReason::IntegrationFailed, monodromy: vec![f64::NAN; m * m] });
        };
        let mut r = residual(&x, &y);
        let mut jac = DMatrix::<f64>::from_element(m, m, f64::NAN);
        let mut iterations = 0;
        let reason = loop {
            crate::interrupt::check()?;
            // the Jacobian of the scaled residual w.r.t. the scaled unknowns, column by column
            let cols: Vec<Option<Vec<f64>>> = (0..m)
                .into_par_iter()
                .map(|j| {
                    let h = 1e-6 * scale[j];
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[j] += h;
                    xm[j] -= h;
                    let (yp, ym) = (flow(&xp)?, flow(&xm)?);
                    let (rp, rm) = (residual(&xp, &yp), residual(&xm, &ym));
                    Some((0..m).map(|i| (rp[i] - rm[i]) / 2e-6).collect())
                })
                .collect();
            if cols.iter().any(|c| c.is_none()) {
                break StopReason::IntegrationFailed;
            }
            for (j, c) in cols.into_iter().enumerate() {
                jac.set_column(j, &DVector::from_vec(c.expect("checked")));
            }
            if max_norm(&r) <= tol {
                break StopReason::Converged;
            }
            if iterations >= max_iter {
                break StopReason::MaxIterations;
            }
            let Some(svd) = jac.clone().try_svd(true, true, f64::EPSILON, 500) else { break StopReason::SingularJacobian };
            let smax = svd.singular_values.max();
            if !(smax > 0.0 && smax.is_finite()) {
                break StopReason::SingularJacobian;
            }
            let Ok(d) = svd.solve(&DVector::from_iterator(m, r.iter().map(|v| -v)), 1e-12 * smax) else { break StopReason::SingularJacobian };
            let mut lambda = 1.0;
            let mut accepted = None;
            for _ in 0..10 {
                let xt: Vec<f64> = (0..m).map(|i| x[i] + lambda * d[i] * scale[i]).collect();
                if let Some(yt) = flow(&xt) {
                    let rt = residual(&xt, &yt);
                    if norm2(&rt) <= (1.0 - 1e-4 * lambda) * norm2(&r) {
                        accepted = Some((xt, rt));
                        break;
                    }
                }
                lambda *= 0.5;
            }
            match accepted {
                Some((xt, rt)) => {
                    x = xt;
                    r = rt;
                    iterations += 1;
                }
                None => break StopReason::NoDescent,
            }
        };
        // unscaled: d y / d x = (scale_i / scale_j) dr_i/dx~_j + I
        let mut mono = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                mono[i * m + j] = jac[(i, j)] * scale[i] / scale[j] + if i == j { 1.0 } else { 0.0 };
            }
        }
        Ok(FlexiblePeriodic { residual: max_norm(&r), x, iterations, reason, monodromy: mono })
    })?
}
