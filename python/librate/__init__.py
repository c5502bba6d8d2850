"""librate: coupled orbit-attitude dynamics of large spacecraft in the Earth-Moon CR3BP.

The numerics live in the Rust extension ``librate._core``; this package is the documented API.
All quantities are nondimensional (CR3BP units) unless a name says otherwise
(``period_days``, ``distance_km``).
"""

from ._core import __version__
from ._errors import ConvergenceError, IntegrationError, LibrateError
from .attitude import AttitudeTrajectory, RigidBody, propagate_attitude, quaternion_from_euler
from .families import OrbitFamily, correct_dro, dro, dro_family, halo, halo_family, lyapunov, lyapunov_family
from .flexible import Appendage, FlexibleBody, flexible_periodic, frequency_scan, quasi_static
from .fourier import FourierOrbit, fit_fourier
from .frames import MeanElements, OsculatingElements, eci_to_synodic, mean_elements, osculating_elements, synodic_to_eci
from .orbits import PeriodicOrbit, correct_periodic, correct_symmetric
from .periodicity import (
    AttitudeFamily,
    AttitudeSolution,
    SrpContinuation,
    attitude_family,
    continue_srp,
    find_periodic_attitudes,
    periodic_attitude,
    periodicity_map,
)
from .propagation import BatchResult, Event, EventHit, Stats, Trajectory, propagate, propagate_many
from .results import open_result
from .runner import run_map
from .srp import Facet, FacetBody, FlatPlateSRP, SunModel
from .study import Study, StudyError
from .system import System

__all__ = [
    "__version__",
    "LibrateError",
    "IntegrationError",
    "ConvergenceError",
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
    "quaternion_from_euler",
    "AttitudeSolution",
    "periodic_attitude",
    "find_periodic_attitudes",
    "periodicity_map",
    "AttitudeFamily",
    "attitude_family",
    "SunModel",
    "Facet",
    "FacetBody",
    "FlatPlateSRP",
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
