//! Orbit data computed once per orbit and shared by every attitude trajectory on it, as piecewise
//! Chebyshev series over one period ([`OrbitTable`], N components): the gravity-gradient forcing
//! S(t), C(t) of the planar model (docs/physics.md, attitude, atan2-free form; [`OrbitForcing`],
//! N = 2) and the synodic-frame tidal tensor of both primaries of the 3-D model ([`TidalTable`],
//! N = 6, [`crate::attitude::tidal_tensor`]).
//!
//! The orbit is integrated once at tight tolerance and sampled at the Chebyshev nodes of every
//! segment (each sample an RK step from the enclosing accepted step, eight at a time on the SIMD
//! lanes; one integration serves every number of segments tried); the coefficients are the
//! exact interpolants at those nodes (the transform and the check below also run eight
//! segments or points at a time, bit for bit the scalar forms). The number of segments doubles until every component at
//! the segment quarter points, also sampled from the orbit, matches the series to `tol` relative
//! to the largest component magnitude, or until doubling no longer halves the error (the
//! samples' own integration noise, ~1e-13 on orbits grazing a primary) while it is below 1e-10.

use crate::attitude::{forcing_sc, tidal_tensor, Forcing};
use crate::cr3bp::{check_mu, Cr3bp};
use crate::error::{check_finite, check_positive, invalid, Error, Result};
use crate::integrate::tableau::{rkf78_stages, A, B8};
use crate::integrate::{Options, Output};
use crate::propagation::{propagate_checked, Collision};
use crate::scalar::{Field, F8};
use crate::simd::Isa;

/// Chebyshev degree per segment.
pub const DEGREE: usize = 12;
const NC: usize = DEGREE + 1;

/// Piecewise Chebyshev representation of N functions of the orbit over one period (periodic in t).
#[derive(Debug, Clone, PartialEq)]
pub struct OrbitTable<const N: usize> {
    pub period: f64,
    segments: usize,
    seg_len: f64,
    /// [segment][k][component].
    coef: Vec<f64>,
    /// Largest error measured at the check points, relative to `scale`.
    pub max_error: f64,
    /// The largest component magnitude over the samples.
    pub scale: f64,
}

/// Piecewise Chebyshev representation of S(t), C(t) over one orbit period (periodic in t).
pub type OrbitForcing = OrbitTable<2>;

/// The synodic-frame tidal tensor (xx, yy, zz, xy, xz, yz) of [`crate::attitude::tidal_tensor`]
/// over one orbit period (periodic in t): all the 3-D gravity-gradient torque needs of the orbit.
pub type TidalTable = OrbitTable<6>;

/// The orbit's accepted steps at the table's tolerance, and its states at any times of the period:
/// each a fresh RK step from the enclosing accepted step (the step's end when it falls there),
/// exactly as [`Output::At`] samples an integration, so a table's bits do not depend on which
/// other times were sampled. The samples are stepped eight at a time on the lanes, on the
/// calling thread (spread over the workers, the samples of a try, then 30-150 us of work, ran
/// slower after other work had left the workers asleep).
struct Sampled {
    mu: f64,
    t: Vec<f64>,
    states: Vec<f64>,
    level: crate::simd::Level,
}

impl Sampled {
    fn new(mu: f64, state0: &[f64; 6], period: f64, opts: &Options) -> Result<Self> {
        // an orbit through a primary (within the point-mass sphere) is a typed collision,
        // never a table of infinite values
        let tr = propagate_checked(mu, state0, 0.0, period, opts, false, Output::Steps, &[], &Collision::new([0.0, 0.0])?)?;
        if let Some(hit) = tr.collision {
            return Err(hit.error(tr.stats.accepted));
        }
        Ok(Self { mu, t: tr.t, states: tr.states, level: crate::simd::active()? })
    }

    fn state(&self, i: usize) -> [f64; 6] {
        std::array::from_fn(|k| self.states[6 * i + k])
    }

    /// The states at `times` (in [0, period]): each a fresh RK step from the start of its
    /// enclosing accepted step, eight at a time on the lanes ([`cr3bp_steps8`]), bit for bit
    /// the scalar stepper's.
    fn sample(&self, times: &[f64]) -> Vec<[f64; 6]> {
        let mut out = vec![[0.0; 6]; times.len()];
        // (sample, start step, step size) of every time strictly inside a step
        let mut steps: Vec<(usize, usize, f64)> = Vec::with_capacity(times.len());
        for (i, &te) in times.iter().enumerate() {
            // the step (t_i, t_{i+1}] that holds te
            let j = self.t.partition_point(|&x| x < te).min(self.t.len() - 1);
            if self.t[j] == te || j == 0 {
                out[i] = self.state(j);
            } else {
                steps.push((i, j - 1, te - self.t[j - 1]));
            }
        }
        struct Run<'a> {
            orbit: &'a Sampled,
            steps: &'a [(usize, usize, f64)],
            out: &'a mut [[f64; 6]],
        }
        impl crate::simd::Kernel for Run<'_> {
            type Output = ();
            #[inline(always)]
            fn run<I: Isa>(self, isa: I) {
                let sys = Cr3bp { mu: self.orbit.mu };
                for group in self.steps.chunks(8) {
                    // a short last group repeats its first step in the spare lanes
                    let at = |l: usize| group[if l < group.len() { l } else { 0 }];
                    let y: [F8<I>; 6] = std::array::from_fn(|c| F8::new(isa, std::array::from_fn(|l| self.orbit.states[6 * at(l).1 + c])));
                    let h = F8::new(isa, std::array::from_fn(|l| at(l).2));
                    let y8 = cr3bp_steps8(&sys, &y, h);
                    for (c, v) in y8.iter().enumerate() {
                        let v = v.to_array();
                        for (l, &(i, _, _)) in group.iter().enumerate() {
                            self.out[i][c] = v[l];
                        }
                    }
                }
            }
        }
        // the level was checked when the sampler was built
        crate::simd::run_at(self.level, Run { orbit: self, steps: &steps, out: &mut out }).expect("the sampler's SIMD level is available");
        out
    }
}

/// Eight RKF7(8) steps of the CR3BP at once: lane l from y[l] by h[l], its first stage the
/// derivative at y[l]. Each lane is bit for bit the 8th-order solution of the scalar stepper
/// ([`crate::integrate::stepper::Rkf78::step`]) at the level `I`: the same stage sums in the same
/// order, multiply-adds fused alike, and the one CR3BP right-hand side
/// ([`Cr3bp::derivative_of`]); IEEE division and square root round lanes as scalars.
#[inline(always)]
fn cr3bp_steps8<I: Isa>(sys: &Cr3bp, y: &[F8<I>; 6], h: F8<I>) -> [F8<I>; 6] {
    let mut k = [[h.cst_like(0.0); 6]; 13];
    k[0] = sys.derivative_of(y);
    macro_rules! stage {
        ($k:ident, $s:literal; $($j:literal),+) => {{
            let yt = stage_sum(y, h, &$k, &[$(A[$s][$j]),+], &[$($j),+]);
            $k[$s] = sys.derivative_of(&yt);
        }};
    }
    rkf78_stages!(stage!(k));
    stage_sum(y, h, &k, &[B8[5], B8[6], B8[7], B8[8], B8[9], B8[11], B8[12]], &[5, 6, 7, 8, 9, 11, 12])
}

/// y + h sum_m coef_m k[idx_m], as the scalar stepper's `lincomb` forms it (a function, not a
/// closure: a closure may be compiled outside the dispatched level's target features).
#[inline(always)]
fn stage_sum<I: Isa>(y: &[F8<I>; 6], h: F8<I>, k: &[[F8<I>; 6]; 13], coef: &[f64], idx: &[usize]) -> [F8<I>; 6] {
    let zero = h.cst_like(0.0);
    let mut out = [zero; 6];
    for i in 0..6 {
        let mut acc = zero;
        for m in 0..coef.len() {
            acc = h.cst_like(coef[m]).mul_add(k[idx[m]][i], acc);
        }
        out[i] = h.mul_add(acc, y[i]);
    }
    out
}

/// The discrete Chebyshev transform's weights cos(pi k (j + 1/2) / NC), [k][j].
fn cheb_weights() -> [[f64; NC]; NC] {
    std::array::from_fn(|k| std::array::from_fn(|j| (std::f64::consts::PI * k as f64 * (j as f64 + 0.5) / NC as f64).cos()))
}

fn cheb_nodes() -> [f64; NC] {
    std::array::from_fn(|j| (std::f64::consts::PI * (j as f64 + 0.5) / NC as f64).cos())
}

impl OrbitTable<2> {
    /// Tabulate the forcing of the planar orbit `state0` with period `period`; `primaries`
    /// selects the gravity-gradient sources [larger, smaller].
    pub fn new(mu: f64, state0: &[f64; 6], period: f64, primaries: [bool; 2], tol: f64) -> Result<Self> {
        check_mu(mu)?;
        check_finite("orbit_state", state0)?;
        if state0[2] != 0.0 || state0[5] != 0.0 {
            return Err(invalid("orbit_state", "the planar attitude model needs a planar orbit (z = zd = 0)"));
        }
        Self::fit(mu, state0, period, tol, |s| {
            let (a, b) = forcing_sc(mu, s, primaries);
            [a, b]
        })
    }

    /// S(t), C(t).
    #[inline]
    pub fn sc(&self, t: f64) -> (f64, f64) {
        let [s, c] = self.eval_with(t, crate::scalar::fmadd);
        (s, c)
    }

    /// S(t), C(t) with the multiply-adds of the instruction set `I` (the dispatched lane engine).
    #[inline(always)]
    pub fn sc_at<I: Isa>(&self, t: f64) -> (f64, f64) {
        let [s, c] = self.eval_with(t, I::mul_add);
        (s, c)
    }
}

impl OrbitTable<6> {
    /// Tabulate the tidal tensor of both primaries (or those `primaries` selects, [larger,
    /// smaller]) along the periodic orbit `state0` (planar or spatial) with period `period`.
    pub fn tidal(mu: f64, state0: &[f64; 6], period: f64, primaries: [bool; 2], tol: f64) -> Result<Self> {
        check_mu(mu)?;
        check_finite("orbit_state", state0)?;
        Self::fit(mu, state0, period, tol, |s| tidal_tensor(mu, &[s[0], s[1], s[2]], primaries))
    }
}

impl<const N: usize> OrbitTable<N> {
    /// Fit the N functions `g` of the orbit state along the orbit `state0` over one `period`.
    pub fn fit(mu: f64, state0: &[f64; 6], period: f64, tol: f64, g: impl Fn(&[f64]) -> [f64; N]) -> Result<Self> {
        check_mu(mu)?;
        check_finite("orbit_state", state0)?;
        check_positive("period", period)?;
        check_positive("tol", tol)?;
        let opts = Options::with_tolerances(1e-14, 1e-14);
        let nodes = cheb_nodes();
        let weights = cheb_weights();
        // one integration serves every try: its accepted steps are the same whatever is sampled
        let orbit = Sampled::new(mu, state0, period, &opts)?;
        // one try: the table with `segments` segments and its error at the check points
        let attempt = |segments: usize| -> Self {
            let seg_len = period / segments as f64;
            // sample times: nodes of every segment, then the check points (1/4, 1/2, 3/4)
            let mut times = Vec::with_capacity(segments * (NC + 3));
            for s in 0..segments {
                let a = s as f64 * seg_len;
                for j in (0..NC).rev() {
                    times.push(a + 0.5 * seg_len * (nodes[j] + 1.0));
                }
            }
            let n_fit = times.len();
            for s in 0..segments {
                let a = s as f64 * seg_len;
                for q in [0.25, 0.5, 0.75] {
                    times.push(a + q * seg_len);
                }
            }
            let (mut fit_t, mut check_t): (Vec<f64>, Vec<f64>) = (times[..n_fit].to_vec(), times[n_fit..].to_vec());
            fit_t.sort_by(f64::total_cmp);
            check_t.sort_by(f64::total_cmp);
            let fit: Vec<[f64; N]> = orbit.sample(&fit_t).iter().map(|s| g(s)).collect();
            let check: Vec<[f64; N]> = orbit.sample(&check_t).iter().map(|s| g(s)).collect();
            // the largest magnitude, one running maximum per component (exact in any order; the
            // values are finite, a comparison rather than f64::max's NaN handling)
            let mut top = [0.0f64; N];
            for v in fit.iter().chain(check.iter()) {
                for (m, x) in top.iter_mut().zip(v) {
                    let a = x.abs();
                    *m = if a > *m { a } else { *m };
                }
            }
            let scale = top.iter().fold(0.0f64, |m, &x| m.max(x));
            let coef = crate::simd::run_at(orbit.level, Transform { fit: &fit, weights: &weights, segments }).expect("the sampler's SIMD level is available");
            let mut table = Self { period, segments, seg_len, coef, max_error: 0.0, scale };
            let err = crate::simd::run_at(orbit.level, CheckError { table: &table, times: &check_t, values: &check }).expect("the sampler's SIMD level is available");
            table.max_error = err / scale;
            table
        };
        // the tries double the segments from 16 until one passes
        let mut segments = 16;
        let mut previous = f64::INFINITY;
        loop {
            let table = attempt(segments);
            let at_noise_floor = table.max_error < 1e-10 && table.max_error > 0.5 * previous;
            if table.max_error <= tol || at_noise_floor {
                return Ok(table);
            }
            previous = table.max_error;
            if segments >= 1 << 16 {
                return Err(Error::Convergence { what: "orbit table (segments)", iterations: segments, residual: table.max_error, tolerance: tol });
            }
            segments *= 2;
        }
    }

    pub fn segments(&self) -> usize {
        self.segments
    }

    /// Segment index and local coordinate in [-1, 1] of time t (reduced modulo the period).
    #[inline(always)]
    fn locate(&self, t: f64) -> (usize, f64) {
        let tm = t - (t / self.period).floor() * self.period;
        let u = tm / self.seg_len;
        let s = (u as usize).min(self.segments - 1);
        (s, 2.0 * (u - s as f64) - 1.0)
    }

    /// The N components at time t.
    #[inline]
    pub fn eval(&self, t: f64) -> [f64; N] {
        self.eval_with(t, crate::scalar::fmadd)
    }

    /// The N components at time t with the multiply-adds of the instruction set `I`.
    #[inline(always)]
    pub fn eval_at<I: Isa>(&self, t: f64) -> [f64; N] {
        self.eval_with(t, I::mul_add)
    }

    /// Clenshaw's recurrence on every component.
    #[inline(always)]
    fn eval_with(&self, t: f64, fma: impl Fn(f64, f64, f64) -> f64) -> [f64; N] {
        let (s, x) = self.locate(t);
        let c = &self.coef[s * NC * N..(s + 1) * NC * N];
        clenshaw(x, 2.0 * x, 0.0, FromFn(|j| c[j]), fma)
    }

    /// The N components at eight times at once on the lanes of `isa`: the same values as
    /// [`Self::eval_at`] at each, bit for bit (the same operations per lane). One vector
    /// Clenshaw recurrence when the times lie in at most three segments (a Runge-Kutta step's
    /// nodes, unless the step spans more than two segments), the coefficients chosen per lane;
    /// otherwise one scalar evaluation per time.
    #[inline(always)]
    pub fn eval8_at<I: Isa>(&self, isa: I, ts: &[f64; 8]) -> [[f64; N]; 8] {
        match self.try_eval8_at(isa, ts) {
            Some(v) => v,
            None => {
                let mut out = [[0.0; N]; 8];
                for l in 0..8 {
                    out[l] = self.eval_at::<I>(ts[l]);
                }
                out
            }
        }
    }

    /// [`Self::locate`] on the lanes: each lane's segment (as f64) and local coordinate, the
    /// scalar form's operations lane by lane (`u as usize` saturates at 0, NaN to 0: the max with
    /// 0, which gives 0 for NaN; then the min with the last segment).
    #[inline(always)]
    fn locate8<I: Isa>(&self, isa: I, ts: &[f64; 8]) -> (F8<I>, F8<I>) {
        let (t, period) = (F8::new(isa, *ts), F8::splat(isa, self.period));
        let tm = t - (t / period).floor() * period;
        let u = tm / F8::splat(isa, self.seg_len);
        let last = F8::splat(isa, (self.segments - 1) as f64);
        let s0 = u.floor().max(F8::splat(isa, 0.0));
        let s = s0.le_select(last, s0, last);
        (s, F8::splat(isa, 2.0) * (u - s) - F8::splat(isa, 1.0))
    }

    /// [`Self::eval8_at`]'s vector recurrence, or None when the times lie in more than three
    /// segments (the caller then evaluates each time where it needs it).
    #[inline(always)]
    pub fn try_eval8_at<I: Isa>(&self, isa: I, ts: &[f64; 8]) -> Option<[[f64; N]; 8]> {
        // loops, not array::from_fn / map: their closures were compiled out of line, outside the
        // lanes' target features, and called at every step
        let (seg, x) = self.locate8(isa, ts);
        let segs = seg.to_array();
        // the distinct segments, ascending: at most three
        let mut d = [segs[0]; 3];
        let mut nd = 1;
        for &sl in &segs[1..] {
            if (0..nd).any(|k| d[k] == sl) {
                continue;
            }
            if nd == 3 {
                return None;
            }
            d[nd] = sl;
            nd += 1;
        }
        // sorted by hand (segment numbers: no NaN), not by a library sort called out of line
        for (a, b) in [(0, 1), (1, 2), (0, 1)] {
            if b < nd && d[b] < d[a] {
                d.swap(a, b);
            }
        }
        let block = |s: f64| {
            let s = s as usize;
            &self.coef[s * NC * N..(s + 1) * NC * N]
        };
        let blocks = [block(d[0]), block(d[nd.min(2) - 1]), block(d[nd - 1])];
        let dv = [F8::splat(isa, d[0]), F8::splat(isa, d[1])];
        let (x2, zero) = (F8::splat(isa, 2.0) * x, F8::splat(isa, 0.0));
        let fma = |a: F8<I>, b: F8<I>, c: F8<I>| a.mul_add(b, c);
        let v: [F8<I>; N] = match nd {
            1 => clenshaw(x, x2, zero, Segments::<I, 1> { seg, d: dv, blocks }, fma),
            2 => clenshaw(x, x2, zero, Segments::<I, 2> { seg, d: dv, blocks }, fma),
            _ => clenshaw(x, x2, zero, Segments::<I, 3> { seg, d: dv, blocks }, fma),
        };
        let mut out = [[0.0; N]; 8];
        for i in 0..N {
            let vi = v[i].to_array();
            for l in 0..8 {
                out[l][i] = vi[l];
            }
        }
        Some(out)
    }
}

/// The discrete Chebyshev transform of every segment's samples at the nodes (`fit`: segment s
/// holds samples s NC .. (s + 1) NC in increasing time, i.e. nodes j = NC - 1 .. 0):
/// coef[s][k][i] = f_k sum_jj fit[s NC + jj][i] w[k][NC - 1 - jj], eight segments at a time on
/// the lanes, each sum formed in jj order by separate multiplies and adds, as for one segment
/// alone (the same bits at every level).
struct Transform<'a, const N: usize> {
    fit: &'a [[f64; N]],
    weights: &'a [[f64; NC]; NC],
    segments: usize,
}

impl<const N: usize> crate::simd::Kernel for Transform<'_, N> {
    type Output = Vec<f64>;
    #[inline(always)]
    fn run<I: Isa>(self, isa: I) -> Vec<f64> {
        let mut coef = vec![0.0; self.segments * NC * N];
        let zero = F8::splat(isa, 0.0);
        for s0 in (0..self.segments).step_by(8) {
            let m = (self.segments - s0).min(8);
            // the lanes' samples, [jj][i] (spare lanes zero)
            let mut x = [[zero; N]; NC];
            for (jj, xj) in x.iter_mut().enumerate() {
                for (i, xji) in xj.iter_mut().enumerate() {
                    let mut v = [0.0; 8];
                    for (l, vl) in v.iter_mut().enumerate().take(m) {
                        *vl = self.fit[(s0 + l) * NC + jj][i];
                    }
                    *xji = F8::new(isa, v);
                }
            }
            for k in 0..NC {
                let f = F8::splat(isa, if k == 0 { 1.0 } else { 2.0 } / NC as f64);
                for i in 0..N {
                    let mut c = zero;
                    for (jj, xj) in x.iter().enumerate() {
                        c += xj[i] * F8::splat(isa, self.weights[k][NC - 1 - jj]);
                    }
                    let v = (c * f).to_array();
                    for (l, &vl) in v.iter().enumerate().take(m) {
                        coef[((s0 + l) * NC + k) * N + i] = vl;
                    }
                }
            }
        }
        coef
    }
}

/// The largest |table(t) - value| over the check points, eight times at a time on the lanes:
/// each lane's Clenshaw recurrence as [`OrbitTable::eval`] forms it ([`fmadd8`]), its
/// coefficients those of its own segment (the same bits at every level).
struct CheckError<'a, const N: usize> {
    table: &'a OrbitTable<N>,
    times: &'a [f64],
    values: &'a [[f64; N]],
}

impl<const N: usize> crate::simd::Kernel for CheckError<'_, N> {
    type Output = f64;
    #[inline(always)]
    fn run<I: Isa>(self, isa: I) -> f64 {
        let tb = self.table;
        let mut err = 0.0f64;
        for (ts, vs) in self.times.chunks(8).zip(self.values.chunks(8)) {
            let (mut xs, mut base) = ([0.0; 8], [0usize; 8]);
            for (l, &t) in ts.iter().enumerate() {
                let (s, x) = tb.locate(t);
                (base[l], xs[l]) = (s * NC * N, x);
            }
            // spare lanes repeat lane 0's point
            for l in ts.len()..8 {
                (base[l], xs[l]) = (base[0], xs[0]);
            }
            let x = F8::new(isa, xs);
            let coef = |j: usize| {
                let mut c = [0.0; 8];
                for (cl, &b) in c.iter_mut().zip(&base) {
                    *cl = tb.coef[b + j];
                }
                F8::new(isa, c)
            };
            let v: [F8<I>; N] = clenshaw(x, F8::splat(isa, 2.0) * x, F8::splat(isa, 0.0), FromFn(coef), fmadd8);
            for (i, vi) in v.iter().enumerate() {
                let a = vi.to_array();
                for (l, w) in vs.iter().enumerate() {
                    err = err.max((a[l] - w[i]).abs());
                }
            }
        }
        err
    }
}

/// [`crate::scalar::fmadd`] on the lanes, lane by lane the same rounding: fused where the build's
/// scalar multiply-add fuses, else a multiply and an add.
#[inline(always)]
fn fmadd8<I: Isa>(a: F8<I>, b: F8<I>, c: F8<I>) -> F8<I> {
    if cfg!(any(target_feature = "fma", target_arch = "aarch64")) {
        if I::FMA {
            a.mul_add(b, c)
        } else {
            let (x, y, z) = (a.to_array(), b.to_array(), c.to_array());
            let mut r = [0.0; 8];
            for l in 0..8 {
                r[l] = x[l].mul_add(y[l], z[l]);
            }
            F8::new(a.isa(), r)
        }
    } else {
        a * b + c
    }
}

/// Coefficient j of a series in [`clenshaw`]'s layout. A trait with always-inlined methods, not a
/// closure: the compiler may leave a closure out of line, outside the lanes' target features,
/// with their intrinsics called there.
trait Coefs<T> {
    fn coef(&self, j: usize) -> T;
}

/// Coefficients from a closure (scalar evaluations; the table check's gathered lanes).
struct FromFn<F>(F);

impl<T, F: Fn(usize) -> T> Coefs<T> for FromFn<F> {
    #[inline(always)]
    fn coef(&self, j: usize) -> T {
        (self.0)(j)
    }
}

/// Each lane's coefficient from its own segment among K = 1, 2 or 3 (`blocks`, ascending segment
/// numbers; the lanes' segment numbers `seg`, the first two blocks' numbers `d`): a broadcast,
/// or one or two lane-wise choices.
struct Segments<'a, I, const K: usize> {
    seg: F8<I>,
    d: [F8<I>; 2],
    blocks: [&'a [f64]; 3],
}

impl<I: Isa, const K: usize> Coefs<F8<I>> for Segments<'_, I, K> {
    #[inline(always)]
    fn coef(&self, j: usize) -> F8<I> {
        let isa = self.seg.isa();
        let [a, b, c] = self.blocks;
        match K {
            1 => F8::splat(isa, a[j]),
            2 => self.seg.le_select(self.d[0], F8::splat(isa, a[j]), F8::splat(isa, c[j])),
            _ => self.seg.le_select(self.d[0], F8::splat(isa, a[j]), self.seg.le_select(self.d[1], F8::splat(isa, b[j]), F8::splat(isa, c[j]))),
        }
    }
}

/// Clenshaw's recurrence for the N components of one segment at x (x2 = 2 x), on a scalar or on
/// the lanes: coefficient j of the segment's [k][component] layout from `coef`, `fma(a, b, c)`
/// = a b + c.
#[inline(always)]
fn clenshaw<T: Copy + std::ops::Sub<Output = T>, const N: usize>(x: T, x2: T, zero: T, coef: impl Coefs<T>, fma: impl Fn(T, T, T) -> T) -> [T; N] {
    // component by component: two running values live, not 2 N (on the lanes, 2 N vectors
    // would not fit the registers); the components' recurrences are independent, so the order
    // changes no bit. Loops, not array::from_fn: its closure would be compiled outside the
    // lanes' target features, and their intrinsics called out of line
    let mut out = [zero; N];
    for (i, o) in out.iter_mut().enumerate() {
        let (mut b1, mut b2) = (zero, zero);
        for k in (1..NC).rev() {
            let tk = fma(x2, b1, coef.coef(N * k + i) - b2);
            b2 = b1;
            b1 = tk;
        }
        *o = fma(x, b1, coef.coef(i) - b2);
    }
    out
}

impl Forcing for OrbitTable<2> {
    fn sc(&self, t: f64) -> (f64, f64) {
        OrbitTable::<2>::sc(self, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sampler against one integration with `Output::At` (what the fit sampled before it
    /// integrated once for all its tries): the same states bit for bit, at node-like times, at
    /// t0, and at accepted steps' ends. Reference: the driver's own output; tolerance: exact.
    #[test]
    fn samples_equal_the_drivers_output_at_those_times() {
        let mu = 0.012150585609624;
        // a DRO of the Earth-Moon system (x0 = 0.70), one period
        let s0 = [0.70, 0.0, 0.0, 0.0, 0.7886786873660538, 0.0];
        let period = 4.8;
        let opts = Options::with_tolerances(1e-14, 1e-14);
        let orbit = Sampled::new(mu, &s0, period, &opts).unwrap();
        let mut ts: Vec<f64> = (0..997).map(|i| period * (i as f64 / 997.0).powf(1.3)).collect();
        ts.extend_from_slice(&orbit.t[1..orbit.t.len() - 1][..5]);
        ts.sort_by(f64::total_cmp);
        let want = propagate_checked(mu, &s0, 0.0, period, &opts, false, Output::At(&ts), &[], &Collision::new([0.0, 0.0]).unwrap()).unwrap();
        let got = orbit.sample(&ts);
        assert_eq!(got.len(), ts.len());
        for (i, (g, w)) in got.iter().zip(want.states.chunks_exact(6)).enumerate() {
            assert_eq!(g.as_slice(), w, "sample {i} at t = {}", ts[i]);
        }
    }

    /// The lanes' Chebyshev transform and check error at every SIMD level this CPU has, against
    /// one segment and one point at a time in scalar code (the test's reference: the sums in the
    /// same order, the check by `eval`), on 21 segments and 61 check points of a smooth function
    /// (three spare lanes in the last group of each). Tolerance: exact.
    #[test]
    fn lane_transform_and_check_equal_the_scalar_forms() {
        let segments = 21;
        let nodes = cheb_nodes();
        let weights = cheb_weights();
        let g = |t: f64| [(1.3 * t).sin() + 0.1 * t * t, (0.7 * t).cos() / (1.0 + 0.2 * t)];
        let (period, seg_len) = (5.0, 5.0 / segments as f64);
        let fit: Vec<[f64; 2]> = (0..segments).flat_map(|s| (0..NC).rev().map(move |j| s as f64 * seg_len + 0.5 * seg_len * (nodes[j] + 1.0))).map(g).collect();
        let check_t: Vec<f64> = (0..3 * segments - 2).map(|i| (i as f64 + 0.41) * period / (3 * segments) as f64).collect();
        let check: Vec<[f64; 2]> = check_t.iter().map(|&t| g(t)).collect();
        let mut want = vec![0.0; segments * NC * 2];
        for s in 0..segments {
            for k in 0..NC {
                let mut cs = [0.0; 2];
                for jj in 0..NC {
                    for (c, x) in cs.iter_mut().zip(&fit[s * NC + jj]) {
                        *c += x * weights[k][NC - 1 - jj];
                    }
                }
                let f = if k == 0 { 1.0 } else { 2.0 } / NC as f64;
                for (i, c) in cs.iter().enumerate() {
                    want[(s * NC + k) * 2 + i] = c * f;
                }
            }
        }
        for level in crate::simd::available() {
            let coef = crate::simd::run_at(level, Transform { fit: &fit, weights: &weights, segments }).unwrap();
            assert_eq!(coef, want, "level {level}");
            let table = OrbitTable::<2> { period, segments, seg_len, coef, max_error: 0.0, scale: 1.0 };
            let err = crate::simd::run_at(level, CheckError { table: &table, times: &check_t, values: &check }).unwrap();
            let want_err = check_t.iter().zip(&check).fold(0.0f64, |m, (&t, v)| {
                let a = table.eval(t);
                m.max((a[0] - v[0]).abs()).max((a[1] - v[1]).abs())
            });
            assert_eq!(err.to_bits(), want_err.to_bits(), "level {level}: {err} vs {want_err}");
            assert!(err > 0.0 && err < 1e-6, "{err}");
        }
    }

    /// The lanes' samples at every SIMD level this CPU has, against the scalar stepper at that
    /// level (the test's reference: one RKF7(8) step from the enclosing accepted step, its
    /// derivative primed there), on a 3-D halo-like orbit and on a DRO, with a short last group
    /// of lanes. Tolerance: exact.
    #[test]
    fn lane_samples_equal_the_scalar_stepper_at_every_level() {
        use crate::integrate::stepper::Rkf78;
        let mu = 0.012150585609624;
        let orbits = [([0.70, 0.0, 0.0, 0.0, 0.7886786873660538, 0.0], 4.8), ([1.12, 0.0, 0.03, 0.0, 0.18, 0.0], 3.4)];
        let opts = Options::with_tolerances(1e-14, 1e-14);
        for (s0, period) in orbits {
            for level in crate::simd::available() {
                let mut orbit = Sampled::new(mu, &s0, period, &opts).unwrap();
                orbit.level = level;
                let ts: Vec<f64> = (0..203).map(|i| period * (i as f64 + 0.37) / 203.5).collect();
                let got = orbit.sample(&ts);
                let sys = Cr3bp { mu };
                let mut st = Rkf78::new(&[0.0; 6], level);
                for (i, &te) in ts.iter().enumerate() {
                    let j = orbit.t.partition_point(|&x| x < te);
                    let (ti, yi) = (orbit.t[j - 1], orbit.state(j - 1));
                    let mut want = [0.0; 6];
                    st.prime(&sys, ti, &yi);
                    st.step(&sys, ti, &yi, te - ti, &mut want, 1e-14, 1e-14);
                    assert_eq!(got[i], want, "level {level}, sample {i} at t = {te}");
                }
            }
        }
    }

    /// The lanes' evaluation at eight times ([`OrbitTable::eval8_at`]: one vector recurrence over
    /// up to three segments, else one scalar evaluation per time) equals the scalar
    /// [`OrbitTable::eval_at`] at each time bit for bit, at every SIMD level this CPU has, on a
    /// six-component table: a step's nodes inside one segment, over two, three (also across the
    /// period's end) and four segments, at the period's start and end, and a NaN time.
    /// Reference: the scalar form; tolerance: exact.
    #[test]
    fn eval8_equals_the_scalar_form_bit_for_bit() {
        let (segments, period) = (7, 3.3);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let coef: Vec<f64> = (0..segments * NC * 6)
            .map(|_| {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let table = OrbitTable::<6> { period, segments, seg_len: period / segments as f64, coef, max_error: 0.0, scale: 1.0 };
        let seg = table.seg_len;
        // a step's eight inner nodes (RKF7(8)'s) at t + c h: (t, h, segments spanned)
        let nodes = [2.0 / 27.0, 1.0 / 9.0, 1.0 / 6.0, 5.0 / 12.0, 0.5, 5.0 / 6.0, 2.0 / 3.0, 1.0 / 3.0];
        let steps = [(1.1 * seg, 0.3 * seg, 1), (1.9 * seg, 0.4 * seg, 2), (0.5 * seg, 2.0 * seg, 3), (period - 1.3 * seg, 1.8 * seg, 3), (0.5 * seg, 3.5 * seg, 4)];
        let mut cases: Vec<([f64; 8], Option<usize>)> = steps.iter().map(|&(t, h, n)| (nodes.map(|c: f64| c.mul_add(h, t)), Some(n))).collect();
        cases.push(([0.0, period, 2.0 * period, 1e-300, period - 1e-15, 0.5 * period, period + 1e-15, 7.0 * period + 0.1], None));
        cases.push(([f64::NAN, 0.1, 0.2, 0.3, 0.1, 0.2, 0.3, 0.1], None));
        use crate::simd::Kernel;
        struct Probe<'a>(&'a OrbitTable<6>, Vec<([f64; 8], Option<usize>)>);
        impl Kernel for Probe<'_> {
            type Output = ();
            fn run<I: Isa>(self, isa: I) {
                for (ts, spanned) in &self.1 {
                    let got = self.0.eval8_at(isa, ts);
                    for l in 0..8 {
                        let want = self.0.eval_at::<I>(ts[l]);
                        // a NaN's payload is not compared (which operand's it keeps is the instruction's choice)
                        let bits = |v: [f64; 6]| v.map(|x| if x.is_nan() { u64::MAX } else { x.to_bits() });
                        assert_eq!(bits(got[l]), bits(want), "{}: lane {l} at t = {}", I::LEVEL, ts[l]);
                    }
                    if let Some(n) = *spanned {
                        assert_eq!(self.0.try_eval8_at(isa, ts).is_some(), n <= 3, "{}: {n} segments", I::LEVEL);
                    }
                }
            }
        }
        for &level in &crate::simd::available() {
            crate::simd::run_at(level, Probe(&table, cases.clone())).unwrap();
        }
    }
}
