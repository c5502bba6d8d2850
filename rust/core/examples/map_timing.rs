//! Times the periodicity-map engine on the standard map and optionally saves or compares its
//! results bit for bit.
//!
//! Standard map: Earth-Moon (mu = 0.01215), the DRO through x0 = 0.70 (symmetric corrector, as
//! in tests/map.rs), Kz = 0.8, phi0 = 0, 2000 wz0 evenly spaced in [-3, 2], one period,
//! rtol = atol = 1e-12; without and with the 2x2 STM; and an SRP case (flat plate eps = 0.05,
//! Cs = 0.4, Cd = 0.1, Sun phase 0.7, STM on). One thread, best of `--reps` runs (default 15),
//! cases alternating round-robin so that a load change on the shared machine hits all alike.
//!
//!   cargo run --release -p librate-core --example map_timing -- [--reps N] [--save FILE] [--compare FILE]
//!
//! `--save` writes every outcome (phi_t, wz_t, stm) as raw f64 bits; `--compare` reads such a
//! file and prints the largest absolute and relative differences per case.

use std::time::Instant;

use librate_core::integrate::Options;
use librate_core::integrate::forcing::OrbitForcing;
use librate_core::integrate::lanes::{Case, LaneOptions, Method, Outcome};
use librate_core::map::sweep;
use librate_core::orbit::correct_planar_symmetric;

const MU: f64 = 0.01215;

fn values(out: &[Outcome]) -> Vec<f64> {
    out.iter().flat_map(|o| [o.phi_t, o.wz_t, o.stm[0], o.stm[1], o.stm[2], o.stm[3]]).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| args.iter().position(|a| a == name).map(|i| args[i + 1].clone());
    let reps: usize = arg("--reps").map(|s| s.parse().unwrap()).unwrap_or(15);

    let x0 = 0.70;
    // ydot0 guess 0.69 (the DRO's is 0.69350, period 4.8588 TU; the guess sqrt(mu/d) + d = 0.49
    // converges to another symmetric orbit, of period 10.79)
    let o = correct_planar_symmetric(MU, x0, 0.69, 1e-12, 30, &Options::with_tolerances(1e-13, 1e-13)).unwrap();
    assert!((o.period - 4.858760).abs() < 1e-5, "not the DRO through x0 = 0.70: period {}", o.period);
    let f = OrbitForcing::new(MU, &o.state0, o.period, [true, true], 1e-13).unwrap();
    println!("orbit: x0 = {:.17e}, ydot0 = {:.17e}, period = {:.17e}; forcing table error {:.3e}", o.state0[0], o.state0[4], o.period, f.max_error);
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
    for _ in 0..reps {
        for (k, (_, cases, stm)) in runs.iter().enumerate() {
            let t0 = Instant::now();
            let out = sweep(&f, o.period, cases, &opts, *stm, 64, Some(1)).unwrap();
            best[k] = best[k].min(t0.elapsed().as_secs_f64());
            results[k] = values(&out);
            steps[k] = out.iter().map(|o| (o.accepted + o.rejected) as f64).sum::<f64>() / n as f64;
        }
    }
    for (k, (name, _, _)) in runs.iter().enumerate() {
        println!("{name:>16}: best of {reps}: {:8.2} ms  ({:.2} us per trajectory)", 1e3 * best[k], 1e6 * best[k] / n as f64);
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
        }
    }
    let all: Vec<f64> = results.concat();
    if let Some(path) = arg("--save") {
        let bytes: Vec<u8> = all.iter().flat_map(|v| v.to_bits().to_le_bytes()).collect();
        std::fs::write(&path, bytes).unwrap();
        println!("saved {} values to {path}", all.len());
    }
    if let Some(path) = arg("--compare") {
        let bytes = std::fs::read(&path).unwrap();
        let old: Vec<f64> = bytes.chunks_exact(8).map(|b| f64::from_bits(u64::from_le_bytes(b.try_into().unwrap()))).collect();
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
