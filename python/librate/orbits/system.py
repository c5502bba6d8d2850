"""CR3BP systems: mass parameter, units, Lagrange points, Jacobi constant, conversions."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from .._checks import as_float_array, as_real, as_states
from .._display import html_summary, short_repr

__all__ = ["System"]


def _scaled(value, name: str, factor: float):
    """``value`` (a number: a float; an array: an array) times ``factor``, a ValueError naming
    ``name`` for what is not numbers."""
    a = as_float_array(value, name)
    return a * factor if a.ndim else float(a) * factor


@dataclass(frozen=True)
class System:
    """A circular restricted three-body system in nondimensional units.

    Mass unit m1 + m2, length unit ``lu_km`` (the primaries' distance), time unit ``tu_s``
    (1 / mean motion), so G = 1 and the synodic frame turns at rate 1. The larger primary sits at
    (-mu, 0, 0), the smaller at (1 - mu, 0, 0).

    Parameters
    ----------
    mu : float
        The mass ratio m2 / (m1 + m2), in (0, 0.5].
    lu_km : float
        The length unit (km): the distance between the primaries.
    tu_s : float
        The time unit (s): 1 / mean motion.
    r1_km, r2_km : float, default 0.0
        The primaries' radii (km), for collision checks (0: point masses).
    name : str, default "custom"
        A label (the presets' names).

    Raises
    ------
    ValueError
        A constant out of range, naming it.

    See Also
    --------
    - [`System.preset`][librate.orbits.system.System.preset]: the named systems (``System.presets()`` lists them).

    Examples
    --------
    >>> import librate
    >>> em = librate.System.preset("earth-moon")
    >>> round(em.period_days(2 * 3.141592653589793), 3)   # one synodic revolution
    27.285
    >>> round(em.distance_km(1.0))
    384400
    """

    mu: float
    lu_km: float
    tu_s: float
    r1_km: float = 0.0
    r2_km: float = 0.0
    name: str = "custom"

    def __post_init__(self) -> None:
        # Types here, values by the core; raises ValueError naming the offending constant.
        if not isinstance(self.name, str):
            raise ValueError(f"invalid argument `name`: must be a string, got {self.name!r}")
        nums = [as_real(getattr(self, k), k, allow_inf=True) for k in ("mu", "lu_km", "tu_s", "r1_km", "r2_km")]
        c = _core.system_validate(self.name, *nums)
        for field in ("mu", "lu_km", "tu_s", "r1_km", "r2_km"):
            object.__setattr__(self, field, getattr(c, field))

    # --- display (librate._display) -----------------------------------------------------------
    def _rows(self):
        return [("name", self.name, ""), ("mu", self.mu, ""), ("lu_km", self.lu_km, "km"), ("tu_s", self.tu_s, "s")]

    def __repr__(self) -> str:
        return short_repr("System", self._rows())

    def _repr_html_(self) -> str:
        radii = [("r1_km", self.r1_km, "km"), ("r2_km", self.r2_km, "km"), ("tu_days", self.tu_days, "d"),
                 ("vu_km_s", self.vu_km_s, "km/s")]
        points = [(f"L{i + 1}", p, "LU") for i, p in enumerate(self.lagrange_points())]
        return html_summary(f"librate.System {self.name!r}", self._rows(), {"units and radii": radii, "Lagrange points": points})

    @classmethod
    def preset(cls, name: str = "earth-moon") -> System:
        """A named system: ``"earth-moon"`` (the thesis's, mu = 0.01215) or ``"earth-moon-jpl"``
        (the JPL periodic-orbit catalog's constants)."""
        c = _core.system_preset(name)
        return cls(mu=c.mu, lu_km=c.lu_km, tu_s=c.tu_s, r1_km=c.r1_km, r2_km=c.r2_km, name=c.name)

    @staticmethod
    def presets() -> list[str]:
        """Names accepted by :meth:`preset`."""
        return list(_core.preset_names())

    # --- geometry -------------------------------------------------------------------------
    def primary_positions(self) -> np.ndarray:
        """(2, 3): the larger primary at (-mu, 0, 0), the smaller at (1 - mu, 0, 0)."""
        return np.array([[-self.mu, 0.0, 0.0], [1.0 - self.mu, 0.0, 0.0]])

    def lagrange_points(self) -> np.ndarray:
        """(5, 3) array of L1..L5 (L1 between the primaries, L2 beyond the smaller, L3 beyond the larger)."""
        return _core.lagrange_points(self.mu)

    def jacobi(self, states) -> np.ndarray | float:
        """Jacobi constant C = 2U - |v|^2 of a (6,) state (a float) or of (n, 6) states."""
        arr = as_float_array(states, "states")
        c = _core.jacobi(self.mu, as_states(arr))
        return float(c[0]) if arr.ndim == 1 else c

    # --- units ----------------------------------------------------------------------------
    @property
    def vu_km_s(self) -> float:
        """Velocity unit, km/s."""
        return self.lu_km / self.tu_s

    @property
    def tu_days(self) -> float:
        """Time unit, days."""
        return self.tu_s / 86400.0

    def distance_km(self, length):
        """Nondimensional length(s) to km."""
        return _scaled(length, "length", self.lu_km)

    def speed_km_s(self, speed):
        """Nondimensional speed(s) to km/s."""
        return _scaled(speed, "speed", self.vu_km_s)

    def time_s(self, t):
        """Nondimensional time(s) to seconds."""
        return _scaled(t, "t", self.tu_s)

    def period_days(self, t):
        """Nondimensional time(s) to days."""
        return _scaled(t, "t", self.tu_days)

    def from_km(self, distance_km):
        """km to nondimensional length."""
        return _scaled(distance_km, "distance_km", 1.0 / self.lu_km)

    def from_days(self, days):
        """Days to nondimensional time."""
        return _scaled(days, "days", 1.0 / self.tu_days)

    def to_dimensional(self, states) -> np.ndarray:
        """(…, 6) states to km and km/s."""
        s = np.array(states, dtype=np.float64)
        s[..., :3] *= self.lu_km
        s[..., 3:] *= self.vu_km_s
        return s


def resolve_system(system) -> System:
    """A :class:`System` from a System or a preset name."""
    if isinstance(system, System):
        return system
    if isinstance(system, str):
        if system not in System.presets():
            raise ValueError(f"invalid argument `system`: unknown system preset {system!r}; known presets: {', '.join(System.presets())}")
        return System.preset(system)
    raise ValueError("invalid argument `system`: must be a librate.System or a preset name "
                     f"({', '.join(System.presets())}), got {system!r}")


def check_system(system) -> System:
    """``system`` itself when it is a :class:`System` (no names resolved)."""
    if not isinstance(system, System):
        raise ValueError(f"invalid argument `system`: must be a librate.System, got {type(system).__name__}")
    return system
