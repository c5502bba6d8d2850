"""The orbit layer: the CR3BP system, trajectory propagation, periodic orbits, their
continuation into families, Fourier fits, frame conversions, and their transition to the
Earth-Moon-Sun ephemeris model."""

from .families import OrbitFamily, correct_dro, dro, dro_family, halo, halo_family, lyapunov, lyapunov_family
from .fourier import FourierOrbit, fit_fourier
from .frames import MeanElements, OsculatingElements, eci_to_synodic, mean_elements, osculating_elements, synodic_to_eci
from .orbit_continuation import ContinuationResult, Geometry, continue_arclength, continue_natural, geometry
from .periodic import PeriodicOrbit, correct_periodic, correct_symmetric
from .propagation import BatchResult, Event, EventHit, Stats, Trajectory, propagate, propagate_many
from .system import System
from .transition import EphemerisOrbit, ephemeris_sweep, to_ephemeris

__all__ = [
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
    "Geometry",
    "geometry",
    "ContinuationResult",
    "continue_natural",
    "continue_arclength",
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
    "EphemerisOrbit",
    "to_ephemeris",
    "ephemeris_sweep",
]
