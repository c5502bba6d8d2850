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
:class:`~librate.FlatPlate` plate, the array of inertial initial rates); the jobs that the ``librate family``, ``librate solve`` and
``librate map`` commands run are in :mod:`librate.app.jobs`.

Units: rates in 1/TU (nondimensional: the synodic frame turns at rate 1), angles in rad, the
inertia in kg m^2, areas in m^2, lengths in m, the solar pressure in N/m^2, periods in days.
"""

from __future__ import annotations

import copy
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ConfigDict, Field, ValidationError

from .._errors import LibrateError
from .rules import common_rules, member_count, planar_rules, rules_3d, start_of
from .schema import (
    ATTITUDE_TOL,
    FIGURES,
    FLEXIBLE_PRESETS,
    PURPOSES,
    SECTIONS,
    Attitude3D,
    AttitudeSection,
    BodySection,
    EphemerisSection,
    Header,
    OrbitsSection,
    OutputSection,
    PlanarAttitude,
    RatesSection,
    SectionProblems,
    SolverSection,
    StudyError,
    SystemSection,
    Table,
    TorquesSection,
    grid_raw,
    grid_size,
    grid_values,
    problem,
)
from .schema_problems import pydantic_problems, unknown_key

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

# ATTITUDE_TOL, grid_raw, member_count and problem: the jobs (librate.app.jobs) read them from here.
__all__ = ["ATTITUDE_TOL", "EXAMPLE_STUDY", "FIGURES", "PURPOSES", "PlanarStudy", "Study", "Study3D", "StudyError", "grid_raw",
           "member_count", "problem"]

# --- the study -----------------------------------------------------------------------------------
class Study(Header):
    """A validated study (see the module docstring). Build it with :meth:`from_toml` or
    :meth:`from_dict`; it is immutable. ``base_dir`` is the folder relative output paths are
    taken from (the study file's folder, or the working directory).

    A study is one of a union discriminated by its attitude model, ``[attitude] model``: a
    :class:`PlanarStudy` or a :class:`Study3D` (a third model is one more subclass, with its
    [attitude] section, its rules between sections and its sizes). The jobs
    (:mod:`librate.app.jobs`) dispatch on that type."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)

    system: SystemSection = Field(default_factory=SystemSection)
    orbits: OrbitsSection = Field(default_factory=OrbitsSection)
    body: BodySection | None = None
    torques: TorquesSection = Field(default_factory=TorquesSection)
    rates: RatesSection | None = None
    attitude: AttitudeSection = Field(default_factory=PlanarAttitude)
    solver: SolverSection = Field(default_factory=SolverSection)
    output: OutputSection = Field(default_factory=OutputSection)
    ephemeris: EphemerisSection | None = None
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
        # Type problems are listed in the order of the file, then the sections' own rules (their
        # validators) in the order of SECTIONS, then the rules between sections. [system] and
        # [orbits] are validated first: the orbits' rules take the mass ratio, and the default
        # start of a 3-D [attitude] depends on the family.
        typed: dict[str, list[str]] = {}
        ruled: dict[str, list[str]] = {}
        sections: dict[str, Table] = {}
        context = {"mu": SystemSection().mass_ratio() if "system" not in data else None,
                   "orbits_kind": OrbitsSection().kind if "orbits" not in data else None}
        for key in sorted(data, key=lambda k: {"system": 0, "orbits": 1}.get(k, 2)):
            value = data[key]
            if key in ("title", "description"):
                if not isinstance(value, str):
                    typed[key] = [problem(key, value, "must be a string")]
            elif key in SECTIONS:
                if not isinstance(value, dict):
                    typed[key] = [problem(key, value, f"must be a table [{key}]",
                                          f"a table [{key}] with keys {', '.join(SECTIONS[key].model_fields)}")]
                    continue
                try:
                    sections[key] = SECTIONS[key].model_validate(value, context=context)
                except ValidationError as err:
                    ruled[key] = []
                    typed[key] = pydantic_problems(key, err, ruled[key])
                    if not typed[key]:  # the types are right, its own rules failed: the rules between sections still see it
                        found = [e["ctx"]["error"] for e in err.errors() if e["loc"] == ()
                                 and isinstance((e.get("ctx") or {}).get("error"), SectionProblems)]
                        if found:
                            sections[key] = found[0].section
                if key == "system" and key in sections:
                    context["mu"] = sections[key].mass_ratio()
                if key == "orbits" and key in sections:
                    context["orbits_kind"] = sections[key].kind
            else:
                typed[key] = [unknown_key(key, value)]
        problems = [p for key in data for p in typed.get(key, [])] + [p for key in SECTIONS for p in ruled.get(key, [])]
        # Sections left out take their defaults ([body] and [rates] have none); a section that
        # failed type validation is left out of the checks that involve it.
        valid: dict[str, Table] = {}
        for k, model in SECTIONS.items():
            if k in sections:
                valid[k] = sections[k]
            elif k not in data and k not in ("body", "rates", "ephemeris"):
                valid[k] = model.model_validate({}, context=context)
        model = _STUDY_OF.get(type(valid.get("attitude")), PlanarStudy)  # a failed [attitude] is checked as the default model
        problems += common_rules(valid, data, purpose) + model.rules_between(valid, data, purpose)
        if problems:
            raise StudyError(problems, source)
        if not issubclass(model, cls):
            raise StudyError([problem("attitude.model", valid["attitude"].model, f"a {cls.__name__} has another attitude model")], source)
        kwargs = {k: v for k, v in data.items() if k in ("title", "description")}
        study = model.model_construct(**kwargs, **valid, base_dir=str(base_dir if base_dir is not None else "."))
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
        return self._with_attitude(d)

    def _with_attitude(self, d: dict) -> dict:
        """``d`` (:meth:`to_dict`) with the model's [attitude] and its defaults written out."""
        raise NotImplementedError  # each model's subclass

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
                return dro_family(system, x0=grid_values(o.x0), progress=progress)
            except LibrateError as err:
                missing = getattr(err, "missing", None)
                if not missing:
                    raise
                raise StudyError([problem("orbits.x0", grid_raw(o.x0),
                                           f"no DRO reached at x0 = {', '.join(f'{v:g}' for v in missing)} (the continuation "
                                           f"ended: {err.end_reason}); {len(err.found)} of the requested members were found",
                                           "x0 values on the DRO family, between the Moon and the DRO that grazes the Earth "
                                           "(about 0.985 to 0.005)")]) from None
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
                          ("resonance", lambda k: fam.resonant(int(k), "synodic")),
                          ("sun_resonance", lambda k: fam.resonant(int(k), "sun"))):
            sel = getattr(o, key)
            if sel is None:
                continue
            values = grid_values(sel) if key in ("x0", "z0", "period_days") else sel
            out = []
            for v in values:
                try:
                    out.append(find(v))
                except ValueError as err:  # outside the family's range (or ambiguous): name the key and the range
                    cands = getattr(err, "candidates", None)
                    if cands:
                        days = ", ".join(f"{fam.system.period_days(c['period']):.4g}" for c in cands)
                        raise StudyError([problem(f"orbits.{key}", grid_raw(sel),
                                                   f"{len(cands)} members of the {fam.kind} family have {key} = {float(v):g} "
                                                   f"(periods {days} d)",
                                                   "a value that one member has, or select by orbits.period_days")]) from None
                    span = {"x0": fam.x0, "z0": fam.z0, "period_days": fam.period_days,
                            "resonance": 2 * math.pi / fam.period, "sun_resonance": _sun_period() / fam.period}[key]
                    what = {"x0": "x0 (LU)", "z0": "z0 (LU)", "period_days": "periods (days)", "resonance": "k = 2 pi / T",
                            "sun_resonance": "k = Ts / T"}[key]
                    raise StudyError([problem(f"orbits.{key}", grid_raw(sel),
                                               f"no member at {float(v):g} on the {fam.kind} family ({len(fam)} members)",
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
            return grid_values(b.kz)
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
            return grid_values(r.wz0)
        return grid_values(r.phidot0) + 1.0

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
        return None

    # --- the model's part: its rules between sections and its sizes -----------------------------
    @classmethod
    def rules_between(cls, s: dict[str, Table], given: dict, purpose: str | None) -> list[str]:
        """This model's rules between the sections that passed type validation (``s``; ``given``:
        the study as written), and what ``purpose`` needs (:mod:`librate.app.rules`)."""
        raise NotImplementedError  # each model's subclass

    def grid_factors(self, purpose: str) -> list[tuple[str, int]]:
        """(key, count) of each grid a ``purpose`` ("solve" or "map") runs over, besides the
        orbits (:func:`librate.app.budget.estimate`)."""
        raise NotImplementedError  # each model's subclass

    def map_bytes(self, n_orbits: int, row_cells: int) -> int:
        """The memory a map of ``n_orbits`` rows of ``row_cells`` cases takes (bytes)."""
        raise NotImplementedError  # each model's subclass

    def build_ephemeris(self):
        """The :class:`~librate.Ephemeris` of ``ephemeris.file`` (relative to the study's
        folder), or of the embedded DE440 excerpt; a StudyError names a file that cannot be read."""
        from ..ephemeris.model import Ephemeris

        f = self.ephemeris.file if self.ephemeris is not None else None
        if f is None:
            return Ephemeris()
        path = Path(f) if Path(f).is_absolute() else Path(self.base_dir) / f
        if not path.is_file():
            raise StudyError([problem("ephemeris.file", f, f"no such file: {path}")])
        try:
            return Ephemeris(path)
        except (OSError, ValueError) as err:
            raise StudyError([problem("ephemeris.file", f, f"not a readable SPK file with type-2 segments: {err}")]) from None

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


class PlanarStudy(Study):
    """A study of the planar attitude model (phi and wz; ``[attitude] model = "planar"``, the
    default: every study without [attitude])."""

    attitude: PlanarAttitude = Field(default_factory=PlanarAttitude)

    @classmethod
    def rules_between(cls, s: dict[str, Table], given: dict, purpose: str | None) -> list[str]:
        return planar_rules(s, given, purpose)

    def _with_attitude(self, d: dict) -> dict:
        d.pop("attitude", None)  # the default model: the stored study of a planar job is unchanged
        return d

    def grid_factors(self, purpose: str) -> list[tuple[str, int]]:
        out = []
        b, r = self.body, self.rates
        if b is not None and b.kz is not None:
            out.append(("body.kz", grid_size(b.kz)))
        if r is not None:
            k = "wz0" if r.wz0 is not None else "phidot0"
            out.append((f"rates.{k}", grid_size(getattr(r, k))))
        return out

    def map_bytes(self, n_orbits: int, row_cells: int) -> int:
        from .._checks import map_bytes

        return map_bytes(n_orbits, row_cells)


class Study3D(Study):
    """A study of the 3-D rigid body (quaternion and three rates; ``[attitude] model = "3d"``)."""

    attitude: Attitude3D

    @classmethod
    def rules_between(cls, s: dict[str, Table], given: dict, purpose: str | None) -> list[str]:
        return rules_3d(s, given, purpose)

    def _with_attitude(self, d: dict) -> dict:
        d["attitude"]["start"] = self.attitude_start()
        d["attitude"].setdefault("tol", ATTITUDE_TOL)
        return d

    def attitude_start(self) -> str:
        return start_of(self.attitude, self.orbits)

    @property
    def tol(self) -> float:
        """The 3-D corrector's tolerance: ``attitude.tol``, else :data:`ATTITUDE_TOL`."""
        return self.attitude.tol or ATTITUDE_TOL

    def q0_3d(self) -> np.ndarray:
        """The initial attitude (scalar-last quaternion, body relative to the synodic frame):
        ``attitude.q0``, else the rotation by ``solver.phi0`` about Z."""
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
        wz = grid_values(r.wz0) if r.wz0 is not None else (None if r.phidot0 is None else grid_values(r.phidot0) + 1.0)
        out = {"wx0": grid_values(r.wx0), "wy0": grid_values(r.wy0), "wz0": wz}
        return {k: v for k, v in out.items() if v is not None}

    def grid_factors(self, purpose: str) -> list[tuple[str, int]]:
        if purpose == "solve" or self.rates is None:
            return []  # a solve is one continuation along the members
        return [(f"rates.{k}", grid_size(g)) for k in ("wx0", "wy0", "wz0", "phidot0")
                if (g := getattr(self.rates, k)) is not None and grid_size(g) > 1]

    def map_bytes(self, n_orbits: int, row_cells: int) -> int:
        from .._checks import MAP3D_CELL_BYTES

        return n_orbits * row_cells * MAP3D_CELL_BYTES


#: The study's class by its [attitude] section's class (the union's discriminator).
_STUDY_OF: dict[type, type[Study]] = {PlanarAttitude: PlanarStudy, Attitude3D: Study3D}


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
