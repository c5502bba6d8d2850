//! Solar radiation pressure (thesis ch. 4; our model, docs/physics.md, solar radiation pressure).
//!
//! Sun direction in the synodic frame, from the spacecraft to the Sun (parallax and the 5.1 deg
//! lunar inclination neglected): s(t) = (cos(omega_sun t + theta_s0), sin(omega_sun t + theta_s0),
//! 0), omega_sun = -(1 - n_sun). Facet k (area A_k, outward unit normal n_k and centre of pressure
//! c_k from the centre of mass, in body axes; coefficients Ca + Cs + Cd = 1 for absorbed,
//! specular and diffuse light) is lit when cos t_k = n_k . s > 0 and then feels
//!   F_k = -P A_k cos t_k [ (Ca + Cd) s + 2 (Cs cos t_k + Cd / 3) n_k ],  T = sum_k c_k x F_k.
//! Two-sided panels are two facets. No self-shadowing: a facet is lit whenever it faces the
//! Sun, even if another part of the body stands in the way.
//!
//! Units: areas in m^2, lengths in m, pressure in N/m^2; the torque model returns N m times
//! TU^2, i.e. kg m^2 / TU^2, so the body's inertia must be given in kg m^2 (the gravity
//! gradient is proportional to the inertia and accepts the same units).

use super::dual::Real;
use crate::scalar::Lane;
use super::torque::{cross, mat_vec, Torque, TorqueInput, D13};
use crate::error::{check_finite, invalid, Result};

pub use crate::constants::{N_SUN, OMEGA_SUN, SOLAR_PRESSURE_1AU};
/// Former name of [`SOLAR_PRESSURE_1AU`] (kept for existing callers).
pub use crate::constants::SOLAR_PRESSURE_1AU as P0;

/// The apparent Sun: its initial phase and the pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sun {
    pub theta0: f64,
    pub omega: f64,
    pub pressure: f64,
}

impl Default for Sun {
    fn default() -> Self {
        Self { theta0: 0.0, omega: OMEGA_SUN, pressure: SOLAR_PRESSURE_1AU }
    }
}

impl Sun {
    /// The Sun's angle from the synodic x axis, theta_sun(t) = omega t + theta0: the one place
    /// the Sun's motion is written (direction, plate law, terminators, map lanes).
    #[inline(always)]
    pub fn angle(&self, t: f64) -> f64 {
        self.omega * t + self.theta0
    }

    /// Unit vector to the Sun in synodic components.
    #[inline]
    pub fn direction(&self, t: f64) -> [f64; 3] {
        let (s, c) = self.angle(t).sin_cos();
        [c, s, 0.0]
    }
}

/// One flat surface element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facet {
    pub area: f64,
    pub normal: [f64; 3],
    pub center: [f64; 3],
    pub ca: f64,
    pub cs: f64,
    pub cd: f64,
}

impl Facet {
    /// Validated: area > 0, normal non-zero (normalised here), coefficients in [0, 1] summing
    /// to one (to 1e-9).
    pub fn new(area: f64, normal: [f64; 3], center: [f64; 3], ca: f64, cs: f64, cd: f64) -> Result<Self> {
        if !(area.is_finite() && area > 0.0) {
            return Err(invalid("area", format!("must be finite and > 0 m^2, got {area}")));
        }
        check_finite("normal", &normal)?;
        check_finite("center", &center)?;
        let n = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
        if n == 0.0 {
            return Err(invalid("normal", "must be a non-zero vector"));
        }
        for (name, v) in [("ca", ca), ("cs", cs), ("cd", cd)] {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(invalid(name, format!("must be in [0, 1], got {v}")));
            }
        }
        if (ca + cs + cd - 1.0).abs() > 1e-9 {
            return Err(invalid("ca", format!("the coefficients must sum to one: ca + cs + cd = {}", ca + cs + cd)));
        }
        Ok(Self { area, normal: normal.map(|v| v / n), center, ca, cs, cd })
    }

    /// Force (N) on the facet for the Sun direction `s` in body axes, over any scalar.
    #[inline]
    fn force<R: Real>(&self, s: &[R; 3], pressure: f64) -> [R; 3] {
        let n = self.normal;
        let cos_t = s[0].scale(n[0]) + s[1].scale(n[1]) + s[2].scale(n[2]);
        if cos_t.re() <= 0.0 {
            return [R::cst(0.0); 3];
        }
        let k = cos_t.scale(-pressure * self.area);
        let a = self.ca + self.cd;
        let b = (cos_t.scale(self.cs) + R::cst(self.cd / 3.0)).scale(2.0);
        std::array::from_fn(|i| k * (s[i].scale(a) + b.scale(n[i])))
    }
}

/// A body as a list of facets: SRP force and torque (a [`Torque`] model); the Rust side of
/// the Python `librate.FacetBody`.
#[derive(Debug, Clone, PartialEq)]
pub struct FacetBody {
    pub facets: Vec<Facet>,
    pub sun: Sun,
    /// TU in seconds: torques are returned in kg m^2 / TU^2.
    pub tu_s: f64,
}

impl FacetBody {
    /// Total force (N) and torque (N m) in body axes for the Sun direction `s_body`.
    pub fn force_torque(&self, s_body: &[f64; 3]) -> ([f64; 3], [f64; 3]) {
        self.eval(s_body)
    }

    /// Force and torque over any scalar (the ephemeris model scales them by distance and shadow).
    pub(crate) fn eval<R: Real>(&self, s: &[R; 3]) -> ([R; 3], [R; 3]) {
        let mut f = [R::cst(0.0); 3];
        let mut t = [R::cst(0.0); 3];
        for facet in &self.facets {
            let fk = facet.force(s, self.sun.pressure);
            let c = facet.center.map(R::cst);
            let tk = cross(&c, &fk);
            for i in 0..3 {
                f[i] = f[i] + fk[i];
                t[i] = t[i] + tk[i];
            }
        }
        (f, t)
    }

    fn torque_generic<R: Real>(&self, x: &TorqueInput<R>) -> [R; 3] {
        let s = self.sun.direction(x.t).map(R::cst);
        let sb = mat_vec(&x.a, &s);
        let (_, t) = self.eval(&sb);
        let k = self.tu_s * self.tu_s;
        t.map(|v| v.scale(k))
    }

    /// SRP acceleration on the orbit in synodic components, nondimensional, for a spacecraft
    /// of `mass_kg` in a system with length unit `lu_m` metres.
    pub fn acceleration<R: Real>(&self, t: f64, a: &[[R; 3]; 3], mass_kg: f64, lu_m: f64) -> [R; 3] {
        let s = self.sun.direction(t).map(R::cst);
        let sb = mat_vec(a, &s);
        let (f, _) = self.eval(&sb);
        let k = self.tu_s * self.tu_s / (mass_kg * lu_m);
        // body -> synodic: A' f
        std::array::from_fn(|j| (a[0][j] * f[0] + a[1][j] * f[1] + a[2][j] * f[2]).scale(k))
    }
}

impl Torque for FacetBody {
    fn name(&self) -> &'static str {
        "srp"
    }
    fn torque(&self, x: &TorqueInput<f64>) -> [f64; 3] {
        self.torque_generic(x)
    }
    fn torque_dual(&self, x: &TorqueInput<D13>) -> [D13; 3] {
        self.torque_generic(x)
    }
}

/// The simplified planar SRP model (docs/physics.md, solar radiation pressure): one two-sided flat plate with normal
/// x_B and centre of pressure offset d along y_B; with alpha = theta_sun(t) - phi,
///   wzdot_srp = eps [ (1 + Cs) cos(alpha) |cos(alpha)| + (2/3) Cd cos(alpha) ],
/// eps = P A d TU^2 / Iz (nondimensional).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatPlate {
    pub eps: f64,
    pub cs: f64,
    pub cd: f64,
    pub sun: Sun,
}

impl FlatPlate {
    pub fn new(eps: f64, cs: f64, cd: f64, sun: Sun) -> Result<Self> {
        if !eps.is_finite() {
            return Err(invalid("eps", format!("must be finite, got {eps}")));
        }
        for (name, v) in [("cs", cs), ("cd", cd)] {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(invalid(name, format!("must be in [0, 1], got {v}")));
            }
        }
        if cs + cd > 1.0 + 1e-12 {
            return Err(invalid("cs", format!("cs + cd must not exceed one (ca = 1 - cs - cd), got {}", cs + cd)));
        }
        Ok(Self { eps, cs, cd, sun })
    }

    /// The law's coefficients (a1, a2) = (eps (1 + Cs), eps (2/3) Cd), see [`flat_plate_wzdot`].
    #[inline(always)]
    pub fn coefficients(&self) -> (f64, f64) {
        (self.eps * (1.0 + self.cs), self.eps * (2.0 / 3.0) * self.cd)
    }

    /// alpha = theta_sun(t) - phi, the Sun's angle from the plate normal.
    #[inline(always)]
    pub fn alpha(&self, t: f64, phi: f64) -> f64 {
        self.sun.angle(t) - phi
    }

    /// cos(alpha) = cos(theta_sun(t) - phi): zero where the plate is edge-on to the Sun, where
    /// the law cos(alpha)|cos(alpha)| has its kinks (integrations stop there).
    #[inline]
    pub fn terminator(&self, t: f64, phi: f64) -> f64 {
        self.alpha(t, phi).cos()
    }

    /// wzdot from SRP and its derivative with respect to phi.
    #[inline]
    pub fn wzdot(&self, t: f64, phi: f64) -> (f64, f64) {
        let (a1, a2) = self.coefficients();
        let (sa, ca) = self.alpha(t, phi).sin_cos();
        flat_plate_wzdot(a1, a2, ca, sa)
    }
}

/// The flat-plate law over f64 or SIMD lanes (the scalar model and the map lanes both call
/// this), from the coefficients (a1, a2) of [`FlatPlate::coefficients`] and (cos alpha,
/// sin alpha):
///   wzdot = cos(a) (a1 |cos(a)| + a2),   d wzdot / d phi = sin(a) (2 a1 |cos(a)| + a2)
/// (d cos(alpha) / d phi = sin(alpha), d (x|x|) / dx = 2|x|).
#[inline(always)]
pub fn flat_plate_wzdot<L: Lane>(a1: L, a2: L, ca: L, sa: L) -> (L, L) {
    let aca = ca.abs();
    (ca * a1.mul_add(aca, a2), sa * (a1 + a1).mul_add(aca, a2))
}
