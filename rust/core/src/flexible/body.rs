//! The lumped-parameter flexible body: a rigid hub and appendage masses on linear springs.

use nalgebra::Complex;

use crate::attitude::RigidBody;
use crate::error::{invalid, Result};

/// Relative tolerance of the geometric checks: |t_j . b_j| / |b_j| (the direction must be normal
/// to the arm) and |b_j| / max_k |b_k| (the mass must not sit at the centre of mass).
pub const GEOMETRY_TOL: f64 = 1e-9;

/// One appendage mass m_j at b_j (body axes, from the undeformed system's centre of mass),
/// deflecting by q_j along the unit vector t_j normal to b_j, held by a spring k_j and a damper
/// c_j. Units: any mass unit (kg), any length unit (m), time in TU; so `stiffness` is in
/// mass / TU^2 and `damping` in mass / TU (the Python facade converts N/m and N s/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Appendage {
    pub mass: f64,
    pub position: [f64; 2],
    pub direction: [f64; 2],
    pub stiffness: f64,
    pub damping: f64,
}

impl Appendage {
    /// Clamped-hub natural frequency Omega_j = sqrt(k_j / m_j) (rad / TU).
    pub fn frequency(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// Damping ratio zeta_j = c_j / (2 sqrt(k_j m_j)) of the clamped appendage.
    pub fn damping_ratio(&self) -> f64 {
        self.damping / (2.0 * (self.stiffness * self.mass).sqrt())
    }

    /// Signed lever arm a_j = b_j x t_j (= +-|b_j| when t_j is normal to b_j).
    pub fn lever(&self) -> f64 {
        cross(self.position, self.direction)
    }
}

#[inline(always)]
pub(crate) fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

#[inline(always)]
pub(crate) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// A validated planar flexible body with its derived constants.
///
/// The hub is a rigid body of mass m0 with principal moments (Ix0, Iy0, Iz0 = J0) about its own
/// centre, axes along the body axes; its centre sits at h = -sum_j m_j b_j / m0, so that the
/// undeformed system's centre of mass is the origin of the b_j.
#[derive(Debug, Clone, PartialEq)]
pub struct FlexibleBody {
    hub_mass: f64,
    hub: RigidBody,
    appendages: Vec<Appendage>,
    total_mass: f64,
    hub_position: [f64; 2],
    inertia: f64,
    asymmetry: Complex<f64>,
    /// (M I_2 - sum_j m_j t_j t_j^T)^{-1}, the 2x2 core of the Woodbury inverse of M_qq.
    wood: [[f64; 2]; 2],
}

impl FlexibleBody {
    /// Validate and build. Errors name the parameter and the appendage: a non-positive mass or
    /// stiffness, negative damping, a zero direction, a direction not normal to the arm, an
    /// appendage at the centre of mass, non-finite values, an invalid hub.
    pub fn new(hub_mass: f64, hub_inertia: [f64; 3], appendages: &[Appendage]) -> Result<Self> {
        if !(hub_mass.is_finite() && hub_mass > 0.0) {
            return Err(invalid("hub_mass", format!("must be finite and > 0, got {hub_mass}")));
        }
        let hub = RigidBody::new(hub_inertia[0], hub_inertia[1], hub_inertia[2])?;
        let scale = appendages.iter().map(|a| a.position[0].hypot(a.position[1])).filter(|v| v.is_finite()).fold(0.0, f64::max);
        let mut apps = Vec::with_capacity(appendages.len());
        for (j, a) in appendages.iter().enumerate() {
            if !(a.mass.is_finite() && a.mass > 0.0) {
                return Err(invalid("mass", format!("appendage {j}: must be finite and > 0, got {}", a.mass)));
            }
            if !(a.stiffness.is_finite() && a.stiffness > 0.0) {
                return Err(invalid("stiffness", format!("appendage {j}: must be finite and > 0, got {}", a.stiffness)));
            }
            if !(a.damping.is_finite() && a.damping >= 0.0) {
                return Err(invalid("damping", format!("appendage {j}: must be finite and >= 0, got {}", a.damping)));
            }
            if !a.position.iter().all(|v| v.is_finite()) {
                return Err(invalid("position", format!("appendage {j}: must be finite, got {:?}", a.position)));
            }
            if !a.direction.iter().all(|v| v.is_finite()) {
                return Err(invalid("direction", format!("appendage {j}: must be finite, got {:?}", a.direction)));
            }
            let b = a.position[0].hypot(a.position[1]);
            if b <= GEOMETRY_TOL * scale || b == 0.0 {
                return Err(invalid(
                    "position",
                    format!("appendage {j}: the mass sits at the centre of mass (|b| = {b:e}); positions are measured from the undeformed system's centre of mass and must be nonzero"),
                ));
            }
            let tn = a.direction[0].hypot(a.direction[1]);
            if tn == 0.0 {
                return Err(invalid("direction", format!("appendage {j}: must be a nonzero vector, got {:?}", a.direction)));
            }
            let t = [a.direction[0] / tn, a.direction[1] / tn];
            let cosine = dot(t, a.position) / b;
            if cosine.abs() > GEOMETRY_TOL {
                return Err(invalid(
                    "direction",
                    format!("appendage {j}: must be normal to the arm (position {:?}); cos(angle) = {cosine:.3e}", a.position),
                ));
            }
            apps.push(Appendage { direction: t, ..*a });
        }
        let total_mass = hub_mass + apps.iter().map(|a| a.mass).sum::<f64>();
        let first: [f64; 2] = apps.iter().fold([0.0, 0.0], |s, a| [s[0] + a.mass * a.position[0], s[1] + a.mass * a.position[1]]);
        let hub_position = [-first[0] / hub_mass, -first[1] / hub_mass];
        let mut inertia = hub.iz + hub_mass * dot(hub_position, hub_position);
        let h = Complex::new(hub_position[0], hub_position[1]);
        let mut asymmetry = Complex::new(hub.iy - hub.ix, 0.0) + h * h * hub_mass;
        let mut s = [[0.0; 2]; 2];
        for a in &apps {
            let b = Complex::new(a.position[0], a.position[1]);
            inertia += a.mass * dot(a.position, a.position);
            asymmetry += b * b * a.mass;
            for (r, row) in s.iter_mut().enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v += a.mass * a.direction[r] * a.direction[c];
                }
            }
        }
        let m = [[total_mass - s[0][0], -s[0][1]], [-s[1][0], total_mass - s[1][1]]];
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let wood = [[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]];
        Ok(Self { hub_mass, hub, appendages: apps, total_mass, hub_position, inertia, asymmetry, wood })
    }

    pub fn hub_mass(&self) -> f64 {
        self.hub_mass
    }
    /// Hub principal moments about its own centre.
    pub fn hub(&self) -> RigidBody {
        self.hub
    }
    /// The appendages, directions normalised.
    pub fn appendages(&self) -> &[Appendage] {
        &self.appendages
    }
    pub fn n(&self) -> usize {
        self.appendages.len()
    }
    /// M = m0 + sum_j m_j.
    pub fn total_mass(&self) -> f64 {
        self.total_mass
    }
    /// h, the hub centre relative to the undeformed system's centre of mass.
    pub fn hub_position(&self) -> [f64; 2] {
        self.hub_position
    }
    /// I0, the composite moment of inertia about z of the undeformed body about its centre of mass.
    pub fn inertia(&self) -> f64 {
        self.inertia
    }
    /// Z0 = (Qxx - Qyy) + 2 i Qxy of the undeformed body (Q the in-plane second moments of
    /// mass about the centre of mass): |Z0| = Iy - Ix about the composite principal axes,
    /// arg(Z0) / 2 the angle of the principal x axis from the body x axis.
    pub fn asymmetry(&self) -> Complex<f64> {
        self.asymmetry
    }
    /// Kz of the rigid composite body, |Z0| / I0.
    pub fn kz(&self) -> f64 {
        self.asymmetry.norm() / self.inertia
    }
    /// Angle (rad) of the composite principal x axis from the body x axis: the rigid model's
    /// attitude is phi + principal_angle.
    pub fn principal_angle(&self) -> f64 {
        if self.asymmetry.norm() == 0.0 {
            0.0
        } else {
            0.5 * self.asymmetry.arg()
        }
    }

    /// u = M_qq^{-1} x applied through Woodbury: u_j = x_j / m_j + t_j . (W sum_k t_k x_k).
    #[inline(always)]
    pub(crate) fn wood(&self, s: [f64; 2]) -> [f64; 2] {
        let w = &self.wood;
        [w[0][0] * s[0] + w[0][1] * s[1], w[1][0] * s[0] + w[1][1] * s[1]]
    }

    /// The constant mass matrix of the deflections, M_qq(j, k) = m_j d_jk - m_j m_k t_j.t_k / M,
    /// row-major (for linear analyses).
    pub fn mass_matrix(&self) -> Vec<f64> {
        let n = self.n();
        let mut out = vec![0.0; n * n];
        for (j, a) in self.appendages.iter().enumerate() {
            for (k, b) in self.appendages.iter().enumerate() {
                out[j * n + k] = if j == k { a.mass } else { 0.0 } - a.mass * b.mass * dot(a.direction, b.direction) / self.total_mass;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn app(b: [f64; 2], t: [f64; 2]) -> Appendage {
        Appendage { mass: 2.0, position: b, direction: t, stiffness: 3.0, damping: 0.0 }
    }

    #[test]
    fn composite_constants_and_woodbury_inverse() {
        // Two masses 2 at (+-10, 0) deflecting along +-y, one mass 2 at (0, 5) along x, hub 10.
        let apps = [app([10.0, 0.0], [0.0, 1.0]), app([-10.0, 0.0], [0.0, -2.0]), app([0.0, 5.0], [1.0, 0.0])];
        let b = FlexibleBody::new(10.0, [1.0, 2.0, 3.0], &apps).unwrap();
        assert_eq!(b.total_mass(), 16.0);
        assert!((b.hub_position()[1] + 1.0).abs() < 1e-15);
        // I0 = 3 + 10 * 1 + 2 * (100 + 100 + 25)
        assert!((b.inertia() - 463.0).abs() < 1e-12);
        // Z0 = (2 - 1) + 10 (-i)^2 + 2 (100 + 100 - 25) = 1 - 10 + 350
        assert!((b.asymmetry() - Complex::new(341.0, 0.0)).norm() < 1e-12);
        assert_eq!(b.appendages()[1].direction, [0.0, -1.0]);
        // M^{-1} through Woodbury times M = identity.
        let n = b.n();
        let m = b.mass_matrix();
        for col in 0..n {
            let x: Vec<f64> = (0..n).map(|i| m[i * n + col]).collect();
            let s = b.appendages().iter().zip(&x).fold([0.0, 0.0], |s, (a, v)| [s[0] + a.direction[0] * v, s[1] + a.direction[1] * v]);
            let ws = b.wood(s);
            for (i, a) in b.appendages().iter().enumerate() {
                let u = x[i] / a.mass + dot(a.direction, ws);
                assert!((u - if i == col { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn bad_parameters_name_themselves() {
        let ok = app([10.0, 0.0], [0.0, 1.0]);
        let cases: [(Appendage, &str); 6] = [
            (Appendage { mass: 0.0, ..ok }, "mass"),
            (Appendage { stiffness: -1.0, ..ok }, "stiffness"),
            (Appendage { damping: -0.1, ..ok }, "damping"),
            (Appendage { position: [0.0, 0.0], ..ok }, "position"),
            (Appendage { direction: [1.0, 0.1], ..ok }, "direction"),
            (Appendage { direction: [0.0, 0.0], ..ok }, "direction"),
        ];
        for (a, name) in cases {
            let e = FlexibleBody::new(1.0, [1.0, 1.0, 2.0], &[ok, a]).unwrap_err();
            let s = e.to_string();
            assert!(s.contains(&format!("`{name}`")) && s.contains("appendage 1"), "{s}");
        }
        assert!(FlexibleBody::new(0.0, [1.0, 1.0, 2.0], &[ok]).unwrap_err().to_string().contains("hub_mass"));
    }
}
