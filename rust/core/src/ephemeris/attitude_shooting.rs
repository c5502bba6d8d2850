//! Multiple shooting of the attitude along an ephemeris orbit ([`super::attitude`]): from
//! attitude nodes at fixed epochs (the orbit's node states given, e.g. a corrected ephemeris
//! orbit), find the node attitudes (q_i, w_i) for which the motion is continuous.
//!
//! Unknowns x = (theta_i, u_i) per node: theta_i (3) a rotation in body axes in a chart about
//! the node's starting guess g_i, q_i = g_i (x) Exp(theta_i), and u_i = w_i / omega_ref (3),
//! the rate in units of omega_ref (the Earth-Moon line's rotation rate at the first node) so
//! that both halves of x are of order one.
//! Constraints per leg i -> i+1 (6): Log(q_{i+1}* (x) q_i(t_{i+1})), the rotation vector of
//! R(q_{i+1})' R(q_i(t_{i+1})) in body axes (rad), and (w_i(t_{i+1}) - w_{i+1}) / omega_ref.
//! With n nodes there are 6n unknowns and 6(n - 1) equations: the project's Newton driver
//! ([`crate::newton`]) takes minimum-norm steps, so the solution is the continuous motion
//! nearest (to first order) the starting guess, the placed CR3BP motion. The Jacobian is exact:
//! the 7x7 attitude STM of each leg ([`propagate_attitude_batch`], dual numbers) through the
//! closed-form derivatives of Exp and Log ([`qexp`], [`qlog`]); the legs run on rayon.
//!
//! The span's attitude monodromy is the product of the legs' STMs in the chart coordinates
//! (theta, w) ([`crate::attitude::linear`]): d(theta, w)(t_end) / d(theta, w)(t_0) of the
//! corrected motion.

use nalgebra::{DMatrix, DVector};

use super::attitude::{propagate_attitude_batch, AttitudeModel, Leg, Quat, ATT, DIM};
use crate::attitude::linear::xi;
use crate::attitude::{conj, lmat, qexp, qlog, qmul, rmat};
use crate::error::{check_finite, invalid, Result};
use crate::integrate::Options;
use crate::newton::{self, Problem, Settings, StopReason};

/// One attitude node: epoch (TDB s), the orbit state there (km, km/s, Moon-centred ICRF), the
/// attitude guess (q body -> ICRF, w rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    pub epoch: f64,
    pub orbit: [f64; 6],
    pub q: Quat,
    pub w: [f64; 3],
}

/// Settings of [`correct_attitude`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShootingOptions {
    /// Stop when the largest defect (rad, and rate / omega_ref) is <= tol.
    pub tol: f64,
    pub max_iter: usize,
    /// Integration tolerances of the legs.
    pub integration: Options,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        Self { tol: 1e-9, max_iter: 30, integration: super::attitude::default_options() }
    }
}

/// The outcome of [`correct_attitude`] (or of [`evaluate_attitude_legs`] for given nodes).
#[derive(Debug, Clone)]
pub struct Shooting {
    pub q: Vec<Quat>,
    pub w: Vec<[f64; 3]>,
    /// Per leg: the rotation vector (rad, body axes of node i+1) of R(q_{i+1})' R(q_i(t_{i+1}))
    /// and w_i(t_{i+1}) - w_{i+1} (rad/s).
    pub defects: Vec<[f64; 6]>,
    /// d(theta, w)(t_end) / d(theta, w)(t_0) over the span (chart coordinates, rad and rad/s).
    pub monodromy: [[f64; 6]; 6],
    pub iterations: usize,
    /// The driver's stop reason ("converged" when it converged).
    pub reason: String,
    pub converged: bool,
}

fn check_nodes(model: &AttitudeModel, nodes: &[Node]) -> Result<()> {
    if nodes.len() < 2 {
        return Err(invalid("epochs", format!("at least two attitude nodes are needed, got {}", nodes.len())));
    }
    for (i, n) in nodes.iter().enumerate() {
        check_finite("orbit", &n.orbit)?;
        check_finite("q", &n.q)?;
        check_finite("w", &n.w)?;
        model.eph.check_epoch("epochs", n.epoch)?;
        let qn = n.q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (qn - 1.0).abs() > 1e-6 {
            return Err(invalid("q", format!("node {i}: must be a unit quaternion (scalar last), |q| = {qn}")));
        }
        if i > 0 && n.epoch <= nodes[i - 1].epoch {
            return Err(invalid("epochs", format!("must increase: node {i} at {} follows {}", n.epoch, nodes[i - 1].epoch)));
        }
    }
    Ok(())
}

/// q_ref (x) Exp(theta) and its derivative (4x3).
fn qexp_about(qr: &Quat, theta: &[f64; 3]) -> (Quat, [[f64; 3]; 4]) {
    let (e, de) = qexp(theta);
    let l = lmat(qr);
    let d = std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| l[i][k] * de[k][j]).sum::<f64>()));
    (qmul(qr, &e), d)
}

/// The attitudes at the unknowns x.
struct Point {
    q: Vec<Quat>,
    dq: Vec<[[f64; 3]; 4]>,
    w: Vec<[f64; 3]>,
}

fn point(nodes: &[Node], x: &[f64], omega_ref: f64) -> Point {
    let mut p = Point { q: Vec::with_capacity(nodes.len()), dq: Vec::with_capacity(nodes.len()), w: Vec::with_capacity(nodes.len()) };
    for (i, n) in nodes.iter().enumerate() {
        let (q, dq) = qexp_about(&n.q, &[x[6 * i], x[6 * i + 1], x[6 * i + 2]]);
        p.q.push(q);
        p.dq.push(dq);
        p.w.push([x[6 * i + 3] * omega_ref, x[6 * i + 4] * omega_ref, x[6 * i + 5] * omega_ref]);
    }
    p
}

/// One leg's end state and STM.
type LegEnd = ([f64; DIM], [[f64; ATT]; ATT]);

fn integrate_legs(model: &AttitudeModel, nodes: &[Node], p: &Point, opts: &Options) -> Result<Vec<LegEnd>> {
    let legs: Vec<Leg> = (0..nodes.len() - 1)
        .map(|i| {
            let mut s = [0.0; DIM];
            s[..6].copy_from_slice(&nodes[i].orbit);
            s[6..10].copy_from_slice(&p.q[i]);
            s[10..].copy_from_slice(&p.w[i]);
            (nodes[i].epoch, s, nodes[i + 1].epoch - nodes[i].epoch)
        })
        .collect();
    propagate_attitude_batch(model, &legs, true, opts)
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            let tr = r?;
            let phi = tr.stm.ok_or_else(|| invalid("nodes", format!("attitude leg {i}: no STM")))?;
            Ok((tr.state_final, phi))
        })
        .collect()
}

/// Rows of leg i: residual (6, scaled), d/dx_from (6x6), d/dx_to (6x6).
fn link(p: &Point, i: usize, end: &LegEnd, omega_ref: f64) -> ([f64; 6], [[f64; 6]; 6], [[f64; 6]; 6]) {
    let (yf, phi) = end;
    let qf: Quat = [yf[6], yf[7], yf[8], yf[9]];
    let (q_to, dq_to, w_to) = (&p.q[i + 1], &p.dq[i + 1], &p.w[i + 1]);
    let dq_from = &p.dq[i];
    let mut delta = qmul(&conj(q_to), &qf);
    let nd = delta.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if delta[3] < 0.0 { -1.0 } else { 1.0 } / nd;
    delta = delta.map(|v| v * sign);
    let (r, dlog) = qlog(&delta);
    // d(qf, wf) / d(theta_i, u_i): the STM through the chart.
    let dend: [[f64; 6]; ATT] = std::array::from_fn(|a| std::array::from_fn(|j| if j < 3 { (0..4).map(|k| phi[a][k] * dq_from[k][j]).sum::<f64>() } else { phi[a][4 + j - 3] * omega_ref }));
    let (lc, rq) = (lmat(&conj(q_to)), rmat(&qf));
    let mut f = [0.0; 6];
    let mut jf = [[0.0; 6]; 6];
    let mut jt = [[0.0; 6]; 6];
    let dd_from: [[f64; 6]; 4] = std::array::from_fn(|a| std::array::from_fn(|j| sign * (0..4).map(|k| lc[a][k] * dend[k][j]).sum::<f64>()));
    let dd_to: [[f64; 3]; 4] = std::array::from_fn(|a| std::array::from_fn(|j| sign * (0..4).map(|k| rq[a][k] * if k < 3 { -dq_to[k][j] } else { dq_to[k][j] }).sum::<f64>()));
    for a in 0..3 {
        f[a] = r[a];
        f[3 + a] = (yf[10 + a] - w_to[a]) / omega_ref;
        for j in 0..6 {
            jf[a][j] = (0..4).map(|k| dlog[a][k] * dd_from[k][j]).sum();
            jf[3 + a][j] = dend[4 + a][j] / omega_ref;
        }
        for j in 0..3 {
            jt[a][j] = (0..4).map(|k| dlog[a][k] * dd_to[k][j]).sum();
        }
        jt[3 + a][3 + a] = -1.0;
    }
    (f, jf, jt)
}

/// The leg's 7x7 STM in chart coordinates (theta, w): P(q_end) Phi E(q_start).
fn reduced(phi: &[[f64; ATT]; ATT], q0: &Quat, qf: &Quat) -> [[f64; 6]; 6] {
    let (x0, xf) = (xi(q0), xi(qf));
    let n2: f64 = qf.iter().map(|v| v * v).sum();
    // E: 7x6, P: 6x7
    let e = |k: usize, j: usize| -> f64 {
        match (k < 4, j < 3) {
            (true, true) => 0.5 * x0[k][j],
            (false, false) => f64::from(u8::from(k - 4 == j - 3)),
            _ => 0.0,
        }
    };
    let pm = |i: usize, k: usize| -> f64 {
        match (i < 3, k < 4) {
            (true, true) => 2.0 * xf[k][i] / n2,
            (false, false) => f64::from(u8::from(i - 3 == k - 4)),
            _ => 0.0,
        }
    };
    let me: [[f64; 6]; ATT] = std::array::from_fn(|k| std::array::from_fn(|j| (0..ATT).map(|l| phi[k][l] * e(l, j)).sum()));
    std::array::from_fn(|i| std::array::from_fn(|j| (0..ATT).map(|k| pm(i, k) * me[k][j]).sum()))
}

fn matmul6(a: &[[f64; 6]; 6], b: &[[f64; 6]; 6]) -> [[f64; 6]; 6] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..6).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The defects (rad, rad/s) and the span monodromy of the motion through the nodes' attitudes
/// as given (no correction), e.g. of a placed guess or a corrected motion.
pub fn evaluate_attitude_legs(model: &AttitudeModel, nodes: &[Node], opts: &Options) -> Result<Shooting> {
    check_nodes(model, nodes)?;
    let omega_ref = 1.0;
    let x: Vec<f64> = nodes.iter().flat_map(|n| [0.0, 0.0, 0.0, n.w[0], n.w[1], n.w[2]]).collect();
    let p = point(nodes, &x, omega_ref);
    finish(model, nodes, &p, opts, 0, "not corrected".into(), false)
}

fn finish(model: &AttitudeModel, nodes: &[Node], p: &Point, opts: &Options, iterations: usize, reason: String, converged: bool) -> Result<Shooting> {
    let ends = integrate_legs(model, nodes, p, opts)?;
    let mut defects = Vec::with_capacity(ends.len());
    let mut mono = [[0.0; 6]; 6];
    for (k, row) in mono.iter_mut().enumerate() {
        row[k] = 1.0;
    }
    for (i, end) in ends.iter().enumerate() {
        let (f, _, _) = link(p, i, end, 1.0);
        defects.push(f);
        let qf = [end.0[6], end.0[7], end.0[8], end.0[9]];
        mono = matmul6(&reduced(&end.1, &p.q[i], &qf), &mono);
    }
    Ok(Shooting { q: p.q.clone(), w: p.w.clone(), defects, monodromy: mono, iterations, reason, converged })
}

/// The multiple-shooting problem for the driver: the residual and, from the same legs, the
/// Jacobian.
struct Legs<'a> {
    model: &'a AttitudeModel,
    nodes: &'a [Node],
    omega_ref: f64,
    opts: Options,
    jac: Option<DMatrix<f64>>,
}

impl Legs<'_> {
    fn residual_and_jacobian(&self, x: &DVector<f64>) -> Result<(DVector<f64>, DMatrix<f64>)> {
        let n = self.nodes.len();
        let p = point(self.nodes, x.as_slice(), self.omega_ref);
        let ends = integrate_legs(self.model, self.nodes, &p, &self.opts)?;
        let mut f = DVector::zeros(6 * (n - 1));
        let mut jac = DMatrix::zeros(6 * (n - 1), 6 * n);
        for (i, end) in ends.iter().enumerate() {
            let (fi, jf, jt) = link(&p, i, end, self.omega_ref);
            for a in 0..6 {
                f[6 * i + a] = fi[a];
                for b in 0..6 {
                    jac[(6 * i + a, 6 * i + b)] = jf[a][b];
                    jac[(6 * i + a, 6 * (i + 1) + b)] = jt[a][b];
                }
            }
        }
        Ok((f, jac))
    }
}

impl Problem for Legs<'_> {
    fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
        let (f, j) = self.residual_and_jacobian(x)?;
        self.jac = Some(j);
        Ok(f)
    }
    fn jacobian(&mut self, _: &DVector<f64>) -> Result<DMatrix<f64>> {
        self.jac.clone().ok_or_else(|| invalid("x", "no residual evaluated"))
    }
}

/// Correct the attitude through `nodes` (their q, w the starting guess, e.g. the placed CR3BP
/// motion) into a continuous motion by multiple shooting (module docs), with the project's
/// Newton driver (minimum-norm steps, backtracking). A stop that is not a convergence is
/// returned with its reason (`reason`, `converged`) and the last accepted point; an error only
/// for invalid input or a guess whose legs cannot be integrated.
pub fn correct_attitude(model: &AttitudeModel, nodes: &[Node], opts: &ShootingOptions) -> Result<Shooting> {
    check_nodes(model, nodes)?;
    opts.integration.validate()?;
    let frame = super::frame::RotatingFrame::at(&model.eph, nodes[0].epoch)?;
    let omega_ref = frame.rate_rad_s;
    let x0 = DVector::from_iterator(6 * nodes.len(), nodes.iter().flat_map(|nd| [0.0, 0.0, 0.0, nd.w[0] / omega_ref, nd.w[1] / omega_ref, nd.w[2] / omega_ref]));
    let mut problem = Legs { model, nodes, omega_ref, opts: opts.integration, jac: None };
    let settings = Settings { tol: opts.tol, max_iter: opts.max_iter, max_halvings: 10 };
    let out = newton::solve(&mut problem, x0, &settings)?;
    let p = point(nodes, out.x.as_slice(), omega_ref);
    finish(model, nodes, &p, &opts.integration, out.iterations, out.reason.as_str().to_string(), out.reason == StopReason::Converged)
}
