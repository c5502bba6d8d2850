//! Ephemeris model checks on synthetic SPK segments (Chebyshev fits of analytic motions):
//! the series and its derivatives against the analytic functions, the STM against central
//! finite differences, the frame maps' round trip, and the analytic check that in a circular
//! Earth-Moon ephemeris with the Sun's GM = 0 the ephemeris dynamics mapped from the synodic
//! frame reproduce the CR3BP (the classical scalings are exact there).

use librate_core::cr3bp::Cr3bp;
use librate_core::ephemeris::{ephemeris_to_synodic, propagate_ephemeris, synodic_to_ephemeris, Ephemeris, EphemerisDynamics, RotatingFrame, Segment, GM_EARTH, GM_MOON};
use librate_core::ephemeris::{transition, TransitionSettings};
use librate_core::integrate::{solve, Options, Output};
use librate_core::newton::StopReason;

const L: f64 = 384400.0;
const DEG: usize = 18;

/// Chebyshev interpolation coefficients of f over [a, b] at DEG + 1 Chebyshev nodes.
fn fit(f: &dyn Fn(f64) -> [f64; 3], a: f64, b: f64) -> Vec<f64> {
    let n = DEG + 1;
    let mut c = vec![0.0; 3 * n];
    for k in 0..n {
        let th = std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
        let s = th.cos();
        let v = f(0.5 * (a + b) + 0.5 * (b - a) * s);
        for j in 0..n {
            let w = (j as f64 * th).cos() * 2.0 / n as f64 * if j == 0 { 0.5 } else { 1.0 };
            for x in 0..3 {
                c[x * n + j] += w * v[x];
            }
        }
    }
    c
}

fn segment(target: i32, center: i32, f: &dyn Fn(f64) -> [f64; 3], start: f64, intlen: f64, records: usize) -> Segment {
    let mut coef = Vec::new();
    for r in 0..records {
        let a = start + r as f64 * intlen;
        coef.extend(fit(f, a, a + intlen));
    }
    Segment::new(target, center, start, start + intlen * records as f64, start, intlen, records, DEG + 1, coef).unwrap()
}

fn mu() -> f64 {
    GM_MOON / (GM_EARTH + GM_MOON)
}

/// Earth and Moon on circles about the EMB (inclined plane), EMB at the SSB, Sun far on a circle.
fn circular(incl: f64) -> Ephemeris {
    let n = ((GM_EARTH + GM_MOON) / L.powi(3)).sqrt();
    let m = mu();
    let (ci, si) = (incl.cos(), incl.sin());
    let circ = move |rad: f64, t: f64| [rad * (n * t).cos(), rad * (n * t).sin() * ci, rad * (n * t).sin() * si];
    let (t0, len, recs) = (-10.0 * 86400.0, 4.0 * 86400.0, 40);
    Ephemeris::new(vec![
        segment(301, 3, &move |t| circ((1.0 - m) * L, t), t0, len, recs),
        segment(399, 3, &move |t| circ(-m * L, t), t0, len, recs),
        segment(3, 0, &|_| [0.0; 3], t0, 16.0 * len, recs / 16 + 1),
        segment(10, 0, &|t| [1.5e8 * (2e-7 * t).cos(), 1.5e8 * (2e-7 * t).sin(), 0.0], t0, len, recs),
    ])
    .unwrap()
}

/// The series reproduces the fitted circle, its velocity and acceleration (1e-6 km, 1e-11 km/s,
/// 1e-14 km/s^2: the interpolation error of degree 18 over 4 days, amplified by differentiation), and the chain Earth rel. Moon.
#[test]
fn chebyshev_series_and_chain() {
    let eph = circular(0.3);
    let n = ((GM_EARTH + GM_MOON) / L.powi(3)).sqrt();
    let (ci, si) = (0.3f64.cos(), 0.3f64.sin());
    for k in 0..200 {
        let t = -9.0 * 86400.0 + k as f64 * 7919.3;
        let p = eph.pva(399, 301, t).unwrap();
        let (c, s) = ((n * t).cos(), (n * t).sin());
        let r = [-L * c, -L * s * ci, -L * s * si];
        let v = [L * n * s, -L * n * c * ci, -L * n * c * si];
        let a = [L * n * n * c, L * n * n * s * ci, L * n * n * s * si];
        for i in 0..3 {
            assert!((p[0][i] - r[i]).abs() < 1e-6, "pos {} vs {}", p[0][i], r[i]);
            assert!((p[1][i] - v[i]).abs() < 1e-11, "vel {} vs {}", p[1][i], v[i]);
            assert!((p[2][i] - a[i]).abs() < 1e-14, "acc {} vs {}", p[2][i], a[i]);
        }
    }
    let err = eph.state(399, 301, 1e9).unwrap_err().to_string();
    assert!(err.contains("outside the ephemeris span"), "{err}");
}

/// The STM against central finite differences of the propagated state over 3 days (relative
/// 1e-6 of each column's magnitude).
#[test]
fn stm_matches_finite_differences() {
    let eph = circular(0.1);
    let dynamics = EphemerisDynamics::new(eph, 0.0).unwrap();
    let opts = Options::with_tolerances(1e-13, 1e-12);
    let x0 = [5000.0, -3000.0, 20000.0, 0.2, 0.5, -0.1];
    let dur = 3.0 * 86400.0;
    let tr = propagate_ephemeris(&dynamics, &x0, dur, true, None, &opts).unwrap();
    let phi = tr.stm.unwrap();
    for j in 0..6 {
        let h = if j < 3 { 1e-2 } else { 1e-5 };
        let mut xp = x0;
        xp[j] += h;
        let mut xm = x0;
        xm[j] -= h;
        let fp = propagate_ephemeris(&dynamics, &xp, dur, false, None, &opts).unwrap().state_final;
        let fm = propagate_ephemeris(&dynamics, &xm, dur, false, None, &opts).unwrap().state_final;
        let col: Vec<f64> = (0..6).map(|i| (fp[i] - fm[i]) / (2.0 * h)).collect();
        let scale = col.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..6 {
            assert!((phi[i * 6 + j] - col[i]).abs() < 1e-6 * scale, "phi[{i}][{j}] = {} vs {}", phi[i * 6 + j], col[i]);
        }
    }
}

/// Synodic -> ephemeris -> synodic is the identity (1e-13).
#[test]
fn frame_maps_round_trip() {
    let eph = circular(0.4);
    let f = RotatingFrame::at(&eph, 12345.0).unwrap();
    let s = [1.1, 0.05, -0.2, 0.01, -0.3, 0.2];
    let e = synodic_to_ephemeris(&f, mu(), &s).unwrap();
    let b = ephemeris_to_synodic(&f, mu(), &e).unwrap();
    for i in 0..6 {
        assert!((b[i] - s[i]).abs() < 1e-13, "{i}: {} vs {}", b[i], s[i]);
    }
    assert!((f.rate_rad_s - ((GM_EARTH + GM_MOON) / L.powi(3)).sqrt()).abs() < 1e-16);
    assert!((f.distance_km - L).abs() < 1e-6);
}

/// Analytic check: in the circular ephemeris (Sun GM 0) a CR3BP trajectory mapped to the
/// ephemeris at epoch 0, propagated there for 5 days and mapped back equals the CR3BP
/// propagation (1e-9 LU, 1e-9 VU: integration and fit error).
#[test]
fn circular_ephemeris_is_the_cr3bp() {
    let eph = circular(0.2);
    let m = mu();
    let dynamics = EphemerisDynamics::with_gm(eph.clone(), 0.0, [GM_EARTH, GM_MOON, 0.0]).unwrap();
    let n = ((GM_EARTH + GM_MOON) / L.powi(3)).sqrt();
    let s0 = [1.05, 0.02, 0.1, 0.01, 0.2, -0.05];
    let f0 = RotatingFrame::at(&eph, 0.0).unwrap();
    let e0 = synodic_to_ephemeris(&f0, m, &s0).unwrap();
    let dur = 5.0 * 86400.0;
    let opts = Options::with_tolerances(1e-13, 1e-12);
    let ef = propagate_ephemeris(&dynamics, &e0, dur, false, None, &opts).unwrap().state_final;
    let f1 = RotatingFrame::at(&eph, dur).unwrap();
    let sf = ephemeris_to_synodic(&f1, m, &ef).unwrap();
    let cr = solve(&Cr3bp { mu: m }, 0.0, &s0, dur * n, &opts, Output::Final, &[]).unwrap().y_final;
    for i in 0..6 {
        assert!((sf[i] - cr[i]).abs() < 1e-9, "{i}: {} vs {}", sf[i], cr[i]);
    }
}

/// Guess nodes: a CR3BP DRO (x0 = 0.9) sampled `per_rev` times a revolution over `revs`
/// revolutions, mapped to the ephemeris at its epochs (dimensional time t = tau / n).
fn dro_nodes(eph: &Ephemeris, revs: usize, per_rev: usize) -> (Vec<[f64; 6]>, Vec<f64>) {
    let m = mu();
    let n = ((GM_EARTH + GM_MOON) / L.powi(3)).sqrt();
    let opts = Options::with_tolerances(1e-13, 1e-13);
    let d = 1.0 - m - 0.9;
    let o = librate_core::orbit::correct_planar_symmetric(m, 0.9, (m / d).sqrt() + d, 1e-12, 30, &opts).unwrap();
    let k = revs * per_rev;
    let ts: Vec<f64> = (0..=k).map(|i| o.period * i as f64 / per_rev as f64).collect();
    let tr = librate_core::propagation::propagate(m, &o.state0, 0.0, ts[k], &opts, false, Output::At(&ts), &[]).unwrap();
    let mut states = Vec::new();
    let mut epochs = Vec::new();
    for (i, t) in ts.iter().enumerate() {
        let s: [f64; 6] = std::array::from_fn(|a| tr.states[6 * i + a]);
        let f = RotatingFrame::at(eph, t / n).unwrap();
        states.push(synodic_to_ephemeris(&f, m, &s).unwrap());
        epochs.push(t / n);
    }
    (states, epochs)
}

fn settings(epoch_free: bool) -> TransitionSettings {
    let n = ((GM_EARTH + GM_MOON) / L.powi(3)).sqrt();
    TransitionSettings { tol_km: 1e-3, tol_km_s: 1e-8, max_iter: 20, epoch_free, length_km: L, time_s: 1.0 / n }
}

/// Analytic check: in the circular ephemeris with the Sun's GM = 0 the model is the CR3BP, so a
/// CR3BP DRO placed there is already continuous (defects below 1e-5 km: the fit's error) and the
/// transition moves no node by more than 1e-4 km.
#[test]
fn a_cr3bp_orbit_is_continuous_in_the_circular_ephemeris() {
    let eph = circular(0.3);
    let (states, epochs) = dro_nodes(&eph, 3, 4);
    let opts = Options::with_tolerances(1e-13, 1e-12);
    let tr = transition(&eph, [GM_EARTH, GM_MOON, 0.0], &states, &epochs, &settings(false), &opts).unwrap();
    assert_eq!(tr.reason, StopReason::Converged);
    assert!(tr.history[0] < 1e-2 / 1e-3, "start defects {:?}", tr.history);
    for (a, b) in tr.states.iter().zip(&states) {
        for i in 0..3 {
            assert!((a[i] - b[i]).abs() < 1e-4, "{a:?} vs {b:?}");
        }
    }
}

/// With the Sun (GM_SUN at 1.5e8 km) the DRO's guess is discontinuous by kilometres; the
/// transition converges (quadratically) and every converged leg, re-propagated from its node,
/// meets the next node within 1 m and 1e-8 km/s. Fixed and free first epoch.
#[test]
fn the_transition_converges_with_the_sun_and_its_legs_meet() {
    use librate_core::ephemeris::GM_SUN;
    let eph = circular(0.3);
    let (states, epochs) = dro_nodes(&eph, 3, 4);
    let opts = Options::with_tolerances(1e-13, 1e-12);
    let gm = [GM_EARTH, GM_MOON, GM_SUN];
    for free in [false, true] {
        let tr = transition(&eph, gm, &states, &epochs, &settings(free), &opts).unwrap();
        assert_eq!(tr.reason, StopReason::Converged, "{:?}", tr.history);
        assert!(tr.history[0] > 10.0, "the guess should be discontinuous: {:?}", tr.history);
        assert!(tr.iterations <= 8, "{:?}", tr.history);
        if !free {
            assert_eq!(tr.epochs[0], epochs[0]);
        }
        for i in 0..tr.states.len() - 1 {
            let d = EphemerisDynamics::with_gm(eph.clone(), tr.epochs[i], gm).unwrap();
            let end = propagate_ephemeris(&d, &tr.states[i], tr.epochs[i + 1] - tr.epochs[i], false, None, &opts).unwrap().state_final;
            let dr = (0..3).map(|a| (end[a] - tr.states[i + 1][a]).powi(2)).sum::<f64>().sqrt();
            let dv = (3..6).map(|a| (end[a] - tr.states[i + 1][a]).powi(2)).sum::<f64>().sqrt();
            assert!(dr < 1e-3 && dv < 1e-8, "leg {i}: {dr} km, {dv} km/s");
            assert!(tr.defects_km[i] < 1e-3 && tr.defects_km_s[i] < 1e-8);
        }
    }
}

/// Bad input is refused naming the parameter.
#[test]
fn transition_input_is_checked() {
    let eph = circular(0.3);
    let (states, mut epochs) = dro_nodes(&eph, 1, 4);
    let opts = Options::with_tolerances(1e-13, 1e-12);
    let gm = [GM_EARTH, GM_MOON, 0.0];
    let e = transition(&eph, gm, &states[..1], &epochs[..1], &settings(false), &opts).unwrap_err();
    assert!(e.to_string().contains("`states`"), "{e}");
    epochs[2] = epochs[1];
    let e = transition(&eph, gm, &states, &epochs, &settings(false), &opts).unwrap_err();
    assert!(e.to_string().contains("`epochs`"), "{e}");
    let mut s = settings(false);
    s.tol_km = 0.0;
    let e = transition(&eph, gm, &states, &dro_nodes(&eph, 1, 4).1, &s, &opts).unwrap_err();
    assert!(e.to_string().contains("`tol_km`"), "{e}");
}
