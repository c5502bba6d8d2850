"""Physical constants of the Earth-Moon-Sun problem (PHYSICS.md section 1)."""

import math

#: Sidereal month and sidereal year, days.
SIDEREAL_MONTH_DAYS = 27.321661
SIDEREAL_YEAR_DAYS = 365.25636
#: Mean motion of the Sun about the Earth-Moon barycentre in units of the Moon's (nondimensional).
N_SUN = SIDEREAL_MONTH_DAYS / SIDEREAL_YEAR_DAYS
#: Rate of the apparent Sun direction in the synodic frame (clockwise).
OMEGA_SUN = -(1.0 - N_SUN)
#: Apparent solar period in the synodic frame, TU (29.49 d with the default TU).
SUN_SYNODIC_PERIOD = 2.0 * math.pi / (1.0 - N_SUN)
#: Solar radiation pressure at 1 AU, N/m^2.
SOLAR_PRESSURE_1AU = 4.56e-6
