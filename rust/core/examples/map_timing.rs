//! Times the periodicity-map engine on the standard map and optionally saves or compares its
//! results bit for bit.
//!
//! Standard map: Earth-Moon (mu = 0.01215), the DRO through x0 = 0.70 (symmetric corrector, as
//! in tests/map.rs), Kz = 0.8, phi0 = 0, 2000 wz0 evenly spaced in [-3, 2], one period,
//! rtol = atol = 1e-12; without and with the 2x2 STM; and an SRP case (flat plate eps = 0.05,
//! Cs = 0.4, Cd = 0.1, Sun phase 0.7, STM on). One thread, best of `--reps` runs (default 15),
//! cases alternating round-robin so that a load change on the shared machine hits all alike.
//!
//!   cargo run --release -p librate-core --example map_timing -- [--reps N] [--method M] [--rtol R] [--only K] [--accuracy [--solo]] [--table] [--save FILE] [--compare FILE]
//!   cargo run --release -p librate-core --example map_timing -- --3d [--12d] [--reps N] [--method M] [--rtol R] [--save FILE] [--compare FILE]
//!
//! `--save` writes every outcome (phi_t, wz_t, stm) as raw f64 bits; `--compare` reads such a
//! file and prints the largest absolute and relative differences per case.

use std::time::Instant;

use librate_core::attitude::RigidBody;
use librate_core::integrate::Options;
use librate_core::integrate::forcing::{OrbitForcing, TidalTable};
use librate_core::integrate::lanes3d::{sweep_3d, Case3d};
use librate_core::integrate::lanes::{Case, LaneOptions, Method, Outcome};
use librate_core::map::sweep;
use librate_core::orbit::{correct_planar_symmetric, Constraint, SymmetricShooting, Var};

const MU: f64 = 0.01215;

fn values(out: &[Outcome]) -> Vec<f64> {
    out.iter().flat_map(|o| [o.phi_t, o.wz_t, o.stm[0], o.stm[1], o.stm[2], o.stm[3]]).collect()
}

/// Write values as raw f64 bits (little-endian).
fn save_bits(path: &str, values: &[f64]) {
    std::fs::write(path, values.iter().flat_map(|v| v.to_bits().to_le_bytes()).collect::<Vec<u8>>()).unwrap();
    println!("saved {} values to {path}", values.len());
}

/// Values written by [`save_bits`].
fn read_bits(path: &str) -> Vec<f64> {
    std::fs::read(path).unwrap().chunks_exact(8).map(|b| f64::from_bits(u64::from_le_bytes(b.try_into().unwrap()))).collect()
}

/// `--3d`: the 3-D lanes on an L2 southern halo (z0 = -0.1227, period 3.3 TU, or with `--12d`
/// the 12-day one, z0 = -0.1946) with its tidal
/// table: 40 wx0 in [-0.2, 0.2] x 50 wz0 in [w - 0.5, w + 0.5] (w = 1 - 2 pi / T), wy0 = 0, q0 the
/// identity, body 0.8 : 0.9 : 1, one period (bench/bench_map3d.py's grid), one thread.
fn timing_3d(reps: usize, tol: f64, method: Method, twelve_days: bool, save: Option<String>, compare: Option<String>) {
    let mut sh = SymmetricShooting::new(MU, true, Options::with_tolerances(1e-13, 1e-13));
    sh.tol = 1e-12;
    let o = if twelve_days {
        // the 12-day halo of bench/bench_map3d.py (z0 = -0.19462, period 2.7634 TU)
        sh.correct([1.10933, -0.19462, -0.22112], Constraint::Fix(Var::Z0, -0.1946204962529079)).unwrap()
    } else {
        sh.correct([1.1608, -0.1227, -0.2077], Constraint::Fix(Var::Z0, -0.1227)).unwrap()
    };
    let table = TidalTable::tidal(MU, &o.state0, o.period, [true, true], 1e-13).unwrap();
    println!("halo: x0 = {:.6}, z0 = {:.6}, period = {:.6}; tidal table: {} segments", o.state0[0], o.state0[2], o.period, table.segments());
    let w = 1.0 - 2.0 * std::f64::consts::PI / o.period;
    let body = RigidBody::new(0.8, 0.9, 1.0).unwrap();
    let cases: Vec<Case3d> = (0..40)
        .flat_map(|i| (0..50).map(move |j| (i, j)))
        .map(|(i, j)| Case3d { q0: [0.0, 0.0, 0.0, 1.0], w0: [-0.2 + 0.4 * i as f64 / 39.0, 0.0, w - 0.5 + j as f64 / 49.0], body })
        .collect();
    let opts = LaneOptions { rtol: tol, atol: tol, method, ..LaneOptions::default() };
    let mut best = f64::INFINITY;
    let mut out = Vec::new();
    for _ in 0..reps {
        let t0 = Instant::now();
        out = sweep_3d(&table, o.period, &cases, &opts, 64, Some(1)).unwrap();
        best = best.min(t0.elapsed().as_secs_f64());
    }
    let steps = out.iter().map(|o| (o.accepted + o.rejected) as f64).sum::<f64>() / cases.len() as f64;
    println!("3-D, {} trajectories, rtol = atol = {tol:.0e}: best of {reps}: {:8.2} ms ({steps:.1} steps per trajectory)", cases.len(), 1e3 * best);
    let all: Vec<f64> = out.iter().flat_map(|o| o.q_t.into_iter().chain(o.w_t)).collect();
    if let Some(path) = save {
        save_bits(&path, &all);
    }
    if let Some(path) = compare {
        let old = read_bits(&path);
        let differ = all.iter().zip(&old).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        let max = all.iter().zip(&old).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("3-D: {differ} of {} values differ from {path}; max |diff| {max:.3e}", all.len());
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| args.iter().position(|a| a == name).map(|i| args[i + 1].clone());
    let reps: usize = arg("--reps").map(|s| s.parse().unwrap()).unwrap_or(15);
    if args.iter().any(|a| a == "--3d") {
        let tol: f64 = arg("--rtol").map(|s| s.parse().unwrap()).unwrap_or(5e-11);
        let method = arg("--method").map(|s| Method::parse(&s).expect("--method: rkf78 or dp87")).unwrap_or_default();
        return timing_3d(reps, tol, method, args.iter().any(|a| a == "--12d"), arg("--save"), arg("--compare"));
    }

    let x0 = 0.70;
    // ydot0 guess 0.69 (the DRO's is 0.69350, period 4.8588 TU; the guess sqrt(mu/d) + d = 0.49
    // converges to another symmetric orbit, of period 10.79)
    let o = correct_planar_symmetric(MU, x0, 0.69, 1e-12, 30, &Options::with_tolerances(1e-13, 1e-13)).unwrap();
    assert!((o.period - 4.858760).abs() < 1e-5, "not the DRO through x0 = 0.70: period {}", o.period);
    let f = OrbitForcing::new(MU, &o.state0, o.period, [true, true], 1e-13).unwrap();
    println!("orbit: x0 = {:.17e}, ydot0 = {:.17e}, period = {:.17e}; forcing table error {:.3e}", o.state0[0], o.state0[4], o.period, f.max_error);
    if args.iter().any(|a| a == "--table") {
        // the forcing table's fit (the scalar RKF7(8) along the orbit), best of `reps`
        let mut best = f64::INFINITY;
        for _ in 0..reps {
            let t0 = Instant::now();
            let g = OrbitForcing::new(MU, &o.state0, o.period, [true, true], 1e-13).unwrap();
            best = best.min(t0.elapsed().as_secs_f64());
            assert_eq!(g, f);
        }
        println!("forcing table ({} segments): best of {reps}: {:.3} ms", f.segments(), 1e3 * best);
        return;
    }
    let n = 2000;
    let grid: Vec<Case> = (0..n).map(|i| Case::new(0.0, -3.0 + 5.0 * i as f64 / (n - 1) as f64, 0.8)).collect();
    let srp: Vec<Case> = grid.iter().map(|c| Case { eps: 0.05, cs: 0.4, cd: 0.1, theta_sun0: 0.7, ..*c }).collect();
    let tol: f64 = arg("--rtol").map(|s| s.parse().unwrap()).unwrap_or(1e-12);
    let method = arg("--method").map(|s| Method::parse(&s).expect("--method: rkf78, rkn86 or dp87")).unwrap_or_default();
    let opts = LaneOptions { rtol: tol, atol: tol, method, ..LaneOptions::default() };
    println!("method {}, rtol = atol = {tol:.0e}", method.name());

    let runs: [(&str, &[Case], bool); 3] = [("gravity, no STM", &grid, false), ("gravity, STM", &grid, true), ("SRP, STM", &srp, true)];
    let mut best = [f64::INFINITY; 3];
    let mut results: Vec<Vec<f64>> = vec![Vec::new(); 3];
    let mut steps = [0.0f64; 3];
    // `--only K`: time only case K (0: no STM, 1: STM, 2: SRP), e.g. for a profiler; nothing is
    // checked, saved or compared then
    let only: Option<usize> = arg("--only").map(|s| s.parse().expect("--only: 0, 1 or 2"));
    for _ in 0..reps {
        for (k, (_, cases, stm)) in runs.iter().enumerate() {
            if only.is_some_and(|o| o != k) {
                continue;
            }
            let t0 = Instant::now();
            let out = sweep(&f, o.period, cases, &opts, *stm, 64, Some(1)).unwrap();
            best[k] = best[k].min(t0.elapsed().as_secs_f64());
            results[k] = values(&out);
            steps[k] = out.iter().map(|o| (o.accepted + o.rejected) as f64).sum::<f64>() / n as f64;
        }
    }
    for (k, (name, _, _)) in runs.iter().enumerate() {
        if only.is_none_or(|o| o == k) {
            println!("{name:>16}: best of {reps}: {:8.2} ms  ({:.2} us per trajectory)", 1e3 * best[k], 1e6 * best[k] / n as f64);
        }
    }
    if only.is_some() {
        return; // the other cases were not run: nothing to check, save or compare
    }
    if args.iter().any(|a| a == "--accuracy") {
        // against RKF7(8) at rtol = atol = 1e-15 (bench/bench_lanes.py's reference and metric):
        // max over the map of max(|d phi(T)|, |d wz(T)|) / max(1, |phi|, |wz|)
        let ref_opts = LaneOptions { rtol: 1e-15, atol: 1e-15, method: Method::Rkf78, ..LaneOptions::default() };
        for (k, (name, cases, stm)) in runs.iter().enumerate() {
            let r = sweep(&f, o.period, cases, &ref_opts, *stm, 64, None).unwrap();
            let mut err = 0.0f64;
            for (i, o) in r.iter().enumerate() {
                let (phi, wz) = (results[k][6 * i], results[k][6 * i + 1]);
                err = err.max((phi - o.phi_t).abs().max((wz - o.wz_t).abs()) / o.phi_t.abs().max(o.wz_t.abs()).max(1.0));
            }
            println!("{name:>16}: accuracy {err:.2e} against RKF7(8) at 1e-15, {:.1} steps per trajectory", steps[k]);
            if args.iter().any(|a| a == "--solo") {
                // each trajectory alone (its group's other lanes copies of it): the lock step's cost
                let out = sweep(&f, o.period, cases, &opts, *stm, 64, None).unwrap();
                let rej: f64 = out.iter().map(|o| o.rejected as f64).sum::<f64>() / n as f64;
                let solo: f64 = cases.iter().map(|c| sweep(&f, o.period, std::slice::from_ref(c), &opts, *stm, 64, Some(1)).unwrap()[0]).map(|o| (o.accepted + o.rejected) as f64).sum::<f64>() / n as f64;
                println!("{name:>16}: {rej:.1} rejected per trajectory; alone {solo:.1} steps per trajectory");
            }
        }
    }
    let all: Vec<f64> = results.concat();
    if let Some(path) = arg("--save") {
        save_bits(&path, &all);
    }
    if let Some(path) = arg("--compare") {
        let old = read_bits(&path);
        assert_eq!(old.len(), all.len(), "different number of values");
        let per = all.len() / 3;
        for (k, (name, _, _)) in runs.iter().enumerate() {
            let (mut abs, mut rel, mut differ) = (0.0f64, 0.0f64, 0usize);
            for i in k * per..(k + 1) * per {
                let (a, b) = (all[i], old[i]);
                if a.to_bits() != b.to_bits() && !(a.is_nan() && b.is_nan()) {
                    differ += 1;
                    abs = abs.max((a - b).abs());
                    rel = rel.max((a - b).abs() / b.abs().max(1.0));
                }
            }
            println!("{name:>16}: {differ} of {per} values differ from {path}; max |diff| {abs:.3e}, max |diff| / max(1, |old|) {rel:.3e}");
        }
    }
}
