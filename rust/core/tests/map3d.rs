//! The 3-D periodicity-map engine (issue 15, item 5): its tidal-tensor table against the tensor
//! of the integrated orbit, its lanes against the scalar coupled 3-D model integrating the orbit
//! alongside, the planar embedding against the planar map, determinism and argument checks.
//! Each test names its reference and tolerance.

use librate_core::attitude::{propagate_attitude, tidal_tensor, GravityGradient, OrbitMode, RigidBody, Torque};
use librate_core::integrate::{Options, Output};
use librate_core::integrate::forcing::{OrbitForcing, TidalTable};
use librate_core::integrate::lanes::{Case, LaneOptions, LaneStatus};
use librate_core::integrate::lanes3d::Case3d;
use librate_core::map::{residuals, sweep, sweep_3d};
use librate_core::attitude::attitude_residual;
use librate_core::orbit::{Constraint, SymmetricShooting, Var};
use librate_core::propagation::propagate;

mod common;
use common::{dro, MU};

fn tight() -> Options {
    Options::with_tolerances(1e-13, 1e-13)
}


/// An Earth-Moon L2 southern halo (z0 = -0.1227 LU, period 3.27 TU, 14.2 days), corrected
/// by the spatial symmetric shooting.
fn halo() -> ([f64; 6], f64) {
    let mut sh = SymmetricShooting::new(MU, true, tight());
    sh.tol = 1e-12;
    let o = sh.correct([1.1608, -0.1227, -0.2077], Constraint::Fix(Var::Z0, -0.1227)).unwrap();
    assert!(o.state0[2] < 0.0 && o.state0[0] > 1.1 && o.period > 3.0 && o.period < 3.6, "{:?} {}", o.state0, o.period);
    (o.state0, o.period)
}

/// A unit quaternion from a rotation vector.
fn quat(r: [f64; 3]) -> [f64; 4] {
    let a = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let (s, c) = (0.5 * a).sin_cos();
    [s * r[0] / a, s * r[1] / a, s * r[2] / a, c]
}

/// A spread of 3-D cases: attitudes away from the axes, rates of either sign, three bodies.
fn cases3d() -> Vec<Case3d> {
    let bodies = [RigidBody::new(0.8, 0.9, 1.0).unwrap(), RigidBody::new(12.12e6, 89.68e6, 96.95e6).unwrap(), RigidBody::new(1.0, 0.6, 0.7).unwrap()];
    (0..19)
        .map(|i| {
            let x = i as f64;
            Case3d { q0: quat([0.3 + 0.1 * x, -0.7 + 0.05 * x, 0.2 * x - 1.0]), w0: [0.3 * (x * 0.7).sin(), -0.2 + 0.03 * x, 1.5 - 0.2 * x], body: bodies[i % 3] }
        })
        .collect()
}

/// The tidal-tensor table reproduces the tensor of the integrated orbit (rtol = atol = 1e-14)
/// at times that are neither its fit nor its check points, on a halo and a DRO, to 1e-12
/// relative to its largest component, and is periodic.
#[test]
fn val_tidal_table_accuracy() {
    for (s0, period) in [halo(), dro(0.7)] {
        let f = TidalTable::tidal(MU, &s0, period, [true, true], 1e-13).unwrap();
        assert!(f.max_error <= 1e-12, "{}", f.max_error);
        let mut times: Vec<f64> = (1..150).map(|k| period * (k as f64 * 0.618034 % 1.0)).collect();
        times.sort_by(f64::total_cmp);
        let tr = propagate(MU, &s0, 0.0, period, &Options::with_tolerances(1e-14, 1e-14), false, Output::At(&times), &[]).unwrap();
        for (k, st) in tr.states.chunks_exact(6).enumerate() {
            let m: [f64; 6] = tidal_tensor(MU, &[st[0], st[1], st[2]], [true, true]);
            let (a, b) = (f.eval(times[k]), f.eval(times[k] + period));
            for i in 0..6 {
                assert!((a[i] - m[i]).abs() < 1e-12 * f.scale, "t = {}, component {i}: {} vs {}", times[k], a[i], m[i]);
                assert!((b[i] - a[i]).abs() < 1e-12 * f.scale);
            }
        }
    }
}

/// The lanes (rtol = atol = 1e-13) against the scalar coupled 3-D model `propagate_attitude`
/// integrating the orbit alongside (rtol = atol = 1e-13), on the x0 = 0.7 DRO and an L2 southern
/// halo: the six residuals (Log(q0* (x) q(T)), w(T) - w0) agree to 1e-9 over one period of
/// either and two of the halo (6.8 TU; over two DRO periods, 21.6 TU, the tumbling motions
/// amplify the integration errors of both to 1e-8).
#[test]
fn val_lanes_match_scalar_model() {
    let gg = GravityGradient::BOTH;
    let cases = cases3d();
    let opts = LaneOptions { rtol: 1e-13, atol: 1e-13, ..LaneOptions::default() };
    for ((s0, period), ks) in [(dro(0.7), &[1.0][..]), (halo(), &[1.0, 2.0][..])] {
        let f = TidalTable::tidal(MU, &s0, period, [true, true], 1e-13).unwrap();
        for &k in ks {
            let out = sweep_3d(&f, k * period, &cases, &opts, 8, None).unwrap();
            let mut worst = 0.0f64;
            for (c, o) in cases.iter().zip(&out) {
                assert_eq!(o.status, LaneStatus::Ok);
                let mut y0 = [0.0; 13];
                y0[..6].copy_from_slice(&s0);
                y0[6..10].copy_from_slice(&c.q0);
                y0[10..].copy_from_slice(&c.w0);
                let tr = propagate_attitude(MU, c.body, &[&gg as &dyn Torque], OrbitMode::Integrate, &y0, 0.0, k * period, &tight(), false, Output::Final, None, None).unwrap();
                let y = &tr.states[..13];
                let r = attitude_residual(&c.q0, &c.w0, &[y[6], y[7], y[8], y[9]], &[y[10], y[11], y[12]]);
                for (i, (a, b)) in o.residual.iter().zip(&r).enumerate() {
                    let d = (a - b).abs();
                    worst = worst.max(d);
                    assert!(d < 1e-9, "period {period}, K = {k}, case {c:?}, component {i}: {a} vs {b}");
                }
            }
            eprintln!("orbit period {period:.6}, K = {k}: largest residual difference lanes vs scalar {worst:.2e}");
        }
    }
}

/// The planar embedding: with q0 = identity and w0 = (0, 0, wz0), a body with Kz = (Iy - Ix)/Iz
/// on the x0 = 0.7 DRO stays in the plane, and the 3-D map's rz and dwz equal the planar map's
/// dphi (phi(T) - phi0 wrapped to (-pi, pi]) and dwz to 1e-9 (both at rtol = atol = 1e-13);
/// rx, ry, dwx, dwy are exactly zero.
#[test]
fn val_planar_embedding_equals_planar_map() {
    let (s0, period) = dro(0.7);
    let opts = LaneOptions { rtol: 1e-13, atol: 1e-13, ..LaneOptions::default() };
    let tidal = TidalTable::tidal(MU, &s0, period, [true, true], 1e-13).unwrap();
    let forcing = OrbitForcing::new(MU, &s0, period, [true, true], 1e-13).unwrap();
    for kz in [0.8, -0.5] {
        let body = RigidBody::from_kz(kz).unwrap();
        let wz: Vec<f64> = (0..41).map(|i| -3.0 + 5.0 * i as f64 / 40.0).collect();
        let c3: Vec<Case3d> = wz.iter().map(|&w| Case3d { q0: [0.0, 0.0, 0.0, 1.0], w0: [0.0, 0.0, w], body }).collect();
        let c2: Vec<Case> = wz.iter().map(|&w| Case::new(0.0, w, kz)).collect();
        let o3 = sweep_3d(&tidal, period, &c3, &opts, 16, None).unwrap();
        let o2 = sweep(&forcing, period, &c2, &opts, false, 16, None).unwrap();
        let mut compared = 0;
        for ((c, a), b) in c2.iter().zip(&o3).zip(&o2) {
            let (dwz, dphi) = residuals(c, b);
            assert_eq!([a.residual[0], a.residual[1], a.residual[3], a.residual[4]], [0.0; 4], "wz0 = {}", c.wz0);
            assert!((a.residual[5] - dwz).abs() < 1e-9, "wz0 = {}: dwz {} vs {}", c.wz0, a.residual[5], dwz);
            if dphi.abs() < std::f64::consts::PI - 1e-6 {
                assert!((a.residual[2] - dphi).abs() < 1e-9, "wz0 = {}: rz {} vs dphi {}", c.wz0, a.residual[2], dphi);
                compared += 1;
            }
        }
        assert!(compared > 30);
    }
}

/// Bit-identical results for any thread count and chunk size (the groups of eight are fixed
/// from the start of the slice).
#[test]
fn val_determinism_across_threads_and_chunks() {
    let (s0, period) = halo();
    let f = TidalTable::tidal(MU, &s0, period, [true, true], 1e-12).unwrap();
    let cases = cases3d();
    let bits = |o: &[librate_core::integrate::lanes3d::Outcome3d]| o.iter().flat_map(|x| x.q_t.iter().chain(&x.w_t).chain(&x.residual).map(|v| v.to_bits()).collect::<Vec<_>>()).collect::<Vec<_>>();
    let base = bits(&sweep_3d(&f, period, &cases, &LaneOptions::default(), 8, Some(1)).unwrap());
    for (chunk, threads) in [(1, Some(2)), (24, Some(2)), (1000, None), (9, Some(3))] {
        assert_eq!(bits(&sweep_3d(&f, period, &cases, &LaneOptions::default(), chunk, threads).unwrap()), base, "chunk {chunk}, threads {threads:?}");
    }
}

/// Every SIMD level this CPU has: the groups are sixteen trajectories on two lane vectors at
/// AVX-512 and eight elsewhere (lanes3d::group_size), so the levels differ by the shared steps
/// of their groups and by fused against unfused multiply-adds. Reference: the FMA level of eight
/// (AVX2) where present; tolerance: the six residuals agree to 1e-10 at rtol = atol = 1e-13 over
/// one halo period (measured on an AVX-512 CPU: 1.2e-12, baseline 1.7e-13 against AVX2),
/// and each level is bit-identical for any chunking and thread count (the wide groups too: 40
/// cases, two groups of sixteen and one of eight).
#[test]
fn val_levels_agree() {
    use librate_core::map::sweep_3d_at;
    use librate_core::simd::Level;
    let (s0, period) = halo();
    let f = TidalTable::tidal(MU, &s0, period, [true, true], 1e-13).unwrap();
    let mut cases = cases3d();
    cases.extend(cases3d());
    cases.extend_from_slice(&cases3d()[..2]);
    let opts = LaneOptions { rtol: 1e-13, atol: 1e-13, ..LaneOptions::default() };
    let bits = |o: &[librate_core::integrate::lanes3d::Outcome3d]| o.iter().flat_map(|x| x.q_t.iter().chain(&x.w_t).map(|v| v.to_bits()).collect::<Vec<_>>()).collect::<Vec<_>>();
    let levels = librate_core::simd::available();
    let runs: Vec<(Level, Vec<_>)> = levels
        .iter()
        .map(|&level| {
            let base = sweep_3d_at(level, &f, period, &cases, &opts, 1000, Some(1)).unwrap();
            for (chunk, threads) in [(1, Some(2)), (9, None)] {
                assert_eq!(bits(&sweep_3d_at(level, &f, period, &cases, &opts, chunk, threads).unwrap()), bits(&base), "{level}: chunk {chunk}");
            }
            (level, base)
        })
        .collect();
    let (l0, r0) = runs.iter().find(|(l, _)| *l == Level::Avx2).unwrap_or(&runs[0]);
    for (level, r) in &runs {
        let mut worst = 0.0f64;
        for (a, b) in r0.iter().zip(r) {
            assert_eq!(b.status, LaneStatus::Ok);
            for (x, y) in a.residual.iter().zip(&b.residual) {
                worst = worst.max((x - y).abs());
            }
        }
        eprintln!("{level} against {l0}: largest residual difference {worst:.1e}");
        assert!(worst < 1e-10, "{level} against {l0}: {worst:e}");
    }
}

/// Invalid arguments are errors naming the argument, never panics or NaN results.
#[test]
fn val_bad_input_is_an_error() {
    let (s0, period) = dro(0.7);
    let f = TidalTable::tidal(MU, &s0, period, [true, true], 1e-12).unwrap();
    let good = cases3d()[0];
    let opts = LaneOptions::default();
    let err = |cases: &[Case3d], t: f64, o: &LaneOptions, chunk: usize, threads: Option<usize>| sweep_3d(&f, t, cases, o, chunk, threads).unwrap_err().to_string();
    assert!(err(&[Case3d { q0: [0.0, 0.0, 0.0, 2.0], ..good }], period, &opts, 8, None).contains("q0"));
    assert!(err(&[Case3d { w0: [f64::NAN, 0.0, 0.0], ..good }], period, &opts, 8, None).contains("w0"));
    assert!(err(&[Case3d { body: RigidBody { ix: -1.0, iy: 1.0, iz: 1.0 }, ..good }], period, &opts, 8, None).contains("ix"));
    assert!(err(&[Case3d { body: RigidBody { ix: 1.0, iy: 1.0, iz: 3.0 }, ..good }], period, &opts, 8, None).contains("iz"));
    assert!(err(&[good], -1.0, &opts, 8, None).contains("t_final"));
    assert!(err(&[good], period, &LaneOptions { rtol: -1.0, ..opts }, 8, None).contains("rtol"));
    assert!(err(&[good], period, &opts, 0, None).contains("chunk"));
    assert!(err(&[good], period, &opts, 8, Some(0)).contains("threads"));
    assert!(TidalTable::tidal(MU, &[f64::NAN; 6], period, [true, true], 1e-12).is_err());
    assert!(TidalTable::tidal(MU, &s0, -1.0, [true, true], 1e-12).is_err());
    // an empty sweep is an empty result; a step budget too small is a status, not an error
    assert!(sweep_3d(&f, period, &[], &opts, 8, None).unwrap().is_empty());
    let o = sweep_3d(&f, period, &[good], &LaneOptions { max_steps: 3, ..opts }, 8, None).unwrap();
    assert_eq!(o[0].status, LaneStatus::MaxSteps);
    assert!(o[0].residual.iter().all(|v| v.is_nan()));
}
