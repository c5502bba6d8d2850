"""The JSON format of the NASA/JPL Three-Body Periodic Orbits API (the JPL periodic-orbit catalog).

A response of ``https://ssd-api.jpl.nasa.gov/periodic_orbits.api?sys=...&family=...`` is one JSON
object: ``signature`` (source, version), ``system`` (``name``, ``mass_ratio``, ``lunit`` km,
``tunit`` s, ``radius_secondary`` km, ``L1``..``L5``), ``family``, ``libration_point``,
``branch``, ``count``, ``limits``, ``fields`` (x, y, z, vx, vy, vz, jacobi, period,
stability) and ``data``, one row per orbit: the state at one perpendicular x-z-plane crossing
(nondimensional, the synodic frame with the larger primary at (-mu, 0, 0)), the Jacobi
constant, the period (TU) and a stability index. Numbers come as strings or as JSON numbers.

This module reads such a response into a :class:`JplCatalog`, re-corrects its rows in librate's
dynamics (:func:`recorrect`), and writes a family in the same format (:func:`jpl_document`).
:meth:`librate.OrbitFamily.from_jpl` and :meth:`~librate.OrbitFamily.to_jpl` are the entry points.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .periodic import SHOOT_ATOL, SHOOT_RTOL, PeriodicOrbit, correct_symmetric, primary_passes
from .propagation import propagate_many
from .system import System

__all__ = ["JplCatalog", "read_jpl", "recorrect", "order_along_family", "jpl_stability", "kind_from_jpl", "jpl_names", "jpl_document"]

#: The row fields librate reads and writes, in the API's order.
JPL_FIELDS = ("x", "y", "z", "vx", "vy", "vz", "jacobi", "period", "stability")
_STATE = ("x", "y", "z", "vx", "vy", "vz")

#: A row is at a perpendicular x-z-plane crossing (what the symmetric corrector starts from) when
#: |y|, |vx| and |vz| are below this (LU, LU/TU). The catalog's rows have them below 1e-8.
CROSSING_TOL = 1e-6

#: A re-corrected row farther than this (max-norm of the state difference, LU and LU/TU) from the
#: catalog's state is reported as a different orbit, not as that row.
SAME_ORBIT_TOL = 1e-5


@dataclass
class JplCatalog:
    """One parsed API response: the system (a librate :class:`System`), the header (everything
    but ``data``, as read) and the rows: ``states`` (n, 6), ``period`` (n,), ``jacobi`` and
    ``stability`` (n,; NaN where the file has no such field)."""

    system: System
    header: dict
    states: np.ndarray
    period: np.ndarray
    jacobi: np.ndarray
    stability: np.ndarray

    @property
    def family(self) -> str:
        return str(self.header.get("family", "unknown"))

    @property
    def libration_point(self) -> str | None:
        v = self.header.get("libration_point")
        return None if v in (None, "") else str(v)

    @property
    def branch(self) -> str | None:
        v = self.header.get("branch")
        return None if v in (None, "") else str(v)


def _number(v, what: str) -> float:
    try:
        x = float(v.strip()) if isinstance(v, str) else float(v)
    except (TypeError, ValueError, AttributeError):
        raise ValueError(f"not a JPL periodic-orbit response: {what} is not a number ({v!r})") from None
    if not math.isfinite(x):
        raise ValueError(f"not a JPL periodic-orbit response: {what} is not finite ({v!r})")
    return x


def _system(block: dict) -> System:
    """The librate system of a response: a preset when mass ratio and units match one (its
    radii then apply, e.g. earth-moon-jpl), else a new System with the file's constants, the
    secondary's radius ``radius_secondary`` and an unknown (0) primary radius."""
    mu = _number(block.get("mass_ratio"), "system.mass_ratio")
    lu = _number(block.get("lunit"), "system.lunit")
    tu = _number(block.get("tunit"), "system.tunit")
    for name in System.presets():
        p = System.preset(name)
        if all(abs(a - b) <= 1e-12 * abs(b) for a, b in ((p.mu, mu), (p.lu_km, lu), (p.tu_s, tu))):
            return p
    r2 = _number(block["radius_secondary"], "system.radius_secondary") if block.get("radius_secondary") not in (None, "") else 0.0
    name = "jpl-" + "-".join(str(block.get("name", "system")).lower().split())
    return System(mu=mu, lu_km=lu, tu_s=tu, r1_km=0.0, r2_km=r2, name=name)


def read_jpl(source) -> JplCatalog:
    """Parse a JPL Three-Body Periodic Orbits API response: a dict, or the path of its JSON file.

    Raises ``FileNotFoundError``, or ``ValueError`` naming what is missing or malformed (an API
    error response is reported with its message)."""
    if isinstance(source, dict):
        doc = source
        where = "the response"
    else:
        p = Path(source)
        if not p.is_file():
            raise FileNotFoundError(f"no JPL periodic-orbit file at {str(source)!r}")
        try:
            doc = json.loads(p.read_text(encoding="utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as err:
            raise ValueError(f"{str(source)!r} is not a JPL periodic-orbit response: not JSON ({err})") from None
        where = repr(str(source))
    if not isinstance(doc, dict):
        raise ValueError(f"{where} is not a JPL periodic-orbit response: the JSON is a {type(doc).__name__}, not an object")
    if "data" not in doc and ("message" in doc or "error" in doc):
        raise ValueError(f"{where} is a JPL API error response: {doc.get('message', doc.get('error'))!r}")
    missing = [k for k in ("system", "fields", "data") if k not in doc]
    if missing:
        raise ValueError(f"{where} is not a JPL periodic-orbit response: missing {', '.join(missing)}")
    fields = doc["fields"]
    if not isinstance(fields, list) or any(f not in fields for f in (*_STATE, "period")):
        raise ValueError(f"{where}: `fields` must list x, y, z, vx, vy, vz and period, got {fields!r}")
    if not isinstance(doc["system"], dict):
        raise ValueError(f"{where}: `system` must be an object")
    system = _system(doc["system"])
    rows = doc["data"]
    if not isinstance(rows, list) or not rows:
        raise ValueError(f"{where} holds no orbit (count {doc.get('count')!r})")
    n = len(rows)
    col = {f: i for i, f in enumerate(fields)}
    table = np.full((n, len(JPL_FIELDS)), np.nan)
    for r, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != len(fields):
            raise ValueError(f"{where}: data row {r} has {len(row) if isinstance(row, list) else 'no'} values, fields has {len(fields)}")
        for j, f in enumerate(JPL_FIELDS):
            if f in col:
                table[r, j] = _number(row[col[f]], f"data row {r} field {f}")
    if np.any(table[:, 7] <= 0):
        raise ValueError(f"{where}: data row {int(np.argmax(table[:, 7] <= 0))} has a period <= 0")
    header = {k: v for k, v in doc.items() if k != "data"}
    return JplCatalog(system, header, np.ascontiguousarray(table[:, :6]), table[:, 7].copy(), table[:, 6].copy(), table[:, 8].copy())


def kind_from_jpl(family: str, libration_point: str | None, branch: str | None) -> str:
    """librate's family name for a catalog family: ``halo-L2-south``, ``lyapunov-L1``, ``dro``;
    other families keep the catalog's words (``butterfly-north``, ``resonant-21``)."""
    name = str(family).lower()
    if libration_point:
        name += f"-L{libration_point}"
    if branch:
        name += "-" + {"N": "north", "S": "south", "E": "east", "W": "west"}.get(str(branch).upper(), str(branch))
    return name


def jpl_names(kind: str, parameters: dict) -> tuple[str, str | None, str | None]:
    """The catalog's (family, libration_point, branch) for a librate family."""
    if "jpl_family" in parameters:
        return parameters["jpl_family"], parameters.get("jpl_libration_point"), parameters.get("jpl_branch")
    parts = kind.split("-")
    family = parts[0]
    point = next((p[1:] for p in parts[1:] if p.startswith("L") and p[1:].isdigit()), None)
    branch = {"north": "N", "south": "S"}.get(str(parameters.get("branch", "")), None)
    return family, point, branch


def jpl_stability(eigenvalues) -> np.ndarray:
    """The catalog's single stability index of each orbit, (|lambda| + 1/|lambda|) / 2 of the
    monodromy eigenvalue largest in modulus: 1 for a linearly stable orbit, above 1 otherwise."""
    ev = np.atleast_2d(np.asarray(eigenvalues))
    big = np.max(np.abs(ev), axis=1)
    return 0.5 * (big + 1.0 / big)


def _closures(system: System, states: np.ndarray, periods: np.ndarray) -> np.ndarray:
    """max-norm |x(T) - x(0)| of each state over its period (point masses; NaN if it fails)."""
    out = np.full(len(states), np.nan)
    if len(states) == 0:
        return out
    b = propagate_many(system, states, periods, rtol=SHOOT_RTOL, atol=SHOOT_ATOL, on_error="mask", collision="point")
    ok = b.ok
    out[ok] = np.max(np.abs(b.y[ok] - states[ok]), axis=1)
    return out


def recorrect(cat: JplCatalog, kind: str, spatial: bool):
    """Re-correct every row of ``cat`` in librate's dynamics (the catalog's mass ratio).

    Each row is first propagated over its period with the primaries' radii (the system's: for
    the Earth-Moon catalog, the earth-moon-jpl preset's 6371.0084 and 1737.4 km): a row that
    passes within a primary's radius is flagged and not re-corrected. Every other row at a
    perpendicular x-z-plane crossing is corrected by half-period shooting
    (:func:`librate.correct_symmetric`) with the catalog's period imposed (x0 fixed instead if
    that fails), starting from the row's state, so the member stays at the row's crossing.

    Returns ``(members, rows, report)``: the corrected orbits, the row index of each, and an
    xarray Dataset over the file's rows (``row``) with the catalog's state, period, Jacobi
    constant and stability, ``closure_before`` and ``closure_after`` (max-norm |x(T) - x(0)| of
    the catalog's and the corrected state over their periods, LU and LU/TU), ``delta_state``
    (max-norm corrected - catalog), ``status`` (``corrected``, ``inside Earth radius``,
    ``inside Moon radius``, ``not a perpendicular x-z crossing``, ``correction failed: ...``,
    ``converged to another orbit``), the flags ``within_primary1_radius`` /
    ``within_primary2_radius`` and ``member`` (the member index, -1 when not corrected).
    """
    import xarray as xr

    from .._errors import ConvergenceError

    system = cat.system
    n = len(cat.period)
    before = _closures(system, cat.states, cat.period)
    radius_run = primary_passes(system, cat.states, cat.period)
    inside1 = radius_run.status == "collision_primary1"
    inside2 = radius_run.status == "collision_primary2"
    names = ("Earth", "Moon") if system.name.startswith("earth-moon") else ("primary 1", "primary 2")
    status = np.full(n, "", dtype=object)
    after = np.full(n, np.nan)
    delta = np.full(n, np.nan)
    corrected = np.full((n, 6), np.nan)
    period_c = np.full(n, np.nan)
    member = np.full(n, -1, dtype=np.int64)
    members: list[PeriodicOrbit] = []
    rows: list[int] = []
    for i in range(n):
        s = cat.states[i]
        if inside1[i] or inside2[i]:
            k = 0 if inside1[i] else 1
            status[i] = f"inside {names[k]} radius ({(system.r1_km, system.r2_km)[k]} km): not re-corrected"
            continue
        if radius_run.status[i] == "failed":
            status[i] = f"propagation failed: {radius_run.errors.get(i)}"
            continue
        if max(abs(s[1]), abs(s[3]), abs(s[5])) > CROSSING_TOL:
            status[i] = "not a perpendicular x-z crossing: not re-corrected (librate corrects x-z-symmetric orbits)"
            continue
        orbit = None
        why = ""
        for kw in (dict(period=float(cat.period[i])), dict(fix="x0")):
            try:
                orbit = correct_symmetric(system, s, spatial=spatial, family=kind, tol=1e-12, max_iter=25, collision=None, **kw)
                break
            except ConvergenceError as err:
                why = str(err).splitlines()[0]
        if orbit is None:
            status[i] = f"correction failed: {why}"
            continue
        corrected[i] = orbit.state0
        period_c[i] = orbit.period
        delta[i] = float(np.max(np.abs(orbit.state0 - s)))
        if delta[i] > SAME_ORBIT_TOL:
            status[i] = f"converged to another orbit ({delta[i]:.3g} from the row's state): not kept"
            continue
        status[i] = "corrected"
        rows.append(i)
        members.append(orbit)
    ok = ~np.isnan(period_c)
    after[ok] = _closures(system, corrected[ok], period_c[ok])
    member[np.array(rows, dtype=np.intp)] = np.arange(len(rows))
    comp = list(_STATE)
    report = xr.Dataset(
        {
            "state_catalog": (("row", "component"), cat.states, {"units": "LU, LU/TU"}),
            "period_catalog": ("row", cat.period, {"units": "TU"}),
            "jacobi_catalog": ("row", cat.jacobi),
            "stability_catalog": ("row", cat.stability),
            "state_corrected": (("row", "component"), corrected, {"units": "LU, LU/TU"}),
            "period_corrected": ("row", period_c, {"units": "TU"}),
            "closure_before": ("row", before, {"long_name": "max |x(T) - x(0)| of the catalog's state over its period"}),
            "closure_after": ("row", after, {"long_name": "max |x(T) - x(0)| of the corrected state over its period"}),
            "delta_state": ("row", delta, {"long_name": "max |corrected - catalog| of the state"}),
            "within_primary1_radius": ("row", inside1),
            "within_primary2_radius": ("row", inside2),
            "status": ("row", status.astype(str)),
            "member": ("row", member),
        },
        coords={"row": np.arange(n), "component": comp},
        attrs={"system": system.name, "mu": system.mu, "lu_km": system.lu_km, "tu_s": system.tu_s,
               "r1_km": system.r1_km, "r2_km": system.r2_km, "kind": kind,
               "header": json.dumps(cat.header, sort_keys=True)},
    )
    return members, rows, report


def order_along_family(states: np.ndarray, period: np.ndarray) -> np.ndarray:
    """Indices that put catalog rows in order along their family (the catalog sorts rows by Jacobi
    constant, which is not monotonic along a halo family): a nearest-neighbour chain in
    (x0, z0, vy0, period), each scaled by its spread, started at one end of the family (the row
    farthest from the row farthest from row 0; rows the chain left for last after a long jump
    are moved to its start), oriented from the longer period to the shorter."""
    n = len(period)
    if n <= 2:
        return np.argsort(-period, kind="stable")
    p = np.column_stack([states[:, 0], states[:, 2], states[:, 4], period])
    spread = np.ptp(p, axis=0)
    p = p / np.where(spread > 0, spread, 1.0)

    def far(i):
        return int(np.argmax(np.linalg.norm(p - p[i], axis=1)))

    start = far(far(0))
    order = [start]
    used = np.zeros(n, dtype=bool)
    used[start] = True
    i = start
    for _ in range(n - 1):
        d = np.linalg.norm(p - p[i], axis=1)
        d[used] = np.inf
        i = int(np.argmin(d))
        order.append(i)
        used[i] = True
    # A start one row short of the true end leaves that row for last, after a long jump back:
    # move such rows to the front, where they are the nearest to the chain's first row.
    for _ in range(n):
        link = np.linalg.norm(np.diff(p[order], axis=0), axis=1)
        last = order[-1]
        if link[-1] <= 3.0 * np.median(link) or np.linalg.norm(p[last] - p[order[0]]) >= link[-1]:
            break
        order = [last] + order[:-1]
    out = np.array(order)
    return out if period[out[0]] >= period[out[-1]] else out[::-1]


def _s(v: float) -> str:
    return f"{v: .16e}"


def jpl_document(system: System, kind: str, parameters: dict, state0: np.ndarray, jacobi: np.ndarray, period: np.ndarray,
                 stability: np.ndarray, version: str) -> dict:
    """A family as a JPL Three-Body Periodic Orbits API response (same keys, fields and number
    formats: states and periods as 17-digit strings, Jacobi constant and stability as numbers).
    The signature names librate as the source, not JPL."""
    family, point, branch = jpl_names(kind, parameters)
    lp = system.lagrange_points()
    block = {
        "name": system.name,
        "mass_ratio": f"{system.mu:.16e}",
        "lunit": system.lu_km,
        "tunit": system.tu_s,
        "radius_secondary": system.r2_km,
        **{f"L{k + 1}": [repr(float(v)) for v in lp[k]] for k in range(5)},
    }
    data = [[*(_s(float(v)) for v in state0[i]), float(jacobi[i]), _s(float(period[i])), float(stability[i])] for i in range(len(period))]
    doc = {
        "signature": {"source": f"librate {version} OrbitFamily.to_jpl (format of the NASA/JPL Three-Body "
                                "Periodic Orbits API)", "version": "1.0"},
        "system": block,
        "family": family,
        "libration_point": point,
        "branch": branch,
        "count": str(len(period)),
        "limits": {"jacobi": [float(np.min(jacobi)), float(np.max(jacobi))], "period": [float(np.min(period)), float(np.max(period))],
                   "stability": [float(np.nanmin(stability)), float(np.nanmax(stability))]},
        "fields": list(JPL_FIELDS),
        "data": data,
    }
    return {k: v for k, v in doc.items() if v is not None}

