//! Physical constants of the Earth-Moon-Sun problem (docs/physics.md: units, solar radiation pressure), in one place.
//! The binding module exposes them to Python (`librate._core.N_SUN`, ...).

/// Sidereal month, days.
pub const SIDEREAL_MONTH_DAYS: f64 = 27.321661;
/// Sidereal year, days.
pub const SIDEREAL_YEAR_DAYS: f64 = 365.25636;
/// The Sun's mean motion about the Earth-Moon barycentre in units of the Moon's
/// (sidereal month / sidereal year).
pub const N_SUN: f64 = SIDEREAL_MONTH_DAYS / SIDEREAL_YEAR_DAYS;
/// Rate of the apparent Sun direction in the synodic frame (clockwise), 1/TU.
pub const OMEGA_SUN: f64 = -(1.0 - N_SUN);
/// Apparent solar period in the synodic frame, TU: 2 pi / (1 - n_sun).
pub const SUN_SYNODIC_PERIOD: f64 = 2.0 * std::f64::consts::PI / (1.0 - N_SUN);
/// Solar radiation pressure at 1 AU, N/m^2.
pub const SOLAR_PRESSURE_1AU: f64 = 4.56e-6;

#[cfg(test)]
mod tests {
    use super::*;

    /// The values the constants had before they moved here (bit for bit); the Sun's synodic
    /// period times its rate is -2 pi (to 1e-15), and is 29.49 d at TU = 375190 s (to 0.01 d).
    #[test]
    fn values() {
        assert_eq!(N_SUN, 27.321661 / 365.25636);
        assert_eq!(OMEGA_SUN, -(1.0 - 27.321661 / 365.25636));
        assert_eq!(SOLAR_PRESSURE_1AU, 4.56e-6);
        assert!((SUN_SYNODIC_PERIOD * OMEGA_SUN + 2.0 * std::f64::consts::PI).abs() < 1e-15);
        assert!((SUN_SYNODIC_PERIOD * 375190.0 / 86400.0 - 29.49).abs() < 0.01);
    }
}
