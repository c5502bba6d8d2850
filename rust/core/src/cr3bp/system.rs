//! Named systems and their dimensional constants.

use crate::error::{check_positive, invalid, Result};

/// A CR3BP system: mass parameter and the units that make it dimensional.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemConstants {
    pub name: String,
    /// m2 / (m1 + m2), in (0, 0.5].
    pub mu: f64,
    /// Length unit: distance between the primaries, km.
    pub lu_km: f64,
    /// Time unit: 1 / mean motion of the primaries, s.
    pub tu_s: f64,
    /// Mean radius of the larger primary, km (collision checks, plots).
    pub r1_km: f64,
    /// Mean radius of the smaller primary, km.
    pub r2_km: f64,
}

/// `(name, mu, LU km, TU s, R1 km, R2 km)` of the presets (docs/physics.md, units and constants). The radii are
/// the IAU mean radii of the Earth (6371.0084 km) and the Moon (1737.4 km).
pub const PRESETS: [(&str, f64, f64, f64, f64, f64); 2] = [
    ("earth-moon", 0.01215, 384400.0, 375190.0, 6371.0084, 1737.4),
    ("earth-moon-jpl", 1.215058560962404e-2, 389703.264829278, 382981.289129055, 6371.0084, 1737.4),
];

/// `Ok` when mu is in (0, 0.5].
pub fn check_mu(mu: f64) -> Result<()> {
    if mu.is_finite() && mu > 0.0 && mu <= 0.5 {
        Ok(())
    } else {
        Err(invalid("mu", format!("must be in (0, 0.5], got {mu}")))
    }
}

impl SystemConstants {
    /// A user-defined system; every constant is validated.
    pub fn new(name: impl Into<String>, mu: f64, lu_km: f64, tu_s: f64, r1_km: f64, r2_km: f64) -> Result<Self> {
        check_mu(mu)?;
        check_positive("lu_km", lu_km)?;
        check_positive("tu_s", tu_s)?;
        if !(r1_km.is_finite() && r1_km >= 0.0) {
            return Err(invalid("r1_km", format!("must be a finite number >= 0, got {r1_km}")));
        }
        if !(r2_km.is_finite() && r2_km >= 0.0) {
            return Err(invalid("r2_km", format!("must be a finite number >= 0, got {r2_km}")));
        }
        Ok(Self { name: name.into(), mu, lu_km, tu_s, r1_km, r2_km })
    }

    /// One of the [`PRESETS`] by name.
    pub fn preset(name: &str) -> Result<Self> {
        PRESETS
            .iter()
            .find(|p| p.0 == name)
            .map(|&(n, mu, lu, tu, r1, r2)| Self { name: n.to_string(), mu, lu_km: lu, tu_s: tu, r1_km: r1, r2_km: r2 })
            .ok_or_else(|| {
                let names: Vec<&str> = PRESETS.iter().map(|p| p.0).collect();
                invalid("name", format!("unknown system preset {name:?}; known presets: {}", names.join(", ")))
            })
    }

    /// Velocity unit, km/s.
    pub fn vu_km_s(&self) -> f64 {
        self.lu_km / self.tu_s
    }

    /// Time unit in days.
    pub fn tu_days(&self) -> f64 {
        self.tu_s / 86400.0
    }

    /// Gravitational parameter of the system (m1 + m2), km^3/s^2, implied by the units.
    pub fn gm_total_km3_s2(&self) -> f64 {
        self.lu_km.powi(3) / (self.tu_s * self.tu_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_and_units() {
        let em = SystemConstants::preset("earth-moon").unwrap();
        // TU = 375190 s = 4.342477 d
        assert!((em.tu_days() - 4.342477).abs() < 1e-6);
        // TU = sqrt(LU^3/GM): GM(Earth+Moon) = 398600.4 + 4902.8 = 403503 km^3/s^2 within 0.1 %
        assert!((em.gm_total_km3_s2() / 403503.2 - 1.0).abs() < 1e-3);
        assert!(SystemConstants::preset("mars").is_err());
        assert!(SystemConstants::new("x", 0.6, 1.0, 1.0, 0.0, 0.0).is_err());
        assert!(SystemConstants::new("x", 0.1, -1.0, 1.0, 0.0, 0.0).is_err());
    }
}
