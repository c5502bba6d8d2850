//! The 3-D attitude map engine's integrator (issue 15, item 5): the rigid body's attitude
//! relative to the synodic frame (quaternion q, scalar last) and its inertial rate w in body
//! axes, 7 states, for eight trajectories in lock step in SIMD lanes, along one periodic orbit
//! (planar or spatial) whose tidal tensor is tabulated once ([`TidalTable`]).
//!
//! As in the planar engine ([`super::lanes`]): the eight share the time and the step (the
//! smallest any of them needs), so the orbit's tidal tensor is evaluated once per stage time
//! (a step's eight distinct inner nodes in one vector Chebyshev recurrence), broadcast to the
//! lanes; trajectories are grouped eight by eight in case order from
//! the start of the slice (chunks are multiples of eight), so results are bit-identical for any
//! chunking and thread count. The step loop, the RKF7(8) stages and the controller are the
//! planar engine's ([`run_steps`], [`Stages`]); the physics are the scalar 3-D model's own laws
//! ([`dcm_with`], [`quat_rate`], [`gravity_gradient_torque`], [`euler_rate`]) evaluated over the
//! lane type, each lane with its own body. No STM: the map needs the end state only.

use rayon::prelude::*;

use super::forcing::TidalTable;
use super::lanes::{lane, run_steps, Fehlberg, LaneOptions, LaneStatus, Method, NoCut, PrinceDormand, Recent, Rhs, Run, Scheme, Stages, LANES};
use crate::attitude::{dcm_with, euler_rate, gravity_gradient_torque, quat_rate, RigidBody};
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::attitude::attitude_residual;
use crate::propagation::with_threads;
use crate::scalar::F8;
use crate::simd::{Isa, Kernel, Level};

/// States per lane: q (4), w (3).
const D: usize = 7;

/// One 3-D attitude trajectory of a map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case3d {
    /// Initial attitude of the body relative to the synodic frame (unit, scalar last).
    pub q0: [f64; 4],
    /// Initial inertial angular velocity in body axes (rad/TU).
    pub w0: [f64; 3],
    pub body: RigidBody,
}

/// The end state of one 3-D trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome3d {
    /// q(T) as integrated (not renormalised) and w(T); NaN unless `status` is Ok.
    pub q_t: [f64; 4],
    pub w_t: [f64; 3],
    /// (Log(q0* (x) q(T)), w(T) - w0), as [`attitude_residual`]; NaN unless Ok.
    pub residual: [f64; 6],
    pub accepted: u32,
    pub rejected: u32,
    pub status: LaneStatus,
}

/// The rigid body on the lanes: the orbit's tidal-tensor table and each lane's moments.
struct Rigid<'a, I> {
    table: &'a TidalTable,
    inertia: [F8<I>; 3],
    inv: [F8<I>; 3],
    one: F8<I>,
    /// The tidal tensor at the latest four single times ([`Rhs::at`]): a step's first node (the
    /// previous step's last, or a rejected step's first) and its last.
    recent: Recent<[f64; 6], 4>,
}

/// The rigid body's orbit data is the tidal tensor at a stage's time: a step's eight distinct
/// nodes in one vector Clenshaw recurrence of the table ([`TidalTable::try_eval8_at`], the same
/// values bit for bit) when they lie in at most two of its segments, else each stage evaluates
/// the table itself, between the lanes' vector work (eight scalar recurrences up front were
/// slower); a step's first and last node from the memo. The data: (t, the tensor or None).
impl<I: Isa> Rhs<I, D> for Rigid<'_, I> {
    type At = (f64, Option<[f64; 6]>);

    #[inline(always)]
    fn at(&self, t: f64) -> (f64, Option<[f64; 6]>) {
        match self.recent.find(t) {
            Some(m6) => (t, Some(m6)),
            None => (t, Some(self.recent.keep(t, self.table.eval_at::<I>(t)))),
        }
    }

    #[inline(always)]
    fn at8(&self, ts: &[f64; 8]) -> [(f64, Option<[f64; 6]>); 8] {
        // loops, not array::from_fn / map (their closures are compiled out of line)
        let v = self.table.try_eval8_at(self.one.isa(), ts);
        let mut out = [(0.0, None); 8];
        for l in 0..8 {
            out[l] = (ts[l], v.map(|v| v[l]));
        }
        out
    }

    #[inline(always)]
    fn eval_at(&self, at: &(f64, Option<[f64; 6]>), y: &[F8<I>; D], dy: &mut [F8<I>; D]) {
        let m6 = match at.1 {
            Some(m6) => m6,
            None => self.table.eval_at::<I>(at.0),
        };
        let isa = y[0].isa();
        let m = [F8::splat(isa, m6[0]), F8::splat(isa, m6[1]), F8::splat(isa, m6[2]), F8::splat(isa, m6[3]), F8::splat(isa, m6[4]), F8::splat(isa, m6[5])];
        let q = [y[0], y[1], y[2], y[3]];
        let w = [y[4], y[5], y[6]];
        let a = dcm_with(&q, self.one);
        let qd = quat_rate(&q, &a, &w);
        let tq = gravity_gradient_torque(&a, &m, &self.inertia);
        let wd = euler_rate(&tq, &w, &self.inertia, &self.inv);
        dy[..4].copy_from_slice(&qd);
        dy[4..].copy_from_slice(&wd);
    }
}

/// Integrate one group of up to LANES trajectories; missing lanes repeat the last.
#[inline(always)]
fn integrate_group<'a, I: Isa, S: Scheme<I, Rigid<'a, I>, Y = [F8<I>; D]>>(isa: I, table: &'a TidalTable, t_final: f64, group: &[Case3d], opts: &LaneOptions, st: &mut S) -> [Outcome3d; LANES] {
    let n = group.len();
    let pick = |l: usize| group[l.min(n - 1)];
    let moments = |i: usize| F8::new(isa, std::array::from_fn(|l| pick(l).body.moments()[i]));
    let inertia = [moments(0), moments(1), moments(2)];
    let one = F8::splat(isa, 1.0);
    // written out: array::map's closure would call the division out of line
    let model = Rigid { table, inertia, inv: [one / inertia[0], one / inertia[1], one / inertia[2]], one, recent: Recent::new([f64::NAN; 6]) };
    let mut y: [F8<I>; D] = std::array::from_fn(|i| F8::new(isa, std::array::from_fn(|l| if i < 4 { pick(l).q0[i] } else { pick(l).w0[i - 4] })));
    st.begin();
    let Run { accepted, rejected, status, .. } = run_steps(isa, st, &model, &mut y, t_final, opts, &mut NoCut);
    std::array::from_fn(|l| {
        if status != LaneStatus::Ok {
            return Outcome3d { q_t: [f64::NAN; 4], w_t: [f64::NAN; 3], residual: [f64::NAN; 6], accepted, rejected, status };
        }
        let q_t = [lane(&y[0], l), lane(&y[1], l), lane(&y[2], l), lane(&y[3], l)];
        let w_t = [lane(&y[4], l), lane(&y[5], l), lane(&y[6], l)];
        let c = pick(l);
        Outcome3d { q_t, w_t, residual: attitude_residual(&c.q0, &c.w0, &q_t, &w_t), accepted, rejected, status }
    })
}

/// The 3-D lane engine as a dispatched kernel.
struct Groups3d<'a> {
    table: &'a TidalTable,
    t_final: f64,
    cases: &'a [Case3d],
    opts: &'a LaneOptions,
}

impl Kernel for Groups3d<'_> {
    type Output = Vec<Outcome3d>;
    #[inline(always)]
    fn run<I: Isa>(self, isa: I) -> Vec<Outcome3d> {
        match self.opts.method {
            Method::Dp87 => self.with::<I, Stages<I, D, PrinceDormand>>(isa),
            _ => self.with::<I, Stages<I, D, Fehlberg>>(isa),
        }
    }
}

impl<'a> Groups3d<'a> {
    #[inline(always)]
    fn with<I: Isa, S: Scheme<I, Rigid<'a, I>, Y = [F8<I>; D]>>(self, isa: I) -> Vec<Outcome3d> {
        let mut st = S::new(isa);
        let mut out = Vec::with_capacity(self.cases.len());
        for group in self.cases.chunks(LANES) {
            let r = integrate_group::<I, S>(isa, self.table, self.t_final, group, self.opts, &mut st);
            out.extend_from_slice(&r[..group.len()]);
        }
        out
    }
}

/// Integrate every case from t = 0 to `t_final` along the tabulated orbit on `threads` workers
/// (None: all cores), `chunk` cases per task, at the active SIMD level. Results are in case
/// order and bit-identical for any `chunk` and thread count. Only `opts.rtol`, `opts.atol`,
/// `opts.max_steps` and `opts.method` apply (RKF7(8) or RK8(7)13M; the Nyström method is planar
/// only: an error).
pub fn sweep_3d(table: &TidalTable, t_final: f64, cases: &[Case3d], opts: &LaneOptions, chunk: usize, threads: Option<usize>) -> Result<Vec<Outcome3d>> {
    sweep_3d_at(crate::simd::active()?, table, t_final, cases, opts, chunk, threads)
}

/// [`sweep_3d`] at a given SIMD level (an error naming `LIBRATE_SIMD` if the CPU lacks it).
pub fn sweep_3d_at(level: Level, table: &TidalTable, t_final: f64, cases: &[Case3d], opts: &LaneOptions, chunk: usize, threads: Option<usize>) -> Result<Vec<Outcome3d>> {
    check_positive("t_final", t_final)?;
    crate::integrate::check_tolerances(opts.rtol, opts.atol)?;
    if chunk == 0 {
        return Err(invalid("chunk", "must be >= 1"));
    }
    if opts.method == Method::Rkn86 {
        return Err(invalid("method", "the 3-D map integrates with 'rkf78' or 'dp87' ('rkn86' is planar only)"));
    }
    if threads == Some(0) {
        return Err(invalid("threads", "must be >= 1 (or None for all cores)"));
    }
    for (i, c) in cases.iter().enumerate() {
        check_finite("q0", &c.q0).map_err(|_| invalid("q0", format!("case {i}: must be finite, got {:?}", c.q0)))?;
        let n = c.q0.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-9 {
            return Err(invalid("q0", format!("case {i}: must be a unit quaternion (scalar last), |q0| = {n}")));
        }
        check_finite("w0", &c.w0).map_err(|_| invalid("w0", format!("case {i}: must be finite, got {:?}", c.w0)))?;
        RigidBody::new(c.body.ix, c.body.iy, c.body.iz)?;
    }
    if !level.is_available() {
        crate::simd::parse(Some(level.name()))?;
    }
    let chunk = chunk.div_ceil(LANES) * LANES;
    let run = |part: &[Case3d]| {
        crate::interrupt::check()?;
        crate::simd::run_at(level, Groups3d { table, t_final, cases: part, opts })
    };
    let parts = with_threads(threads, || cases.par_chunks(chunk).map(run).collect::<Result<Vec<_>>>())??;
    Ok(parts.concat())
}
