//! Coupled orbit-attitude equations of motion (docs/physics.md, attitude).
//!
//! State (13): synodic position and velocity (6), the quaternion q = (q1, q2, q3, q4) of the
//! body relative to the synodic frame, scalar last (4), and the inertial angular velocity w in
//! body axes (3). A(q) maps synodic components to body components. Equations:
//!   orbit: the CR3BP, plus (optionally) the second-order extended-body acceleration (thesis
//!          eq. 37), or held fixed (a body artificially kept at a point, as at the L-points);
//!   qdot = 1/2 Xi(q) (w - A e_Z)   (the synodic frame turns at rate 1 about Z);
//!   I wdot = T - w x I w.
//! The quaternion is not renormalised inside the dynamics (the exact flow preserves |q|); A(q)
//! is evaluated as A(q)/|q|^2 so that a small drift of |q| does not distort the rotation.

use super::body::RigidBody;
use super::dual::{Dual, Real};
use super::torque::{euler_rate, mat_vec, Torque, TorqueInput, D13};
use crate::scalar::Arith;
use crate::integrate::System;

/// Dimension of the coupled state and of the state with its 13x13 STM.
pub const DIM: usize = 13;
pub const STM_DIM: usize = DIM + DIM * DIM;

/// How the orbit is treated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrbitMode {
    /// Integrated with the attitude (point-mass CR3BP).
    Integrate,
    /// Integrated, with the second-order extended-body acceleration of both primaries
    /// (thesis eq. 37; MacCullagh). `inertia_nd` = principal moments / (m LU^2).
    Coupled { inertia_nd: [f64; 3] },
    /// Held at its initial state (zero derivative).
    Held,
}

/// The coupled 3-D model.
pub struct Coupled<'a> {
    pub mu: f64,
    pub body: RigidBody,
    pub torques: Vec<&'a dyn Torque>,
    pub orbit: OrbitMode,
    /// Solar radiation pressure force on the orbit (facets, spacecraft mass in kg, LU in m);
    /// off (None) by default, as for the maps.
    pub orbit_srp: Option<(&'a super::srp::FacetBody, f64, f64)>,
}

/// Attitude matrix A(q)/|q|^2 (synodic -> body), scalar-last quaternion.
#[inline(always)]
pub fn dcm<R: Real>(q: &[R; 4]) -> [[R; 3]; 3] {
    dcm_with(q, R::cst(1.0))
}

/// [`dcm`] over any [`Arith`] type, given its `one` (the SIMD lanes: a splat of 1).
#[inline(always)]
pub fn dcm_with<R: Arith>(q: &[R; 4], one: R) -> [[R; 3]; 3] {
    let [q1, q2, q3, q4] = *q;
    let n = one / (q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4);
    let (a, b, c, d) = (q1 * q1, q2 * q2, q3 * q3, q4 * q4);
    // the off-diagonal terms 2 (qi qj +- qk ql) n as (qi qj +- qk ql) (2 n): the same bits
    // (doubling is exact); the sums fused on the lanes of FMA levels ([`Arith::madd`])
    let n2 = n.scale(2.0);
    let (p12, p13, p23) = (q1 * q2, q1 * q3, q2 * q3);
    [
        [(a - b - c + d) * n, q3.madd(q4, p12) * n2, (-q2).madd(q4, p13) * n2],
        [(-q3).madd(q4, p12) * n2, (-a + b - c + d) * n, q1.madd(q4, p23) * n2],
        [q2.madd(q4, p13) * n2, (-q1).madd(q4, p23) * n2, (-a - b + c + d) * n],
    ]
}

/// The attitude kinematics relative to the synodic frame (turning at rate 1 about Z):
/// qdot = 1/2 Xi(q) (w - A e_Z), with A = A(q) (its third column is A e_Z).
#[inline(always)]
pub fn quat_rate<R: Arith>(q: &[R; 4], a: &[[R; 3]; 3], w: &[R; 3]) -> [R; 4] {
    quat_kinematics(q, &[w[0] - a[0][2], w[1] - a[1][2], w[2] - a[2][2]])
}

/// qdot = 1/2 Xi(q) wr = 1/2 q (x) (wr, 0): the kinematics for the rate `wr` of the body relative
/// to q's reference frame, in body axes (the synodic frame: [`quat_rate`]; an inertial frame, as
/// ICRF in [`crate::ephemeris::attitude`]: wr = w).
#[inline(always)]
pub fn quat_kinematics<R: Arith>(q: &[R; 4], wr: &[R; 3]) -> [R; 4] {
    let [q1, q2, q3, q4] = *q;
    // 1/2 (q4 w1 - q3 w2 + q2 w3, ...) as (q4 (w1/2) - ...): the same bits (halving is exact);
    // the sums fused on the lanes of FMA levels ([`Arith::madd`])
    let h = [wr[0].scale(0.5), wr[1].scale(0.5), wr[2].scale(0.5)];
    [
        q2.madd(h[2], (-q3).madd(h[1], q4 * h[0])),
        (-q1).madd(h[2], q4.madd(h[1], q3 * h[0])),
        q4.madd(h[2], q1.madd(h[1], -q2 * h[0])),
        (-q3).madd(h[2], (-q2).madd(h[1], -q1 * h[0])),
    ]
}

impl Coupled<'_> {
    /// The right-hand side over any [`Real`] scalar.
    #[inline(always)]
    pub(crate) fn rhs<R: Real>(&self, t: f64, y: &[R; DIM], dy: &mut [R; DIM], torque: impl Fn(&dyn Torque, &TorqueInput<R>) -> [R; 3]) {
        let mu = self.mu;
        let pos = [y[0], y[1], y[2]];
        let vel = [y[3], y[4], y[5]];
        let q = [y[6], y[7], y[8], y[9]];
        let w = [y[10], y[11], y[12]];
        let a = dcm(&q);
        let inertia = self.body.moments();

        // Orbit.
        match self.orbit {
            OrbitMode::Held => {
                for d in dy.iter_mut().take(6) {
                    *d = R::cst(0.0);
                }
            }
            OrbitMode::Integrate | OrbitMode::Coupled { .. } => {
                let mut acc = crate::cr3bp::acceleration(mu, &pos, &vel);
                if let OrbitMode::Coupled { inertia_nd } = self.orbit {
                    let extra = extended_body_acc(mu, &pos, &a, inertia_nd);
                    for i in 0..3 {
                        acc[i] = acc[i] + extra[i];
                    }
                }
                if let Some((srp, mass, lu_m)) = self.orbit_srp {
                    let extra = srp.acceleration(t, &a, mass, lu_m);
                    for i in 0..3 {
                        acc[i] = acc[i] + extra[i];
                    }
                }
                dy[0] = vel[0];
                dy[1] = vel[1];
                dy[2] = vel[2];
                dy[3] = acc[0];
                dy[4] = acc[1];
                dy[5] = acc[2];
            }
        }

        // Kinematics: w_rel = w - A e_Z.
        let qd = quat_rate(&q, &a, &w);
        dy[6..10].copy_from_slice(&qd);

        // Euler's equations.
        let input = TorqueInput { t, mu, pos, vel, a, w, inertia };
        let mut tq = [R::cst(0.0); 3];
        for m in &self.torques {
            let ti = torque(*m, &input);
            for i in 0..3 {
                tq[i] = tq[i] + ti[i];
            }
        }
        let inv = inertia.map(|v| 1.0 / v);
        let wd = euler_rate(&tq, &w, &inertia, &inv);
        dy[10..13].copy_from_slice(&wd);
    }
}

/// Second-order extended-body acceleration of both primaries (thesis eq. 37):
/// a2 = -sum_i mu_i / r^4 [ (3/2)(tr I - 5 rhat' I_S rhat) rhat + 3 I_S rhat ], I_S = A' I A,
/// with I the principal moments / (m LU^2) and rhat the unit vector from primary i.
fn extended_body_acc<R: Real>(mu: f64, p: &[R; 3], a: &[[R; 3]; 3], inertia_nd: [f64; 3]) -> [R; 3] {
    let tr = inertia_nd[0] + inertia_nd[1] + inertia_nd[2];
    let mut out = [R::cst(0.0); 3];
    for (cx, gm) in [(-mu, 1.0 - mu), (1.0 - mu, mu)] {
        let rs = [p[0] - R::cst(cx), p[1], p[2]];
        let r2 = rs[0] * rs[0] + rs[1] * rs[1] + rs[2] * rs[2];
        let r = r2.sqrt();
        let u = [rs[0] / r, rs[1] / r, rs[2] / r];
        let ub = mat_vec(a, &u);
        let iub = [ub[0].scale(inertia_nd[0]), ub[1].scale(inertia_nd[1]), ub[2].scale(inertia_nd[2])];
        let quad = ub[0] * iub[0] + ub[1] * iub[1] + ub[2] * iub[2];
        let coef = (R::cst(tr) - quad.scale(5.0)).scale(1.5);
        // I_S rhat = A' (I (A rhat)).
        let is_u: [R; 3] = std::array::from_fn(|j| a[0][j] * iub[0] + a[1][j] * iub[1] + a[2][j] * iub[2]);
        let k = R::cst(-gm) / (r2 * r2);
        for j in 0..3 {
            out[j] = out[j] + k * (coef * u[j] + is_u[j].scale(3.0));
        }
    }
    out
}

impl System<[f64; DIM]> for Coupled<'_> {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; DIM], dy: &mut [f64; DIM]) {
        self.rhs(t, y, dy, |m, x| m.torque(x));
    }
}

/// The coupled model with its 13x13 state transition matrix (row-major after the state); the
/// Jacobian of the right-hand side is exact, by forward-mode dual numbers.
pub struct CoupledStm<'a>(pub Coupled<'a>);

impl CoupledStm<'_> {
    pub fn initial(state: &[f64; DIM]) -> [f64; STM_DIM] {
        let mut y = [0.0; STM_DIM];
        y[..DIM].copy_from_slice(state);
        for i in 0..DIM {
            y[DIM + i * DIM + i] = 1.0;
        }
        y
    }
}

impl System<[f64; STM_DIM]> for CoupledStm<'_> {
    fn derivative(&self, t: f64, y: &[f64; STM_DIM], dy: &mut [f64; STM_DIM]) {
        let yd: [D13; DIM] = std::array::from_fn(|k| Dual::var(y[k], k));
        let mut fd = [D13::cst(0.0); DIM];
        self.0.rhs(t, &yd, &mut fd, |m, x| m.torque_dual(x));
        for i in 0..DIM {
            dy[i] = fd[i].re;
        }
        let phi = &y[DIM..];
        for i in 0..DIM {
            let ji = &fd[i].eps;
            for j in 0..DIM {
                let mut s = 0.0;
                for k in 0..DIM {
                    s += ji[k] * phi[k * DIM + j];
                }
                dy[DIM + i * DIM + j] = s;
            }
        }
    }
}
