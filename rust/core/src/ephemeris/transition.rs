//! The transition of an orbit to the ephemeris model by multiple shooting.
//!
//! Nodes k = 0..n (n legs) carry a Moon-centred ICRF state X_k (km, km/s) and an epoch t_k (TDB
//! s). Leg i runs from (X_i, t_i) to t_{i+1} under [`EphemerisDynamics`]; the conditions are the
//! full-state continuity at every interior junction, F_i = phi(t_{i+1}; t_i, X_i) - X_{i+1} = 0
//! (6 n equations). The unknowns are every node state and every node epoch but the first, whose
//! epoch is fixed unless `epoch_free` (7 (n + 1) - 1 or 7 (n + 1) unknowns): the system is
//! underdetermined and each Newton step is the minimum-norm one ([`crate::newton`]), which keeps
//! the solution near the guess (a CR3BP orbit placed at the epoch).
//!
//! Partials of leg i (Phi its STM, f the right-hand side): d F_i / d X_i = Phi,
//! d F_i / d X_{i+1} = -I, d F_i / d t_{i+1} = f(X_f, t_{i+1}),
//! d F_i / d t_i = -Phi f(X_i, t_i) (the flow's dependence on its initial time).
//!
//! Scaling: positions by `length_km`, velocities by `length_km / time_s`, epochs by `time_s` (the
//! CR3BP units: the minimum norm is measured in them); the continuity rows by `tol_km` and
//! `tol_km_s` so that one tolerance serves both (the leg's 2-norm defects).

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::chebyshev::Ephemeris;
use super::dynamics::{propagate_ephemeris, EphemerisDynamics};
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::integrate::{Options, System};
use crate::newton::{self, Problem, Settings, StopReason};

/// Settings of a transition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransitionSettings {
    /// Continuity tolerances of every leg (2-norms): position (km) and velocity (km/s).
    pub tol_km: f64,
    pub tol_km_s: f64,
    pub max_iter: usize,
    /// The first node's epoch is an unknown too.
    pub epoch_free: bool,
    /// The scales of the unknowns: length (km) and time (s).
    pub length_km: f64,
    pub time_s: f64,
}

impl TransitionSettings {
    fn validate(&self) -> Result<()> {
        check_positive("tol_km", self.tol_km)?;
        check_positive("tol_km_s", self.tol_km_s)?;
        check_positive("length_km", self.length_km)?;
        check_positive("time_s", self.time_s)?;
        if self.max_iter == 0 || self.max_iter > 1000 {
            return Err(invalid("max_iter", format!("must be in 1..=1000, got {}", self.max_iter)));
        }
        Ok(())
    }
}

/// A converged (or stopped) transition.
#[derive(Debug, Clone)]
pub struct Transition {
    /// Node states (km, km/s) and epochs (TDB s), the last node included.
    pub states: Vec<[f64; 6]>,
    pub epochs: Vec<f64>,
    pub iterations: usize,
    pub reason: StopReason,
    /// Per leg: |position defect| (km) and |velocity defect| (km/s) at the end.
    pub defects_km: Vec<f64>,
    pub defects_km_s: Vec<f64>,
    /// Max-norm of the scaled conditions at the start and after each step (1 = the tolerance).
    pub history: Vec<f64>,
}

struct Legs<'a> {
    eph: &'a Ephemeris,
    gm: [f64; 3],
    opts: &'a Options,
    n_nodes: usize,
    epoch_free: bool,
    /// The epochs of the guess: t_k = t_ref[k] + time_s u_k.
    t_ref: Vec<f64>,
    l: f64,
    v: f64,
    t: f64,
    /// Row scales: position, velocity.
    rp: f64,
    rv: f64,
    jac: Option<DMatrix<f64>>,
}

/// One leg's outcome: the final state, the STM, f at the start and at the end.
type Leg = ([f64; 6], [f64; 36], [f64; 6], [f64; 6]);

impl Legs<'_> {
    fn n_unknowns(&self) -> usize {
        7 * self.n_nodes - usize::from(!self.epoch_free)
    }
    /// Column of node k's epoch (None: fixed).
    fn epoch_col(&self, k: usize) -> Option<usize> {
        let base = 6 * self.n_nodes;
        match (self.epoch_free, k) {
            (false, 0) => None,
            (false, k) => Some(base + k - 1),
            (true, k) => Some(base + k),
        }
    }
    fn node(&self, x: &DVector<f64>, k: usize) -> ([f64; 6], f64) {
        let s = std::array::from_fn(|a| x[6 * k + a] * if a < 3 { self.l } else { self.v });
        let t = self.t_ref[k] + self.epoch_col(k).map_or(0.0, |c| self.t * x[c]);
        (s, t)
    }
    fn unknowns(&self, states: &[[f64; 6]]) -> DVector<f64> {
        DVector::from_fn(self.n_unknowns(), |c, _| if c < 6 * self.n_nodes { states[c / 6][c % 6] / if c % 6 < 3 { self.l } else { self.v } } else { 0.0 })
    }
    fn legs(&self, x: &DVector<f64>) -> Result<Vec<Leg>> {
        let n = self.n_nodes - 1;
        for i in 0..n {
            let (t0, t1) = (self.node(x, i).1, self.node(x, i + 1).1);
            if !(t1 > t0) {
                return Err(invalid("epochs", format!("the epochs of nodes {i} and {} no longer increase ({t0} and {t1} TDB s)", i + 1)));
            }
        }
        (0..n)
            .into_par_iter()
            .map(|i| {
                let (s0, t0) = self.node(x, i);
                let t1 = self.node(x, i + 1).1;
                let dynamics = EphemerisDynamics::with_gm(self.eph.clone(), t0, self.gm)?;
                let tr = propagate_ephemeris(&dynamics, &s0, t1 - t0, true, Some(&[t1 - t0]), self.opts)?;
                let (mut f0, mut f1) = ([0.0; 6], [0.0; 6]);
                dynamics.derivative(0.0, &s0, &mut f0);
                dynamics.derivative(t1 - t0, &tr.state_final, &mut f1);
                Ok((tr.state_final, tr.stm.expect("with STM"), f0, f1))
            })
            .collect()
    }
    fn row_scale(&self, a: usize) -> f64 {
        if a < 3 {
            self.rp
        } else {
            self.rv
        }
    }
    fn residual_and_jacobian(&self, x: &DVector<f64>) -> Result<(DVector<f64>, DMatrix<f64>)> {
        let legs = self.legs(x)?;
        let n = legs.len();
        let mut r = DVector::zeros(6 * n);
        let mut j = DMatrix::zeros(6 * n, self.n_unknowns());
        // unknown scales of a state column
        let cs = |b: usize| if b < 3 { self.l } else { self.v };
        for (i, (xf, phi, f0, f1)) in legs.iter().enumerate() {
            let next = self.node(x, i + 1).0;
            for a in 0..6 {
                let w = 1.0 / self.row_scale(a);
                r[6 * i + a] = (xf[a] - next[a]) * w;
                for b in 0..6 {
                    j[(6 * i + a, 6 * i + b)] = phi[6 * a + b] * cs(b) * w;
                }
                j[(6 * i + a, 6 * (i + 1) + a)] = -cs(a) * w;
                if let Some(c) = self.epoch_col(i) {
                    let pf: f64 = (0..6).map(|b| phi[6 * a + b] * f0[b]).sum();
                    j[(6 * i + a, c)] = -pf * self.t * w;
                }
                if let Some(c) = self.epoch_col(i + 1) {
                    j[(6 * i + a, c)] = f1[a] * self.t * w;
                }
            }
        }
        Ok((r, j))
    }
}

impl Problem for Legs<'_> {
    fn residual(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
        let (r, j) = self.residual_and_jacobian(x)?;
        self.jac = Some(j);
        Ok(r)
    }
    fn jacobian(&mut self, _: &DVector<f64>) -> Result<DMatrix<f64>> {
        self.jac.clone().ok_or_else(|| invalid("x", "no residual evaluated"))
    }
}

/// Correct the guess `states`/`epochs` (n + 1 >= 2 nodes, increasing epochs) into a continuous
/// trajectory of the ephemeris model (see the module documentation). Stops that are not a
/// convergence are returned with their reason; an error only for invalid input or a guess whose
/// legs cannot be integrated.
pub fn transition(eph: &Ephemeris, gm: [f64; 3], states: &[[f64; 6]], epochs: &[f64], settings: &TransitionSettings, opts: &Options) -> Result<Transition> {
    settings.validate()?;
    opts.validate()?;
    if states.len() < 2 || states.len() != epochs.len() {
        return Err(invalid("states", format!("need at least 2 nodes and one epoch per node, got {} states and {} epochs", states.len(), epochs.len())));
    }
    for s in states {
        check_finite("states", s)?;
    }
    check_finite("epochs", epochs)?;
    for (k, w) in epochs.windows(2).enumerate() {
        if !(w[1] > w[0]) {
            return Err(invalid("epochs", format!("must increase, got {} then {} at node {k}", w[0], w[1])));
        }
    }
    eph.check_epoch("epochs[0]", epochs[0])?;
    eph.check_epoch("epochs[-1]", epochs[epochs.len() - 1])?;
    let (l, t) = (settings.length_km, settings.time_s);
    let v = l / t;
    // rows: position / l, velocity / (tol_km_s l / tol_km): both tolerances become tol_km / l
    let mut problem = Legs {
        eph,
        gm,
        opts,
        n_nodes: states.len(),
        epoch_free: settings.epoch_free,
        t_ref: epochs.to_vec(),
        l,
        v,
        t,
        rp: l,
        rv: settings.tol_km_s * l / settings.tol_km,
        jac: None,
    };
    let x0 = problem.unknowns(states);
    // the max-norm of a leg's 3 components below tol / sqrt 3 keeps its 2-norm below tol
    let ns = Settings { tol: settings.tol_km / l / 3f64.sqrt(), max_iter: settings.max_iter, max_halvings: 10 };
    let out = newton::solve(&mut problem, x0, &ns)?;
    let n = states.len() - 1;
    let mut defects_km = Vec::with_capacity(n);
    let mut defects_km_s = Vec::with_capacity(n);
    for i in 0..n {
        let f = out.f.rows(6 * i, 6);
        defects_km.push((0..3).map(|a| (f[a] * problem.rp).powi(2)).sum::<f64>().sqrt());
        defects_km_s.push((3..6).map(|a| (f[a] * problem.rv).powi(2)).sum::<f64>().sqrt());
    }
    let nodes: Vec<([f64; 6], f64)> = (0..=n).map(|k| problem.node(&out.x, k)).collect();
    let scale = ns.tol;
    Ok(Transition {
        states: nodes.iter().map(|p| p.0).collect(),
        epochs: nodes.iter().map(|p| p.1).collect(),
        iterations: out.iterations,
        reason: out.reason,
        defects_km,
        defects_km_s,
        history: out.history.iter().map(|h| h / scale).collect(),
    })
}
