//! From candidates to verified solutions in one call: a batch of planar candidates corrected
//! ([`correct_planar_attitudes`]), the converged ones inside a rate window kept once per
//! solution, each re-propagated independently ([`verify_planar_attitudes`]), and those whose
//! independent residual is small kept. A map's crossings and a periodic-attitude search take
//! this path; the Python facade only turns its records into solutions.

use super::periodic::{correct_planar_attitudes, full_closure_residual, verify_planar_attitudes, Candidate, Closure, Correction, CorrectorOptions, Free, PlanarEnd, PlanarStart};
use super::srp::{FlatPlate, Sun};
use crate::error::{check_finite, invalid, Result};
use crate::integrate::forcing::OrbitForcing;

/// Two converged candidates of one group with the same Kz and turns are one solution when their
/// wz0 differ by less than this (1/TU).
pub const SAME_SOLUTION: f64 = 1e-8;

/// A verified solution is kept when its independent residual (max-norm of the full closure's
/// residuals) is at most this.
pub const MAX_VERIFIED_RESIDUAL: f64 = 1e-8;

/// What tells two solutions apart: the same group, Kz and turns with wz0 within
/// [`SAME_SOLUTION`] are one solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolutionKey {
    pub group: i64,
    pub kz: f64,
    pub turns: f64,
    pub wz0: f64,
}

/// The indices of the first of each solution among `keys`, in order: a key is kept unless a
/// kept one is the same solution ([`SolutionKey`]).
pub fn distinct(keys: &[SolutionKey]) -> Vec<usize> {
    let mut ok: Vec<usize> = Vec::with_capacity(keys.len());
    for (i, k) in keys.iter().enumerate() {
        let same = |j: &usize| {
            let o = &keys[*j];
            o.group == k.group && o.kz == k.kz && o.turns == k.turns && (o.wz0 - k.wz0).abs() < SAME_SOLUTION
        };
        if !ok.iter().any(same) {
            ok.push(i);
        }
    }
    ok
}

/// The orbit of a forcing table with what its independent re-propagation needs.
#[derive(Debug, Clone, Copy)]
pub struct PlanarOrbit<'a> {
    pub mu: f64,
    pub state0: [f64; 6],
    /// The gravity-gradient sources [larger, smaller] of the table.
    pub primaries: [bool; 2],
    pub forcing: &'a OrbitForcing,
}

/// One kept solution.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    /// Its candidate's index in the batch.
    pub index: usize,
    /// The corrector's outcome (converged).
    pub correction: Correction,
    /// The independent re-propagation over the full closure time (K T), with its 2x2 STM.
    pub end: PlanarEnd,
    /// The full closure's residuals of that re-propagation ([`full_closure_residual`]).
    pub residual: [f64; 2],
}

/// Refine a batch of candidates (the form of [`correct_planar_attitudes`] with phi0 the free
/// angle of the full closure; `t_final` its closure time) and verify the solutions:
///
/// 1. every candidate corrected in one call (`opts`; `opts.monodromy` is not needed, as the
///    verification brings the STM);
/// 2. the converged ones with `keep.0 <= wz0 <= keep.1`, ordered by group (in order of first
///    appearance in `groups`, one label per candidate), Kz and wz0, kept once per solution
///    ([`distinct`]: (group, Kz, turns) and wz0 within [`SAME_SOLUTION`]; the first);
/// 3. those re-propagated in that order, together ([`verify_planar_attitudes`] over the full
///    closure time, K T = 2 `t_final` for the half closure; a plate where the candidate has
///    one), and kept when their residual's max-norm is at most [`MAX_VERIFIED_RESIDUAL`].
///
/// Results are in that order and do not depend on the thread count; `Err` for invalid
/// arguments (each naming the parameter).
pub fn refine_planar_attitudes(
    orbit: &PlanarOrbit<'_>,
    t_final: f64,
    closure: Closure,
    candidates: &[Candidate],
    groups: &[i64],
    opts: &CorrectorOptions,
    keep: (f64, f64),
) -> Result<Vec<Refined>> {
    if groups.len() != candidates.len() {
        return Err(invalid("groups", format!("one label per candidate ({}), got {}", candidates.len(), groups.len())));
    }
    if keep.0.is_nan() || keep.1.is_nan() || keep.0 > keep.1 {
        return Err(invalid("keep", format!("a window (lo, hi) of wz0 with lo <= hi, got {keep:?}")));
    }
    check_finite("orbit_state0", &orbit.state0)?;
    if candidates.is_empty() {
        return Ok(Vec::new());
    }
    let corrections = correct_planar_attitudes(orbit.forcing, t_final, closure, Free::Phi0, candidates, opts)?;
    // groups in order of first appearance
    let mut labels: Vec<i64> = Vec::new();
    for g in groups {
        if !labels.contains(g) {
            labels.push(*g);
        }
    }
    let rank = |g: i64| labels.iter().position(|&l| l == g).unwrap_or(usize::MAX);
    let mut conv: Vec<usize> = (0..candidates.len()).filter(|&i| corrections[i].converged() && corrections[i].wz0 >= keep.0 && corrections[i].wz0 <= keep.1).collect();
    // a stable sort (the batch order among equals)
    let key = |i: usize| (rank(groups[i]), candidates[i].case.kz, corrections[i].wz0);
    conv.sort_by(|&i, &j| key(i).partial_cmp(&key(j)).unwrap_or(std::cmp::Ordering::Equal));
    let keys: Vec<SolutionKey> = conv.iter().map(|&i| SolutionKey { group: groups[i], kz: candidates[i].case.kz, turns: candidates[i].turns, wz0: corrections[i].wz0 }).collect();
    let ok: Vec<usize> = distinct(&keys).into_iter().map(|j| conv[j]).collect();
    let starts = ok
        .iter()
        .map(|&i| {
            let (c, x) = (&candidates[i].case, &corrections[i]);
            let plate = if c.eps != 0.0 { Some(FlatPlate::new(c.eps, c.cs, c.cd, Sun { theta0: x.theta_sun0, omega: opts.sun_omega, ..Sun::default() })?) } else { None };
            Ok(PlanarStart { kz: c.kz, phi0: x.phi0, wz0: x.wz0, plate })
        })
        .collect::<Result<Vec<_>>>()?;
    let t_verify = if closure == Closure::Half { 2.0 * t_final } else { t_final };
    let ends = verify_planar_attitudes(orbit.mu, &orbit.state0, t_verify, &starts, orbit.primaries, opts.threads)?;
    Ok(ok
        .into_iter()
        .zip(ends)
        .filter_map(|(i, end)| {
            let x = &corrections[i];
            let residual = full_closure_residual(x.phi0, x.wz0, candidates[i].turns, end.phi_t, end.wz_t);
            // a NaN (a failed re-propagation) is never kept
            let small = residual.iter().all(|r| r.abs() <= MAX_VERIFIED_RESIDUAL);
            small.then_some(Refined { index: i, correction: *x, end, residual })
        })
        .collect())
}
