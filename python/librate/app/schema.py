"""The study schema: one pydantic model per TOML section, each key's type, range and description
on its field, and each section's own rules as its model's validator (``_rules``, raising
:class:`SectionProblems`); the error messages (every one names the dotted key, the value given and
what is allowed)."""

from __future__ import annotations

import json
import math
import re
import warnings
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, TypeAdapter, ValidationInfo, model_validator

#: What a study can be checked for (the commands that run it).
PURPOSES = ("family", "solve", "map", "transition")
#: Figure names accepted in ``output.figures`` ("multipliers" and "body_axes": 3-D solves; "attitude" and "pointing":
#: transitions with ephemeris.attitude_n).
FIGURES = ("family", "period", "stability", "map", "residuals", "solutions", "multipliers", "body_axes", "transition", "defects", "sweep",
           "attitude", "pointing")
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
class SectionProblems(ValueError):
    """What a section's rules (its model's validator) found, one line per problem naming its
    key; :func:`librate.app.schema_problems.pydantic_problems` lists them after the type problems. ``section``: the section
    as validated (its types are right), for the rules between sections."""

    def __init__(self, problems: list[str], section: BaseModel):
        super().__init__("; ".join(problems))
        self.problems = list(problems)
        self.section = section


def _rules_found(section: BaseModel, found: list[str]) -> BaseModel:
    if found:
        raise SectionProblems(found, section)
    return section


class Table(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)


class Range(Table):
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
    Annotated[KzValue, Tag("number")] | Annotated[list[KzValue], Field(min_length=1, max_length=MAX_GRID),
                                                  Tag("list")] | Annotated[Range, Tag("range")],
    Discriminator(_number_grid_tag, custom_error_type="grid",
                  custom_error_message="must be a number, a list of numbers or a table {start, stop, num}"),
]
RateGrid = Annotated[
    Annotated[float, Tag("number")] | Annotated[list[float], Field(min_length=1, max_length=MAX_GRID),
                                                Tag("list")] | Annotated[Range, Tag("range")],
    Discriminator(_number_grid_tag, custom_error_type="grid", custom_error_message=_RATE_MSG),
]
GRID_TAGS = {"list", "range", "number", "planar", "3d"}


class SystemSection(Table):
    """[system]: a preset, or a custom system from mu, lu_km, tu_s (and radii_km)."""

    preset: str | None = Field(None, description="one of the presets ({presets})")
    mu: float | None = Field(None, gt=0, le=0.5, description="a number in (0, 0.5], the mass ratio m2 / (m1 + m2)")
    lu_km: float | None = Field(None, gt=0, description="a number > 0, the length unit (distance between the primaries) in km")
    tu_s: float | None = Field(None, gt=0, description="a number > 0, the time unit (1 / mean motion) in s")
    radii_km: list[Annotated[float, Field(ge=0)]] | None = Field(None, min_length=2, max_length=2,
                                                                 description="two numbers >= 0, the primaries' radii in km")
    name: str | None = Field(None, description="a string")

    def mass_ratio(self) -> float | None:
        """The system's mass ratio mu when it is known (for the orbits' rules)."""
        from ..orbits.system import System

        if self.preset is not None:
            return System.preset(self.preset).mu if self.preset in System.presets() else None
        if any(getattr(self, k) is not None for k in ("mu", "lu_km", "tu_s", "radii_km")):
            return self.mu
        return System.preset("earth-moon").mu

    @model_validator(mode="after")
    def _rules(self) -> SystemSection:
        """The rules between this section's keys: a preset, or a custom system."""
        from ..orbits.system import System

        sysc, problems = self, []
        custom = [k for k in ("mu", "lu_km", "tu_s", "radii_km") if getattr(sysc, k) is not None]
        if sysc.preset is not None:
            if sysc.preset not in System.presets():
                problems.append(problem("system.preset", sysc.preset, "unknown preset"))
            for k in custom:
                problems.append(problem(f"system.{k}", getattr(sysc, k),
                                         "cannot be combined with system.preset (a preset fixes the constants)",
                                         "either system.preset alone, or system.mu, system.lu_km and system.tu_s (and "
                                         "optionally system.radii_km)"))
        elif custom:
            for k in ("mu", "lu_km", "tu_s"):
                if getattr(sysc, k) is None:
                    problems.append(missing(f"system.{k}",
                                            f"missing: a custom system (given {', '.join('system.' + c for c in custom)}) needs system.mu, "
                                            "system.lu_km and system.tu_s"))
        return _rules_found(self, problems)


class OrbitsSection(Table):
    """[orbits]: the family and the members wanted."""

    kind: Literal["dro", "lyapunov", "halo"] = Field("dro", description="'dro', 'lyapunov' or 'halo'")
    point: Literal[1, 2] | None = Field(None, description="1 (L1) or 2 (L2), for lyapunov and halo families")
    branch: Literal["north", "south"] | None = Field(None, description="'north' or 'south', for halo families")
    x0: Grid | None = Field(None, description="a list of x0 values (LU) or a table {start, stop, num}")
    z0: Grid | None = Field(None, description="a list of z0 values (LU) or a table {start, stop, num}, for halo families")
    period_days: Grid | None = Field(None, description="a list of periods (days) or a table {start, stop, num}")
    resonance: list[Annotated[int, Field(ge=1, le=100)]] | None = Field(None, min_length=1, max_length=100,
                                                                        description="a list of integers k >= 1 (synodic 1:k "
                                                                                    "members, T = 2 pi / k)")
    sun_resonance: list[Annotated[int, Field(ge=1, le=100)]] | None = Field(None, min_length=1, max_length=100,
                                                                            description="a list of integers k >= 1 (Sun-resonant "
                                                                                        "members, T = Ts / k)")
    members: int | None = Field(None, ge=1, le=10_000, description="an integer >= 1: that many members evenly spread along the family")
    max_members: int | None = Field(None, ge=2, le=5_000,
                                    description="an integer in [2, 5000], the continuation's length (lyapunov and halo)")

    @model_validator(mode="after")
    def _rules(self, info: ValidationInfo) -> OrbitsSection:
        """The rules between this section's keys (what applies to which family, one way to
        select the members, their ranges; the validation context's ``mu``: the system's mass
        ratio, when known)."""
        mu = (info.context or {}).get("mu")
        orb, problems = self, []
        if orb.kind == "dro":
            for k in ("point", "branch", "max_members"):
                if getattr(orb, k) is not None:
                    problems.append(problem(f"orbits.{k}", getattr(orb, k), "does not apply to orbits.kind = \"dro\"",
                                             "orbits.point and orbits.max_members for 'lyapunov' and 'halo', orbits.branch for 'halo'"))
        if orb.kind == "lyapunov" and orb.branch is not None:
            problems.append(problem("orbits.branch", orb.branch, "does not apply to orbits.kind = \"lyapunov\" (planar)",
                                    "orbits.branch only with orbits.kind = 'halo'"))
        if orb.kind != "halo" and orb.z0 is not None:
            problems.append(problem("orbits.z0", grid_raw(orb.z0), f"does not apply to orbits.kind = \"{orb.kind}\" (planar: z0 = 0)",
                                    "orbits.z0 only with orbits.kind = 'halo'"))
        sel = [k for k in ("x0", "z0", "period_days", "resonance", "sun_resonance", "members") if getattr(orb, k) is not None]
        if len(sel) > 1:
            for k in sel[1:]:
                problems.append(problem(f"orbits.{k}", grid_raw(getattr(orb, k)),
                                         f"cannot be combined with orbits.{sel[0]}: choose the members one way",
                                         "at most one of orbits.x0, z0, period_days, resonance, sun_resonance, members"))
        for k in ("x0", "z0", "period_days"):
            v = grid_values(getattr(orb, k))
            if v is None:
                continue
            if k == "x0" and mu is not None and orb.kind == "dro" and (np.any(v <= -mu) or np.any(v >= 1 - mu)):
                problems.append(problem("orbits.x0", grid_raw(orb.x0),
                                         f"DROs start between the primaries, -mu < x0 < 1 - mu = ({-mu:.6g}, {1 - mu:.6g})",
                                         "values in (-mu, 1 - mu)"))
            if k == "period_days" and np.any(v <= 0):
                problems.append(problem("orbits.period_days", grid_raw(orb.period_days), "periods must be > 0 days"))
        return _rules_found(self, problems)


FLEXIBLE_PRESETS = ("sample-station", "sample-station-low-frequency")
#: The 3-D corrector's default tolerance (``attitude.tol``).
ATTITUDE_TOL = 1e-12


class BodySection(Table):
    """[body]: Kz, or the principal moments of inertia in kg m^2, or a flexible spacecraft
    (``flexible``: a preset name or the path of a FlexibleBody TOML file)."""

    kz: KzGrid | None = Field(None, description="a number in [-1, 1] (Kz = (Iy - Ix) / Iz), a list of them or a table {start, stop, num}")
    ix: float | None = Field(None, gt=0, description="a number > 0, principal moment of inertia about x in kg m^2")
    iy: float | None = Field(None, gt=0, description="a number > 0, principal moment of inertia about y in kg m^2")
    iz: float | None = Field(None, gt=0, description="a number > 0, principal moment of inertia about z in kg m^2")
    mass_kg: float | None = Field(None, gt=0, description="a number > 0, the mass in kg")
    flexible: str | None = None

    @model_validator(mode="after")
    def _rules(self) -> BodySection:
        """The rules between this section's keys (Kz, the moments or a flexible body; the
        moments' triangle inequality; a Kz table within [-1, 1])."""
        body, problems = self, []
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
            problems.append(missing("body.kz", "missing: give body.kz, or body.ix, body.iy and body.iz in kg m^2 (or body.flexible)"))
        elif moments and len(moments) < 3:
            for k in ("ix", "iy", "iz"):
                if k not in moments:
                    problems.append(missing(f"body.{k}",
                                            "missing: the inertia needs all three of body.ix, body.iy, body.iz (given: "
                                            f"{', '.join('body.' + m for m in moments)})"))
        elif len(moments) == 3:
            ix, iy, iz = moments["ix"], moments["iy"], moments["iz"]
            for k, a, b, c in (("ix", ix, iy, iz), ("iy", iy, ix, iz), ("iz", iz, ix, iy)):
                if a > b + c:
                    problems.append(problem(f"body.{k}", a,
                                             f"violates the triangle inequality: {k} must not exceed the sum of the other two "
                                             f"moments ({b + c:g} kg m^2)",
                                             "principal moments with each <= the sum of the other two"))
                    break
        if isinstance(body.kz, Range):
            for k in ("start", "stop"):
                v = getattr(body.kz, k)
                if not -1 <= v <= 1:
                    problems.append(problem(f"body.kz.{k}", v, "Kz must be in [-1, 1]", "a number in [-1, 1]"))
        return _rules_found(self, problems)


class SrpSection(Table):
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

    @model_validator(mode="after")
    def _rules(self) -> SrpSection:
        """The rules between this section's keys (eps or the geometry; cs + cd <= 1)."""
        srp, problems = self, []
        geo = [k for k in ("area_m2", "offset_m") if getattr(srp, k) is not None]
        if srp.eps is not None and geo:
            for k in geo:
                problems.append(problem(f"torques.srp.{k}", getattr(srp, k),
                                         "cannot be combined with torques.srp.eps (eps follows from the geometry)",
                                         "either torques.srp.eps, or torques.srp.area_m2 and torques.srp.offset_m"))
        elif srp.eps is None and len(geo) < 2:
            absent = [k for k in ("area_m2", "offset_m") if k not in geo] if geo else ["eps"]
            for k in absent:
                problems.append(missing(f"torques.srp.{k}",
                                        "missing: the plate needs torques.srp.eps, or torques.srp.area_m2 and torques.srp.offset_m"))
        if srp.cs + srp.cd > 1 + 1e-12:
            problems.append(problem("torques.srp.cd", srp.cd,
                                    f"cs + cd = {srp.cs + srp.cd:g} exceeds 1 (the absorbed fraction is 1 - cs - cd)"))
        if srp.pressure is not None and srp.eps is not None:
            problems.append(problem("torques.srp.pressure", srp.pressure,
                                    "only used with the geometry (area_m2, offset_m); eps already includes it"))
        return _rules_found(self, problems)


class TorquesSection(Table):
    """[torques]: gravity gradient of the primaries, and solar radiation pressure."""

    gravity_gradient: list[Literal["earth", "moon"]] = Field(default_factory=lambda: ["earth", "moon"],
                                                             description="a list of primaries among 'earth' and 'moon'")
    srp: SrpSection | None = None

    @model_validator(mode="after")
    def _rules(self) -> TorquesSection:
        """The rules between this section's keys ([torques.srp] checks its own)."""
        problems: list[str] = []
        if len(set(self.gravity_gradient)) != len(self.gravity_gradient):
            problems.append(problem("torques.gravity_gradient", self.gravity_gradient, "a primary is listed twice"))
        return _rules_found(self, problems)


class RatesSection(Table):
    """[rates]: the initial rates, inertial wz0 or relative phidot0 = wz0 - 1 (1/TU); for a 3-D
    map also wx0 and wy0 (inertial, body axes): two grids and one fixed number."""

    wz0: RateGrid | None = Field(None,
                                 description="a list of inertial initial rates (1/TU), strictly increasing, or a table {start, stop, num} "
                                             "with start < stop, num >= 2")
    phidot0: RateGrid | None = Field(None,
                                     description="a list of initial rates relative to the synodic frame (1/TU), strictly increasing, or a "
                                                 "table {start, stop, num} with start < stop, num >= 2")
    wx0: RateGrid | None = Field(None,
                                 description="for attitude.model = '3d' maps: a number (fixed) or a grid of inertial initial rates about "
                                             "body x (1/TU): a strictly increasing list or a table {start, stop, num} with "
                                             "start < stop, num >= 2")
    wy0: RateGrid | None = Field(None,
                                 description="for attitude.model = '3d' maps: a number (fixed) or a grid of inertial initial rates about "
                                             "body y (1/TU): a strictly increasing list or a table {start, stop, num} with "
                                             "start < stop, num >= 2")


class AttitudeSection(Table):
    """[attitude]: the attitude model ("planar" or "3d") and how a 3-D solve starts."""

    model: Literal["planar", "3d"] = Field("planar",
                                           description="'planar' (the default: the planar model, phi and wz) or '3d' (the 3-D rigid body, "
                                                       "quaternion and three rates)")
    start: Literal["planar", "spin", "given"] | None = Field(None,
                                                             description="'planar' (the planar N-family solution on the first member, "
                                                                         "planar families), 'spin' (the torque-free spin wz0 = 1 + 2 pi n "
                                                                         "/ (K T) about synodic Z) or 'given' (attitude.q0 and "
                                                                         "attitude.w0), with attitude.model = '3d'")
    n: int | None = Field(None, ge=-100, le=100,
                          description="an integer in [-100, 100], net turns about synodic Z per attitude period, with attitude.start "
                                      "= 'planar' or 'spin' (a transition takes each N from ephemeris.attitude_n instead)")
    q0: list[float] | None = Field(None, min_length=4, max_length=4,
                                   description="four numbers, a unit quaternion (scalar last): the body relative to the synodic frame at t "
                                               "= 0, with attitude.start = 'given' or 'spin'")
    w0: list[float] | None = Field(None, min_length=3, max_length=3,
                                   description="three numbers, the inertial rate in body axes (1/TU), with attitude.start = 'given'")
    tol: float | None = Field(None, ge=1e-14, le=1e-6,
                              description="a number in [1e-14, 1e-6], the 3-D corrector's tolerance on the closure (default "
                                          "1e-12; 1e-10 for NRHOs)")

    @classmethod
    def model_validate(cls, obj: Any, **kwargs: Any) -> AttitudeSection:
        """[attitude] is a union discriminated by ``model``: :class:`PlanarAttitude` or
        :class:`Attitude3D` (a third model, e.g. the ephemeris, is one more member)."""
        if cls is AttitudeSection:
            return _ATTITUDE.validate_python(obj, **kwargs)
        return super().model_validate(obj, **kwargs)


_3D_KEYS = ("start", "n", "q0", "w0", "tol")


class PlanarAttitude(AttitudeSection):
    """[attitude] model = "planar" (the default): the planar model, phi and wz."""

    model: Literal["planar"] = "planar"

    @model_validator(mode="after")
    def _rules(self) -> PlanarAttitude:
        """The 3-D keys do not apply to the planar model."""
        return _rules_found(self, [problem(f"attitude.{k}", getattr(self, k), "applies only to attitude.model = \"3d\"",
                                           "attitude.model = '3d' with it, or leave it out") for k in _3D_KEYS
                                   if getattr(self, k) is not None])


class Attitude3D(AttitudeSection):
    """[attitude] model = "3d": the 3-D rigid body (quaternion and three rates), and how a solve starts."""

    model: Literal["3d"]

    def start_on(self, orbits_kind: str | None) -> str:
        """How a 3-D solve starts: ``start``, else "given" with ``w0``, else "spin" on a halo
        family, else "planar"."""
        if self.start is not None:
            return self.start
        if self.w0 is not None:
            return "given"
        return "spin" if orbits_kind == "halo" else "planar"

    @model_validator(mode="after")
    def _rules(self, info: ValidationInfo) -> Attitude3D:
        """The rules between this section's keys: what each start takes (the validation
        context's ``orbits_kind`` decides the default start), and a unit ``q0``."""
        start = self.start_on((info.context or {}).get("orbits_kind"))
        problems: list[str] = []
        if start == "planar":
            for k in ("q0", "w0"):
                if getattr(self, k) is not None:
                    problems.append(problem(f"attitude.{k}", getattr(self, k),
                                             "cannot be combined with attitude.start = \"planar\" (the start is the planar solution: "
                                             "phi0 = solver.phi0 about Z, wz0 from the rates.wz0 scan)",
                                             "attitude.q0 and attitude.w0 with attitude.start = 'given'"))
        elif start == "spin" and self.w0 is not None:
            problems.append(problem("attitude.w0", self.w0,
                                     "cannot be combined with attitude.start = \"spin\" (the spin is w = (1 + 2 pi n / (K T)) e_Z)",
                                     "attitude.w0 with attitude.start = 'given'"))
        # a missing attitude.n is a rule between sections (rules_3d): ephemeris.attitude_n may stand in for it
        if start == "given":
            if self.w0 is None:
                problems.append(missing("attitude.w0",
                                        "missing: attitude.start = \"given\" starts from attitude.w0 (and attitude.q0, "
                                        "default the identity)"))
            if self.n is not None:
                problems.append(problem("attitude.n", self.n,
                                         "does not apply to attitude.start = \"given\" (the start is attitude.q0, attitude.w0)",
                                         "attitude.n with attitude.start = 'planar' or 'spin'"))
        if self.q0 is not None and abs(math.hypot(*self.q0) - 1) > 1e-6:  # finite: the schema refuses inf and nan
            problems.append(problem("attitude.q0", self.q0, f"must be a unit quaternion (|q0| = {math.hypot(*self.q0):.6g})"))
        return _rules_found(self, problems)


def _model_tag(v: Any) -> str | None:
    if isinstance(v, dict):
        m = v.get("model", "planar")
        return m if m in ("planar", "3d") else None
    return getattr(v, "model", None)


_ATTITUDE = TypeAdapter(Annotated[Annotated[PlanarAttitude, Tag("planar")] | Annotated[Attitude3D, Tag("3d")],
                                  Discriminator(_model_tag, custom_error_type="attitude_model",
                                                custom_error_message="must be 'planar' or '3d'")])




# --- [ephemeris] ----------------------------------------------------------------------------------
#: The most epochs of one [ephemeris] section (a list, or a range's count).
MAX_EPOCHS = 10_000
#: The most attitude solutions one transition carries (``ephemeris.attitude_n``).
MAX_ATTITUDES = 8
_EPOCH_TEXT = "an ISO string with a time scale ('2030-01-01T00:00:00 TDB', or UTC, TT) or TDB seconds past J2000"
EpochValue = Annotated[float | int | str, Field(description=_EPOCH_TEXT)]


class EpochRange(Table):
    """Epochs from ``start`` to ``stop`` (included when it falls on a step), every ``step_days``."""

    start: float | int | str = Field(description="the first epoch: " + _EPOCH_TEXT)
    stop: float | int | str = Field(description="the last epoch (included when it falls on a step): " + _EPOCH_TEXT + ", not before start")
    step_days: float = Field(gt=0, le=36_525, description="a number in (0, 36525], the days between epochs (TDB)")


def _epoch_tag(v: Any) -> str | None:
    if isinstance(v, (dict, EpochRange)):
        return "range"
    if isinstance(v, (list, tuple)):
        return "list"
    if isinstance(v, (int, float, str)) and not isinstance(v, bool):
        return "number"
    return None


_EPOCHS_MSG = "must be an epoch (an ISO string with a scale, or TDB seconds past J2000), a list of them or a table {start, stop, step_days}"
Epochs = Annotated[
    Annotated[EpochValue, Tag("number")] | Annotated[list[EpochValue], Field(min_length=1, max_length=MAX_EPOCHS), Tag("list")]
    | Annotated[EpochRange, Tag("range")],
    Discriminator(_epoch_tag, custom_error_type="grid", custom_error_message=_EPOCHS_MSG),
]


def _embedded_span() -> tuple[float, float]:
    from ..ephemeris.model import Ephemeris

    if not _SPAN:
        _SPAN.append(Ephemeris().span)
    return _SPAN[0]


_SPAN: list[tuple[float, float]] = []


class EphemerisSection(Table):
    """[ephemeris]: the epochs at which the study's orbit is carried into the Earth-Moon-Sun
    ephemeris model (``librate transition``), over how many revolutions, and the SPK file."""

    epoch: Epochs = Field(description="an epoch (" + _EPOCH_TEXT + "), a list of them, or a table {start, stop, step_days} "
                          f"(at most {MAX_EPOCHS} epochs), within the ephemeris file's span")
    revolutions: int = Field(10, ge=1, le=100,
                             description="an integer in [1, 100], the orbit's revolutions carried into the ephemeris model")
    nodes_per_rev: int | None = Field(None, ge=2, le=100, description="an integer in [2, 100], the multiple-shooting nodes per revolution "
                                      "(default: the transition's own choice for the orbit)")
    file: str | None = Field(None, min_length=1, description="the path of a JPL SPK file with type-2 segments of the Sun, the Earth-Moon "
                             "barycentre, the Moon and the Earth (relative paths from the study file's folder); default the embedded DE440 "
                             "excerpt, 2020-2070")
    attitude_n: list[Annotated[int, Field(ge=-100, le=100)]] | None = Field(
        None, min_length=1, max_length=MAX_ATTITUDES,
        description=f"a list of at most {MAX_ATTITUDES} distinct integers N in [-100, 100]: for each N, the first periodic attitude "
        "solution with N net turns that `librate solve` finds on the orbit ([body], [rates], [solver]; with attitude.model = '3d', "
        "the 3-D motion started with n = N, attitude.n not needed) is carried along the ephemeris orbit at every epoch and corrected")

    def epochs_tdb(self) -> np.ndarray:
        """The epochs in TDB seconds past J2000, (n,) (a range: start + k step, up to stop)."""
        from ..ephemeris.epochs import tdb_seconds

        e = self.epoch
        if isinstance(e, EpochRange):
            t0, t1, step = tdb_seconds(e.start), tdb_seconds(e.stop), e.step_days * 86400.0
            n = int(math.floor((t1 - t0) / step * (1 + 1e-12) + 1e-9)) + 1
            return t0 + step * np.arange(n)
        return np.array([tdb_seconds(v) for v in (e if isinstance(e, list) else [e])], dtype=float)

    @model_validator(mode="after")
    def _rules(self) -> EphemerisSection:
        """Every epoch readable, a range running forwards with at most MAX_EPOCHS steps, and
        (with the embedded file) every epoch within its span."""
        from ..ephemeris.epochs import iso_tdb, tdb_seconds

        problems: list[str] = []
        e = self.epoch
        items = [("start", e.start), ("stop", e.stop)] if isinstance(e, EpochRange) else (
            [(f"[{i}]", v) for i, v in enumerate(e)] if isinstance(e, list) else [("", e)])
        bad = False
        for where, v in items:
            key = "ephemeris.epoch" + (f".{where}" if where and not where.startswith("[") else where)
            try:
                tdb_seconds(v)
            except ValueError as err:
                bad = True
                problems.append(problem(key, v, str(err).removeprefix("epoch: "), _EPOCH_TEXT))
        if not bad and isinstance(e, EpochRange):
            t0, t1 = tdb_seconds(e.start), tdb_seconds(e.stop)
            if t1 < t0:
                bad = True
                problems.append(problem("ephemeris.epoch.stop", e.stop, f"is before ephemeris.epoch.start = {show_value(e.start)}",
                                        "an epoch not before ephemeris.epoch.start"))
            elif (t1 - t0) / (e.step_days * 86400.0) + 1 > MAX_EPOCHS:
                bad = True
                problems.append(problem("ephemeris.epoch.step_days", e.step_days,
                                        f"gives {int((t1 - t0) / (e.step_days * 86400.0)) + 1} epochs from start to stop",
                                        f"a step giving at most {MAX_EPOCHS} epochs"))
        if self.attitude_n is not None and len(set(self.attitude_n)) != len(self.attitude_n):
            problems.append(problem("ephemeris.attitude_n", self.attitude_n, "an N is listed twice"))
        if not bad and self.file is None:
            lo, hi = _embedded_span()
            t = self.epochs_tdb()
            out = np.flatnonzero((t < lo) | (t >= hi))
            if out.size:
                key = "ephemeris.epoch" + ("" if not isinstance(e, list) else f"[{int(out[0])}]")
                shown = e.model_dump() if isinstance(e, EpochRange) else (e[int(out[0])] if isinstance(e, list) else e)
                problems.append(problem(key, shown, f"{iso_tdb(float(t[out[0]]))} is outside the embedded DE440 excerpt",
                                        f"epochs from {iso_tdb(lo)} to {iso_tdb(hi)} (less the revolutions' duration), or ephemeris.file"))
        return _rules_found(self, problems)


class SolverSection(Table):
    """[solver]: tolerances, periods per solution, initial angle."""

    rtol: float = Field(1e-12, ge=1e-15, le=1e-3, description="a number in [1e-15, 1e-3]")
    atol: float = Field(1e-12, ge=1e-15, le=1e-3, description="a number in [1e-15, 1e-3]")
    n_periods: int | None = Field(None, ge=1, le=1000, description="an integer in [1, 1000], orbit periods per attitude period")
    phi0: float = Field(0.0, ge=-2 * math.pi, le=2 * math.pi, description="a number in [-2 pi, 2 pi], the initial attitude angle in rad")


class OutputSection(Table):
    """[output]: where and how results are written."""

    folder: str = Field("librate-out", min_length=1, description="a non-empty path (relative paths are taken from the study file's folder)")
    format: Literal["zarr", "netcdf"] = Field("zarr", description="'zarr' or 'netcdf'")
    figures: list[Literal[FIGURES]] | None = Field(None, description=FIGURES_TEXT)


SECTIONS: dict[str, type[Table]] = {
    "system": SystemSection,
    "orbits": OrbitsSection,
    "body": BodySection,
    "torques": TorquesSection,
    "rates": RatesSection,
    "attitude": AttitudeSection,
    "solver": SolverSection,
    "output": OutputSection,
    "ephemeris": EphemerisSection,
}
TABLES: dict[str, type[Table]] = {**SECTIONS, "torques.srp": SrpSection, "ephemeris.epoch": EpochRange}
TOP_KEYS = ("title", "description", *SECTIONS)

def _described(model: type[BaseModel], name: str) -> str | None:
    f = model.model_fields.get(name)
    return f.description if f is not None else None


def _allowed(key: str) -> str | None:
    """What ``key`` accepts: the description on its field (a grid's start, stop, num: Range's)."""
    base = re.sub(r"\[\d+\]", "", key)
    parent, _, name = base.rpartition(".")
    model = Header if parent == "" else TABLES.get(parent)
    text = _described(model, name) if model is not None else None
    if text is None:
        text = _described(Range, name)
    if text and "{presets}" in text:
        from ..orbits.system import System

        text = text.format(presets=", ".join(repr(p) for p in System.presets()))
    return text


def show_value(value: Any) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {show_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(show_value(v) for v in value) + "]"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


def problem(key: str, value: Any, message: str, allowed: str | None = None) -> str:
    allowed = _allowed(key) if allowed is None else allowed
    text = f"{key} = {show_value(value)}: {message}"
    return text + (f"; allowed: {allowed}" if allowed else "")


def missing(key: str, message: str) -> str:
    allowed = _allowed(key)
    return f"{key}: {message}" + (f"; allowed: {allowed}" if allowed else "")


# --- checks beyond the types -------------------------------------------------------------------
def grid_values(g) -> np.ndarray | None:
    if g is None:
        return None
    if isinstance(g, Range):
        return g.values()
    if isinstance(g, (int, float)):
        return np.array([float(g)])
    return np.asarray(g, dtype=float)


def grid_size(g) -> int:
    """The number of values of a grid (a number: 1; a list; a table {start, stop, num}), from
    its size alone (nothing is allocated)."""
    if g is None or isinstance(g, (int, float)):
        return 1
    return int(g.num) if isinstance(g, Range) else len(g)


def grid_raw(g) -> Any:
    if isinstance(g, Range):
        return g.model_dump()
    return g



class Header(Table):
    """The study's top-level keys that are not sections."""

    title: str | None = Field(None, description="a string")
    description: str | None = Field(None, description="a string")
