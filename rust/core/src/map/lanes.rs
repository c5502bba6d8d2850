//! The attitude periodicity engine's integrator: RKF7(8) on four trajectories at once in SIMD
//! lanes (`wide::f64x4`), each lane with its own time, step size and Kz, refilled with the next
//! trajectory as soon as its own finishes.
//!
//! State per lane: (phi, wz, cos phi, sin phi) and, with the STM, the 2x2 d(phi, wz)/d(phi0,
//! wz0) row-major. Carrying (cos phi, sin phi) as states (d/dt = phidot (-sin, cos)) removes the
//! trigonometric calls of the gravity gradient (cos 2phi = c^2 - s^2, sin 2phi = 2 c s); phi
//! itself is integrated (phidot = wz - 1) and gives the unwrapped phi(T). With solar radiation
//! pressure (the flat plate of PHYSICS.md sec. 6, per-lane eps, Cs, Cd and Sun phase) the Sun
//! angle needs one sin_cos per evaluation; that path is compiled separately (`SRP`).
//!
//! Every operation is lane-wise, so a trajectory's result does not depend on which lane it
//! ran in or on its neighbours: results are bit-identical for any chunking and thread count.

use wide::f64x4;

use super::forcing::OrbitForcing;
use crate::integrate::tableau::{A, B8, C, ERR};

type V = f64x4;

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
        Self { rtol: 1e-12, atol: 1e-12, max_steps: 200_000, sun_omega: crate::attitude::OMEGA_SUN }
    }
}

/// Per-lane parameters.
#[derive(Clone, Copy)]
struct Params {
    kz15: V,
    /// eps (1 + Cs), eps (2/3) Cd, Sun phase at t = 0.
    a1: V,
    a2: V,
    theta0: V,
    omega: V,
}

#[inline(always)]
fn lincomb<const D: usize, const M: usize>(out: &mut [V; D], y: &[V; D], h: V, coef: [f64; M], ks: [&[V; D]; M]) {
    for i in 0..D {
        let mut acc = V::ZERO;
        for m in 0..M {
            acc = V::splat(coef[m]).mul_add(ks[m][i], acc);
        }
        out[i] = h.mul_add(acc, y[i]);
    }
}

#[inline(always)]
fn rhs<const D: usize, const SRP: bool>(f: &OrbitForcing, t: V, y: &[V; D], p: &Params, dy: &mut [V; D]) {
    let (s, c) = f.sc4(t);
    let w = y[1] - V::ONE;
    let (cp, sp) = (y[2], y[3]);
    let c2 = cp * cp - sp * sp;
    let s2 = (cp + cp) * sp;
    dy[0] = w;
    let mut dwz = p.kz15 * (s * c2 - c * s2);
    dy[2] = -(w * sp);
    dy[3] = w * cp;
    let mut k = V::ZERO;
    if D == 8 {
        k = -(p.kz15 + p.kz15) * (s * s2 + c * c2);
    }
    if SRP {
        // alpha = theta_sun(t) - phi
        let (st, ct) = p.omega.mul_add(t, p.theta0).sin_cos();
        let ca = ct.mul_add(cp, st * sp);
        let aca = ca.abs();
        dwz = dwz + ca * p.a1.mul_add(aca, p.a2);
        if D == 8 {
            let sa = st.mul_add(cp, -(ct * sp));
            k = k + sa * (p.a1 + p.a1).mul_add(aca, p.a2);
        }
    }
    dy[1] = dwz;
    if D == 8 {
        dy[4] = y[6];
        dy[5] = y[7];
        dy[6] = k * y[4];
        dy[7] = k * y[5];
    }
}

struct Stages<const D: usize> {
    k: [[V; D]; 13],
    tmp: [V; D],
}

macro_rules! stage {
    ($st:ident, $f:ident, $t:ident, $y:ident, $h:ident, $kz:ident, $s:literal; $($j:literal),+) => {{
        lincomb(&mut $st.tmp, $y, $h, [$(A[$s][$j]),+], [$(&$st.k[$j]),+]);
        let ts = V::splat(C[$s]).mul_add($h, $t);
        rhs::<D, SRP>($f, ts, &$st.tmp, $kz, &mut $st.k[$s]);
    }};
}

impl<const D: usize> Stages<D> {
    /// One step of size h (per lane) from (t, y): writes the 8th-order solution and returns the
    /// scaled max-norm error per lane.
    #[inline(always)]
    fn step<const SRP: bool>(&mut self, f: &OrbitForcing, t: V, y: &[V; D], h: V, kz15: &Params, out: &mut [V; D], rtol: V, atol: V) -> V {
        rhs::<D, SRP>(f, t, y, kz15, &mut self.k[0]);
        stage!(self, f, t, y, h, kz15, 1; 0);
        stage!(self, f, t, y, h, kz15, 2; 0, 1);
        stage!(self, f, t, y, h, kz15, 3; 0, 2);
        stage!(self, f, t, y, h, kz15, 4; 0, 2, 3);
        stage!(self, f, t, y, h, kz15, 5; 0, 3, 4);
        stage!(self, f, t, y, h, kz15, 6; 0, 3, 4, 5);
        stage!(self, f, t, y, h, kz15, 7; 0, 4, 5, 6);
        stage!(self, f, t, y, h, kz15, 8; 0, 3, 4, 5, 6, 7);
        stage!(self, f, t, y, h, kz15, 9; 0, 3, 4, 5, 6, 7, 8);
        stage!(self, f, t, y, h, kz15, 10; 0, 3, 4, 5, 6, 7, 8, 9);
        stage!(self, f, t, y, h, kz15, 11; 0, 5, 6, 7, 8, 9);
        stage!(self, f, t, y, h, kz15, 12; 0, 3, 4, 5, 6, 7, 8, 9, 11);
        let k = &self.k;
        lincomb(out, y, h, [B8[5], B8[6], B8[7], B8[8], B8[9], B8[11], B8[12]], [&k[5], &k[6], &k[7], &k[8], &k[9], &k[11], &k[12]]);
        let he = h * V::splat(ERR);
        let mut err = V::ZERO;
        for i in 0..D {
            let e = (he * ((k[0][i] + k[10][i]) - (k[11][i] + k[12][i]))).abs();
            let sc = rtol.mul_add(y[i].abs().max(out[i].abs()), atol);
            let r = e / sc;
            // keep NaN: a NaN ratio fails the `<=` test and becomes the lane's error
            err = r.simd_le(err).select(err, r);
        }
        err
    }
}

/// Integrate `cases` from t = 0 to `t_final` along the orbit forcing, four at a time. `D` is 4
/// (no STM) or 8 (with the 2x2 STM); `SRP` compiles the flat-plate term in (cases with eps = 0
/// give the same bits on either path: the term adds exact zeros).
pub fn integrate_cases<const D: usize, const SRP: bool>(f: &OrbitForcing, t_final: f64, cases: &[Case], opts: &LaneOptions) -> Vec<Outcome> {
    let mut out = vec![
        Outcome { phi_t: f64::NAN, wz_t: f64::NAN, stm: [f64::NAN; 4], accepted: 0, rejected: 0, status: LaneStatus::Failed };
        cases.len()
    ];
    let mut st = Stages::<D> { k: [[V::ZERO; D]; 13], tmp: [V::ZERO; D] };
    let (rtol, atol) = (V::splat(opts.rtol), V::splat(opts.atol));
    let h_init = t_final / 100.0;
    // Lane bookkeeping (scalar), mirrored into vectors before each step.
    let mut lane_case: [Option<usize>; 4] = [None; 4];
    let mut yl = [[0.0f64; D]; 4];
    let mut tl = [0.0f64; 4];
    let mut hl = [0.0f64; 4];
    let mut kzl = [0.0f64; 4];
    let mut a1l = [0.0f64; 4];
    let mut a2l = [0.0f64; 4];
    let mut th0l = [0.0f64; 4];
    let mut acc = [0u32; 4];
    let mut rej = [0u32; 4];
    let mut after_reject = [false; 4];
    let mut next = 0usize;

    let start = |l: usize, i: usize, yl: &mut [[f64; D]; 4], tl: &mut [f64; 4], hl: &mut [f64; 4], pl: [&mut [f64; 4]; 4]| {
        let c = cases[i];
        let mut y = [0.0; D];
        y[0] = c.phi0;
        y[1] = c.wz0;
        let (s1, c1) = c.phi0.sin_cos();
        y[2] = c1;
        y[3] = s1;
        let [kzl, a1l, a2l, th0l] = pl;
        a1l[l] = c.eps * (1.0 + c.cs);
        a2l[l] = c.eps * (2.0 / 3.0) * c.cd;
        th0l[l] = c.theta_sun0;
        if D == 8 {
            y[4] = 1.0;
            y[7] = 1.0;
        }
        yl[l] = y;
        tl[l] = 0.0;
        hl[l] = h_init;
        kzl[l] = c.kz;
    };
    for l in 0..4 {
        if next < cases.len() {
            start(l, next, &mut yl, &mut tl, &mut hl, [&mut kzl, &mut a1l, &mut a2l, &mut th0l]);
            lane_case[l] = Some(next);
            next += 1;
        }
    }
    let mut ynew = [V::ZERO; D];
    while lane_case.iter().any(|c| c.is_some()) {
        // Pack lanes (idle lanes take h = 0: a harmless null step).
        let mut y = [V::ZERO; D];
        for i in 0..D {
            y[i] = V::new(std::array::from_fn(|l| if lane_case[l].is_some() { yl[l][i] } else if i == 2 { 1.0 } else { 0.0 }));
        }
        let mut heff = [0.0; 4];
        let mut last = [false; 4];
        for l in 0..4 {
            if lane_case[l].is_some() {
                let rem = t_final - tl[l];
                if hl[l] >= rem {
                    heff[l] = rem;
                    last[l] = true;
                } else {
                    heff[l] = hl[l];
                }
            }
        }
        let t = V::new(tl);
        let h = V::new(heff);
        let params = Params { kz15: V::new(kzl) * V::splat(1.5), a1: V::new(a1l), a2: V::new(a2l), theta0: V::new(th0l), omega: V::splat(opts.sun_omega) };
        let err = st.step::<SRP>(f, t, &y, h, &params, &mut ynew, rtol, atol).to_array();
        // err^(-1/8) per lane through three square roots, lane-wise.
        let e8 = V::new(err).sqrt().sqrt().sqrt().to_array();
        let mut ynew_l: [[f64; 4]; D] = std::array::from_fn(|i| ynew[i].to_array());
        if SRP {
            // The plate law is C1 only: a step may not span a terminator crossing
            // (cos(theta_sun - phi) = 0). Lanes whose accepted step crosses one are cut back to
            // the crossing, located by Illinois iterations on the step length (each trial one
            // RK step from the step start; lanes not searching take h = 0).
            let g = |l: usize, tt: f64, phi: f64| (opts.sun_omega * tt + th0l[l] - phi).cos();
            let mut search = [false; 4];
            let (mut ta, mut tb, mut ga, mut gb) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
            let mut side = [0i8; 4];
            for l in 0..4 {
                // lanes without a plate term (eps = 0) have no kink: same steps as gravity only
                if lane_case[l].is_none() || !(err[l] <= 1.0) || (a1l[l] == 0.0 && a2l[l] == 0.0) {
                    continue;
                }
                let g0 = g(l, tl[l], yl[l][0]);
                let g1 = g(l, tl[l] + heff[l], ynew_l[0][l]);
                if (g0 < 0.0 && g1 > 0.0) || (g0 > 0.0 && g1 < 0.0) {
                    search[l] = true;
                    (ta[l], tb[l], ga[l], gb[l]) = (0.0, heff[l], g0, g1);
                }
            }
            if search.iter().any(|&b| b) {
                let mut yc = [V::ZERO; D];
                let mut tau = [0.0f64; 4];
                for _ in 0..60 {
                    let mut active = false;
                    for l in 0..4 {
                        tau[l] = 0.0;
                        if search[l] {
                            let tol = 1e-15 * (1.0 + tl[l].abs()) + 4.0 * f64::EPSILON * tb[l].abs();
                            if (tb[l] - ta[l]).abs() <= tol {
                                continue;
                            }
                            active = true;
                            let c = tb[l] - gb[l] * (tb[l] - ta[l]) / (gb[l] - ga[l]);
                            tau[l] = c.clamp(ta[l].min(tb[l]), ta[l].max(tb[l]));
                        }
                    }
                    if !active {
                        break;
                    }
                    st.step::<SRP>(f, t, &y, V::new(tau), &params, &mut yc, rtol, atol);
                    let yc0 = yc[0].to_array();
                    for l in 0..4 {
                        if !search[l] || tau[l] == 0.0 {
                            continue;
                        }
                        let gc = g(l, tl[l] + tau[l], yc0[l]);
                        if (gc > 0.0) == (gb[l] > 0.0) {
                            tb[l] = tau[l];
                            gb[l] = gc;
                            if side[l] == 1 {
                                ga[l] *= 0.5;
                            }
                            side[l] = 1;
                        } else {
                            ta[l] = tau[l];
                            ga[l] = gc;
                            if side[l] == -1 {
                                gb[l] *= 0.5;
                            }
                            side[l] = -1;
                        }
                    }
                }
                // Cut each searching lane's step at the far end of its final bracket (just past
                // the crossing), unless the crossing is at the very start (a restart).
                let mut cut = [0.0f64; 4];
                for l in 0..4 {
                    if search[l] && tb[l].abs() > 1e-12 * (1.0 + tl[l].abs()) {
                        cut[l] = tb[l];
                    }
                }
                if cut.iter().any(|&c| c != 0.0) {
                    st.step::<SRP>(f, t, &y, V::new(cut), &params, &mut yc, rtol, atol);
                    let ycl: [[f64; 4]; D] = std::array::from_fn(|i| yc[i].to_array());
                    for l in 0..4 {
                        if cut[l] != 0.0 {
                            for i in 0..D {
                                ynew_l[i][l] = ycl[i][l];
                            }
                            if cut[l] < heff[l] {
                                last[l] = false;
                                heff[l] = cut[l];
                            }
                        }
                    }
                }
            }
        }
        for l in 0..4 {
            let Some(ci) = lane_case[l] else { continue };
            let finite = (0..D).all(|i| ynew_l[i][l].is_finite());
            let ok = err[l] <= 1.0 && finite;
            let fac_max = if after_reject[l] { 1.0 } else { 5.0 };
            let fac = if ok {
                if err[l] == 0.0 { fac_max } else { (0.8 / e8[l]).clamp(0.2, fac_max) }
            } else if err[l].is_finite() {
                (0.8 / e8[l]).clamp(0.2, 1.0)
            } else {
                0.2
            };
            let mut finished = None;
            if ok {
                acc[l] += 1;
                after_reject[l] = false;
                for i in 0..D {
                    yl[l][i] = ynew_l[i][l];
                }
                tl[l] = if last[l] { t_final } else { tl[l] + heff[l] };
                hl[l] = heff[l] * fac;
                if last[l] {
                    finished = Some(LaneStatus::Ok);
                }
            } else {
                rej[l] += 1;
                after_reject[l] = true;
                hl[l] = heff[l] * fac;
                if hl[l] <= 1e-14 * t_final.max(1.0) {
                    finished = Some(LaneStatus::Failed);
                }
            }
            if finished.is_none() && acc[l] + rej[l] >= opts.max_steps {
                finished = Some(LaneStatus::MaxSteps);
            }
            if let Some(status) = finished {
                let y = &yl[l];
                out[ci] = Outcome {
                    phi_t: if status == LaneStatus::Ok { y[0] } else { f64::NAN },
                    wz_t: if status == LaneStatus::Ok { y[1] } else { f64::NAN },
                    stm: if D == 8 && status == LaneStatus::Ok { [y[4], y[5], y[6], y[7]] } else { [f64::NAN; 4] },
                    accepted: acc[l],
                    rejected: rej[l],
                    status,
                };
                acc[l] = 0;
                rej[l] = 0;
                after_reject[l] = false;
                if next < cases.len() {
                    start(l, next, &mut yl, &mut tl, &mut hl, [&mut kzl, &mut a1l, &mut a2l, &mut th0l]);
                    lane_case[l] = Some(next);
                    next += 1;
                } else {
                    lane_case[l] = None;
                }
            }
        }
    }
    out
}
