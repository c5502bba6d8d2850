//! The instantaneous Earth-Moon rotating frame and the maps between CR3BP synodic states
//! (nondimensional, barycentric, the project's units) and Moon-centred ICRF states.
//!
//! With R, V, A the Moon's position, velocity and acceleration relative to the Earth (from the
//! ephemeris), h = R x V: x = R / |R|, z = h / |h|, y = z x x; distance l = |R|, its rate
//! l' = R.V / l, rotation rate theta' = |h| / l^2. The frame's angular velocity is
//! omega = theta' z + (l (A.z) / |h|) x, so that C' = [omega]x C for C = [x y z].
//! A synodic state (rho, rho') maps, with rho_m = rho - (1 - mu, 0, 0) (relative to the Moon) and
//! dimensional time dt = d tau / theta', to
//! r = l C rho_m, v = l' C rho_m + l omega x (C rho_m) + l theta' C rho_m'.
//! In a circular ephemeris (l' = 0, omega = n z, n^2 l^3 = GM_E + GM_M) these are the classical
//! CR3BP scalings.

use super::chebyshev::{Ephemeris, EARTH, MOON};
use crate::error::{check_finite, invalid, Result};

/// The frame at one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotatingFrame {
    pub epoch: f64,
    /// Earth-Moon distance (km) and its rate (km/s).
    pub distance_km: f64,
    pub distance_rate_km_s: f64,
    /// Rotation rate theta' (rad/s).
    pub rate_rad_s: f64,
    /// Rows x, y, z in ICRF.
    pub axes: [[f64; 3]; 3],
    /// Angular velocity of the frame in ICRF (rad/s).
    pub omega: [f64; 3],
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl RotatingFrame {
    pub fn at(eph: &Ephemeris, epoch: f64) -> Result<Self> {
        let p = eph.pva(MOON, EARTH, epoch)?;
        let (r, v, a) = (p[0], p[1], p[2]);
        let l = norm(&r);
        let h = cross(&r, &v);
        let hn = norm(&h);
        let x = r.map(|c| c / l);
        let z = h.map(|c| c / hn);
        let y = cross(&z, &x);
        let rate = hn / (l * l);
        let wx = l * dot(&a, &z) / hn;
        let omega = std::array::from_fn(|i| rate * z[i] + wx * x[i]);
        Ok(Self { epoch, distance_km: l, distance_rate_km_s: dot(&r, &v) / l, rate_rad_s: rate, axes: [x, y, z], omega })
    }

    /// C v (rotating components -> ICRF).
    fn rot_icrf(&self, v: &[f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| self.axes[0][i] * v[0] + self.axes[1][i] * v[1] + self.axes[2][i] * v[2])
    }
    /// C^T v.
    fn icrf_rot(&self, v: &[f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| dot(&self.axes[k], v))
    }
}

fn check_mu(mu: f64) -> Result<()> {
    if !(mu > 0.0 && mu < 0.5) {
        return Err(invalid("mu", format!("must be in (0, 0.5), got {mu}")));
    }
    Ok(())
}

/// Synodic (nondimensional, barycentric) state -> Moon-centred ICRF state (km, km/s).
pub fn synodic_to_ephemeris(frame: &RotatingFrame, mu: f64, s: &[f64; 6]) -> Result<[f64; 6]> {
    check_mu(mu)?;
    check_finite("state", s)?;
    let (l, ld, th) = (frame.distance_km, frame.distance_rate_km_s, frame.rate_rad_s);
    let rho = [s[0] - (1.0 - mu), s[1], s[2]];
    let cr = frame.rot_icrf(&rho);
    let cv = frame.rot_icrf(&[s[3], s[4], s[5]]);
    let wr = cross(&frame.omega, &cr);
    let r = cr.map(|c| l * c);
    let v: [f64; 3] = std::array::from_fn(|i| ld * cr[i] + l * wr[i] + l * th * cv[i]);
    Ok([r[0], r[1], r[2], v[0], v[1], v[2]])
}

/// Moon-centred ICRF state (km, km/s) -> synodic state (the inverse of [`synodic_to_ephemeris`]).
pub fn ephemeris_to_synodic(frame: &RotatingFrame, mu: f64, e: &[f64; 6]) -> Result<[f64; 6]> {
    check_mu(mu)?;
    check_finite("state_km", e)?;
    let (l, ld, th) = (frame.distance_km, frame.distance_rate_km_s, frame.rate_rad_s);
    let r = [e[0], e[1], e[2]];
    let cr = r.map(|c| c / l);
    let wr = cross(&frame.omega, &cr);
    let rest: [f64; 3] = std::array::from_fn(|i| (e[3 + i] - ld * cr[i] - l * wr[i]) / (l * th));
    let rho = frame.icrf_rot(&cr);
    let rv = frame.icrf_rot(&rest);
    Ok([rho[0] + (1.0 - mu), rho[1], rho[2], rv[0], rv[1], rv[2]])
}
