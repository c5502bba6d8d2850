//! The planar reduced attitude model along an orbit (docs/physics.md, attitude, thesis eq. 31, 33):
//!   phidot = wz - 1,   wzdot = (3/2) Kz [S(t) cos 2phi - C(t) sin 2phi],
//!   S = sum_i mu_i sin(2 theta_i) / r_i^3 = sum_i mu_i 2 x_i y_i / r_i^5,
//!   C = sum_i mu_i cos(2 theta_i) / r_i^3 = sum_i mu_i (x_i^2 - y_i^2) / r_i^5,
//! with (x_i, y_i) the position relative to primary i (the atan2-free form). S and C depend on
//! the orbit only: the orbit is integrated with the attitude, held at a point, or supplied
//! precomputed through the [`Forcing`] trait (e.g. the map engine's Chebyshev table).
//! Optional 2x2 attitude STM: d/dt [dphi, dwz] = [[0, 1], [-3 Kz (S sin 2phi + C cos 2phi), 0]].

use super::srp::FlatPlate;
use crate::cr3bp::Cr3bp;
use crate::integrate::System;
use crate::scalar::Lane;

/// S, C and P = sum_i mu_i / r_i^3 at a synodic position, for the enabled primaries [larger,
/// smaller]: the one definition of the tidal field (the flexible model's complex field is
/// W = C + i S, `flexible::tidal_field`).
#[inline(always)]
pub fn forcing_scp(mu: f64, pos: &[f64], primaries: [bool; 2]) -> (f64, f64, f64) {
    let mut s = 0.0;
    let mut c = 0.0;
    let mut p = 0.0;
    for (k, (cx, gm)) in [(-mu, 1.0 - mu), (1.0 - mu, mu)].into_iter().enumerate() {
        if !primaries[k] {
            continue;
        }
        let x = pos[0] - cx;
        let y = pos[1];
        let r2 = x * x + y * y + pos[2] * pos[2];
        let inv5 = gm / (r2 * r2 * r2.sqrt());
        s += 2.0 * x * y * inv5;
        c += (x * x - y * y) * inv5;
        p += inv5 * r2;
    }
    (s, c, p)
}

/// S and C at a synodic position, for the enabled primaries [larger, smaller].
#[inline(always)]
pub fn forcing_sc(mu: f64, pos: &[f64], primaries: [bool; 2]) -> (f64, f64) {
    let (s, c, _) = forcing_scp(mu, pos, primaries);
    (s, c)
}

/// The planar gravity-gradient angular acceleration and its derivative in phi (thesis eq. 33),
/// over f64 or SIMD lanes (the scalar model and the map engine both call this): with
/// kz15 = (3/2) Kz and (c2, s2) = (cos 2phi, sin 2phi),
///   wzdot = kz15 (S c2 - C s2),   d wzdot / d phi = -2 kz15 (S s2 + C c2).
#[inline(always)]
pub fn gravity_gradient_wzdot<L: Lane>(kz15: L, s: L, c: L, c2: L, s2: L) -> (L, L) {
    (kz15 * (s * c2 - c * s2), -(kz15 + kz15) * (s * s2 + c * c2))
}

/// The planar gravity-gradient angular acceleration (1.5 Kz [S cos 2phi - C sin 2phi]) at the
/// attitude phi from the orbit's forcing (S, C), and its derivative with respect to phi.
#[inline]
pub fn planar_gravity_gradient(kz: f64, s: f64, c: f64, phi: f64) -> (f64, f64) {
    let (s2, c2) = (2.0 * phi).sin_cos();
    gravity_gradient_wzdot(1.5 * kz, s, c, c2, s2)
}

/// The orbit part (first six components) of a state's derivative: the CR3BP, or zero for a
/// body held at its initial position (as at the Lagrange points).
#[inline(always)]
pub(crate) fn orbit_derivative(mu: f64, held: bool, t: f64, y: &[f64], dy: &mut [f64]) {
    if held {
        dy[..6].fill(0.0);
    } else {
        let s: [f64; 6] = std::array::from_fn(|i| y[i]);
        let mut d = [0.0; 6];
        Cr3bp { mu }.derivative(t, &s, &mut d);
        dy[..6].copy_from_slice(&d);
    }
}

/// A precomputed orbit's S(t), C(t).
pub trait Forcing: Sync {
    fn sc(&self, t: f64) -> (f64, f64);
}

/// (phidot, wzdot) and the STM coefficient d(wzdot)/d(phi) from S, C (and the flat-plate SRP).
#[inline(always)]
fn attitude_rhs(kz: f64, s: f64, c: f64, t: f64, phi: f64, wz: f64, srp: &Option<FlatPlate>) -> (f64, f64, f64) {
    let (mut dwz, mut k) = planar_gravity_gradient(kz, s, c, phi);
    if let Some(p) = srp {
        let (v, d) = p.wzdot(t, phi);
        dwz += v;
        k += d;
    }
    (wz - 1.0, dwz, k)
}

/// Planar attitude with the orbit integrated alongside (or held): state (x, y, z, xd, yd, zd,
/// phi, wz) (8), or with the 2x2 STM appended row-major (12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarAlongOrbit {
    pub mu: f64,
    pub kz: f64,
    pub primaries: [bool; 2],
    pub held: bool,
    /// Optional simplified SRP (one flat plate).
    pub srp: Option<FlatPlate>,
}

impl PlanarAlongOrbit {
    #[inline(always)]
    fn orbit_and_attitude(&self, t: f64, y: &[f64], dy: &mut [f64]) -> f64 {
        orbit_derivative(self.mu, self.held, t, y, dy);
        let (s, c) = forcing_sc(self.mu, &y[..3], self.primaries);
        let (dphi, dwz, k) = attitude_rhs(self.kz, s, c, t, y[6], y[7], &self.srp);
        dy[6] = dphi;
        dy[7] = dwz;
        k
    }
}

impl System<[f64; 8]> for PlanarAlongOrbit {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 8], dy: &mut [f64; 8]) {
        self.orbit_and_attitude(t, y, dy);
    }
}

impl System<[f64; 12]> for PlanarAlongOrbit {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 12], dy: &mut [f64; 12]) {
        let k = self.orbit_and_attitude(t, y, dy);
        stm2(k, &y[8..12], &mut dy[8..12]);
    }
}

#[inline(always)]
fn stm2(k: f64, p: &[f64], d: &mut [f64]) {
    // [[0, 1], [k, 0]] * [[p0, p1], [p2, p3]]
    d[0] = p[2];
    d[1] = p[3];
    d[2] = k * p[0];
    d[3] = k * p[1];
}

/// Planar attitude driven by a precomputed forcing: state (phi, wz), or with the STM (6).
pub struct PlanarForced<'a> {
    pub kz: f64,
    pub forcing: &'a dyn Forcing,
    pub srp: Option<FlatPlate>,
}

impl System<[f64; 2]> for PlanarForced<'_> {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        let (s, c) = self.forcing.sc(t);
        let (a, b, _) = attitude_rhs(self.kz, s, c, t, y[0], y[1], &self.srp);
        dy[0] = a;
        dy[1] = b;
    }
}

impl System<[f64; 6]> for PlanarForced<'_> {
    #[inline]
    fn derivative(&self, t: f64, y: &[f64; 6], dy: &mut [f64; 6]) {
        let (s, c) = self.forcing.sc(t);
        let (a, b, k) = attitude_rhs(self.kz, s, c, t, y[0], y[1], &self.srp);
        dy[0] = a;
        dy[1] = b;
        stm2(k, &y[2..6], &mut dy[2..6]);
    }
}
