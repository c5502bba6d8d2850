//! The periodicity-map engine (thesis sec. 3.3, docs/physics.md, periodic attitude motions): planar attitude
//! trajectories along one orbit for many (phi0, wz0, Kz), integrated over one period (or K
//! periods) in SIMD lanes on all cores, with the orbit forcing computed once per orbit; and its
//! 3-D counterpart ([`sweep_3d`]): the rigid body's (q, w) along any periodic orbit for many
//! initial rates and bodies, over the orbit's tidal tensor tabulated once.

pub mod crossings;

pub use crate::integrate::lanes3d::{sweep_3d, sweep_3d_at};
pub use crossings::{crossings, levels, unresolved, windows, Crossing};

use crate::integrate::forcing::OrbitForcing;
use crate::integrate::lanes::{self, integrate_cases, Case, LaneOptions, Outcome};

use rayon::prelude::*;

use crate::error::{check_positive, invalid, Result};
use crate::propagation::with_threads;
use crate::simd::Level;

/// Residuals of one trajectory: Dwz = wz(T) - wz0, Dphi = phi(T) - phi0 wrapped to (-pi, pi].
pub fn residuals(case: &Case, o: &Outcome) -> (f64, f64) {
    let d = o.phi_t - case.phi0;
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut w = d - two_pi * (d / two_pi).round();
    if w <= -std::f64::consts::PI {
        w += two_pi;
    }
    (o.wz_t - case.wz0, w)
}

/// Integrate every case over `t_final` on `threads` workers (None: all cores), `chunk` cases
/// per task, at the active SIMD level ([`crate::simd::active`]). Results are in case order and
/// bit-identical for any `chunk` and thread count.
pub fn sweep(
    forcing: &OrbitForcing,
    t_final: f64,
    cases: &[Case],
    opts: &LaneOptions,
    with_stm: bool,
    chunk: usize,
    threads: Option<usize>,
) -> Result<Vec<Outcome>> {
    sweep_at(crate::simd::active()?, forcing, t_final, cases, opts, with_stm, chunk, threads)
}

/// [`sweep`] at a given SIMD level (an error naming `LIBRATE_SIMD` if the CPU lacks it).
/// Bit-identical for any `chunk` and thread count on one level; between levels, equal to the
/// rounding of fused against unfused multiply-adds ([`crate::simd`]).
pub fn sweep_at(
    level: Level,
    forcing: &OrbitForcing,
    t_final: f64,
    cases: &[Case],
    opts: &LaneOptions,
    with_stm: bool,
    chunk: usize,
    threads: Option<usize>,
) -> Result<Vec<Outcome>> {
    check_positive("t_final", t_final)?;
    crate::integrate::check_tolerances(opts.rtol, opts.atol)?;
    if chunk == 0 {
        return Err(invalid("chunk", "must be >= 1"));
    }
    for (i, c) in cases.iter().enumerate() {
        if !(c.phi0.is_finite() && c.wz0.is_finite()) {
            return Err(invalid("wz0", format!("case {i}: phi0 and wz0 must be finite, got ({}, {})", c.phi0, c.wz0)));
        }
        if !(c.kz.is_finite() && (-1.0..=1.0).contains(&c.kz)) {
            return Err(invalid("kz", format!("case {i}: must be in [-1, 1], got {}", c.kz)));
        }
    }
    for (i, c) in cases.iter().enumerate() {
        if !(c.eps.is_finite() && c.theta_sun0.is_finite()) {
            return Err(invalid("eps", format!("case {i}: eps and the Sun phase must be finite")));
        }
        if !(c.cs >= 0.0 && c.cd >= 0.0 && c.cs + c.cd <= 1.0 + 1e-12) {
            return Err(invalid("cs", format!("case {i}: need cs, cd >= 0 and cs + cd <= 1, got ({}, {})", c.cs, c.cd)));
        }
    }
    // One kernel for the whole sweep: with SRP anywhere, every group takes the flat-plate kernel
    // (its lanes without a plate add exact zeros: the gravity kernel's bits on the same group).
    let srp = opts.sensitivity == lanes::Sensitivity::Eps || cases.iter().any(|c| c.eps != 0.0);
    // Lock-step groups are taken from the start of each chunk: chunks are multiples of the group
    // size (lanes::group_size: two lane vectors for the gravity map without the STM, else one)
    // so that the groups, and so the results, are the same for any chunk size.
    let group = lanes::group_size(with_stm, srp, opts);
    let chunk = chunk.div_ceil(group) * group;
    if !level.is_available() {
        crate::simd::parse(Some(level.name()))?;
    }
    let run = |part: &[Case]| -> Result<Vec<Outcome>> {
        crate::interrupt::check()?;
        match (with_stm, srp) {
            (true, false) => integrate_cases::<8, false>(level, forcing, t_final, part, opts),
            (false, false) => integrate_cases::<4, false>(level, forcing, t_final, part, opts),
            (true, true) => integrate_cases::<8, true>(level, forcing, t_final, part, opts),
            (false, true) => integrate_cases::<4, true>(level, forcing, t_final, part, opts),
        }
    };
    let parts = with_threads(threads, || cases.par_chunks(chunk).map(run).collect::<Result<Vec<_>>>())??;
    Ok(parts.concat())
}
