//! The 3-D attitude map engine's integrator (issue 15, item 5): the rigid body's attitude
//! relative to the synodic frame (quaternion q, scalar last) and its inertial rate w in body
//! axes, 7 states, for groups of trajectories in lock step in SIMD lanes, along one periodic orbit
//! (planar or spatial) whose tidal tensor is tabulated once ([`TidalTable`]).
//!
//! As in the planar engine ([`super::lanes`]): a group's trajectories share the time and the
//! step (the smallest any of them needs), so the orbit's tidal tensor is evaluated once per stage
//! time (a step's eight distinct inner nodes in one vector Chebyshev recurrence), broadcast to
//! the lanes. A group is eight trajectories on one lane vector, or at AVX-512 sixteen on two
//! ([`group_size`]); groups are taken in case order from the start of the slice (chunks are
//! multiples of the group), so results are bit-identical for any chunking and thread count, and
//! differ between levels in their last bits. The step loop, the RKF7(8) stages and the controller are the
//! planar engine's ([`run_steps`], [`Stages`]); the physics are the scalar 3-D model's own laws
//! ([`dcm_with`], [`quat_rate`]; the gravity-gradient torque into Euler's equations in one form,
//! [`gravity_gradient_euler_rate`]) evaluated over the lane type, each lane with its own body.
//! No STM: the map needs the end state only.

use rayon::prelude::*;

use super::forcing::TidalTable;
use super::lanes::{lane, run_steps, Fehlberg, LaneOptions, LaneStatus, Method, NoCut, PrinceDormand, Recent, Rhs, Run, Scheme, Stages, LANES};
use crate::attitude::{dcm_with, euler_ratios, gravity_gradient_euler_rate, quat_rate, RigidBody};
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

/// The rigid body on the lanes: the orbit's tidal-tensor table and each lane's moments (as
/// their [`euler_ratios`]).
struct Rigid<'a, I> {
    table: &'a TidalTable,
    /// Each lane's [`euler_ratios`], formed once per group.
    k: [F8<I>; 3],
    one: F8<I>,
    /// The tidal tensor at the latest four single times ([`Rhs::at`]): a step's first node (the
    /// previous step's last, or a rejected step's first) and its last.
    recent: Recent<[f64; 6], 4>,
}

/// The rigid body's orbit data is the tidal tensor at a stage's time: a step's eight distinct
/// nodes in one vector Clenshaw recurrence of the table ([`TidalTable::try_eval8_at`], the same
/// values bit for bit) when they lie in at most three of its segments, else each stage evaluates
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
        rigid_rate(&self.tensor(at), y, &self.k, self.one, dy);
    }
}

impl<I: Isa> Rigid<'_, I> {
    /// The tidal tensor of a stage's orbit data.
    #[inline(always)]
    fn tensor(&self, at: &(f64, Option<[f64; 6]>)) -> [f64; 6] {
        match at.1 {
            Some(m6) => m6,
            None => self.table.eval_at::<I>(at.0),
        }
    }
}

/// The derivative of one lane vector's (q, w) under the tidal tensor m (the same for every lane),
/// with the lanes' [`euler_ratios`] k ([`gravity_gradient_euler_rate`]).
#[inline(always)]
fn rigid_rate<I: Isa>(m: &[f64; 6], y: &[F8<I>], k: &[F8<I>; 3], one: F8<I>, dy: &mut [F8<I>]) {
    let isa = one.isa();
    let m = [F8::splat(isa, m[0]), F8::splat(isa, m[1]), F8::splat(isa, m[2]), F8::splat(isa, m[3]), F8::splat(isa, m[4]), F8::splat(isa, m[5])];
    let q = [y[0], y[1], y[2], y[3]];
    let w = [y[4], y[5], y[6]];
    let a = dcm_with(&q, one);
    let qd = quat_rate(&q, &a, &w);
    let wd = gravity_gradient_euler_rate(&a, &m, &w, k);
    dy[..4].copy_from_slice(&qd);
    dy[4..D].copy_from_slice(&wd);
}

/// States of a wide group: two lane vectors' (q, w).
const WIDE: usize = 2 * D;

/// Two lane vectors of the rigid body as one state of fourteen components, (q, w) of lanes 0-7
/// then of lanes 8-15: one step size and one tidal-tensor evaluation per stage for sixteen
/// trajectories ([`group_size`]).
struct Wide<'a, I> {
    a: Rigid<'a, I>,
    /// The second vector's [`euler_ratios`].
    k: [F8<I>; 3],
}

impl<I: Isa> Rhs<I, WIDE> for Wide<'_, I> {
    type At = (f64, Option<[f64; 6]>);

    #[inline(always)]
    fn at(&self, t: f64) -> (f64, Option<[f64; 6]>) {
        <Rigid<'_, I> as Rhs<I, D>>::at(&self.a, t)
    }

    #[inline(always)]
    fn at8(&self, ts: &[f64; 8]) -> [(f64, Option<[f64; 6]>); 8] {
        <Rigid<'_, I> as Rhs<I, D>>::at8(&self.a, ts)
    }

    #[inline(always)]
    fn eval_at(&self, at: &(f64, Option<[f64; 6]>), y: &[F8<I>; WIDE], dy: &mut [F8<I>; WIDE]) {
        let m = self.a.tensor(at);
        let (ya, yb) = y.split_at(D);
        let (da, db) = dy.split_at_mut(D);
        rigid_rate(&m, ya, &self.a.k, self.a.one, da);
        rigid_rate(&m, yb, &self.k, self.a.one, db);
    }
}

/// Trajectories per lock-step group on two lane vectors ([`Wide`]).
const WIDE_GROUP: usize = 2 * LANES;

/// Trajectories per lock-step group of the 3-D map at a SIMD level: sixteen on two lane vectors
/// at AVX-512, whose 32 registers hold a stage's fourteen sums (the 12-day halo at 5e-11, 2000
/// trajectories, one thread: 7.4 -> 6.4 ms); eight elsewhere (at AVX2 the fourteen sums of two vectors take 28 of its 16
/// registers, and sixteen were slower). Results thus depend on the level in their last bits, as
/// between fused and unfused levels (a 3-D map run records its level and resumes only at it);
/// never on the chunking or the thread count.
pub fn group_size(level: Level) -> usize {
    if level == Level::Avx512 {
        WIDE_GROUP
    } else {
        LANES
    }
}

/// A multiple of [`group_size`] at every level: slices of a map that start at multiples of it
/// give the results of one call over all cases, bit for bit, whatever the level.
pub const ALIGN: usize = WIDE_GROUP;

/// One lane vector's moments and its (q0, w0) as states; `pick(l)` is lane l's case.
#[inline(always)]
fn vector_start<I: Isa>(isa: I, pick: impl Fn(usize) -> Case3d) -> ([F8<I>; 3], [F8<I>; D]) {
    let moments = |i: usize| F8::new(isa, std::array::from_fn(|l| pick(l).body.moments()[i]));
    let inertia = [moments(0), moments(1), moments(2)];
    let y: [F8<I>; D] = std::array::from_fn(|i| F8::new(isa, std::array::from_fn(|l| if i < 4 { pick(l).q0[i] } else { pick(l).w0[i - 4] })));
    (euler_ratios(&inertia), y)
}

/// Lane l's outcome from the end states `y` of its vector (`base`: where its (q, w) start).
#[inline(always)]
fn outcome<I: Isa>(c: Case3d, y: &[F8<I>], base: usize, l: usize, run: &Run) -> Outcome3d {
    let (accepted, rejected, status) = (run.accepted, run.rejected, run.status);
    if status != LaneStatus::Ok {
        return Outcome3d { q_t: [f64::NAN; 4], w_t: [f64::NAN; 3], residual: [f64::NAN; 6], accepted, rejected, status };
    }
    let q_t = [lane(&y[base], l), lane(&y[base + 1], l), lane(&y[base + 2], l), lane(&y[base + 3], l)];
    let w_t = [lane(&y[base + 4], l), lane(&y[base + 5], l), lane(&y[base + 6], l)];
    Outcome3d { q_t, w_t, residual: attitude_residual(&c.q0, &c.w0, &q_t, &w_t), accepted, rejected, status }
}

/// Integrate one group of up to LANES trajectories; missing lanes repeat the last.
#[inline(always)]
fn integrate_group<'a, I: Isa, S: Scheme<I, Rigid<'a, I>, Y = [F8<I>; D]>>(isa: I, table: &'a TidalTable, t_final: f64, group: &[Case3d], opts: &LaneOptions, st: &mut S) -> [Outcome3d; LANES] {
    let n = group.len();
    let pick = |l: usize| group[l.min(n - 1)];
    let (k, mut y) = vector_start(isa, pick);
    let model = Rigid { table, k, one: F8::splat(isa, 1.0), recent: Recent::new([f64::NAN; 6]) };
    st.begin();
    let run = run_steps(isa, st, &model, &mut y, t_final, opts, &mut NoCut);
    std::array::from_fn(|l| outcome(pick(l), &y, 0, l, &run))
}

/// Integrate one group of up to WIDE_GROUP trajectories on two lane vectors in lock step;
/// missing lanes repeat the last.
#[inline(always)]
fn integrate_wide<'a, I: Isa, S: Scheme<I, Wide<'a, I>, Y = [F8<I>; WIDE]>>(isa: I, table: &'a TidalTable, t_final: f64, group: &[Case3d], opts: &LaneOptions, st: &mut S) -> [Outcome3d; WIDE_GROUP] {
    let n = group.len();
    let pick = |l: usize| group[l.min(n - 1)];
    let (k_a, ya) = vector_start(isa, pick);
    let (k, yb) = vector_start(isa, |l| pick(LANES + l));
    let a = Rigid { table, k: k_a, one: F8::splat(isa, 1.0), recent: Recent::new([f64::NAN; 6]) };
    let model = Wide { a, k };
    let mut y = [ya[0]; WIDE];
    y[..D].copy_from_slice(&ya);
    y[D..].copy_from_slice(&yb);
    st.begin();
    let run = run_steps(isa, st, &model, &mut y, t_final, opts, &mut NoCut);
    std::array::from_fn(|l| if l < LANES { outcome(pick(l), &y, 0, l, &run) } else { outcome(pick(l), &y, D, l - LANES, &run) })
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
        match (self.opts.method, group_size(I::LEVEL) > LANES) {
            (Method::Dp87, false) => self.with::<I, Stages<I, D, PrinceDormand>>(isa),
            (_, false) => self.with::<I, Stages<I, D, Fehlberg>>(isa),
            (Method::Dp87, true) => self.wide::<I, Stages<I, WIDE, PrinceDormand>, Stages<I, D, PrinceDormand>>(isa),
            (_, true) => self.wide::<I, Stages<I, WIDE, Fehlberg>, Stages<I, D, Fehlberg>>(isa),
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

    /// Groups of WIDE_GROUP in case order on two lane vectors; a chunk's last group of at most
    /// LANES on one.
    #[inline(always)]
    fn wide<I: Isa, W: Scheme<I, Wide<'a, I>, Y = [F8<I>; WIDE]>, S: Scheme<I, Rigid<'a, I>, Y = [F8<I>; D]>>(self, isa: I) -> Vec<Outcome3d> {
        let (mut st, mut narrow) = (W::new(isa), S::new(isa));
        let mut out = Vec::with_capacity(self.cases.len());
        for group in self.cases.chunks(WIDE_GROUP) {
            if group.len() > LANES {
                let r = integrate_wide::<I, W>(isa, self.table, self.t_final, group, self.opts, &mut st);
                out.extend_from_slice(&r[..group.len()]);
            } else {
                let r = integrate_group::<I, S>(isa, self.table, self.t_final, group, self.opts, &mut narrow);
                out.extend_from_slice(&r[..group.len()]);
            }
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
    // chunks are multiples of the level's group size, so the groups do not depend on chunking
    let group = group_size(level);
    let chunk = chunk.div_ceil(group) * group;
    let run = |part: &[Case3d]| {
        crate::interrupt::check()?;
        crate::simd::run_at(level, Groups3d { table, t_final, cases: part, opts })
    };
    let parts = with_threads(threads, || cases.par_chunks(chunk).map(run).collect::<Result<Vec<_>>>())??;
    Ok(parts.concat())
}
