//! The batched planar attitude corrector (attitude::correct_planar_attitudes) and verifier
//! (attitude::verify_planar_attitudes): analytic cases, the thesis's Fig. 23 solution, the
//! agreement of its forms, batching, threads, globalisation and the Sun-phase form with SRP.
//! Each test names its reference and its tolerance.

use librate_core::attitude::srp::N_SUN;
use librate_core::attitude::{FlatPlate, Sun};
use librate_core::integrate::Options;
use librate_core::integrate::forcing::OrbitForcing;
use librate_core::integrate::lanes::{Case, LaneOptions, LaneStatus};
use librate_core::map::sweep;
use librate_core::attitude::{
    correct_bordered, correct_planar_attitudes, verify_planar_attitudes, Bordered, Candidate, Closure, Correction, CorrectorOptions,
    Free, Parameter, PlanarStart, StopReason,
};
use librate_core::orbit::{Constraint, SymmetricShooting};
use std::f64::consts::PI;

mod common;
use common::{dro, MU};
/// Earth-Moon TU: 375190 s (docs/physics.md).
const TU_S: f64 = 375190.0;


/// The DRO with the given period (TU), from a guess (x0, vy0).
fn dro_period(period: f64, x0: f64, vy0: f64) -> ([f64; 6], f64) {
    let mut sh = SymmetricShooting::new(MU, false, Options::with_tolerances(1e-13, 1e-13));
    sh.tol = 1e-12;
    let o = sh.correct([x0, 0.0, vy0], Constraint::Period(period)).unwrap();
    assert!((o.period - period).abs() < 1e-10);
    (o.state0, o.period)
}

/// The thesis's 12.66-day DRO (Fig. 23).
fn dro1266() -> ([f64; 6], f64) {
    dro_period(12.66 * 86400.0 / TU_S, 0.82017, 0.50343)
}

/// The 1:2 Sun-resonant DRO: T = Ts / 2, Ts = 2 pi / (1 - N_SUN).
fn sun12() -> ([f64; 6], f64) {
    dro_period(PI / (1.0 - N_SUN), 0.79593, 0.53151)
}

fn table(s0: &[f64; 6], period: f64) -> OrbitForcing {
    OrbitForcing::new(MU, s0, period, [true, true], 1e-13).unwrap()
}

fn bits(c: &Correction) -> Vec<u64> {
    let mut v = vec![c.phi0.to_bits(), c.wz0.to_bits(), c.theta_sun0.to_bits(), c.residual_norm.to_bits(), c.iterations as u64, c.reason as u64];
    v.extend(c.residual.iter().chain(&c.monodromy).map(|x| x.to_bits()));
    v
}

fn lane_opts() -> LaneOptions {
    LaneOptions { rtol: 1e-13, atol: 1e-13, ..LaneOptions::default() }
}

/// Kz = 0 (axisymmetric body, no torque): phi(t) = phi0 + (wz0 - 1) t exactly, so the periodic
/// motions are exactly wz0 = 1 + 2 pi turns / (K T) (analytic; Half: phi(KT/2) = phi0 + pi turns
/// gives the same). From starts 0.3 off, both forms converge to it to 1e-12 for N = -2..1 and
/// half turns, K = 1 and 2. Full: Phi(KT) - I = [[0, KT], [0, 0]] is singular (every phi0 is a
/// solution): the minimum-norm step keeps phi0 and converges. The monodromy is [[1, KT], [0, 1]].
#[test]
fn val_torque_free_solutions_are_analytic() {
    let (s0, t) = dro(0.8);
    let f = table(&s0, t);
    let opts = CorrectorOptions::default();
    for k in [1.0, 2.0] {
        let turns: Vec<f64> = vec![-2.0, -1.0, -0.5, 0.0, 0.5, 1.0];
        let exact = |n: f64| 1.0 + 2.0 * PI * n / (k * t);
        let half: Vec<Candidate> = turns.iter().map(|&n| Candidate::new(0.0, exact(n) + 0.3, 0.0, n)).collect();
        let full: Vec<Candidate> = turns.iter().map(|&n| Candidate::new(0.4, exact(n) - 0.3, 0.0, n)).collect();
        let rh = correct_planar_attitudes(&f, 0.5 * k * t, Closure::Half, Free::Phi0, &half, &opts).unwrap();
        let rf = correct_planar_attitudes(&f, k * t, Closure::Full, Free::Phi0, &full, &opts).unwrap();
        for ((n, h), g) in turns.iter().zip(&rh).zip(&rf) {
            for r in [h, g] {
                assert_eq!(r.reason, StopReason::Converged, "K = {k}, N = {n}: {r:?}");
                assert!((r.wz0 - exact(*n)).abs() < 1e-12, "K = {k}, N = {n}: {} vs {}", r.wz0, exact(*n));
                assert!(r.residual_norm <= 1e-12 && r.iterations >= 1);
                let m = r.monodromy;
                assert!((m[0] - 1.0).abs() < 1e-12 && (m[1] - k * t).abs() < 1e-11 && m[2].abs() < 1e-12 && (m[3] - 1.0).abs() < 1e-12, "{m:?}");
            }
            assert_eq!(h.phi0, 0.0);
            assert_eq!(g.phi0, 0.4);
        }
    }
}

/// Thesis Fig. 23 (docs/physics.md, periodic attitude motions): on the 12.66-day DRO (mu = 0.01215, TU = 375190 s) with
/// Kz = 0.8 the N = -1 solution is at phidot0 = wz0 - 1 = -2.4545 (4 digits: 1e-4). From the
/// torque-free guess the half-period form converges (residual <= 1e-12); the independent
/// re-propagation over the full period (the lanes with the orbit integrated alongside, 1e-14)
/// closes to < 1e-11 and its monodromy equals the corrector's to 1e-8 relative.
#[test]
fn val_thesis_fig23_solution() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let c = Candidate::new(0.0, 1.0 - 2.0 * PI / t, 0.8, -1.0);
    let r = correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, &[c], &CorrectorOptions::default()).unwrap()[0];
    assert_eq!(r.reason, StopReason::Converged);
    assert!((r.wz0 - 1.0 + 2.4545).abs() < 1e-4 && (r.wz0 + 1.4545).abs() < 1e-4, "wz0 = {}", r.wz0);
    assert!(r.residual_norm <= 1e-12);
    let v = verify_planar_attitudes(MU, &s0, t, &[PlanarStart { kz: 0.8, phi0: r.phi0, wz0: r.wz0, plate: None }], [true, true], None).unwrap();
    let v = &v[0];
    assert!(v.error.is_none());
    let res = (v.phi_t - r.phi0 + 2.0 * PI).abs().max((v.wz_t - r.wz0).abs());
    assert!(res < 1e-11, "re-propagated residual {res:e}");
    let n = v.stm.iter().map(|x| x * x).sum::<f64>().sqrt();
    let e = (0..4).map(|i| (v.stm[i] - r.monodromy[i]).powi(2)).sum::<f64>().sqrt() / n;
    assert!(e < 1e-8, "monodromy {:?} vs {:?}", r.monodromy, v.stm);
}

/// On a symmetric case (12.66-day DRO, Kz = 0.8, N = -1, phi0 = 0) the half-period and the
/// full-period forms find the same solution: wz0 to 1e-10, phi0 = 0 to 1e-10 (Full started
/// 1e-3 off in both unknowns), monodromies to 1e-8 relative.
#[test]
fn val_half_and_full_closures_agree() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let opts = CorrectorOptions::default();
    let h = correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, &[Candidate::new(0.0, -1.4, 0.8, -1.0)], &opts).unwrap()[0];
    let g = correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[Candidate::new(1e-3, h.wz0 + 1e-3, 0.8, -1.0)], &opts).unwrap()[0];
    assert!(h.converged() && g.converged(), "{h:?} {g:?}");
    assert!((h.wz0 - g.wz0).abs() < 1e-10 && g.phi0.abs() < 1e-10, "{} vs {} (phi0 {})", h.wz0, g.wz0, g.phi0);
    let n = g.monodromy.iter().map(|x| x * x).sum::<f64>().sqrt();
    let e = (0..4).map(|i| (g.monodromy[i] - h.monodromy[i]).powi(2)).sum::<f64>().sqrt() / n;
    assert!(e < 1e-8);
}

fn batch_candidates(t: f64) -> Vec<Candidate> {
    let mut c = Vec::new();
    for (i, kz) in [0.8, 0.5, 0.3, -0.4, 0.95].into_iter().enumerate() {
        for n in [-2.0, -1.0, 0.0, 1.0] {
            for dw in [-0.1, 0.15] {
                c.push(Candidate::new(0.0, 1.0 + 2.0 * PI * n / t + dw + 0.01 * i as f64, kz, n));
            }
        }
    }
    c
}

/// Batching: 40 candidates (5 Kz, N = -2..1, two starts each) corrected in one batch end as
/// each corrected alone: the same stop reason, and for the converged ones wz0 and phi0 to 1e-11
/// (lock-step lanes share step sizes: the last bits may differ; module docs). For both forms;
/// the batch is bit-identical for 1 and 2 threads and chunk sizes 1 and 64.
#[test]
fn val_batch_equals_single_and_is_deterministic() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let cands = batch_candidates(t);
    for (closure, tf) in [(Closure::Half, 0.5 * t), (Closure::Full, t)] {
        let one = CorrectorOptions { threads: Some(1), ..CorrectorOptions::default() };
        let two = CorrectorOptions { threads: Some(2), chunk: 1, ..CorrectorOptions::default() };
        let a = correct_planar_attitudes(&f, tf, closure, Free::Phi0, &cands, &one).unwrap();
        let b = correct_planar_attitudes(&f, tf, closure, Free::Phi0, &cands, &two).unwrap();
        assert_eq!(a.iter().map(bits).collect::<Vec<_>>(), b.iter().map(bits).collect::<Vec<_>>(), "{closure:?}: threads/chunk changed bits");
        let mut converged = 0;
        for (c, r) in cands.iter().zip(&a) {
            let s = correct_planar_attitudes(&f, tf, closure, Free::Phi0, &[*c], &one).unwrap()[0];
            assert_eq!(s.reason, r.reason, "{closure:?} {c:?}: {s:?} vs {r:?}");
            if r.converged() {
                converged += 1;
                assert!((s.wz0 - r.wz0).abs() < 1e-11 && (s.phi0 - r.phi0).abs() < 1e-11, "{closure:?} {c:?}: {s:?} vs {r:?}");
            }
        }
        assert!(converged >= 30, "{closure:?}: only {converged} of {} converged", cands.len());
    }
}

/// Undamped Newton (x += -J^-1 F) on (phi0, wz0) (12.66-day DRO, Kz = 0.8, N = -1, phi0 = 0.3)
/// from 40 starts wz0 in [-3, 2.85] ends 40 iterations later with a residual > 1 from several of
/// them (e.g. wz0 = -1.5: thrown to wz0 = -516); the globalised corrector converges from at least
/// one of those (residual <= 1e-12) and from >= 30 of the 40 starts. Every result is either
/// converged with a finite residual <= tol and a finite monodromy, or reports why not: never a
/// NaN labelled converged. With max_steps = 5 every candidate reports IntegrationFailed.
#[test]
fn val_line_search_globalises_newton() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let opts = CorrectorOptions::default();
    let starts: Vec<Candidate> = (0..40).map(|k| Candidate::new(0.3, -3.0 + 0.15 * k as f64, 0.8, -1.0)).collect();
    let all = correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &starts, &opts).unwrap();
    let mut undamped_failed = Vec::new();
    for (k, c) in starts.iter().enumerate() {
        let (mut p, mut w) = (c.case.phi0, c.case.wz0);
        let mut res = f64::INFINITY;
        for _ in 0..40 {
            let o = sweep(&f, t, &[Case::new(p, w, 0.8)], &lane_opts(), true, 8, Some(1)).unwrap()[0];
            if o.status != LaneStatus::Ok {
                res = f64::INFINITY;
                break;
            }
            let fv = [o.phi_t - p + 2.0 * PI, o.wz_t - w];
            res = fv[0].abs().max(fv[1].abs());
            if res <= 1e-12 {
                break;
            }
            let j = [o.stm[0] - 1.0, o.stm[1], o.stm[2], o.stm[3] - 1.0];
            let det = j[0] * j[3] - j[1] * j[2];
            p -= (j[3] * fv[0] - j[1] * fv[1]) / det;
            w -= (-j[2] * fv[0] + j[0] * fv[1]) / det;
            if !(p.is_finite() && w.is_finite()) {
                res = f64::INFINITY;
                break;
            }
        }
        if res.is_nan() || res >= 1.0 {
            undamped_failed.push(k);
        }
    }
    assert!(undamped_failed.len() >= 2, "undamped Newton failed from {undamped_failed:?} only");
    assert!(undamped_failed.iter().any(|&k| all[k].converged()), "{:?}", undamped_failed.iter().map(|&k| all[k]).collect::<Vec<_>>());
    for r in &all {
        if r.converged() {
            assert!(r.residual_norm <= opts.tol && r.phi0.is_finite() && r.wz0.is_finite() && r.monodromy.iter().all(|x| x.is_finite()), "{r:?}");
        } else {
            assert!(r.residual_norm.is_nan() || r.residual_norm > opts.tol || r.reason == StopReason::MaxIterations, "{r:?}");
        }
    }
    let n_conv = all.iter().filter(|r| r.converged()).count();
    println!("undamped failed from {:?}; globalised: {n_conv} of 40 converged; there: {:?}", undamped_failed.iter().map(|&k| starts[k].case.wz0).collect::<Vec<_>>(), undamped_failed.iter().map(|&k| all[k].reason).collect::<Vec<_>>());
    assert!(n_conv >= 30);
    let starved = CorrectorOptions { max_steps: 5, ..opts };
    for closure in [Closure::Half, Closure::Full] {
        let tf = if closure == Closure::Half { 0.5 * t } else { t };
        let r = correct_planar_attitudes(&f, tf, closure, Free::Phi0, &[Candidate::new(0.0, -1.4, 0.8, -1.0)], &starved).unwrap();
        for x in &r {
            assert_eq!(x.reason, StopReason::IntegrationFailed);
            assert!(x.residual_norm.is_nan() && x.monodromy[0].is_nan() && x.iterations == 0);
        }
    }
}

/// docs/physics.md, solar radiation pressure: with SRP and phi0 = 0 kept, periodic motions exist for special Sun
/// phases only. On the 1:2 Sun-resonant DRO (T = Ts / 2, K = 2), Kz = 0.8, N = -2, a flat plate
/// eps = 0.5, cs = 0.4, cd = 0.1: Free::SunPhase from the gravity-only solution and Sun phase
/// 1.4 converges (residual <= 1e-12) to the phase pi/2 (to 1e-9; the solution of the Python
/// corrector: wz0 = -1.43736, 1e-5); the re-propagation with the plate closes to < 1e-9
/// over 2 T and its STM equals the corrector's monodromy to 1e-7 relative (FD-free column).
/// From the phases 1.6 and 0.3 (same batch) the result is converged and re-verified likewise, or
/// an honest stop reason with a residual above tol (from 1.6 the line search ends in a local
/// minimum of |F| at residual 0.25: NoDescent). Bit-identical for 1 and 2 threads.
#[test]
fn val_sun_phase_with_srp() {
    let (s0, t) = sun12();
    let f = table(&s0, t);
    let opts = CorrectorOptions::default();
    let g = correct_planar_attitudes(&f, t, Closure::Half, Free::Phi0, &[Candidate::new(0.0, 1.0 - 4.0 * PI / (2.0 * t), 0.8, -2.0)], &opts).unwrap()[0];
    assert!(g.converged());
    let starts = [1.4, 1.6, 0.3].map(|th| Candidate::new(0.0, g.wz0, 0.8, -2.0).with_plate(0.5, 0.4, 0.1, th));
    let r = correct_planar_attitudes(&f, 2.0 * t, Closure::Full, Free::SunPhase, &starts, &opts).unwrap();
    let r1 = correct_planar_attitudes(&f, 2.0 * t, Closure::Full, Free::SunPhase, &starts, &CorrectorOptions { threads: Some(1), chunk: 3, ..opts }).unwrap();
    let r2 = correct_planar_attitudes(&f, 2.0 * t, Closure::Full, Free::SunPhase, &starts, &CorrectorOptions { threads: Some(2), chunk: 1, ..opts }).unwrap();
    assert_eq!(r.iter().map(bits).collect::<Vec<_>>(), r1.iter().map(bits).collect::<Vec<_>>());
    assert_eq!(r.iter().map(bits).collect::<Vec<_>>(), r2.iter().map(bits).collect::<Vec<_>>());
    let ok: Vec<&Correction> = r.iter().filter(|x| x.converged()).collect();
    assert!(r[0].converged());
    assert!((r[0].theta_sun0 - 0.5 * PI).abs() < 1e-9 && (r[0].wz0 + 1.43736).abs() < 1e-5, "{:?}", r[0]);
    assert!(r.iter().all(|x| x.converged() || x.residual_norm > opts.tol));
    let items: Vec<PlanarStart> = ok
        .iter()
        .map(|x| PlanarStart { kz: 0.8, phi0: x.phi0, wz0: x.wz0, plate: Some(FlatPlate::new(0.5, 0.4, 0.1, Sun { theta0: x.theta_sun0, ..Sun::default() }).unwrap()) })
        .collect();
    let v = verify_planar_attitudes(MU, &s0, 2.0 * t, &items, [true, true], Some(2)).unwrap();
    for (x, e) in ok.iter().zip(&v) {
        assert_eq!(x.phi0, 0.0);
        assert!(x.residual_norm <= 1e-12);
        let res = (e.phi_t - x.phi0 + 4.0 * PI).abs().max((e.wz_t - x.wz0).abs());
        assert!(res < 1e-9, "{x:?}: re-propagated residual {res:e}");
        let n = e.stm.iter().map(|v| v * v).sum::<f64>().sqrt();
        let d = (0..4).map(|i| (e.stm[i] - x.monodromy[i]).powi(2)).sum::<f64>().sqrt() / n;
        assert!(d < 1e-7, "monodromy {:?} vs {:?}", x.monodromy, e.stm);
    }
}

/// The verifier (the SIMD lanes with the orbit's CR3BP states integrated alongside, 1e-14) against
/// an independent reference: the scalar planar model with the orbit alongside
/// (`propagate_planar`, integrated piecewise between the plate's terminator crossings located as
/// events) at rtol = atol = 3e-15. Nineteen motions on the 1:2 Sun-resonant DRO over 2 T, Kz =
/// 0.6, rates -1.6..1.2 (fast and slow, many terminator crossings), plates eps 0..2 (cs 0.4,
/// cd 0.1, Sun phases 0..2) and three without: phi and wz within 1e-10 of the reference, each
/// STM entry within 1e-8 relative to max(1, |entry|) (the scalar model at 1e-14 is within 5e-11
/// and 1e-9 of it on such motions). Results do not depend on the threads; a motion's result
/// depends on its group of eight (the first eight alone equal themselves in the full call).
#[test]
fn val_verifier_matches_the_scalar_model() {
    use librate_core::attitude::propagate_planar;
    use librate_core::integrate::Output;
    let (s0, t) = sun12();
    let items: Vec<PlanarStart> = (0..19)
        .map(|i| {
            let x = i as f64;
            let plate = (i % 6 != 5).then(|| FlatPlate::new(0.11 * x, 0.4, 0.1, Sun { theta0: 0.1 * x, ..Sun::default() }).unwrap());
            PlanarStart { kz: 0.6, phi0: 0.3 * x - 2.0, wz0: -1.6 + 2.8 * x / 18.0, plate }
        })
        .collect();
    let v = verify_planar_attitudes(MU, &s0, 2.0 * t, &items, [true, true], None).unwrap();
    let reference = Options::with_tolerances(3e-15, 3e-15);
    for (it, e) in items.iter().zip(&v) {
        assert!(e.error.is_none(), "{it:?}: {:?}", e.error);
        let r = propagate_planar(MU, it.kz, [true, true], false, &s0, it.phi0, it.wz0, 0.0, 2.0 * t, &reference, true, Output::Final, it.plate).unwrap();
        let (phi, wz, stm) = (*r.phi.last().unwrap(), *r.wz.last().unwrap(), r.stm_final.unwrap());
        assert!((e.phi_t - phi).abs() < 1e-10 && (e.wz_t - wz).abs() < 1e-10, "{it:?}: ({}, {}) vs ({phi}, {wz})", e.phi_t, e.wz_t);
        for k in 0..4 {
            assert!((e.stm[k] - stm[k]).abs() < 1e-8 * stm[k].abs().max(1.0), "{it:?}: stm {:?} vs {stm:?}", e.stm);
        }
    }
    let same = |a: &[librate_core::attitude::PlanarEnd], b: &[librate_core::attitude::PlanarEnd]| {
        a.iter().zip(b).all(|(x, y)| x.phi_t.to_bits() == y.phi_t.to_bits() && x.wz_t.to_bits() == y.wz_t.to_bits() && x.stm.map(f64::to_bits) == y.stm.map(f64::to_bits))
    };
    let v1 = verify_planar_attitudes(MU, &s0, 2.0 * t, &items, [true, true], Some(1)).unwrap();
    let v2 = verify_planar_attitudes(MU, &s0, 2.0 * t, &items, [true, true], Some(2)).unwrap();
    assert!(same(&v, &v1) && same(&v, &v2));
    let first = verify_planar_attitudes(MU, &s0, 2.0 * t, &items[..8], [true, true], Some(1)).unwrap();
    assert!(same(&v[..8], &first));
}

/// A motion the lanes cannot integrate (here a rate so fast that the 1e-14 steps exceed the
/// lanes' step limit) fails its group of eight; the verifier runs that group again one motion
/// at a time, so its seven companions keep their values (equal to their values alone) and only
/// it carries an integration error (maximum steps, with the time reached), with NaN values.
#[test]
fn val_verifier_keeps_a_failing_motions_companions() {
    let (s0, t) = dro1266();
    let mut items: Vec<PlanarStart> = (0..8).map(|i| PlanarStart { kz: 0.8, phi0: 0.0, wz0: -1.5 + 0.1 * i as f64, plate: None }).collect();
    items[3].wz0 = 1e9;
    let v = verify_planar_attitudes(MU, &s0, t, &items, [true, true], Some(1)).unwrap();
    for (i, e) in v.iter().enumerate() {
        if i == 3 {
            assert!(e.phi_t.is_nan() && e.stm.iter().all(|x| x.is_nan()));
            let msg = e.error.as_ref().map(|e| e.to_string()).unwrap_or_default();
            assert!(msg.contains("maximum number of steps") && msg.contains("at t = "), "{msg}");
        } else {
            assert!(e.error.is_none(), "item {i}: {:?}", e.error);
            let alone = verify_planar_attitudes(MU, &s0, t, &items[i..=i], [true, true], Some(1)).unwrap();
            assert_eq!((e.phi_t.to_bits(), e.wz_t.to_bits()), (alone[0].phi_t.to_bits(), alone[0].wz_t.to_bits()), "item {i}");
        }
    }
}

/// Invalid arguments are errors naming the parameter (never panics).
#[test]
fn val_corrector_rejects_invalid_arguments() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let o = CorrectorOptions::default();
    let c = Candidate::new(0.0, -1.4, 0.8, -1.0);
    let plate = c.with_plate(0.1, 0.4, 0.1, 0.0);
    let name = |r: librate_core::Result<Vec<Correction>>| match r {
        Err(librate_core::Error::InvalidArgument { name, .. }) => name,
        other => panic!("expected an invalid argument, got {other:?}"),
    };
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Half, Free::SunPhase, &[c], &o)), "free");
    assert_eq!(name(correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, &[plate], &o)), "eps");
    assert_eq!(name(correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, &[Candidate::new(0.3, -1.4, 0.8, -1.0)], &o)), "phi0");
    assert_eq!(name(correct_planar_attitudes(&f, 0.3 * t, Closure::Half, Free::Phi0, &[c], &o)), "t_final");
    assert_eq!(name(correct_planar_attitudes(&f, 0.5 * t, Closure::Full, Free::Phi0, &[c], &o)), "t_final");
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::SunPhase, &[c], &o)), "free");
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[Candidate::new(0.0, -1.4, 1.5, -1.0)], &o)), "kz");
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[Candidate::new(0.0, f64::NAN, 0.8, -1.0)], &o)), "wz0");
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[c], &CorrectorOptions { threads: Some(0), ..o })), "threads");
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[c], &CorrectorOptions { tol: 0.0, ..o })), "tol");
    assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[c], &CorrectorOptions { max_iter: 0, ..o })), "max_iter");
    assert_eq!(name(correct_planar_attitudes(&f, f64::NAN, Closure::Full, Free::Phi0, &[c], &o)), "t_final");
    for (lo, hi) in [(-1.3, -1.2), (-1.5, -1.45), (f64::NAN, -1.0), (-1.5, f64::NAN), (f64::INFINITY, f64::INFINITY)] {
        assert_eq!(name(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[c.with_window(lo, hi)], &o)), "window", "({lo}, {hi})");
    }
    // an orbit that is not x-symmetric on its start: the half closure is refused
    let (s1, t1) = dro(0.8);
    let mut shifted = [0.0; 6];
    let tr = librate_core::propagation::propagate(MU, &s1, 0.0, 0.1 * t1, &Options::with_tolerances(1e-13, 1e-13), false, librate_core::integrate::Output::Final, &[]).unwrap();
    shifted.copy_from_slice(&tr.states[tr.states.len() - 6..]);
    let g = table(&shifted, t1);
    assert_eq!(name(correct_planar_attitudes(&g, 0.5 * t1, Closure::Half, Free::Phi0, &[c], &o)), "closure");
    assert!(correct_planar_attitudes(&g, t1, Closure::Full, Free::Phi0, &[c], &o).is_ok());
    assert!(correct_planar_attitudes(&f, t, Closure::Full, Free::Phi0, &[], &o).unwrap().is_empty());
    // the verifier
    let item = PlanarStart { kz: 0.8, phi0: 0.0, wz0: -1.4, plate: None };
    let vname = |r: librate_core::Result<Vec<librate_core::attitude::PlanarEnd>>| match r {
        Err(librate_core::Error::InvalidArgument { name, .. }) => name,
        other => panic!("expected an invalid argument, got {other:?}"),
    };
    assert_eq!(vname(verify_planar_attitudes(MU, &s0, t, &[PlanarStart { kz: 2.0, ..item }], [true, true], None)), "kz");
    assert_eq!(vname(verify_planar_attitudes(MU, &s0, -1.0, &[item], [true, true], None)), "t_final");
    assert_eq!(vname(verify_planar_attitudes(MU, &[0.8, 0.0, 0.1, 0.0, 0.5, 0.0], t, &[item], [true, true], None)), "orbit_state0");
    assert_eq!(vname(verify_planar_attitudes(MU, &s0, t, &[item], [true, true], Some(0))), "threads");
    let plate = |omega: f64| Some(FlatPlate::new(0.1, 0.4, 0.1, Sun { omega, ..Sun::default() }).unwrap());
    let two_suns = [PlanarStart { plate: plate(-0.9), ..item }, PlanarStart { plate: plate(-0.5), ..item }];
    assert_eq!(vname(verify_planar_attitudes(MU, &s0, t, &two_suns, [true, true], None)), "plate");
}

/// A candidate's search window (a map's crossing refined in place). On the 12.66-day DRO at
/// Kz = 0.8 (the N = -1 solution of Fig. 23, wz0 = -1.4545): (1) a start 1e-4 from the
/// solution, in a window of +-0.01, converges exactly as without the window (bit for bit: the
/// window never binds); (2) the torque-free start 0.3 away, which converges without a window
/// (val_thesis_fig23_solution), stops at its first Newton step in a window of +-0.01
/// (LeftWindow, no step accepted, the start's residual kept); (3) in a batch the stopped
/// candidate takes no further rounds and the near one still converges to 1e-12 of its
/// solution alone.
#[test]
fn val_search_window_stops_a_far_newton_step() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let o = CorrectorOptions::default();
    let solve = |cs: &[Candidate]| correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, cs, &o).unwrap();
    let exact = solve(&[Candidate::new(0.0, -1.4545, 0.8, -1.0)])[0];
    assert_eq!(exact.reason, StopReason::Converged);
    let near = Candidate::new(0.0, exact.wz0 + 1e-4, 0.8, -1.0);
    let w = |c: Candidate| c.with_window(c.case.wz0 - 0.01, c.case.wz0 + 0.01);
    let (plain, windowed) = (solve(&[near])[0], solve(&[w(near)])[0]);
    assert_eq!(windowed.reason, StopReason::Converged);
    assert_eq!(bits(&plain), bits(&windowed));
    let far = Candidate::new(0.0, 1.0 - 2.0 * PI / t, 0.8, -1.0);
    assert_eq!(solve(&[far])[0].reason, StopReason::Converged);
    let stopped = solve(&[w(far)])[0];
    assert_eq!(stopped.reason, StopReason::LeftWindow, "{stopped:?}");
    assert_eq!((stopped.iterations, stopped.wz0), (0, far.case.wz0));
    assert!(stopped.residual_norm.is_finite() && stopped.residual_norm > 1e-3, "{stopped:?}");
    let both = solve(&[w(far), w(near)]);
    assert_eq!(both[0].reason, StopReason::LeftWindow);
    assert_eq!(both[1].reason, StopReason::Converged);
    assert!((both[1].wz0 - plain.wz0).abs() < 1e-12, "{} vs {}", both[1].wz0, plain.wz0);
    // an unbounded window is no window
    let open = solve(&[far.with_window(f64::NEG_INFINITY, f64::INFINITY)])[0];
    assert_eq!(bits(&open), bits(&solve(&[far])[0]));
}

/// The bordered correction (continuation's corrector). References: (1) with the parameter fixed
/// (natural condition) it equals the plain correction at that Kz to 1e-11; (2) its parameter
/// column d g / d Kz matches the implicit-function derivative of the plain solutions,
/// d wz0 / d Kz = -g_Kz / g_wz0, against central differences of plain corrections at
/// Kz +- 1e-4 (to 1e-6 relative: second-order truncation); (3) a pseudo-arclength condition
/// a . x = b lands on the curve (residual <= 1e-12) and on the condition (to 1e-12); (4) eps as
/// the parameter with the full closure (SRP, phi0 free) equals the plain correction at that
/// eps (1e-10).
#[test]
fn val_bordered_correction_is_the_continuation_corrector() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let opts = CorrectorOptions::default();
    let plain = |kz: f64| correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, &[Candidate::new(0.0, -1.45, kz, -1.0)], &opts).unwrap()[0];
    let p = plain(0.8);
    assert!(p.converged());
    let fixed = Bordered::fixed(Parameter::Kz, 0.8);
    let b = correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &fixed, &[Candidate::new(0.0, -1.40, 0.75, -1.0)], &opts).unwrap()[0];
    assert!(b.converged(), "{:?}", b.reason);
    assert!((b.parameter - 0.8).abs() < 1e-14 && (b.wz0 - p.wz0).abs() < 1e-11, "{} vs {}", b.wz0, p.wz0);
    // (2) the tangent's slope
    let slope = -b.jacobian[0][2] / b.jacobian[0][1];
    let fd = (plain(0.8001).wz0 - plain(0.7999).wz0) / 2e-4;
    assert!((slope - fd).abs() <= 1e-6 * fd.abs().max(1.0), "{slope} vs {fd}");
    // (3) an arclength-type condition through the solution, tilted
    let (tw, tk) = (0.6, 0.8);
    let arc = Bordered { parameter: Parameter::Kz, a: [0.0, tw, tk], b: tw * p.wz0 + tk * 0.8 + 0.01, step: 1e-6, max_step: 0.5 };
    let r = correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &arc, &[Candidate::new(0.0, p.wz0, 0.8, -1.0)], &opts).unwrap()[0];
    assert!(r.converged() && r.residual_norm <= 1e-12);
    assert!((tw * r.wz0 + tk * r.parameter - arc.b).abs() <= 1e-12);
    let check = plain(r.parameter);
    assert!((check.wz0 - r.wz0).abs() < 1e-10);
    // (4) eps with SRP, full closure, phi0 free, on the 1:2 Sun-resonant DRO over K = 2
    let (s2, t2) = sun12();
    let f2 = table(&s2, t2);
    let start = Candidate::new(0.0, 0.934, 0.6, 0.0).with_plate(0.0, 0.4, 0.1, 0.0);
    let e = correct_bordered(&f2, 2.0 * t2, Closure::Full, Free::Phi0, &Bordered::fixed(Parameter::Eps, 0.02), &[start], &opts).unwrap()[0];
    assert!(e.converged(), "{:?}", e.reason);
    let pe = correct_planar_attitudes(&f2, 2.0 * t2, Closure::Full, Free::Phi0, &[Candidate::new(e.phi0, e.wz0, 0.6, 0.0).with_plate(0.02, 0.4, 0.1, 0.0)], &opts).unwrap()[0];
    assert!(pe.converged() && (pe.wz0 - e.wz0).abs() < 1e-10 && (pe.phi0 - e.phi0).abs() < 1e-10);
    // Kz's range: a condition that would need |Kz| > 1 fails cleanly, never panics
    let out = Bordered { parameter: Parameter::Kz, a: [0.0, 0.0, 1.0], b: 1.5, step: 1e-6, max_step: 0.5 };
    let r = correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &out, &[Candidate::new(0.0, p.wz0, 0.8, -1.0)], &opts).unwrap()[0];
    assert!(!r.converged());
}

/// Branches corrected in one batch (lock-step continuation): candidates with their own linear
/// conditions, in one `correct_bordered` call, land where each lands alone (1e-10: lock-step
/// lanes share their step size, so only the last bits may differ), each on its own condition
/// (1e-12); a non-finite or zero per-candidate condition is an argument error naming the
/// candidate.
#[test]
fn val_per_candidate_conditions_batch_branches() {
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let opts = CorrectorOptions::default();
    let base = Bordered::fixed(Parameter::Kz, 0.8);
    let cands = [
        Candidate::new(0.0, -1.40, 0.75, -1.0).with_condition([0.0, 0.0, 1.0], 0.8),
        Candidate::new(0.0, -1.45, 0.80, -1.0).with_condition([0.0, 0.6, 0.8], 0.6 * -1.45 + 0.8 * 0.8 + 0.01),
        Candidate::new(0.0, 1.0, 0.3, 0.0).with_condition([0.0, 0.0, 1.0], 0.3),
        Candidate::new(0.0, 1.0 + 2.0 * PI / t, 0.2, 1.0).with_condition([0.0, 0.0, 1.0], 0.25),
    ];
    let all = correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &base, &cands, &opts).unwrap();
    for (c, r) in cands.iter().zip(&all) {
        assert!(r.converged(), "{:?}", r.reason);
        let (a, b) = c.condition.unwrap();
        assert!((a[1] * r.wz0 + a[2] * r.parameter - b).abs() <= 1e-12);
        let alone = Bordered { a, b, ..base };
        let one = correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &alone, &[Candidate { condition: None, ..*c }], &opts).unwrap()[0];
        assert!(one.converged() && (one.wz0 - r.wz0).abs() < 1e-10 && (one.parameter - r.parameter).abs() < 1e-10, "{} vs {}", one.wz0, r.wz0);
    }
    let bad = [Candidate::new(0.0, 1.0, 0.3, 0.0).with_condition([0.0, f64::NAN, 1.0], 0.3)];
    let e = correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &base, &bad, &opts).unwrap_err().to_string();
    assert!(e.contains("candidate 0") && e.contains('a'), "{e}");
    let zero = [Candidate::new(0.0, 1.0, 0.3, 0.0).with_condition([0.0, 0.0, 0.0], 0.3)];
    assert!(correct_bordered(&f, 0.5 * t, Closure::Half, Free::Phi0, &base, &zero, &opts).is_err());
}

/// The correction across a planar orbit family (the orbit's x0 freed). References: (1) with x0
/// fixed at a value between members it equals the plain half-period correction on the DRO
/// corrected directly at that x0 (1e-10: both orbits corrected to 1e-12); (2) its x0 column
/// d g / d x0 gives the family's slope d wz0 / d x0 = -g_x0 / g_wz, against central differences
/// of plain corrections at x0 +- 1e-4 (1e-5 relative: truncation and the orbits' correction
/// noise); (3) x0 outside the members' range fails cleanly.
#[test]
fn val_correction_across_the_orbit_family() {
    use librate_core::attitude::{correct_across_family, PlanarFamily};
    let members: Vec<([f64; 6], f64)> = [0.80, 0.83, 0.86, 0.89].iter().map(|&x| dro(x)).collect();
    let x0s: Vec<f64> = members.iter().map(|m| m.0[0]).collect();
    let vy0s: Vec<f64> = members.iter().map(|m| m.0[4]).collect();
    let fam = PlanarFamily::new(MU, &x0s, &vy0s).unwrap();
    let opts = CorrectorOptions::default();
    let plain = |x0: f64| {
        let (s0, t) = dro(x0);
        correct_planar_attitudes(&table(&s0, t), 0.5 * t, Closure::Half, Free::Phi0, &[Candidate::new(0.0, 1.8, 0.8, 0.0)], &opts).unwrap()[0]
    };
    let p = plain(0.85);
    assert!(p.converged());
    let fixed = Bordered { parameter: Parameter::OrbitX0, ..Bordered::fixed(Parameter::Kz, 0.85) };
    let c = correct_across_family(&fam, &fixed, &[Candidate::new(0.0, p.wz0 + 0.01, 0.8, 0.0).with_x0(0.84)], &opts);
    let c = c.unwrap()[0];
    assert!(c.converged(), "{:?}", c.reason);
    assert!((c.parameter - 0.85).abs() < 1e-14 && (c.wz0 - p.wz0).abs() < 1e-10, "{} vs {}", c.wz0, p.wz0);
    let slope = -c.jacobian[0][2] / c.jacobian[0][1];
    let fd = (plain(0.8501).wz0 - plain(0.8499).wz0) / 2e-4;
    assert!((slope - fd).abs() <= 1e-5 * fd.abs().max(1.0), "{slope} vs {fd}");
    // at the end of the family's range the x0 derivative is one-sided (issue 11: a probe past the
    // family's end made the first member unusable)
    let end = Bordered { b: 0.89, ..fixed };
    let e = correct_across_family(&fam, &end, &[Candidate::new(0.0, p.wz0, 0.8, 0.0).with_x0(0.88)], &opts).unwrap()[0];
    let pe = plain(0.89);
    assert!(e.converged() && (e.wz0 - pe.wz0).abs() < 1e-10, "{:?} {} {}", e.reason, e.wz0, pe.wz0);
    let out = Bordered { b: 0.95, ..fixed };
    let r = correct_across_family(&fam, &out, &[Candidate::new(0.0, p.wz0, 0.8, 0.0).with_x0(0.85)], &opts).unwrap()[0];
    assert!(!r.converged());
}

/// The family's orbit linearised from a member (`PlanarFamily::linearised`, the neighbours of
/// the central differences in x0): against the orbit corrected at that x0 (reference: Newton's
/// half-period shooting to 1e-12), its vy0 and period differ by O(dx^2) (Taylor): < 1e-5 at
/// dx = 1e-3, and the error falls about 4-fold when dx halves (ratio in [3, 5]); at dx = 1e-6
/// (the differences' step) vy0 and T agree to 1e-10 and the forcing tables to 1e-8 of their
/// scale: there the difference is the corrected orbit's own noise (vy0 to ~1e-11, residual
/// 1e-12, grown along the orbit), not the linearisation's O(dx^2) ~ 1e-12.
#[test]
fn val_linearised_family_orbit_is_second_order() {
    use librate_core::attitude::PlanarFamily;
    let members: Vec<([f64; 6], f64)> = [0.80, 0.83, 0.86, 0.89].iter().map(|&x| dro(x)).collect();
    let x0s: Vec<f64> = members.iter().map(|m| m.0[0]).collect();
    let vy0s: Vec<f64> = members.iter().map(|m| m.0[4]).collect();
    let fam = PlanarFamily::new(MU, &x0s, &vy0s).unwrap();
    let centre = fam.orbit_at(0.845).unwrap();
    let err = |dx: f64| {
        let (period, _) = fam.linearised(&centre.0, 0.845 + dx).unwrap();
        let exact = fam.orbit_at(0.845 + dx).unwrap();
        // the linearised vy0: the table is built from it; recover it from the slope
        let dvy = centre.0.evaluation.tangent(false, [1.0, 0.0, 0.0]).unwrap()[2];
        let vy_lin = centre.0.state0[4] + dvy * dx;
        ((vy_lin - exact.0.state0[4]).abs(), (period - exact.0.period).abs())
    };
    let (ev1, et1) = err(1e-3);
    let (ev2, et2) = err(5e-4);
    assert!(ev1 < 1e-5 && et1 < 1e-5, "{ev1} {et1}");
    assert!((3.0..5.0).contains(&(ev1 / ev2)) && (3.0..5.0).contains(&(et1 / et2)), "{} {}", ev1 / ev2, et1 / et2);
    let (_, near) = fam.linearised(&centre.0, 0.845 + 1e-6).unwrap();
    let exact = fam.orbit_at(0.845 + 1e-6).unwrap();
    let worst = (0..200).map(|i| {
        let t = i as f64 * 0.005 * exact.0.period;
        let (a, b) = (near.sc(t), exact.1.sc(t));
        (a.0 - b.0).abs().max((a.1 - b.1).abs())
    });
    let worst = worst.fold(0.0f64, f64::max);
    let scale = (0..200).map(|i| { let (a, b) = exact.1.sc(i as f64 * 0.005 * exact.0.period); a.abs().max(b.abs()) }).fold(0.0f64, f64::max);
    let (ev, et) = err(1e-6);
    assert!(worst < 1e-8 * scale && ev < 1e-10 && et < 1e-10, "{worst} {scale} {ev} {et}");
    assert!(fam.linearised(&centre.0, f64::NAN).is_err());
}

/// The refinement of candidates into verified solutions (attitude::refine_planar_attitudes) is
/// the corrector, the selection and the verifier in one call: on the 12.66-day DRO, the 40
/// candidates of `batch_candidates` in two groups (alternating labels), half closure, rates kept
/// in [-2.5, 1.5]:
/// - each kept solution's correction is, bit for bit, the batch correction of its candidate, and
///   its re-propagation, bit for bit, the verifier's run of the kept starts in the returned order;
/// - the order is group (first appearance), Kz, wz0; no two kept solutions of a group share Kz
///   and turns within SAME_SOLUTION (1e-8) in wz0; every converged candidate inside the window
///   has a kept solution of its group, Kz and turns within 1e-8 (its residual passed the check:
///   the verifier closes these to < 1e-11, test val_thesis_fig23_solution);
/// - the kept residuals are the full closure's of the re-propagation and at most 1e-8;
/// - the outcome is bit-identical on 1 and 2 threads.
#[test]
fn val_refine_is_correct_select_verify() {
    use librate_core::attitude::{full_closure_residual, refine_planar_attitudes, PlanarOrbit, MAX_VERIFIED_RESIDUAL, SAME_SOLUTION};
    let (s0, t) = dro1266();
    let f = table(&s0, t);
    let orbit = PlanarOrbit { mu: MU, state0: s0, primaries: [true, true], forcing: &f };
    let cands = batch_candidates(t);
    let groups: Vec<i64> = (0..cands.len()).map(|i| [7, 3][i % 2]).collect();
    let keep = (-2.5, 1.5);
    let opts = CorrectorOptions { monodromy: false, threads: Some(2), ..CorrectorOptions::default() };
    let out = refine_planar_attitudes(&orbit, 0.5 * t, Closure::Half, &cands, &groups, &opts, keep).unwrap();
    let one = refine_planar_attitudes(&orbit, 0.5 * t, Closure::Half, &cands, &groups, &CorrectorOptions { threads: Some(1), ..opts }, keep).unwrap();
    // (Debug prints each value's shortest round-trip form: equal strings are equal bits; NaN == NaN)
    assert!(format!("{out:?}") == format!("{one:?}"), "threads changed the refinement");
    let batch = correct_planar_attitudes(&f, 0.5 * t, Closure::Half, Free::Phi0, &cands, &opts).unwrap();
    let starts: Vec<PlanarStart> = out.iter().map(|r| PlanarStart { kz: cands[r.index].case.kz, phi0: r.correction.phi0, wz0: r.correction.wz0, plate: None }).collect();
    let ends = verify_planar_attitudes(MU, &s0, t, &starts, [true, true], Some(2)).unwrap();
    assert!(out.len() >= 8, "only {} solutions", out.len());
    let rank = |g: i64| if g == 7 { 0 } else { 1 };
    for (j, r) in out.iter().enumerate() {
        assert_eq!(bits(&r.correction), bits(&batch[r.index]));
        assert_eq!(r.end, ends[j]);
        let (c, x) = (&cands[r.index], &r.correction);
        assert_eq!(r.residual, full_closure_residual(x.phi0, x.wz0, c.turns, r.end.phi_t, r.end.wz_t));
        assert!(r.residual.iter().all(|v| v.abs() <= MAX_VERIFIED_RESIDUAL), "{r:?}");
        assert!(x.converged() && x.wz0 >= keep.0 && x.wz0 <= keep.1);
        if j > 0 {
            let p = &out[j - 1];
            let (kp, kr) = ((rank(groups[p.index]), cands[p.index].case.kz, p.correction.wz0), (rank(groups[r.index]), c.case.kz, x.wz0));
            assert!(kp <= kr, "order: {kp:?} then {kr:?}");
        }
        for q in &out[..j] {
            let same = groups[q.index] == groups[r.index] && cands[q.index].case.kz == c.case.kz && cands[q.index].turns == c.turns;
            assert!(!same || (q.correction.wz0 - x.wz0).abs() >= SAME_SOLUTION, "kept twice: {q:?} and {r:?}");
        }
    }
    for (i, b) in batch.iter().enumerate() {
        if b.converged() && b.wz0 >= keep.0 && b.wz0 <= keep.1 {
            let found = out.iter().any(|r| groups[r.index] == groups[i] && cands[r.index].case.kz == cands[i].case.kz && cands[r.index].turns == cands[i].turns && (r.correction.wz0 - b.wz0).abs() < 1e-8);
            assert!(found, "converged candidate {i} ({b:?}) has no kept solution");
        } else {
            assert!(out.iter().all(|r| r.index != i), "candidate {i} kept: {b:?}");
        }
    }
    // bad arguments name the parameter
    let name = |r: librate_core::Result<Vec<librate_core::attitude::Refined>>| match r {
        Err(librate_core::Error::InvalidArgument { name, .. }) => name,
        other => panic!("expected an invalid argument, got {other:?}"),
    };
    assert_eq!(name(refine_planar_attitudes(&orbit, 0.5 * t, Closure::Half, &cands, &groups[1..], &opts, keep)), "groups");
    assert_eq!(name(refine_planar_attitudes(&orbit, 0.5 * t, Closure::Half, &cands, &groups, &opts, (1.0, -1.0))), "keep");
    assert_eq!(name(refine_planar_attitudes(&orbit, 0.5 * t, Closure::Half, &cands, &groups, &opts, (f64::NAN, 1.0))), "keep");
    assert!(refine_planar_attitudes(&orbit, 0.5 * t, Closure::Half, &[], &[], &opts, keep).unwrap().is_empty());
}

/// Kz = 0 (no torque): the refinement keeps exactly the analytic motions wz0 = 1 + 2 pi N / T
/// (to 1e-12, as val_torque_free_solutions_are_analytic), once each although every one is found
/// from two starts (0.2 below and 0.3 above), with the monodromy [[1, T], [0, 1]] of the
/// re-propagation to 1e-11; full closure with phi0 free.
#[test]
fn val_refine_torque_free_keeps_each_analytic_motion_once() {
    use librate_core::attitude::{refine_planar_attitudes, PlanarOrbit};
    let (s0, t) = dro(0.8);
    let f = table(&s0, t);
    let orbit = PlanarOrbit { mu: MU, state0: s0, primaries: [true, true], forcing: &f };
    let exact = |n: f64| 1.0 + 2.0 * PI * n / t;
    let turns = [-1.0, -0.5, 0.0, 0.5, 1.0];
    let cands: Vec<Candidate> = turns.iter().flat_map(|&n| [Candidate::new(0.4, exact(n) - 0.2, 0.0, n), Candidate::new(0.4, exact(n) + 0.3, 0.0, n)]).collect();
    let out = refine_planar_attitudes(&orbit, t, Closure::Full, &cands, &vec![0; cands.len()], &CorrectorOptions::default(), (f64::NEG_INFINITY, f64::INFINITY)).unwrap();
    assert_eq!(out.len(), turns.len());
    for (r, n) in out.iter().zip(turns) {
        assert!((r.correction.wz0 - exact(n)).abs() < 1e-12, "N = {n}: {r:?}");
        let m = r.end.stm;
        assert!((m[0] - 1.0).abs() < 1e-11 && (m[1] - t).abs() < 1e-10 && m[2].abs() < 1e-11 && (m[3] - 1.0).abs() < 1e-11, "{m:?}");
    }
}
