"""Rigid bodies and attitude conventions (thesis ch. 3.1; docs/physics.md, attitude).

:class:`RigidBody` holds the principal moments of inertia; attitudes are scalar-last quaternions
of the body relative to the synodic frame (:func:`quaternion_from_euler`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _core
from .._checks import as_float_array

__all__ = ["RigidBody", "quaternion_from_euler", "TORQUES", "EULER_SEQUENCES", "torque_names"]

#: Torque model names accepted by ``torques=``.
TORQUES = ("gravity_gradient", "gravity_gradient_earth", "gravity_gradient_moon", "srp")
#: Euler sequence names accepted besides scipy's own ("123" = rotations about x, then y, then z).
EULER_SEQUENCES = {"123": "XYZ", "321": "ZYX", "313": "ZXZ"}


def torque_names(torques) -> tuple[str, ...]:
    """The torque names of ``torques=``: one name (a string) or a sequence of names from
    :data:`TORQUES`; anything else is a ValueError naming ``torques``."""
    names = (torques,) if isinstance(torques, str) else torques
    try:
        names = tuple(names)
    except TypeError:
        raise ValueError("invalid argument `torques`: must be a torque name or a list of names from "
                         f"{', '.join(TORQUES)}, got {torques!r}") from None
    for n in names:
        if not isinstance(n, str) or n not in TORQUES:
            raise ValueError(f"invalid argument `torques`: unknown torque {n!r}; known: {', '.join(TORQUES)}")
    if len(set(names)) != len(names):
        raise ValueError(f"invalid argument `torques`: a torque is listed twice in {list(names)}")
    return names


@dataclass(frozen=True)
class RigidBody:
    """A rigid body by its principal moments of inertia about the body axes x, y, z.

    Only the ratios matter for gravity-gradient dynamics, so normalised moments are accepted; the
    planar model depends only on Kz. One zero moment is a thin rod along that axis (Ix = 0 and
    Iy = Iz: Kz = 1; Iy = 0 and Ix = Iz: Kz = -1), valid for the planar model; the 3-D models need
    every moment > 0.

    Parameters
    ----------
    ix, iy, iz : float
        Principal moments (kg m^2, or normalised): finite, >= 0, Iz > 0, obeying the triangle
        inequality.
    mass_kg : float, optional
        The mass, needed only for the orbital coupling term (thesis eq. 37, ``orbit="coupled"``).

    Attributes
    ----------
    kz : float
        Kz = (Iy - Ix) / Iz, in [-1, 1].
    moments : (float, float, float)
        (ix, iy, iz).
    is_rod : bool
        One moment is zero.

    Raises
    ------
    ValueError
        A negative, non-finite or zero Iz moment, or moments breaking the triangle inequality.

    Examples
    --------
    >>> import librate
    >>> librate.RigidBody(12.12e6, 89.68e6, 96.95e6).kz
    0.8
    >>> librate.RigidBody.from_kz(0.5).kz
    0.5
    """

    ix: float
    iy: float
    iz: float
    mass_kg: float | None = None

    def __post_init__(self) -> None:
        for name in ("ix", "iy", "iz"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"invalid argument `{name}`: principal moment must be a finite number >= 0, got {v!r}")
            object.__setattr__(self, name, float(v))
        ix, iy, iz = self.ix, self.iy, self.iz
        if min(ix, iy, iz) > 0:
            _core.rigid_body_kz(ix, iy, iz)  # the triangle inequality, in the core
        else:
            if iz <= 0:
                raise ValueError(f"invalid argument `iz`: must be > 0 (Kz = (Iy - Ix) / Iz), got {iz!r}")
            tol = 1e-12 * (ix + iy + iz)
            for name, a, b, c in (("ix", ix, iy, iz), ("iy", iy, ix, iz), ("iz", iz, ix, iy)):
                if a > b + c + tol:
                    raise ValueError(f"invalid argument `{name}`: principal moments violate the triangle inequality: {name} = {a} "
                                     f"exceeds the sum of the other two ({b + c}); a zero moment is a thin rod (the other two equal)")
        m = self.mass_kg
        if m is not None and (isinstance(m, bool) or not isinstance(m, (int, float, np.integer, np.floating))
                              or not (math.isfinite(m) and m > 0)):
            raise ValueError(f"invalid argument `mass_kg`: must be a finite number > 0, got {m!r}")

    @classmethod
    def from_kz(cls, kz: float) -> RigidBody:
        """A planar body with Kz = (Iy - Ix)/Iz in [-1, 1] (Iz = 1, Ix + Iy = 1). The ends are
        thin rods: Kz = 1 gives Ix = 0, Kz = -1 gives Iy = 0 (planar model only)."""
        if isinstance(kz, bool) or not isinstance(kz, (int, float, np.integer, np.floating)) or not (math.isfinite(kz) and -1 <= kz <= 1):
            raise ValueError(f"invalid argument `kz`: must be a number in [-1, 1], got {kz!r}")
        kz = float(kz)
        return cls(0.5 * (1 - kz), 0.5 * (1 + kz), 1.0)

    @property
    def is_rod(self) -> bool:
        """A zero principal moment (Kz = +-1): only the planar model applies."""
        return min(self.ix, self.iy, self.iz) == 0

    @property
    def kz(self) -> float:
        """Kz = (Iy - Ix) / Iz."""
        return (self.iy - self.ix) / self.iz

    @property
    def moments(self) -> tuple[float, float, float]:
        return (float(self.ix), float(self.iy), float(self.iz))


def quaternion_from_euler(angles: Sequence[float], sequence: str = "123") -> np.ndarray:
    """The scalar-last quaternion of the body relative to the synodic frame from Euler angles.

    Parameters
    ----------
    angles : sequence of 3 float
        The angles (rad).
    sequence : str, default "123"
        "123" = rotations about x, then the new y, then the new z (the thesis's convention); also
        "321", "313" or any scipy rotation sequence.

    Returns
    -------
    numpy.ndarray, shape (4,)
        (qx, qy, qz, qw).

    Examples
    --------
    >>> import librate, numpy as np
    >>> np.round(librate.quaternion_from_euler([0.0, 0.0, np.pi / 2]), 6)
    array([0.      , 0.      , 0.707107, 0.707107])
    """
    from scipy.spatial.transform import Rotation

    seq = EULER_SEQUENCES.get(sequence, sequence) if isinstance(sequence, str) else None
    if seq is None or len(seq) != 3 or not (set(seq) <= set("xyz") or set(seq) <= set("XYZ")) or seq[0] == seq[1] or seq[1] == seq[2]:
        raise ValueError("invalid argument `sequence`: must be '123', '321', '313' or three axes (scipy's 'XYZ', 'zxz', "
                         f"...), got {sequence!r}")
    a = as_float_array(angles, "angles")
    if a.shape[-1:] != (3,) or a.ndim > 2 or not np.all(np.isfinite(a)):
        raise ValueError(f"invalid argument `angles`: must be 3 finite angles (rad) or an (n, 3) array of them, got {angles!r}")
    return Rotation.from_euler(seq, a).as_quat()


