//! Eclipses of the Sun by a spherical body, seen from the spacecraft: the conical shadow with its
//! penumbra, as the fraction of the solar disc left visible (Montenbruck & Gill, Satellite
//! Orbits, sec. 3.4.2, the overlapping discs).
//!
//! With the apparent radii a = asin(R_sun / |d_sun|) of the Sun and b = asin(R_b / |d_b|) of the
//! body, and c the angle between their centres (d_sun, d_b from the spacecraft):
//! - c >= a + b: no eclipse, fraction 1;
//! - c <= b - a: total (umbra), fraction 0;
//! - c <= a - b: annular, fraction 1 - b^2 / a^2;
//! - otherwise partial (penumbra): the discs overlap in the area
//!   A = a^2 acos(x / a) + b^2 acos((c - x) / b) - c y, x = (c^2 + a^2 - b^2) / (2 c),
//!   y = sqrt(a^2 - x^2), and the fraction is 1 - A / (pi a^2).
//!
//! The fraction is continuous; its derivative jumps at the contacts c = a + b and c = |a - b|
//! ([`contacts`]), where an integration of the attitude with solar radiation pressure restarts.

/// Radii (km): the Sun's IAU 2015 nominal radius, the Earth's equatorial radius (IERS 2010), the
/// Moon's mean radius (IAU).
pub const R_SUN_KM: f64 = 695_700.0;
pub const R_EARTH_KM: f64 = 6378.1366;
pub const R_MOON_KM: f64 = 1737.4;
/// The astronomical unit (IAU 2012), km.
pub const AU_KM: f64 = 149_597_870.7;

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// (a, b, c): the apparent radii of the Sun and of the body and the angle between their centres,
/// seen from the spacecraft at `r` (the Sun at `sun`, the body of radius `radius_km` at `body`;
/// any common origin and axes). Inside the body b is pi/2.
pub fn geometry(r: &[f64; 3], sun: &[f64; 3], body: &[f64; 3], radius_km: f64) -> (f64, f64, f64) {
    let ds = [sun[0] - r[0], sun[1] - r[1], sun[2] - r[2]];
    let db = [body[0] - r[0], body[1] - r[1], body[2] - r[2]];
    let (ns, nb) = (norm(&ds), norm(&db));
    let a = (R_SUN_KM / ns).min(1.0).asin();
    let b = (radius_km / nb).min(1.0).asin();
    let cosc = (ds[0] * db[0] + ds[1] * db[1] + ds[2] * db[2]) / (ns * nb);
    (a, b, cosc.clamp(-1.0, 1.0).acos())
}

/// The visible fraction of the solar disc for apparent radii a (Sun), b (body) and centre
/// separation c (rad), by the cases of the module docs.
pub fn visible_fraction(a: f64, b: f64, c: f64) -> f64 {
    if c >= a + b {
        1.0
    } else if c <= b - a {
        0.0
    } else if c <= a - b {
        1.0 - (b * b) / (a * a)
    } else {
        let x = (c * c + a * a - b * b) / (2.0 * c);
        let y = (a * a - x * x).max(0.0).sqrt();
        let area = a * a * (x / a).clamp(-1.0, 1.0).acos() + b * b * ((c - x) / b).clamp(-1.0, 1.0).acos() - c * y;
        (1.0 - area / (std::f64::consts::PI * a * a)).clamp(0.0, 1.0)
    }
}

/// The sunlit fraction at `r` behind one body (see [`geometry`]).
pub fn sunlit_fraction(r: &[f64; 3], sun: &[f64; 3], body: &[f64; 3], radius_km: f64) -> f64 {
    let (a, b, c) = geometry(r, sun, body, radius_km);
    visible_fraction(a, b, c)
}

/// The two contact functions c - (a + b) (outer: penumbra entry) and c - |a - b| (inner: umbra or
/// annular phase), whose zeros are the kinks of the fraction.
pub fn contacts(r: &[f64; 3], sun: &[f64; 3], body: &[f64; 3], radius_km: f64) -> [f64; 2] {
    let (a, b, c) = geometry(r, sun, body, radius_km);
    [c - (a + b), c - (a - b).abs()]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand values: discs apart (1), the body's disc covering the Sun's (0), a small body inside
    /// the Sun's disc (1 - b^2/a^2), and half-overlap of equal discs at c = a: the lens area
    /// 2 a^2 acos(1/2) - a^2 sqrt(3)/2, so the fraction is 1 - (2 pi/3 - sqrt(3)/2)/pi.
    #[test]
    fn fraction_cases() {
        let (a, b) = (0.01, 0.01);
        assert_eq!(visible_fraction(a, b, 0.03), 1.0);
        assert_eq!(visible_fraction(a, 0.02, 0.005), 0.0);
        assert!((visible_fraction(a, 0.005, 0.002) - 0.75).abs() < 1e-15);
        let want = 1.0 - (2.0 * std::f64::consts::PI / 3.0 - 3f64.sqrt() / 2.0) / std::f64::consts::PI;
        assert!((visible_fraction(a, b, a) - want).abs() < 1e-12);
        // continuity at the contacts
        assert!((visible_fraction(a, 0.004, a + 0.004 - 1e-12) - 1.0).abs() < 1e-6);
        assert!((visible_fraction(a, 0.004, a - 0.004 + 1e-12) - (1.0 - 0.16)).abs() < 1e-5);
    }
}
