//! The coupled attitude-structure equations (see the module documentation for the derivation)
//! and the energy integral.

use nalgebra::Complex;

use super::body::{cross, dot, FlexibleBody};
use crate::attitude::forcing_scp;
use crate::integrate::System;

/// The tidal field of the enabled primaries [larger, smaller] at a synodic position:
/// W = C + i S = sum_i mu_i zeta_i^2 / r_i^5 (zeta_i = x_i + i y_i relative to primary i:
/// zeta^2 = (x^2 - y^2) + i 2 x y, so C, S are those of the planar model (docs/physics.md, attitude), computed by the planar
/// model's [`forcing_scp`]) and P = sum_i mu_i / r_i^3.
#[inline(always)]
pub fn tidal_field(mu: f64, pos: &[f64], primaries: [bool; 2]) -> (Complex<f64>, f64) {
    let (s, c, p) = forcing_scp(mu, pos, primaries);
    (Complex::new(c, s), p)
}

/// W ([`tidal_field`]) and its first two time derivatives along a planar orbit, from the
/// position, velocity and acceleration (synodic): W = sum mu zeta^2 f, f = r^-5, so
/// W' = sum mu (2 zeta zeta' f + zeta^2 f'), W'' = sum mu (2 zeta'^2 f + 2 zeta zeta'' f +
/// 4 zeta zeta' f' + zeta^2 f''), f' = -5 r^-7 s, f'' = 35 r^-9 s^2 - 5 r^-7 s', s = r.v,
/// s' = |v|^2 + r.a.
pub fn tidal_field_derivatives(mu: f64, pos: &[f64], vel: &[f64], acc: &[f64], primaries: [bool; 2]) -> [Complex<f64>; 3] {
    let mut out = [tidal_field(mu, pos, primaries).0, Complex::new(0.0, 0.0), Complex::new(0.0, 0.0)];
    for (k, (cx, gm)) in [(-mu, 1.0 - mu), (1.0 - mu, mu)].into_iter().enumerate() {
        if !primaries[k] {
            continue;
        }
        let z = Complex::new(pos[0] - cx, pos[1]);
        let zd = Complex::new(vel[0], vel[1]);
        let zdd = Complex::new(acc[0], acc[1]);
        let r2 = z.norm_sqr();
        let r = r2.sqrt();
        let f = 1.0 / (r2 * r2 * r);
        let s = z.re * zd.re + z.im * zd.im;
        let sd = zd.norm_sqr() + z.re * zdd.re + z.im * zdd.im;
        let fd = -5.0 * f / r2 * s;
        let fdd = 35.0 * f / (r2 * r2) * s * s - 5.0 * f / r2 * sd;
        out[1] += (z * zd * 2.0 * f + z * z * fd) * gm;
        out[2] += (zd * zd * 2.0 * f + z * zdd * 2.0 * f + z * zd * 4.0 * fd + z * z * fdd) * gm;
    }
    out
}

/// The tidal field in body axes: w = W e^{-2 i phi} = Cb + i Sb and P; the tidal tensor is
/// T_B = (P/2) I + (3/2) [[Cb, Sb], [Sb, -Cb]].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyField {
    pub w: Complex<f64>,
    pub p: f64,
}

/// e^{-2 i phi}: turns a synodic tidal field into body axes (w = W e^{-2 i phi}).
#[inline(always)]
pub(crate) fn to_body_axes(phi: f64) -> Complex<f64> {
    let (s2, c2) = (2.0 * phi).sin_cos();
    Complex::new(c2, -s2)
}

impl BodyField {
    #[inline(always)]
    pub fn new(w_synodic: Complex<f64>, p: f64, phi: f64) -> Self {
        Self { w: w_synodic * to_body_axes(phi), p }
    }
    /// T_B r.
    #[inline(always)]
    fn apply(&self, r: [f64; 2]) -> [f64; 2] {
        let (cb, sb) = (1.5 * self.w.re, 1.5 * self.w.im);
        let h = 0.5 * self.p;
        [(h + cb) * r[0] + sb * r[1], sb * r[0] + (h - cb) * r[1]]
    }
}

/// Positions relative to the instantaneous centre of mass: c = sum m_j q_j t_j / M and its rate.
#[inline(always)]
fn centre_shift(body: &FlexibleBody, q: &[f64], qd: &[f64]) -> ([f64; 2], [f64; 2]) {
    let mut c = [0.0; 2];
    let mut cd = [0.0; 2];
    for ((a, &qj), &qdj) in body.appendages().iter().zip(q).zip(qd) {
        for i in 0..2 {
            c[i] += a.mass * qj * a.direction[i];
            cd[i] += a.mass * qdj * a.direction[i];
        }
    }
    let m = body.total_mass();
    ([c[0] / m, c[1] / m], [cd[0] / m, cd[1] / m])
}

impl FlexibleBody {
    /// wzdot and qddot (written to `qdd`) from the field, wz, q and qdot: the solution of
    /// [[I(q), gamma^T], [gamma, M_qq]] [wzdot; qddot] = [tau - Idot wz; F] by the Schur
    /// complement, M_qq^{-1} applied through Woodbury (O(n), allocation-free).
    #[inline]
    pub fn accelerations(&self, field: &BodyField, wz: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> f64 {
        let (c, cd) = centre_shift(self, q, qd);
        let hub = self.hub();
        let r0 = [self.hub_position()[0] - c[0], self.hub_position()[1] - c[1]];
        let mut inertia = hub.iz + self.hub_mass() * dot(r0, r0);
        let mut tau = self.hub_mass() * cross(r0, field.apply(r0)) + 1.5 * (hub.iy - hub.ix) * field.w.im;
        let mut idot = 0.0;
        let (mut sf, mut sg) = ([0.0; 2], [0.0; 2]);
        let (mut gu, mut gv) = (0.0, 0.0);
        for (j, a) in self.appendages().iter().enumerate() {
            let t = a.direction;
            let rho = [a.position[0] + q[j] * t[0] - c[0], a.position[1] + q[j] * t[1] - c[1]];
            let trho = field.apply(rho);
            let gamma = a.mass * cross(rho, t);
            let f = a.mass * (dot(t, trho) + wz * wz * dot(t, rho) + 2.0 * wz * cross(cd, t)) - a.stiffness * q[j] - a.damping * qd[j];
            inertia += a.mass * dot(rho, rho);
            tau += a.mass * cross(rho, trho);
            idot += 2.0 * a.mass * qd[j] * dot(t, rho);
            for i in 0..2 {
                sf[i] += t[i] * f;
                sg[i] += t[i] * gamma;
            }
            gu += gamma * f / a.mass;
            gv += gamma * gamma / a.mass;
            qdd[j] = f;
        }
        let wsf = self.wood(sf);
        let wsg = self.wood(sg);
        gu += dot(sg, wsf);
        gv += dot(sg, wsg);
        let wzd = (tau - idot * wz - gu) / (inertia - gv);
        for (j, a) in self.appendages().iter().enumerate() {
            let t = a.direction;
            let rho = [a.position[0] + q[j] * t[0] - c[0], a.position[1] + q[j] * t[1] - c[1]];
            let gamma = a.mass * cross(rho, t);
            let u = qdd[j] / a.mass + dot(t, wsf);
            let v = gamma / a.mass + dot(t, wsg);
            qdd[j] = u - v * wzd;
        }
        wzd
    }

    /// Energies, momentum and torque of a state (see [`Energies`]).
    pub fn energies(&self, field: &BodyField, wz: f64, q: &[f64], qd: &[f64]) -> Energies {
        let (c, cd) = centre_shift(self, q, qd);
        let hub = self.hub();
        let r0 = [self.hub_position()[0] - c[0], self.hub_position()[1] - c[1]];
        let v0 = [-wz * r0[1] - cd[0], wz * r0[0] - cd[1]];
        let mut inertia = hub.iz + self.hub_mass() * dot(r0, r0);
        let mut two_t = hub.iz * wz * wz + self.hub_mass() * dot(v0, v0);
        let mut quad = self.hub_mass() * dot(r0, field.apply(r0));
        let mut tau = self.hub_mass() * cross(r0, field.apply(r0)) + 1.5 * (hub.iy - hub.ix) * field.w.im;
        let mut gq = 0.0;
        let mut elastic = 0.0;
        for (j, a) in self.appendages().iter().enumerate() {
            let t = a.direction;
            let rho = [a.position[0] + q[j] * t[0] - c[0], a.position[1] + q[j] * t[1] - c[1]];
            let rhod = [qd[j] * t[0] - cd[0], qd[j] * t[1] - cd[1]];
            let v = [-wz * rho[1] + rhod[0], wz * rho[0] + rhod[1]];
            let trho = field.apply(rho);
            inertia += a.mass * dot(rho, rho);
            two_t += a.mass * dot(v, v);
            quad += a.mass * dot(rho, trho);
            tau += a.mass * cross(rho, trho);
            gq += a.mass * cross(rho, t) * qd[j];
            elastic += 0.5 * a.stiffness * q[j] * q[j];
        }
        let hub_own = -0.75 * (hub.iy - hub.ix) * field.w.re - 0.5 * field.p * (hub.iz - 0.5 * (hub.ix + hub.iy));
        let momentum = inertia * wz + gq;
        let kinetic = 0.5 * two_t;
        Energies {
            kinetic,
            elastic,
            tidal: -0.5 * quad + hub_own,
            momentum,
            structural: kinetic + elastic - 0.5 * momentum * momentum / inertia,
            torque: tau,
            inertia,
        }
    }
}

/// Energies and momentum of the motion about the centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energies {
    /// T_rel: kinetic energy of the motion relative to the centre of mass (inertial rates).
    pub kinetic: f64,
    /// V_el = sum k_j q_j^2 / 2.
    pub elastic: f64,
    /// V_tidal: the second-order gravity potential of both primaries about the centre of mass
    /// (hub's own moments included, exact to second order; only the enabled primaries).
    pub tidal: f64,
    /// h_z = I(q) wz + gamma(q) . qdot, inertial angular momentum about the centre of mass.
    pub momentum: f64,
    /// T_rel + V_el - h_z^2 / (2 I(q)): the energy above rigid rotation with the same momentum
    /// (zero for an undeformed body at rest relative to the hub; quadratic in (q, qdot)).
    pub structural: f64,
    /// tau: the tidal torque on the deformed body.
    pub torque: f64,
    /// I(q), the instantaneous moment of inertia about the centre of mass.
    pub inertia: f64,
}

/// The flexible body with its orbit integrated alongside (or held): state
/// (x, y, z, xd, yd, zd, phi, wz, q_1..q_n, qdot_1..qdot_n), dimension 8 + 2n.
#[derive(Debug, Clone)]
pub struct FlexibleAlongOrbit<'a> {
    pub mu: f64,
    pub body: &'a FlexibleBody,
    pub primaries: [bool; 2],
    pub held: bool,
}

impl System<Vec<f64>> for FlexibleAlongOrbit<'_> {
    #[inline]
    fn derivative(&self, t: f64, y: &Vec<f64>, dy: &mut Vec<f64>) {
        let n = self.body.n();
        crate::attitude::planar::orbit_derivative(self.mu, self.held, t, y, dy);
        let (w, p) = tidal_field(self.mu, &y[..3], self.primaries);
        let field = BodyField::new(w, p, y[6]);
        let wz = y[7];
        let (q, qd) = y[8..].split_at(n);
        let (dq, dqd) = dy[8..].split_at_mut(n);
        let wzd = self.body.accelerations(&field, wz, q, qd, dqd);
        dq.copy_from_slice(qd);
        dy[6] = wz - 1.0;
        dy[7] = wzd;
    }
}
