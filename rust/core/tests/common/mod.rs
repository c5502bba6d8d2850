//! Helpers shared by the integration tests.
#![allow(dead_code)]

use librate_core::integrate::Options;
use librate_core::orbit::{correct_planar_symmetric, SymmetricOrbit};

/// Earth-Moon mass ratio of the tests (docs/physics.md).
pub const MU: f64 = 0.01215;

/// Members of the Earth-Moon DRO family (mu = 0.01215): (x0, ydot0, period in TU), read off the
/// family continued from the Moon outwards (`librate.dro_family`). The ydot0 values are the
/// corrector's first guesses; the periods identify the family member. (The guess
/// sqrt(mu / d) + d, d = 1 - mu - x0, is near only close to the Moon: from x0 = 0.7 it converges
/// to another symmetric orbit, of period 10.79.)
const DROS: [(f64, f64, f64); 9] = [
    (0.70, 0.693503, 4.858760231),
    (0.75, 0.600385, 4.196250126),
    (0.80, 0.526355, 3.317194172),
    (0.83, 0.494023, 2.713679003),
    (0.85, 0.479069, 2.297421883),
    (0.86, 0.474033, 2.088767230),
    (0.89, 0.471903, 1.474363434),
    (0.90, 0.477014, 1.276920551),
    (0.95, 0.607195, 0.396901429),
];

/// The DRO through x0 in [0.70, 0.95], corrected to 1e-12 at rtol = atol = 1e-13 from the guess
/// interpolated linearly in [`DROS`]; panics unless its period is within 1 % of the family's,
/// likewise interpolated (another orbit's differs by far more: 10.79 against 4.86 at x0 = 0.7).
pub fn dro_orbit(x0: f64) -> SymmetricOrbit {
    let i = DROS.windows(2).position(|w| w[0].0 <= x0 && x0 <= w[1].0).unwrap_or_else(|| panic!("x0 = {x0} outside the DRO table [0.70, 0.95]"));
    let (a, b) = (DROS[i], DROS[i + 1]);
    let u = (x0 - a.0) / (b.0 - a.0);
    let (guess, period) = (a.1 + u * (b.1 - a.1), a.2 + u * (b.2 - a.2));
    let o = correct_planar_symmetric(MU, x0, guess, 1e-12, 30, &Options::with_tolerances(1e-13, 1e-13)).unwrap();
    assert!((o.period - period).abs() < 0.01 * period, "x0 = {x0}: period {} is not the DRO's (about {period})", o.period);
    o
}

/// The DRO through x0: (initial state, period).
pub fn dro(x0: f64) -> ([f64; 6], f64) {
    let o = dro_orbit(x0);
    (o.state0, o.period)
}
