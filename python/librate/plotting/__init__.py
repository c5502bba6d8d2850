"""Figures of periodic-orbit families and orbits (thesis ch. 2), of periodic attitude motions
(thesis sec. 3.3) and of solar radiation pressure (thesis ch. 4), drawn with matplotlib.

This module is the only part of librate that uses matplotlib, and ``import librate`` does not
import it: import it explicitly, ``import librate.plotting as lp``. matplotlib is a required
dependency (the command line draws its figures by default), installed with librate.
``matplotlib.pyplot`` itself is imported only when a function has to create a figure.

Every ``plot_*`` function takes the data (an :class:`~librate.OrbitFamily`,
:class:`~librate.PeriodicOrbit` objects, a Dataset from :func:`librate.periodicity_map`,
:class:`~librate.AttitudeSolution` objects) and an optional ``ax``: with ``ax=None`` it creates a
new figure (through ``pyplot``, so ``plt.show()`` displays it; close it with ``plt.close(fig)``
when drawing many), otherwise it draws into the given Axes (a sequence of Axes where a
function draws several panels). **Every function returns the matplotlib Figure** it drew
into; it never calls ``plt.show()``. Axes are labelled with units: LU (the primaries'
distance, ``system.lu_km``), TU, days or km. Attitude rates are plotted RELATIVE to the
synodic frame by default, phidot = wz - 1 (the quantity on the thesis figures' axes, which
label it wz(0)); ``rate="inertial"`` plots wz, and the axis label says which. Artists carry a ``gid`` naming what they show
(``"orbit"``, ``"earth"``, ``"resonance-synodic-2"``, ...), so figures can be inspected.

- :func:`plot_family`: a family's orbits in the synodic frame, coloured by Jacobi constant (Fig. 3)
- :func:`plot_period`: period against x0 with synodic and Sun resonances (Fig. 6)
- :func:`plot_stability`: stability indices against x0 with bifurcations (Fig. 5)
- :func:`plot_eci`: orbits in the Earth-centred inertial frame, in km (Figs. 7a, 10, 11)
- :func:`plot_attitude`: an attitude response, rates and Euler angles (Figs. 16-21)
- :func:`plot_residuals`: Dwz and Dphi after one period against the initial rate (Fig. 23)
- :func:`plot_map`: the periodicity map, zero contours and solutions over (orbit, rate) (Fig. 24)
- :func:`plot_solution_families`: solutions of each N across the orbit family, per Kz (Figs. 27-29)
- :func:`plot_solution_scatter`: the solutions of ``librate solve``, phidot0 against x0 by N
- :func:`plot_attitude_motion`: phi(t) and the rate of periodic motions (Figs. 30-31)
- :func:`plot_sun_motion`: the apparent Sun motion in the synodic frame (Fig. 33)
- :func:`plot_sun_resonant`: the Sun-resonant members T = Ts / K of a family (Fig. 34)
- :func:`plot_srp_map`: flat-plate SRP periodicity maps of one orbit over (eps, rate), zero
  contours and solution branches with folds (Figs. 35-36), from the data of
  :func:`librate.periodicity.srp_map` (also importable from here)
- :func:`plot_srp_maps`: several maps side by side, one per Cs, Kz, ... (Figs. 40-41)
- :func:`plot_srp_comparison`: a gravity-only periodic motion and its SRP counterpart (Figs. 37-38)
- :func:`plot_sun_pointing`: gravity-gradient and SRP angular accelerations on a Sun-pointing
  spacecraft (Fig. 39), computed by :func:`librate.periodicity.sun_pointing_accelerations` (also
  importable from here)

- :func:`plot_transition_orbit`: an orbit in the rotating frame in the CR3BP and in the ephemeris model
- :func:`plot_node_defects`: the continuity defects of a multiple-shooting transition, per leg and epoch
- :func:`plot_transition_sweep`: an epoch sweep, departure and perilune range against the epoch
- :func:`plot_ephemeris_attitude`, :func:`plot_pointing_error`: attitude in the ephemeris model
  against the CR3BP motion

This package only draws: the data come from :mod:`librate.periodicity` and the layers below.
- :func:`save_figure`: write a figure to a file

The SRP amplitude of the flat plate is eps = P A d TU^2 / Iz = P (A/m) d TU^2 / k^2 (k the radius
of gyration, Iz = m k^2): with the Earth-Moon TU (375190 s), P = 4.56e-6 N/m^2 and A/m = 0.016
m^2/kg, eps = 1.03e4 d / k^2 (d, k in m). The samples and examples take k = 10 m and a centre of
pressure d = 1 cm from the centre of mass: eps = 1.03. Far from the primaries the gravity gradient
is weak: on the 1:2 Sun-resonant DRO its angular acceleration is below 1 1/TU^2 (7e-12 1/s^2) for
Kz = 0.6, so a CoP offset of 1 m (eps ~ 100) makes SRP dominate by two orders of magnitude, and the
gravity-only solution branches there fold at eps ~ 0.3 - 0.7 (d ~ 3 - 7 mm for k = 10 m).
"""

try:
    import matplotlib  # noqa: F401
except ImportError as exc:  # pragma: no cover - depends on the environment
    raise ImportError("librate.plotting needs matplotlib >= 3.6, a required dependency of librate: reinstall librate") from exc

from ..periodicity.srp_motions import srp_map, sun_pointing_accelerations
from ._attitude3d import plot_body_axes, plot_equilibrium_stability, plot_family_multipliers, plot_map_3d, plot_out_of_plane_stability
from ._ephemeris import plot_ephemeris_attitude, plot_node_defects, plot_pointing_error, plot_transition_orbit, plot_transition_sweep
from ._flexible import plot_flexible_body, plot_flexible_coordinate, plot_flexible_response, plot_frequency_scan
from ._maps import plot_map, plot_residuals
from ._orbits import plot_attitude, plot_eci, plot_family, plot_period, plot_stability
from ._solutions import plot_attitude_motion, plot_solution_families, plot_solution_scatter
from ._srp import plot_srp_comparison, plot_srp_map, plot_srp_maps
from ._style import KIND_MARKERS, N_COLORS, figure_axes, n_color, save_figure
from ._sun import plot_sun_motion, plot_sun_pointing, plot_sun_resonant

__all__ = [
    "plot_family",
    "plot_period",
    "plot_stability",
    "plot_eci",
    "plot_attitude",
    "plot_residuals",
    "plot_map",
    "plot_solution_families",
    "plot_solution_scatter",
    "plot_attitude_motion",
    "plot_sun_motion",
    "plot_sun_resonant",
    "srp_map",
    "plot_srp_map",
    "plot_srp_maps",
    "plot_srp_comparison",
    "sun_pointing_accelerations",
    "plot_sun_pointing",
    "plot_flexible_body",
    "plot_flexible_coordinate",
    "plot_flexible_response",
    "plot_frequency_scan",
    "plot_equilibrium_stability",
    "plot_out_of_plane_stability",
    "plot_family_multipliers",
    "plot_body_axes",
    "plot_map_3d",
    "plot_transition_orbit",
    "plot_node_defects",
    "plot_transition_sweep",
    "plot_ephemeris_attitude",
    "plot_pointing_error",
    "figure_axes",
    "n_color",
    "N_COLORS",
    "KIND_MARKERS",
    "save_figure",
]
