"""Studies: one TOML file describes a whole librate job, validated before any work starts.

A study names the CR3BP system, the orbit family and the members wanted, the body (Kz or its
principal moments of inertia), the torques and their parameters, the grid of initial rates, the
solver settings and the outputs. :meth:`Study.from_toml` (or :meth:`Study.from_dict`) checks
everything first: unknown keys, wrong types, out-of-range values and inconsistent combinations
are collected and raised together as one :class:`StudyError`, one line per problem, each naming
the key (dotted, e.g. ``body.kz``), the value given and what is allowed. Nothing is computed or
written before the study is valid.

The ``[attitude]`` section chooses the attitude model: ``model = "planar"`` (the default; every
study without the section) or ``model = "3d"``: the 3-D rigid body (quaternion and three rates)
with the gravity gradient of both primaries, on any orbit family (halos too). A 3-D ``solve``
continues one periodic 3-D motion along the selected members (:func:`librate.attitude_family_3d`),
started from the planar N-family solution on the first member (``start = "planar"``), from the
torque-free spin about the synodic Z axis (``start = "spin"``) or from a given (q0, w0)
(``start = "given"``).

The ``build_*`` helpers turn a valid study into librate objects (:class:`~librate.System`, the
:class:`~librate.OrbitFamily` or a list of :class:`~librate.PeriodicOrbit`, the Kz values, the
:class:`~librate.FlatPlate` plate, the array of inertial initial rates); the jobs that the ``librate family``, ``librate solve`` and ``librate map`` commands run are in
:mod:`librate.app.jobs`.

Units: rates in 1/TU (nondimensional: the synodic frame turns at rate 1), angles in rad, the
inertia in kg m^2, areas in m^2, lengths in m, the solar pressure in N/m^2, periods in days.
"""

from __future__ import annotations

import copy
import difflib
import json
import math
import re
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, ValidationError, model_validator

from .._errors import LibrateError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["EXAMPLE_STUDY", "FIGURES", "PURPOSES", "Study", "StudyError"]

#: What a study can be checked for (the commands that run it).
PURPOSES = ("family", "solve", "map")
#: Figure names accepted in ``output.figures`` ("multipliers" and "body_axes": 3-D solves).
FIGURES = ("family", "period", "stability", "map", "residuals", "solutions", "multipliers", "body_axes")
#: What output.figures accepts (its field's description).
FIGURES_TEXT = "a list of figure names among " + ", ".join(repr(f) for f in FIGURES)


class StudyError(ValueError):
    """An invalid study: ``problems`` lists one message per problem, each naming the key (dotted
    path), the value given and what is allowed. ``str(err)`` shows them all."""

    def __init__(self, problems: list[str], source: str | None = None):
        self.problems = list(problems)
        self.source = source
        where = f" {source}" if source else ""
        n = len(self.problems)
        head = f"invalid study{where}: {n} problem{'s' if n != 1 else ''}"
        super().__init__(head + "".join(f"\n  - {p}" for p in self.problems))


# --- schema ------------------------------------------------------------------------------------
class _Table(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)


class Range(_Table):
    """``num`` evenly spaced values from ``start`` to ``stop`` (both included)."""

    start: float = Field(description="a finite number, the first value")
    stop: float = Field(description="a finite number, the last value")
    num: int = Field(ge=1, le=1_000_000, description="an integer in [1, 1000000], the number of values (both ends included)")

    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)


def _grid_tag(v: Any) -> str | None:
    if isinstance(v, (dict, Range)):
        return "range"
    if isinstance(v, (list, tuple)):
        return "list"
    return None


def _number_grid_tag(v: Any) -> str | None:
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return "number"
    return _grid_tag(v)


_GRID_MSG = "must be a list of numbers or a table {start, stop, num}"
_RATE_MSG = "must be a number (a fixed rate, 3-D maps), a list of numbers or a table {start, stop, num}"
#: The most values of one grid (a list, or a table's ``num``).
MAX_GRID = 1_000_000
Grid = Annotated[
    Annotated[list[float], Field(min_length=1, max_length=MAX_GRID), Tag("list")] | Annotated[Range, Tag("range")],
    Discriminator(_grid_tag, custom_error_type="grid", custom_error_message=_GRID_MSG),
]
KzValue = Annotated[float, Field(ge=-1, le=1)]
KzGrid = Annotated[
    Annotated[KzValue, Tag("number")] | Annotated[list[KzValue], Field(min_length=1, max_length=MAX_GRID), Tag("list")] | Annotated[Range, Tag("range")],
    Discriminator(_number_grid_tag, custom_error_type="grid", custom_error_message="must be a number, a list of numbers or a table {start, stop, num}"),
]
RateGrid = Annotated[
    Annotated[float, Tag("number")] | Annotated[list[float], Field(min_length=1, max_length=MAX_GRID), Tag("list")] | Annotated[Range, Tag("range")],
    Discriminator(_number_grid_tag, custom_error_type="grid", custom_error_message=_RATE_MSG),
]
_TAGS = {"list", "range", "number"}


class SystemSection(_Table):
    """[system]: a preset, or a custom system from mu, lu_km, tu_s (and radii_km)."""

    preset: str | None = Field(None, description="one of the presets ({presets})")
    mu: float | None = Field(None, gt=0, le=0.5, description="a number in (0, 0.5], the mass ratio m2 / (m1 + m2)")
    lu_km: float | None = Field(None, gt=0, description="a number > 0, the length unit (distance between the primaries) in km")
    tu_s: float | None = Field(None, gt=0, description="a number > 0, the time unit (1 / mean motion) in s")
    radii_km: list[Annotated[float, Field(ge=0)]] | None = Field(None, min_length=2, max_length=2, description="two numbers >= 0, the primaries' radii in km")
    name: str | None = Field(None, description="a string")


class OrbitsSection(_Table):
    """[orbits]: the family and the members wanted."""

    kind: Literal["dro", "lyapunov", "halo"] = Field("dro", description="'dro', 'lyapunov' or 'halo'")
    point: Literal[1, 2] | None = Field(None, description="1 (L1) or 2 (L2), for lyapunov and halo families")
    branch: Literal["north", "south"] | None = Field(None, description="'north' or 'south', for halo families")
    x0: Grid | None = Field(None, description="a list of x0 values (LU) or a table {start, stop, num}")
    z0: Grid | None = Field(None, description="a list of z0 values (LU) or a table {start, stop, num}, for halo families")
    period_days: Grid | None = Field(None, description="a list of periods (days) or a table {start, stop, num}")
    resonance: list[Annotated[int, Field(ge=1, le=100)]] | None = Field(None, min_length=1, max_length=100, description="a list of integers k >= 1 (synodic 1:k members, T = 2 pi / k)")
    sun_resonance: list[Annotated[int, Field(ge=1, le=100)]] | None = Field(None, min_length=1, max_length=100, description="a list of integers k >= 1 (Sun-resonant members, T = Ts / k)")
    members: int | None = Field(None, ge=1, le=10_000, description="an integer >= 1: that many members evenly spread along the family")
    max_members: int | None = Field(None, ge=2, le=5_000, description="an integer in [2, 5000], the continuation's length (lyapunov and halo)")


FLEXIBLE_PRESETS = ("sample-station", "sample-station-low-frequency")
#: The 3-D corrector's default tolerance (``attitude.tol``).
ATTITUDE_TOL = 1e-12


class BodySection(_Table):
    """[body]: Kz, or the principal moments of inertia in kg m^2, or a flexible spacecraft
    (``flexible``: a preset name or the path of a FlexibleBody TOML file)."""

    kz: KzGrid | None = Field(None, description="a number in [-1, 1] (Kz = (Iy - Ix) / Iz), a list of them or a table {start, stop, num}")
    ix: float | None = Field(None, gt=0, description="a number > 0, principal moment of inertia about x in kg m^2")
    iy: float | None = Field(None, gt=0, description="a number > 0, principal moment of inertia about y in kg m^2")
    iz: float | None = Field(None, gt=0, description="a number > 0, principal moment of inertia about z in kg m^2")
    mass_kg: float | None = Field(None, gt=0, description="a number > 0, the mass in kg")
    flexible: str | None = None


class SrpSection(_Table):
    """[torques.srp]: the flat plate, by its amplitude eps or by its geometry."""

    eps: float | None = Field(None, description="a finite number, the nondimensional plate amplitude P A d TU^2 / Iz")
    area_m2: float | None = Field(None, gt=0, description="a number > 0, the plate's area in m^2")
    offset_m: float | None = Field(None, description="a finite number, the centre-of-pressure offset along y_B in m")
    cs: float = Field(0.0, ge=0, le=1, description="a number in [0, 1], the specular reflection fraction (cs + cd <= 1)")
    cd: float = Field(0.0, ge=0, le=1, description="a number in [0, 1], the diffuse reflection fraction (cs + cd <= 1)")
    theta_sun0: float = Field(0.0, description="a finite number, the Sun's phase at t = 0 in rad")
    pressure: float | None = Field(None, ge=0, description="a number >= 0, the solar pressure in N/m^2 (default 4.56e-6)")

    @model_validator(mode="before")
    @classmethod
    def _old_theta0(cls, data: Any) -> Any:
        """The Sun's phase was `theta0` before it became `theta_sun0`: still read, with a warning."""
        if isinstance(data, dict) and "theta0" in data:
            if "theta_sun0" in data:
                raise ValueError("theta0 is the old name of theta_sun0; give only theta_sun0")
            warnings.warn("[torques.srp] theta0 is deprecated and will be removed: write theta_sun0 "
                          "(the same Sun phase at t = 0, rad)", FutureWarning, stacklevel=2)
            data = {("theta_sun0" if k == "theta0" else k): v for k, v in data.items()}
        return data


class TorquesSection(_Table):
    """[torques]: gravity gradient of the primaries, and solar radiation pressure."""

    gravity_gradient: list[Literal["earth", "moon"]] = Field(default_factory=lambda: ["earth", "moon"], description="a list of primaries among 'earth' and 'moon'")
    srp: SrpSection | None = None


class RatesSection(_Table):
    """[rates]: the initial rates, inertial wz0 or relative phidot0 = wz0 - 1 (1/TU); for a 3-D
    map also wx0 and wy0 (inertial, body axes): two grids and one fixed number."""

    wz0: RateGrid | None = Field(None, description="a list of inertial initial rates (1/TU), strictly increasing, or a table {start, stop, num} with start < stop, num >= 2")
    phidot0: RateGrid | None = Field(None, description="a list of initial rates relative to the synodic frame (1/TU), strictly increasing, or a table {start, stop, num} with start < stop, num >= 2")
    wx0: RateGrid | None = Field(None, description="for attitude.model = '3d' maps: a number (fixed) or a grid of inertial initial rates about body x (1/TU): a strictly increasing list or a table {start, stop, num} with start < stop, num >= 2")
    wy0: RateGrid | None = Field(None, description="for attitude.model = '3d' maps: a number (fixed) or a grid of inertial initial rates about body y (1/TU): a strictly increasing list or a table {start, stop, num} with start < stop, num >= 2")


class AttitudeSection(_Table):
    """[attitude]: the attitude model ("planar" or "3d") and how a 3-D solve starts."""

    model: Literal["planar", "3d"] = Field("planar", description="'planar' (the default: the planar model, phi and wz) or '3d' (the 3-D rigid body, quaternion and three rates)")
    start: Literal["planar", "spin", "given"] | None = Field(None, description="'planar' (the planar N-family solution on the first member, planar families), 'spin' (the torque-free spin wz0 = 1 + 2 pi n / (K T) about synodic Z) or 'given' (attitude.q0 and attitude.w0), with attitude.model = '3d'")
    n: int | None = Field(None, ge=-100, le=100, description="an integer in [-100, 100], net turns about synodic Z per attitude period, with attitude.start = 'planar' or 'spin'")
    q0: list[float] | None = Field(None, min_length=4, max_length=4, description="four numbers, a unit quaternion (scalar last): the body relative to the synodic frame at t = 0, with attitude.start = 'given' or 'spin'")
    w0: list[float] | None = Field(None, min_length=3, max_length=3, description="three numbers, the inertial rate in body axes (1/TU), with attitude.start = 'given'")
    tol: float | None = Field(None, ge=1e-14, le=1e-6, description="a number in [1e-14, 1e-6], the 3-D corrector's tolerance on the closure (default 1e-12; 1e-10 for NRHOs)")


class SolverSection(_Table):
    """[solver]: tolerances, periods per solution, initial angle."""

    rtol: float = Field(1e-12, ge=1e-15, le=1e-3, description="a number in [1e-15, 1e-3]")
    atol: float = Field(1e-12, ge=1e-15, le=1e-3, description="a number in [1e-15, 1e-3]")
    n_periods: int | None = Field(None, ge=1, le=1000, description="an integer in [1, 1000], orbit periods per attitude period")
    phi0: float = Field(0.0, ge=-2 * math.pi, le=2 * math.pi, description="a number in [-2 pi, 2 pi], the initial attitude angle in rad")


class OutputSection(_Table):
    """[output]: where and how results are written."""

    folder: str = Field("librate-out", min_length=1, description="a non-empty path (relative paths are taken from the study file's folder)")
    format: Literal["zarr", "netcdf"] = Field("zarr", description="'zarr' or 'netcdf'")
    figures: list[Literal["family", "period", "stability", "map", "residuals", "solutions", "multipliers", "body_axes"]] | None = Field(None, description=FIGURES_TEXT)


_SECTIONS: dict[str, type[_Table]] = {
    "system": SystemSection,
    "orbits": OrbitsSection,
    "body": BodySection,
    "torques": TorquesSection,
    "rates": RatesSection,
    "attitude": AttitudeSection,
    "solver": SolverSection,
    "output": OutputSection,
}
_TABLES: dict[str, type[_Table]] = {**_SECTIONS, "torques.srp": SrpSection}
_TOP_KEYS = ("title", "description", *_SECTIONS)

def _described(model: type[BaseModel], name: str) -> str | None:
    f = model.model_fields.get(name)
    return f.description if f is not None else None


def _allowed(key: str) -> str | None:
    """What ``key`` accepts: the description on its field (a grid's start, stop, num: Range's)."""
    base = re.sub(r"\[\d+\]", "", key)
    parent, _, name = base.rpartition(".")
    model = Study if parent == "" else _TABLES.get(parent)
    text = _described(model, name) if model is not None else None
    if text is None:
        text = _described(Range, name)
    if text and "{presets}" in text:
        from ..orbits.system import System

        text = text.format(presets=", ".join(repr(p) for p in System.presets()))
    return text


def _show(value: Any) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


def problem(key: str, value: Any, message: str, allowed: str | None = None) -> str:
    allowed = _allowed(key) if allowed is None else allowed
    text = f"{key} = {_show(value)}: {message}"
    return text + (f"; allowed: {allowed}" if allowed else "")


def _missing(key: str, message: str) -> str:
    allowed = _allowed(key)
    return f"{key}: {message}" + (f"; allowed: {allowed}" if allowed else "")


def _dotted(prefix: str, loc: tuple) -> str:
    key = prefix
    for part in loc:
        if isinstance(part, int):
            key += f"[{part}]"
        elif part in _TAGS:
            continue
        else:
            key = f"{key}.{part}" if key else str(part)
    return key


def _keys_of(parent: str) -> list[str] | None:
    base = re.sub(r"\[\d+\]", "", parent)
    if base == "":
        return list(_TOP_KEYS)
    if base in _TABLES:
        return list(_TABLES[base].model_fields)
    last = base.rsplit(".", 1)[-1]
    if last in ("x0", "z0", "period_days", "wz0", "phidot0", "wx0", "wy0", "kz"):
        return list(Range.model_fields)
    return None


def _unknown(key: str, value: Any) -> str:
    parent, _, name = key.rpartition(".")
    keys = _keys_of(parent) or []
    where = f"[{parent}]" if parent else "the top level"
    hint = difflib.get_close_matches(name, keys, n=1)
    text = f"{key} = {_show(value)}: unknown key; allowed keys in {where}: {', '.join(keys)}"
    return text + (f" (did you mean `{(parent + '.') if parent else ''}{hint[0]}`?)" if hint else "")


def _pydantic_problems(prefix: str, err: ValidationError) -> list[str]:
    out = []
    for e in err.errors():
        key = _dotted(prefix, e["loc"])
        if e["type"] == "extra_forbidden":
            out.append(_unknown(key, e["input"]))
        elif e["type"] == "missing":
            out.append(_missing(key, "missing (required)"))
        else:
            msg = e["msg"]
            msg = msg[0].lower() + msg[1:]
            msg = msg.removeprefix("value error, ")
            if e["type"] == "model_type":
                msg = "must be a table"
            out.append(problem(key, e["input"], msg))
    return out


# --- checks beyond the types -------------------------------------------------------------------
def _grid_values(g) -> np.ndarray | None:
    if g is None:
        return None
    if isinstance(g, Range):
        return g.values()
    if isinstance(g, (int, float)):
        return np.array([float(g)])
    return np.asarray(g, dtype=float)


def grid_raw(g) -> Any:
    if isinstance(g, Range):
        return g.model_dump()
    return g


def _check_increasing(key: str, g, problems: list[str]) -> None:
    if isinstance(g, Range):
        if g.num < 2:
            problems.append(problem(f"{key}.num", g.num, "a rate grid needs at least 2 values", "an integer in [2, 1000000]"))
        if not g.start < g.stop:
            problems.append(problem(f"{key}.stop", g.stop, f"must be greater than {key}.start = {_show(g.start)} (rates increase)",
                                     f"a number > {key}.start"))
    else:
        v = np.asarray(g, dtype=float)
        if v.size < 2:
            problems.append(problem(key, g, "a rate grid needs at least 2 values"))
        elif np.any(np.diff(v) <= 0):
            problems.append(problem(key, g, "must be strictly increasing"))


def _check_sections(s: dict[str, _Table], given: dict, purpose: str | None) -> list[str]:
    """Consistency checks on the sections that passed type validation (``s``); ``given`` is the
    raw study as written (to tell a missing section from a defaulted one)."""
    from ..orbits.system import System

    problems: list[str] = []
    # [system]
    mu = None
    sysc = s.get("system")
    if sysc is not None:
        custom = [k for k in ("mu", "lu_km", "tu_s", "radii_km") if getattr(sysc, k) is not None]
        if sysc.preset is not None:
            if sysc.preset not in System.presets():
                problems.append(problem("system.preset", sysc.preset, "unknown preset"))
            else:
                mu = System.preset(sysc.preset).mu
            for k in custom:
                problems.append(problem(f"system.{k}", getattr(sysc, k), "cannot be combined with system.preset (a preset fixes the constants)",
                                         "either system.preset alone, or system.mu, system.lu_km and system.tu_s (and optionally system.radii_km)"))
        elif custom:
            for k in ("mu", "lu_km", "tu_s"):
                if getattr(sysc, k) is None:
                    problems.append(_missing(f"system.{k}", f"missing: a custom system (given {', '.join('system.' + c for c in custom)}) needs system.mu, system.lu_km and system.tu_s"))
            if sysc.mu is not None:
                mu = sysc.mu
        else:
            mu = System.preset("earth-moon").mu

    # [orbits]
    orb = s.get("orbits")
    if orb is not None:
        if orb.kind == "dro":
            for k in ("point", "branch", "max_members"):
                if getattr(orb, k) is not None:
                    problems.append(problem(f"orbits.{k}", getattr(orb, k), "does not apply to orbits.kind = \"dro\"",
                                             "orbits.point and orbits.max_members for 'lyapunov' and 'halo', orbits.branch for 'halo'"))
        if orb.kind == "lyapunov" and orb.branch is not None:
            problems.append(problem("orbits.branch", orb.branch, "does not apply to orbits.kind = \"lyapunov\" (planar)", "orbits.branch only with orbits.kind = 'halo'"))
        if orb.kind != "halo" and orb.z0 is not None:
            problems.append(problem("orbits.z0", grid_raw(orb.z0), f"does not apply to orbits.kind = \"{orb.kind}\" (planar: z0 = 0)", "orbits.z0 only with orbits.kind = 'halo'"))
        sel = [k for k in ("x0", "z0", "period_days", "resonance", "sun_resonance", "members") if getattr(orb, k) is not None]
        if len(sel) > 1:
            for k in sel[1:]:
                problems.append(problem(f"orbits.{k}", grid_raw(getattr(orb, k)), f"cannot be combined with orbits.{sel[0]}: choose the members one way",
                                         "at most one of orbits.x0, z0, period_days, resonance, sun_resonance, members"))
        for k in ("x0", "z0", "period_days"):
            v = _grid_values(getattr(orb, k))
            if v is None:
                continue
            if k == "x0" and mu is not None and orb.kind == "dro" and (np.any(v <= -mu) or np.any(v >= 1 - mu)):
                problems.append(problem("orbits.x0", grid_raw(orb.x0), f"DROs start between the primaries, -mu < x0 < 1 - mu = ({-mu:.6g}, {1 - mu:.6g})",
                                         "values in (-mu, 1 - mu)"))
            if k == "period_days" and np.any(v <= 0):
                problems.append(problem("orbits.period_days", grid_raw(orb.period_days), "periods must be > 0 days"))

    # [body]
    body = s.get("body")
    if body is not None:
        moments = {k: getattr(body, k) for k in ("ix", "iy", "iz") if getattr(body, k) is not None}
        if body.flexible is not None and (body.kz is not None or moments):
            for k in ["kz", *moments]:
                if getattr(body, k) is not None:
                    problems.append(problem(f"body.{k}", grid_raw(body.kz) if k == "kz" else getattr(body, k),
                                             "cannot be combined with body.flexible (the flexible body defines its inertia)",
                                             "either body.flexible, or body.kz, or body.ix/iy/iz"))
        elif body.kz is not None and moments:
            for k, v in moments.items():
                problems.append(problem(f"body.{k}", v, "cannot be combined with body.kz (Kz follows from the moments)",
                                         "either body.kz, or body.ix, body.iy and body.iz"))
        elif body.flexible is not None:
            if body.flexible not in FLEXIBLE_PRESETS and not body.flexible.endswith(".toml"):
                problems.append(problem("body.flexible", body.flexible, "not a flexible-body preset or TOML file",
                                         f"one of {', '.join(FLEXIBLE_PRESETS)}, or the path of a FlexibleBody TOML file (*.toml)"))
        elif body.kz is None and not moments:
            problems.append(_missing("body.kz", "missing: give body.kz, or body.ix, body.iy and body.iz in kg m^2 (or body.flexible)"))
        elif moments and len(moments) < 3:
            for k in ("ix", "iy", "iz"):
                if k not in moments:
                    problems.append(_missing(f"body.{k}", f"missing: the inertia needs all three of body.ix, body.iy, body.iz (given: {', '.join('body.' + m for m in moments)})"))
        elif len(moments) == 3:
            ix, iy, iz = moments["ix"], moments["iy"], moments["iz"]
            for k, a, b, c in (("ix", ix, iy, iz), ("iy", iy, ix, iz), ("iz", iz, ix, iy)):
                if a > b + c:
                    problems.append(problem(f"body.{k}", a, f"violates the triangle inequality: {k} must not exceed the sum of the other two moments ({b + c:g} kg m^2)",
                                             "principal moments with each <= the sum of the other two"))
                    break
        if isinstance(body.kz, Range):
            for k in ("start", "stop"):
                v = getattr(body.kz, k)
                if not -1 <= v <= 1:
                    problems.append(problem(f"body.kz.{k}", v, "Kz must be in [-1, 1]", "a number in [-1, 1]"))

    # [torques]
    tq = s.get("torques")
    if tq is not None:
        if len(set(tq.gravity_gradient)) != len(tq.gravity_gradient):
            problems.append(problem("torques.gravity_gradient", tq.gravity_gradient, "a primary is listed twice"))
        srp = tq.srp
        if srp is not None:
            geo = [k for k in ("area_m2", "offset_m") if getattr(srp, k) is not None]
            if srp.eps is not None and geo:
                for k in geo:
                    problems.append(problem(f"torques.srp.{k}", getattr(srp, k), "cannot be combined with torques.srp.eps (eps follows from the geometry)",
                                             "either torques.srp.eps, or torques.srp.area_m2 and torques.srp.offset_m"))
            elif srp.eps is None and len(geo) < 2:
                missing = [k for k in ("area_m2", "offset_m") if k not in geo] if geo else ["eps"]
                for k in missing:
                    problems.append(_missing(f"torques.srp.{k}", "missing: the plate needs torques.srp.eps, or torques.srp.area_m2 and torques.srp.offset_m"))
            if srp.cs + srp.cd > 1 + 1e-12:
                problems.append(problem("torques.srp.cd", srp.cd, f"cs + cd = {srp.cs + srp.cd:g} exceeds 1 (the absorbed fraction is 1 - cs - cd)"))
            if srp.pressure is not None and srp.eps is not None:
                problems.append(problem("torques.srp.pressure", srp.pressure, "only used with the geometry (area_m2, offset_m); eps already includes it"))
            if srp.eps is None and len(geo) == 2 and body is not None and body.iz is None and body.kz is not None:
                problems.append(problem("torques.srp.area_m2", srp.area_m2, "the plate's geometry needs the body's Iz in kg m^2 (body.ix, body.iy, body.iz); with body.kz alone give torques.srp.eps",
                                         "torques.srp.eps with body.kz, or the geometry with body.ix/iy/iz"))

    # [attitude] (a section that failed type validation counts as the default planar model)
    att = s.get("attitude")
    three_d = att is not None and att.model == "3d"
    start = _start_of(att, orb) if three_d else None

    # [rates]
    rates = s.get("rates")
    if rates is not None:
        if rates.wz0 is not None and rates.phidot0 is not None:
            problems.append(problem("rates.phidot0", grid_raw(rates.phidot0), "cannot be combined with rates.wz0 (phidot0 = wz0 - 1)", "either rates.wz0 or rates.phidot0"))
        elif rates.wz0 is None and rates.phidot0 is None and not three_d:
            problems.append(_missing("rates.wz0", "missing: give rates.wz0 (inertial) or rates.phidot0 (relative to the synodic frame)"))
        if not three_d:
            for k in ("wx0", "wy0"):
                if getattr(rates, k) is not None:
                    problems.append(problem(f"rates.{k}", grid_raw(getattr(rates, k)), "applies only to attitude.model = \"3d\" (the planar model has the one rate wz)",
                                             "rates.wz0 or rates.phidot0 with the planar model; rates.wx0 and rates.wy0 with [attitude] model = '3d'"))
        for k in ("wz0", "phidot0", "wx0", "wy0"):
            g = getattr(rates, k)
            # a number is a fixed rate of a 3-D map; every grid increases
            if g is not None and not (three_d and isinstance(g, (int, float))) and (k in ("wz0", "phidot0") or three_d):
                _check_increasing(f"rates.{k}", g, problems)

    if att is not None and not three_d:
        for k in ("start", "n", "q0", "w0", "tol"):
            if getattr(att, k) is not None:
                problems.append(problem(f"attitude.{k}", getattr(att, k), "applies only to attitude.model = \"3d\"", "attitude.model = '3d' with it, or leave it out"))
    if three_d:
        problems += _check_3d(att, start, s, given)

    # what the command needs
    if purpose in ("solve", "map") and three_d:
        problems += _needs_3d(purpose, start, s, given)
    elif purpose in ("solve", "map"):
        what, need = ("periodic solutions", "need") if purpose == "solve" else ("a periodicity map", "needs")
        if "body" not in given:
            problems.append(_missing("body", f"missing section [body]: {what} {need} the body (body.kz, or body.ix/iy/iz)"))
        if "rates" not in given:
            problems.append(_missing("rates", f"missing section [rates]: {what} {need} the initial rates (rates.wz0 or rates.phidot0)"))
        if orb is not None and orb.kind == "halo":
            problems.append(problem("orbits.kind", orb.kind, f"{what} use{'s' if need == 'needs' else ''} the planar attitude model, which needs a planar family",
                                     "'dro' or 'lyapunov' with the planar model, or any family with [attitude] model = '3d'"))
        if purpose == "map" and body is not None and body.flexible is not None:
            problems.append(problem("body.flexible", body.flexible, "the periodicity-map engine integrates rigid bodies; "
                                     "`librate solve` reports how flexibility moves each periodic solution", "body.kz or body.ix/iy/iz for a map"))
        if body is not None and body.flexible is not None and tq is not None and tq.srp is not None:
            problems.append(problem("torques.srp", "[torques.srp]", "the flexible model has no solar radiation pressure yet", "no [torques.srp] with body.flexible"))
        if tq is not None and sorted(tq.gravity_gradient) != ["earth", "moon"]:
            problems.append(problem("torques.gravity_gradient", tq.gravity_gradient,
                                     f"the planar engine behind {what} models the gravity gradient of both primaries", "[\"earth\", \"moon\"]"))
        if tq is not None and tq.srp is not None and orb is not None:
            why = "with torques.srp the forcing is periodic only on a Sun-resonant orbit (T = Ts / k): select exactly one"
            if orb.sun_resonance is None:
                problems.append(_missing("orbits.sun_resonance", f"missing: {why}, e.g. orbits.sun_resonance = [2]"))
            elif len(orb.sun_resonance) != 1:
                problems.append(problem("orbits.sun_resonance", orb.sun_resonance, why, "a list of one integer k >= 1, e.g. [2]"))
            else:
                k = orb.sun_resonance[0]
                sol = s.get("solver")
                if sol is not None and sol.n_periods is not None and sol.n_periods % k:
                    problems.append(problem("solver.n_periods", sol.n_periods, f"with torques.srp on the 1:{k} Sun-resonant orbit the attitude period must cover whole Sun periods",
                                             f"a multiple of {k}"))
    return problems


def _start_of(att, orb) -> str:
    """How a 3-D solve starts: ``attitude.start``, else "given" with attitude.w0, else "spin"
    on a halo family, else "planar"."""
    if att.start is not None:
        return att.start
    if att.w0 is not None:
        return "given"
    return "spin" if orb is not None and orb.kind == "halo" else "planar"


_NOT_3D = "not modelled in 3-D yet (the 3-D model has the gravity gradient of both primaries on a rigid body)"


def _check_3d(att, start: str, s: dict, given: dict) -> list[str]:
    """The checks of ``[attitude] model = "3d"`` on the sections that passed type validation."""
    problems: list[str] = []
    orb, body, tq, sol = s.get("orbits"), s.get("body"), s.get("torques"), s.get("solver")
    if start == "planar":
        if orb is not None and orb.kind == "halo":
            problems.append(problem("attitude.start", start, "the planar start takes a planar solution, which needs a planar family (orbits.kind = 'dro' or 'lyapunov')",
                                     "'spin' or 'given' on a halo family"))
        for k in ("q0", "w0"):
            if getattr(att, k) is not None:
                problems.append(problem(f"attitude.{k}", getattr(att, k), "cannot be combined with attitude.start = \"planar\" (the start is the planar solution: "
                                         "phi0 = solver.phi0 about Z, wz0 from the rates.wz0 scan)", "attitude.q0 and attitude.w0 with attitude.start = 'given'"))
    elif start == "spin" and att.w0 is not None:
        problems.append(problem("attitude.w0", att.w0, "cannot be combined with attitude.start = \"spin\" (the spin is w = (1 + 2 pi n / (K T)) e_Z)",
                                 "attitude.w0 with attitude.start = 'given'"))
    if start in ("planar", "spin") and att.n is None:
        problems.append(_missing("attitude.n", f"missing: attitude.start = \"{start}\" needs the net turns n per attitude period"))
    if start == "given":
        if att.w0 is None:
            problems.append(_missing("attitude.w0", "missing: attitude.start = \"given\" starts from attitude.w0 (and attitude.q0, default the identity)"))
        if att.n is not None:
            problems.append(problem("attitude.n", att.n, "does not apply to attitude.start = \"given\" (the start is attitude.q0, attitude.w0)",
                                     "attitude.n with attitude.start = 'planar' or 'spin'"))
    if att.q0 is not None and abs(math.hypot(*att.q0) - 1) > 1e-6:  # finite: the schema refuses inf and nan
        problems.append(problem("attitude.q0", att.q0, f"must be a unit quaternion (|q0| = {math.hypot(*att.q0):.6g})"))
    if att.q0 is not None and sol is not None and "phi0" in (given.get("solver") or {}):
        problems.append(problem("solver.phi0", sol.phi0, "cannot be combined with attitude.q0 (q0 is the whole initial attitude)",
                                 "solver.phi0 (a rotation about Z) or attitude.q0, not both"))
    if body is not None:
        if body.flexible is not None:
            problems.append(problem("body.flexible", body.flexible, f"flexible bodies are {_NOT_3D}", "body.ix, body.iy and body.iz (kg m^2) with attitude.model = '3d'"))
        elif body.kz is not None and body.ix is None and body.iy is None and body.iz is None:
            problems.append(problem("body.kz", grid_raw(body.kz), "the 3-D attitude model needs the full inertia, not Kz alone (Kz fixes only (Iy - Ix) / Iz)",
                                     "body.ix, body.iy and body.iz in kg m^2 (principal moments, each <= the sum of the other two)"))
    if tq is not None:
        if tq.srp is not None:
            problems.append(problem("torques.srp", "[torques.srp]", f"solar radiation pressure is {_NOT_3D}", "no [torques.srp] with attitude.model = '3d'"))
        if sorted(tq.gravity_gradient) != ["earth", "moon"]:
            problems.append(problem("torques.gravity_gradient", tq.gravity_gradient, "the 3-D attitude model has the gravity gradient of both primaries",
                                     "[\"earth\", \"moon\"]"))
    return problems


def member_count(orb) -> tuple[str, Any, int] | None:
    """(key, value, count) of the members [orbits] selects, None for the whole family."""
    for k in ("x0", "z0", "period_days"):
        g = getattr(orb, k)
        if g is not None:
            return k, grid_raw(g), int(_grid_values(g).size)
    for k in ("resonance", "sun_resonance"):
        if getattr(orb, k) is not None:
            return k, getattr(orb, k), len(getattr(orb, k))
    if orb.members is not None:
        return "members", orb.members, orb.members
    return None


def _needs_3d(purpose: str, start: str, s: dict, given: dict) -> list[str]:
    """What ``librate solve`` or ``librate map`` needs from a 3-D study."""
    problems: list[str] = []
    rates = s.get("rates")
    what = "a 3-D solve" if purpose == "solve" else "a 3-D map"
    if "body" not in given:
        problems.append(_missing("body", f"missing section [body]: {what} needs the body's principal moments (body.ix, body.iy, body.iz)"))
    if purpose == "solve":
        if start == "planar":
            if "rates" not in given:
                problems.append(_missing("rates", "missing section [rates]: the planar start scans rates.wz0 (or rates.phidot0) for the planar solution"))
            elif rates is not None:
                if rates.wz0 is None and rates.phidot0 is None:
                    problems.append(_missing("rates.wz0", "missing: the planar start scans rates.wz0 (or rates.phidot0) for the planar solution"))
                for k in ("wz0", "phidot0"):
                    g = getattr(rates, k)
                    if isinstance(g, (int, float)):
                        problems.append(problem(f"rates.{k}", g, "the planar start scans a grid of rates for the planar solution, not one value"))
        return problems
    if "rates" not in given:
        problems.append(_missing("rates", "missing section [rates]: a 3-D map needs rates.wx0, rates.wy0 and rates.wz0 (or rates.phidot0): two grids and one fixed number"))
        return problems
    if rates is None:
        return problems
    comp = {"wx0": rates.wx0, "wy0": rates.wy0, "wz0": rates.wz0 if rates.wz0 is not None else rates.phidot0}
    for k, v in comp.items():
        if v is None:
            problems.append(_missing(f"rates.{k}", "missing: a 3-D map needs rates.wx0, rates.wy0 and rates.wz0 (or rates.phidot0): two grids and one fixed number"))
    fixed = [k for k, v in comp.items() if isinstance(v, (int, float))]
    if all(v is not None for v in comp.values()) and len(fixed) != 1:
        key = fixed[-1] if fixed else "wz0"
        name = key if key != "wz0" or rates.wz0 is not None else "phidot0"
        problems.append(problem(f"rates.{name}", grid_raw(getattr(rates, name)), f"a 3-D map has grids over two rate components and one fixed number; "
                                 f"given {len(fixed)} fixed ({', '.join('rates.' + f for f in fixed) or 'none'})",
                                 "exactly one of rates.wx0, rates.wy0, rates.wz0 (or rates.phidot0) a number, the other two grids"))
    return problems


# --- the study -----------------------------------------------------------------------------------
class Study(BaseModel):
    """A validated study (see the module docstring). Build it with :meth:`from_toml` or
    :meth:`from_dict`; it is immutable. ``base_dir`` is the folder relative output paths are
    taken from (the study file's folder, or the working directory)."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)

    title: str | None = Field(None, description="a string")
    description: str | None = Field(None, description="a string")
    system: SystemSection = Field(default_factory=SystemSection)
    orbits: OrbitsSection = Field(default_factory=OrbitsSection)
    body: BodySection | None = None
    torques: TorquesSection = Field(default_factory=TorquesSection)
    rates: RatesSection | None = None
    attitude: AttitudeSection = Field(default_factory=AttitudeSection)
    solver: SolverSection = Field(default_factory=SolverSection)
    output: OutputSection = Field(default_factory=OutputSection)
    base_dir: str = Field(".", exclude=True)

    # --- construction --------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Any, *, purpose: str | None = None, base_dir: str | Path | None = None, source: str | None = None,
                  force: bool = False) -> Study:
        """Validate ``data`` (the parsed TOML: a dict of tables) and return the study.

        ``purpose``: also check what a command needs ("family", "solve" or "map"; e.g. a map needs
        [body] and [rates] and a planar family), and, for "solve" and "map", that its size is
        within :data:`librate.app.budget.MAX_WORK` and ``MAX_MAP_BYTES`` (``force=True`` lifts
        that). Raises :class:`StudyError` listing every problem.
        """
        if purpose is not None and purpose not in PURPOSES:
            raise ValueError(f"invalid argument `purpose`: must be one of {', '.join(PURPOSES)} or None, got {purpose!r}")
        if not isinstance(data, dict):
            raise StudyError([f"the study must be a table of sections, got {type(data).__name__}"], source)
        problems: list[str] = []
        sections: dict[str, _Table] = {}
        for key, value in data.items():
            if key in ("title", "description"):
                if not isinstance(value, str):
                    problems.append(problem(key, value, "must be a string"))
            elif key in _SECTIONS:
                if not isinstance(value, dict):
                    problems.append(problem(key, value, f"must be a table [{key}]", f"a table [{key}] with keys {', '.join(_SECTIONS[key].model_fields)}"))
                    continue
                try:
                    sections[key] = _SECTIONS[key].model_validate(value)
                except ValidationError as err:
                    problems += _pydantic_problems(key, err)
            else:
                problems.append(_unknown(key, value))
        # Sections left out take their defaults ([body] and [rates] have none); a section that
        # failed type validation is left out of the checks that involve it.
        valid: dict[str, _Table] = {}
        for k, model in _SECTIONS.items():
            if k in sections:
                valid[k] = sections[k]
            elif k not in data and k not in ("body", "rates"):
                valid[k] = model()
        problems += _check_sections(valid, data, purpose)
        if problems:
            raise StudyError(problems, source)
        kwargs = {k: v for k, v in data.items() if k in ("title", "description")}
        study = cls.model_construct(**kwargs, **valid, base_dir=str(base_dir if base_dir is not None else "."))
        if purpose in ("solve", "map") and not force:
            from .budget import estimate, refusal

            too_large = refusal(estimate(study, purpose), purpose)
            if too_large:
                raise StudyError([too_large], source)
        return study

    @classmethod
    def from_toml(cls, path: str | Path, *, purpose: str | None = None, overrides: dict | None = None, force: bool = False) -> Study:
        """Read and validate a TOML study file (relative output folders are taken from its
        folder). ``overrides``: a dict of dotted keys to values applied on top (e.g.
        ``{"rates.wz0.num": 50}``), as the command line's ``--set``. Raises :class:`StudyError`."""
        p = Path(path)
        try:
            text = p.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise StudyError([f"study file {str(p)!r} not found"], str(p)) from None
        except (OSError, UnicodeDecodeError) as err:
            raise StudyError([f"study file {str(p)!r} cannot be read: {err}"], str(p)) from None
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as err:
            raise StudyError([f"not valid TOML: {err}"], str(p)) from None
        if overrides:
            data = apply_overrides(data, overrides)
        return cls.from_dict(data, purpose=purpose, base_dir=p.resolve().parent, source=str(p), force=force)

    def check(self, purpose: str, force: bool = False) -> Study:
        """Check that the study has what a command needs ("family", "solve", "map") and, for
        "solve" and "map", a size within the limits (``force=True`` lifts them); returns itself,
        or raises :class:`StudyError`."""
        return Study.from_dict(self.to_dict(), purpose=purpose, base_dir=self.base_dir, force=force)

    def estimate(self, purpose: str):
        """The size of this study run as ``purpose`` ("solve" or "map"): trajectories, orbit
        periods, memory (:class:`librate.app.budget.Estimate`; ``.text()`` says it)."""
        from .budget import estimate

        return estimate(self, purpose)

    # --- serialisation -------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """The full study as plain data (TOML/JSON compatible), with the defaults written out:
        the system preset, the Lagrange point and halo branch, the periods per solution."""
        d = self.model_dump(mode="json", exclude_none=True, exclude={"base_dir"})
        if self.system.mu is None:
            d["system"]["preset"] = self.system.preset or "earth-moon"
        if self.orbits.kind != "dro":
            d["orbits"].setdefault("point", 1 if self.orbits.kind == "lyapunov" else 2)
        if self.orbits.kind == "halo":
            d["orbits"].setdefault("branch", "south")
        d["solver"]["n_periods"] = self.n_periods()
        if self.attitude.model == "planar":
            d.pop("attitude", None)  # the default model: the stored study of a planar job is unchanged
        else:
            d["attitude"]["start"] = self.attitude_start()
            d["attitude"].setdefault("tol", ATTITUDE_TOL)
        return d

    def to_json(self) -> str:
        """The full study as a JSON string (stored as the ``study`` attribute of every result)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_json(cls, text: str, **kwargs) -> Study:
        """The study stored in a result's ``study`` attribute."""
        return cls.from_dict(json.loads(text), **kwargs)

    # --- librate objects -----------------------------------------------------------------------
    def build_system(self):
        """The :class:`~librate.System`."""
        from ..orbits.system import System

        s = self.system
        if s.mu is None:
            return System.preset(s.preset or "earth-moon")
        r1, r2 = s.radii_km or (0.0, 0.0)
        return System(mu=s.mu, lu_km=s.lu_km, tu_s=s.tu_s, r1_km=r1, r2_km=r2, name=s.name or "custom")

    def build_family(self, system=None, progress: Callable[[int, int], None] | None = None):
        """The orbit family this study works on (computed by continuation, takes 0.1 s to a few
        s): for DROs with ``orbits.x0``, exactly those members; otherwise the whole family (DRO
        0.985 -> 0.005; Lyapunov or halo at ``orbits.point`` up to ``orbits.max_members``).
        ``progress(done, total)`` after each member."""
        from ..orbits.families import dro_family, halo_family, lyapunov_family

        system = system or self.build_system()
        o = self.orbits
        if o.kind == "dro":
            if o.x0 is None:
                return dro_family(system, progress=progress)
            try:
                return dro_family(system, x0=_grid_values(o.x0), progress=progress)
            except LibrateError as err:
                missing = getattr(err, "missing", None)
                if not missing:
                    raise
                raise StudyError([problem("orbits.x0", grid_raw(o.x0),
                                           f"no DRO reached at x0 = {', '.join(f'{v:g}' for v in missing)} (the continuation ended: {err.end_reason}); "
                                           f"{len(err.found)} of the requested members were found",
                                           "x0 values on the DRO family, between the Moon and the DRO that grazes the Earth (about 0.985 to 0.005)")]) from None
        kw = {"progress": progress} if o.max_members is None else {"max_members": o.max_members, "progress": progress}
        if o.kind == "lyapunov":
            return lyapunov_family(system, o.point or 1, **kw)
        return halo_family(system, o.point or 2, o.branch or "south", **kw)

    def build_orbits(self, family=None):
        """The orbits selected by [orbits]: an :class:`~librate.OrbitFamily` (DROs by x0, all
        members, or ``orbits.members`` of them evenly spread) or a list of corrected
        :class:`~librate.PeriodicOrbit` (by x0 or z0 for Lyapunov/halo, period_days, resonance,
        sun_resonance)."""
        o = self.orbits
        fam = family if family is not None else self.build_family()
        if o.members is not None:
            idx = np.unique(np.round(np.linspace(0, len(fam) - 1, min(o.members, len(fam)))).astype(int))
            return _subset(fam, idx)
        if o.kind == "dro" and o.x0 is not None:
            return fam  # dro_family(x0=...) computed exactly these members
        for key, find in (("x0", lambda v: fam.member(x0=float(v))), ("z0", lambda v: fam.member(z0=float(v))),
                          ("period_days", lambda v: fam.member(period_days=float(v))),
                          ("resonance", lambda k: fam.resonant(int(k), "synodic")), ("sun_resonance", lambda k: fam.resonant(int(k), "sun"))):
            sel = getattr(o, key)
            if sel is None:
                continue
            values = _grid_values(sel) if key in ("x0", "z0", "period_days") else sel
            out = []
            for v in values:
                try:
                    out.append(find(v))
                except ValueError as err:  # outside the family's range (or ambiguous): name the key and the range
                    cands = getattr(err, "candidates", None)
                    if cands:
                        days = ", ".join(f"{fam.system.period_days(c['period']):.4g}" for c in cands)
                        raise StudyError([problem(f"orbits.{key}", grid_raw(sel), f"{len(cands)} members of the {fam.kind} family have {key} = {float(v):g} "
                                                   f"(periods {days} d)",
                                                   "a value that one member has, or select by orbits.period_days")]) from None
                    span = {"x0": fam.x0, "z0": fam.z0, "period_days": fam.period_days,
                            "resonance": 2 * math.pi / fam.period, "sun_resonance": _sun_period() / fam.period}[key]
                    what = {"x0": "x0 (LU)", "z0": "z0 (LU)", "period_days": "periods (days)", "resonance": "k = 2 pi / T",
                            "sun_resonance": "k = Ts / T"}[key]
                    raise StudyError([problem(f"orbits.{key}", grid_raw(sel), f"no member at {float(v):g} on the {fam.kind} family ({len(fam)} members)",
                                               f"{what} from {np.min(span):.6g} to {np.max(span):.6g}")]) from None
            return out
        return fam

    def kz_values(self) -> np.ndarray:
        """The Kz value(s) of the body, (n,) array: ``body.kz`` or (Iy - Ix) / Iz."""
        b = self.body
        if b is None:
            raise ValueError("the study has no [body]")
        if b.flexible is not None:
            return np.array([self.build_flexible().rigid_body().kz])
        if b.kz is not None:
            return _grid_values(b.kz)
        return np.array([(b.iy - b.ix) / b.iz])

    def build_flexible(self):
        """The :class:`~librate.FlexibleBody` of ``body.flexible`` (a preset, or a TOML file
        relative to the study's folder), or None."""
        from ..attitude.flexible import FlexibleBody

        b = self.body
        if b is None or b.flexible is None:
            return None
        if b.flexible in FLEXIBLE_PRESETS:
            return FlexibleBody.preset(b.flexible)
        path = Path(self.base_dir) / b.flexible
        if not path.is_file():
            raise StudyError([problem("body.flexible", b.flexible, f"no such file: {path}", "an existing FlexibleBody TOML file")])
        return FlexibleBody.from_toml(path)

    def build_body(self):
        """The :class:`~librate.RigidBody` (moments in kg m^2 when given; else normalised from
        the single Kz), or None without [body] or with several Kz values."""
        from ..attitude.body import RigidBody

        b = self.body
        if b is None:
            return None
        if b.ix is not None:
            return RigidBody(b.ix, b.iy, b.iz, mass_kg=b.mass_kg)
        kz = self.kz_values()
        return RigidBody.from_kz(float(kz[0])) if kz.size == 1 else None

    def build_srp(self, system=None):
        """The :class:`~librate.FlatPlate` plate of [torques.srp], or None."""
        from ..attitude.srp import FlatPlate, Sun

        p = self.torques.srp
        if p is None:
            return None
        sun = Sun(theta0=p.theta_sun0) if p.pressure is None else Sun(theta0=p.theta_sun0, pressure=p.pressure)
        if p.eps is not None:
            return FlatPlate(p.eps, p.cs, p.cd, sun)
        return FlatPlate.from_geometry(system or self.build_system(), area_m2=p.area_m2, offset_m=p.offset_m, iz_kgm2=self.body.iz,
                                          cs=p.cs, cd=p.cd, sun=sun)

    def wz0_values(self) -> np.ndarray:
        """The inertial initial rates wz0 (1/TU), strictly increasing (``rates.phidot0`` + 1)."""
        r = self.rates
        if r is None:
            raise ValueError("the study has no [rates]")
        if r.wz0 is not None:
            return _grid_values(r.wz0)
        return _grid_values(r.phidot0) + 1.0

    def n_periods(self) -> int:
        """Orbit periods per attitude period: ``solver.n_periods``, else k for an SRP study on
        the 1:k Sun-resonant orbit, else 1."""
        if self.solver.n_periods is not None:
            return self.solver.n_periods
        if self.torques.srp is not None and self.orbits.sun_resonance:
            return int(self.orbits.sun_resonance[0])
        return 1

    def attitude_start(self) -> str | None:
        """How a 3-D solve starts ("planar", "spin" or "given"; see ``attitude.start``), None
        with the planar model."""
        return _start_of(self.attitude, self.orbits) if self.attitude.model == "3d" else None

    def q0_3d(self) -> np.ndarray:
        """The initial attitude of a 3-D study (scalar-last quaternion, body relative to the
        synodic frame): ``attitude.q0``, else the rotation by ``solver.phi0`` about Z."""
        if self.attitude.q0 is not None:
            q = np.asarray(self.attitude.q0, dtype=float)
            return q / np.linalg.norm(q)
        h = 0.5 * self.solver.phi0
        return np.array([0.0, 0.0, math.sin(h), math.cos(h)])

    def rates_3d(self) -> dict[str, np.ndarray]:
        """The initial rates of a 3-D map, ``{"wx0", "wy0", "wz0"}`` -> values (1/TU, inertial,
        body axes; a fixed rate is one value; ``rates.phidot0`` + 1 for wz0)."""
        r = self.rates
        if r is None:
            raise ValueError("the study has no [rates]")
        wz = _grid_values(r.wz0) if r.wz0 is not None else (None if r.phidot0 is None else _grid_values(r.phidot0) + 1.0)
        out = {"wx0": _grid_values(r.wx0), "wy0": _grid_values(r.wy0), "wz0": wz}
        return {k: v for k, v in out.items() if v is not None}

    def output_dir(self, out: str | Path | None = None) -> Path:
        """The output folder, absolute: ``out`` if given (relative to the working directory),
        else ``output.folder`` (relative to ``base_dir``, the study file's folder)."""
        if out is not None:
            return Path(out).resolve()
        p = Path(self.output.folder)
        return (p if p.is_absolute() else Path(self.base_dir) / p).resolve()

    def figures(self, available: tuple[str, ...]) -> list[str]:
        """The figures to draw among ``available`` (all of them unless ``output.figures``)."""
        want = self.output.figures
        return [f for f in available if want is None or f in want]

    def result_attrs(self, kind: str, command: str | None = None) -> dict:
        """Attributes every result carries: the result kind, the command that made it, the full
        study (JSON) and the package version."""
        from .._core import __version__

        return {"librate_result": kind, **({"librate_command": command} if command else {}), "study": self.to_json(),
                "librate_version": __version__}


def _sun_period() -> float:
    from ..constants import SUN_SYNODIC_PERIOD

    return SUN_SYNODIC_PERIOD


def _subset(fam, idx):
    import dataclasses

    return dataclasses.replace(
        fam, state0=fam.state0[idx], state_half=fam.state_half[idx], period=fam.period[idx], jacobi=fam.jacobi[idx],
        eigenvalues=fam.eigenvalues[idx], stability_indices=fam.stability_indices[idx], bifurcations=[],
        parameters={**fam.parameters, "members": [int(i) for i in idx]},
    )


def parse_value(text: str) -> Any:
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict, overrides: dict) -> dict:
    """A copy of ``data`` with dotted ``overrides`` applied (``{"rates.wz0.num": 50}``; string
    values are parsed as TOML values when they can be: ``"0.5"`` -> 0.5, ``"[1, 2]"`` -> a list,
    ``"{start = 0, stop = 1, num = 5}"`` -> a table; otherwise kept as strings)."""
    out = copy.deepcopy(data)
    for key, value in overrides.items():
        if isinstance(value, str):
            value = parse_value(value)
        parts = key.split(".")
        d = out
        for p in parts[:-1]:
            nxt = d.get(p)
            if not isinstance(nxt, dict):
                nxt = {}
                d[p] = nxt
            d = nxt
        d[parts[-1]] = value
    return out


# --- the example written by `librate init` ------------------------------------------------------
EXAMPLE_STUDY = '''\
# A librate study: everything one job needs, in one file.
#   librate family study.toml   the orbit family (continuation), saved with figures
#   librate solve  study.toml   the periodic attitude motions of each orbit in the rate window
#   librate map    study.toml   the attitude periodicity map (thesis Fig. 24) and its solutions
#   librate plot   librate-out/map.zarr   re-draw the figures from the saved result
# Units: nondimensional CR3BP units (LU, TU; rates in 1/TU, the synodic frame turns at 1),
# angles in rad, inertia in kg m^2, lengths in m, periods in days.
# Any key can be overridden on the command line: --set rates.wz0.num=200

title = "DRO attitude periodicity map at Kz = 0.8"

[system]
preset = "earth-moon"          # or: mu = 0.01215, lu_km = 384400, tu_s = 375190, radii_km = [6378, 1737]

[orbits]
kind = "dro"                   # "dro", "lyapunov" (point = 1|2) or "halo" (point, branch = "north"|"south")
x0 = { start = 0.9, stop = 0.3, num = 12 }    # members by x0 (LU); or a list [0.9, 0.8]
# period_days = [12.66]        # or by period (days)
# resonance = [1, 2]           # or synodic 1:k members (T = 2 pi / k)
# sun_resonance = [2]          # or Sun-resonant members (T = Ts / k), for SRP
# members = 20                 # or that many members evenly spread along the whole family

[body]
kz = 0.8                       # Kz = (Iy - Ix) / Iz in [-1, 1]; a list [0.2, 0.5, 0.8] maps several
# ix = 12.12e6                 # or the principal moments (kg m^2) instead of kz
# iy = 89.68e6
# iz = 96.95e6
# mass_kg = 4.0e5
# flexible = "sample-station"  # or a flexible spacecraft (a preset, or a FlexibleBody .toml file);
#                              # `librate solve` then reports how flexibility moves each solution

[torques]
gravity_gradient = ["earth", "moon"]   # the planar engine models both primaries
# [torques.srp]                # solar radiation pressure, a two-sided flat plate
# eps = 0.02                   # amplitude P A d TU^2 / Iz; or area_m2 = 100 and offset_m = 2 (needs ix/iy/iz)
# cs = 0.4                     # specular fraction; cd: diffuse fraction (cs + cd <= 1)
# theta_sun0 = 0.0             # Sun phase at t = 0 (rad)
# (SRP needs one Sun-resonant orbit: [orbits] sun_resonance = [2], and solver.n_periods = 2)

# [attitude]
# model = "3d"                 # the 3-D rigid body instead of the planar model (default "planar"):
#                              # needs body.ix/iy/iz, works on any family (halos too); `librate solve`
#                              # continues one periodic 3-D motion along the members
# n = -1                       # starting from the planar n-turn solution on the first member
#                              # (or start = "spin", the torque-free spin; or start = "given" with q0, w0)

[rates]
wz0 = { start = -3.0, stop = 2.0, num = 300 }   # inertial initial rates (1/TU), increasing
# phidot0 = { start = -4.0, stop = 1.0, num = 300 }   # or relative to the synodic frame (wz0 - 1)

[solver]
rtol = 1e-12
atol = 1e-12
n_periods = 1                  # orbit periods per attitude period
phi0 = 0.0                     # initial attitude angle (rad)

[output]
folder = "librate-out"         # relative to this file's folder
format = "zarr"                # "zarr" (chunked, resumable maps) or "netcdf" (also writes .nc)
figures = ["family", "period", "stability", "map", "residuals", "solutions"]
'''
