//! Equilibrium points L1..L5.

use super::system::check_mu;
use crate::error::{Error, Result};

/// dU/dx on the x axis (y = z = 0).
fn ux_axis(mu: f64, x: f64) -> f64 {
    let d1 = x + mu;
    let d2 = x - 1.0 + mu;
    x - (1.0 - mu) * d1 / d1.abs().powi(3) - mu * d2 / d2.abs().powi(3)
}

fn ux_axis_derivative(mu: f64, x: f64) -> f64 {
    1.0 + 2.0 * (1.0 - mu) / (x + mu).abs().powi(3) + 2.0 * mu / (x - 1.0 + mu).abs().powi(3)
}

/// Collinear point `k` (1, 2 or 3): the zero of dU/dx on the x axis in its interval, by Newton's
/// method safeguarded with bisection (dU/dx is strictly increasing between the singularities).
pub fn collinear_point(mu: f64, k: u8) -> Result<f64> {
    check_mu(mu)?;
    let (mut lo, mut hi) = match k {
        1 => (-mu + 1e-9, 1.0 - mu - 1e-9),
        2 => (1.0 - mu + 1e-9, 2.0),
        3 => (-2.0, -mu - 1e-9),
        _ => return Err(crate::error::invalid("k", format!("collinear points are 1, 2, 3; got {k}"))),
    };
    // Hill-sphere guesses for L1/L2, a first-order expansion for L3.
    let rh = (mu / 3.0).cbrt();
    let mut x = match k {
        1 => 1.0 - mu - rh,
        2 => 1.0 - mu + rh,
        _ => -1.0 - 5.0 * mu / 12.0,
    };
    for it in 0..100 {
        let f = ux_axis(mu, x);
        if f == 0.0 {
            return Ok(x);
        }
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let mut next = x - f / ux_axis_derivative(mu, x);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 2.0 * f64::EPSILON * x.abs().max(1.0) && it > 0 {
            return Ok(next);
        }
        x = next;
    }
    Err(Error::Convergence { what: "collinear Lagrange point", iterations: 100, residual: ux_axis(mu, x).abs(), tolerance: 0.0 })
}

/// L1..L5 as rows (x, y, z).
pub fn lagrange_points(mu: f64) -> Result<[[f64; 3]; 5]> {
    let h = 3f64.sqrt() / 2.0;
    Ok([
        [collinear_point(mu, 1)?, 0.0, 0.0],
        [collinear_point(mu, 2)?, 0.0, 0.0],
        [collinear_point(mu, 3)?, 0.0, 0.0],
        [0.5 - mu, h, 0.0],
        [0.5 - mu, -h, 0.0],
    ])
}
