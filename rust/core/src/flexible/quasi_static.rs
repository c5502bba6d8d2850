//! High structural frequencies: the quasi-static deflection in closed form along a rigid
//! solution and the attitude perturbation it causes (first order in 1/k).
//!
//! Along the rigid composite solution (phi_r, wz_r) the transverse load on m_j is
//!   L_j = m_j [ t_j . T_B b_j - wzdot_r (b_j x t_j) ]   (tidal + Euler; the centrifugal
//!         load m_j wz^2 t_j . b_j vanishes because t_j is normal to b_j)
//!       = m_j [ (3/2) Re(conj(w) t_j b_j) - wzdot_r a_j ]   (complex products, w = Cb + i Sb),
//! and the closed form is q_j = L_j / k_j = L_j / (m_j Omega_j^2), corrected for the viscous lag
//! of a damped appendage: q_j = (L_j - (c_j / k_j) L_j') / k_j (the damper's c_j q_j' is a
//! relative 2 zeta_j rate / Omega_j of the spring force, first order in 1/Omega unlike the
//! inertial terms; with it the closed form is exact to O((rate / Omega)^2) for any damping
//! ratio; q_j' carries the lag with L_j'', q_j'' = L_j'' / k_j without it). Its derivatives follow from
//! those of w = W e^{-2 i phi} (W', W'' from the orbit's velocity and acceleration):
//!   w'  = (W' - 2i phi' W) e^{-2i phi},
//!   w'' = (W'' - 4i phi' W' - 2i phi'' W - 4 phi'^2 W) e^{-2i phi},
//!   wz^(k+1) = (3 / (2 I0)) Im(conj(Z0) w^(k)),
//! so q', q'' are closed-form too. Feeding q back into the attitude equation and keeping the
//! first order in 1/k (I(q) = I0 + O(q^2), gamma = gamma0 + O(q)):
//!   I0 wzdot = tau_r(phi, t) + dtau(t),
//!   dtau = sum_j [ 3 m_j Im(conj(b_j t_j) w) q_j - m_j a_j q_j'' ]
//! (the change of the tidal torque with the deflection, and the reaction of the appendages'
//! accelerations on the hub). The attitude perturbation (dphi, dwz) obeys the rigid model's
//! variational equation forced by dtau:
//!   dphi' = dwz,   dwz' = -(3 / I0) Re(conj(Z0) w) dphi + dtau / I0,
//! i.e. d(t) = int_0^t Phi(t, s) [0, dtau(s) / I0] ds with the rigid 2x2 STM (Duhamel); it is
//! integrated alongside the rigid solution. Both q and (dphi, dwz) are O((rate / Omega)^2)
//! relative to the loads and the rigid motion; the full model differs from them by
//! O((rate / Omega)^4) (tested).

use nalgebra::Complex;

use super::body::FlexibleBody;
use super::dynamics::{tidal_field, tidal_field_derivatives, to_body_axes, BodyField};
use crate::attitude::planar::orbit_derivative;
use crate::integrate::System;

/// The closed-form deflections and their derivatives at one point of a rigid solution.
#[derive(Debug, Clone, PartialEq)]
pub struct QuasiStaticPoint {
    pub q: Vec<f64>,
    pub qdot: Vec<f64>,
    pub qddot: Vec<f64>,
    /// wzdot of the rigid composite model.
    pub wzdot: f64,
    /// The first-order torque perturbation dtau.
    pub dtau: f64,
}

/// The rigid composite model's attitude derivatives and the tidal-field derivatives in body
/// axes: (w, w', w'', wz', wz'', wz''').
#[inline]
fn chain(body: &FlexibleBody, wsyn: [Complex<f64>; 3], phi: f64, wz: f64) -> ([Complex<f64>; 3], [f64; 3]) {
    let e = to_body_axes(phi);
    let i = Complex::new(0.0, 1.0);
    let p1 = wz - 1.0;
    let w0 = wsyn[0] * e;
    let wz1 = body.rigid_response(w0);
    let w1 = (wsyn[1] - i * 2.0 * p1 * wsyn[0]) * e;
    let wz2 = body.rigid_response(w1);
    let w2 = (wsyn[2] - i * 4.0 * p1 * wsyn[1] - i * 2.0 * wz1 * wsyn[0] - wsyn[0] * 4.0 * p1 * p1) * e;
    let wz3 = body.rigid_response(w2);
    ([w0, w1, w2], [wz1, wz2, wz3])
}

/// The torque perturbation dtau from the closed form (allocation-free).
#[inline]
fn dtau(body: &FlexibleBody, w: &[Complex<f64>; 3], wzk: &[f64; 3]) -> f64 {
    let mut d = 0.0;
    for a in body.appendages() {
        let bt = Complex::new(a.position[0], a.position[1]) * Complex::new(a.direction[0], a.direction[1]);
        let lever = a.lever();
        let l1 = a.mass * (1.5 * (w[1].conj() * bt).re - wzk[1] * lever);
        let q = (a.mass * (1.5 * (w[0].conj() * bt).re - wzk[0] * lever) - a.damping / a.stiffness * l1) / a.stiffness;
        let qdd = a.mass * (1.5 * (w[2].conj() * bt).re - wzk[2] * lever) / a.stiffness;
        d += 3.0 * a.mass * (bt.conj() * w[0]).im * q - a.mass * lever * qdd;
    }
    d
}

impl FlexibleBody {
    /// The closed form at a point of a rigid solution: orbit position, velocity and
    /// acceleration (synodic; zero velocity and acceleration for a held orbit), phi, wz.
    pub fn quasi_static(&self, mu: f64, primaries: [bool; 2], pos: &[f64], vel: &[f64], acc: &[f64], phi: f64, wz: f64) -> QuasiStaticPoint {
        let wsyn = tidal_field_derivatives(mu, pos, vel, acc, primaries);
        let (w, wzk) = chain(self, wsyn, phi, wz);
        let n = self.n();
        let (mut q, mut qdot, mut qddot) = (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
        for a in self.appendages() {
            let bt = Complex::new(a.position[0], a.position[1]) * Complex::new(a.direction[0], a.direction[1]);
            let lever = a.lever();
            let l: [f64; 3] = std::array::from_fn(|k| a.mass * (1.5 * (w[k].conj() * bt).re - wzk[k] * lever));
            let lag = a.damping / a.stiffness;
            q.push((l[0] - lag * l[1]) / a.stiffness);
            qdot.push((l[1] - lag * l[2]) / a.stiffness);
            qddot.push(l[2] / a.stiffness);
        }
        QuasiStaticPoint { q, qdot, qddot, wzdot: wzk[0], dtau: dtau(self, &w, &wzk) }
    }

    /// wzdot of the rigid composite model (the flexible body frozen undeformed).
    #[inline]
    pub fn rigid_wzdot(&self, field: &BodyField) -> f64 {
        self.rigid_response(field.w)
    }

    /// (3/2) Im(conj(Z0) w) / I0: the rigid composite body's gravity-gradient angular
    /// acceleration for the body-axes field w, i.e. the planar law
    /// [`crate::attitude::gravity_gradient_wzdot`] for a body turned by its principal angle
    /// (tests/flexible.rs checks the two agree); linear in w, so applied to w', w'' it gives
    /// the rate's higher derivatives.
    #[inline(always)]
    fn rigid_response(&self, w: Complex<f64>) -> f64 {
        1.5 * (self.asymmetry().conj() * w).im / self.inertia()
    }
}

/// The rigid composite model with the first-order flexible perturbation: state
/// (x, y, z, xd, yd, zd, phi_r, wz_r, dphi, dwz), orbit integrated alongside or held.
#[derive(Debug, Clone)]
pub struct QuasiStaticAlongOrbit<'a> {
    pub mu: f64,
    pub body: &'a FlexibleBody,
    pub primaries: [bool; 2],
    pub held: bool,
}

impl System<[f64; 10]> for QuasiStaticAlongOrbit<'_> {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 10], dy: &mut [f64; 10]) {
        let mut d = [0.0; 6];
        orbit_derivative(self.mu, self.held, t, y, &mut d);
        dy[..6].copy_from_slice(&d);
        let (phi, wz) = (y[6], y[7]);
        let wsyn = if self.held {
            let (w, _) = tidal_field(self.mu, &y[..3], self.primaries);
            [w, Complex::new(0.0, 0.0), Complex::new(0.0, 0.0)]
        } else {
            tidal_field_derivatives(self.mu, &y[..3], &y[3..6], &d[3..6], self.primaries)
        };
        let (w, wzk) = chain(self.body, wsyn, phi, wz);
        let k = -3.0 * (self.body.asymmetry().conj() * w[0]).re / self.body.inertia();
        dy[6] = wz - 1.0;
        dy[7] = wzk[0];
        dy[8] = y[9];
        dy[9] = k * y[8] + dtau(self.body, &w, &wzk) / self.body.inertia();
    }
}
