"""Physical constants of the Earth-Moon-Sun problem (docs/physics.md, units and constants), defined once in the
Rust core (``rust/core/src/constants.rs``) and read from it here."""

from ._core import N_SUN, OMEGA_SUN, SOLAR_PRESSURE_1AU, SUN_SYNODIC_PERIOD

__all__ = ["N_SUN", "OMEGA_SUN", "SUN_SYNODIC_PERIOD", "SOLAR_PRESSURE_1AU"]

#: N_SUN: mean motion of the Sun about the Earth-Moon barycentre in units of the Moon's
#: (sidereal month / sidereal year); OMEGA_SUN = -(1 - N_SUN): rate of the apparent Sun direction
#: in the synodic frame (clockwise); SUN_SYNODIC_PERIOD = 2 pi / (1 - N_SUN): the apparent solar
#: period, TU (29.49 d with the default TU); SOLAR_PRESSURE_1AU: N/m^2.
