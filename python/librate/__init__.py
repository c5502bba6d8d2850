"""librate: coupled orbit-attitude dynamics of large spacecraft in the Earth-Moon CR3BP.

The numerics live in the Rust extension ``librate._core``; this package is the documented API.
All quantities are nondimensional (CR3BP units) unless a name says otherwise
(``period_days``, ``distance_km``).
"""

import warnings as _warnings

from ._build import build_info
from ._core import __version__
from ._errors import CollisionError, ConvergenceError, IntegrationError, LibrateError
from .attitude import (
    Appendage,
    AttitudeEquilibrium,
    AttitudeTrajectory,
    Facet,
    FacetBody,
    FlatPlate,
    FlexibleBody,
    RigidBody,
    Sun,
    attitude_equilibrium,
    equilibrium_stability,
    propagate_attitude,
    quasi_static,
    quaternion_from_euler,
)
from .ephemeris import Ephemeris, EphemerisBatch, EphemerisTrajectory, propagate_ephemeris, propagate_ephemeris_many
from .orbits import (
    BatchResult,
    EphemerisOrbit,
    Event,
    EventHit,
    FourierOrbit,
    MeanElements,
    OrbitFamily,
    OsculatingElements,
    PeriodicOrbit,
    Stats,
    System,
    Trajectory,
    correct_dro,
    correct_periodic,
    correct_symmetric,
    dro,
    dro_family,
    eci_to_synodic,
    ephemeris_sweep,
    fit_fourier,
    halo,
    halo_family,
    lyapunov,
    lyapunov_family,
    mean_elements,
    osculating_elements,
    propagate,
    propagate_many,
    synodic_to_eci,
    to_ephemeris,
)
from .periodicity import (
    AttitudeFamily,
    AttitudeSolution,
    AttitudeSolution3D,
    EphemerisAttitude,
    SrpContinuation,
    attitude_family,
    attitude_family_3d,
    attitude_family_3d_inertia,
    attitude_map_3d,
    attitude_to_ephemeris,
    continue_srp,
    find_periodic_attitudes,
    find_periodic_attitudes_3d,
    flexible_periodic,
    frequency_scan,
    out_of_plane_stability,
    periodic_attitude,
    periodic_attitude_3d,
    periodicity_map,
    srp_map,
    sun_pointing_accelerations,
    zero_contours,
)

__all__ = [
    "__version__",
    "build_info",
    "srp_map",
    "sun_pointing_accelerations",
    "zero_contours",
    "LibrateError",
    "IntegrationError",
    "CollisionError",
    "ConvergenceError",
    "Ephemeris",
    "EphemerisTrajectory",
    "propagate_ephemeris",
    "EphemerisBatch",
    "propagate_ephemeris_many",
    "EphemerisOrbit",
    "to_ephemeris",
    "ephemeris_sweep",
    "EphemerisAttitude",
    "attitude_to_ephemeris",
    "System",
    "Event",
    "EventHit",
    "Stats",
    "Trajectory",
    "BatchResult",
    "propagate",
    "propagate_many",
    "PeriodicOrbit",
    "correct_dro",
    "correct_symmetric",
    "correct_periodic",
    "RigidBody",
    "AttitudeTrajectory",
    "propagate_attitude",
    "AttitudeEquilibrium",
    "attitude_equilibrium",
    "equilibrium_stability",
    "quaternion_from_euler",
    "AttitudeSolution",
    "periodic_attitude",
    "AttitudeSolution3D",
    "periodic_attitude_3d",
    "attitude_map_3d",
    "find_periodic_attitudes_3d",
    "out_of_plane_stability",
    "attitude_family_3d",
    "attitude_family_3d_inertia",
    "find_periodic_attitudes",
    "periodicity_map",
    "AttitudeFamily",
    "attitude_family",
    "Sun",
    "Facet",
    "FacetBody",
    "FlatPlate",
    "continue_srp",
    "run_map",
    "SrpContinuation",
    "OrbitFamily",
    "dro",
    "dro_family",
    "lyapunov",
    "lyapunov_family",
    "halo",
    "halo_family",
    "FourierOrbit",
    "fit_fourier",
    "synodic_to_eci",
    "eci_to_synodic",
    "OsculatingElements",
    "osculating_elements",
    "MeanElements",
    "mean_elements",
    "Appendage",
    "FlexibleBody",
    "quasi_static",
    "flexible_periodic",
    "frequency_scan",
    "Study",
    "StudyError",
    "open_result",
]

#: Old names kept importable for a while: ``librate.<old>`` warns and returns the new object.
_DEPRECATED = {"FlatPlateSRP": ("FlatPlate", FlatPlate), "SunModel": ("Sun", Sun)}
#: The application layer (pydantic, tqdm; studies, result files, the map runner) is loaded on
#: first use only, so that ``import librate`` stays light: ``librate.Study`` imports it (through
#: ``librate.app``, which loads each name's own module on first use).
_APP = ("Study", "StudyError", "open_result", "run_map")


def __getattr__(name: str):
    if name in _APP:
        import importlib

        obj = getattr(importlib.import_module("librate.app"), name)
        globals()[name] = obj
        return obj
    if name in _DEPRECATED:
        new, obj = _DEPRECATED[name]
        _warnings.warn(f"librate.{name} is deprecated; use librate.{new}", DeprecationWarning, stacklevel=2)
        return obj
    raise AttributeError(f"module 'librate' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
