//! Single shooting for orbits symmetric about the x-z plane (planar DROs and Lyapunov orbits,
//! halos): start perpendicular to the plane at (x0, 0, z0, 0, vy0, 0), integrate with the STM to
//! the next crossing of y = 0 (located in time), and drive xdot (and zdot in 3-D) there to zero.
//!
//! The unknowns are p = (x0, z0, vy0) (z0 = 0 in the planar case). One extra scalar condition
//! makes the Newton system square: a fixed unknown, a target period, a target Jacobi constant,
//! or the pseudo-arclength condition of continuation. Sensitivities account for the moving
//! crossing time: d(state_c)/dp = Phi[:, p] + f(state_c) dt_c/dp, dt_c/dp = -Phi[y, p] / ydot_c
//! (thesis eq. 19 is the planar case with x0 fixed).

use nalgebra::{DMatrix, DVector};

use crate::cr3bp::{check_mu, jacobi, potential_gradient, Cr3bp};
use crate::error::{check_finite, check_positive, invalid, Error, Result};
use crate::integrate::{Options, Output, Status, System};
use crate::propagation::{propagate, EventKind, EventSpec};

/// An unknown of the symmetric problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Var {
    X0 = 0,
    Z0 = 1,
    Vy0 = 2,
}

/// The extra condition closing the Newton system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Constraint {
    /// Keep one unknown at a value (natural-parameter continuation).
    Fix(Var, f64),
    /// Full period equal to a target (TU).
    Period(f64),
    /// Jacobi constant equal to a target.
    Jacobi(f64),
    /// tangent . (p - prev) = ds (pseudo-arclength continuation).
    Arclength { prev: [f64; 3], tangent: [f64; 3], ds: f64 },
}

/// The shooting problem: system, planar or spatial, integration settings.
#[derive(Debug, Clone, Copy)]
pub struct SymmetricShooting {
    pub mu: f64,
    /// 3-D (x0, z0, vy0 free, xdot and zdot targeted) or planar (z0 = 0, xdot targeted).
    pub spatial: bool,
    pub opts: Options,
    /// Longest half period searched for the crossing (TU).
    pub t_max: f64,
    /// Convergence tolerance on the residual (max norm).
    pub tol: f64,
    pub max_iter: usize,
}

/// Residuals and sensitivities of the symmetric conditions at one p.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    pub p: [f64; 3],
    /// (xdot_c, zdot_c) at the half-period crossing.
    pub cond: [f64; 2],
    /// d cond / d p (rows xdot_c, zdot_c; columns x0, z0, vy0).
    pub dcond: [[f64; 3]; 2],
    pub half_period: f64,
    /// d(T/2)/dp.
    pub dhalf: [f64; 3],
    pub jacobi: f64,
    pub djacobi: [f64; 3],
    /// State at the crossing.
    pub crossing: [f64; 6],
    /// State transition matrix Phi(T/2, 0) to the crossing.
    pub stm_half: [[f64; 6]; 6],
}

impl Evaluation {
    /// The monodromy matrix of the symmetric orbit from the half-period STM alone:
    /// Phi(T, 0) = S Phi(T/2, 0)^-1 S Phi(T/2, 0), S = diag(1, -1, 1, -1, 1, -1) (the mirror
    /// x-z-plane symmetry with time reversal maps the second half of the orbit onto the first);
    /// exact at a periodic orbit, to the integration's accuracy. None when Phi(T/2) is singular.
    pub fn monodromy(&self) -> Option<[[f64; 6]; 6]> {
        let phi = nalgebra::Matrix6::from_fn(|i, j| self.stm_half[i][j]);
        let s = nalgebra::Matrix6::from_diagonal(&nalgebra::Vector6::new(1.0, -1.0, 1.0, -1.0, 1.0, -1.0));
        let m = s * phi.try_inverse()? * s * phi;
        m.iter().all(|v| v.is_finite()).then(|| std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)])))
    }
}

impl Evaluation {
    /// The family's tangent dp = (dx0, dz0, dvy0) at this point: the direction along which the
    /// symmetric conditions (xdot_c, and zdot_c in 3-D) stay zero to first order, scaled so that
    /// `along` . dp = 1 (e.g. (1, 0, 0): per unit x0; 2 dhalf: per unit period). Planar
    /// (`spatial` false): dz0 = 0, one condition. None when singular (a fold of the family in
    /// that parameter).
    pub fn tangent(&self, spatial: bool, along: [f64; 3]) -> Option<[f64; 3]> {
        use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
        let v = if spatial {
            let d = &self.dcond;
            let m = Matrix3::new(d[0][0], d[0][1], d[0][2], d[1][0], d[1][1], d[1][2], along[0], along[1], along[2]);
            let v = m.lu().solve(&Vector3::new(0.0, 0.0, 1.0))?;
            [v[0], v[1], v[2]]
        } else {
            let m = Matrix2::new(self.dcond[0][0], self.dcond[0][2], along[0], along[2]);
            let v = m.lu().solve(&Vector2::new(0.0, 1.0))?;
            [v[0], 0.0, v[1]]
        };
        v.iter().all(|x| x.is_finite()).then_some(v)
    }
}

/// A corrected symmetric orbit.
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetricOrbit {
    pub state0: [f64; 6],
    pub period: f64,
    pub jacobi: f64,
    pub iterations: usize,
    /// Max-norm of the residual after the last iteration.
    pub residual: f64,
    /// The final evaluation (sensitivities at the solution, used for continuation tangents).
    pub evaluation: Evaluation,
}

const COLS: [usize; 3] = [0, 2, 4];

impl SymmetricShooting {
    pub fn new(mu: f64, spatial: bool, opts: Options) -> Self {
        Self { mu, spatial, opts, t_max: 50.0, tol: 1e-11, max_iter: 40 }
    }

    fn validate(&self) -> Result<()> {
        check_mu(self.mu)?;
        self.opts.validate()?;
        check_positive("t_max", self.t_max)?;
        check_positive("tol", self.tol)?;
        if self.max_iter == 0 {
            return Err(invalid("max_iter", "must be >= 1"));
        }
        Ok(())
    }

    /// Unknowns that move: (x0, vy0) in the planar case, (x0, z0, vy0) in 3-D.
    fn free(&self) -> &'static [usize] {
        if self.spatial {
            &[0, 1, 2]
        } else {
            &[0, 2]
        }
    }

    /// Integrate to the half-period crossing and return residuals and sensitivities.
    pub fn evaluate(&self, p: [f64; 3]) -> Result<Evaluation> {
        check_finite("p", &p)?;
        let mu = self.mu;
        let s0 = [p[0], 0.0, if self.spatial { p[1] } else { 0.0 }, 0.0, p[2], 0.0];
        let ev = EventSpec { kind: EventKind::Crossing { index: 1, value: 0.0 }, direction: 0, terminal: true };
        let tr = propagate(mu, &s0, 0.0, self.t_max, &self.opts, true, Output::Final, &[ev])?;
        if tr.status == Status::Completed {
            return Err(Error::Convergence {
                what: "symmetric shooting (no crossing of y = 0 within t_max)",
                iterations: 0,
                residual: f64::INFINITY,
                tolerance: self.tol,
            });
        }
        let hit = &tr.events[0];
        let s = hit.state;
        let phi = hit.stm.expect("propagated with the STM");
        let mut f = [0.0; 6];
        Cr3bp { mu }.derivative(hit.t, &s, &mut f);
        let mut dhalf = [0.0; 3];
        let mut dcond = [[0.0; 3]; 2];
        for (k, &c) in COLS.iter().enumerate() {
            let dt = -phi[1][c] / s[4];
            dhalf[k] = dt;
            dcond[0][k] = phi[3][c] + f[3] * dt;
            dcond[1][k] = phi[5][c] + f[5] * dt;
        }
        let g = potential_gradient(mu, &s0);
        Ok(Evaluation {
            p,
            cond: [s[3], s[5]],
            dcond,
            half_period: hit.t,
            dhalf,
            jacobi: jacobi(mu, &s0),
            djacobi: [2.0 * g[0], 2.0 * g[2], -2.0 * p[2]],
            crossing: s,
            stm_half: phi,
        })
    }

    /// Residual vector and Jacobian (over the free unknowns) of the square Newton system.
    fn system(&self, e: &Evaluation, c: &Constraint) -> (DVector<f64>, DMatrix<f64>) {
        let free = self.free();
        let n = free.len();
        let mut r = DVector::zeros(n);
        let mut j = DMatrix::zeros(n, n);
        let ncond = n - 1;
        for row in 0..ncond {
            r[row] = e.cond[row];
            for (col, &k) in free.iter().enumerate() {
                j[(row, col)] = e.dcond[row][k];
            }
        }
        let (value, grad): (f64, [f64; 3]) = match *c {
            Constraint::Fix(v, target) => {
                let mut g = [0.0; 3];
                g[v as usize] = 1.0;
                (e.p[v as usize] - target, g)
            }
            Constraint::Period(t) => (2.0 * e.half_period - t, e.dhalf.map(|d| 2.0 * d)),
            Constraint::Jacobi(cj) => (e.jacobi - cj, e.djacobi),
            Constraint::Arclength { prev, tangent, ds } => {
                let dot: f64 = (0..3).map(|i| tangent[i] * (e.p[i] - prev[i])).sum();
                (dot - ds, tangent)
            }
        };
        r[ncond] = value;
        for (col, &k) in free.iter().enumerate() {
            j[(ncond, col)] = grad[k];
        }
        (r, j)
    }

    /// Newton's method from the guess `p`, with step halving when the residual grows.
    pub fn correct(&self, p: [f64; 3], constraint: Constraint) -> Result<SymmetricOrbit> {
        self.validate()?;
        if let Constraint::Fix(Var::Z0, _) = constraint {
            if !self.spatial {
                return Err(invalid("constraint", "z0 cannot be the fixed unknown of a planar orbit"));
            }
        }
        let free = self.free();
        let mut p = p;
        if !self.spatial {
            p[1] = 0.0;
        }
        // Start on the constraint where it is explicit.
        if let Constraint::Fix(v, value) = constraint {
            p[v as usize] = value;
        }
        let mut e = self.evaluate(p)?;
        let (mut r, mut j) = self.system(&e, &constraint);
        let mut norm = r.amax();
        for it in 0..=self.max_iter {
            crate::interrupt::check()?;
            if norm <= self.tol {
                let s0 = [e.p[0], 0.0, e.p[1], 0.0, e.p[2], 0.0];
                return Ok(SymmetricOrbit { state0: s0, period: 2.0 * e.half_period, jacobi: e.jacobi, iterations: it, residual: norm, evaluation: e });
            }
            if it == self.max_iter {
                break;
            }
            let dx = j.clone().lu().solve(&(-&r)).ok_or(Error::Convergence {
                what: "symmetric shooting (singular Jacobian: a fold or bifurcation of the family?)",
                iterations: it,
                residual: norm,
                tolerance: self.tol,
            })?;
            // Damped update: halve until the residual decreases (or accept after 6 halvings).
            let mut lambda = 1.0;
            let mut accepted = None;
            for _ in 0..7 {
                let mut q = p;
                for (col, &k) in free.iter().enumerate() {
                    q[k] += lambda * dx[col];
                }
                if let Ok(eq) = self.evaluate(q) {
                    let (rq, jq) = self.system(&eq, &constraint);
                    let nq = rq.amax();
                    if nq.is_finite() && (nq < norm || lambda < 0.02) {
                        accepted = Some((q, eq, rq, jq, nq));
                        break;
                    }
                }
                lambda *= 0.5;
            }
            match accepted {
                Some((q, eq, rq, jq, nq)) => {
                    p = q;
                    e = eq;
                    r = rq;
                    j = jq;
                    norm = nq;
                }
                None => {
                    return Err(Error::Convergence {
                        what: "symmetric shooting (no step reduces the residual)",
                        iterations: it,
                        residual: norm,
                        tolerance: self.tol,
                    })
                }
            }
        }
        Err(Error::Convergence { what: "symmetric shooting", iterations: self.max_iter, residual: norm, tolerance: self.tol })
    }
}

/// Planar x-symmetric orbit with x0 fixed (thesis eq. 19): correct ydot0.
pub fn correct_planar_symmetric(mu: f64, x0: f64, ydot0_guess: f64, tol: f64, max_iter: usize, opts: &Options) -> Result<SymmetricOrbit> {
    let mut sh = SymmetricShooting::new(mu, false, *opts);
    sh.tol = tol;
    sh.max_iter = max_iter;
    if !x0.is_finite() || !ydot0_guess.is_finite() {
        return Err(invalid("x0", format!("x0 and ydot0 must be finite, got ({x0}, {ydot0_guess})")));
    }
    sh.correct([x0, 0.0, ydot0_guess], Constraint::Fix(Var::X0, x0))
}
