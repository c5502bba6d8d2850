//! The one batched, globalised Newton driver of the attitude correctors (planar: [`super::periodic`];
//! 3-D: [`super::periodic3d`]). A problem form ([`Problem`]) says which trajectories a point of
//! the unknowns needs and how its residual and Jacobian follow from their outcomes; the driver
//! integrates the pending points of every candidate in ONE call per iteration and runs, per
//! candidate, capped Newton steps (minimum-norm when the Jacobian is rank-deficient) with a
//! backtracking line search (Armijo-type sufficient decrease of the residual's 2-norm, step
//! halved up to `max_halvings` times). Where the integrator runs lock-step groups, a batch's idle
//! lanes carry the searching candidates' next halvings ahead of time ([`Settings::group`]): the
//! same points and decisions, in fewer rounds. Each candidate reports why it stopped ([`StopReason`]);
//! nothing panics and a non-finite result is never labelled converged.

use nalgebra::{DMatrix, DVector};

use crate::error::Result;

pub use crate::newton::StopReason;

/// The residual rows and Jacobian of one point, and what the form keeps of its trajectories
/// (e.g. the monodromy).
#[derive(Debug, Clone)]
pub(crate) struct Eval<const N: usize> {
    /// Residual rows; unused rows NaN.
    pub f: [f64; N],
    /// d f / d x; unused rows and columns NaN or 0.
    pub jac: [[f64; N]; N],
    pub keep: Vec<f64>,
}

/// An evaluated point of the unknowns.
#[derive(Debug, Clone)]
pub(crate) struct Point<const N: usize> {
    pub x: [f64; N],
    pub f: [f64; N],
    pub norm: f64,
    /// Line-search merit: the 2-norm of the used rows.
    pub merit: f64,
    pub jac: [[f64; N]; N],
    pub keep: Vec<f64>,
}

/// One problem form of the driver over N unknowns.
pub(crate) trait Problem<const N: usize>: Sync {
    type Cand;
    /// One trajectory to integrate.
    type Traj;
    /// Its outcome.
    type Out;
    fn initial(&self, c: &Self::Cand) -> [f64; N];
    /// Push the trajectories of the point x (always [`Problem::per_point`] of them); false when x
    /// cannot be integrated (outside the domain of a parameter).
    fn push(&self, c: &Self::Cand, x: &[f64; N], out: &mut Vec<Self::Traj>) -> bool;
    fn per_point(&self) -> usize;
    /// Residual and Jacobian from the point's outcomes; None when any failed or is non-finite.
    fn evaluate(&self, c: &Self::Cand, x: &[f64; N], o: &[Self::Out]) -> Option<Eval<N>>;
    /// The residual rows and unknown columns in use (square).
    fn rows(&self) -> &[usize];
    fn cols(&self) -> &[usize];
    /// The factor (<= 1) scaling the Newton step `d` to the step caps (direction kept).
    fn step_scale(&self, d: &[f64; N]) -> f64;
    /// The closure rows (the rows in use but a continuation's linear condition).
    fn closure_rows(&self) -> &[usize] {
        self.rows()
    }
    /// Whether x lies in the candidate's search window (default: everywhere). A Newton step
    /// whose target leaves it stops the candidate ([`StopReason::LeftWindow`]): the accepted
    /// points then stay inside (the window is convex: an interval per unknown).
    fn admits(&self, _c: &Self::Cand, _x: &[f64; N]) -> bool {
        true
    }
}

/// The largest |d F / d x| of the closure rows at a point (at least 1): the factor by which
/// errors in the unknowns, and the integration's own, show in the residual.
fn conditioning<const N: usize, P: Problem<N>>(p: &P, pt: &Point<N>) -> f64 {
    p.closure_rows().iter().flat_map(|&r| p.cols().iter().map(move |&c| pt.jac[r][c].abs())).fold(1.0, f64::max)
}

/// Settings of the driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Settings {
    pub tol: f64,
    pub max_iter: usize,
    pub max_halvings: u32,
    /// The integrator's lock-step group: `integrate` runs its trajectories in consecutive
    /// groups of this many (the SIMD lanes), a group costing the same however many of its lanes
    /// are in use. The driver fills the last group's idle lanes with the next trial points of
    /// the line searches that have halved their step (halved once more, and again), so that a
    /// search that backtracks does not cost a round per halving. 1: no look-ahead (one
    /// trajectory per call of a scalar integrator, or groups the driver cannot see).
    pub group: usize,
    /// The largest ratio of the residual's 2-norm after an accepted step to before it, while
    /// above the noise floor; a slower step stops the candidate ([`StopReason::SlowConvergence`]).
    /// For a continuation's corrections (Deuflhard's contraction test on the predictor): a
    /// Newton iteration that converges contracts quickly, and one that creeps (damped steps far
    /// from the solution, 0.8 -> 0.7 -> 0.7 ...) would spend every remaining iteration before
    /// failing. `f64::INFINITY`: no test.
    pub max_contraction: f64,
}

#[derive(Debug, Clone, Copy)]
enum Phase {
    Start,
    Trial { lambda: f64, halvings: u32, any_integrated: bool },
    Done(StopReason),
}

/// One candidate's state, and its outcome when the driver returns.
pub(crate) struct Track<const N: usize> {
    pub start: [f64; N],
    pub cur: Option<Point<N>>,
    /// Newton direction, already scaled to the step caps; `scale` is that factor (<= 1).
    dir: [f64; N],
    scale: f64,
    rank_deficient: bool,
    phase: Phase,
    pub iterations: usize,
}

/// Singular values below this fraction of the largest are treated as zero (minimum-norm step).
const RANK_TOL: f64 = 1e-11;
/// Armijo constant of the sufficient-decrease test |F(x + l d)|_2 <= (1 - C l) |F(x)|_2.
const ARMIJO: f64 = 1e-4;

fn point<const N: usize, P: Problem<N>>(p: &P, x: [f64; N], e: Eval<N>) -> Option<Point<N>> {
    let rows = p.rows();
    let norm = rows.iter().fold(0.0f64, |a, &i| a.max(e.f[i].abs()));
    let merit = rows.iter().map(|&i| e.f[i] * e.f[i]).sum::<f64>().sqrt();
    let used = rows.iter().all(|&i| p.cols().iter().all(|&j| e.jac[i][j].is_finite()));
    (norm.is_finite() && merit.is_finite() && used).then_some(Point { x, f: e.f, norm, merit, jac: e.jac, keep: e.keep })
}

/// Newton direction at pt (minimum-norm step when J is rank-deficient) and whether J was;
/// None when J is zero or non-finite.
fn direction<const N: usize, P: Problem<N>>(p: &P, pt: &Point<N>) -> Option<([f64; N], bool)> {
    let (rows, cols) = (p.rows(), p.cols());
    let n = rows.len();
    let j = DMatrix::from_fn(n, n, |r, c| pt.jac[rows[r]][cols[c]]);
    let rhs = DVector::from_fn(n, |r, _| -pt.f[rows[r]]);
    let svd = j.try_svd(true, true, f64::EPSILON, 200)?;
    let s1 = svd.singular_values.max();
    let s2 = svd.singular_values.min();
    if !(s1 > 0.0 && s1.is_finite()) {
        return None;
    }
    let deficient = s2 <= RANK_TOL * s1;
    let d = svd.solve(&rhs, RANK_TOL * s1).ok()?;
    let mut out = [0.0; N];
    for (k, &c) in cols.iter().enumerate() {
        out[c] = d[k];
    }
    out.iter().all(|v| v.is_finite()).then_some((out, deficient))
}

impl<const N: usize> Track<N> {
    /// Why it stopped (MaxIterations if it had not).
    pub fn reason(&self) -> StopReason {
        match self.phase {
            Phase::Done(r) => r,
            _ => StopReason::MaxIterations,
        }
    }

    /// The final unknowns (the last accepted point; the start when nothing was accepted).
    pub fn x(&self) -> [f64; N] {
        self.cur.as_ref().map_or(self.start, |p| p.x)
    }

    fn pending(&self) -> Option<[f64; N]> {
        match self.phase {
            Phase::Start => Some(self.start),
            Phase::Trial { lambda, .. } => self.trial(lambda),
            Phase::Done(_) => None,
        }
    }

    fn trial(&self, lambda: f64) -> Option<[f64; N]> {
        let x = self.cur.as_ref()?.x;
        Some(std::array::from_fn(|i| x[i] + lambda * self.dir[i]))
    }

    /// The trial point `level` halvings beyond the pending one, if the line search can get
    /// there (the same arithmetic as the search itself: the point it would evaluate); only for
    /// a search that has already halved its step once: a full step is accepted most of the
    /// time near a solution, and a lane's trajectory is not free where lanes share their steps
    /// (the SRP lanes end a step at every lane's terminator crossing).
    fn ahead(&self, level: u32, s: &Settings) -> Option<[f64; N]> {
        match self.phase {
            Phase::Trial { lambda, halvings, .. } if halvings >= 1 && halvings + level <= s.max_halvings => {
                let mut l = lambda;
                for _ in 0..level {
                    l *= 0.5;
                }
                self.trial(l)
            }
            _ => None,
        }
    }

    fn advance<P: Problem<N>>(&mut self, p: &P, c: &P::Cand, pt: Option<Point<N>>, s: &Settings) {
        match self.phase {
            Phase::Start => match pt {
                None => self.phase = Phase::Done(StopReason::IntegrationFailed),
                Some(pt) => {
                    self.cur = Some(pt);
                    self.next_step(p, c, s);
                }
            },
            Phase::Trial { lambda, halvings, any_integrated } => {
                let Some(cur_merit) = self.cur.as_ref().map(|c| c.merit) else { return };
                let floor = self.cur.as_ref().is_some_and(|c| c.norm <= s.tol * conditioning(p, c));
                let integrated = any_integrated || pt.is_some();
                match pt.filter(|pt| pt.merit <= (1.0 - ARMIJO * lambda * self.scale) * cur_merit) {
                    Some(pt) => {
                        let slow = pt.merit > s.max_contraction * cur_merit && pt.norm > s.tol * conditioning(p, &pt);
                        self.cur = Some(pt);
                        self.iterations += 1;
                        if slow {
                            self.phase = Phase::Done(StopReason::SlowConvergence);
                        } else {
                            self.next_step(p, c, s);
                        }
                    }
                    None if halvings >= s.max_halvings => {
                        self.phase = Phase::Done(if integrated && floor {
                            StopReason::Converged
                        } else if !integrated {
                            StopReason::IntegrationFailed
                        } else if self.rank_deficient {
                            StopReason::SingularJacobian
                        } else {
                            StopReason::NoDescent
                        })
                    }
                    None => self.phase = Phase::Trial { lambda: 0.5 * lambda, halvings: halvings + 1, any_integrated: integrated },
                }
            }
            Phase::Done(_) => {}
        }
    }

    /// After accepting a point: stop, or set up the line search along the Newton direction.
    fn next_step<P: Problem<N>>(&mut self, p: &P, c: &P::Cand, s: &Settings) {
        let Some(cur) = self.cur.as_ref() else { return };
        if cur.norm <= s.tol {
            self.phase = Phase::Done(StopReason::Converged);
            return;
        }
        if self.iterations >= s.max_iter {
            self.phase = Phase::Done(StopReason::MaxIterations);
            return;
        }
        match direction(p, cur) {
            None => self.phase = Phase::Done(StopReason::SingularJacobian),
            Some((d, deficient)) => {
                let scale = p.step_scale(&d).min(1.0);
                let dir = d.map(|v| v * scale);
                if !p.admits(c, &std::array::from_fn(|i| cur.x[i] + dir[i])) {
                    self.phase = Phase::Done(StopReason::LeftWindow);
                    return;
                }
                self.dir = dir;
                self.scale = scale;
                self.rank_deficient = deficient;
                self.phase = Phase::Trial { lambda: 1.0, halvings: 0, any_integrated: false };
            }
        }
    }
}

/// Run the driver on every candidate: all pending points integrated in one call of
/// `integrate` per iteration (trajectories in order, outcomes in the same order), a line
/// search per candidate. Returns the tracks in the candidates' order.
pub(crate) fn solve<const N: usize, P: Problem<N>>(
    problem: &P,
    candidates: &[P::Cand],
    settings: &Settings,
    integrate: &dyn Fn(&[P::Traj]) -> Result<Vec<P::Out>>,
) -> Result<Vec<Track<N>>> {
    let per = problem.per_point();
    let mut tracks: Vec<Track<N>> = candidates
        .iter()
        .map(|c| Track { start: problem.initial(c), cur: None, dir: [0.0; N], scale: 1.0, rank_deficient: false, phase: Phase::Start, iterations: 0 })
        .collect();
    let mut batch: Vec<P::Traj> = Vec::with_capacity(per * tracks.len());
    let mut active: Vec<(usize, [f64; N], Option<usize>)> = Vec::with_capacity(tracks.len());
    // look-ahead trial points: (index into `active`, point, where its trajectories start)
    let mut ahead: Vec<(usize, [f64; N], Option<usize>)> = Vec::new();
    let push = |i: usize, x: &[f64; N], batch: &mut Vec<P::Traj>| {
        let at = batch.len();
        let pushed = problem.push(&candidates[i], x, batch);
        if !pushed {
            batch.truncate(at);
        }
        pushed.then_some(at)
    };
    loop {
        crate::interrupt::check()?;
        batch.clear();
        active.clear();
        ahead.clear();
        for (i, t) in tracks.iter().enumerate() {
            if let Some(x) = t.pending() {
                let at = push(i, &x, &mut batch);
                active.push((i, x, at));
            }
        }
        if active.is_empty() {
            break;
        }
        // the last group's idle lanes: each searching candidate's next halving, then the one
        // after, ... (in candidate order; the same points whatever the thread count)
        let group = settings.group.max(1);
        let idle = |batch: &Vec<P::Traj>| (group - batch.len() % group) % group;
        let mut level = 1;
        while !batch.is_empty() && idle(&batch) >= per {
            let before = ahead.len();
            for (a, &(i, _, _)) in active.iter().enumerate() {
                if idle(&batch) < per {
                    break;
                }
                if let Some(x) = tracks[i].ahead(level, settings) {
                    let at = push(i, &x, &mut batch);
                    ahead.push((a, x, at));
                }
            }
            if ahead.len() == before {
                break;
            }
            level += 1;
        }
        let out = if batch.is_empty() { Vec::new() } else { integrate(&batch)? };
        let eval = |i: usize, x: &[f64; N], at: Option<usize>| {
            at.and_then(|k| out.get(k..k + per)).and_then(|o| problem.evaluate(&candidates[i], x, o)).and_then(|e| point(problem, *x, e))
        };
        for (a, &(i, x, at)) in active.iter().enumerate() {
            tracks[i].advance(problem, &candidates[i], eval(i, &x, at), settings);
            // a rejected trial goes on with the look-ahead points already integrated, in order,
            // while they are the points the search asks for next
            for (_, y, at) in ahead.iter().filter(|h| h.0 == a) {
                if tracks[i].pending().map(|p| p.map(f64::to_bits)) != Some(y.map(f64::to_bits)) {
                    break; // accepted, or stopped
                }
                tracks[i].advance(problem, &candidates[i], eval(i, y, *at), settings);
            }
        }
    }
    Ok(tracks)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    /// F(x) = atan(x - c) in one unknown: Newton from far away overshoots (|x - c| > 1.39
    /// diverges), so the line search backtracks several times a step; trajectories are pure
    /// functions of x, so a look-ahead must leave every decision and every value unchanged.
    struct Atan;
    impl Problem<1> for Atan {
        type Cand = f64;
        type Traj = f64;
        type Out = f64;
        fn initial(&self, c: &f64) -> [f64; 1] {
            [*c]
        }
        fn push(&self, _: &f64, x: &[f64; 1], out: &mut Vec<f64>) -> bool {
            out.push(x[0]);
            x[0].abs() < 1e3
        }
        fn per_point(&self) -> usize {
            1
        }
        fn evaluate(&self, _: &f64, x: &[f64; 1], o: &[f64]) -> Option<Eval<1>> {
            let u = x[0] - 0.3;
            Some(Eval { f: [o[0]], jac: [[1.0 / (1.0 + u * u)]], keep: Vec::new() })
        }
        fn rows(&self) -> &[usize] {
            &[0]
        }
        fn cols(&self) -> &[usize] {
            &[0]
        }
        fn step_scale(&self, _: &[f64; 1]) -> f64 {
            1.0
        }
    }

    #[test]
    fn look_ahead_changes_nothing_but_the_rounds() {
        // starts near (converging in a few steps) and far (backtracking, some to NoDescent)
        let starts = [0.31, 1.0, 2.5, -4.0, 9.0, 40.0, -150.0];
        let run = |group: usize, max_halvings: u32| {
            let rounds = Cell::new(0usize);
            let s = Settings { tol: 1e-13, max_iter: 30, max_halvings, group, max_contraction: f64::INFINITY };
            let tracks = solve(&Atan, &starts, &s, &|b: &[f64]| {
                rounds.set(rounds.get() + 1);
                Ok(b.iter().map(|&x| (x - 0.3).atan()).collect())
            })
            .unwrap();
            let out: Vec<(u64, usize, StopReason)> = tracks.iter().map(|t| (t.x()[0].to_bits(), t.iterations, t.reason())).collect();
            (out, rounds.get())
        };
        for max_halvings in [0, 2, 10] {
            let (plain, r1) = run(1, max_halvings);
            let (ahead, r8) = run(8, max_halvings);
            assert_eq!(plain, ahead, "max_halvings {max_halvings}");
            assert!(r8 <= r1, "max_halvings {max_halvings}: {r8} rounds with the look-ahead, {r1} without");
            if max_halvings == 10 {
                assert!(r8 < r1, "the far starts backtrack: fewer rounds expected ({r8} against {r1})");
                assert!(plain.iter().filter(|p| p.2 == StopReason::Converged).count() >= 4, "{plain:?}");
            }
        }
    }

    #[test]
    fn contraction_test_stops_creeping_starts_and_leaves_the_converging_ones() {
        // atan(x - 0.3): from 0.31 and 1.0 Newton contracts at once (1.0: |F| 0.611 -> 0.207 ->
        // 0.006, ratios 0.34 and 0.03, analytic); from 2.5 on, its full steps overshoot and the
        // damped steps the line search accepts barely reduce |F|
        let starts = [0.31, 1.0, 2.5, -4.0, 9.0, 40.0];
        let run = |max_contraction: f64| {
            let s = Settings { tol: 1e-13, max_iter: 30, max_halvings: 10, group: 1, max_contraction };
            solve(&Atan, &starts, &s, &|b: &[f64]| Ok(b.iter().map(|&x| (x - 0.3).atan()).collect()))
                .unwrap()
                .iter()
                .map(|t| (t.x()[0].to_bits(), t.iterations, t.reason()))
                .collect::<Vec<_>>()
        };
        let (free, tested) = (run(f64::INFINITY), run(0.5));
        assert_eq!(&tested[..2], &free[..2], "the converging starts take the same steps to the same bits");
        assert!(tested[..2].iter().all(|t| t.2 == StopReason::Converged));
        for (i, (t, f)) in tested.iter().zip(&free).enumerate().skip(2) {
            assert_eq!(t.2, StopReason::SlowConvergence, "start {}: {t:?}", starts[i]);
            assert!(t.1 <= 2 && t.1 < f.1, "start {}: stopped after {} accepted steps, {} without the test", starts[i], t.1, f.1);
        }
        assert_eq!(StopReason::SlowConvergence.as_str(), "slow_convergence");
    }
}
