"""The periodicity layer: periodic orbit-attitude solutions, periodicity maps, attitude families,
solar radiation pressure continuation and maps, and the effect of flexibility on periodic
motion."""

from .attitude3d import (
    AttitudeSolution3D,
    attitude_family_3d,
    attitude_family_3d_inertia,
    out_of_plane_family,
    out_of_plane_stability,
    periodic_attitude_3d,
)
from .attitude_families import AttitudeFamily, attitude_family
from .branches import SrpContinuation, continue_srp, periodic_attitude
from .ephemeris_attitude import EphemerisAttitude, attitude_to_ephemeris
from .flexible_periodic import FlexiblePeriodic, FrequencyScan, flexible_periodic, frequency_scan
from .map3d import attitude_map_3d, find_periodic_attitudes_3d
from .maps import periodicity_map, zero_contours
from .solutions import (
    MAP_ATOL,
    MAP_RTOL,
    AttitudeSolution,
    clear_forcing_cache,
    find_periodic_attitudes,
    orbit_forcing,
    sweep,
)
from .srp_motions import srp_map, sun_pointing_accelerations

__all__ = [
    "EphemerisAttitude",
    "attitude_to_ephemeris",
    "AttitudeSolution",
    "AttitudeSolution3D",
    "periodic_attitude_3d",
    "attitude_map_3d",
    "find_periodic_attitudes_3d",
    "out_of_plane_stability",
    "out_of_plane_family",
    "attitude_family_3d",
    "attitude_family_3d_inertia",
    "periodic_attitude",
    "find_periodic_attitudes",
    "orbit_forcing",
    "sweep",
    "clear_forcing_cache",
    "MAP_RTOL",
    "MAP_ATOL",
    "periodicity_map",
    "zero_contours",
    "AttitudeFamily",
    "attitude_family",
    "SrpContinuation",
    "continue_srp",
    "srp_map",
    "sun_pointing_accelerations",
    "FlexiblePeriodic",
    "FrequencyScan",
    "flexible_periodic",
    "frequency_scan",
]
