//! Spacecraft dynamics under Earth, Moon and Sun point masses in Moon-centred ICRF axes (km,
//! km/s, TDB s), and the exact 6x6 STM by the variational equations.
//!
//! The relative equations: r'' = -GM_M r / |r|^3 + sum_b GM_b (d_b / |d_b|^3 - r_b / |r_b|^3),
//! d_b = r_b - r, r_b the body relative to the Moon (the second term is the Moon's own
//! acceleration by b, subtracted). Each third-body term is written in Battin's form
//! -GM_b / |d_b|^3 (r + F(q) r_b), q = r.(r - 2 r_b) / |r_b|^2,
//! F(q) = q (3 + 3q + q^2) / (1 + (1 + q)^(3/2)), which avoids the cancellation of the two
//! nearly equal terms (Battin, An Introduction to the Mathematics and Methods of Astrodynamics,
//! sec. 8.4). The gravity gradient of b is -GM_b (I / |d|^3 - 3 d d^T / |d|^5).

use rayon::prelude::*;

use super::chebyshev::{Ephemeris, MoonCentred};
use crate::error::{check_finite, invalid, Result};
use crate::integrate::{solve, Options, Output, System};

/// DE440 GM values, km^3/s^2 (the Sun's as published, 132712440041.279419).
pub const GM_EARTH: f64 = 398600.435507;
pub const GM_MOON: f64 = 4902.800118;
pub const GM_SUN: f64 = 132_712_440_041.279_42;

/// The right-hand side. Time is measured from `epoch0` (TDB s) to keep its resolution.
#[derive(Debug, Clone)]
pub struct EphemerisDynamics {
    bodies: MoonCentred,
    pub epoch0: f64,
    /// GM of Earth, Moon, Sun (km^3/s^2).
    pub gm: [f64; 3],
}

#[inline(always)]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl EphemerisDynamics {
    pub fn new(eph: Ephemeris, epoch0: f64) -> Result<Self> {
        Self::with_gm(eph, epoch0, [GM_EARTH, GM_MOON, GM_SUN])
    }

    pub fn with_gm(eph: Ephemeris, epoch0: f64, gm: [f64; 3]) -> Result<Self> {
        check_finite("gm", &gm)?;
        if gm.iter().any(|g| *g < 0.0) || gm[1] <= 0.0 {
            return Err(invalid("gm", format!("GM values must be >= 0 (the Moon's > 0), got {gm:?}")));
        }
        eph.check_epoch("epoch", epoch0)?;
        Ok(Self { bodies: MoonCentred::new(eph)?, epoch0, gm })
    }

    pub fn ephemeris(&self) -> &Ephemeris {
        self.bodies.ephemeris()
    }

    /// Acceleration at (t, r) and, when `grad` is given, its gradient d a / d r.
    #[inline]
    pub fn acceleration(&self, t: f64, r: &[f64; 3], grad: Option<&mut [[f64; 3]; 3]>) -> [f64; 3] {
        self.acceleration_among(&self.bodies(t), r, grad)
    }

    /// Earth and Sun relative to the Moon at t (s from `epoch0`): their positions (km); NaN
    /// outside the span.
    #[inline]
    pub fn bodies(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        self.bodies.positions(self.epoch0 + t)
    }

    /// [`Self::acceleration`] with the bodies of [`Self::bodies`] already evaluated (a model that
    /// needs them too, as the attitude's torques, evaluates the Chebyshev series once).
    #[inline]
    pub fn acceleration_among(&self, bodies: &([f64; 3], [f64; 3]), r: &[f64; 3], grad: Option<&mut [[f64; 3]; 3]>) -> [f64; 3] {
        let (earth, sun) = *bodies;
        let mut a = [0.0; 3];
        let r2 = dot(r, r);
        let rn = r2.sqrt();
        let k = self.gm[1] / (r2 * rn);
        for c in 0..3 {
            a[c] = -k * r[c];
        }
        let mut g = [[0.0; 3]; 3];
        let want = grad.is_some();
        if want {
            let k5 = 3.0 * self.gm[1] / (r2 * r2 * rn);
            for i in 0..3 {
                for j in 0..3 {
                    g[i][j] = k5 * r[i] * r[j] - if i == j { k } else { 0.0 };
                }
            }
        }
        for (gm, rb) in [(self.gm[0], earth), (self.gm[2], sun)] {
            if gm == 0.0 {
                continue;
            }
            let d = [rb[0] - r[0], rb[1] - r[1], rb[2] - r[2]];
            let d2 = dot(&d, &d);
            let dn = d2.sqrt();
            let q = (r2 - 2.0 * dot(r, &rb)) / dot(&rb, &rb);
            let f = q * (3.0 + 3.0 * q + q * q) / (1.0 + (1.0 + q).powf(1.5));
            let kd = gm / (d2 * dn);
            for c in 0..3 {
                a[c] -= kd * (r[c] + f * rb[c]);
            }
            if want {
                let k5 = 3.0 * gm / (d2 * d2 * dn);
                for i in 0..3 {
                    for j in 0..3 {
                        g[i][j] += k5 * d[i] * d[j] - if i == j { kd } else { 0.0 };
                    }
                }
            }
        }
        if let Some(out) = grad {
            *out = g;
        }
        a
    }
}

impl System<[f64; 6]> for EphemerisDynamics {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 6], dy: &mut [f64; 6]) {
        let a = self.acceleration(t, &[y[0], y[1], y[2]], None);
        *dy = [y[3], y[4], y[5], a[0], a[1], a[2]];
    }
}

/// State and STM (row-major 6x6 after the state): 42 components.
impl System<[f64; 42]> for EphemerisDynamics {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 42], dy: &mut [f64; 42]) {
        let mut g = [[0.0; 3]; 3];
        let a = self.acceleration(t, &[y[0], y[1], y[2]], Some(&mut g));
        dy[..6].copy_from_slice(&[y[3], y[4], y[5], a[0], a[1], a[2]]);
        let phi = &y[6..];
        // Phi' = [[0, I], [G, 0]] Phi.
        for j in 0..6 {
            for i in 0..3 {
                dy[6 + i * 6 + j] = phi[(i + 3) * 6 + j];
                dy[6 + (i + 3) * 6 + j] = g[i][0] * phi[j] + g[i][1] * phi[6 + j] + g[i][2] * phi[12 + j];
            }
        }
    }
}

/// A propagated ephemeris trajectory.
#[derive(Debug, Clone)]
pub struct EphemerisTrajectory {
    /// Output epochs, TDB s past J2000.
    pub t_tdb: Vec<f64>,
    /// Row-major n x 6, km and km/s.
    pub states: Vec<f64>,
    pub state_final: [f64; 6],
    /// Row-major 6x6 STM from the start to the end, when asked for.
    pub stm: Option<[f64; 36]>,
}

/// The integration tolerances of ephemeris propagation unless given: rtol 1e-13, atol 1e-9 (km,
/// km/s).
pub fn default_options() -> Options {
    Options::with_tolerances(1e-13, 1e-9)
}

/// Propagate a Moon-centred ICRF state from `epoch` for `duration` s (either sign), with the STM
/// when asked. `t_eval` are offsets from the epoch (None: every step).
pub fn propagate_ephemeris(dynamics: &EphemerisDynamics, state: &[f64; 6], duration: f64, stm: bool, t_eval: Option<&[f64]>, opts: &Options) -> Result<EphemerisTrajectory> {
    check_finite("state_km", state)?;
    if !duration.is_finite() {
        return Err(invalid("duration_s", format!("must be finite, got {duration}")));
    }
    let eph = dynamics.ephemeris();
    eph.check_epoch("epoch", dynamics.epoch0)?;
    eph.check_epoch("epoch + duration_s", dynamics.epoch0 + duration)?;
    let output = match t_eval {
        Some(ts) => Output::At(ts),
        None => Output::Steps,
    };
    let e0 = dynamics.epoch0;
    if stm {
        let mut y0 = [0.0; 42];
        y0[..6].copy_from_slice(state);
        for i in 0..6 {
            y0[6 + 7 * i] = 1.0;
        }
        let sol = solve(dynamics, 0.0, &y0, duration, opts, output, &[])?;
        let mut states = Vec::with_capacity(sol.t.len() * 6);
        for row in sol.y.chunks_exact(42) {
            states.extend_from_slice(&row[..6]);
        }
        let mut phi = [0.0; 36];
        phi.copy_from_slice(&sol.y_final[6..]);
        let mut sf = [0.0; 6];
        sf.copy_from_slice(&sol.y_final[..6]);
        Ok(EphemerisTrajectory { t_tdb: sol.t.iter().map(|t| e0 + t).collect(), states, state_final: sf, stm: Some(phi) })
    } else {
        let sol = solve(dynamics, 0.0, state, duration, opts, output, &[])?;
        Ok(EphemerisTrajectory { t_tdb: sol.t.iter().map(|t| e0 + t).collect(), states: sol.y, state_final: sol.y_final, stm: None })
    }
}

/// Propagate many (state, start epoch, duration) legs on rayon; results in the input order
/// (each leg is integrated alone, so the result does not depend on the thread count). Only the
/// final state (and STM) of each leg is kept.
pub fn propagate_ephemeris_batch(eph: &Ephemeris, gm: [f64; 3], legs: &[([f64; 6], f64, f64)], stm: bool, opts: &Options) -> Vec<Result<EphemerisTrajectory>> {
    legs.par_iter()
        .map(|(s, e, d)| {
            let dynamics = EphemerisDynamics::with_gm(eph.clone(), *e, gm)?;
            propagate_ephemeris(&dynamics, s, *d, stm, Some(&[*d]), opts)
        })
        .collect()
}
