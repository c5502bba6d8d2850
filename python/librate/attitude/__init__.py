"""The attitude layer: rigid and flexible bodies, solar radiation pressure models and the
propagation of the attitude along a CR3BP orbit."""

from .body import TORQUES, RigidBody, quaternion_from_euler
from .equilibria import AttitudeEquilibrium, attitude_equilibrium, equilibrium_stability
from .flexible import Appendage, FlexibleBody, FlexibleModes, FlexibleResponse, QuasiStaticResponse, quasi_static
from .propagate import AttitudeTrajectory, propagate_attitude
from .srp import Facet, FacetBody, FlatPlate, Sun

__all__ = [
    "RigidBody",
    "quaternion_from_euler",
    "TORQUES",
    "AttitudeTrajectory",
    "propagate_attitude",
    "AttitudeEquilibrium",
    "attitude_equilibrium",
    "equilibrium_stability",
    "Sun",
    "Facet",
    "FacetBody",
    "FlatPlate",
    "Appendage",
    "FlexibleBody",
    "FlexibleModes",
    "FlexibleResponse",
    "QuasiStaticResponse",
    "quasi_static",
]
