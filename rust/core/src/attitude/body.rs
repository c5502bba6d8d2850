//! Rigid-body inertia.

use crate::error::{invalid, Result};

/// A rigid body by its principal moments of inertia about the body axes x, y, z (any consistent
/// unit; kg m^2 for dimensional work). Gravity-gradient dynamics depend only on their ratios.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidBody {
    pub ix: f64,
    pub iy: f64,
    pub iz: f64,
}

impl RigidBody {
    /// Validated: moments finite and > 0 and satisfying the triangle inequality
    /// (each no larger than the sum of the other two), as every physical body does.
    pub fn new(ix: f64, iy: f64, iz: f64) -> Result<Self> {
        for (name, v) in [("ix", ix), ("iy", iy), ("iz", iz)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, format!("principal moment must be finite and > 0, got {v}")));
            }
        }
        let tol = 1e-12 * (ix + iy + iz);
        for (name, a, b, c) in [("ix", ix, iy, iz), ("iy", iy, ix, iz), ("iz", iz, ix, iy)] {
            if a > b + c + tol {
                return Err(invalid(
                    name,
                    format!("principal moments violate the triangle inequality: {name} = {a} exceeds the sum of the other two ({})", b + c),
                ));
            }
        }
        Ok(Self { ix, iy, iz })
    }

    /// A planar body with the given Kz = (Iy - Ix)/Iz in [-1, 1] (Iz = 1, Ix + Iy = 1, so the
    /// triangle inequality holds with equality for the out-of-plane moment).
    pub fn from_kz(kz: f64) -> Result<Self> {
        if !(kz.is_finite() && (-1.0..=1.0).contains(&kz)) {
            return Err(invalid("kz", format!("must be in [-1, 1], got {kz}")));
        }
        Self::new(0.5 * (1.0 - kz), 0.5 * (1.0 + kz), 1.0)
    }

    /// Kz = (Iy - Ix) / Iz, the planar inertia parameter (in [-1, 1]).
    pub fn kz(&self) -> f64 {
        (self.iy - self.ix) / self.iz
    }

    pub fn moments(&self) -> [f64; 3] {
        [self.ix, self.iy, self.iz]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_and_kz() {
        // Thesis Table 3 canonical case: Kz = (89.68 - 12.12) / 96.95 = 0.8000.
        let b = RigidBody::new(12.12e6, 89.68e6, 96.95e6).unwrap();
        assert!((b.kz() - 0.8).abs() < 1e-3);
        assert!(RigidBody::new(1.0, 1.0, 3.0).is_err());
        assert!(RigidBody::new(-1.0, 1.0, 1.0).is_err());
        assert_eq!(RigidBody::from_kz(0.8).unwrap().kz(), 0.8);
        assert!(RigidBody::from_kz(1.5).is_err());
    }
}
