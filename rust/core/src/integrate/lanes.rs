//! The attitude periodicity engine's integrator: RKF7(8) on eight trajectories at once in SIMD
//! lanes ([`F8`]: 4 x SSE2, 2 x AVX2 or 1 x AVX-512 registers, the level dispatched at run time by
//! [`crate::simd`]), in lock step: the eight share the time
//! and the step size (the smallest any of them needs), each with its own state, Kz and SRP
//! parameters.
//!
//! Why lock step: the planar model's only orbit input is the forcing S(t), C(t), tabulated once
//! per orbit. With a time per lane, every stage had to gather four lanes' table coefficients,
//! and that gather took about 76 % of the stage time (measured: 62 ns per 4-lane stage, 15 ns
//! with the lookup removed). With a shared time the forcing is one scalar Chebyshev sum per
//! stage, broadcast to the lanes, and so is the Sun's direction for SRP
//! (cos(w t + theta0_l) from one scalar sin_cos and each lane's (cos theta0_l, sin theta0_l)).
//! Trajectories are grouped in case order from the start of the slice (the caller aligns slices
//! to multiples of the group size, [`group_size`]), so a trajectory's result depends only on its
//! group, never on chunking or thread count: results are bit-identical for any of them.
//!
//! The gravity map without the STM (the periodicity map's hot path) groups sixteen trajectories
//! on two lane vectors ([`GROUP`]; a slice's last group of at most eight on one): its lanes need
//! the same steps (the orbit's forcing sets them: 74.9 steps a trajectory in groups of sixteen,
//! 74.6 in groups of eight, 2000 rates at rtol 2e-12), so the orbit data and the step control
//! of one step serve sixteen, and the two vectors' stage arithmetic is independent work for the
//! CPU to overlap: 1.43x faster at the AVX-512 level and 1.26x at AVX2 than groups of eight,
//! 4 % slower at the SSE2 baseline (whose sixteen registers the second vector overflows; the
//! grouping is the same at every level, so that levels still differ only by the rounding of
//! fused multiply-adds). Everything else (the STM, SRP, the sensitivities, the other methods)
//! runs in groups of eight: its batches are small (a corrector's candidates) or its lanes'
//! steps differ (SRP's terminator cuts).
//!
//! State per lane: (phi, wz, cos phi, sin phi) and, with the STM, the 2x2 d(phi, wz)/d(phi0,
//! wz0) row-major. Carrying (cos phi, sin phi) as states (d/dt = phidot (-sin, cos)) removes the
//! trigonometric calls of the gravity gradient (cos 2phi = c^2 - s^2, sin 2phi = 2 c s); phi
//! itself is integrated (phidot = wz - 1) and gives the unwrapped phi(T); the right-hand side
//! never reads it, so the stages form only the other components ([`Rhs::READS`]: 9 % faster at
//! AVX2, 2-3 % at AVX-512, the same bits). The flat-plate SRP
//! law (docs/physics.md, solar radiation pressure) is C1 only: a step never spans a lane's Sun-terminator crossing
//! (cos(theta_sun - phi) = 0); the step is cut just past it ([`CUT_TOL`]: a Hermite first guess,
//! then Newton on cos alpha along trial steps).
//!
//! Nothing of the physics or the step control is written here: the lanes call the laws the
//! scalar planar model calls ([`gravity_gradient_wzdot`], [`flat_plate_wzdot`], [`Sun::angle`],
//! generic over the lane type) and step with the scalar driver's [`Controller`] and tableau.

use super::forcing::OrbitForcing;
use crate::attitude::{flat_plate_wzdot, forcing_sc, gravity_gradient_wzdot, FlatPlate, Sun};
use crate::attitude::planar::orbit_derivative;
use crate::constants::SOLAR_PRESSURE_1AU;
use crate::integrate::rkn::{A as RKN_A, B as RKN_B, BP as RKN_BP, BPT as RKN_BPT, BT as RKN_BT, C as RKN_C, ERROR_ORDER as RKN_ERROR_ORDER, STAGES as RKN_STAGES};
use crate::integrate::tableau::dp87::{dp87_stages, A as DP_A, B8 as DP_B8, C as DP_C, E as DP_E};
use crate::integrate::tableau::{rkf78_stages, A, B8, C, ERR};
use crate::integrate::Controller;
use crate::scalar::F8;
use crate::error::{IntegrationError, Result};
use crate::simd::{Isa, Kernel, Level};

/// The scalar driver's step-size controller with its default settings.
const CONTROLLER: Controller = Controller::RKF78;

/// Trajectories per lane vector (SIMD width).
pub const LANES: usize = 8;

/// Trajectories per lock-step group of the wide path ([`group_size`]).
pub const GROUP: usize = 2 * LANES;

/// Whether [`integrate_cases`] takes the wide path: groups of [`GROUP`] trajectories on two lane
/// vectors, one step size and one orbit evaluation per stage for all sixteen. It is the gravity
/// map's (RKF7(8), no STM, no SRP, no parameter sensitivity); everything else runs in groups of
/// [`LANES`].
pub fn wide(with_stm: bool, srp: bool, opts: &LaneOptions) -> bool {
    !with_stm && !srp && opts.method == Method::Rkf78 && opts.sensitivity == Sensitivity::None
}

/// The lock-step group size of [`integrate_cases`] for these arguments: callers align the slices
/// they pass to multiples of it, so that the groups, and the results, do not depend on chunking.
pub fn group_size(with_stm: bool, srp: bool, opts: &LaneOptions) -> usize {
    if wide(with_stm, srp, opts) {
        GROUP
    } else {
        LANES
    }
}

/// One attitude trajectory of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    pub phi0: f64,
    /// Inertial initial rate.
    pub wz0: f64,
    pub kz: f64,
    /// Flat-plate SRP amplitude (0: gravity only), its coefficients and the Sun's initial phase.
    pub eps: f64,
    pub cs: f64,
    pub cd: f64,
    pub theta_sun0: f64,
}

impl Case {
    /// A gravity-gradient-only trajectory.
    pub fn new(phi0: f64, wz0: f64, kz: f64) -> Self {
        Self { phi0, wz0, kz, eps: 0.0, cs: 0.0, cd: 0.0, theta_sun0: 0.0 }
    }

    /// The case's flat plate (not validated; eps = 0: none) with the Sun turning at `sun_omega`.
    pub fn plate(&self, sun_omega: f64) -> FlatPlate {
        FlatPlate { eps: self.eps, cs: self.cs, cd: self.cd, sun: Sun { theta0: self.theta_sun0, omega: sun_omega, pressure: SOLAR_PRESSURE_1AU } }
    }
}

/// How a trajectory ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum LaneStatus {
    Ok = 0,
    MaxSteps = 1,
    /// Non-finite state or step-size underflow.
    Failed = 2,
}

/// The end state of one trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Unwrapped phi at the final time.
    pub phi_t: f64,
    pub wz_t: f64,
    /// d(phi, wz)(T) / d(phi0, wz0), row-major (NaN when not computed).
    pub stm: [f64; 4],
    /// d(phi, wz)(T) / d parameter for [`LaneOptions::sensitivity`] (NaN when not computed).
    pub dparam: [f64; 2],
    pub accepted: u32,
    pub rejected: u32,
    pub status: LaneStatus,
}

/// Tolerances and limits of the lane integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneOptions {
    pub rtol: f64,
    pub atol: f64,
    pub max_steps: u32,
    /// Rate of the Sun direction in the synodic frame (1/TU), for SRP cases.
    pub sun_omega: f64,
    pub method: Method,
    /// With the STM, also d(phi, wz)(T) / d parameter ([`Outcome::dparam`]) from the
    /// variational equation: the torques are linear in Kz and in the plate amplitude eps, so
    /// the sensitivity is integrated exactly (RKF7(8) lanes; the continuation's bordered
    /// corrections use it instead of two finite-difference trajectories).
    pub sensitivity: Sensitivity,
}

/// The parameter of [`Outcome::dparam`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sensitivity {
    #[default]
    None,
    Kz,
    Eps,
}

impl Default for LaneOptions {
    fn default() -> Self {
        Self { rtol: 1e-12, atol: 1e-12, max_steps: 200_000, sun_omega: crate::constants::OMEGA_SUN, method: Method::default(), sensitivity: Sensitivity::None }
    }
}

/// The lanes' integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Runge-Kutta-Fehlberg 7(8) on (phi, wz, cos phi, sin phi): the reference and the default.
    #[default]
    Rkf78,
    /// Runge-Kutta-Nyström 8(6) on phi'' = wzdot(t, phi) ([`crate::integrate::rkn`]).
    Rkn86,
    /// Prince and Dormand's RK8(7)13M on the RKF7(8) states
    /// ([`crate::integrate::tableau::dp87`]).
    Dp87,
}

impl Method {
    /// "rkf78", "rkn86" or "dp87".
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "rkf78" => Some(Self::Rkf78),
            "rkn86" => Some(Self::Rkn86),
            "dp87" => Some(Self::Dp87),
            _ => None,
        }
    }

    /// The name [`Self::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Self::Rkf78 => "rkf78",
            Self::Rkn86 => "rkn86",
            Self::Dp87 => "dp87",
        }
    }
}

/// Per-lane parameters and the stage's shared forcing.
#[derive(Clone, Copy)]
struct Params<I> {
    kz15: F8<I>,
    /// The plate law's coefficients (FlatPlate::coefficients), cos and sin of the Sun phase
    /// at t = 0.
    a1: F8<I>,
    a2: F8<I>,
    c0: F8<I>,
    s0: F8<I>,
    /// The parameter sensitivity's forcing, d wzdot / d parameter at fixed phi: 1.5 (S c2 - C s2)
    /// times `gk` (1 for Kz) plus the plate law with the unit-amplitude coefficients (`u1`, `u2`;
    /// zero unless eps).
    gk: F8<I>,
    u1: F8<I>,
    u2: F8<I>,
    /// The Sun with phase zero: its angle at the shared time, turned by each lane's phase.
    sun: Sun,
}

impl<I: Isa> Params<I> {
    /// The lanes' parameters and their cases' plates.
    fn new(isa: I, pick: impl Fn(usize) -> Case, sun_omega: f64, sensitivity: Sensitivity) -> (Self, [FlatPlate; LANES]) {
        let plates: [FlatPlate; LANES] = std::array::from_fn(|l| pick(l).plate(sun_omega));
        let unit = |l: usize| if sensitivity == Sensitivity::Eps { FlatPlate { eps: 1.0, ..plates[l] }.coefficients() } else { (0.0, 0.0) };
        let p = Params {
            kz15: F8::new(isa, std::array::from_fn(|l| 1.5 * pick(l).kz)),
            a1: F8::new(isa, std::array::from_fn(|l| plates[l].coefficients().0)),
            a2: F8::new(isa, std::array::from_fn(|l| plates[l].coefficients().1)),
            c0: F8::new(isa, std::array::from_fn(|l| plates[l].sun.theta0.cos())),
            s0: F8::new(isa, std::array::from_fn(|l| plates[l].sun.theta0.sin())),
            gk: F8::splat(isa, if sensitivity == Sensitivity::Kz { 1.5 } else { 0.0 }),
            u1: F8::new(isa, std::array::from_fn(|l| unit(l).0)),
            u2: F8::new(isa, std::array::from_fn(|l| unit(l).1)),
            sun: Sun { theta0: 0.0, ..plates[0].sun },
        };
        (p, plates)
    }
}

/// out = y + h sum_m coef[m] ks[m], for the components i with `wanted[i]` (the others of `out`
/// are left as they are).
#[inline(always)]
fn lincomb<I: Isa, const D: usize, const M: usize>(out: &mut [F8<I>; D], y: &[F8<I>; D], h: F8<I>, coef: [f64; M], ks: [&[F8<I>; D]; M], wanted: &[bool; D]) {
    let isa = h.isa();
    // term by term across the components: each coefficient broadcast once for all D of them
    // (the D accumulators stay in registers); per component the same operations in the same
    // order as a sum per component
    // the first term a product: c k + 0 with one or two roundings is c k rounded, but for the
    // sign of a zero product, which the following terms or y absorb
    let mut acc = [F8::splat(isa, 0.0); D];
    let c = F8::splat(isa, coef[0]);
    for i in 0..D {
        if wanted[i] {
            acc[i] = c * ks[0][i];
        }
    }
    for m in 1..M {
        let c = F8::splat(isa, coef[m]);
        for i in 0..D {
            if wanted[i] {
                acc[i] = c.mul_add(ks[m][i], acc[i]);
            }
        }
    }
    for i in 0..D {
        if wanted[i] {
            out[i] = h.mul_add(acc[i], y[i]);
        }
    }
}

/// `D` components, all true but those at `skip`.
const fn all_but<const D: usize>(skip: &[usize]) -> [bool; D] {
    let mut r = [true; D];
    let mut j = 0;
    while j < skip.len() {
        r[skip[j]] = false;
        j += 1;
    }
    r
}

/// The components of a model's state that its right-hand side reads ([`Rhs::READS`]).
#[inline(always)]
fn reads<I: Isa, const D: usize, M: Rhs<I, D>>(_: &M) -> &'static [bool; D] {
    &M::READS
}

/// What the planar lanes need of the orbit at one time, the same for every lane: the gravity
/// gradient's forcing S, C and, with SRP, (sin, cos) of the Sun's phase w t (zeros without).
#[derive(Clone, Copy)]
pub(crate) struct PlanarAt {
    s: f64,
    c: f64,
    swt: f64,
    cwt: f64,
}

/// The lanes' angular acceleration wzdot(t, phi) and its derivative k = d wzdot / d phi (only
/// used with the STM: compiled away otherwise), from (cos phi, sin phi) and the orbit's data at t:
/// gravity gradient and, with SRP, the flat plate.
#[inline(always)]
fn accel<I: Isa, const SRP: bool>(at: &PlanarAt, cp: F8<I>, sp: F8<I>, p: &Params<I>) -> (F8<I>, F8<I>) {
    let (a, k, _) = accel_sens::<I, SRP, false>(at, cp, sp, p);
    (a, k)
}

/// [`accel`] and, with `SENS`, d wzdot / d parameter at fixed phi (the torques are linear in Kz
/// and in eps: the same laws at unit Kz or unit plate amplitude, weighted per the parameter).
#[inline(always)]
fn accel_sens<I: Isa, const SRP: bool, const SENS: bool>(at: &PlanarAt, cp: F8<I>, sp: F8<I>, p: &Params<I>) -> (F8<I>, F8<I>, F8<I>) {
    let isa = cp.isa();
    let (s, c) = (F8::splat(isa, at.s), F8::splat(isa, at.c));
    let c2 = cp * cp - sp * sp;
    let s2 = (cp + cp) * sp;
    let (mut dwz, mut k) = gravity_gradient_wzdot(p.kz15, s, c, c2, s2);
    let mut dp = F8::splat(isa, 0.0);
    if SENS {
        dp = gravity_gradient_wzdot(p.gk, s, c, c2, s2).0;
    }
    if SRP {
        // Sun angle theta = w t + theta0_l: (cos, sin)(w t) turned by each lane's theta0_l;
        // alpha = theta - phi (sin alpha, like k, is compiled away without the STM)
        let (ca, sa) = sun_alpha(at.swt, at.cwt, p, cp, sp);
        let (v, d) = flat_plate_wzdot(p.a1, p.a2, ca, sa);
        dwz += v;
        k += d;
        if SENS {
            dp += flat_plate_wzdot(p.u1, p.u2, ca, sa).0;
        }
    }
    (dwz, k, dp)
}

/// (cos, sin) of each lane's Sun angle from its plate normal, alpha = theta_l - phi: the Sun's
/// shared phase (sin, cos)(w t) turned by each lane's theta0_l, then by -phi from (cos phi, sin
/// phi). The law's kinks and the steps' cuts are where cos alpha = 0.
#[inline(always)]
fn sun_alpha<I: Isa>(swt: f64, cwt: f64, p: &Params<I>, cp: F8<I>, sp: F8<I>) -> (F8<I>, F8<I>) {
    let isa = cp.isa();
    let (swt, cwt) = (F8::splat(isa, swt), F8::splat(isa, cwt));
    let ct = cwt * p.c0 - swt * p.s0;
    let st = swt * p.c0 + cwt * p.s0;
    (ct.mul_add(cp, st * sp), st.mul_add(cp, -(ct * sp)))
}

#[inline(always)]
fn rhs<I: Isa, const D: usize, const SRP: bool>(at: &PlanarAt, y: &[F8<I>; D], p: &Params<I>, dy: &mut [F8<I>; D]) {
    let isa = y[0].isa();
    let w = y[1] - F8::splat(isa, 1.0);
    let (cp, sp) = (y[2], y[3]);
    dy[0] = w;
    dy[2] = -(w * sp);
    dy[3] = w * cp;
    let (dwz, k, dp) = if D == 10 { accel_sens::<I, SRP, true>(at, cp, sp, p) } else { accel_sens::<I, SRP, false>(at, cp, sp, p) };
    dy[1] = dwz;
    if D >= 8 {
        dy[4] = y[6];
        dy[5] = y[7];
        dy[6] = k * y[4];
        dy[7] = k * y[5];
    }
    if D == 10 {
        // d(phi, wz)/d parameter: d/dt = (dwz/dp, k dphi/dp + d wzdot/dp)
        dy[8] = y[9];
        dy[9] = k.mul_add(y[8], dp);
    }
}

/// A right-hand side of D states on the lanes at a shared time (the planar model here, the 3-D
/// rigid body in [`super::lanes3d`]), split in two: what it needs of the orbit at a time (the
/// same for every lane: [`Rhs::at`], or [`Rhs::at8`] for eight times at once) and the lanes'
/// derivatives given that ([`Rhs::eval_at`]).
pub(crate) trait Rhs<I: Isa, const D: usize> {
    type At: Copy;
    fn at(&self, t: f64) -> Self::At;
    /// [`Rhs::at`] at eight times, the same values bit for bit.
    fn at8(&self, ts: &[f64; 8]) -> [Self::At; 8];
    fn eval_at(&self, at: &Self::At, y: &[F8<I>; D], dy: &mut [F8<I>; D]);
    /// The components of `y` that [`Rhs::eval_at`] reads. A stage forms only these of its state
    /// (the others' stage values would be computed and never used, like phi's: the right-hand
    /// side takes the angle from cos phi and sin phi); every component's derivative still enters
    /// the step's solution and its error, so the results are those of forming them all.
    const READS: [bool; D] = [true; D];
}

/// The orbit data of a lane model at its K latest evaluated times (a step's first node is the
/// previous step's last, or a rejected step's first; a pair's recurring nodes): a pure memo, so
/// the values, and every result, are those of evaluating each time.
pub(crate) struct Recent<T, const K: usize> {
    /// (t as bits, data at t) in a ring, and where the next one goes; the key u64::MAX (NaN bits
    /// that no time has) marks an empty entry. One cell per entry: a lookup reads the entries it
    /// passes, not the whole ring.
    entries: [std::cell::Cell<(u64, T)>; K],
    next: std::cell::Cell<usize>,
}

impl<T: Copy, const K: usize> Recent<T, K> {
    pub(crate) fn new(empty: T) -> Self {
        Recent { entries: std::array::from_fn(|_| std::cell::Cell::new((u64::MAX, empty))), next: std::cell::Cell::new(0) }
    }

    /// The data kept at t, or None, and then the caller evaluates it and [`Self::keep`]s it. (No
    /// closure here: a closure is compiled outside the dispatched kernel's target features, and
    /// the lanes' evaluations in it would not be inlined.)
    #[inline(always)]
    pub(crate) fn find(&self, t: f64) -> Option<T> {
        let key = t.to_bits();
        for e in &self.entries {
            let (k, v) = e.get();
            if k == key {
                return Some(v);
            }
        }
        None
    }

    /// Keep the data v at t, in place of the oldest.
    #[inline(always)]
    pub(crate) fn keep(&self, t: f64, v: T) -> T {
        let next = self.next.get();
        self.entries[next].set((t.to_bits(), v));
        self.next.set((next + 1) % K);
        v
    }
}

/// The planar model on the lanes: the orbit's forcing table and the lanes' parameters, and the
/// orbit data of its last four single times ([`Rhs::at`]).
pub(crate) struct Planar<'a, I, const SRP: bool> {
    f: &'a OrbitForcing,
    p: Params<I>,
    recent: Recent<PlanarAt, 4>,
}

impl<'a, I: Isa, const SRP: bool> Planar<'a, I, SRP> {
    fn new(f: &'a OrbitForcing, p: Params<I>) -> Self {
        Planar { f, p, recent: Recent::new(PlanarAt { s: f64::NAN, c: f64::NAN, swt: f64::NAN, cwt: f64::NAN }) }
    }
}

impl<I: Isa> Params<I> {
    /// The Sun's phase (sin, cos)(w t) with SRP (zeros without), from the lanes' sin_cos (one
    /// lane of [`Self::sun8`]'s evaluation, the same bits).
    #[inline(always)]
    fn sun<const SRP: bool>(&self, t: f64) -> (f64, f64) {
        if SRP {
            let (s, c) = F8::splat(self.kz15.isa(), self.sun.angle(t)).sin_cos();
            (lane(&s, 0), lane(&c, 0))
        } else {
            (0.0, 0.0)
        }
    }

    /// [`Self::sun`] at eight times, in one vector evaluation.
    #[inline(always)]
    fn sun8<const SRP: bool>(&self, ts: &[f64; 8]) -> ([f64; 8], [f64; 8]) {
        if SRP {
            let mut angles = [0.0; 8];
            for l in 0..8 {
                angles[l] = self.sun.angle(ts[l]);
            }
            let (s, c) = F8::new(self.kz15.isa(), angles).sin_cos();
            (s.to_array(), c.to_array())
        } else {
            ([0.0; 8], [0.0; 8])
        }
    }
}

/// What the terminator cut ([`Terminators`]) needs of a planar lane model with the flat plate.
trait SunLanes<I: Isa> {
    /// Whether the flat-plate term is compiled in (without it, steps are never cut).
    const SRP: bool;
    /// (cos alpha, sin alpha) of the lanes in the state y at t, as the right-hand side has them.
    fn alpha<Y: PlanarY<I>>(&self, t: f64, y: &Y) -> (F8<I>, F8<I>);
    /// The Sun's rate w (1/TU).
    fn sun_omega(&self) -> f64;
}

impl<I: Isa, const SRP: bool> SunLanes<I> for Planar<'_, I, SRP> {
    const SRP: bool = SRP;

    #[inline(always)]
    fn alpha<Y: PlanarY<I>>(&self, t: f64, y: &Y) -> (F8<I>, F8<I>) {
        // a step's ends and the cut's trial ends: the data its stages had there
        let at = <Self as Rhs<I, 4>>::at(self, t);
        let (cp, sp) = y.cos_sin();
        sun_alpha(at.swt, at.cwt, &self.p, cp, sp)
    }

    fn sun_omega(&self) -> f64 {
        self.p.sun.omega
    }
}

impl<I: Isa, const SRP: bool> Planar<'_, I, SRP> {
    /// The orbit's data at time t.
    #[inline(always)]
    fn orbit_at(&self, t: f64) -> PlanarAt {
        let (s, c) = self.f.sc_at::<I>(t);
        let (swt, cwt) = self.p.sun::<SRP>(t);
        PlanarAt { s, c, swt, cwt }
    }
}

impl<I: Isa, const D: usize, const SRP: bool> Rhs<I, D> for Planar<'_, I, SRP> {
    type At = PlanarAt;
    /// Not phi (component 0): [`rhs`] reads (wz, cos phi, sin phi) and the STM.
    const READS: [bool; D] = all_but(&[0]);

    #[inline(always)]
    fn at(&self, t: f64) -> PlanarAt {
        match self.recent.find(t) {
            Some(at) => at,
            None => self.recent.keep(t, self.orbit_at(t)),
        }
    }

    #[inline(always)]
    fn at8(&self, ts: &[f64; 8]) -> [PlanarAt; 8] {
        let sc = self.f.eval8_at(self.p.kz15.isa(), ts);
        let (swt, cwt) = self.p.sun8::<SRP>(ts);
        // a loop, not array::from_fn (its closure is compiled out of line)
        let mut out = [PlanarAt { s: 0.0, c: 0.0, swt: 0.0, cwt: 0.0 }; 8];
        for l in 0..8 {
            out[l] = PlanarAt { s: sc[l][0], c: sc[l][1], swt: swt[l], cwt: cwt[l] };
        }
        out
    }

    #[inline(always)]
    fn eval_at(&self, at: &PlanarAt, y: &[F8<I>; D], dy: &mut [F8<I>; D]) {
        rhs::<I, D, SRP>(at, y, &self.p, dy);
    }
}

/// The 13 stages of D states of an explicit pair ([`Fehlberg`]'s RKF7(8) or [`PrinceDormand`]'s
/// RK8(7)13M, both 13 stages, both propagating their 8th-order solution).
pub(crate) struct Stages<I, const D: usize, T = Fehlberg> {
    k: [[F8<I>; D]; 13],
    tmp: [F8<I>; D],
    tableau: std::marker::PhantomData<T>,
}

/// The RKF7(8) tableau ([`crate::integrate::tableau`]).
pub(crate) struct Fehlberg;
/// The RK8(7)13M tableau ([`crate::integrate::tableau::dp87`]).
pub(crate) struct PrinceDormand;

macro_rules! stage {
    ($a:ident, $ats:ident, $st:ident, $m:ident, $y:ident, $h:ident, $s:literal; $($j:literal),+) => {{
        lincomb(&mut $st.tmp, $y, F8::splat($y[0].isa(), $h), [$($a[$s][$j]),+], [$(&$st.k[$j]),+], reads($m));
        $m.eval_at(&$ats[$s], &$st.tmp, &mut $st.k[$s]);
    }};
}

/// A stage that takes its orbit data from its own [`Rhs::at`] ([`stage_plan`]).
const OWN: i8 = i8::MAX;

/// Where each of a 13-stage pair's stages takes its orbit data: `-1 - l` from lane l of one
/// [`Rhs::at8`] over the stages `vec`, `j >= 0` from the earlier stage j at the same node, or
/// [`OWN`].
const fn stage_plan(c: &[f64; 13], vec: [usize; 8]) -> [i8; 13] {
    let mut plan = [OWN; 13];
    let mut l = 0;
    while l < 8 {
        plan[vec[l]] = -1 - l as i8;
        l += 1;
    }
    let mut s = 0;
    while s < 13 {
        if plan[s] == OWN {
            let mut j = 0;
            while j < s {
                if c[j] == c[s] {
                    plan[s] = j as i8;
                    break;
                }
                j += 1;
            }
        }
        s += 1;
    }
    plan
}

/// RKF7(8)'s plan: eight distinct nodes on the lanes, t and t + h once each (c = 1/6, 0 and 1
/// recur).
const FEHLBERG_PLAN: [i8; 13] = stage_plan(&C, [1, 2, 3, 4, 5, 6, 8, 9]);
/// RK8(7)13M's plan: its first eight non-zero nodes on the lanes, the other three once each.
const DP87_PLAN: [i8; 13] = stage_plan(&DP_C, [1, 2, 3, 4, 5, 6, 7, 8]);

/// Where a stage's orbit data is kept in [`StageData`]: lane l of the step's one [`Rhs::at8`], or
/// the k-th of its own [`Rhs::at`] evaluations.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slot {
    Lane(usize),
    Own(usize),
}

/// At most this many stages of a plan evaluate on their own (RK8(7)13M: t and three nodes).
const OWN_SLOTS: usize = 4;

/// A plan's slots, every recurring stage in its first stage's slot.
const fn slots(plan: &[i8; 13]) -> [Slot; 13] {
    let mut out = [Slot::Own(0); 13];
    let mut own = 0;
    let mut s = 0;
    while s < 13 {
        out[s] = if plan[s] == OWN {
            own += 1;
            Slot::Own(own - 1)
        } else if plan[s] < 0 {
            Slot::Lane((-1 - plan[s]) as usize)
        } else {
            out[plan[s] as usize]
        };
        s += 1;
    }
    assert!(own <= OWN_SLOTS);
    out
}

/// A 13-stage pair's nodes c_s, its plan ([`stage_plan`]) and where each stage's orbit data is
/// kept ([`stage_data`]).
trait StagePlan {
    const C: [f64; 13];
    const PLAN: [i8; 13];
    const SLOTS: [Slot; 13] = slots(&Self::PLAN);
    /// The stages that evaluate on their own, in stage order, and how many there are (the
    /// entries past that count are unused).
    const OWN_STAGES: ([usize; OWN_SLOTS], usize) = own_stages(&Self::PLAN);
}

/// The stages of a plan that evaluate on their own ([`OWN`]), in stage order, and how many.
const fn own_stages(plan: &[i8; 13]) -> ([usize; OWN_SLOTS], usize) {
    let mut out = [0; OWN_SLOTS];
    let mut n = 0;
    let mut s = 0;
    while s < 13 {
        if plan[s] == OWN {
            out[n] = s;
            n += 1;
        }
        s += 1;
    }
    (out, n)
}

impl StagePlan for Fehlberg {
    const C: [f64; 13] = C;
    const PLAN: [i8; 13] = FEHLBERG_PLAN;
}

impl StagePlan for PrinceDormand {
    const C: [f64; 13] = DP_C;
    const PLAN: [i8; 13] = DP87_PLAN;
}

/// The orbit data of a step's 13 nodes ([`stage_data`]), indexed by stage: each stage reads its
/// slot in place (the plan is a constant, so an index known at compile time costs nothing), no
/// record copied per stage.
struct StageData<A, T> {
    lanes: [A; 8],
    own: [A; OWN_SLOTS],
    plan: std::marker::PhantomData<T>,
}

impl<A, T: StagePlan> std::ops::Index<usize> for StageData<A, T> {
    type Output = A;
    #[inline(always)]
    fn index(&self, s: usize) -> &A {
        match T::SLOTS[s] {
            Slot::Lane(l) => &self.lanes[l],
            Slot::Own(k) => &self.own[k],
        }
    }
}

/// The orbit data at a 13-stage pair's nodes, t_s = c_s h + t (one fused multiply-add, as
/// always), by its plan ([`stage_plan`]): the same values as one [`Rhs::at`] per stage, its own
/// evaluations in stage order.
#[inline(always)]
fn stage_data<I: Isa, const D: usize, M: Rhs<I, D>, T: StagePlan>(m: &M, t: f64, h: f64) -> StageData<M::At, T> {
    let mut ts = [0.0; 13];
    for (ts, c) in ts.iter_mut().zip(T::C) {
        *ts = c.mul_add(h, t);
    }
    let mut lanes = [0.0; 8];
    for s in 0..13 {
        if T::PLAN[s] < 0 {
            lanes[(-1 - T::PLAN[s]) as usize] = ts[s];
        }
    }
    let lanes = m.at8(&lanes);
    let mut own = [lanes[0]; OWN_SLOTS];
    let (stages, n) = T::OWN_STAGES;
    for k in 0..n {
        own[k] = m.at(ts[stages[k]]);
    }
    StageData { lanes, own, plan: std::marker::PhantomData }
}

/// A lane integration scheme on the model `M`: its state and one step.
pub(crate) trait Scheme<I: Isa, M> {
    type Y: Copy;
    /// The step-size controller (the scalar driver's, at this scheme's error order).
    const CONTROLLER: Controller;
    fn new(isa: I) -> Self;
    /// Forget anything kept from the previous group (its cases differ).
    fn begin(&mut self) {}
    /// One step of size h from (t, y), all lanes: writes the propagated solution and returns
    /// the scaled max-norm error per lane.
    fn step(&mut self, m: &M, t: f64, y: &Self::Y, h: f64, out: &mut Self::Y, rtol: F8<I>, atol: F8<I>) -> F8<I>;
    fn finite(y: &Self::Y) -> bool;
}

/// How a planar trajectory's lane state starts and ends.
trait PlanarY<I: Isa>: Copy {
    /// The state at t = 0 of the lanes' cases.
    fn start(isa: I, pick: impl Fn(usize) -> Case) -> Self;
    /// The lanes' phi.
    fn phi(&self) -> F8<I>;
    /// The lanes' (cos phi, sin phi), as the right-hand side sees them.
    fn cos_sin(&self) -> (F8<I>, F8<I>);
    /// The lanes' phidot = wz - 1.
    fn rate(&self) -> F8<I>;
    /// Lane l's (phi, wz, 2x2 STM row-major or NaN, d(phi, wz)/d parameter or NaN).
    fn end(&self, l: usize) -> (f64, f64, [f64; 4], [f64; 2]);
}

/// The scaled error of one component, |e| / (rtol max(|y|, |y_new|) + atol), folded into the
/// lanes' running maximum (a NaN ratio fails the `<=` test and becomes the lane's error).
#[inline(always)]
fn fold_error<I: Isa>(err: F8<I>, e: F8<I>, y: F8<I>, ynew: F8<I>, rtol: F8<I>, atol: F8<I>) -> F8<I> {
    let r = e.abs() / rtol.mul_add(y.abs().max(ynew.abs()), atol);
    r.le_select(err, err, r)
}

impl<I: Isa, const D: usize> PlanarY<I> for [F8<I>; D] {
    fn start(isa: I, pick: impl Fn(usize) -> Case) -> [F8<I>; D] {
        let mut y = [F8::splat(isa, 0.0); D];
        y[0] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0));
        y[1] = F8::new(isa, std::array::from_fn(|l| pick(l).wz0));
        y[2] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0.cos()));
        y[3] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0.sin()));
        if D >= 8 {
            y[4] = F8::splat(isa, 1.0);
            y[7] = F8::splat(isa, 1.0);
        }
        y
    }

    fn phi(&self) -> F8<I> {
        self[0]
    }

    #[inline(always)]
    fn cos_sin(&self) -> (F8<I>, F8<I>) {
        (self[2], self[3])
    }

    fn rate(&self) -> F8<I> {
        self[1] - F8::splat(self[1].isa(), 1.0)
    }

    fn end(&self, l: usize) -> (f64, f64, [f64; 4], [f64; 2]) {
        let y = self;
        let stm = if D >= 8 { [lane(&y[4], l), lane(&y[5], l), lane(&y[6], l), lane(&y[7], l)] } else { [f64::NAN; 4] };
        let dparam = if D == 10 { [lane(&y[8], l), lane(&y[9], l)] } else { [f64::NAN; 2] };
        (lane(&y[0], l), lane(&y[1], l), stm, dparam)
    }
}

impl<I: Isa, const D: usize, M: Rhs<I, D>> Scheme<I, M> for Stages<I, D, Fehlberg> {
    type Y = [F8<I>; D];
    const CONTROLLER: Controller = CONTROLLER;

    fn new(isa: I) -> Self {
        Stages { k: [[F8::splat(isa, 0.0); D]; 13], tmp: [F8::splat(isa, 0.0); D], tableau: std::marker::PhantomData }
    }

    #[inline(always)]
    fn finite(y: &[F8<I>; D]) -> bool {
        finite_lanes(y)
    }

    /// One RKF7(8) step: the 8th-order solution and the scaled max-norm error per lane.
    #[inline(always)]
    fn step(&mut self, m: &M, t: f64, y: &[F8<I>; D], h: f64, out: &mut [F8<I>; D], rtol: F8<I>, atol: F8<I>) -> F8<I> {
        let isa = y[0].isa();
        let ats = stage_data::<I, D, M, Fehlberg>(m, t, h);
        m.eval_at(&ats[0], y, &mut self.k[0]);
        rkf78_stages!(stage!(A, ats, self, m, y, h));
        let k = &self.k;
        let hv = F8::splat(isa, h);
        lincomb(out, y, hv, [B8[5], B8[6], B8[7], B8[8], B8[9], B8[11], B8[12]], [&k[5], &k[6], &k[7], &k[8], &k[9], &k[11], &k[12]], &[true; D]);
        let he = hv * F8::splat(isa, ERR);
        let mut err = F8::splat(isa, 0.0);
        for i in 0..D {
            err = fold_error(err, he * ((k[0][i] + k[10][i]) - (k[11][i] + k[12][i])), y[i], out[i], rtol, atol);
        }
        err
    }
}

/// Every lane of every component finite.
#[inline(always)]
fn finite_lanes<I: Isa, const D: usize>(y: &[F8<I>; D]) -> bool {
    (0..D).all(|i| y[i].to_array().iter().all(|v| v.is_finite()))
}

/// Prince and Dormand's RK8(7)13M on the lanes: the same stage loop (the tableau's sparsity from
/// `dp87_stages!`), the 8th-order solution propagated, the error from the embedded 7th-order one
/// (nine non-zero weights), the RKF7(8) controller (both estimates are of order 7).
impl<I: Isa, const D: usize, M: Rhs<I, D>> Scheme<I, M> for Stages<I, D, PrinceDormand> {
    type Y = [F8<I>; D];
    const CONTROLLER: Controller = Controller::new(0.8, 0.2, 5.0, crate::integrate::tableau::dp87::ERROR_ORDER);

    fn new(isa: I) -> Self {
        Stages { k: [[F8::splat(isa, 0.0); D]; 13], tmp: [F8::splat(isa, 0.0); D], tableau: std::marker::PhantomData }
    }

    #[inline(always)]
    fn finite(y: &[F8<I>; D]) -> bool {
        finite_lanes(y)
    }

    #[inline(always)]
    fn step(&mut self, m: &M, t: f64, y: &[F8<I>; D], h: f64, out: &mut [F8<I>; D], rtol: F8<I>, atol: F8<I>) -> F8<I> {
        let isa = y[0].isa();
        let ats = stage_data::<I, D, M, PrinceDormand>(m, t, h);
        m.eval_at(&ats[0], y, &mut self.k[0]);
        dp87_stages!(stage!(DP_A, ats, self, m, y, h));
        let k = &self.k;
        let hv = F8::splat(isa, h);
        let w = DP_B8;
        lincomb(out, y, hv, [w[0], w[5], w[6], w[7], w[8], w[9], w[10], w[11], w[12]], [&k[0], &k[5], &k[6], &k[7], &k[8], &k[9], &k[10], &k[11], &k[12]], &[true; D]);
        let e = DP_E;
        let ec = [e[0], e[5], e[6], e[7], e[8], e[9], e[10], e[11], e[12]];
        let ek = [&k[0], &k[5], &k[6], &k[7], &k[8], &k[9], &k[10], &k[11], &k[12]];
        let mut err = F8::splat(isa, 0.0);
        for i in 0..D {
            let mut acc = F8::splat(isa, 0.0);
            for m in 0..9 {
                acc = F8::splat(isa, ec[m]).mul_add(ek[m][i], acc);
            }
            err = fold_error(err, hv * acc, y[i], out[i], rtol, atol);
        }
        err
    }
}

/// Runge-Kutta-Nyström RKN8(6) ([`crate::integrate::rkn`]) on the lanes: with the orbit
/// tabulated, the planar attitude is a special second-order equation, phi'' = wzdot(t, phi)
/// (phidot = wz - 1), and so is its variational equation, Y'' = k(t, phi) Y for the columns Y of
/// d phi / d(phi0, wz0). Positions x = (phi[, Y1, Y2]) and velocities v = (phidot[, Y1', Y2'])
/// with P = 1 (no STM) or 3 components; cos phi and sin phi from one vector sin_cos per stage
/// (RKF7(8) carries them as states instead). Eight new evaluations per step (the last stage is
/// the next step's first) against RKF7(8)'s thirteen.
struct Nystrom<I, const P: usize> {
    k: [[F8<I>; P]; RKN_STAGES],
    tmp: [F8<I>; P],
    /// First same as last: the last stage of the latest step and where it was evaluated (the
    /// next step reuses it when it starts there, after an accepted step, not after a trial).
    last: [F8<I>; P],
    last_at: Option<(f64, [F8<I>; P])>,
}

/// Positions and velocities of the Nyström lanes.
#[derive(Clone, Copy)]
struct NyState<I, const P: usize> {
    x: [F8<I>; P],
    v: [F8<I>; P],
}

impl<I: Isa, const P: usize> Nystrom<I, P> {
    #[inline(always)]
    fn acc<const SRP: bool>(m: &Planar<'_, I, SRP>, t: f64, x: &[F8<I>; P], out: &mut [F8<I>; P]) {
        let (sp, cp) = x[0].sin_cos();
        let (a, k) = accel::<I, SRP>(&m.orbit_at(t), cp, sp, &m.p);
        out[0] = a;
        for i in 1..P {
            out[i] = k * x[i];
        }
    }
}

impl<I: Isa, const P: usize> PlanarY<I> for NyState<I, P> {
    fn start(isa: I, pick: impl Fn(usize) -> Case) -> NyState<I, P> {
        let mut y = NyState { x: [F8::splat(isa, 0.0); P], v: [F8::splat(isa, 0.0); P] };
        y.x[0] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0));
        y.v[0] = F8::new(isa, std::array::from_fn(|l| pick(l).wz0 - 1.0));
        if P == 3 {
            y.x[1] = F8::splat(isa, 1.0); // d phi / d phi0
            y.v[2] = F8::splat(isa, 1.0); // d phidot / d wz0
        }
        y
    }

    fn phi(&self) -> F8<I> {
        self.x[0]
    }

    #[inline(always)]
    fn cos_sin(&self) -> (F8<I>, F8<I>) {
        let (sp, cp) = self.x[0].sin_cos();
        (cp, sp)
    }

    fn rate(&self) -> F8<I> {
        self.v[0]
    }

    fn end(&self, l: usize) -> (f64, f64, [f64; 4], [f64; 2]) {
        let y = self;
        // STM rows (phi, wz), columns (phi0, wz0): (Y1, Y2; Y1', Y2')
        let stm = if P == 3 { [lane(&y.x[1], l), lane(&y.x[2], l), lane(&y.v[1], l), lane(&y.v[2], l)] } else { [f64::NAN; 4] };
        (lane(&y.x[0], l), lane(&y.v[0], l) + 1.0, stm, [f64::NAN; 2])
    }
}

impl<I: Isa, const P: usize, const SRP: bool> Scheme<I, Planar<'_, I, SRP>> for Nystrom<I, P> {
    type Y = NyState<I, P>;
    const CONTROLLER: Controller = Controller::new(0.8, 0.2, 5.0, RKN_ERROR_ORDER);

    fn new(isa: I) -> Self {
        let z = [F8::splat(isa, 0.0); P];
        Nystrom { k: [z; RKN_STAGES], tmp: z, last: z, last_at: None }
    }

    fn begin(&mut self) {
        self.last_at = None;
    }

    #[inline(always)]
    fn finite(y: &NyState<I, P>) -> bool {
        (0..P).all(|i| y.x[i].to_array().iter().chain(y.v[i].to_array().iter()).all(|v| v.is_finite()))
    }

    #[inline(always)]
    fn step(&mut self, m: &Planar<'_, I, SRP>, t: f64, y: &NyState<I, P>, h: f64, out: &mut NyState<I, P>, rtol: F8<I>, atol: F8<I>) -> F8<I> {
        let isa = y.x[0].isa();
        let (hv, h2) = (F8::splat(isa, h), F8::splat(isa, h * h));
        let same = |a: &[F8<I>; P], b: &[F8<I>; P]| (0..P).all(|i| a[i].to_array().iter().zip(b[i].to_array().iter()).all(|(u, v)| u.to_bits() == v.to_bits()));
        match self.last_at {
            Some((tl, ref xl)) if tl.to_bits() == t.to_bits() && same(xl, &y.x) => self.k[0] = self.last,
            _ => Self::acc::<SRP>(m, t, &y.x, &mut self.k[0]),
        }
        for s in 1..RKN_STAGES - 1 {
            for i in 0..P {
                let mut acc = F8::splat(isa, 0.0);
                for (a, k) in RKN_A[s][..s].iter().zip(&self.k) {
                    acc = F8::splat(isa, *a).mul_add(k[i], acc);
                }
                self.tmp[i] = h2.mul_add(acc, (hv * F8::splat(isa, RKN_C[s])).mul_add(y.v[i], y.x[i]));
            }
            let tmp = self.tmp;
            Self::acc::<SRP>(m, RKN_C[s].mul_add(h, t), &tmp, &mut self.k[s]);
        }
        // the new position (the last stage's: A's last row is B), then the last stage there
        for i in 0..P {
            let mut acc = F8::splat(isa, 0.0);
            for (b, k) in RKN_B[..RKN_STAGES - 1].iter().zip(&self.k) {
                acc = F8::splat(isa, *b).mul_add(k[i], acc);
            }
            out.x[i] = h2.mul_add(acc, hv.mul_add(y.v[i], y.x[i]));
        }
        let xnew = out.x;
        Self::acc::<SRP>(m, t + h, &xnew, &mut self.k[RKN_STAGES - 1]);
        self.last = self.k[RKN_STAGES - 1];
        self.last_at = Some((t + h, xnew));
        let mut err = F8::splat(isa, 0.0);
        for i in 0..P {
            let (mut dv, mut ex, mut ev) = (F8::splat(isa, 0.0), F8::splat(isa, 0.0), F8::splat(isa, 0.0));
            for (j, k) in self.k.iter().enumerate() {
                dv = F8::splat(isa, RKN_BP[j]).mul_add(k[i], dv);
                ex = F8::splat(isa, RKN_BT[j]).mul_add(k[i], ex);
                ev = F8::splat(isa, RKN_BPT[j]).mul_add(k[i], ev);
            }
            out.v[i] = hv.mul_add(dv, y.v[i]);
            err = fold_error(err, h2 * ex, y.x[i], out.x[i], rtol, atol);
            err = fold_error(err, hv * ev, y.v[i], out.v[i], rtol, atol);
        }
        err
    }
}

pub(crate) fn lane<I: Isa>(v: &F8<I>, l: usize) -> f64 {
    v.to_array()[l]
}

/// How a lock-step run ended: steps taken (shared by the lanes), the status, and where it
/// stopped (the time reached and the last step size tried).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Run {
    pub accepted: u32,
    pub rejected: u32,
    pub status: LaneStatus,
    pub t: f64,
    pub h: f64,
}

/// A hook of the step loop that may shorten an accepted step (the planar SRP terminators).
/// A trait with an `#[inline(always)]` method rather than a closure, so that it is compiled
/// inside the dispatched kernel with the level's target features.
pub(crate) trait Cut<I: Isa, M, S: Scheme<I, M>> {
    /// For the accepted step of length `h` from (t, y) to `ynew`: the shorter length, with `ynew`
    /// recomputed for it, or None to keep the step.
    fn cut(&mut self, st: &mut S, m: &M, t: f64, h: f64, y: &S::Y, ynew: &mut S::Y) -> Option<f64>;
}

/// Steps are never cut.
pub(crate) struct NoCut;

impl<I: Isa, M, S: Scheme<I, M>> Cut<I, M, S> for NoCut {
    #[inline(always)]
    fn cut(&mut self, _: &mut S, _: &M, _: f64, _: f64, _: &S::Y, _: &mut S::Y) -> Option<f64> {
        None
    }
}

/// The lock-step loop of every lane engine: steps `y` from t = 0 to `t_final` with the scheme
/// `st` on the model `m` and the controller, a step accepted when every lane's error is <= 1;
/// `cut` may shorten accepted steps.
#[inline(always)]
pub(crate) fn run_steps<I: Isa, M, S: Scheme<I, M>>(isa: I, st: &mut S, m: &M, y: &mut S::Y, t_final: f64, opts: &LaneOptions, cut: &mut impl Cut<I, M, S>) -> Run {
    let (rtol, atol) = (F8::splat(isa, opts.rtol), F8::splat(isa, opts.atol));
    let mut ynew = *y;
    let (mut t, mut h) = (0.0f64, t_final / 100.0);
    let (mut accepted, mut rejected) = (0u32, 0u32);
    let mut after_reject = false;
    let mut status = LaneStatus::Ok;
    while t < t_final {
        if accepted + rejected >= opts.max_steps {
            status = LaneStatus::MaxSteps;
            break;
        }
        let rem = t_final - t;
        let (mut heff, mut last) = if h >= rem { (rem, true) } else { (h, false) };
        let err = st.step(m, t, y, heff, &mut ynew, rtol, atol).to_array();
        let emax = err.iter().fold(0.0f64, |m, &e| if e.is_nan() || e > m { if e.is_nan() { f64::INFINITY } else { e } } else { m });
        let finite = S::finite(&ynew);
        if !(emax <= 1.0) || !finite {
            rejected += 1;
            after_reject = true;
            h = heff * S::CONTROLLER.factor_rejected(emax);
            if h <= min_step(t_final) {
                status = LaneStatus::Failed;
                break;
            }
            continue;
        }
        if let Some(c) = cut.cut(st, m, t, heff, y, &mut ynew) {
            heff = c;
            last = false;
        }
        accepted += 1;
        *y = ynew;
        t = if last { t_final } else { t + heff };
        let fac = S::CONTROLLER.factor_accepted(emax, after_reject);
        after_reject = false;
        h = h.max(heff) * fac;
    }
    Run { accepted, rejected, status, t, h }
}

/// The step size below which [`run_steps`] gives up (status Failed): relative to the span.
#[inline(always)]
fn min_step(t_final: f64) -> f64 {
    1e-14 * t_final.max(1.0)
}

impl Run {
    /// The run's failure as the scalar driver reports it (None if it ended Ok): the step limit
    /// `max_steps` exceeded, or the step size fallen below [`min_step`] (non-finite states are
    /// rejected until it does).
    fn error(&self, t_final: f64, max_steps: u32) -> Option<IntegrationError> {
        let steps = (self.accepted + self.rejected) as usize;
        match self.status {
            LaneStatus::Ok => None,
            LaneStatus::MaxSteps => Some(IntegrationError::MaxStepsExceeded { t: self.t, steps, max_steps: max_steps as usize }),
            LaneStatus::Failed => Some(IntegrationError::StepSizeUnderflow { t: self.t, steps, h: self.h, h_min: min_step(t_final) }),
        }
    }
}

/// How far past a terminator crossing a cut step may end (TU). A step across a kink of the plate
/// law (a jump J in the third derivative of phi) at a distance d from its end errs by about
/// b J d^2 h (b the weight of the step's last nodes, about 0.05): below 1e-20 for d = 1e-10,
/// J <= 100 and h <= 1.
const CUT_TOL: f64 = 1e-10;

/// The planar SRP cut: an accepted step never spans a lane's Sun-terminator crossing (where its
/// plate acts, cos alpha = 0 in the right-hand side's own alpha); it is cut less than
/// [`CUT_TOL`] past the earliest one. Per crossing lane, a first guess from the cubic Hermite
/// interpolant of phi over the step (no evaluations), then Newton iterations on cos alpha along
/// trial steps (its time derivative, -sin alpha (w - phidot), from the trial's end state),
/// bracketed, with regula falsi where a Newton iterate leaves the bracket. Lanes are taken in
/// the order of their guesses; a lane that has not crossed yet at the cut found so far needs no
/// trial steps.
struct Terminators<I, Y> {
    /// The lanes whose steps stop at their crossings (a plate acts, or the sensitivity to eps
    /// does; a short group's copies of its last lane follow that lane).
    plate: [bool; LANES],
    /// Scratch states: the trial step, and the latest trial ending past the crossing.
    yc: Y,
    yb: Y,
    rtol: F8<I>,
    atol: F8<I>,
}

/// Whether g changes sign strictly between a and b.
#[inline(always)]
fn crosses(a: f64, b: f64) -> bool {
    (a < 0.0 && b > 0.0) || (a > 0.0 && b < 0.0)
}

/// The first guess of a lane's crossing time within a step of length h: where
/// alpha(tau) = w tau + theta_0 - phi(tau), with phi its cubic Hermite interpolant on (phi, phidot)
/// at both ends, first reaches an odd multiple of pi/2 from alpha(0) = atan2(sa0, ca0) (Newton on
/// the cubic, bracketed); the secant of cos alpha, `lin`, where the interpolant misses.
fn crossing_guess(h: f64, w: f64, (phi0, phi1): (f64, f64), (r0, r1): (f64, f64), (ca0, sa0): (f64, f64), lin: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let a0 = sa0.atan2(ca0);
    let dphi = phi1 - phi0;
    let u1 = w * h - dphi;
    let target = if u1 > 0.0 { (FRAC_PI_2 - a0).rem_euclid(PI) } else { -(a0 - FRAC_PI_2).rem_euclid(PI) };
    // F(s) = alpha(s h) - alpha(0) - target on s in [0, 1]
    let f = |s: f64| {
        let s2 = s * s;
        let (h01, h10, h11) = (s2 * (3.0 - 2.0 * s), s * (s - 1.0) * (s - 1.0), s2 * (s - 1.0));
        let (d01, d10, d11) = (6.0 * s * (1.0 - s), (3.0 * s - 1.0) * (s - 1.0), s * (3.0 * s - 2.0));
        let v = w * h * s - (h * r0 * h10 + dphi * h01 + h * r1 * h11) - target;
        let d = w * h - (h * r0 * d10 + dphi * d01 + h * r1 * d11);
        (v, d)
    };
    let (fa, fb) = (f(0.0).0, f(1.0).0);
    if !crosses(fa, fb) {
        return lin;
    }
    let (mut sa, mut sb, mut s) = (0.0f64, 1.0f64, (target / u1).clamp(0.0, 1.0));
    for _ in 0..12 {
        let (v, d) = f(s);
        if v == 0.0 {
            break;
        }
        if (v > 0.0) == (fa > 0.0) {
            sa = s;
        } else {
            sb = s;
        }
        let next = s - v / d;
        let next = if next > sa && next < sb { next } else { 0.5 * (sa + sb) };
        if (next - s).abs() <= 1e-13 {
            s = next;
            break;
        }
        s = next;
    }
    s * h
}

impl<I: Isa, M: SunLanes<I>, S: Scheme<I, M>> Cut<I, M, S> for Terminators<I, S::Y>
where
    S::Y: PlanarY<I>,
{
    #[inline(always)]
    fn cut(&mut self, st: &mut S, model: &M, t: f64, heff: f64, y: &S::Y, ynew: &mut S::Y) -> Option<f64> {
        if !M::SRP {
            return None;
        }
        let (rtol, atol) = (self.rtol, self.atol);
        let w = model.sun_omega();
        let (ca0, sa0) = model.alpha(t, y);
        let (ca1, _) = model.alpha(t + heff, ynew);
        let (ca0, sa0, ca1) = (ca0.to_array(), sa0.to_array(), ca1.to_array());
        let (phi0, phi1, r0, r1) = (y.phi().to_array(), ynew.phi().to_array(), y.rate().to_array(), ynew.rate().to_array());
        let mut order = [(0.0f64, 0usize); LANES];
        let mut n = 0;
        for l in 0..LANES {
            if self.plate[l] && crosses(ca0[l], ca1[l]) {
                let lin = heff * ca0[l] / (ca0[l] - ca1[l]);
                order[n] = (crossing_guess(heff, w, (phi0[l], phi1[l]), (r0[l], r1[l]), (ca0[l], sa0[l]), lin), l);
                n += 1;
            }
        }
        if n == 0 {
            return None;
        }
        order[..n].sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // every iterate aims half a tolerance past its estimate of the crossing
        let aim = 0.5 * CUT_TOL;
        // the earliest crossing found so far; `ynew` is the state there
        let mut cut = heff;
        let mut ends = ca1;
        for &(guess, l) in &order[..n] {
            let g0 = ca0[l];
            if !crosses(g0, ends[l]) {
                continue; // not crossed yet at `cut`
            }
            let (mut ta, mut tb, mut ga, mut gb) = (0.0f64, cut, g0, ends[l]);
            let mut tau = if guess + aim > ta && guess + aim < tb { guess + aim } else { tb - gb * (tb - ta) / (gb - ga) };
            let mut found = false;
            for _ in 0..60 {
                st.step(model, t, y, tau, &mut self.yc, rtol, atol);
                let (ca, sa) = model.alpha(t + tau, &self.yc);
                let gc = lane(&ca, l);
                // Newton's estimate of the crossing is d from tau
                let d = gc / (lane(&sa, l) * (w - lane(&self.yc.rate(), l)));
                if gc == 0.0 || (gc > 0.0) == (gb > 0.0) {
                    tb = tau;
                    gb = gc;
                    self.yb = self.yc;
                    found = true;
                    if gc == 0.0 || (-CUT_TOL..=0.0).contains(&d) {
                        break; // past the crossing, by at most the tolerance
                    }
                } else {
                    ta = tau;
                    ga = gc;
                }
                if tb - ta <= CUT_TOL {
                    break;
                }
                let mut next = tau + d + aim;
                if !(next > ta && next < tb) {
                    next = tb - gb * (tb - ta) / (gb - ga);
                    if !(next > ta && next < tb) || (next - ta).min(tb - next) < 0.01 * (tb - ta) {
                        next = 0.5 * (ta + tb);
                    }
                }
                tau = next;
            }
            // just past the crossing, unless it is at the very start (a restart)
            if found && tb > 1e-12 * (1.0 + t.abs()) {
                cut = tb;
                *ynew = self.yb;
                ends = model.alpha(t + cut, ynew).0.to_array();
            }
        }
        (cut < heff).then_some(cut)
    }
}

/// Integrate one group of up to LANES trajectories in lock step; missing lanes repeat the last.
#[inline(always)]
fn integrate_group<'a, I: Isa, S: Scheme<I, Planar<'a, I, SRP>>, const SRP: bool>(isa: I, f: &'a OrbitForcing, t_final: f64, group: &[Case], opts: &LaneOptions, st: &mut S) -> [Outcome; LANES]
where
    S::Y: PlanarY<I>,
{
    let n = group.len();
    let pick = |l: usize| group[l.min(n - 1)];
    let mut y = <S::Y as PlanarY<I>>::start(isa, pick);
    st.begin();
    let (p, plates) = Params::new(isa, pick, opts.sun_omega, opts.sensitivity);
    let model = Planar::<I, SRP>::new(f, p);
    let mut cut = Terminators::new(isa, n, &plates, opts, y);
    let run = run_steps(isa, st, &model, &mut y, t_final, opts, &mut cut);
    outcomes(&y, run)
}

impl<I: Isa, Y: Copy> Terminators<I, Y> {
    /// The cut of a group of `n` cases: the steps stop at a lane's terminator crossings where
    /// its plate acts, or where the sensitivity to eps does (the law's kink is there for any
    /// amplitude); a short group's copies of its last lane are that lane, bit for bit, and cross
    /// with it.
    #[inline(always)]
    fn new(isa: I, n: usize, plates: &[FlatPlate; LANES], opts: &LaneOptions, y: Y) -> Self {
        let plate: [bool; LANES] = std::array::from_fn(|l| l < n && (plates[l].eps != 0.0 || opts.sensitivity == Sensitivity::Eps));
        Terminators { plate, yc: y, yb: y, rtol: F8::splat(isa, opts.rtol), atol: F8::splat(isa, opts.atol) }
    }
}

/// The lanes' outcomes at the end of a planar run (NaN values unless it ended Ok).
#[inline(always)]
fn outcomes<I: Isa, Y: PlanarY<I>>(y: &Y, run: Run) -> [Outcome; LANES] {
    let Run { accepted, rejected, status, .. } = run;
    std::array::from_fn(|l| {
        if status != LaneStatus::Ok {
            return Outcome { phi_t: f64::NAN, wz_t: f64::NAN, stm: [f64::NAN; 4], dparam: [f64::NAN; 2], accepted, rejected, status };
        }
        let (phi_t, wz_t, stm, dparam) = y.end(l);
        Outcome { phi_t, wz_t, stm, dparam, accepted, rejected, status }
    })
}

/// Integrate `cases` from t = 0 to `t_final` along the orbit forcing, in lock-step groups of
/// [`group_size`] taken in order from the start of the slice, at the SIMD `level`
/// ([`crate::simd`]; an error only if the CPU lacks it), with `opts.method`. `D` is 4 (no STM)
/// or 8 (with the 2x2 STM);
/// `SRP` compiles the flat-plate term in (lanes with eps = 0 add exact zeros and never cut
/// steps).
pub fn integrate_cases<const D: usize, const SRP: bool>(level: Level, f: &OrbitForcing, t_final: f64, cases: &[Case], opts: &LaneOptions) -> Result<Vec<Outcome>> {
    crate::simd::run_at(level, Groups::<D, SRP> { f, t_final, cases, opts })
}

/// The lane engine as a dispatched kernel: everything below `run` is inlined into it.
struct Groups<'a, const D: usize, const SRP: bool> {
    f: &'a OrbitForcing,
    t_final: f64,
    cases: &'a [Case],
    opts: &'a LaneOptions,
}

impl<const D: usize, const SRP: bool> Kernel for Groups<'_, D, SRP> {
    type Output = Vec<Outcome>;
    #[inline(always)]
    fn run<I: Isa>(self, isa: I) -> Vec<Outcome> {
        match (self.opts.method, D == 8) {
            (Method::Dp87, true) if self.opts.sensitivity != Sensitivity::None => self.with::<I, Stages<I, 10, PrinceDormand>>(isa),
            (_, true) if self.opts.sensitivity != Sensitivity::None => self.with::<I, Stages<I, 10>>(isa),
            _ if wide(D == 8, SRP, self.opts) => Groups::<4, false> { f: self.f, t_final: self.t_final, cases: self.cases, opts: self.opts }.wide(isa),
            (Method::Rkf78, _) => self.with::<I, Stages<I, D>>(isa),
            (Method::Dp87, _) => self.with::<I, Stages<I, D, PrinceDormand>>(isa),
            (Method::Rkn86, true) => self.with::<I, Nystrom<I, 3>>(isa),
            (Method::Rkn86, false) => self.with::<I, Nystrom<I, 1>>(isa),
        }
    }
}

impl<'a, const D: usize, const SRP: bool> Groups<'a, D, SRP> {
    #[inline(always)]
    fn with<I: Isa, S: Scheme<I, Planar<'a, I, SRP>>>(self, isa: I) -> Vec<Outcome>
    where
        S::Y: PlanarY<I>,
    {
        let mut st = S::new(isa);
        let mut out = Vec::with_capacity(self.cases.len());
        for group in self.cases.chunks(LANES) {
            let r = integrate_group::<I, S, SRP>(isa, self.f, self.t_final, group, self.opts, &mut st);
            out.extend_from_slice(&r[..group.len()]);
        }
        out
    }
}

impl<'a> Groups<'a, 4, false> {
    /// The wide path (RKF7(8), no STM, no SRP, no sensitivity): groups of [`GROUP`] in case
    /// order, two lane vectors in lock step on one orbit evaluation per stage; a chunk's last
    /// group of at most [`LANES`] on one vector.
    #[inline(always)]
    fn wide<I: Isa>(self, isa: I) -> Vec<Outcome> {
        let mut st = <Stages<I, 8> as Scheme<I, Wide<'a, I>>>::new(isa);
        let mut narrow = <Stages<I, 4> as Scheme<I, Planar<'a, I, false>>>::new(isa);
        let mut out = Vec::with_capacity(self.cases.len());
        for group in self.cases.chunks(GROUP) {
            if group.len() > LANES {
                let r = integrate_wide(isa, self.f, self.t_final, group, self.opts, &mut st);
                out.extend_from_slice(&r[..group.len()]);
            } else {
                let r = integrate_group::<I, Stages<I, 4>, false>(isa, self.f, self.t_final, group, self.opts, &mut narrow);
                out.extend_from_slice(&r[..group.len()]);
            }
        }
        out
    }
}

/// Two lane vectors of the planar model (no STM, no SRP) as one state of eight components,
/// (phi, wz, cos phi, sin phi) of lanes 0-7 then of lanes 8-15: one step size and one orbit
/// evaluation per stage for both.
struct Wide<'a, I> {
    m: Planar<'a, I, false>,
    /// The second vector's parameters.
    q: Params<I>,
}

impl<I: Isa> Rhs<I, 8> for Wide<'_, I> {
    type At = PlanarAt;
    /// Not the two vectors' phi.
    const READS: [bool; 8] = all_but(&[0, 4]);

    #[inline(always)]
    fn at(&self, t: f64) -> PlanarAt {
        <Planar<'_, I, false> as Rhs<I, 4>>::at(&self.m, t)
    }

    #[inline(always)]
    fn at8(&self, ts: &[f64; 8]) -> [PlanarAt; 8] {
        <Planar<'_, I, false> as Rhs<I, 4>>::at8(&self.m, ts)
    }

    #[inline(always)]
    fn eval_at(&self, at: &PlanarAt, y: &[F8<I>; 8], dy: &mut [F8<I>; 8]) {
        // the halves in place: no copies of the states in, nor of the derivatives out
        let (ya, yb) = y.split_at(4);
        let (da, db) = dy.split_at_mut(4);
        rhs::<I, 4, false>(at, ya.try_into().expect("four components"), &self.m.p, da.try_into().expect("four components"));
        rhs::<I, 4, false>(at, yb.try_into().expect("four components"), &self.q, db.try_into().expect("four components"));
    }
}

/// Integrate one group of up to [`GROUP`] trajectories (no STM, no SRP) in lock step on two lane
/// vectors; missing lanes repeat the last.
#[inline(always)]
fn integrate_wide<I: Isa>(isa: I, f: &OrbitForcing, t_final: f64, group: &[Case], opts: &LaneOptions, st: &mut Stages<I, 8>) -> [Outcome; GROUP] {
    let n = group.len();
    let pick = |l: usize| group[l.min(n - 1)];
    let ya = <[F8<I>; 4] as PlanarY<I>>::start(isa, pick);
    let yb = <[F8<I>; 4] as PlanarY<I>>::start(isa, |l| pick(LANES + l));
    let mut y = [ya[0], ya[1], ya[2], ya[3], yb[0], yb[1], yb[2], yb[3]];
    let (p, _) = Params::new(isa, pick, opts.sun_omega, Sensitivity::None);
    let (q, _) = Params::new(isa, |l| pick(LANES + l), opts.sun_omega, Sensitivity::None);
    let model = Wide { m: Planar::<I, false>::new(f, p), q };
    let Run { accepted, rejected, status, .. } = run_steps(isa, st, &model, &mut y, t_final, opts, &mut NoCut);
    std::array::from_fn(|l| {
        if status != LaneStatus::Ok {
            return Outcome { phi_t: f64::NAN, wz_t: f64::NAN, stm: [f64::NAN; 4], dparam: [f64::NAN; 2], accepted, rejected, status };
        }
        let base = if l < LANES { 0 } else { 4 };
        let (phi_t, wz_t) = (lane(&y[base], l % LANES), lane(&y[base + 1], l % LANES));
        Outcome { phi_t, wz_t, stm: [f64::NAN; 4], dparam: [f64::NAN; 2], accepted, rejected, status }
    })
}

/// States of the planar model with the orbit alongside ([`Along`]): the attitude's eight (phi,
/// wz, cos phi, sin phi, the 2x2 STM), then the orbit's six.
const ALONG: usize = 14;

/// The planar model with the orbit integrated alongside, no forcing table: the re-propagation
/// of solutions ([`integrate_along`]). The orbit's six states are the same in every lane (set
/// from one state, advanced by the same operations, never cut differently), so each stage
/// evaluates the CR3BP and the forcing S, C once, from lane 0, for all eight, with the scalar
/// model's own functions ([`orbit_derivative`], [`forcing_sc`]); the attitude's derivatives are
/// the planar lanes' ([`rhs`]). Its orbit data at a time is the Sun's phase alone.
struct Along<I, const SRP: bool> {
    mu: f64,
    primaries: [bool; 2],
    p: Params<I>,
    recent: Recent<(f64, f64), 4>,
}

impl<I: Isa, const SRP: bool> Rhs<I, ALONG> for Along<I, SRP> {
    type At = (f64, f64);
    /// Not phi: [`rhs`] reads (wz, cos phi, sin phi) and the STM, the orbit part its state.
    const READS: [bool; ALONG] = all_but(&[0]);

    #[inline(always)]
    fn at(&self, t: f64) -> (f64, f64) {
        match self.recent.find(t) {
            Some(at) => at,
            None => self.recent.keep(t, self.p.sun::<SRP>(t)),
        }
    }

    #[inline(always)]
    fn at8(&self, ts: &[f64; 8]) -> [(f64, f64); 8] {
        let (swt, cwt) = self.p.sun8::<SRP>(ts);
        let mut out = [(0.0, 0.0); 8];
        for l in 0..8 {
            out[l] = (swt[l], cwt[l]);
        }
        out
    }

    #[inline(always)]
    fn eval_at(&self, at: &(f64, f64), y: &[F8<I>; ALONG], dy: &mut [F8<I>; ALONG]) {
        let isa = y[0].isa();
        let mut orbit = [0.0; 6];
        for i in 0..6 {
            orbit[i] = lane(&y[8 + i], 0);
        }
        let mut d = [0.0; 6];
        orbit_derivative(self.mu, false, 0.0, &orbit, &mut d);
        let (s, c) = forcing_sc(self.mu, &orbit, self.primaries);
        let mut ya = [y[0]; 8];
        ya.copy_from_slice(&y[..8]);
        let mut da = [y[0]; 8];
        rhs::<I, 8, SRP>(&PlanarAt { s, c, swt: at.0, cwt: at.1 }, &ya, &self.p, &mut da);
        dy[..8].copy_from_slice(&da);
        for i in 0..6 {
            dy[8 + i] = F8::splat(isa, d[i]);
        }
    }
}

impl<I: Isa, const SRP: bool> SunLanes<I> for Along<I, SRP> {
    const SRP: bool = SRP;

    #[inline(always)]
    fn alpha<Y: PlanarY<I>>(&self, t: f64, y: &Y) -> (F8<I>, F8<I>) {
        let (swt, cwt) = <Self as Rhs<I, ALONG>>::at(self, t);
        let (cp, sp) = y.cos_sin();
        sun_alpha(swt, cwt, &self.p, cp, sp)
    }

    fn sun_omega(&self) -> f64 {
        self.p.sun.omega
    }
}

/// Integrate planar attitude motions with the 2x2 STM, and the orbit from `orbit0` integrated
/// alongside (no forcing table: [`Along`]), from t = 0 to `t_final`, in lock-step groups of
/// [`LANES`] taken in order from the start of `cases`, at the SIMD `level`, RKF7(8) at
/// `opts.rtol`, `opts.atol` (`opts.method` is not read). Each outcome comes with its group's
/// integration error when the group's run failed. `SRP` compiles the flat-plate term in.
pub fn integrate_along<const SRP: bool>(level: Level, mu: f64, primaries: [bool; 2], orbit0: &[f64; 6], t_final: f64, cases: &[Case], opts: &LaneOptions) -> Result<Vec<(Outcome, Option<IntegrationError>)>> {
    crate::simd::run_at(level, AlongGroups::<SRP> { mu, primaries, orbit0, t_final, cases, opts })
}

/// [`integrate_along`] as a dispatched kernel.
struct AlongGroups<'a, const SRP: bool> {
    mu: f64,
    primaries: [bool; 2],
    orbit0: &'a [f64; 6],
    t_final: f64,
    cases: &'a [Case],
    opts: &'a LaneOptions,
}

impl<const SRP: bool> Kernel for AlongGroups<'_, SRP> {
    type Output = Vec<(Outcome, Option<IntegrationError>)>;
    #[inline(always)]
    fn run<I: Isa>(self, isa: I) -> Self::Output {
        let mut st = <Stages<I, ALONG> as Scheme<I, Along<I, SRP>>>::new(isa);
        let mut out = Vec::with_capacity(self.cases.len());
        for group in self.cases.chunks(LANES) {
            let n = group.len();
            let pick = |l: usize| group[l.min(n - 1)];
            let mut y = <[F8<I>; ALONG] as PlanarY<I>>::start(isa, pick);
            for i in 0..6 {
                y[8 + i] = F8::splat(isa, self.orbit0[i]);
            }
            <Stages<I, ALONG> as Scheme<I, Along<I, SRP>>>::begin(&mut st);
            let (p, plates) = Params::new(isa, pick, self.opts.sun_omega, Sensitivity::None);
            let model = Along::<I, SRP> { mu: self.mu, primaries: self.primaries, p, recent: Recent::new((f64::NAN, f64::NAN)) };
            let mut cut = Terminators::new(isa, n, &plates, self.opts, y);
            let run = run_steps(isa, &mut st, &model, &mut y, self.t_final, self.opts, &mut cut);
            let error = run.error(self.t_final, self.opts.max_steps);
            out.extend(outcomes(&y, run)[..n].iter().map(|o| (*o, error.clone())));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attitude::PlanarForced;
    use crate::integrate::{Options, System};
    use crate::orbit::correct_planar_symmetric;
    use crate::simd::Baseline;

    type I = Baseline;
    type V = F8<I>;
    const ISA: I = Baseline;

    /// The Earth-Moon DRO through x0 = 0.7 (mu = 0.01215): its period and forcing table.
    fn dro_forcing() -> (f64, OrbitForcing) {
        let mu = 0.01215;
        // ydot0 guess 0.6935, the family's (tests/common/mod.rs)
        let o = correct_planar_symmetric(mu, 0.7, 0.6935, 1e-12, 30, &Options::with_tolerances(1e-13, 1e-13)).unwrap();
        assert!((o.period - 4.858760231).abs() < 1e-6, "not the DRO: period {}", o.period);
        (o.period, OrbitForcing::new(mu, &o.state0, o.period, [true, true], 1e-13).unwrap())
    }

    /// The lanes' right-hand side (gravity gradient and flat plate through the shared generic
    /// laws, cos 2phi and sin 2phi from the (cos phi, sin phi) states, the Sun turned per lane)
    /// equals the scalar planar model's (`PlanarForced` on the same forcing table, with each
    /// case's `FlatPlate`), 2x2 STM included, to 1e-14 relative to the size of the terms
    /// (1 + 3 |Kz| max(|S|, |C|) + 3 |eps|, times max |STM entry|).
    #[test]
    fn lane_rhs_equals_scalar_model() {
        let (period, f) = dro_forcing();
        let cases: [Case; LANES] = std::array::from_fn(|l| {
            let x = l as f64;
            Case { phi0: -2.9 + 0.8 * x, wz0: -2.0 + 0.6 * x, kz: 0.9 - 0.25 * x, eps: [0.0, 0.05, 0.3, -0.2][l % 4], cs: 0.1 * (l % 3) as f64, cd: 0.2, theta_sun0: 0.9 * x - 3.0 }
        });
        let (p, plates) = Params::new(ISA, |l| cases[l], LaneOptions::default().sun_omega, Sensitivity::None);
        let model = Planar::<I, true>::new(&f, p);
        let stm = [0.7, -1.3, 2.1, 0.4];
        for t in [0.0, 0.37 * period, 0.81 * period, 3.3 * period] {
            let mut y = [V::splat(ISA, 0.0); 8];
            y[0] = V::new(ISA, cases.map(|c| c.phi0));
            y[1] = V::new(ISA, cases.map(|c| c.wz0));
            y[2] = V::new(ISA, cases.map(|c| c.phi0.cos()));
            y[3] = V::new(ISA, cases.map(|c| c.phi0.sin()));
            for i in 0..4 {
                y[4 + i] = V::splat(ISA, stm[i]);
            }
            let mut dy = [V::splat(ISA, 0.0); 8];
            rhs::<I, 8, true>(&model.orbit_at(t), &y, &model.p, &mut dy);
            let (s, c) = f.sc(t);
            for (l, case) in cases.iter().enumerate() {
                let scalar = PlanarForced { kz: case.kz, forcing: &f, srp: if case.eps != 0.0 { Some(plates[l]) } else { None } };
                let mut ds = [0.0; 6];
                scalar.derivative(t, &[case.phi0, case.wz0, stm[0], stm[1], stm[2], stm[3]], &mut ds);
                let scale = 1.0 + 3.0 * case.kz.abs() * s.abs().max(c.abs()) + 3.0 * case.eps.abs();
                let lanes = [lane(&dy[0], l), lane(&dy[1], l), lane(&dy[4], l), lane(&dy[5], l), lane(&dy[6], l), lane(&dy[7], l)];
                for i in 0..6 {
                    assert!((lanes[i] - ds[i]).abs() <= 1e-14 * scale * 3.0, "lane {l}, t {t}, component {i}: {} vs {}", lanes[i], ds[i]);
                }
                // the (cos phi, sin phi) states turn at phidot
                assert_eq!(lane(&dy[2], l), -(ds[0] * case.phi0.sin()));
                assert_eq!(lane(&dy[3], l), ds[0] * case.phi0.cos());
            }
        }
    }

    /// The orbit data of a step's 13 nodes, eight of them on the lanes ([`stage_data`]), equal
    /// one scalar evaluation per node bit for bit at every SIMD level this CPU has: steps inside
    /// one segment of the forcing table, across a segment boundary, across the period's end,
    /// over three segments (also across the period's end) and over four (the scalar fallback);
    /// with the Sun's phase (SRP). The plans take
    /// every recurring node (RKF7(8)'s c = 0, 1/6, 1; RK8(7)13M's c = 1) from its first stage.
    #[test]
    fn stage_data_equals_one_evaluation_per_node() {
        assert_eq!(FEHLBERG_PLAN, [OWN, -1, -2, -3, -4, -5, -6, 3, -7, -8, OWN, 0, 10]);
        assert_eq!(DP87_PLAN, [OWN, -1, -2, -3, -4, -5, -6, -7, -8, OWN, OWN, OWN, 11]);
        use Slot::{Lane as L, Own as O};
        assert_eq!(Fehlberg::SLOTS, [O(0), L(0), L(1), L(2), L(3), L(4), L(5), L(2), L(6), L(7), O(1), O(0), O(1)]);
        assert_eq!(PrinceDormand::SLOTS, [O(0), L(0), L(1), L(2), L(3), L(4), L(5), L(6), L(7), O(1), O(2), O(3), O(3)]);
        assert_eq!(Fehlberg::OWN_STAGES, ([0, 10, 0, 0], 2));
        assert_eq!(PrinceDormand::OWN_STAGES, ([0, 9, 10, 11], 4));
        let (period, f) = dro_forcing();
        let seg = period / f.segments() as f64;
        assert!(f.segments() >= 4, "{} segments", f.segments());
        // (t, h): inside segment 1, across the boundary of segments 1 and 2, across the period's
        // end, over three segments (the vector recurrence's three-way choice), over three
        // segments across the period's end, over four segments (the scalar fallback)
        let steps = [
            (1.1 * seg, 0.3 * seg),
            (1.9 * seg, 0.4 * seg),
            (period - 0.2 * seg, 0.5 * seg),
            (0.5 * seg, 2.0 * seg),
            (period - 1.3 * seg, 1.8 * seg),
            (0.5 * seg, 3.5 * seg),
        ];
        struct Probe<'a>(&'a OrbitForcing, [(f64, f64); 6]);
        impl Kernel for Probe<'_> {
            type Output = ();
            fn run<I: Isa>(self, isa: I) {
                let case = Case { eps: 0.05, theta_sun0: 0.7, ..Case::new(0.1, 0.3, 0.8) };
                let (p, _) = Params::new(isa, |_| case, LaneOptions::default().sun_omega, Sensitivity::None);
                let m = Planar::<I, true>::new(self.0, p);
                for (t, h) in self.1 {
                    let fehlberg = stage_data::<I, 4, _, Fehlberg>(&m, t, h);
                    let prince_dormand = stage_data::<I, 4, _, PrinceDormand>(&m, t, h);
                    let fehlberg: [PlanarAt; 13] = std::array::from_fn(|s| fehlberg[s]);
                    let prince_dormand: [PlanarAt; 13] = std::array::from_fn(|s| prince_dormand[s]);
                    for (c, got) in [(&C, &fehlberg), (&DP_C, &prince_dormand)] {
                        for s in 0..13 {
                            let want = m.orbit_at(c[s].mul_add(h, t));
                            let bits = |a: &PlanarAt| [a.s, a.c, a.swt, a.cwt].map(f64::to_bits);
                            assert_eq!(bits(&got[s]), bits(&want), "{}: t {t}, h {h}, stage {s}", I::LEVEL);
                        }
                    }
                }
            }
        }
        for &level in &crate::simd::available() {
            crate::simd::run_at(level, Probe(&f, steps)).unwrap();
        }
    }

    /// The SRP cut (analytic property of [`Terminators`]): along a trajectory of eight lanes with
    /// plates (different Sun phases and rates; RKF7(8) with the STM, and the Nystrom lanes), every
    /// accepted step that spans a crossing of cos alpha ends past the earliest one by at most
    /// [`CUT_TOL`]: at the cut some lane has crossed, and CUT_TOL before it none had; the state
    /// returned is the step to the cut, bit for bit; a step with no crossing is never cut.
    #[test]
    fn srp_cut_ends_just_past_the_earliest_crossing() {
        let (_, f) = dro_forcing();
        let cases: [Case; LANES] = std::array::from_fn(|l| {
            let x = l as f64;
            Case { eps: 0.3 + 0.2 * x, cs: 0.4, cd: 0.1, theta_sun0: 0.8 * x - 2.0, ..Case::new(0.3 * x, -2.5 + 0.7 * x, 0.8) }
        });
        fn check<S: Scheme<I, Planar<'static, I, true>>>(f: &'static OrbitForcing, cases: &[Case; LANES], t_end: f64) -> usize
        where
            S::Y: PlanarY<I>,
        {
            let opts = LaneOptions::default();
            let (rtol, atol) = (V::splat(ISA, opts.rtol), V::splat(ISA, opts.atol));
            let (p, _) = Params::new(ISA, |l| cases[l], opts.sun_omega, Sensitivity::None);
            let m = Planar::<I, true>::new(f, p);
            let mut st = S::new(ISA);
            let mut y = <S::Y as PlanarY<I>>::start(ISA, |l| cases[l]);
            let mut cut = Terminators { plate: [true; LANES], yc: y, yb: y, rtol, atol };
            let (mut t, h, mut cuts) = (0.0, 0.05, 0);
            let (mut ynew, mut yc) = (y, y);
            let sign = |v: &V| v.to_array().map(|g| g > 0.0);
            while t < t_end {
                st.step(&m, t, &y, h, &mut ynew, rtol, atol);
                let full = ynew;
                let g0 = sign(&m.alpha(t, &y).0);
                match cut.cut(&mut st, &m, t, h, &y, &mut ynew) {
                    None => {
                        let g1 = sign(&m.alpha(t + h, &full).0);
                        let gap = (0..LANES).find(|&l| g0[l] != g1[l]).map(|l| (l, m.alpha(t + h, &full).0.to_array()[l]));
                        assert!(gap.is_none() || gap.unwrap().1.abs() < 1e-9, "t {t}: a crossing not cut, {gap:?}");
                        y = full;
                        t += h;
                    }
                    Some(c) => {
                        cuts += 1;
                        assert!(c > 0.0 && c < h, "t {t}: cut {c}");
                        st.step(&m, t, &y, c, &mut yc, rtol, atol);
                        assert!((0..LANES).all(|l| yc.phi().to_array()[l].to_bits() == ynew.phi().to_array()[l].to_bits()), "t {t}: state at the cut");
                        let at = sign(&m.alpha(t + c, &ynew).0);
                        assert!((0..LANES).any(|l| at[l] != g0[l]), "t {t}: cut {c} before every crossing");
                        st.step(&m, t, &y, c - CUT_TOL, &mut yc, rtol, atol);
                        let before = sign(&m.alpha(t + c - CUT_TOL, &yc).0);
                        assert_eq!(before, g0, "t {t}: cut {c} more than CUT_TOL past a crossing");
                        y = ynew;
                        t += c;
                    }
                }
            }
            cuts
        }
        let f: &'static OrbitForcing = Box::leak(Box::new(f));
        let n = check::<Stages<I, 8>>(f, &cases, 8.0);
        assert!(n > 20, "{n} cuts");
        let n = check::<Nystrom<I, 3>>(f, &cases, 8.0);
        assert!(n > 20, "{n} cuts");
    }

    /// A model that declares every component read ([`Rhs::READS`]' default), delegating to `M`.
    struct ReadsAll<M>(M);

    impl<const D: usize, M: Rhs<I, D>> Rhs<I, D> for ReadsAll<M> {
        type At = M::At;
        fn at(&self, t: f64) -> M::At {
            self.0.at(t)
        }
        fn at8(&self, ts: &[f64; 8]) -> [M::At; 8] {
            self.0.at8(ts)
        }
        fn eval_at(&self, at: &M::At, y: &[V; D], dy: &mut [V; D]) {
            self.0.eval_at(at, y, dy)
        }
    }

    /// The stages skip phi's sums (`Planar::READS`, `Wide::READS`): the right-hand side must not
    /// read phi. Stepping with every component formed gives the same bits, for the state without
    /// and with the STM, with a flat plate (its terminator cuts), and on the wide path.
    #[test]
    fn stages_skip_only_what_the_rhs_does_not_read() {
        let (period, f) = dro_forcing();
        let opts = LaneOptions::default();
        let cases: Vec<Case> = (0..GROUP).map(|l| Case { eps: 0.02 * (l % 3) as f64, cs: 0.4, cd: 0.1, theta_sun0: 0.7, ..Case::new(0.1 * l as f64, -1.7 + 0.2 * l as f64, 0.8) }).collect();
        fn both<const D: usize, M: Rhs<I, D>>(m: M, y0: [V; D], t: f64, opts: &LaneOptions) -> ([V; D], [V; D]) {
            let (mut y1, mut y2) = (y0, y0);
            let (mut s1, mut s2) = (<Stages<I, D> as Scheme<I, M>>::new(ISA), <Stages<I, D> as Scheme<I, ReadsAll<M>>>::new(ISA));
            let r1 = run_steps(ISA, &mut s1, &m, &mut y1, t, opts, &mut NoCut);
            let m = ReadsAll(m);
            let r2 = run_steps(ISA, &mut s2, &m, &mut y2, t, opts, &mut NoCut);
            assert!(r1.accepted == r2.accepted && r1.accepted > 20, "{} against {} steps", r1.accepted, r2.accepted);
            (y1, y2)
        }
        let bits = |y: &[V]| y.iter().flat_map(|v| v.to_array()).map(f64::to_bits).collect::<Vec<u64>>();
        let pick = |l: usize| cases[l];
        let (p, _) = Params::new(ISA, pick, opts.sun_omega, Sensitivity::None);
        let (a, b) = both(Planar::<I, true>::new(&f, p), <[V; 8] as PlanarY<I>>::start(ISA, pick), period, &opts);
        assert_eq!(bits(&a), bits(&b));
        let (p, _) = Params::new(ISA, pick, opts.sun_omega, Sensitivity::None);
        let (a, b) = both(Planar::<I, false>::new(&f, p), <[V; 4] as PlanarY<I>>::start(ISA, pick), period, &opts);
        assert_eq!(bits(&a), bits(&b));
        let (p, _) = Params::new(ISA, pick, opts.sun_omega, Sensitivity::None);
        let (q, _) = Params::new(ISA, |l| pick(LANES + l), opts.sun_omega, Sensitivity::None);
        let (ya, yb) = (<[V; 4] as PlanarY<I>>::start(ISA, pick), <[V; 4] as PlanarY<I>>::start(ISA, |l| pick(LANES + l)));
        let y0 = [ya[0], ya[1], ya[2], ya[3], yb[0], yb[1], yb[2], yb[3]];
        let (a, b) = both(Wide { m: Planar::<I, false>::new(&f, p), q }, y0, period, &opts);
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(<Planar<'_, I, false> as Rhs<I, 8>>::READS, [false, true, true, true, true, true, true, true]);
        assert_eq!(<Wide<'_, I> as Rhs<I, 8>>::READS, [false, true, true, true, false, true, true, true]);
    }

    /// The wide path (groups of [`GROUP`] on two lane vectors): sixteen copies of one case give
    /// the bits of that case in a group of eight copies (both groups then see the same errors,
    /// so take the same steps); sixteen distinct cases agree with their groups of eight to 1e-9
    /// relative (the lanes' step sequences differ, each within tolerance; rtol 1e-12), and in
    /// steps to 2 %; a slice's last group of at most eight runs on one vector, the bits of the
    /// narrow path; and only the gravity map without the STM takes the wide path.
    #[test]
    fn wide_groups_agree_with_groups_of_eight() {
        let (period, f) = dro_forcing();
        let opts = LaneOptions::default();
        let wide_run = |cases: &[Case]| integrate_cases::<4, false>(Level::Baseline, &f, period, cases, &opts).unwrap();
        let narrow_run = |cases: &[Case]| {
            Groups::<4, false> { f: &f, t_final: period, cases, opts: &opts }.with::<I, Stages<I, 4>>(ISA)
        };
        let key = |o: &Outcome| (o.phi_t.to_bits(), o.wz_t.to_bits(), o.accepted, o.rejected);
        // one case, sixteen times
        let one = Case::new(0.3, -1.1, 0.8);
        let w = wide_run(&[one; GROUP]);
        let n = narrow_run(&[one; LANES]);
        assert!(w.iter().all(|o| key(o) == key(&n[0])), "{:?} vs {:?}", w[0], n[0]);
        // sixteen distinct cases: far apart (kz 0.9 to -0.6, wz0 -2.8 to 1.7), and sixteen
        // neighbours on a map's rate grid (wz0 step 0.0025, the standard map's)
        let apart: Vec<Case> = (0..GROUP).map(|l| Case::new(0.1 * l as f64, -2.8 + 0.3 * l as f64, 0.9 - 0.1 * l as f64)).collect();
        let near: Vec<Case> = (0..GROUP).map(|l| Case::new(0.0, -1.3 + 0.0025 * l as f64, 0.8)).collect();
        let steps = |r: &[Outcome]| r.iter().map(|o| o.accepted as f64).sum::<f64>();
        let mut w = Vec::new();
        for (cases, max_extra) in [(&apart, 0.5), (&near, 0.02)] {
            let n = narrow_run(cases);
            w = wide_run(cases);
            for (a, b) in w.iter().zip(&n) {
                let scale = 1f64.max(b.phi_t.abs()).max(b.wz_t.abs());
                assert!((a.phi_t - b.phi_t).abs() / scale < 1e-9 && (a.wz_t - b.wz_t).abs() / scale < 1e-9, "{a:?} vs {b:?}");
            }
            // the lock step costs steps where the lanes differ (here 31 %), not on a map's grid
            assert!(steps(&w) <= (1.0 + max_extra) * steps(&n), "{} against {} steps", steps(&w), steps(&n));
        }
        let cases = near;
        // 21 cases: a wide group, then a last group of five on one vector
        let mut more = cases.clone();
        more.extend((0..5).map(|l| Case::new(0.0, 1.0 + 0.2 * l as f64, 0.7)));
        let r = wide_run(&more);
        assert!(r[..GROUP].iter().zip(&w).all(|(a, b)| key(a) == key(b)));
        assert!(r[GROUP..].iter().zip(&narrow_run(&more[GROUP..])).all(|(a, b)| key(a) == key(b)));
        // the paths
        assert!(wide(false, false, &opts) && group_size(false, false, &opts) == GROUP);
        let other = [(true, false, opts), (false, true, opts), (false, false, LaneOptions { method: Method::Dp87, ..opts }), (false, false, LaneOptions { method: Method::Rkn86, ..opts }), (false, false, LaneOptions { sensitivity: Sensitivity::Kz, ..opts })];
        assert!(other.iter().all(|(stm, srp, o)| !wide(*stm, *srp, o) && group_size(*stm, *srp, o) == LANES));
    }
}
