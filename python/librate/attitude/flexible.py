"""Flexible spacecraft (thesis ch. 5, docs/physics.md, flexible spacecraft): a planar lumped-parameter model.

A rigid hub (mass m0, principal moments (Ix0, Iy0, Iz0) about its centre, axes along the body
axes) carries appendage masses m_j at body positions b_j, each deflecting by q_j along a unit
vector t_j normal to b_j against a spring k_j and a damper c_j >= 0 (clamped natural frequency
Omega_j = sqrt(k_j / m_j), damping ratio zeta_j = c_j / (2 sqrt(k_j m_j))). Every mass feels the
tidal (second-order) field of both primaries about the system's instantaneous centre of mass,
which follows the orbit. The equations, derived with Lagrange's method, are written out in the
Rust core's documentation (``rust/core/src/flexible/mod.rs``): with rho_k the positions relative
to the instantaneous centre of mass,

    I(q) wzdot + gamma(q) . qddot = tau - Idot wz,          phidot = wz - 1,
    gamma_j wzdot + (M_qq qddot)_j = m_j t_j . (T_B rho_j) + m_j wz^2 t_j . rho_j
                                     + 2 wz m_j (cdot x t_j) - k_j q_j - c_j qdot_j,

I(q) the instantaneous moment of inertia, gamma_j = m_j rho_j x t_j, M_qq the (constant) mass
matrix of the deflections including the centre-of-mass shift, T_B the tidal tensor in body axes
and tau the tidal torque on the deformed body.

Units: the API takes SI (kg, m, kg m^2, N/m, N s/m) and converts with the system's time unit;
time and rates stay in TU and 1/TU as everywhere in librate, so deflections are in m and their
rates in m/TU. Positions b_j are measured from the **undeformed system's centre of mass**; the
hub's centre sits where it balances them, h = -sum_j m_j b_j / m0.

- :class:`Appendage`, :class:`FlexibleBody` (presets :meth:`FlexibleBody.sample_station`, TOML
  input and output, free-free modes, the rigid composite body);
- :func:`librate.propagate_attitude` accepts a FlexibleBody (planar model, the deflections in
  ``traj.flex``);
- :func:`quasi_static`: high structural frequencies, the closed form q_j = L_j / k_j along the
  rigid solution (L_j the transverse load) and the first-order attitude perturbation;
- :func:`librate.periodicity.flexible_periodic` (in the periodicity layer): what flexibility does to a periodic orbit-attitude solution
  (drift and first-order shift in closed form; re-solved with the full model at low frequencies);
- :func:`librate.periodicity.frequency_scan`: the coupled response against the structural frequency (resonances).

Two precisions on the model (docs/physics.md, flexible spacecraft). Omega_j = sqrt(k_j / m_j) is the *clamped-hub* frequency:
with the hub free to rotate and the centre of mass free to shift, the structural modes are
stiffer (:meth:`FlexibleBody.modes`, sqrt(k / m_eff) with m_eff < m), and the damping ratio that
sets the decay of the structural energy is the mode's, c / (2 sqrt(k m_eff)), not
c / (2 sqrt(k m)). And with dampers, q_j = L_j / k_j alone is off by a relative 2 zeta_j
rate / Omega_j (the damper's force, first order); the closed form here subtracts that viscous
lag, c_j L_j' / k_j^2, which restores the O((rate / Omega)^2) error for any damping ratio.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import _core
from .._checks import as_state, as_time_span
from ..orbits.propagation import Stats, integration_options
from ..orbits.system import System, resolve_system
from .body import RigidBody, torque_names

__all__ = [
    "Appendage",
    "FlexibleBody",
    "FlexibleModes",
    "FlexibleResponse",
    "QuasiStaticResponse",
    "quasi_static",
]

#: Relative tolerance of the geometric checks (direction normal to the arm, mass off the CM).
GEOMETRY_TOL = 1e-9


def _positive(name: str, value, *, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `{name}`: must be a number, got {value!r}") from None
    ok = math.isfinite(v) and (v >= 0 if allow_zero else v > 0)
    if not ok:
        raise ValueError(f"invalid argument `{name}`: must be finite and {'>= 0' if allow_zero else '> 0'}, got {value!r}")
    return v


def _vector2(name: str, value) -> tuple[float, float]:
    try:
        arr = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `{name}`: must be a 2-vector (x, y) in body axes, got {value!r}") from None
    if arr.shape == (3,):
        if arr[2] != 0.0:
            raise ValueError(f"invalid argument `{name}`: the flexible model is planar, the z component must be 0, got {value!r}")
        arr = arr[:2]
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"invalid argument `{name}`: must be a finite 2-vector (x, y) in body axes, got {value!r}")
    return float(arr[0]), float(arr[1])


@dataclass(frozen=True)
class Appendage:
    """An appendage mass on a spring, in the planar flexible model.

    Parameters
    ----------
    mass : float
        Mass (kg, > 0).
    position : (float, float)
        Position (m) in body axes (x, y), from the undeformed system's centre of mass (not zero).
    direction : (float, float)
        The deflection direction, normal to the position (normalised).
    stiffness : float
        Spring stiffness (N/m, > 0).
    damping : float, default 0.0
        Damping (N s/m, >= 0).
    name : str, default ""
        A label in figures and files.

    Raises
    ------
    ValueError
        A non-positive mass or stiffness, negative damping, a mass at the centre of mass, a zero
        direction or one not normal to the arm.
    """

    mass: float
    position: tuple[float, float]
    direction: tuple[float, float]
    stiffness: float
    damping: float = 0.0
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", _positive("mass", self.mass))
        object.__setattr__(self, "stiffness", _positive("stiffness", self.stiffness))
        object.__setattr__(self, "damping", _positive("damping", self.damping, allow_zero=True))
        b = _vector2("position", self.position)
        t = _vector2("direction", self.direction)
        nb, nt = math.hypot(*b), math.hypot(*t)
        if nb == 0.0:
            raise ValueError("invalid argument `position`: the appendage sits at the centre of mass (position (0, 0)); "
                             "positions are measured from the undeformed system's centre of mass")
        if nt == 0.0:
            raise ValueError(f"invalid argument `direction`: must be a nonzero vector, got {self.direction!r}")
        t = (t[0] / nt, t[1] / nt)
        cosine = (t[0] * b[0] + t[1] * b[1]) / nb
        if abs(cosine) > GEOMETRY_TOL:
            raise ValueError(f"invalid argument `direction`: must be normal to the arm (position {b}); "
                             f"the angle between them is {math.degrees(math.acos(max(-1.0, min(1.0, cosine)))):.6g} deg")
        object.__setattr__(self, "position", b)
        object.__setattr__(self, "direction", t)
        object.__setattr__(self, "name", str(self.name))

    @classmethod
    def from_frequency(cls, mass: float, position, direction, frequency_hz: float, damping_ratio: float = 0.0, name: str = "") -> Appendage:
        """An appendage with the clamped natural frequency ``frequency_hz`` (Hz) and damping ratio
        (k = m (2 pi f)^2, c = 2 zeta sqrt(k m))."""
        m = _positive("mass", mass)
        f = _positive("frequency_hz", frequency_hz)
        z = _positive("damping_ratio", damping_ratio, allow_zero=True)
        k = m * (2 * math.pi * f) * (2 * math.pi * f)
        if not 0 < k < math.inf or not math.isfinite(2 * z * math.sqrt(k * m)):
            raise ValueError(f"invalid arguments `mass`, `frequency_hz`: the stiffness m (2 pi f)^2 = {k:g} must be finite and > 0, "
                             f"got mass = {mass!r}, frequency_hz = {frequency_hz!r}")
        return cls(m, position, direction, k, 2 * z * math.sqrt(k * m), name)

    @property
    def frequency(self) -> float:
        """Clamped natural frequency Omega = sqrt(k / m), rad/s."""
        return math.sqrt(self.stiffness / self.mass)

    @property
    def frequency_hz(self) -> float:
        return self.frequency / (2 * math.pi)

    @property
    def damping_ratio(self) -> float:
        """zeta = c / (2 sqrt(k m))."""
        return self.damping / (2 * math.sqrt(self.stiffness * self.mass))

    @property
    def lever(self) -> float:
        """Signed lever arm b x t (m): +|b| when a positive deflection turns counterclockwise."""
        return self.position[0] * self.direction[1] - self.position[1] * self.direction[0]

    def to_dict(self) -> dict:
        return {"name": self.name, "mass": self.mass, "position": list(self.position), "direction": list(self.direction),
                "stiffness": self.stiffness, "damping": self.damping}


@dataclass(frozen=True)
class FlexibleModes:
    """Free-free modes of a flexible body (hub free to rotate, no external field), from the
    linearisation about the undeformed body: ``frequency`` (rad/s), ``frequency_hz``,
    ``damping_ratio`` (from the damped eigenvalues, zeta = -Re(lambda) / |lambda|), ``shapes``
    (n, n) mass-normalised undamped mode shapes (columns, deflections q), and ``mass`` (n, n), the
    effective mass matrix M_qq - gamma0 gamma0^T / I0 of the deflections."""

    frequency: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray
    mass: np.ndarray

    @property
    def frequency_hz(self) -> np.ndarray:
        return self.frequency / (2 * math.pi)


def _hub(hub) -> RigidBody:
    if isinstance(hub, RigidBody):
        if hub.mass_kg is None:
            raise ValueError("invalid argument `hub`: the hub needs its mass: RigidBody(ix, iy, iz, mass_kg=...)")
        return hub
    try:
        m, j0 = hub
    except (TypeError, ValueError):
        raise ValueError("invalid argument `hub`: must be a librate.RigidBody with mass_kg, or a pair "
                         f"(mass_kg, J0), got {hub!r}") from None
    j0 = _positive("hub", j0)
    return RigidBody(0.5 * j0, 0.5 * j0, j0, mass_kg=_positive("hub", m))


@dataclass(frozen=True)
class FlexibleBody:
    """A planar flexible spacecraft: a rigid hub with spring-mass appendages.

    Parameters
    ----------
    hub : RigidBody or (float, float)
        A `RigidBody` with ``mass_kg`` (its principal moments about its own centre, kg m^2, axes
        along the body axes), or a pair ``(mass_kg, J0)`` for a hub with inertia J0 about z only.
    appendages : sequence of Appendage
        Positions from the undeformed system's centre of mass.
    name : str, default "custom"
        A label.

    Attributes
    ----------
    total_mass : float
        kg.
    hub_position : numpy.ndarray
        The hub centre (m).
    inertia : float
        The composite moment about z (kg m^2).
    kz, principal_angle : float
        Of the rigid composite body (`FlexibleBody.rigid_body`).

    Raises
    ------
    ValueError
        A bad hub or appendage.
    """

    hub: RigidBody
    appendages: tuple[Appendage, ...]
    name: str = "custom"
    _derived: _core.FlexibleBodyConstants = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "hub", _hub(self.hub))
        try:
            apps = tuple(self.appendages)
        except TypeError:
            raise ValueError(f"invalid argument `appendages`: must be a sequence of librate.Appendage, got {self.appendages!r}") from None
        for j, a in enumerate(apps):
            if not isinstance(a, Appendage):
                raise ValueError(f"invalid argument `appendages`: item {j} must be a librate.Appendage, got {a!r}")
        object.__setattr__(self, "appendages", apps)
        object.__setattr__(self, "name", str(self.name))
        object.__setattr__(self, "_derived", _core.flexible_body_check(self._core_arg(1.0)))

    # --- conversion ---------------------------------------------------------------------------
    def _core_arg(self, tu_s: float):
        """(hub_mass, [ix, iy, iz], [(m, b, t, k TU^2, c TU), ...]) for the Rust core."""
        apps = [(a.mass, list(a.position), list(a.direction), a.stiffness * tu_s * tu_s, a.damping * tu_s) for a in self.appendages]
        return (float(self.hub.mass_kg), list(self.hub.moments), apps)

    def _core_model(self, system, primaries, held: bool = False) -> _core.FlexibleModel:
        """The core's model of this body in ``system`` with the enabled ``primaries``, the orbit
        held or integrated."""
        return _core.FlexibleModel(system.mu, self._core_arg(system.tu_s), primaries=[bool(p) for p in primaries], held=bool(held))

    # --- derived quantities ------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of appendages (flexible coordinates)."""
        return len(self.appendages)

    @property
    def total_mass(self) -> float:
        return self._derived.total_mass

    @property
    def hub_position(self) -> tuple[float, float]:
        """Hub centre relative to the undeformed system's centre of mass (m)."""
        x, y = self._derived.hub_position
        return (x, y)

    @property
    def inertia(self) -> float:
        """I0: the composite moment of inertia about z of the undeformed body (kg m^2)."""
        return self._derived.inertia

    @property
    def kz(self) -> float:
        """Kz = (Iy - Ix) / Iz of the rigid composite body (principal axes)."""
        return self._derived.kz

    @property
    def principal_angle(self) -> float:
        """Angle (rad) of the composite principal x axis from the body x axis: the rigid
        composite model's phi is the flexible model's phi plus this angle."""
        return self._derived.principal_angle

    @property
    def mass_matrix(self) -> np.ndarray:
        """(n, n) mass matrix of the deflections, M_qq = diag(m) - m_j m_k t_j . t_k / M (kg)."""
        return self._derived.mass_matrix.copy()

    @property
    def frequencies(self) -> np.ndarray:
        """(n,) clamped natural frequencies Omega_j = sqrt(k_j / m_j), rad/s."""
        return np.array([a.frequency for a in self.appendages])

    def frequencies_nd(self, system: System | str) -> np.ndarray:
        """(n,) clamped natural frequencies in rad/TU of ``system``."""
        return self.frequencies * resolve_system(system).tu_s

    def rigid_body(self) -> RigidBody:
        """The rigid composite body (undeformed): principal moments (kg m^2) and mass; its x axis
        is at :attr:`principal_angle` from the body x axis."""
        delta = abs(self._derived.asymmetry)
        s = self.hub.ix + self.hub.iy + (self.inertia - self.hub.iz)
        return RigidBody(0.5 * (s - delta), 0.5 * (s + delta), self.inertia, mass_kg=self.total_mass)

    def modes(self) -> FlexibleModes:
        """Free-free modes (hub free to rotate, no external field): frequencies (rad/s) and damping
        ratios from the linearised equations [M_qq - gamma0 gamma0^T / I0] qdd + C qd + K q = 0
        (the rotation eliminated through the angular momentum), gamma0_j = m_j (b_j x t_j). They
        are stiffer than the clamped Omega_j: the hub recoils."""
        from scipy.linalg import eigh

        g = np.array([a.mass * a.lever for a in self.appendages])
        meff = self.mass_matrix - np.outer(g, g) / self.inertia
        k = np.diag([a.stiffness for a in self.appendages])
        c = np.diag([a.damping for a in self.appendages])
        w2, shapes = eigh(k, meff)
        n = self.n
        minv = np.linalg.inv(meff)
        a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
        lam = np.linalg.eigvals(a)
        osc = sorted((z for z in lam if z.imag > 0), key=abs)
        real = sorted(z.real for z in lam if z.imag == 0)
        freq, zeta = [abs(z) for z in osc], [-z.real / abs(z) for z in osc]
        for i in range(0, len(real) - 1, 2):  # overdamped pairs
            w = math.sqrt(real[i] * real[i + 1])
            freq.append(w)
            zeta.append(-(real[i] + real[i + 1]) / (2 * w))
        order = np.argsort(freq)
        return FlexibleModes(np.sqrt(w2), np.asarray(zeta)[order], shapes, meff)

    def scaled(self, frequency_factor: float, name: str | None = None) -> FlexibleBody:
        """The same body with every clamped frequency multiplied by ``frequency_factor`` (stiffness
        by its square, damping by it: the damping ratios are kept)."""
        f = _positive("frequency_factor", frequency_factor)
        if not all(0 < a.stiffness * f * f < math.inf for a in self.appendages):
            raise ValueError(f"invalid argument `frequency_factor`: the scaled stiffnesses (times {f:g}**2) must stay finite and > 0, "
                             f"got {frequency_factor!r}")
        apps = [replace(a, stiffness=a.stiffness * f * f, damping=a.damping * f) for a in self.appendages]
        return FlexibleBody(self.hub, apps, name if name is not None else f"{self.name} x{f:g}")

    # --- presets -------------------------------------------------------------------------------
    @classmethod
    def sample_station(cls, low_frequency: bool = False) -> FlexibleBody:
        """A real-scale station (ISS-like numbers), thesis Table 5's role; planar, the 109 m truss
        along the body x axis, the pressurised modules along y, in the orbit plane.

        - total mass 420 t (ISS: about 420 t);
        - hub 371.28 t: the integrated truss (about 90 t over 109 m, (1/12) m L^2 = 7.5e7 kg m^2)
          and the pressurised core; principal moments (6.36e6, 75.09471e6, 76.60471e6) kg m^2 about its
          centre;
        - four solar-array assemblies of 2180 kg (two 35 m x 12 m wings of about 1090 kg each, as
          on the ISS photovoltaic modules) at x = +-33 m and +-47.5 m along the truss, bending in
          the plane normal to it (along +-y), first bending mode 0.10 Hz (the ISS wings' first modes
          are 0.05-0.1 Hz), damping ratio 0.5 %;
        - two module clusters of 20 t (a laboratory and a habitation stack, each about one and a
          half ISS modules) at y = +-12 m, bending along x, first mode 0.50 Hz, damping ratio 0.5 %.

        The rigid composite body is the thesis's canonical case (Table 3): Ix = 12.12e6,
        Iy = 89.68e6, Iz = 96.95e6 kg m^2, Kz = 0.800. With the Earth-Moon TU (375190 s) the
        structural frequencies are 2.4e5 and 1.2e6 rad/TU, five orders of magnitude above the
        orbital and attitude rates: the quasi-static regime (:func:`quasi_static`).

        ``low_frequency=True``: the same structure with every frequency lowered by the factor
        34560, which puts the arrays' first mode at a 4-day period (1.82e-5 rad/s, 6.82 rad/TU)
        and the modules' at 0.8 days, within a decade of the orbital and attitude rates (thesis
        Figs. 45-46: "lowered frequencies"); the damping ratios are kept.
        """
        zeta = 0.005
        arrays = [
            ("array P4 (inboard port)", (-33.0, 0.0), (0.0, -1.0)),
            ("array S4 (inboard starboard)", (33.0, 0.0), (0.0, 1.0)),
            ("array P6 (outboard port)", (-47.5, 0.0), (0.0, -1.0)),
            ("array S6 (outboard starboard)", (47.5, 0.0), (0.0, 1.0)),
        ]
        apps = [Appendage.from_frequency(2180.0, b, t, 0.10, zeta, name) for name, b, t in arrays]
        apps += [
            Appendage.from_frequency(20000.0, (0.0, 12.0), (-1.0, 0.0), 0.50, zeta, "laboratory modules"),
            Appendage.from_frequency(20000.0, (0.0, -12.0), (1.0, 0.0), 0.50, zeta, "habitation modules"),
        ]
        body = cls(RigidBody(6.36e6, 75.09471e6, 76.60471e6, mass_kg=371280.0), apps, "sample-station")
        if low_frequency:
            return body.scaled(1.0 / LOW_FREQUENCY_FACTOR, "sample-station-low-frequency")
        return body

    @classmethod
    def preset(cls, name: str) -> FlexibleBody:
        """A named preset: ``"sample-station"`` or ``"sample-station-low-frequency"``."""
        if name == "sample-station":
            return cls.sample_station()
        if name == "sample-station-low-frequency":
            return cls.sample_station(low_frequency=True)
        raise ValueError(f"invalid argument `name`: unknown flexible-body preset {name!r}; known: {', '.join(FLEXIBLE_PRESETS)}")

    # --- files ---------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """Plain data (SI units): name, hub (mass, inertia), appendages."""
        return {"name": self.name, "hub": {"mass": float(self.hub.mass_kg), "inertia": list(self.hub.moments)},
                "appendages": [a.to_dict() for a in self.appendages]}

    @classmethod
    def from_dict(cls, data: dict) -> FlexibleBody:
        """From :meth:`to_dict`'s layout, or ``{"preset": name}`` (optionally with
        ``low_frequency``). Appendages may give ``frequency_hz`` (and ``damping_ratio``) instead of
        ``stiffness`` (and ``damping``)."""
        if not isinstance(data, dict):
            raise ValueError(f"invalid argument `data`: must be a dict, got {type(data).__name__}")
        if "preset" in data:
            name = str(data["preset"]).replace("_", "-")
            if data.get("low_frequency", False) and not name.endswith("low-frequency"):
                name += "-low-frequency"
            return cls.preset(name)
        try:
            hub = data["hub"]
            inertia = hub["inertia"]
            hub_body = RigidBody(*map(float, inertia), mass_kg=float(hub["mass"])) if np.ndim(inertia) else (hub["mass"], inertia)
            apps = []
            for j, a in enumerate(data.get("appendages", [])):
                kw = {"name": a.get("name", "")}
                if "stiffness" in a:
                    apps.append(Appendage(a["mass"], a["position"], a["direction"], a["stiffness"], a.get("damping", 0.0), **kw))
                elif "frequency_hz" in a:
                    apps.append(Appendage.from_frequency(a["mass"], a["position"], a["direction"], a["frequency_hz"],
                                                         a.get("damping_ratio", 0.0), **kw))
                else:
                    raise ValueError(f"invalid argument `appendages`: appendage {j} needs `stiffness` (N/m) or `frequency_hz`")
        except (KeyError, TypeError) as exc:
            raise ValueError("invalid argument `data`: a flexible body needs hub.mass, hub.inertia and appendages with mass, "
                             f"position, direction ({exc!r})") from None
        return cls(hub_body, apps, data.get("name", "custom"))

    def to_toml(self, path=None) -> str:
        """The body as TOML (SI units); written to ``path`` when given. Read back with
        :meth:`from_toml`."""
        def num(v):
            return repr(float(v))

        lines = [f"name = {json.dumps(self.name)}", "", "[hub]", f"mass = {num(self.hub.mass_kg)}  # kg",
                 f"inertia = [{', '.join(num(v) for v in self.hub.moments)}]  # kg m^2, principal, about the hub centre"]
        for a in self.appendages:
            lines += ["", "[[appendages]]", f"name = {json.dumps(a.name)}", f"mass = {num(a.mass)}  # kg",
                      f"position = [{num(a.position[0])}, {num(a.position[1])}]  # m, from the undeformed centre of mass",
                      f"direction = [{num(a.direction[0])}, {num(a.direction[1])}]",
                      f"stiffness = {num(a.stiffness)}  # N/m ({a.frequency_hz:.6g} Hz)",
                      f"damping = {num(a.damping)}  # N s/m (damping ratio {a.damping_ratio:.6g})"]
        text = "\n".join(lines) + "\n"
        if path is not None:
            Path(path).write_text(text)
        return text

    @classmethod
    def from_toml(cls, source) -> FlexibleBody:
        """From a TOML file path or TOML text: :meth:`to_toml`'s layout, or ``preset =
        "sample-station"`` (with ``low_frequency = true`` for the low-frequency variant)."""
        try:
            import tomllib
        except ImportError:  # Python 3.10
            try:
                import tomli as tomllib  # type: ignore[no-redef]
            except ImportError:
                raise ImportError("reading TOML on Python 3.10 needs tomli: pip install tomli") from None
        text = source
        if isinstance(source, Path) or (isinstance(source, str) and "\n" not in source and "=" not in source):
            text = Path(source).read_text()
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"invalid argument `source`: not valid TOML ({exc})") from None
        return cls.from_dict(data)


#: Factor by which :meth:`FlexibleBody.sample_station` (``low_frequency=True``) lowers every frequency.
LOW_FREQUENCY_FACTOR = 34560.0
#: Names accepted by :meth:`FlexibleBody.preset`.
FLEXIBLE_PRESETS = ("sample-station", "sample-station-low-frequency")


# --- propagation -------------------------------------------------------------------------------
@dataclass(frozen=True)
class FlexibleResponse:
    """The flexible coordinates of a :func:`librate.propagate_attitude` run with a
    :class:`FlexibleBody` (``traj.flex``): ``q`` (n_t, n) deflections (m) and ``qdot`` (n_t, n)
    their rates (m/TU), with the run's system, body, enabled primaries and the trajectory's t,
    orbit, phi, wz."""

    system: System
    body: FlexibleBody
    primaries: tuple[bool, bool]
    t: np.ndarray
    orbit: np.ndarray
    phi: np.ndarray
    wz: np.ndarray
    q: np.ndarray
    qdot: np.ndarray

    def energies(self) -> dict[str, np.ndarray]:
        """Per output time, in SI: ``kinetic`` (J, motion about the centre of mass, inertial
        rates), ``elastic`` (J), ``tidal`` (J, the second-order gravity potential of the enabled
        primaries), ``momentum`` (kg m^2/s, inertial, about the centre of mass), ``structural``
        (J: kinetic + elastic - momentum^2 / (2 I), the energy above rigid rotation with the same
        momentum), ``torque`` (N m, tidal torque on the deformed body), ``inertia`` (kg m^2,
        I(q))."""
        e = _core.flexible_energies(self.body._core_model(self.system, self.primaries),
                                    np.ascontiguousarray(self.orbit), np.ascontiguousarray(self.phi), np.ascontiguousarray(self.wz),
                                    np.ascontiguousarray(self.q), np.ascontiguousarray(self.qdot))
        tu = self.system.tu_s
        return {"kinetic": e.kinetic / tu**2, "elastic": e.elastic / tu**2, "tidal": e.tidal / tu**2, "momentum": e.momentum / tu,
                "structural": e.structural / tu**2, "torque": e.torque / tu**2, "inertia": e.inertia}

    def jacobi_energy(self, mean_motion: float) -> np.ndarray:
        """E_J = T + V_el + V_tidal - n h_z (J) for a circular orbit of inertial mean motion
        ``mean_motion`` (rad/TU) about one primary (the other off): constant without damping."""
        e = self.energies()
        return e["kinetic"] + e["elastic"] + e["tidal"] - mean_motion / self.system.tu_s * e["momentum"]


def enabled_primaries(names: Sequence[str]) -> list[bool]:
    return [any(n in ("gravity_gradient", "gravity_gradient_earth") for n in names),
            any(n in ("gravity_gradient", "gravity_gradient_moon") for n in names)]


def flexible_attitude(attitude) -> tuple[float, float]:
    try:
        phi0, wz0 = (float(v) for v in attitude)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `attitude`: flexible runs are planar and take (phi0, wz0), got {attitude!r}") from None
    if not (math.isfinite(phi0) and math.isfinite(wz0)):
        raise ValueError(f"invalid argument `attitude`: (phi0, wz0) must be finite, got {attitude!r}")
    return phi0, wz0


def initial_deflection(deflection, sys_, body, primaries, held, s, phi0, wz0):
    n = body.n
    if deflection is None or (isinstance(deflection, str) and deflection == "rest"):
        return [0.0] * n, [0.0] * n
    if isinstance(deflection, str):
        if deflection != "quasi-static":
            raise ValueError(f"invalid argument `deflection`: must be None/'rest', 'quasi-static' or (q0, qdot0), got {deflection!r}")
        p = _core.flexible_quasi_static_point(body._core_model(sys_, primaries, held), [float(v) for v in s], phi0, wz0)
        return p.q, p.qdot
    try:
        q0, qd0 = deflection
        q0 = np.asarray(q0, dtype=np.float64).ravel()
        qd0 = np.asarray(qd0, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `deflection`: must be None/'rest', 'quasi-static' or (q0, qdot0), got {deflection!r}") from None
    if q0.shape != (n,) or qd0.shape != (n,) or not (np.all(np.isfinite(q0)) and np.all(np.isfinite(qd0))):
        raise ValueError(f"invalid argument `deflection`: q0 (m) and qdot0 (m/TU) need {n} finite values each, got shapes "
                         f"{q0.shape}, {qd0.shape}")
    return q0.tolist(), qd0.tolist()


def flexible_run_inputs(system, orbit_state, body, t_span, torques, orbit):
    sys_ = resolve_system(system)
    s = as_state(orbit_state, "orbit_state")
    t0, tf = as_time_span(t_span)
    if not isinstance(body, FlexibleBody):
        raise ValueError(f"invalid argument `body`: must be a librate.FlexibleBody, got {type(body).__name__}")
    names = torque_names(torques)
    if orbit not in ("integrate", "held"):
        raise ValueError(f"invalid argument `orbit`: must be 'integrate' or 'held', got {orbit!r}")
    return sys_, s, t0, tf, names


# --- high frequencies: the closed form ---------------------------------------------------------
@dataclass(frozen=True)
class QuasiStaticResponse:
    """Result of :func:`quasi_static`. ``phi``, ``wz`` (n_t,): the rigid composite solution (phi of
    the body x axis); ``q``, ``qdot``, ``qddot`` (n_t, n): the closed-form deflections q_j = L_j / k_j
    along it (with the damper's lag) and their derivatives (m, m/TU, m/TU^2); ``dtau`` (n_t,): the first-order torque
    perturbation (N m); ``dphi``, ``dwz``: the first-order attitude perturbation (rad, rad/TU),
    so the flexible model's attitude is ``phi + dphi``, ``wz + dwz`` to O((rate / Omega)^4)."""

    system: System
    body: FlexibleBody
    t: np.ndarray
    orbit: np.ndarray
    phi: np.ndarray
    wz: np.ndarray
    dphi: np.ndarray
    dwz: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    dtau: np.ndarray
    stats: Stats

    @property
    def load(self) -> np.ndarray:
        """(n_t, n) transverse loads L_j = k_j q_j on the appendages (N)."""
        return self.q * np.array([a.stiffness for a in self.body.appendages])


def quasi_static(
    system: System | str,
    orbit_state,
    attitude,
    body: FlexibleBody,
    t_span,
    *,
    torques: Sequence[str] = ("gravity_gradient",),
    orbit: str = "integrate",
    t_eval=None,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    max_steps: int = 1_000_000,
) -> QuasiStaticResponse:
    """The quasi-static response of a stiff flexible body along its rigid solution (high structural
    frequencies).

    The rigid composite body (the flexible body frozen undeformed) is propagated from
    ``attitude``. Along it the transverse load on m_j is L_j = m_j [t_j . T_B b_j - wzdot (b_j x
    t_j)] (tidal + Euler) and the deflection q_j = L_j / k_j, less the damper's lag, with its
    derivatives in closed form. Fed back into the attitude equation, it gives the torque
    perturbation and the attitude perturbation (dphi, dwz) from the rigid variational equation
    (Duhamel's integral). Valid when every Omega_j is much larger than the orbital and attitude
    rates: the full model differs by a relative O((rate / Omega)^2).

    Parameters
    ----------
    system : System or str
        The system.
    orbit_state : array_like, shape (6,)
        The initial orbit state.
    attitude : (float, float)
        (phi0, wz0): the angle of the body x axis (rad) and the inertial rate (1/TU).
    body : FlexibleBody
        The body.
    t_span : float or (float, float)
        Final time, or (t0, tf), in TU.
    torques : sequence of str, default ("gravity_gradient",)
        Torque names.
    orbit : {"integrate", "held"}
        As in `propagate_attitude`.
    t_eval : array_like, optional
        Output times.
    rtol, atol : float, default 1e-12
        Tolerances.
    max_steps : int
        Step limit.

    Returns
    -------
    QuasiStaticResponse
        The deflections, their rates and the attitude perturbation along the rigid solution.
    """
    sys_, s, t0, tf, names = flexible_run_inputs(system, orbit_state, body, t_span, torques, orbit)
    phi0, wz0 = flexible_attitude(attitude)
    opts = integration_options(rtol, atol, None, 0.0, math.inf, max_steps, 0.8, None)
    te = None if t_eval is None else np.ascontiguousarray(t_eval, dtype=np.float64).ravel()
    r = _core.flexible_quasi_static(body._core_model(sys_, enabled_primaries(names), orbit == "held"), [float(v) for v in s],
                                    (phi0, wz0), (t0, tf), options=opts, t_eval=te)
    tu2 = sys_.tu_s**2
    return QuasiStaticResponse(sys_, body, r.t, r.orbit, r.phi, r.wz, r.dphi, r.dwz, r.q, r.qdot, r.qddot,
                               r.dtau / tu2, Stats.from_core(r.stats))
