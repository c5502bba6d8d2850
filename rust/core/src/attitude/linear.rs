//! Linearised 3-D attitude: the exact Jacobian of the coupled model, its reduction to the six
//! attitude coordinates (a small body-axis rotation and the rate) and the equilibrium attitudes
//! of a body held at a collinear Lagrange point (Robinson 1974; docs/physics/attitude-equilibria.md).
//!
//! Attitude chart: about a unit quaternion q (scalar last), a small rotation theta in body axes
//! gives q (+) 1/2 Xi(q) theta, the first-order form of q (x) (theta / 2, 1) (Hamilton product;
//! the kinematics qdot = 1/2 Xi(q) w_rel of [`super::dynamics`] is the same map). Conversely a
//! quaternion perturbation dq has the rotation 2 Xi(q)' dq (Xi' Xi = I for |q| = 1; the
//! perturbation along q itself, a change of |q|, is dropped).

use super::body::RigidBody;
use super::dual::{Dual, Real};
use super::dynamics::{dcm, Coupled, OrbitMode, DIM};
use super::torque::{GravityGradient, Torque, D13};
use crate::cr3bp::{check_mu, collinear_point};
use crate::error::{check_finite, invalid, Result};

/// Xi(q) (4x3): qdot = 1/2 Xi(q) w for a rate w in body axes, scalar-last q.
pub fn xi(q: &[f64; 4]) -> [[f64; 3]; 4] {
    let [q1, q2, q3, q4] = *q;
    [[q4, -q3, q2], [q3, q4, -q1], [-q2, q1, q4], [-q1, -q2, -q3]]
}

/// The exact Jacobian d f / d y (13x13, row-major) of the coupled model at (t, y), by
/// forward-mode dual numbers (the same evaluation as the STM's variational equations).
pub fn jacobian(model: &Coupled<'_>, t: f64, y: &[f64; DIM]) -> [[f64; DIM]; DIM] {
    let yd: [D13; DIM] = std::array::from_fn(|k| Dual::var(y[k], k));
    let mut fd = [D13::cst(0.0); DIM];
    model.rhs(t, &yd, &mut fd, |m, x| m.torque_dual(x));
    std::array::from_fn(|i| fd[i].eps)
}

/// The 13x6 map from the attitude coordinates (theta, dw) at quaternion q to a state
/// perturbation (orbit rows zero).
pub fn chart_in(q: &[f64; 4]) -> [[f64; 6]; DIM] {
    let x = xi(q);
    let mut e = [[0.0; 6]; DIM];
    for i in 0..4 {
        for j in 0..3 {
            e[6 + i][j] = 0.5 * x[i][j];
        }
    }
    for k in 0..3 {
        e[10 + k][3 + k] = 1.0;
    }
    e
}

/// The 6x13 map from a state perturbation to the attitude coordinates (theta, dw) at q.
pub fn chart_out(q: &[f64; 4]) -> [[f64; DIM]; 6] {
    let x = xi(q);
    let n2: f64 = q.iter().map(|v| v * v).sum();
    let mut p = [[0.0; DIM]; 6];
    for j in 0..3 {
        for i in 0..4 {
            p[j][6 + i] = 2.0 * x[i][j] / n2;
        }
    }
    for k in 0..3 {
        p[3 + k][10 + k] = 1.0;
    }
    p
}

/// P M E: a 13x13 matrix (a Jacobian or an STM from quaternion `q_from` to `q_to`) in the
/// attitude coordinates (6x6), the orbit block dropped.
pub fn reduce(m: &[[f64; DIM]; DIM], q_from: &[f64; 4], q_to: &[f64; 4]) -> [[f64; 6]; 6] {
    let e = chart_in(q_from);
    let p = chart_out(q_to);
    let mut me = [[0.0; 6]; DIM];
    for i in 0..DIM {
        for j in 0..6 {
            me[i][j] = (0..DIM).map(|k| m[i][k] * e[k][j]).sum();
        }
    }
    std::array::from_fn(|i| std::array::from_fn(|j| (0..DIM).map(|k| p[i][k] * me[k][j]).sum()))
}

/// A body held at a collinear Lagrange point with its principal axes on the synodic axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// The 13 coupled states: the point, at rest; q0; w0 = A(q0) e_Z (the body turns with the
    /// synodic frame).
    pub state: [f64; DIM],
    /// The linearised attitude equations d(theta, dw)/dt = M (theta, dw), body axes.
    pub matrix: [[f64; 6]; 6],
    /// sigma = (1 - mu) / r1^3 + mu / r2^3 at the point (the thesis's h is 3 sigma).
    pub sigma: f64,
    /// Largest |derivative| of the attitude states at the equilibrium (zero up to rounding).
    pub residual: f64,
}

/// The linearised attitude of `body` held at the collinear point `point` (1, 2, 3) of the
/// Earth-Moon-like system `mu`, gravity gradient of both primaries, attitude `q0` (scalar last,
/// body relative to synodic), which must put every principal axis on a synodic axis (a signed
/// permutation to 1e-12, e.g. the identity).
pub fn collinear_equilibrium(mu: f64, body: RigidBody, point: u8, q0: &[f64; 4]) -> Result<Equilibrium> {
    check_mu(mu)?;
    RigidBody::new(body.ix, body.iy, body.iz)?;
    check_finite("q0", q0)?;
    if !(1..=3).contains(&point) {
        return Err(invalid("point", format!("the equilibrium attitudes are computed at the collinear points 1, 2, 3; got {point}")));
    }
    let n = q0.iter().map(|v| v * v).sum::<f64>().sqrt();
    if (n - 1.0).abs() > 1e-9 {
        return Err(invalid("q0", format!("must be a unit quaternion (scalar last), |q0| = {n}")));
    }
    let q = q0.map(|v| v / n);
    let a = dcm(&q);
    let off = a.iter().map(|row| {
        let big = row.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        (1.0 - big).abs().max(row.iter().map(|v| v.abs()).sum::<f64>() - big)
    });
    let dev = off.fold(0.0f64, f64::max);
    if !(dev <= 1e-12) {
        return Err(invalid("q0", format!("must put the principal axes on the synodic axes (a signed permutation of the axes); off by {dev:.2e}")));
    }
    let x = collinear_point(mu, point)?;
    let sigma = (1.0 - mu) / (x + mu).abs().powi(3) + mu / (x - 1.0 + mu).abs().powi(3);
    let mut state = [0.0; DIM];
    state[0] = x;
    state[6..10].copy_from_slice(&q);
    for i in 0..3 {
        state[10 + i] = a[i][2];
    }
    let gg = GravityGradient::BOTH;
    let model = Coupled { mu, body, torques: vec![&gg as &dyn Torque], orbit: OrbitMode::Held, orbit_srp: None };
    let mut f = [0.0; DIM];
    crate::integrate::System::derivative(&model, 0.0, &state, &mut f);
    let residual = f[6..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let j = jacobian(&model, 0.0, &state);
    Ok(Equilibrium { state, matrix: reduce(&j, &q, &q), sigma, residual })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At the identity the reduced matrix is Robinson's (docs/physics/attitude-equilibria.md):
    /// theta1'' = -K1 theta1 - (K1 - 1) theta2', theta2'' = -(1 - K2) theta1' - (1 + 3 sigma) K2
    /// theta2, theta3'' = -3 sigma K3 theta3, in first-order form with w = (theta1' - theta2,
    /// theta2' + theta1, 1 + theta3').
    #[test]
    fn identity_matches_the_closed_form_matrix() {
        let mu = 0.012150585609624;
        let body = RigidBody::new(12.12, 89.68, 96.95).unwrap();
        let e = collinear_equilibrium(mu, body, 1, &[0.0, 0.0, 0.0, 1.0]).unwrap();
        assert!(e.residual < 1e-14);
        let (a, b, c) = (body.ix, body.iy, body.iz);
        let s = e.sigma;
        // theta' = w_rel: theta1' = dw1 + theta2, theta2' = dw2 - theta1, theta3' = dw3
        let m = e.matrix;
        let expect_theta = [[0.0, 1.0, 0.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]];
        // Euler: A dw1' = -(C - B)(w2 w3)_lin = -(C - B) dw2,
        //        B dw2' = 3 sigma (A - C) theta2 - (A - C) dw1,
        //        C dw3' = 3 sigma (A - B) theta3.
        let expect_w = [
            [0.0, 0.0, 0.0, 0.0, -(c - b) / a, 0.0],
            [0.0, 3.0 * s * (a - c) / b, 0.0, -(a - c) / b, 0.0, 0.0],
            [0.0, 0.0, 3.0 * s * (a - b) / c, 0.0, 0.0, 0.0],
        ];
        for i in 0..3 {
            for j in 0..6 {
                assert!((m[i][j] - expect_theta[i][j]).abs() < 1e-13, "row {i} col {j}: {}", m[i][j]);
                assert!((m[3 + i][j] - expect_w[i][j]).abs() < 1e-12, "row {} col {j}: {}", 3 + i, m[3 + i][j]);
            }
        }
    }

    #[test]
    fn refuses_tilted_attitudes_and_bad_points() {
        let mu = 0.0121505856;
        let body = RigidBody::new(1.0, 2.0, 2.5).unwrap();
        let s = (0.1f64).sin();
        assert!(collinear_equilibrium(mu, body, 1, &[s, 0.0, 0.0, (0.1f64).cos()]).is_err());
        assert!(collinear_equilibrium(mu, body, 4, &[0.0, 0.0, 0.0, 1.0]).is_err());
        let h = 0.5f64.sqrt();
        assert!(collinear_equilibrium(mu, body, 2, &[0.0, 0.0, h, h]).is_ok());
    }
}
