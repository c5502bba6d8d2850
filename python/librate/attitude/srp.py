"""Solar radiation pressure (thesis ch. 4; the models of docs/physics.md, solar radiation pressure).

Two models: the general one (any list of :class:`Facet`, force and torque, lit only when facing
the Sun; no self-shadowing) attached to a body as a :class:`FacetBody`, used by the 3-D model;
and the simplified planar one, a two-sided flat plate with a single amplitude, :class:`FlatPlate`,
used by the planar model, periodic solutions and periodicity maps. The Sun direction turns
clockwise in the synodic frame at omega_sun = -(1 - n_sun); ``Sun.theta0`` is its phase at
t = 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_float_array, as_real
from ..constants import OMEGA_SUN, SOLAR_PRESSURE_1AU
from ..orbits.system import resolve_system
from .body import RigidBody

__all__ = ["Sun", "Facet", "FacetBody", "FlatPlate"]


@dataclass(frozen=True)
class Sun:
    """The apparent Sun, seen from the Earth-Moon synodic frame.

    Parameters
    ----------
    theta0 : float, default 0.0
        The Sun's phase: its angle from the synodic X axis at t = 0 (rad).
    pressure : float, default 4.56e-6
        Solar radiation pressure (N/m^2; 4.56e-6 at 1 AU).

    Raises
    ------
    ValueError
        A non-finite phase, or a negative pressure.

    See Also
    --------
    - [`Sun.at_epoch`][librate.attitude.srp.Sun.at_epoch]: the Sun's phase at a calendar epoch.
    """

    theta0: float = 0.0
    pressure: float = SOLAR_PRESSURE_1AU

    def __post_init__(self):
        object.__setattr__(self, "theta0", as_real(self.theta0, "theta0"))
        object.__setattr__(self, "pressure", as_real(self.pressure, "pressure", nonnegative=True))

    @classmethod
    def at_epoch(cls, epoch, ephemeris=None, pressure: float = SOLAR_PRESSURE_1AU) -> Sun:
        """The Sun at a calendar epoch (an ISO string with its scale, "2030-01-01T00:00:00 TDB" or
        "... UTC", or TDB seconds past J2000): ``theta0`` is the Sun's angle seen from the
        Earth-Moon barycentre in the instantaneous Earth-Moon frame's x-y plane, from x towards y,
        in the ephemeris model (``ephemeris``: a :class:`librate.Ephemeris`; None, the embedded
        DE440 excerpt). A Sun-resonant solution found with this phase holds at that date."""
        from ..ephemeris.model import sun_phase

        return cls(sun_phase(epoch, ephemeris), pressure)

    @property
    def omega(self) -> float:
        """Rate of the Sun direction in the synodic frame, 1/TU (clockwise)."""
        return OMEGA_SUN

    def angle(self, t) -> np.ndarray:
        """The Sun's angle from the synodic X axis at times t (TU), unwrapped (rad)."""
        t = as_float_array(t, "t")
        return _core.sun_angle(float(self.theta0), np.ascontiguousarray(t.ravel())).reshape(t.shape)

    def direction(self, t) -> np.ndarray:
        """Unit vector(s) from the spacecraft to the Sun in synodic components, (3,) or (n, 3)."""
        a = self.angle(t)
        return np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=-1)


@dataclass(frozen=True)
class Facet:
    """A flat surface element of a spacecraft, for solar radiation pressure.

    Parameters
    ----------
    area : float
        Area (m^2, > 0).
    normal : (float, float, float)
        Outward normal in body axes (normalised).
    center : (float, float, float), default (0, 0, 0)
        Centre of pressure (m, from the centre of mass, body axes).
    ca, cs, cd : float
        Fractions of the light absorbed, reflected specularly and reflected diffusely: each in
        [0, 1], summing to one.

    Raises
    ------
    ValueError
        A bad area, a zero normal, or fractions outside [0, 1] or not summing to one.
    """

    area: float
    normal: tuple[float, float, float]
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    ca: float = 1.0
    cs: float = 0.0
    cd: float = 0.0

    def __post_init__(self):
        n = as_float_array(self.normal, "normal").ravel()
        c = as_float_array(self.center, "center").ravel()
        for name, v in (("normal", n), ("center", c)):
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ValueError(f"invalid argument `{name}`: must be 3 finite numbers, got {getattr(self, name)!r}")
        if not np.any(n):
            raise ValueError("invalid argument `normal`: must not be zero")
        object.__setattr__(self, "area", as_real(self.area, "area", positive=True))
        for name in ("ca", "cs", "cd"):
            v = as_real(getattr(self, name), name)
            if not 0 <= v <= 1:
                raise ValueError(f"invalid argument `{name}`: must be in [0, 1], got {v!r}")
            object.__setattr__(self, name, v)
        # validated by the core: area > 0, non-zero normal, coefficients in [0, 1] summing to one
        _core.facets_force_torque([self._tuple(n, c)], [1.0, 0.0, 0.0])
        object.__setattr__(self, "normal", tuple(float(v) for v in n / np.linalg.norm(n)))
        object.__setattr__(self, "center", tuple(float(v) for v in c))

    def _tuple(self, n=None, c=None):
        n = self.normal if n is None else n
        c = self.center if c is None else c
        return (float(self.area), [float(v) for v in n], [float(v) for v in c], float(self.ca), float(self.cs), float(self.cd))


def force_torque(facets, sun_body) -> tuple[np.ndarray, np.ndarray]:
    """SRP force (N) and torque (N m) in body axes on ``facets`` for the Sun direction ``sun_body``
    (unit vector in body axes), at 1 AU."""
    f, t = _core.facets_force_torque([fa._tuple() for fa in facets], [float(v) for v in sun_body])
    return np.array(f), np.array(t)


@dataclass(frozen=True)
class FacetBody(RigidBody):
    """A rigid body with a surface of `Facet` elements, for the 3-D SRP torque and force.

    Parameters
    ----------
    ix, iy, iz : float
        Principal moments of inertia (kg m^2).
    mass_kg : float, optional
        The mass, needed for the SRP force on the orbit (``srp_force=True``).
    facets : tuple of Facet
        The surface.

    See Also
    --------
    - [`FacetBody.flat_plate`][librate.attitude.srp.FacetBody.flat_plate],
      [`FacetBody.two_sided_panel`][librate.attitude.srp.FacetBody.two_sided_panel],
      [`FacetBody.box_with_arrays`][librate.attitude.srp.FacetBody.box_with_arrays]: ready-made surfaces.
    """

    facets: tuple = field(default=())

    def __post_init__(self):
        super().__post_init__()
        if not self.facets or not all(isinstance(f, Facet) for f in self.facets):
            raise ValueError("invalid argument `facets`: must be a non-empty sequence of librate.Facet")
        object.__setattr__(self, "facets", tuple(self.facets))

    def force_torque(self, sun_body):
        """Force (N) and torque (N m) in body axes for a Sun direction in body axes."""
        return force_torque(self.facets, sun_body)

    @classmethod
    def flat_plate(cls, area, *, normal=(1.0, 0.0, 0.0), center=(0.0, 0.0, 0.0), ca=1.0, cs=0.0, cd=0.0, inertia, mass_kg=None):
        """One one-sided plate."""
        return cls(*inertia, mass_kg=mass_kg, facets=(Facet(area, normal, center, ca, cs, cd),))

    @classmethod
    def two_sided_panel(cls, area, *, normal=(1.0, 0.0, 0.0), center=(0.0, 0.0, 0.0), ca=1.0, cs=0.0, cd=0.0, inertia, mass_kg=None):
        """A two-sided panel: two facets with opposite normals at the same centre of pressure."""
        n = np.asarray(normal, dtype=float)
        return cls(*inertia, mass_kg=mass_kg, facets=(Facet(area, tuple(n), center, ca, cs, cd),
                                                      Facet(area, tuple(-n), center, ca, cs, cd)))

    @classmethod
    def box_with_arrays(cls, bus_size=(4.0, 4.0, 6.0), *, array_area=50.0, array_offset=8.0, bus_coefficients=(0.6, 0.2, 0.2),
                        array_coefficients=(0.8, 0.15, 0.05), inertia, mass_kg=None):
        """A box bus (side lengths along x, y, z in m, six facets) with two solar arrays: two-sided
        panels of ``array_area`` each, normal x_B, centres at +-``array_offset`` along y_B."""
        a, b, c = (0.5 * float(v) for v in bus_size)
        facets = []
        for axis, half, area in ((0, a, 4 * b * c), (1, b, 4 * a * c), (2, c, 4 * a * b)):
            for sg in (1.0, -1.0):
                n = [0.0, 0.0, 0.0]
                n[axis] = sg
                ctr = [0.0, 0.0, 0.0]
                ctr[axis] = sg * half
                facets.append(Facet(area, tuple(n), tuple(ctr), *bus_coefficients))
        for sy in (1.0, -1.0):
            for sx in (1.0, -1.0):
                facets.append(Facet(array_area, (sx, 0.0, 0.0), (0.0, sy * array_offset, 0.0), *array_coefficients))
        return cls(*inertia, mass_kg=mass_kg, facets=tuple(facets))


@dataclass(frozen=True)
class FlatPlate:
    """The simplified planar SRP model (docs/physics.md, solar radiation pressure).

    One two-sided flat plate with normal x_B and centre of pressure offset d along y_B; with
    alpha the Sun's angle in body axes,
    wzdot_srp = eps [(1 + Cs) cos(alpha) |cos(alpha)| + (2/3) Cd cos(alpha)],
    eps = P A d TU^2 / Iz (nondimensional; eps = P (A/m) TU^2 d / k^2 = 1.03e4 d / k^2 with d and
    k in metres for A/m = 0.016 m^2/kg and the default TU: the often quoted "about 10 d / k^2 per
    metre" holds with d and k in km).

    Parameters
    ----------
    eps : float
        The plate amplitude (nondimensional, any sign).
    cs, cd : float, default 0.0
        Specular and diffuse reflection fractions, each in [0, 1], cs + cd <= 1 (absorbed: ca =
        1 - cs - cd).
    sun : Sun, default Sun()
        The Sun (phase and pressure).

    Raises
    ------
    ValueError
        A non-finite eps, or fractions out of range.

    See Also
    --------
    - [`FlatPlate.from_geometry`][librate.attitude.srp.FlatPlate.from_geometry]: eps from the plate's area, offset and the body's Iz.

    Examples
    --------
    >>> import librate
    >>> plate = librate.FlatPlate(0.02, cs=0.4)
    >>> round(plate.ca, 6)
    0.6
    """

    eps: float
    cs: float = 0.0
    cd: float = 0.0
    sun: Sun = field(default_factory=Sun)

    def __post_init__(self):
        object.__setattr__(self, "eps", as_real(self.eps, "eps"))
        for name in ("cs", "cd"):
            v = as_real(getattr(self, name), name)
            if not 0 <= v <= 1:
                raise ValueError(f"invalid argument `{name}`: must be in [0, 1], got {v!r}")
            object.__setattr__(self, name, v)
        if self.cs + self.cd > 1 + 1e-12:
            raise ValueError(f"invalid argument `cs`: cs + cd must not exceed one (ca = 1 - cs - cd), got {self.cs + self.cd}")
        if not isinstance(self.sun, Sun):
            raise ValueError("invalid argument `sun`: must be a librate.Sun")

    @property
    def ca(self) -> float:
        return 1.0 - self.cs - self.cd

    @classmethod
    def from_geometry(cls, system, *, area_m2: float, offset_m: float, iz_kgm2: float, cs: float = 0.0, cd: float = 0.0,
                      sun: Sun | None = None):
        """eps = P A d TU^2 / Iz from the plate's area, offset and the body's Iz (SI units)."""
        sun = Sun() if sun is None else sun
        if not isinstance(sun, Sun):
            raise ValueError(f"invalid argument `sun`: must be a librate.Sun, got {sun!r}")
        area_m2 = as_real(area_m2, "area_m2", positive=True)
        iz_kgm2 = as_real(iz_kgm2, "iz_kgm2", positive=True)
        offset_m = as_real(offset_m, "offset_m")
        return cls(sun.pressure * area_m2 * offset_m * resolve_system(system).tu_s**2 / iz_kgm2, cs, cd, sun)

    def with_eps(self, eps: float) -> FlatPlate:
        return FlatPlate(float(eps), self.cs, self.cd, self.sun)

    def wzdot(self, t, phi) -> np.ndarray:
        """The SRP angular acceleration (1/TU^2) at times t and attitudes phi (broadcast), by the
        core's plate law."""
        t, phi = np.broadcast_arrays(as_float_array(t, "t"), as_float_array(phi, "phi"))
        out = _core.flat_plate_wzdot(float(self.eps), float(self.cs), float(self.cd), float(self.sun.theta0),
                                     np.ascontiguousarray(t.ravel()), np.ascontiguousarray(phi.ravel()))
        return out.reshape(t.shape)

    def _plate(self):
        return (float(self.eps), float(self.cs), float(self.cd), float(self.sun.theta0), float(self.sun.omega))
