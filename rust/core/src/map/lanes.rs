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
//! Trajectories are grouped eight by eight in case order from the start of the slice (the caller
//! aligns slices to multiples of eight), so a trajectory's result depends only on its group, never
//! on chunking or thread count: results are bit-identical for any of them.
//!
//! State per lane: (phi, wz, cos phi, sin phi) and, with the STM, the 2x2 d(phi, wz)/d(phi0,
//! wz0) row-major. Carrying (cos phi, sin phi) as states (d/dt = phidot (-sin, cos)) removes the
//! trigonometric calls of the gravity gradient (cos 2phi = c^2 - s^2, sin 2phi = 2 c s); phi
//! itself is integrated (phidot = wz - 1) and gives the unwrapped phi(T). The flat-plate SRP
//! law (PHYSICS.md sec. 6) is C1 only: a step never spans a lane's Sun-terminator crossing
//! (cos(theta_sun - phi) = 0); the step is cut there (Illinois iterations on its length).
//!
//! Nothing of the physics or the step control is written here: the lanes call the laws the
//! scalar planar model calls ([`gravity_gradient_wzdot`], [`flat_plate_wzdot`], [`Sun::angle`],
//! generic over the lane type) and step with the scalar driver's [`Controller`] and tableau.

use super::forcing::OrbitForcing;
use crate::attitude::{flat_plate_wzdot, gravity_gradient_wzdot, FlatPlate, Sun};
use crate::constants::SOLAR_PRESSURE_1AU;
use crate::integrate::tableau::{A, B8, C, ERR};
use crate::integrate::Controller;
use crate::scalar::F8;
use crate::error::Result;
use crate::simd::{Isa, Kernel, Level};

/// The scalar driver's step-size controller with its default settings.
const CONTROLLER: Controller = Controller::RKF78;

/// Trajectories per lock-step group (SIMD width).
pub const LANES: usize = 8;

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
}

impl Default for LaneOptions {
    fn default() -> Self {
        Self { rtol: 1e-12, atol: 1e-12, max_steps: 200_000, sun_omega: crate::constants::OMEGA_SUN }
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
    /// The Sun with phase zero: its angle at the shared time, turned by each lane's phase.
    sun: Sun,
}

impl<I: Isa> Params<I> {
    /// The lanes' parameters and their cases' plates.
    fn new(isa: I, pick: impl Fn(usize) -> Case, sun_omega: f64) -> (Self, [FlatPlate; LANES]) {
        let plates: [FlatPlate; LANES] = std::array::from_fn(|l| pick(l).plate(sun_omega));
        let p = Params {
            kz15: F8::new(isa, std::array::from_fn(|l| 1.5 * pick(l).kz)),
            a1: F8::new(isa, std::array::from_fn(|l| plates[l].coefficients().0)),
            a2: F8::new(isa, std::array::from_fn(|l| plates[l].coefficients().1)),
            c0: F8::new(isa, std::array::from_fn(|l| plates[l].sun.theta0.cos())),
            s0: F8::new(isa, std::array::from_fn(|l| plates[l].sun.theta0.sin())),
            sun: Sun { theta0: 0.0, ..plates[0].sun },
        };
        (p, plates)
    }
}

#[inline(always)]
fn lincomb<I: Isa, const D: usize, const M: usize>(out: &mut [F8<I>; D], y: &[F8<I>; D], h: F8<I>, coef: [f64; M], ks: [&[F8<I>; D]; M]) {
    let isa = h.isa();
    for i in 0..D {
        let mut acc = F8::splat(isa, 0.0);
        for m in 0..M {
            acc = F8::splat(isa, coef[m]).mul_add(ks[m][i], acc);
        }
        out[i] = h.mul_add(acc, y[i]);
    }
}

#[inline(always)]
fn rhs<I: Isa, const D: usize, const SRP: bool>(f: &OrbitForcing, t: f64, y: &[F8<I>; D], p: &Params<I>, dy: &mut [F8<I>; D]) {
    let isa = y[0].isa();
    let (s, c) = f.sc_at::<I>(t);
    let (s, c) = (F8::splat(isa, s), F8::splat(isa, c));
    let w = y[1] - F8::splat(isa, 1.0);
    let (cp, sp) = (y[2], y[3]);
    let c2 = cp * cp - sp * sp;
    let s2 = (cp + cp) * sp;
    dy[0] = w;
    // k (d wzdot / d phi) is only used with the STM: unused, it is compiled away
    let (mut dwz, mut k) = gravity_gradient_wzdot(p.kz15, s, c, c2, s2);
    dy[2] = -(w * sp);
    dy[3] = w * cp;
    if SRP {
        // Sun angle theta = w t + theta0_l: (cos, sin)(w t) turned by each lane's theta0_l;
        // alpha = theta - phi (sin alpha, like k, is compiled away without the STM)
        let (swt, cwt) = p.sun.angle(t).sin_cos();
        let (swt, cwt) = (F8::splat(isa, swt), F8::splat(isa, cwt));
        let ct = cwt * p.c0 - swt * p.s0;
        let st = swt * p.c0 + cwt * p.s0;
        let ca = ct.mul_add(cp, st * sp);
        let sa = st.mul_add(cp, -(ct * sp));
        let (v, d) = flat_plate_wzdot(p.a1, p.a2, ca, sa);
        dwz += v;
        k += d;
    }
    dy[1] = dwz;
    if D == 8 {
        dy[4] = y[6];
        dy[5] = y[7];
        dy[6] = k * y[4];
        dy[7] = k * y[5];
    }
}

struct Stages<I, const D: usize> {
    k: [[F8<I>; D]; 13],
    tmp: [F8<I>; D],
}

macro_rules! stage {
    ($st:ident, $f:ident, $t:ident, $y:ident, $h:ident, $p:ident, $s:literal; $($j:literal),+) => {{
        lincomb(&mut $st.tmp, $y, F8::splat($y[0].isa(), $h), [$(A[$s][$j]),+], [$(&$st.k[$j]),+]);
        rhs::<I, D, SRP>($f, C[$s].mul_add($h, $t), &$st.tmp, $p, &mut $st.k[$s]);
    }};
}

impl<I: Isa, const D: usize> Stages<I, D> {
    /// One step of size h from (t, y), all lanes: writes the 8th-order solution and returns the
    /// scaled max-norm error per lane.
    #[inline(always)]
    fn step<const SRP: bool>(&mut self, f: &OrbitForcing, t: f64, y: &[F8<I>; D], h: f64, p: &Params<I>, out: &mut [F8<I>; D], rtol: F8<I>, atol: F8<I>) -> F8<I> {
        let isa = y[0].isa();
        rhs::<I, D, SRP>(f, t, y, p, &mut self.k[0]);
        stage!(self, f, t, y, h, p, 1; 0);
        stage!(self, f, t, y, h, p, 2; 0, 1);
        stage!(self, f, t, y, h, p, 3; 0, 2);
        stage!(self, f, t, y, h, p, 4; 0, 2, 3);
        stage!(self, f, t, y, h, p, 5; 0, 3, 4);
        stage!(self, f, t, y, h, p, 6; 0, 3, 4, 5);
        stage!(self, f, t, y, h, p, 7; 0, 4, 5, 6);
        stage!(self, f, t, y, h, p, 8; 0, 3, 4, 5, 6, 7);
        stage!(self, f, t, y, h, p, 9; 0, 3, 4, 5, 6, 7, 8);
        stage!(self, f, t, y, h, p, 10; 0, 3, 4, 5, 6, 7, 8, 9);
        stage!(self, f, t, y, h, p, 11; 0, 5, 6, 7, 8, 9);
        stage!(self, f, t, y, h, p, 12; 0, 3, 4, 5, 6, 7, 8, 9, 11);
        let k = &self.k;
        let hv = F8::splat(isa, h);
        lincomb(out, y, hv, [B8[5], B8[6], B8[7], B8[8], B8[9], B8[11], B8[12]], [&k[5], &k[6], &k[7], &k[8], &k[9], &k[11], &k[12]]);
        let he = hv * F8::splat(isa, ERR);
        let mut err = F8::splat(isa, 0.0);
        for i in 0..D {
            let e = (he * ((k[0][i] + k[10][i]) - (k[11][i] + k[12][i]))).abs();
            let sc = rtol.mul_add(y[i].abs().max(out[i].abs()), atol);
            let r = e / sc;
            // keep NaN: a NaN ratio fails the `<=` test and becomes the lane's error
            err = r.le_select(err, err, r);
        }
        err
    }
}

fn lane<I: Isa>(v: &F8<I>, l: usize) -> f64 {
    v.to_array()[l]
}

/// Integrate one group of up to LANES trajectories in lock step; missing lanes repeat the last.
#[inline(always)]
fn integrate_group<I: Isa, const D: usize, const SRP: bool>(isa: I, f: &OrbitForcing, t_final: f64, group: &[Case], opts: &LaneOptions, st: &mut Stages<I, D>) -> [Outcome; LANES] {
    let n = group.len();
    let pick = |l: usize| group[l.min(n - 1)];
    let mut y = [F8::splat(isa, 0.0); D];
    y[0] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0));
    y[1] = F8::new(isa, std::array::from_fn(|l| pick(l).wz0));
    y[2] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0.cos()));
    y[3] = F8::new(isa, std::array::from_fn(|l| pick(l).phi0.sin()));
    if D == 8 {
        y[4] = F8::splat(isa, 1.0);
        y[7] = F8::splat(isa, 1.0);
    }
    let (p, plates) = Params::new(isa, pick, opts.sun_omega);
    let plate: [bool; LANES] = std::array::from_fn(|l| plates[l].eps != 0.0);
    let (rtol, atol) = (F8::splat(isa, opts.rtol), F8::splat(isa, opts.atol));
    let mut ynew = [F8::splat(isa, 0.0); D];
    let mut yc = [F8::splat(isa, 0.0); D];
    let (mut t, mut h) = (0.0f64, t_final / 100.0);
    let (mut accepted, mut rejected) = (0u32, 0u32);
    let mut after_reject = false;
    let mut status = LaneStatus::Ok;
    let g = |l: usize, tt: f64, phi: f64| plates[l].terminator(tt, phi);
    while t < t_final {
        if accepted + rejected >= opts.max_steps {
            status = LaneStatus::MaxSteps;
            break;
        }
        let rem = t_final - t;
        let (mut heff, mut last) = if h >= rem { (rem, true) } else { (h, false) };
        let err = st.step::<SRP>(f, t, &y, heff, &p, &mut ynew, rtol, atol).to_array();
        let emax = err.iter().fold(0.0f64, |m, &e| if e.is_nan() || e > m { if e.is_nan() { f64::INFINITY } else { e } } else { m });
        let finite = (0..D).all(|i| ynew[i].to_array().iter().all(|v| v.is_finite()));
        if !(emax <= 1.0) || !finite {
            rejected += 1;
            after_reject = true;
            h = heff * CONTROLLER.factor_rejected(emax);
            if h <= 1e-14 * t_final.max(1.0) {
                status = LaneStatus::Failed;
                break;
            }
            continue;
        }
        if SRP {
            // Cut the step at the earliest terminator crossing of any lane with a plate.
            let mut cut = f64::INFINITY;
            for (l, &has_plate) in plate.iter().enumerate() {
                if !has_plate {
                    continue;
                }
                let g0 = g(l, t, lane(&y[0], l));
                let g1 = g(l, t + heff, lane(&ynew[0], l));
                if !((g0 < 0.0 && g1 > 0.0) || (g0 > 0.0 && g1 < 0.0)) {
                    continue;
                }
                let (mut ta, mut tb, mut ga, mut gb, mut side) = (0.0f64, heff, g0, g1, 0i8);
                for _ in 0..60 {
                    if (tb - ta).abs() <= 1e-15 * (1.0 + t.abs()) + 4.0 * f64::EPSILON * tb.abs() {
                        break;
                    }
                    let tau = (tb - gb * (tb - ta) / (gb - ga)).clamp(ta.min(tb), ta.max(tb));
                    st.step::<SRP>(f, t, &y, tau, &p, &mut yc, rtol, atol);
                    let gc = g(l, t + tau, lane(&yc[0], l));
                    if (gc > 0.0) == (gb > 0.0) {
                        tb = tau;
                        gb = gc;
                        if side == 1 {
                            ga *= 0.5;
                        }
                        side = 1;
                    } else {
                        ta = tau;
                        ga = gc;
                        if side == -1 {
                            gb *= 0.5;
                        }
                        side = -1;
                    }
                }
                // just past the crossing, unless it is at the very start (a restart)
                if tb > 1e-12 * (1.0 + t.abs()) {
                    cut = cut.min(tb);
                }
            }
            if cut < heff {
                st.step::<SRP>(f, t, &y, cut, &p, &mut ynew, rtol, atol);
                heff = cut;
                last = false;
            }
        }
        accepted += 1;
        y = ynew;
        t = if last { t_final } else { t + heff };
        let fac = CONTROLLER.factor_accepted(emax, after_reject);
        after_reject = false;
        h = h.max(heff) * fac;
    }
    std::array::from_fn(|l| {
        if status != LaneStatus::Ok {
            return Outcome { phi_t: f64::NAN, wz_t: f64::NAN, stm: [f64::NAN; 4], accepted, rejected, status };
        }
        Outcome {
            phi_t: lane(&y[0], l),
            wz_t: lane(&y[1], l),
            stm: if D == 8 { [lane(&y[4], l), lane(&y[5], l), lane(&y[6], l), lane(&y[7], l)] } else { [f64::NAN; 4] },
            accepted,
            rejected,
            status,
        }
    })
}

/// Integrate `cases` from t = 0 to `t_final` along the orbit forcing, in lock-step groups of LANES
/// taken in order from the start of the slice, at the SIMD `level` ([`crate::simd`]; an error
/// only if the CPU lacks it). `D` is 4 (no STM) or 8 (with the 2x2 STM); `SRP` compiles the
/// flat-plate term in (lanes with eps = 0 add exact zeros and never cut steps).
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
        let mut st = Stages::<I, D> { k: [[F8::splat(isa, 0.0); D]; 13], tmp: [F8::splat(isa, 0.0); D] };
        let mut out = Vec::with_capacity(self.cases.len());
        for group in self.cases.chunks(LANES) {
            let r = integrate_group::<I, D, SRP>(isa, self.f, self.t_final, group, self.opts, &mut st);
            out.extend_from_slice(&r[..group.len()]);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attitude::PlanarForced;
    use crate::integrate::{Options, System};
    use crate::periodic::correct_planar_symmetric;
    use crate::simd::Baseline;

    type I = Baseline;
    type V = F8<I>;
    const ISA: I = Baseline;

    /// The lanes' right-hand side (gravity gradient and flat plate through the shared generic
    /// laws, cos 2phi and sin 2phi from the (cos phi, sin phi) states, the Sun turned per lane)
    /// equals the scalar planar model's (`PlanarForced` on the same forcing table, with each
    /// case's `FlatPlate`), 2x2 STM included, to 1e-14 relative to the size of the terms
    /// (1 + 3 |Kz| max(|S|, |C|) + 3 |eps|, times max |STM entry|).
    #[test]
    fn lane_rhs_equals_scalar_model() {
        let mu = 0.01215;
        let (x0, d) = (0.7, 1.0 - mu - 0.7);
        let o = correct_planar_symmetric(mu, x0, (mu / d).sqrt() + d, 1e-12, 30, &Options::with_tolerances(1e-13, 1e-13)).unwrap();
        let f = OrbitForcing::new(mu, &o.state0, o.period, [true, true], 1e-13).unwrap();
        let cases: [Case; LANES] = std::array::from_fn(|l| {
            let x = l as f64;
            Case { phi0: -2.9 + 0.8 * x, wz0: -2.0 + 0.6 * x, kz: 0.9 - 0.25 * x, eps: [0.0, 0.05, 0.3, -0.2][l % 4], cs: 0.1 * (l % 3) as f64, cd: 0.2, theta_sun0: 0.9 * x - 3.0 }
        });
        let (p, plates) = Params::new(ISA, |l| cases[l], LaneOptions::default().sun_omega);
        let stm = [0.7, -1.3, 2.1, 0.4];
        for t in [0.0, 0.37 * o.period, 0.81 * o.period, 3.3 * o.period] {
            let mut y = [V::splat(ISA, 0.0); 8];
            y[0] = V::new(ISA, cases.map(|c| c.phi0));
            y[1] = V::new(ISA, cases.map(|c| c.wz0));
            y[2] = V::new(ISA, cases.map(|c| c.phi0.cos()));
            y[3] = V::new(ISA, cases.map(|c| c.phi0.sin()));
            for i in 0..4 {
                y[4 + i] = V::splat(ISA, stm[i]);
            }
            let mut dy = [V::splat(ISA, 0.0); 8];
            rhs::<I, 8, true>(&f, t, &y, &p, &mut dy);
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
}
