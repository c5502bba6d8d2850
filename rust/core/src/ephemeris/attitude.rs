//! Rigid-body attitude along an ephemeris orbit (Earth, Moon and Sun from the ephemeris).
//!
//! State (13): the Moon-centred ICRF orbit state (6, km, km/s), the quaternion q of the body
//! relative to ICRF (4, scalar last; v_icrf = R(q) v_body, R(q) = A(q)' with A = [`dcm`]) and
//! the inertial angular velocity w in body axes (3, rad/s). Time: TDB seconds from the model's
//! start epoch. Equations (the one-way coupling of the CR3BP model: the orbit drives the
//! attitude):
//!   orbit: [`EphemerisDynamics`] (point masses, relative equations);
//!   qdot = 1/2 q (x) (w, 0)            ([`quat_kinematics`], ICRF is inertial);
//!   I wdot = T - w x I w               ([`euler_rate`]).
//! Torques: the gravity gradient of each of Earth, Moon and Sun, T = ((Iz - Iy) N_yz, ...) with
//! N = A M A' and M = sum_b 3 GM_b / |d_b|^5 d_b d_b' ([`tidal_term`],
//! [`gravity_gradient_torque`]; d_b the spacecraft relative to body b, 1/s^2, so T / I is in
//! rad/s^2 for any unit of the inertia); and optionally solar radiation pressure on facets
//! ([`FacetBody`]), with the ephemeris Sun direction, the pressure scaled by (1 AU / r)^2 and the
//! eclipses of the Earth and the Moon ([`super::eclipse`]; the two fractions multiply, their
//! shadows never overlapping in practice). With SRP the inertia must be in kg m^2 (torques in N
//! m), and the integration restarts at the facets' terminators and the shadow contacts, where the
//! right-hand side has kinks.
//!
//! Placement ([`place_attitude`]): a CR3BP attitude (q_s relative to the synodic frame, w_s
//! inertial in body axes, 1/TU) at an epoch goes to q = q_F (x) q_s (q_F the rotating frame's
//! quaternion, axes -> ICRF) and w = theta' (w_s - A_s e_Z) + A(q) omega: the rate relative to
//! the rotating frame, scaled from 1/TU to rad/s with the instantaneous rotation rate theta',
//! plus the frame's own angular velocity omega (ICRF, [`RotatingFrame`]).
//! [`synodic_attitude`] is its inverse.

use rayon::prelude::*;

use super::chebyshev::Ephemeris;
use super::dynamics::{EphemerisDynamics, GM_EARTH, GM_MOON, GM_SUN};
use super::eclipse::{contacts, sunlit_fraction, AU_KM, R_EARTH_KM, R_MOON_KM};
use super::frame::RotatingFrame;
use crate::attitude::{conj, dcm, euler_rate, gravity_gradient_torque, qmul, quat_kinematics, tidal_term, FacetBody, RigidBody};
use crate::error::{check_finite, invalid, Result};
use crate::integrate::{solve, solve_piecewise, EventFn, Options, Output, System};
use crate::scalar::{Dual, Real};

pub type Quat = [f64; 4];
/// The coupled state and the attitude part (q, w).
pub const DIM: usize = 13;
pub const ATT: usize = 7;
/// The state with the 7x7 attitude STM d(q, w)(t) / d(q, w)(t0) (row-major) after it.
pub const STM_DIM: usize = DIM + ATT * ATT;

/// Solar radiation pressure: the facets (their `sun.pressure` is the pressure at 1 AU, N/m^2; the
/// CR3BP Sun phase and TU are not used) and whether the Earth and the Moon eclipse the Sun.
#[derive(Debug, Clone, PartialEq)]
pub struct Srp {
    pub facets: FacetBody,
    pub eclipses: bool,
}

/// The attitude model along an ephemeris orbit.
#[derive(Debug, Clone)]
pub struct AttitudeModel {
    pub eph: Ephemeris,
    /// GM of Earth, Moon, Sun (km^3/s^2), for the orbit and the gravity gradient.
    pub gm: [f64; 3],
    pub body: RigidBody,
    /// The gravity gradient of [Earth, Moon, Sun], each switchable.
    pub gravity_gradient: [bool; 3],
    pub srp: Option<Srp>,
}

impl AttitudeModel {
    /// DE440 GM values; the body validated.
    pub fn new(eph: Ephemeris, body: RigidBody, gravity_gradient: [bool; 3], srp: Option<Srp>) -> Result<Self> {
        let body = RigidBody::new(body.ix, body.iy, body.iz)?;
        Ok(Self { eph, gm: [GM_EARTH, GM_MOON, GM_SUN], body, gravity_gradient, srp })
    }

    /// The right-hand side with time counted from `epoch0` (TDB s).
    pub fn at(&self, epoch0: f64) -> Result<AttitudeDynamics<'_>> {
        let orbit = EphemerisDynamics::with_gm(self.eph.clone(), epoch0, self.gm)?;
        let inertia = self.body.moments();
        Ok(AttitudeDynamics { orbit, model: self, inertia, inv: inertia.map(|v| 1.0 / v) })
    }
}

/// The right-hand side of [`AttitudeModel`] from one epoch.
pub struct AttitudeDynamics<'a> {
    pub orbit: EphemerisDynamics,
    model: &'a AttitudeModel,
    inertia: [f64; 3],
    inv: [f64; 3],
}

/// What the torques see at one instant, from the orbit only.
struct Environment {
    /// sum_b 3 GM_b / |d_b|^5 d_b d_b' (ICRF, 1/s^2): (xx, yy, zz, xy, xz, yz).
    tidal: [f64; 6],
    /// Unit vector spacecraft -> Sun (ICRF) and the pressure factor (1 AU / r)^2 x sunlit fraction.
    sun: [f64; 3],
    pressure_scale: f64,
}

/// Earth and Sun positions relative to the Moon (km).
type Bodies = ([f64; 3], [f64; 3]);

impl AttitudeDynamics<'_> {
    fn environment(&self, bodies: &Bodies, pos: &[f64; 3]) -> Environment {
        let (earth, sun) = (bodies.0, bodies.1);
        let gm = self.model.gm;
        let mut tidal = [0.0; 6];
        let rel = [[pos[0] - earth[0], pos[1] - earth[1], pos[2] - earth[2]], *pos, [pos[0] - sun[0], pos[1] - sun[1], pos[2] - sun[2]]];
        for b in 0..3 {
            if self.model.gravity_gradient[b] {
                let term = tidal_term(gm[b], &rel[b]);
                for i in 0..6 {
                    tidal[i] += term[i];
                }
            }
        }
        let mut env = Environment { tidal, sun: [0.0; 3], pressure_scale: 0.0 };
        if let Some(srp) = &self.model.srp {
            let d = [sun[0] - pos[0], sun[1] - pos[1], sun[2] - pos[2]];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            env.sun = d.map(|c| c / n);
            let lit = if srp.eclipses { sunlit_fraction(pos, &sun, &earth, R_EARTH_KM) * sunlit_fraction(pos, &sun, &[0.0; 3], R_MOON_KM) } else { 1.0 };
            env.pressure_scale = (AU_KM / n).powi(2) * lit;
        }
        env
    }

    /// (qdot, wdot) over any scalar (f64, or dual numbers for the STM).
    #[inline(always)]
    fn attitude_rate<R: Real>(&self, env: &Environment, q: &[R; 4], w: &[R; 3]) -> ([R; 4], [R; 3]) {
        let a = dcm(q);
        let mut tq = gravity_gradient_torque(&a, &env.tidal.map(R::cst), &self.inertia);
        if let (Some(srp), true) = (&self.model.srp, env.pressure_scale > 0.0) {
            let s = env.sun.map(R::cst);
            let sb: [R; 3] = std::array::from_fn(|i| a[i][0] * s[0] + a[i][1] * s[1] + a[i][2] * s[2]);
            let (_, t) = srp.facets.eval(&sb);
            for i in 0..3 {
                tq[i] = tq[i] + t[i].scale(env.pressure_scale);
            }
        }
        (quat_kinematics(q, w), euler_rate(&tq, w, &self.inertia, &self.inv))
    }

    /// The total external torque (body axes, inertia units / s^2: N m for kg m^2) at (t, state).
    pub fn torque(&self, t: f64, y: &[f64; DIM]) -> [f64; 3] {
        let pos = [y[0], y[1], y[2]];
        let env = self.environment(&self.orbit.bodies(t), &pos);
        let q = [y[6], y[7], y[8], y[9]];
        let w = [y[10], y[11], y[12]];
        let (_, wd) = self.attitude_rate(&env, &q, &w);
        // I wdot + w x I w = T
        let iw = [self.inertia[0] * w[0], self.inertia[1] * w[1], self.inertia[2] * w[2]];
        let gyro = [w[1] * iw[2] - w[2] * iw[1], w[2] * iw[0] - w[0] * iw[2], w[0] * iw[1] - w[1] * iw[0]];
        std::array::from_fn(|i| self.inertia[i] * wd[i] + gyro[i])
    }

    #[inline]
    fn orbit_and_env(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Environment {
        let bodies = self.orbit.bodies(t);
        let pos = [y[0], y[1], y[2]];
        let a = self.orbit.acceleration_among(&bodies, &pos, None);
        dy[..6].copy_from_slice(&[y[3], y[4], y[5], a[0], a[1], a[2]]);
        self.environment(&bodies, &pos)
    }

    /// The kink functions of the right-hand side with SRP: each facet's n_k . s_body, then the
    /// Earth's and the Moon's two shadow contacts.
    fn n_kinks(&self) -> usize {
        match &self.model.srp {
            None => 0,
            Some(s) => s.facets.facets.len() + if s.eclipses { 4 } else { 0 },
        }
    }

    fn kink(&self, k: usize, t: f64, y: &[f64]) -> f64 {
        let Some(srp) = &self.model.srp else { return 1.0 };
        let (earth, sun) = self.orbit.bodies(t);
        let pos = [y[0], y[1], y[2]];
        let nf = srp.facets.facets.len();
        if k < nf {
            let a = dcm(&[y[6], y[7], y[8], y[9]]);
            let d = [sun[0] - pos[0], sun[1] - pos[1], sun[2] - pos[2]];
            let n = srp.facets.facets[k].normal;
            (0..3).map(|i| n[i] * (a[i][0] * d[0] + a[i][1] * d[1] + a[i][2] * d[2])).sum()
        } else {
            let j = k - nf;
            let (body, radius) = if j < 2 { (earth, R_EARTH_KM) } else { ([0.0; 3], R_MOON_KM) };
            contacts(&pos, &sun, &body, radius)[j % 2]
        }
    }
}

impl System<[f64; DIM]> for AttitudeDynamics<'_> {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; DIM], dy: &mut [f64; DIM]) {
        let env = self.orbit_and_env(t, y, dy);
        let (qd, wd) = self.attitude_rate(&env, &[y[6], y[7], y[8], y[9]], &[y[10], y[11], y[12]]);
        dy[6..10].copy_from_slice(&qd);
        dy[10..13].copy_from_slice(&wd);
    }
}

impl System<[f64; STM_DIM]> for AttitudeDynamics<'_> {
    fn derivative(&self, t: f64, y: &[f64; STM_DIM], dy: &mut [f64; STM_DIM]) {
        let env = self.orbit_and_env(t, y, dy);
        let q: [Dual<ATT>; 4] = std::array::from_fn(|k| Dual::var(y[6 + k], k));
        let w: [Dual<ATT>; 3] = std::array::from_fn(|k| Dual::var(y[10 + k], 4 + k));
        let (qd, wd) = self.attitude_rate(&env, &q, &w);
        let rows: [&Dual<ATT>; ATT] = [&qd[0], &qd[1], &qd[2], &qd[3], &wd[0], &wd[1], &wd[2]];
        let phi = &y[DIM..];
        for (i, r) in rows.iter().enumerate() {
            dy[6 + i] = r.re;
            for j in 0..ATT {
                let mut s = 0.0;
                for k in 0..ATT {
                    s += r.eps[k] * phi[k * ATT + j];
                }
                dy[DIM + i * ATT + j] = s;
            }
        }
    }
}

struct Kink<'a, 'b> {
    dynamics: &'a AttitudeDynamics<'b>,
    k: usize,
}

impl<const N: usize> EventFn<[f64; N]> for Kink<'_, '_> {
    fn value(&self, t: f64, y: &[f64; N]) -> f64 {
        self.dynamics.kink(self.k, t, y)
    }
}

/// A propagated attitude along the ephemeris orbit.
#[derive(Debug, Clone)]
pub struct AttitudeTrajectory {
    /// Output epochs, TDB s past J2000.
    pub t_tdb: Vec<f64>,
    /// Row-major n x 13 (orbit km, km/s; q; w rad/s).
    pub states: Vec<f64>,
    pub state_final: [f64; DIM],
    /// The 7x7 d(q, w)(end) / d(q, w)(start), when asked.
    pub stm: Option<[[f64; ATT]; ATT]>,
}

/// The integration tolerances of the attitude propagation unless given: rtol 1e-12, atol 1e-15
/// (one absolute tolerance for every component, so it is set for the rates, about 3e-6 rad/s).
pub fn default_options() -> Options {
    Options::with_tolerances(1e-12, 1e-15)
}

fn check_state(state: &[f64; DIM]) -> Result<()> {
    check_finite("state", state)?;
    let qn = state[6..10].iter().map(|v| v * v).sum::<f64>().sqrt();
    if (qn - 1.0).abs() > 1e-9 {
        return Err(invalid("q", format!("must be a unit quaternion (scalar last), |q| = {qn}")));
    }
    Ok(())
}

/// Propagate the attitude model from `epoch` (TDB s) for `duration` s (either sign), with the 7x7
/// attitude STM when asked; `t_eval` are offsets from the epoch (None: every step).
pub fn propagate_attitude(model: &AttitudeModel, epoch: f64, state: &[f64; DIM], duration: f64, stm: bool, t_eval: Option<&[f64]>, opts: &Options) -> Result<AttitudeTrajectory> {
    check_state(state)?;
    if !duration.is_finite() {
        return Err(invalid("duration_s", format!("must be finite, got {duration}")));
    }
    model.eph.check_epoch("epoch", epoch)?;
    model.eph.check_epoch("epoch + duration_s", epoch + duration)?;
    let sys = model.at(epoch)?;
    let output = match t_eval {
        Some(ts) => Output::At(ts),
        None => Output::Steps,
    };
    let kinks: Vec<Kink> = (0..sys.n_kinks()).map(|k| Kink { dynamics: &sys, k }).collect();
    if stm {
        let mut y0 = [0.0; STM_DIM];
        y0[..DIM].copy_from_slice(state);
        for i in 0..ATT {
            y0[DIM + i * ATT + i] = 1.0;
        }
        let ks: Vec<&dyn EventFn<[f64; STM_DIM]>> = kinks.iter().map(|k| k as &dyn EventFn<[f64; STM_DIM]>).collect();
        let sol = if ks.is_empty() { solve(&sys, 0.0, &y0, duration, opts, output, &[])? } else { solve_piecewise(&sys, 0.0, &y0, duration, opts, output, &ks)? };
        let mut states = Vec::with_capacity(sol.t.len() * DIM);
        for row in sol.y.chunks_exact(STM_DIM) {
            states.extend_from_slice(&row[..DIM]);
        }
        let f = &sol.y_final;
        let phi = std::array::from_fn(|i| std::array::from_fn(|j| f[DIM + i * ATT + j]));
        Ok(AttitudeTrajectory { t_tdb: sol.t.iter().map(|t| epoch + t).collect(), states, state_final: std::array::from_fn(|i| f[i]), stm: Some(phi) })
    } else {
        let ks: Vec<&dyn EventFn<[f64; DIM]>> = kinks.iter().map(|k| k as &dyn EventFn<[f64; DIM]>).collect();
        let sol = if ks.is_empty() { solve(&sys, 0.0, state, duration, opts, output, &[])? } else { solve_piecewise(&sys, 0.0, state, duration, opts, output, &ks)? };
        Ok(AttitudeTrajectory { t_tdb: sol.t.iter().map(|t| epoch + t).collect(), states: sol.y, state_final: sol.y_final, stm: None })
    }
}

/// One leg of a batch: start epoch (TDB s), start state, duration (s).
pub type Leg = (f64, [f64; DIM], f64);

/// Propagate many legs on rayon, results in the input order (each leg integrated alone, so the
/// result does not depend on the thread count); only the final state (and STM) is kept.
pub fn propagate_attitude_batch(model: &AttitudeModel, legs: &[Leg], stm: bool, opts: &Options) -> Vec<Result<AttitudeTrajectory>> {
    legs.par_iter().map(|(e, s, d)| propagate_attitude(model, *e, s, *d, stm, Some(&[*d]), opts)).collect()
}

/// The unit quaternion (scalar last) of a rotation matrix m (v_to = m v_from), by Shepperd's
/// method (the largest of the four squared components first).
pub fn quat_from_matrix(m: &[[f64; 3]; 3]) -> Quat {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let cands = [tr, m[0][0], m[1][1], m[2][2]];
    let k = (0..4).fold(0, |b, i| if cands[i] > cands[b] { i } else { b });
    let q = match k {
        0 => {
            let s = 2.0 * (1.0 + tr).sqrt();
            [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
        }
        1 => {
            let s = 2.0 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
            [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
        }
        2 => {
            let s = 2.0 * (1.0 - m[0][0] + m[1][1] - m[2][2]).sqrt();
            [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
        }
        _ => {
            let s = 2.0 * (1.0 - m[0][0] - m[1][1] + m[2][2]).sqrt();
            [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]
        }
    };
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 } / n;
    q.map(|v| v * sign)
}

/// The rotating frame's quaternion: rotating components -> ICRF (its matrix has the axes as columns).
pub fn frame_quaternion(frame: &RotatingFrame) -> Quat {
    let c: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| frame.axes[j][i]));
    quat_from_matrix(&c)
}

fn unit(q: &Quat) -> Quat {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

fn check_attitude(q: &Quat, w: &[f64; 3]) -> Result<()> {
    check_finite("q", q)?;
    check_finite("w", w)?;
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if (n - 1.0).abs() > 1e-6 {
        return Err(invalid("q", format!("must be a unit quaternion (scalar last), |q| = {n}")));
    }
    Ok(())
}

/// A CR3BP attitude (q_s relative to the synodic frame, w_s inertial in body axes, 1/TU) placed
/// in ICRF at the frame's epoch (module docs): (q body -> ICRF, w rad/s inertial in body axes).
pub fn place_attitude(frame: &RotatingFrame, q_s: &Quat, w_s: &[f64; 3]) -> Result<(Quat, [f64; 3])> {
    check_attitude(q_s, w_s)?;
    let q_s = unit(q_s);
    let q = unit(&qmul(&frame_quaternion(frame), &q_s));
    let a_s = dcm(&q_s);
    let a = dcm(&q);
    let om = frame.omega;
    let w = std::array::from_fn(|i| frame.rate_rad_s * (w_s[i] - a_s[i][2]) + a[i][0] * om[0] + a[i][1] * om[1] + a[i][2] * om[2]);
    Ok((q, w))
}

/// The inverse of [`place_attitude`]: an ICRF attitude at the frame's epoch in the synodic frame
/// (q_s, w_s in 1/TU of the instantaneous rotation rate).
pub fn synodic_attitude(frame: &RotatingFrame, q: &Quat, w: &[f64; 3]) -> Result<(Quat, [f64; 3])> {
    check_attitude(q, w)?;
    let q = unit(q);
    let mut q_s = unit(&qmul(&conj(&frame_quaternion(frame)), &q));
    if q_s[3] < 0.0 {
        q_s = q_s.map(|v| -v);
    }
    let a_s = dcm(&q_s);
    let a = dcm(&q);
    let om = frame.omega;
    let w_s = std::array::from_fn(|i| (w[i] - (a[i][0] * om[0] + a[i][1] * om[1] + a[i][2] * om[2])) / frame.rate_rad_s + a_s[i][2]);
    Ok((q_s, w_s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ephemeris::Segment;

    /// A synthetic ephemeris (linear motions over +-1e6 s): the Moon 384,400 km from the Earth.
    fn toy() -> Ephemeris {
        let seg = |t, c, v: [f64; 6]| Segment::new(t, c, -1e6, 1e6, -1e6, 2e6, 1, 2, v.to_vec()).unwrap();
        Ephemeris::new(vec![
            seg(3, 0, [1.496e8, 0.0, 0.0, 3e6, 0.0, 0.0]),
            seg(10, 0, [0.0; 6]),
            seg(399, 3, [-4700.0, 0.0, 0.0, -12.0, 0.0, 0.0]),
            seg(301, 3, [379_700.0, 0.0, 0.0, 1e6, 0.0, 2e4]),
        ])
        .unwrap()
    }

    fn state() -> [f64; DIM] {
        let q = unit(&[0.2, -0.4, 0.1, 0.85]);
        [7e4, 1e4, -5e3, 0.05, 0.35, 0.02, q[0], q[1], q[2], q[3], 2e-6, -1e-6, 4e-6]
    }

    /// The 7x7 attitude STM (dual numbers) against central differences of the integrated
    /// 13-state over 2 days: 1e-6 of each column's scale.
    #[test]
    fn stm_matches_finite_differences() {
        let model = AttitudeModel::new(toy(), RigidBody::new(1.0, 1.8, 2.5).unwrap(), [true, true, true], None).unwrap();
        let y0 = state();
        let opts = Options::with_tolerances(1e-13, 1e-18);
        let dur = 2.0 * 86400.0;
        let tr = propagate_attitude(&model, 0.0, &y0, dur, true, Some(&[dur]), &opts).unwrap();
        let phi = tr.stm.unwrap();
        let sys = model.at(0.0).unwrap();
        for j in 0..ATT {
            let h = if j < 4 { 1e-6 } else { 1e-10 };
            let mut yp = y0;
            let mut ym = y0;
            yp[6 + j] += h;
            ym[6 + j] -= h;
            let fp = solve(&sys, 0.0, &yp, dur, &opts, Output::Final, &[]).unwrap().y_final;
            let fm = solve(&sys, 0.0, &ym, dur, &opts, Output::Final, &[]).unwrap().y_final;
            let col: Vec<f64> = (0..ATT).map(|i| (fp[6 + i] - fm[6 + i]) / (2.0 * h)).collect();
            let scale = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..ATT {
                assert!((phi[i][j] - col[i]).abs() <= 1e-6 * scale, "({i}, {j}): {} vs {}", phi[i][j], col[i]);
            }
        }
    }

    /// Torque-free (every gradient off): the angular momentum R(q) I w in ICRF and the kinetic
    /// energy are constant (1e-11 relative over 5 days).
    #[test]
    fn torque_free_conserves_momentum_and_energy() {
        let body = RigidBody::new(1.0, 1.8, 2.5).unwrap();
        let model = AttitudeModel::new(toy(), body, [false; 3], None).unwrap();
        let y0 = state();
        let tr = propagate_attitude(&model, 0.0, &y0, 5.0 * 86400.0, false, None, &default_options()).unwrap();
        let inv = |y: &[f64]| {
            let a = dcm(&[y[6], y[7], y[8], y[9]]);
            let iw = [body.ix * y[10], body.iy * y[11], body.iz * y[12]];
            let h: [f64; 3] = std::array::from_fn(|j| a[0][j] * iw[0] + a[1][j] * iw[1] + a[2][j] * iw[2]);
            (h, iw[0] * y[10] + iw[1] * y[11] + iw[2] * y[12])
        };
        let (h0, e0) = inv(&y0[..]);
        let (h1, e1) = inv(&tr.state_final[..]);
        let hn = h0.iter().map(|v| v * v).sum::<f64>().sqrt();
        for k in 0..3 {
            assert!((h1[k] - h0[k]).abs() < 1e-11 * hn);
        }
        assert!((e1 - e0).abs() < 1e-11 * e0);
    }

    #[test]
    fn matrix_quaternion_round_trip() {
        for q in [[0.1, -0.7, 0.2, 0.5], [0.9, 0.1, 0.1, 0.05], [0.0, 0.0, 1.0, 0.0], [0.0, 0.6, 0.0, -0.8]] {
            let q = unit(&q);
            let a = dcm(&q);
            let r: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]));
            let p = quat_from_matrix(&r);
            let s = if (p[3] * q[3] + p[0] * q[0] + p[1] * q[1] + p[2] * q[2]) < 0.0 { -1.0 } else { 1.0 };
            for k in 0..4 {
                assert!((p[k] - s * q[k]).abs() < 1e-14, "{p:?} vs {q:?}");
            }
        }
    }
}
