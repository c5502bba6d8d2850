//! Propagation drivers of the attitude models.

use super::body::RigidBody;
use super::dynamics::{dcm, Coupled, CoupledStm, OrbitMode, DIM, STM_DIM};
use super::planar::PlanarAlongOrbit;
use super::srp::FlatPlate;
use super::torque::Torque;
use crate::cr3bp::check_mu;
use crate::error::{check_finite, invalid, Result};
use crate::integrate::{solve, solve_piecewise, EventFn, Options, Output, Stats};

/// Result of [`propagate_attitude`].
#[derive(Debug, Clone)]
pub struct AttitudeTrajectory {
    pub t: Vec<f64>,
    /// Row-major n x 13: orbit (6), quaternion (4, scalar last), inertial rate in body axes (3).
    pub states: Vec<f64>,
    /// 13x13 STM (row-major) from t0 to the final time, when asked.
    pub stm_final: Option<Vec<f64>>,
    pub stats: Stats,
}

/// Propagate the coupled 3-D model.
pub fn propagate_attitude(
    mu: f64,
    body: RigidBody,
    torques: &[&dyn Torque],
    orbit: OrbitMode,
    state0: &[f64; DIM],
    t0: f64,
    tf: f64,
    opts: &Options,
    with_stm: bool,
    output: Output<'_>,
    orbit_srp: Option<(&super::srp::FacetBody, f64, f64)>,
    terminators: Option<&super::srp::FacetBody>,
) -> Result<AttitudeTrajectory> {
    check_mu(mu)?;
    RigidBody::new(body.ix, body.iy, body.iz)?;
    check_finite("state", state0)?;
    let qn = (state0[6..10].iter().map(|v| v * v).sum::<f64>()).sqrt();
    if (qn - 1.0).abs() > 1e-9 {
        return Err(invalid("q", format!("must be a unit quaternion (scalar last), |q| = {qn}")));
    }
    if let OrbitMode::Coupled { inertia_nd } = orbit {
        check_finite("inertia_nd", &inertia_nd)?;
    }
    let model = Coupled { mu, body, torques: torques.to_vec(), orbit, orbit_srp };
    // Facet SRP is C1 in the attitude: integrate piecewise between the facets' terminator
    // crossings n_k . s_body = 0 (one switching function per facet).
    let facets = terminators.map(|m| m.facets.clone()).unwrap_or_default();
    let sun = terminators.map(|m| m.sun).unwrap_or_default();
    let switch = |k: usize, t: f64, y: &[f64]| -> f64 {
        let a = dcm(&[y[6], y[7], y[8], y[9]]);
        let s = sun.direction(t);
        let n = facets[k].normal;
        (0..3).map(|i| n[i] * (a[i][0] * s[0] + a[i][1] * s[1] + a[i][2] * s[2])).sum()
    };
    if with_stm {
        let sys = CoupledStm(model);
        let fns: Vec<Box<dyn Fn(f64, &[f64; STM_DIM]) -> f64 + Sync + '_>> = (0..facets.len()).map(|k| Box::new(move |t: f64, y: &[f64; STM_DIM]| switch(k, t, y)) as Box<dyn Fn(f64, &[f64; STM_DIM]) -> f64 + Sync>).collect();
        let kinks: Vec<&dyn EventFn<[f64; STM_DIM]>> = fns.iter().map(|f| f as &dyn EventFn<[f64; STM_DIM]>).collect();
        let sol = if kinks.is_empty() {
            solve(&sys, t0, &CoupledStm::initial(state0), tf, opts, output, &[])?
        } else {
            solve_piecewise(&sys, t0, &CoupledStm::initial(state0), tf, opts, output, &kinks)?
        };
        let mut states = Vec::with_capacity(sol.t.len() * DIM);
        for row in sol.y.chunks_exact(STM_DIM) {
            states.extend_from_slice(&row[..DIM]);
        }
        Ok(AttitudeTrajectory { t: sol.t, states, stm_final: Some(sol.y_final[DIM..].to_vec()), stats: sol.stats })
    } else {
        let fns: Vec<Box<dyn Fn(f64, &[f64; DIM]) -> f64 + Sync + '_>> = (0..facets.len()).map(|k| Box::new(move |t: f64, y: &[f64; DIM]| switch(k, t, y)) as Box<dyn Fn(f64, &[f64; DIM]) -> f64 + Sync>).collect();
        let kinks: Vec<&dyn EventFn<[f64; DIM]>> = fns.iter().map(|f| f as &dyn EventFn<[f64; DIM]>).collect();
        let sol = if kinks.is_empty() { solve(&model, t0, state0, tf, opts, output, &[])? } else { solve_piecewise(&model, t0, state0, tf, opts, output, &kinks)? };
        Ok(AttitudeTrajectory { t: sol.t, states: sol.y, stm_final: None, stats: sol.stats })
    }
}

/// Result of [`propagate_planar`].
#[derive(Debug, Clone)]
pub struct PlanarTrajectory {
    pub t: Vec<f64>,
    /// Row-major n x 6.
    pub orbit: Vec<f64>,
    pub phi: Vec<f64>,
    pub wz: Vec<f64>,
    /// 2x2 attitude STM d(phi, wz)(tf) / d(phi, wz)(t0), row-major, when asked.
    pub stm_final: Option<[f64; 4]>,
    pub stats: Stats,
}

fn check_kz(kz: f64) -> Result<()> {
    if kz.is_finite() && (-1.0..=1.0).contains(&kz) {
        Ok(())
    } else {
        Err(invalid("kz", format!("must be in [-1, 1], got {kz}")))
    }
}

/// Planar attitude (phi, wz) with the orbit integrated alongside (or held at its start).
pub fn propagate_planar(
    mu: f64,
    kz: f64,
    primaries: [bool; 2],
    held: bool,
    orbit0: &[f64; 6],
    phi0: f64,
    wz0: f64,
    t0: f64,
    tf: f64,
    opts: &Options,
    with_stm: bool,
    output: Output<'_>,
    srp: Option<FlatPlate>,
) -> Result<PlanarTrajectory> {
    check_mu(mu)?;
    check_kz(kz)?;
    check_finite("orbit_state", orbit0)?;
    check_finite("attitude", &[phi0, wz0])?;
    if orbit0[2] != 0.0 || orbit0[5] != 0.0 {
        return Err(invalid("orbit_state", format!("the planar model needs a planar orbit (z = zd = 0), got z = {}, zd = {}", orbit0[2], orbit0[5])));
    }
    let sys = PlanarAlongOrbit { mu, kz, primaries, held, srp };
    let mut y0 = [0.0; 12];
    y0[..6].copy_from_slice(orbit0);
    y0[6] = phi0;
    y0[7] = wz0;
    // The plate law is C1 only: integrate piecewise between the terminator crossings.
    let kink12 = srp.map(|p| move |t: f64, y: &[f64; 12]| p.terminator(t, y[6]));
    let kink8 = srp.map(|p| move |t: f64, y: &[f64; 8]| p.terminator(t, y[6]));
    let (t, rows, width, stm, stats) = if with_stm {
        y0[8] = 1.0;
        y0[11] = 1.0;
        let sol = match &kink12 {
            Some(k) => solve_piecewise(&sys, t0, &y0, tf, opts, output, &[k as &dyn EventFn<[f64; 12]>])?,
            None => solve(&sys, t0, &y0, tf, opts, output, &[])?,
        };
        let f = sol.y_final;
        (sol.t, sol.y, 12, Some([f[8], f[9], f[10], f[11]]), sol.stats)
    } else {
        let y8: [f64; 8] = std::array::from_fn(|i| y0[i]);
        let sol = match &kink8 {
            Some(k) => solve_piecewise(&sys, t0, &y8, tf, opts, output, &[k as &dyn EventFn<[f64; 8]>])?,
            None => solve(&sys, t0, &y8, tf, opts, output, &[])?,
        };
        (sol.t, sol.y, 8, None, sol.stats)
    };
    let n = t.len();
    let mut orbit = Vec::with_capacity(6 * n);
    let (mut phi, mut wz) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for row in rows.chunks_exact(width) {
        orbit.extend_from_slice(&row[..6]);
        phi.push(row[6]);
        wz.push(row[7]);
    }
    Ok(PlanarTrajectory { t, orbit, phi, wz, stm_final: stm, stats })
}

/// The total torque of `torques` (body axes) at each coupled state (rows of 13).
pub fn evaluate_torques(mu: f64, body: RigidBody, torques: &[&dyn Torque], t: &[f64], states: &[f64]) -> Result<Vec<[f64; 3]>> {
    check_mu(mu)?;
    if states.len() != 13 * t.len() {
        return Err(invalid("states", format!("need one row of 13 per time: {} values for {} times", states.len(), t.len())));
    }
    Ok(states
        .chunks_exact(13)
        .zip(t)
        .map(|(s, &ti)| {
            let q = [s[6], s[7], s[8], s[9]];
            let input = super::torque::TorqueInput {
                t: ti,
                mu,
                pos: [s[0], s[1], s[2]],
                vel: [s[3], s[4], s[5]],
                a: super::dynamics::dcm(&q),
                w: [s[10], s[11], s[12]],
                inertia: body.moments(),
            };
            let mut out = [0.0; 3];
            for m in torques {
                let v = m.torque(&input);
                for i in 0..3 {
                    out[i] += v[i];
                }
            }
            out
        })
        .collect())
}
