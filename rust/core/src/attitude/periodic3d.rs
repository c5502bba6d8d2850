//! Periodic 3-D attitude motions along a periodic orbit (issue 15): the coupled model
//! ([`crate::attitude::Coupled`], gravity gradient of both primaries, orbit integrated alongside)
//! corrected so that, after `t_final` = K T,
//!
//!   the attitude relative to the synodic frame repeats:  r = Log(q0* (x) q(T)) = 0 (the rotation
//!       vector of R(0)' R(T), in body axes at t = 0; q and -q are one attitude),
//!   the inertial rate repeats:                            w(T) - w0 = 0.
//!
//! Unknowns x = (theta, w0): theta (3) a rotation in body axes in a chart about the candidate's
//! guess q_ref, q0 = q_ref (x) Exp(theta), and w0 (3). The Jacobian is exact: from the 13x13
//! STM of the coupled model (dual numbers), the derivative of Exp and of Log in closed form.
//! Half-period symmetric form ([`Options3d::half`]): the CR3BP is symmetric under the reflection
//! S = diag(1, -1, 1) of the synodic frame with time reversal, and so is the attitude (R(t) ->
//! S R(-t) S, any principal-axis inertia). On an orbit started on the x-z plane perpendicularly
//! (y = xdot = zdot = 0), a motion with R(0) e_y = +-e_y and w_y(0) = 0 is mirror symmetric, and
//! it is periodic when the same holds at T/2: (A[1][0], A[1][2], w_y)(KT/2) = 0, three equations
//! in the unknowns (theta_y, w_x, w_z) (theta about body y keeps R(0) e_y = +-e_y). The
//! full-period monodromy comes from one more batch over KT at the solutions.
//!
//! Across an orbit family ([`correct_attitudes_3d_across`], the corrector of continuation in
//! the orbit period): the bordered form, with the period T a seventh unknown and a linear
//! condition closing the system; each Newton point's orbit is the family member of its period
//! (symmetric shooting), and d F / d T is exact from the STM and the family's tangent.
//!
//! Newton runs on the one batched driver ([`super::newton`]); each iteration integrates the
//! pending points of every candidate in parallel (rayon). The 6x6 attitude monodromy is the
//! STM in the coordinates (theta, dw) of [`crate::attitude::linear`].

use rayon::prelude::*;

use super::newton::{self, Eval, Problem, Settings, StopReason};
use crate::attitude::linear::reduce;
use crate::orbit::{Constraint as SymConstraint, Evaluation, SymmetricOrbit, SymmetricShooting};
use crate::attitude::{propagate_attitude, Coupled, GravityGradient, OrbitMode, RigidBody, Torque};
use crate::integrate::System;
use crate::cr3bp::check_mu;
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::integrate::{Options, Output};
use crate::propagation::{with_threads, with_threads_rounds};

type Quat = [f64; 4];

/// Hamilton product p (x) q, scalar last.
pub fn qmul(p: &Quat, q: &Quat) -> Quat {
    let [a1, a2, a3, a4] = *p;
    let [b1, b2, b3, b4] = *q;
    [
        a4 * b1 + b4 * a1 + a2 * b3 - a3 * b2,
        a4 * b2 + b4 * a2 + a3 * b1 - a1 * b3,
        a4 * b3 + b4 * a3 + a1 * b2 - a2 * b1,
        a4 * b4 - a1 * b1 - a2 * b2 - a3 * b3,
    ]
}

pub(crate) fn conj(q: &Quat) -> Quat {
    [-q[0], -q[1], -q[2], q[3]]
}

/// The 4x4 matrices of p (x) q = L(p) q = R(q) p.
pub(crate) fn lmat(p: &Quat) -> [[f64; 4]; 4] {
    let [a1, a2, a3, a4] = *p;
    [[a4, -a3, a2, a1], [a3, a4, -a1, a2], [-a2, a1, a4, a3], [-a1, -a2, -a3, a4]]
}

pub(crate) fn rmat(q: &Quat) -> [[f64; 4]; 4] {
    let [b1, b2, b3, b4] = *q;
    [[b4, b3, -b2, b1], [-b3, b4, b1, b2], [b2, -b1, b4, b3], [-b1, -b2, -b3, b4]]
}

/// Exp(theta) = (sin(|theta|/2) theta/|theta|, cos(|theta|/2)) and its derivative (4x3).
pub fn qexp(t: &[f64; 3]) -> (Quat, [[f64; 3]; 4]) {
    let a = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    let (s, c) = (0.5 * a).sin_cos();
    // f = sin(a/2)/a, with f' / a = (cos(a/2)/2 - f) / a^2 (series below 1e-4)
    let (f, g) = if a < 1e-4 { (0.5 - a * a / 48.0, -1.0 / 24.0 + a * a / 960.0) } else { (s / a, (0.5 * c - s / a) / (a * a)) };
    let q = [f * t[0], f * t[1], f * t[2], c];
    let mut d = [[0.0; 3]; 4];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = g * t[i] * t[j] + if i == j { f } else { 0.0 };
        }
        d[3][i] = -0.5 * f * t[i];
    }
    (q, d)
}

/// Log(q) = 2 atan2(|v|, s) v/|v| of a unit quaternion with s >= 0, and its derivative (3x4).
pub fn qlog(q: &Quat) -> ([f64; 3], [[f64; 4]; 3]) {
    let v = [q[0], q[1], q[2]];
    let s = q[3];
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let m2 = n * n + s * s;
    // r = f v, f = 2 atan2(n, s) / n; df/dn, df/ds
    let (f, dfdn_over_n, dfds) = if n < 1e-6 * s.abs().max(1e-300) {
        // series in n: f = 2/s - 2 n^2 / (3 s^3) + ...
        (2.0 / s - 2.0 * n * n / (3.0 * s * s * s), -4.0 / (3.0 * s * s * s), -2.0 / m2)
    } else {
        let at = n.atan2(s);
        let f = 2.0 * at / n;
        (f, (2.0 * s / m2 - f) / (n * n), -2.0 / m2)
    };
    let r = [f * v[0], f * v[1], f * v[2]];
    let mut d = [[0.0; 4]; 3];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = dfdn_over_n * v[i] * v[j] + if i == j { f } else { 0.0 };
        }
        d[i][3] = dfds * v[i];
    }
    (r, d)
}

/// q0* (x) qT scaled to a unit quaternion with a non-negative scalar part (q and -q are one
/// attitude), and the factor applied (+-1 / |q0* (x) qT|).
fn relative(q0: &Quat, qt: &Quat) -> (Quat, f64) {
    let delta = qmul(&conj(q0), qt);
    let nd = delta.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if delta[3] < 0.0 { -1.0 } else { 1.0 } / nd;
    (delta.map(|v| v * sign), sign)
}

/// The residuals of a 3-D attitude motion from (q0, w0) to (qT, wT), as the corrector defines
/// them: (Log(q0* (x) qT), the rotation vector of R(0)' R(T) in body axes at t = 0, with angle in
/// [0, pi]; wT - w0).
pub fn attitude_residual(q0: &Quat, w0: &[f64; 3], qt: &Quat, wt: &[f64; 3]) -> [f64; 6] {
    let (r, _) = qlog(&relative(q0, qt).0);
    [r[0], r[1], r[2], wt[0] - w0[0], wt[1] - w0[1], wt[2] - w0[2]]
}

/// One starting guess: the attitude q (scalar last, body relative to synodic; the chart's
/// centre) and the inertial rate w (body axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start3d {
    pub q: Quat,
    pub w: [f64; 3],
}

/// Settings of [`correct_attitudes_3d`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options3d {
    /// Convergence: residual max-norm <= tol (rad and rad/TU).
    pub tol: f64,
    pub max_iter: usize,
    pub max_halvings: u32,
    /// Integration tolerances of the corrector's trajectories.
    pub rtol: f64,
    pub atol: f64,
    /// Largest Newton step in the attitude (rad) and in the rate (1/TU); the step is scaled down.
    pub max_angle_step: f64,
    pub max_rate_step: f64,
    /// Worker threads (None: all cores).
    pub threads: Option<usize>,
    /// Enabled primaries of the gravity gradient [larger, smaller].
    pub primaries: [bool; 2],
    /// The half-period symmetric form (see the module docs): `t_final` is still K T.
    pub half: bool,
}

impl Default for Options3d {
    fn default() -> Self {
        Self { tol: 1e-12, max_iter: 40, max_halvings: 10, rtol: 1e-13, atol: 1e-13, max_angle_step: 0.5, max_rate_step: 0.5, threads: None, primaries: [true, true], half: false }
    }
}

/// The outcome of one candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Correction3d {
    /// Final attitude (unit, scalar last) and inertial rate in body axes.
    pub q0: Quat,
    pub w0: [f64; 3],
    /// (rotation vector of R(0)' R(T) in body axes, w(T) - w0); the half form: (A[1][0], A[1][2],
    /// w_y) at T/2, then NaN. NaN when not integrated.
    pub residual: [f64; 6],
    pub residual_norm: f64,
    pub iterations: usize,
    pub reason: StopReason,
    /// 6x6 attitude monodromy d(theta, w)(T) / d(theta, w)(0) (body-axis chart), NaN when not
    /// integrated.
    pub monodromy: [[f64; 6]; 6],
}

struct Form3d<'a> {
    starts: &'a [Start3d],
    opts: Options3d,
}

const ROWS: [usize; 6] = [0, 1, 2, 3, 4, 5];
const HALF_ROWS: [usize; 3] = [0, 1, 2];
/// (theta_y, w_x, w_z).
const HALF_COLS: [usize; 3] = [1, 3, 5];

/// The attitude matrix A(q) and its derivative d A[i][j] / d q_k (dual numbers).
fn dcm_and_derivative(q: &Quat) -> ([[f64; 3]; 3], [[[f64; 4]; 3]; 3]) {
    use crate::scalar::Dual;
    let qd: [Dual<4>; 4] = std::array::from_fn(|k| Dual::var(q[k], k));
    let a = crate::attitude::dcm(&qd);
    (a.map(|r| r.map(|v| v.re)), a.map(|r| r.map(|v| v.eps)))
}

impl Form3d<'_> {
    fn q0(&self, c: usize, x: &[f64; 6]) -> (Quat, [[f64; 3]; 4]) {
        let (e, de) = qexp(&[x[0], x[1], x[2]]);
        let qr = self.starts[c].q;
        let l = lmat(&qr);
        let d: [[f64; 3]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| l[i][k] * de[k][j]).sum()));
        (qmul(&qr, &e), d)
    }
}

type Traj = [f64; 13];
type Out = Option<(Vec<f64>, Vec<f64>)>;

impl Problem<6> for Form3d<'_> {
    type Cand = usize;
    type Traj = Traj;
    type Out = Out;
    fn initial(&self, c: &usize) -> [f64; 6] {
        let w = self.starts[*c].w;
        [0.0, 0.0, 0.0, w[0], w[1], w[2]]
    }
    fn push(&self, c: &usize, x: &[f64; 6], out: &mut Vec<Traj>) -> bool {
        let (q, _) = self.q0(*c, x);
        let mut s = [0.0; 13];
        s[6..10].copy_from_slice(&q);
        s[10..13].copy_from_slice(&x[3..6]);
        out.push(s);
        true
    }
    fn per_point(&self) -> usize {
        1
    }
    fn evaluate(&self, c: &usize, x: &[f64; 6], o: &[Out]) -> Option<Eval<6>> {
        let (yt, stm) = o.first()?.as_ref()?;
        if !(yt.iter().all(|v| v.is_finite()) && stm.iter().all(|v| v.is_finite())) {
            return None;
        }
        let (q0, dq0) = self.q0(*c, x);
        let qt: Quat = [yt[6], yt[7], yt[8], yt[9]];
        let phi = |i: usize, j: usize| stm[i * 13 + j];
        let (delta, sign) = relative(&q0, &qt);
        let (r, dlog) = qlog(&delta);
        // d qT / d x (4x6) and d wT / d x (3x6)
        let mut dqt = [[0.0; 6]; 4];
        let mut dwt = [[0.0; 6]; 3];
        for (rows, off, dst) in [(6usize, 4usize, 0usize), (10, 3, 1)] {
            for i in 0..off {
                for j in 0..6 {
                    let v = if j < 3 { (0..4).map(|k| phi(rows + i, 6 + k) * dq0[k][j]).sum::<f64>() } else { phi(rows + i, 10 + j - 3) };
                    if dst == 0 {
                        dqt[i][j] = v;
                    } else {
                        dwt[i][j] = v;
                    }
                }
            }
        }
        if self.opts.half {
            // (A[1][0], A[1][2], w_y)(T/2) and their derivatives
            let (a, da) = dcm_and_derivative(&qt);
            let mut f = [f64::NAN; 6];
            let mut jac = [[f64::NAN; 6]; 6];
            for (row, (i, j)) in [(1usize, 0usize), (1, 2)].into_iter().enumerate() {
                f[row] = a[i][j];
                jac[row] = std::array::from_fn(|c| (0..4).map(|k| da[i][j][k] * dqt[k][c]).sum());
            }
            f[2] = yt[11];
            jac[2] = dwt[1];
            return Some(Eval { f, jac, keep: Vec::new() });
        }
        // d delta = R(qT) conj(d q0) + L(conj q0) d qT, times the sign (and 1/|delta|)
        let (rq, lc) = (rmat(&qt), lmat(&conj(&q0)));
        let mut ddelta = [[0.0; 6]; 4];
        for i in 0..4 {
            for j in 0..6 {
                let a: f64 = if j < 3 { (0..4).map(|k| rq[i][k] * if k < 3 { -dq0[k][j] } else { dq0[k][j] }).sum() } else { 0.0 };
                let b: f64 = (0..4).map(|k| lc[i][k] * dqt[k][j]).sum();
                ddelta[i][j] = sign * (a + b);
            }
        }
        let mut f = [0.0; 6];
        let mut jac = [[0.0; 6]; 6];
        for i in 0..3 {
            f[i] = r[i];
            f[3 + i] = yt[10 + i] - x[3 + i];
            for j in 0..6 {
                jac[i][j] = (0..4).map(|k| dlog[i][k] * ddelta[k][j]).sum();
                jac[3 + i][j] = dwt[i][j] - if j == 3 + i { 1.0 } else { 0.0 };
            }
        }
        let m13: [[f64; 13]; 13] = std::array::from_fn(|i| std::array::from_fn(|j| phi(i, j)));
        let mono = reduce(&m13, &q0, &qt);
        Some(Eval { f, jac, keep: mono.iter().flatten().copied().collect() })
    }
    fn rows(&self) -> &[usize] {
        if self.opts.half {
            &HALF_ROWS
        } else {
            &ROWS
        }
    }
    fn cols(&self) -> &[usize] {
        if self.opts.half {
            &HALF_COLS
        } else {
            &ROWS
        }
    }
    fn step_scale(&self, d: &[f64; 6]) -> f64 {
        let na = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let nw = (d[3] * d[3] + d[4] * d[4] + d[5] * d[5]).sqrt();
        let cap = |v: f64, m: f64| if v > m { m / v } else { 1.0 };
        cap(na, self.opts.max_angle_step).min(cap(nw, self.opts.max_rate_step))
    }
}

/// Correct many guesses at once to periodic 3-D attitude motions along the orbit started at
/// `orbit0` over `t_final` (K orbit periods; the orbit is integrated alongside, so it must be
/// periodic with a period dividing `t_final`). Returns one [`Correction3d`] per start, in
/// order; `Err` only for invalid arguments.
pub fn correct_attitudes_3d(mu: f64, body: RigidBody, orbit0: &[f64; 6], t_final: f64, starts: &[Start3d], opts: &Options3d) -> Result<Vec<Correction3d>> {
    check_mu(mu)?;
    RigidBody::new(body.ix, body.iy, body.iz)?;
    check_finite("orbit_state", orbit0)?;
    check_positive("t_final", t_final)?;
    check_positive("tol", opts.tol)?;
    check_positive("max_angle_step", opts.max_angle_step)?;
    check_positive("max_rate_step", opts.max_rate_step)?;
    crate::integrate::check_tolerances(opts.rtol, opts.atol)?;
    if opts.max_iter == 0 {
        return Err(invalid("max_iter", "must be >= 1"));
    }
    if opts.max_halvings > 60 {
        return Err(invalid("max_halvings", format!("must be in [0, 60], got {}", opts.max_halvings)));
    }
    if opts.threads == Some(0) {
        return Err(invalid("threads", "must be >= 1 (or None for all cores)"));
    }
    for (i, s) in starts.iter().enumerate() {
        if !(s.q.iter().all(|v| v.is_finite()) && s.w.iter().all(|v| v.is_finite())) {
            return Err(invalid("guess", format!("start {i}: q and w must be finite")));
        }
        let n = s.q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-9 {
            return Err(invalid("guess", format!("start {i}: q must be a unit quaternion (scalar last), |q| = {n}")));
        }
    }
    if opts.half {
        if orbit0[1] != 0.0 || orbit0[3] != 0.0 || orbit0[5] != 0.0 {
            return Err(invalid("closure", format!("the half-period form needs an orbit started on the x-z plane perpendicularly (y = xdot = zdot = 0), got {orbit0:?}")));
        }
        for (i, s) in starts.iter().enumerate() {
            let a = crate::attitude::dcm(&s.q);
            if a[1][0].abs() > 1e-12 || a[1][2].abs() > 1e-12 || s.w[1].abs() > 1e-12 {
                return Err(invalid("guess", format!("start {i}: the half-period form needs a mirror-symmetric guess, body y on synodic +-Y and w_y = 0 (got A[1] = {:?}, w_y = {})", a[1], s.w[1])));
            }
        }
    }
    let starts: Vec<Start3d> = starts.iter().map(|s| Start3d { q: s.q.map(|v| v / s.q.iter().map(|u| u * u).sum::<f64>().sqrt()), w: s.w }).collect();
    let form = Form3d { starts: &starts, opts: *opts };
    let gg = GravityGradient { primaries: opts.primaries };
    let integ = Options::with_tolerances(opts.rtol, opts.atol);
    let run = |y: &Traj, tf: f64| -> Out {
        let mut s = *y;
        s[..6].copy_from_slice(orbit0);
        let torques: [&dyn Torque; 1] = [&gg];
        let r = propagate_attitude(mu, body, &torques, OrbitMode::Integrate, &s, 0.0, tf, &integ, true, Output::Final, None, None).ok()?;
        let yt = r.states[r.states.len() - 13..].to_vec();
        Some((yt, r.stm_final?))
    };
    let t_solve = if opts.half { 0.5 * t_final } else { t_final };
    let one = |y: &Traj| run(y, t_solve);
    let settings = Settings { tol: opts.tol, max_iter: opts.max_iter, max_halvings: opts.max_halvings, group: 1, max_contraction: f64::INFINITY };
    let cands: Vec<usize> = (0..starts.len()).collect();
    let (tracks, full) = with_threads_rounds(opts.threads, || -> Result<_> {
        let tracks = newton::solve(&form, &cands, &settings, &|b: &[Traj]| Ok(b.par_iter().map(one).collect()))?;
        // the half form's full-period monodromy: one more batch over K T at the final points
        let full: Vec<Option<[[f64; 6]; 6]>> = if opts.half {
            (0..tracks.len())
                .into_par_iter()
                .map(|c| {
                    tracks[c].cur.as_ref()?;
                    let x = tracks[c].x();
                    let mut y = [0.0; 13];
                    let (q0, _) = form.q0(c, &x);
                    y[6..10].copy_from_slice(&q0);
                    y[10..13].copy_from_slice(&x[3..6]);
                    let (yt, stm) = run(&y, t_final)?;
                    let m13: [[f64; 13]; 13] = std::array::from_fn(|i| std::array::from_fn(|j| stm[i * 13 + j]));
                    Some(reduce(&m13, &q0, &[yt[6], yt[7], yt[8], yt[9]]))
                })
                .collect()
        } else {
            vec![None; tracks.len()]
        };
        Ok((tracks, full))
    })??;
    Ok(tracks
        .iter()
        .zip(full)
        .enumerate()
        .map(|(c, (t, full))| {
            let x = t.x();
            let (q0, _) = form.q0(c, &x);
            let p = t.cur.as_ref();
            let mono = match (full, p) {
                (Some(m), _) => m,
                (None, Some(p)) if !p.keep.is_empty() => std::array::from_fn(|i| std::array::from_fn(|j| p.keep[6 * i + j])),
                _ => [[f64::NAN; 6]; 6],
            };
            Correction3d {
                q0,
                w0: [x[3], x[4], x[5]],
                residual: p.map_or([f64::NAN; 6], |p| p.f),
                residual_norm: p.map_or(f64::NAN, |p| p.norm),
                iterations: t.iterations,
                reason: t.reason(),
                monodromy: mono,
            }
        })
        .collect())
}

/// One candidate of [`correct_attitudes_3d_across`]: the guess (q the chart's centre, w), the
/// orbit period `period` at which it starts (TU), and its linear condition
/// `a . (theta, w0, period) = b` closing the 7x7 system (natural continuation: a = e_7, b the
/// period; pseudo-arclength: the tangent in these coordinates and the step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartAcross3d {
    pub q: Quat,
    pub w: [f64; 3],
    pub period: f64,
    pub a: [f64; 7],
    pub b: f64,
}

/// The outcome of one candidate of [`correct_attitudes_3d_across`].
#[derive(Debug, Clone, PartialEq)]
pub struct CorrectionAcross3d {
    pub q0: Quat,
    pub w0: [f64; 3],
    /// The family member at the final point: its initial state and period (TU), corrected by
    /// symmetric shooting with the period fixed (NaN when none was reached).
    pub orbit0: [f64; 6],
    pub period: f64,
    /// (rotation vector of R(0)' R(KT), w(KT) - w0, the linear condition's a . x - b).
    pub residual: [f64; 7],
    pub residual_norm: f64,
    pub iterations: usize,
    pub reason: StopReason,
    /// 6x6 attitude monodromy over K T, as [`Correction3d::monodromy`].
    pub monodromy: [[f64; 6]; 6],
    /// d F / d T of the six closure residuals at the final point (exact, from the 13x13 STM and
    /// the family's tangent d s0 / d T). At a solution it does not depend on the chart, and with
    /// the monodromy M it gives the family's Jacobian [M - I, dF/dT] in the solution's own
    /// body-axis chart.
    pub dparam: [f64; 6],
}

/// The orbit family of [`correct_attitudes_3d_across`]: x-z-symmetric members
/// (x0, 0, z0, 0, vy0, 0), each period its own member, corrected by symmetric shooting
/// ([`SymmetricShooting`], [`Constraint::Period`]) from the first-order guess along the family's
/// tangent at a reference member.
struct SymmetricFamily {
    shooting: SymmetricShooting,
    reference: SymmetricOrbit,
    tangent: [f64; 3],
}

/// d (x0, z0, vy0) / d T along an x-z-symmetric family at an evaluated member
/// ([`Evaluation::tangent`] per unit of T = 2 t_half). None at a fold of the family in T.
fn family_tangent(e: &Evaluation, spatial: bool) -> Option<[f64; 3]> {
    e.tangent(spatial, e.dhalf.map(|d| 2.0 * d))
}

impl SymmetricFamily {
    fn new(mu: f64, member: &[f64; 6], period: f64, rtol: f64, atol: f64) -> Result<Self> {
        if member[1] != 0.0 || member[3] != 0.0 || member[5] != 0.0 {
            return Err(invalid("orbit0", format!("the family's member must start on the x-z plane perpendicularly (y = xdot = zdot = 0), got {member:?}")));
        }
        let spatial = member[2] != 0.0;
        let mut shooting = SymmetricShooting::new(mu, spatial, Options::with_tolerances(rtol, atol));
        shooting.tol = 1e-12;
        shooting.t_max = period;
        let reference = shooting.correct([member[0], member[2], member[4]], SymConstraint::Period(period))?;
        let tangent = family_tangent(&reference.evaluation, spatial).ok_or_else(|| invalid("orbit0", "the orbit family has no tangent in the period at this member (a fold of the family in T)"))?;
        Ok(Self { shooting, reference, tangent })
    }

    /// The member of period `t` with its tangent d s0 / d T.
    fn member(&self, t: f64) -> Option<(SymmetricOrbit, [f64; 6])> {
        if !(t.is_finite() && t > 0.0) {
            return None;
        }
        let r = &self.reference;
        let dt = t - r.period;
        let guess = [r.state0[0] + self.tangent[0] * dt, r.state0[2] + self.tangent[1] * dt, r.state0[4] + self.tangent[2] * dt];
        let mut sh = self.shooting;
        sh.t_max = t;
        let o = sh.correct(guess, SymConstraint::Period(t)).ok()?;
        let v = family_tangent(&o.evaluation, self.shooting.spatial)?;
        Some((o, [v[0], 0.0, v[1], 0.0, v[2], 0.0]))
    }
}

struct FormAcross<'a> {
    starts: &'a [StartAcross3d],
    opts: Options3d,
    max_period_step: f64,
}

const ROWS7: [usize; 7] = [0, 1, 2, 3, 4, 5, 6];

/// The end of one bordered trajectory: the state and 13x13 STM at K T(p), d y(KT) / d T along
/// the family, and the member.
type OutAcross = Option<(Vec<f64>, Vec<f64>, [f64; 13], [f64; 6], f64)>;

impl Problem<7> for FormAcross<'_> {
    type Cand = usize;
    type Traj = (Traj, f64);
    type Out = OutAcross;
    fn initial(&self, c: &usize) -> [f64; 7] {
        let s = &self.starts[*c];
        [0.0, 0.0, 0.0, s.w[0], s.w[1], s.w[2], s.period]
    }
    fn push(&self, c: &usize, x: &[f64; 7], out: &mut Vec<(Traj, f64)>) -> bool {
        if !(x[6].is_finite() && x[6] > 0.0) {
            return false;
        }
        let (q, _) = qexp_about(&self.starts[*c].q, &[x[0], x[1], x[2]]);
        let mut s = [0.0; 13];
        s[6..10].copy_from_slice(&q);
        s[10..13].copy_from_slice(&x[3..6]);
        out.push((s, x[6]));
        true
    }
    fn per_point(&self) -> usize {
        1
    }
    fn evaluate(&self, c: &usize, x: &[f64; 7], o: &[OutAcross]) -> Option<Eval<7>> {
        let (yt, stm, dydt, _, _) = o.first()?.as_ref()?;
        let (q0, dq0) = qexp_about(&self.starts[*c].q, &[x[0], x[1], x[2]]);
        let (f6, j6, mono) = closure_rows(&q0, &dq0, &[x[3], x[4], x[5]], yt, stm)?;
        // d F / d T: the end state moves by dydt (orbit columns of the STM on d s0 / d T, plus
        // the vector field times K); q0 and w0 do not depend on T
        let qt: Quat = [yt[6], yt[7], yt[8], yt[9]];
        let mut delta = qmul(&conj(&q0), &qt);
        let nd = delta.iter().map(|v| v * v).sum::<f64>().sqrt();
        let sign = if delta[3] < 0.0 { -1.0 } else { 1.0 } / nd;
        delta = delta.map(|v| v * sign);
        let (_, dlog) = qlog(&delta);
        let lc = lmat(&conj(&q0));
        let dd: [f64; 4] = std::array::from_fn(|i| sign * (0..4).map(|k| lc[i][k] * dydt[6 + k]).sum::<f64>());
        let s = &self.starts[*c];
        let mut f = [0.0; 7];
        let mut jac = [[0.0; 7]; 7];
        for i in 0..6 {
            f[i] = f6[i];
            jac[i][..6].copy_from_slice(&j6[i]);
            jac[i][6] = if i < 3 { (0..4).map(|k| dlog[i][k] * dd[k]).sum() } else { dydt[10 + i - 3] };
        }
        f[6] = (0..7).map(|k| s.a[k] * x[k]).sum::<f64>() - s.b;
        jac[6] = s.a;
        let mut keep: Vec<f64> = mono.iter().flatten().copied().collect();
        keep.extend((0..6).map(|i| jac[i][6]));
        Some(Eval { f, jac, keep })
    }
    fn rows(&self) -> &[usize] {
        &ROWS7
    }
    fn cols(&self) -> &[usize] {
        &ROWS7
    }
    fn closure_rows(&self) -> &[usize] {
        &ROWS7[..6]
    }
    fn step_scale(&self, d: &[f64; 7]) -> f64 {
        let na = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let nw = (d[3] * d[3] + d[4] * d[4] + d[5] * d[5]).sqrt();
        let cap = |v: f64, m: f64| if v > m { m / v } else { 1.0 };
        cap(na, self.opts.max_angle_step).min(cap(nw, self.opts.max_rate_step)).min(cap(d[6].abs(), self.max_period_step))
    }
}

/// q_ref (x) Exp(theta) and its derivative (4x3).
fn qexp_about(qr: &Quat, theta: &[f64; 3]) -> (Quat, [[f64; 3]; 4]) {
    let (e, de) = qexp(theta);
    let l = lmat(qr);
    let d: [[f64; 3]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| l[i][k] * de[k][j]).sum()));
    (qmul(qr, &e), d)
}

/// The full-period closure rows (Log(q0* (x) qT), wT - w0), their Jacobian in (theta, w0) and
/// the 6x6 monodromy, from the end state and 13x13 STM (the same algebra as [`Form3d`]).
fn closure_rows(q0: &Quat, dq0: &[[f64; 3]; 4], w0: &[f64; 3], yt: &[f64], stm: &[f64]) -> Option<([f64; 6], [[f64; 6]; 6], [[f64; 6]; 6])> {
    if !(yt.iter().all(|v| v.is_finite()) && stm.iter().all(|v| v.is_finite())) {
        return None;
    }
    let qt: Quat = [yt[6], yt[7], yt[8], yt[9]];
    let phi = |i: usize, j: usize| stm[i * 13 + j];
    let mut delta = qmul(&conj(q0), &qt);
    let nd = delta.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if delta[3] < 0.0 { -1.0 } else { 1.0 } / nd;
    delta = delta.map(|v| v * sign);
    let (r, dlog) = qlog(&delta);
    let dqt: [[f64; 6]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| if j < 3 { (0..4).map(|k| phi(6 + i, 6 + k) * dq0[k][j]).sum() } else { phi(6 + i, 10 + j - 3) }));
    let dwt: [[f64; 6]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| if j < 3 { (0..4).map(|k| phi(10 + i, 6 + k) * dq0[k][j]).sum() } else { phi(10 + i, 10 + j - 3) }));
    let (rq, lc) = (rmat(&qt), lmat(&conj(q0)));
    let ddelta: [[f64; 6]; 4] = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let a: f64 = if j < 3 { (0..4).map(|k| rq[i][k] * if k < 3 { -dq0[k][j] } else { dq0[k][j] }).sum() } else { 0.0 };
            let b: f64 = (0..4).map(|k| lc[i][k] * dqt[k][j]).sum();
            sign * (a + b)
        })
    });
    let mut f = [0.0; 6];
    let mut jac = [[0.0; 6]; 6];
    for i in 0..3 {
        f[i] = r[i];
        f[3 + i] = yt[10 + i] - w0[i];
        for j in 0..6 {
            jac[i][j] = (0..4).map(|k| dlog[i][k] * ddelta[k][j]).sum();
            jac[3 + i][j] = dwt[i][j] - if j == 3 + i { 1.0 } else { 0.0 };
        }
    }
    let m13: [[f64; 13]; 13] = std::array::from_fn(|i| std::array::from_fn(|j| phi(i, j)));
    Some((f, jac, reduce(&m13, q0, &qt)))
}

/// The bordered 3-D correction across an x-z-symmetric orbit family (DROs, planar Lyapunov
/// orbits, halos and NRHOs): as [`correct_attitudes_3d`] (full period, K = `n_periods`), with the
/// orbit period T an unknown too, closed by each candidate's linear condition
/// a . (theta, w0, T) = b ([`StartAcross3d`]).
///
/// The family enters through each point's own member: at every Newton point, the orbit of
/// period T is corrected by symmetric shooting with the period fixed (from the first-order guess
/// along the family's tangent at the reference member `member0` of period `period0`) to 1e-12,
/// and the coupled model is integrated along it over K T. The column d F / d T is exact: the
/// 13x13 STM's orbit columns applied to the family's tangent d s0 / d T (from the shooting's
/// sensitivities: the crossing conditions xdot_c = zdot_c = 0 held and T = 2 t_half moved,
/// one 3x3 solve), plus the vector field at K T times K, through the same Log/Exp Jacobians as the
/// closure rows. So the reported solution's orbit is a family member corrected at the final T.
/// Each Newton step in T is capped at `max_period_step` (TU).
pub fn correct_attitudes_3d_across(
    mu: f64,
    body: RigidBody,
    member0: &[f64; 6],
    period0: f64,
    n_periods: usize,
    starts: &[StartAcross3d],
    max_period_step: f64,
    opts: &Options3d,
) -> Result<Vec<CorrectionAcross3d>> {
    check_mu(mu)?;
    RigidBody::new(body.ix, body.iy, body.iz)?;
    check_finite("orbit0", member0)?;
    check_positive("period", period0)?;
    check_positive("max_period_step", max_period_step)?;
    check_positive("tol", opts.tol)?;
    crate::integrate::check_tolerances(opts.rtol, opts.atol)?;
    if n_periods == 0 {
        return Err(invalid("n_periods", "must be >= 1"));
    }
    if opts.max_iter == 0 {
        return Err(invalid("max_iter", "must be >= 1"));
    }
    if opts.half {
        return Err(invalid("half", "the bordered correction across a family uses the full period"));
    }
    if opts.threads == Some(0) {
        return Err(invalid("threads", "must be >= 1 (or None for all cores)"));
    }
    for (i, s) in starts.iter().enumerate() {
        if !(s.q.iter().all(|v| v.is_finite()) && s.w.iter().all(|v| v.is_finite()) && s.a.iter().all(|v| v.is_finite()) && s.b.is_finite()) {
            return Err(invalid("guess", format!("start {i}: q, w, a and b must be finite")));
        }
        if !(s.period.is_finite() && s.period > 0.0) {
            return Err(invalid("period", format!("start {i}: must be finite and > 0, got {}", s.period)));
        }
        if s.a.iter().all(|&v| v == 0.0) {
            return Err(invalid("a", format!("start {i}: the linear condition needs a non-zero row")));
        }
        let n = s.q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-9 {
            return Err(invalid("guess", format!("start {i}: q must be a unit quaternion (scalar last), |q| = {n}")));
        }
    }
    let starts: Vec<StartAcross3d> = starts.iter().map(|s| StartAcross3d { q: s.q.map(|v| v / s.q.iter().map(|u| u * u).sum::<f64>().sqrt()), ..*s }).collect();
    let family = SymmetricFamily::new(mu, member0, period0, opts.rtol, opts.atol)?;
    let form = FormAcross { starts: &starts, opts: *opts, max_period_step };
    let gg = GravityGradient { primaries: opts.primaries };
    let integ = Options::with_tolerances(opts.rtol, opts.atol);
    let k = n_periods as f64;
    let one = |(y, t): &(Traj, f64)| -> OutAcross {
        let (orbit, ds0) = family.member(*t)?;
        let mut s = *y;
        s[..6].copy_from_slice(&orbit.state0);
        let torques: [&dyn Torque; 1] = [&gg];
        let tf = k * orbit.period;
        let r = propagate_attitude(mu, body, &torques, OrbitMode::Integrate, &s, 0.0, tf, &integ, true, Output::Final, None, None).ok()?;
        let yt: [f64; 13] = r.states[r.states.len() - 13..].try_into().ok()?;
        let stm = r.stm_final?;
        let model = Coupled { mu, body, torques: vec![&gg], orbit: OrbitMode::Integrate, orbit_srp: None };
        let mut f = [0.0; 13];
        model.derivative(tf, &yt, &mut f);
        let dydt: [f64; 13] = std::array::from_fn(|i| (0..6).map(|j| stm[i * 13 + j] * ds0[j]).sum::<f64>() + k * f[i]);
        Some((yt.to_vec(), stm, dydt, orbit.state0, orbit.period))
    };
    let settings = Settings { tol: opts.tol, max_iter: opts.max_iter, max_halvings: opts.max_halvings, group: 1, max_contraction: f64::INFINITY };
    let cands: Vec<usize> = (0..starts.len()).collect();
    let tracks = with_threads_rounds(opts.threads, || newton::solve(&form, &cands, &settings, &|b: &[(Traj, f64)]| Ok(b.par_iter().map(one).collect())))??;
    // the member at each final point (cheap: one symmetric shooting, no attitude integration)
    let members: Vec<Option<SymmetricOrbit>> = with_threads(opts.threads, || tracks.par_iter().map(|t| t.cur.as_ref().and_then(|p| family.member(p.x[6])).map(|m| m.0)).collect())?;
    Ok(tracks
        .iter()
        .zip(members)
        .enumerate()
        .map(|(c, (t, m))| {
            let x = t.x();
            let (q0, _) = qexp_about(&starts[c].q, &[x[0], x[1], x[2]]);
            let p = t.cur.as_ref();
            let keep = p.map(|p| p.keep.as_slice()).filter(|k| k.len() == 42);
            CorrectionAcross3d {
                q0,
                w0: [x[3], x[4], x[5]],
                orbit0: m.as_ref().map_or([f64::NAN; 6], |m| m.state0),
                period: m.as_ref().map_or(f64::NAN, |m| m.period),
                residual: p.map_or([f64::NAN; 7], |p| p.f),
                residual_norm: p.map_or(f64::NAN, |p| p.norm),
                iterations: t.iterations,
                reason: t.reason(),
                monodromy: keep.map_or([[f64::NAN; 6]; 6], |k| std::array::from_fn(|i| std::array::from_fn(|j| k[6 * i + j]))),
                dparam: keep.map_or([f64::NAN; 6], |k| std::array::from_fn(|i| k[36 + i])),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_log_and_their_derivatives() {
        let t = [0.3, -0.2, 0.7];
        let (q, d) = qexp(&t);
        let (r, dl) = qlog(&q);
        for i in 0..3 {
            assert!((r[i] - t[i]).abs() < 1e-14);
        }
        let h = 1e-6;
        for j in 0..3 {
            let mut tp = t;
            let mut tm = t;
            tp[j] += h;
            tm[j] -= h;
            let (qp, _) = qexp(&tp);
            let (qm, _) = qexp(&tm);
            for i in 0..4 {
                assert!(((qp[i] - qm[i]) / (2.0 * h) - d[i][j]).abs() < 1e-9);
            }
            // Log o Exp = identity: dlog * dexp = I
            for (i, row) in dl.iter().enumerate() {
                let v: f64 = (0..4).map(|k| row[k] * d[k][j]).sum();
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
        // near zero (series branches)
        let (q, d) = qexp(&[1e-9, 0.0, -2e-9]);
        assert!((q[3] - 1.0).abs() < 1e-15 && (d[0][0] - 0.5).abs() < 1e-15);
        let (r, dl) = qlog(&q);
        assert!((r[0] - 1e-9).abs() < 1e-22 && (dl[0][0] - 2.0).abs() < 1e-12);
    }

    /// The torque-free sphere (no gravity-gradient torque for equal moments): from a tilted
    /// guess the corrector finds a spin (1 + 2 pi N / T) e_Z (inertial) in a few steps, and the
    /// monodromy is expm([[-[w x] T, T I], [0, 0]]) to 1e-10 (docs/physics/periodic-attitude-3d.md).
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn torque_free_sphere_monodromy_is_the_closed_form() {
        use nalgebra::DMatrix;
        let mu = 0.012150585609624;
        let body = RigidBody::new(1.0, 1.0, 1.0).unwrap();
        let t = 2.5;
        let wz = 1.0 - 2.0 * std::f64::consts::PI / t;
        let (q, _) = qexp(&[0.1, -0.05, 0.2]);
        let a = crate::attitude::dcm(&q);
        let w: [f64; 3] = std::array::from_fn(|i| a[i][2] * wz + if i == 0 { 1e-3 } else { 0.0 });
        let out = correct_attitudes_3d(mu, body, &[0.8, 0.0, 0.0, 0.0, 0.5, 0.0], t, &[Start3d { q, w }], &Options3d::default()).unwrap();
        let c = &out[0];
        assert_eq!(c.reason, StopReason::Converged, "{c:?}");
        let w = c.w0;
        let mut m = DMatrix::<f64>::zeros(6, 6);
        let wx = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]];
        for i in 0..3 {
            for j in 0..3 {
                m[(i, j)] = -wx[i][j] * t;
            }
            m[(i, 3 + i)] = t;
        }
        let e = m.exp();
        for i in 0..6 {
            for j in 0..6 {
                assert!((e[(i, j)] - c.monodromy[i][j]).abs() < 1e-10, "({i}, {j}): {} vs {}", c.monodromy[i][j], e[(i, j)]);
            }
        }
        // the converged spin is inertial-Z: A(q0)' w0 = wz e_Z
        let a = crate::attitude::dcm(&c.q0);
        for k in 0..3 {
            let v: f64 = (0..3).map(|i| a[i][k] * w[i]).sum();
            assert!((v - if k == 2 { wz } else { 0.0 }).abs() < 1e-12);
        }
    }

    /// The bordered correction across the DRO family (earth-moon; the body of Kz = 0.8, the
    /// N = 1 motion at T = 25.49 d, unstable in the plane): with the period fixed it converges
    /// back onto the plain solution (1e-10), and its exact d F / d T gives the family's
    /// derivative d(theta, w0)/dT = -(M - I)^-1 dF/dT, which matches central differences of
    /// plain corrections on the members at T +- h (relative 1e-6; h = 1e-4 TU: O(h^2) ~ 1e-8).
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn bordered_derivative_matches_central_differences_of_plain_corrections() {
        use nalgebra::{Matrix6, Vector6};
        let mu = 0.012150585609624;
        let body = RigidBody::new(0.1, 0.9, 1.0).unwrap();
        let opts = Options3d::default();
        // the DRO of x0 = 0.5385 and its period, from symmetric shooting with x0 fixed
        let mut sh = SymmetricShooting::new(mu, false, Options::with_tolerances(1e-13, 1e-13));
        sh.tol = 1e-12;
        let dro = sh.correct([0.5385453306274934, 0.0, 0.6], SymConstraint::Fix(crate::orbit::Var::X0, 0.5385453306274934)).unwrap();
        let t0 = dro.period;
        let start = Start3d { q: [0.0, 0.0, 0.0, 1.0], w: [0.0, 0.0, 3.9254597] };
        let plain = &correct_attitudes_3d(mu, body, &dro.state0, t0, &[start], &opts).unwrap()[0];
        assert_eq!(plain.reason, StopReason::Converged);
        let tilted = Start3d { q: qexp(&[1e-4, -2e-4, 3e-4]).0, w: [1e-4, 1e-4, plain.w0[2] + 1e-3] };
        let mut a = [0.0; 7];
        a[6] = 1.0;
        let across = StartAcross3d { q: tilted.q, w: tilted.w, period: t0, a, b: t0 };
        let b = &correct_attitudes_3d_across(mu, body, &dro.state0, t0, 1, &[across], 0.5, &opts).unwrap()[0];
        assert_eq!(b.reason, StopReason::Converged, "{b:?}");
        assert!((b.period - t0).abs() < 1e-12);
        for k in 0..3 {
            assert!((b.w0[k] - plain.w0[k]).abs() < 1e-10, "{:?} vs {:?}", b.w0, plain.w0);
        }
        let (dq, _) = qlog(&qmul(&conj(&plain.q0), &b.q0));
        assert!(dq.iter().all(|v| v.abs() < 1e-10), "{dq:?}");
        // predicted d(theta, w0)/dT in the solution's body-axis chart
        let m = Matrix6::from_fn(|i, j| b.monodromy[i][j]) - Matrix6::identity();
        let pred = -m.lu().solve(&Vector6::from_fn(|i, _| b.dparam[i])).unwrap();
        let h = 1e-4;
        let family = SymmetricFamily::new(mu, &dro.state0, t0, 1e-13, 1e-13).unwrap();
        let side = |t: f64| {
            let (o, _) = family.member(t).unwrap();
            let c = correct_attitudes_3d(mu, body, &o.state0, o.period, &[Start3d { q: b.q0, w: b.w0 }], &opts).unwrap()[0].clone();
            assert_eq!(c.reason, StopReason::Converged);
            let (th, _) = qlog(&qmul(&conj(&b.q0), &c.q0));
            (o.period, [th[0], th[1], th[2], c.w0[0], c.w0[1], c.w0[2]])
        };
        let ((tp, xp), (tm, xm)) = (side(t0 + h), side(t0 - h));
        let scale = pred.amax();
        for i in 0..6 {
            let fd = (xp[i] - xm[i]) / (tp - tm);
            assert!((fd - pred[i]).abs() <= 1e-6 * scale, "component {i}: {fd} vs {}", pred[i]);
        }
    }

    /// Invalid arguments of the bordered corrector are errors naming the parameter, never panics.
    #[test]
    fn bordered_invalid_arguments() {
        let mu = 0.012150585609624;
        let body = RigidBody::new(0.1, 0.9, 1.0).unwrap();
        let dro = [0.8, 0.0, 0.0, 0.0, 0.5, 0.0];
        let mut a = [0.0; 7];
        a[6] = 1.0;
        let ok = StartAcross3d { q: [0.0, 0.0, 0.0, 1.0], w: [0.0, 0.0, 1.0], period: 3.0, a, b: 3.0 };
        let run = |m: &[f64; 6], s: StartAcross3d, o: Options3d| correct_attitudes_3d_across(mu, body, m, 3.0, 1, &[s], 0.5, &o).unwrap_err().to_string();
        assert!(run(&[0.8, 0.1, 0.0, 0.0, 0.5, 0.0], ok, Options3d::default()).contains("orbit0"));
        assert!(run(&dro, StartAcross3d { a: [0.0; 7], ..ok }, Options3d::default()).contains("`a`"));
        assert!(run(&dro, StartAcross3d { period: -1.0, ..ok }, Options3d::default()).contains("period"));
        assert!(run(&dro, ok, Options3d { half: true, ..Options3d::default() }).contains("half"));
        assert!(correct_attitudes_3d_across(mu, body, &dro, 3.0, 0, &[ok], 0.5, &Options3d::default()).unwrap_err().to_string().contains("n_periods"));
    }
}
