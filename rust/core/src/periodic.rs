//! Symmetric periodic orbits by single shooting on the half period (PHYSICS.md section 3).

use crate::cr3bp::{check_mu, jacobi};
use crate::error::{check_positive, invalid, Error, Result};
use crate::integrate::Options;
use crate::propagation::{propagate, EventKind, EventSpec};
use crate::integrate::Output;

/// A corrected planar orbit symmetric about the x axis: (x0, 0, 0, 0, ydot0, 0).
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetricOrbit {
    pub state0: [f64; 6],
    pub period: f64,
    pub jacobi: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// |xdot| at the half-period crossing after the last correction.
    pub residual: f64,
}

/// Correct ydot0 of a planar x-symmetric orbit started at (x0, 0) so that it crosses y = 0 again
/// perpendicularly (thesis eq. 19, with the event located in time, not at a fixed time):
/// delta ydot0 = -xdot_c / (Phi[xdot][ydot0] - (xddot_c / ydot_c) Phi[y][ydot0]).
/// `crossing_direction` is the sign of ydot at the half-period crossing (-1 for a DRO started
/// on the Earth side of the Moon with ydot0 > 0).
pub fn correct_planar_symmetric(
    mu: f64,
    x0: f64,
    ydot0_guess: f64,
    crossing_direction: i8,
    tol: f64,
    max_iter: usize,
    opts: &Options,
) -> Result<SymmetricOrbit> {
    check_mu(mu)?;
    check_positive("tol", tol)?;
    if !x0.is_finite() || !ydot0_guess.is_finite() {
        return Err(invalid("x0", format!("x0 and ydot0 must be finite, got ({x0}, {ydot0_guess})")));
    }
    if crossing_direction != 1 && crossing_direction != -1 {
        return Err(invalid("crossing_direction", "must be +1 or -1"));
    }
    let event = EventSpec { kind: EventKind::Crossing { index: 1, value: 0.0 }, direction: crossing_direction, terminal: true };
    let mut vy = ydot0_guess;
    let mut residual = f64::INFINITY;
    // Generous final time: the half period of any bounded orbit is far below 100 TU.
    let t_max = 100.0;
    for it in 0..=max_iter {
        let s0 = [x0, 0.0, 0.0, 0.0, vy, 0.0];
        let tr = propagate(mu, &s0, 0.0, t_max, opts, true, Output::Final, &[event])?;
        let hit = tr.events.first().ok_or_else(|| Error::Convergence {
            what: "symmetric orbit correction (no half-period crossing of y = 0 within 100 TU)",
            iterations: it,
            residual,
            tolerance: tol,
        })?;
        let s = hit.state;
        let phi = hit.stm.expect("propagated with the STM");
        residual = s[3].abs();
        if residual <= tol {
            return Ok(SymmetricOrbit { state0: s0, period: 2.0 * hit.t, jacobi: jacobi(mu, &s0), iterations: it, residual });
        }
        let mut acc = [0.0; 6];
        crate::integrate::System::derivative(&crate::cr3bp::Cr3bp { mu }, hit.t, &s, &mut acc);
        let denom = phi[3][4] - acc[3] / s[4] * phi[1][4];
        vy -= s[3] / denom;
    }
    Err(Error::Convergence { what: "symmetric orbit correction", iterations: max_iter, residual, tolerance: tol })
}
