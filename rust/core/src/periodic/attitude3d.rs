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
//! Newton runs on the one batched driver ([`super::newton`]); each iteration integrates the
//! pending points of every candidate in parallel (rayon). The 6x6 attitude monodromy is the
//! STM in the coordinates (theta, dw) of [`crate::attitude::linear`].

use rayon::prelude::*;

use super::newton::{self, Eval, Problem, Settings, StopReason};
use crate::attitude::linear::reduce;
use crate::attitude::{propagate_attitude, GravityGradient, OrbitMode, RigidBody, Torque};
use crate::cr3bp::check_mu;
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::integrate::{Options, Output};
use crate::propagation::with_threads;

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

fn conj(q: &Quat) -> Quat {
    [-q[0], -q[1], -q[2], q[3]]
}

/// The 4x4 matrices of p (x) q = L(p) q = R(q) p.
fn lmat(p: &Quat) -> [[f64; 4]; 4] {
    let [a1, a2, a3, a4] = *p;
    [[a4, -a3, a2, a1], [a3, a4, -a1, a2], [-a2, a1, a4, a3], [-a1, -a2, -a3, a4]]
}

fn rmat(q: &Quat) -> [[f64; 4]; 4] {
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
    let settings = Settings { tol: opts.tol, max_iter: opts.max_iter, max_halvings: opts.max_halvings };
    let cands: Vec<usize> = (0..starts.len()).collect();
    let (tracks, full) = with_threads(opts.threads, || -> Result<_> {
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
}
