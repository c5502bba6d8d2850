"""Rigid bodies and attitude conventions (thesis ch. 3.1; PHYSICS.md sec. 4).

:class:`RigidBody` holds the principal moments of inertia; attitudes are scalar-last quaternions
of the body relative to the synodic frame (:func:`quaternion_from_euler`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _core

__all__ = ["RigidBody", "quaternion_from_euler", "TORQUES", "EULER_SEQUENCES"]

#: Torque model names accepted by ``torques=``.
TORQUES = ("gravity_gradient", "gravity_gradient_earth", "gravity_gradient_moon", "srp")
#: Euler sequence names accepted besides scipy's own ("123" = rotations about x, then y, then z).
EULER_SEQUENCES = {"123": "XYZ", "321": "ZYX", "313": "ZXZ"}


@dataclass(frozen=True)
class RigidBody:
    """Principal moments of inertia about the body axes x, y, z (kg m^2, or normalised: only
    ratios matter for gravity-gradient dynamics). ``mass_kg`` is needed only for the orbital
    coupling term (thesis eq. 37). Validated: positive, triangle inequality."""

    ix: float
    iy: float
    iz: float
    mass_kg: float | None = None

    def __post_init__(self) -> None:
        _core.rigid_body_kz(float(self.ix), float(self.iy), float(self.iz))
        if self.mass_kg is not None and not (math.isfinite(self.mass_kg) and self.mass_kg > 0):
            raise ValueError(f"invalid argument `mass_kg`: must be finite and > 0, got {self.mass_kg!r}")

    @classmethod
    def from_kz(cls, kz: float) -> RigidBody:
        """A planar body with Kz = (Iy - Ix)/Iz in [-1, 1] (Iz = 1, Ix + Iy = 1)."""
        if not (math.isfinite(kz) and -1 <= kz <= 1):
            raise ValueError(f"invalid argument `kz`: must be in [-1, 1], got {kz!r}")
        return cls(0.5 * (1 - kz), 0.5 * (1 + kz), 1.0)

    @property
    def kz(self) -> float:
        """Kz = (Iy - Ix) / Iz."""
        return (self.iy - self.ix) / self.iz

    @property
    def moments(self) -> tuple[float, float, float]:
        return (float(self.ix), float(self.iy), float(self.iz))


def quaternion_from_euler(angles: Sequence[float], sequence: str = "123") -> np.ndarray:
    """Scalar-last quaternion of the body relative to the synodic frame from Euler angles
    (rad) in a named sequence ("123" = rotations about x, then the new y, then the new z, the
    thesis's convention; also "321", "313" or any scipy sequence)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler(EULER_SEQUENCES.get(sequence, sequence), angles).as_quat()


