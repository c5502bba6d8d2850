//! Propagation drivers of the flexible model and of its quasi-static closed form.

use super::body::FlexibleBody;
use super::dynamics::{tidal_field, BodyField, Energies, FlexibleAlongOrbit};
use super::quasi_static::{QuasiStaticAlongOrbit, QuasiStaticPoint};
use crate::cr3bp::{check_mu, Cr3bp};
use crate::error::{check_finite, invalid, Result};
use crate::integrate::{solve, Options, Output, Stats, System};

/// Result of [`propagate_flexible`].
#[derive(Debug, Clone)]
pub struct FlexibleTrajectory {
    pub t: Vec<f64>,
    /// Row-major n_t x 6.
    pub orbit: Vec<f64>,
    pub phi: Vec<f64>,
    pub wz: Vec<f64>,
    /// Row-major n_t x n (n appendages): deflections and their rates (length, length / TU).
    pub q: Vec<f64>,
    pub qdot: Vec<f64>,
    pub stats: Stats,
}

fn check_orbit(orbit0: &[f64; 6]) -> Result<()> {
    check_finite("orbit_state", orbit0)?;
    if orbit0[2] != 0.0 || orbit0[5] != 0.0 {
        return Err(invalid("orbit_state", format!("the planar model needs a planar orbit (z = zd = 0), got z = {}, zd = {}", orbit0[2], orbit0[5])));
    }
    Ok(())
}

/// Propagate the coupled flexible model (phi, wz, q, qdot) with the orbit integrated alongside
/// (or held at its initial position).
pub fn propagate_flexible(
    mu: f64,
    body: &FlexibleBody,
    primaries: [bool; 2],
    held: bool,
    orbit0: &[f64; 6],
    phi0: f64,
    wz0: f64,
    q0: &[f64],
    qdot0: &[f64],
    t0: f64,
    tf: f64,
    opts: &Options,
    output: Output<'_>,
) -> Result<FlexibleTrajectory> {
    check_mu(mu)?;
    check_orbit(orbit0)?;
    check_finite("attitude", &[phi0, wz0])?;
    let n = body.n();
    if q0.len() != n || qdot0.len() != n {
        return Err(invalid("deflection", format!("q0 and qdot0 need one value per appendage ({n}), got {} and {}", q0.len(), qdot0.len())));
    }
    check_finite("deflection", q0)?;
    check_finite("deflection", qdot0)?;
    let sys = FlexibleAlongOrbit { mu, body, primaries, held };
    let mut y0 = Vec::with_capacity(8 + 2 * n);
    y0.extend_from_slice(orbit0);
    y0.extend_from_slice(&[phi0, wz0]);
    y0.extend_from_slice(q0);
    y0.extend_from_slice(qdot0);
    let sol = solve(&sys, t0, &y0, tf, opts, output, &[])?;
    let m = sol.t.len();
    let w = 8 + 2 * n;
    let mut tr = FlexibleTrajectory {
        t: sol.t,
        orbit: Vec::with_capacity(6 * m),
        phi: Vec::with_capacity(m),
        wz: Vec::with_capacity(m),
        q: Vec::with_capacity(n * m),
        qdot: Vec::with_capacity(n * m),
        stats: sol.stats,
    };
    for row in sol.y.chunks_exact(w) {
        tr.orbit.extend_from_slice(&row[..6]);
        tr.phi.push(row[6]);
        tr.wz.push(row[7]);
        tr.q.extend_from_slice(&row[8..8 + n]);
        tr.qdot.extend_from_slice(&row[8 + n..]);
    }
    Ok(tr)
}

/// Result of [`propagate_quasi_static`]: the rigid composite solution, the closed-form
/// deflections along it and the first-order attitude perturbation.
#[derive(Debug, Clone)]
pub struct QuasiStaticTrajectory {
    pub t: Vec<f64>,
    pub orbit: Vec<f64>,
    /// Rigid composite solution (phi measured like the flexible model's, from the body x axis).
    pub phi: Vec<f64>,
    pub wz: Vec<f64>,
    /// First-order attitude perturbation: the flexible model's phi, wz ~ phi + dphi, wz + dwz.
    pub dphi: Vec<f64>,
    pub dwz: Vec<f64>,
    /// Row-major n_t x n: closed-form q, q', q''.
    pub q: Vec<f64>,
    pub qdot: Vec<f64>,
    pub qddot: Vec<f64>,
    /// The first-order torque perturbation.
    pub dtau: Vec<f64>,
    pub stats: Stats,
}

fn orbit_acceleration(mu: f64, held: bool, s: &[f64]) -> [f64; 3] {
    if held {
        return [0.0; 3];
    }
    let st: [f64; 6] = std::array::from_fn(|i| s[i]);
    let mut d = [0.0; 6];
    Cr3bp { mu }.derivative(0.0, &st, &mut d);
    [d[3], d[4], d[5]]
}

/// The closed form at one state of the rigid solution (orbit state, phi, wz).
pub fn quasi_static_point(mu: f64, body: &FlexibleBody, primaries: [bool; 2], held: bool, orbit: &[f64; 6], phi: f64, wz: f64) -> Result<QuasiStaticPoint> {
    check_mu(mu)?;
    check_orbit(orbit)?;
    check_finite("attitude", &[phi, wz])?;
    let acc = orbit_acceleration(mu, held, orbit);
    let vel = if held { [0.0; 3] } else { [orbit[3], orbit[4], orbit[5]] };
    Ok(body.quasi_static(mu, primaries, &orbit[..3], &vel, &acc, phi, wz))
}

/// Propagate the rigid composite model with the first-order flexible perturbation, and
/// evaluate the closed-form deflections at the output times.
pub fn propagate_quasi_static(
    mu: f64,
    body: &FlexibleBody,
    primaries: [bool; 2],
    held: bool,
    orbit0: &[f64; 6],
    phi0: f64,
    wz0: f64,
    t0: f64,
    tf: f64,
    opts: &Options,
    output: Output<'_>,
) -> Result<QuasiStaticTrajectory> {
    check_mu(mu)?;
    check_orbit(orbit0)?;
    check_finite("attitude", &[phi0, wz0])?;
    let sys = QuasiStaticAlongOrbit { mu, body, primaries, held };
    let mut y0 = [0.0; 10];
    y0[..6].copy_from_slice(orbit0);
    y0[6] = phi0;
    y0[7] = wz0;
    let sol = solve(&sys, t0, &y0, tf, opts, output, &[])?;
    let m = sol.t.len();
    let n = body.n();
    let mut tr = QuasiStaticTrajectory {
        t: sol.t,
        orbit: Vec::with_capacity(6 * m),
        phi: Vec::with_capacity(m),
        wz: Vec::with_capacity(m),
        dphi: Vec::with_capacity(m),
        dwz: Vec::with_capacity(m),
        q: Vec::with_capacity(n * m),
        qdot: Vec::with_capacity(n * m),
        qddot: Vec::with_capacity(n * m),
        dtau: Vec::with_capacity(m),
        stats: sol.stats,
    };
    for row in sol.y.chunks_exact(10) {
        let acc = orbit_acceleration(mu, held, row);
        let vel = if held { [0.0; 3] } else { [row[3], row[4], row[5]] };
        let p = body.quasi_static(mu, primaries, &row[..3], &vel, &acc, row[6], row[7]);
        tr.orbit.extend_from_slice(&row[..6]);
        tr.phi.push(row[6]);
        tr.wz.push(row[7]);
        tr.dphi.push(row[8]);
        tr.dwz.push(row[9]);
        tr.q.extend_from_slice(&p.q);
        tr.qdot.extend_from_slice(&p.qdot);
        tr.qddot.extend_from_slice(&p.qddot);
        tr.dtau.push(p.dtau);
    }
    Ok(tr)
}

/// Energies of each state of a trajectory (rows of the orbit, phi, wz, q, qdot as returned by
/// [`propagate_flexible`]), for the enabled primaries.
pub fn evaluate_energies(mu: f64, body: &FlexibleBody, primaries: [bool; 2], orbit: &[f64], phi: &[f64], wz: &[f64], q: &[f64], qdot: &[f64]) -> Result<Vec<Energies>> {
    check_mu(mu)?;
    let m = phi.len();
    let n = body.n();
    if orbit.len() != 6 * m || wz.len() != m || q.len() != n * m || qdot.len() != n * m {
        return Err(invalid("states", format!("need {m} rows: orbit of 6, phi, wz, and q, qdot of {n} each")));
    }
    Ok((0..m)
        .map(|i| {
            let (w, p) = tidal_field(mu, &orbit[6 * i..6 * i + 3], primaries);
            let field = BodyField::new(w, p, phi[i]);
            body.energies(&field, wz[i], &q[n * i..n * (i + 1)], &qdot[n * i..n * (i + 1)])
        })
        .collect())
}

/// The right-hand side at one state, for tests and diagnostics: (wzdot, qddot).
pub fn flexible_rates(mu: f64, body: &FlexibleBody, primaries: [bool; 2], orbit: &[f64; 6], phi: f64, wz: f64, q: &[f64], qdot: &[f64]) -> (f64, Vec<f64>) {
    let sys = FlexibleAlongOrbit { mu, body, primaries, held: true };
    let mut y = orbit.to_vec();
    y.extend_from_slice(&[phi, wz]);
    y.extend_from_slice(q);
    y.extend_from_slice(qdot);
    let mut dy = vec![0.0; y.len()];
    sys.derivative(0.0, &y, &mut dy);
    (dy[7], dy[8 + body.n()..].to_vec())
}
