"""Families of symmetric periodic orbits: DROs, planar Lyapunov orbits, halos and NRHOs.

A family is computed by continuation (``librate.orbits.orbit_continuation``), every member's stability from
its monodromy matrix (batch-propagated on all cores), and bifurcations located where a
stability index crosses +1 or -1. :class:`OrbitFamily` holds the members, finds members by x0,
z0, period or Jacobi constant by root finding on the family (returning a corrected orbit),
saves to / loads from a self-describing netCDF or Zarr file (xarray Dataset), and reads and
writes the JPL Three-Body Periodic Orbits catalog's JSON format (:mod:`librate.orbits.jpl`).

Where ``state0`` lies: planar families start on the x axis. Spatial families (halos, NRHOs)
start at the x-z-plane crossing in the branch's hemisphere, as the JPL catalog lists them: a
southern halo at its crossing with z < 0 (apolune for the NRHOs), a northern one at z > 0.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_between, as_count, as_float_array, as_real, as_tolerance
from .._display import fmt, html_summary, short_repr
from .._errors import ConvergenceError, LibrateError
from .._progress import as_progress
from ..constants import SUN_SYNODIC_PERIOD
from ..solving.continuation import sign_changes
from .orbit_continuation import continue_arclength, continue_natural, geometry
from .periodic import (
    INDEX_TESTS,
    SHOOT_ATOL,
    SHOOT_RTOL,
    PeriodicOrbit,
    check_outside_primaries,
    collision_mode,
    correct_symmetric,
    index_tests,
    inside_primary_index,
    primary_passes,
    real_if_real,
)
from .propagation import propagate_many
from .system import System, resolve_system

__all__ = ["OrbitFamily", "correct_dro", "dro", "dro_family", "lyapunov", "lyapunov_family", "halo", "halo_family"]


def _bifurcation_record(b) -> dict:
    """A family's record of one of the driver's bifurcations: the member before it, the index and
    its level, and the located orbit's two x-z-plane crossings (x0, z0 and x0_half, z0_half)."""
    index, level, kind = INDEX_TESTS[b.name]
    orbit = b.point.data
    half = orbit._evaluation.crossing if orbit._evaluation is not None else orbit.state0
    return {"member": int(b.after), "index": index, "type": kind, "level": level, "x0": float(b.parameter), "z0": float(orbit.state0[2]),
            "x0_half": float(half[0]), "z0_half": float(half[2]), "located": bool(b.located)}


@dataclass
class OrbitFamily:
    """Members of one family of x-z-symmetric periodic orbits.

    Arrays over members: ``state0`` (n, 6) initial states on the x-z plane, ``state_half`` (n, 6)
    the states at the half-period crossing (the other symmetric point of the same orbit),
    ``period`` (TU), ``jacobi``, ``eigenvalues`` (n, 6) complex, ``stability_indices`` (n, 2)
    ([in-plane, out-of-plane] for planar families; float when every index is real, complex
    only when some member has a complex pair). ``end_reason`` says why the continuation
    stopped; ``bifurcations`` lists the members where an index crosses +1 or -1.

    For spatial families ``state0`` is the crossing in the branch's hemisphere (z < 0 for a
    southern halo, z > 0 for a northern one), the JPL catalog's convention; ``x0`` and ``z0``
    refer to it. A family read by :meth:`from_jpl` keeps the catalog's crossing and carries
    ``import_report``, the per-row record of the import (not saved by :meth:`save`).
    """

    system: System
    kind: str
    spatial: bool
    state0: np.ndarray
    state_half: np.ndarray
    period: np.ndarray
    jacobi: np.ndarray
    eigenvalues: np.ndarray
    stability_indices: np.ndarray
    end_reason: str = ""
    bifurcations: list[dict] = field(default_factory=list)
    parameters: dict = field(default_factory=dict)
    import_report: object = field(default=None, repr=False, compare=False)

    # --- display (librate._display) -----------------------------------------------------------
    def _rows(self):
        n = len(self)
        return [("kind", self.kind, ""), ("members", n, ""), ("x0", self.x0, "LU"), ("period_days", self.period_days, "d"),
                ("stable", int(np.count_nonzero(self.stable)), f"of {n}"), ("bifurcations", len(self.bifurcations), "")]

    def __repr__(self) -> str:
        return short_repr("OrbitFamily", self._rows(), digits=4)

    def _repr_html_(self) -> str:
        arrays = [("state0", self.state0, "LU, LU/TU"), ("period", self.period, "TU"), ("jacobi", self.jacobi, ""),
                  ("stability_indices", self.stability_indices, "")]
        bif = [(f"member {b.get('member', '')}", ", ".join(f"{k}={fmt(v)}" for k, v in b.items() if k != "member"), "")
               for b in self.bifurcations]
        title = f"librate.OrbitFamily {self.kind} ({len(self)} members, {'spatial' if self.spatial else 'planar'})"
        return html_summary(title, self._rows() + [("end_reason", self.end_reason, "")],
                            {"arrays": arrays, "bifurcations": bif, "parameters": [(str(k), v, "") for k, v in self.parameters.items()],
                             "system": [("system", repr(self.system), "")]})


    # --- construction ----------------------------------------------------------------------
    @classmethod
    def from_members(cls, system: System, kind: str, spatial: bool, members: list[PeriodicOrbit], end_reason: str, parameters=None,
                     bifurcations=None) -> OrbitFamily:
        """The family of ``members`` (in order along it), with their stability from one batched
        propagation. ``bifurcations``: the continuation driver's (located; see
        :class:`librate.orbits.orbit_continuation.ContinuationResult`); without them (members known
        without a run: an import, a selection) the sign changes of the same test functions
        between consecutive members, interpolated linearly."""
        if not members:
            raise LibrateError(f"the {kind} family has no member ({end_reason})")
        state0 = np.array([m.state0 for m in members])
        period = np.array([m.period for m in members])
        half = np.array([np.full(6, np.nan) if m._evaluation is None else m._evaluation.crossing for m in members])
        missing = np.flatnonzero(np.isnan(half[:, 0]))
        if missing.size:  # members not from the symmetric corrector: their half-period states
            half[missing] = propagate_many(system, state0[missing], 0.5 * period[missing], rtol=SHOOT_RTOL, atol=SHOOT_ATOL, collision="point").y
        batch = propagate_many(system, state0, period, stm=True, rtol=SHOOT_RTOL, atol=SHOOT_ATOL, on_error="mask", collision="point")
        eig = np.full((len(members), 6), np.nan + 0j)
        nu = np.full((len(members), 2), np.nan + 0j)
        for i in range(len(members)):
            if batch.ok[i]:
                eig[i], nu[i] = _core.stability(np.ascontiguousarray(batch.stm[i]), not spatial)
        fam = cls(system, kind, spatial, state0, half, period, np.array([m.jacobi for m in members]), eig, real_if_real(nu), end_reason, [],
                  dict(parameters or {}))
        if bifurcations is None:
            fam.bifurcations = fam._find_bifurcations()
        else:
            fam.bifurcations = [_bifurcation_record(b) for b in bifurcations]
        return fam

    def _hemisphere_first(self, sign: float) -> None:
        """Put each member's ``state0`` at its x-z-plane crossing farther into the hemisphere
        ``sign`` (-1 south, +1 north), swapping it with ``state_half`` where needed (the same
        orbit, started half a period later), and relocate the bifurcations on the new x0."""
        swap = sign * self.state_half[:, 2] > sign * self.state0[:, 2]
        s0 = np.where(swap[:, None], self.state_half, self.state0)
        self.state_half = np.where(swap[:, None], self.state0, self.state_half)
        self.state0 = s0
        if not all("z0_half" in b for b in self.bifurcations):  # records of an older file: detect again
            self.bifurcations = self._find_bifurcations()
        for b in self.bifurcations:
            if sign * b["z0_half"] > sign * b["z0"]:
                b["x0"], b["z0"], b["x0_half"], b["z0_half"] = b["x0_half"], b["z0_half"], b["x0"], b["z0"]

    def _find_bifurcations(self) -> list[dict]:
        """Sign changes of the stability-index test functions between consecutive members,
        interpolated linearly (the driver's detection rule, without a corrector to locate)."""
        tests = [index_tests(nu, self.spatial) for nu in self.stability_indices]
        out = []
        for i in range(len(tests) - 1):
            for name, _, _, w in sign_changes(tests[i], tests[i + 1]):
                index, level, kind = INDEX_TESTS[name]
                x0, z0, xh, zh = (float(a[i] + w * (a[i + 1] - a[i])) for a in (self.state0[:, 0], self.state0[:, 2], self.state_half[:, 0],
                                                                               self.state_half[:, 2]))
                out.append({"member": i, "index": index, "type": kind, "level": level, "x0": x0, "z0": z0, "x0_half": xh, "z0_half": zh,
                            "located": False})
        return out

    # --- access ----------------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.period)

    def __getitem__(self, i: int) -> PeriodicOrbit:
        i = range(len(self))[i]
        return PeriodicOrbit(self.system, self.state0[i].copy(), float(self.period[i]), float(self.jacobi[i]), self.kind)

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    @property
    def x0(self) -> np.ndarray:
        return self.state0[:, 0]

    @property
    def z0(self) -> np.ndarray:
        return self.state0[:, 2]

    @property
    def period_days(self) -> np.ndarray:
        return self.system.period_days(self.period)

    @functools.cached_property
    def inside_primary(self) -> np.ndarray:
        """(n,) int8 per member: 1 or 2 when the orbit passes within that primary's radius over
        its period (a solution of the point-mass model only, not a valid orbit of a body of
        that size), 0 when it stays outside both (always 0 in a point-mass system, radii 0);
        -1 if its propagation failed. The one collision check of :func:`librate.propagate_many`
        with the system's radii (:func:`librate.orbits.periodic.primary_passes`), as
        :meth:`from_jpl` flags catalog rows; computed on first use. :meth:`member` refuses a
        value in a flagged stretch with :class:`librate.CollisionError`."""
        return inside_primary_index(primary_passes(self.system, self.state0, self.period).status)

    @functools.cached_property
    def closest_km(self) -> np.ndarray:
        """(n, 2) closest approach of each member to the larger and the smaller primary's
        centre (km, from :func:`librate.orbits.orbit_continuation.geometry`); computed on first use."""
        return np.array([geometry(o).min_distance for o in self]) * self.system.lu_km

    @property
    def outside_primaries(self) -> np.ndarray:
        """(n,) bool: the members that stay outside both primaries' radii (``inside_primary == 0``)."""
        return self.inside_primary == 0

    @property
    def stable(self) -> np.ndarray:
        """Linearly stable members (both indices real with |nu| <= 1)."""
        nu = self.stability_indices
        return np.all((np.abs(nu.imag) < 1e-9) & (np.abs(nu.real) <= 1 + 1e-9), axis=1)

    # --- lookup ----------------------------------------------------------------------------
    def member(self, *, x0: float | None = None, z0: float | None = None, period: float | None = None,
               period_days: float | None = None, jacobi: float | None = None, which: int | None = None) -> PeriodicOrbit:
        """The corrected member with the given x0, z0, period (TU or days) or Jacobi constant.

        Root finding on the family: every interval between consecutive members where the
        quantity crosses the value is a candidate (``x0`` and ``z0`` are those of ``state0``:
        for spatial families the crossing in the branch's hemisphere); the guess is
        interpolated linearly and the orbit corrected with that quantity imposed, so the
        returned ``state0`` is at the same crossing as the family's. A value exactly at a
        member returns that member (re-corrected).

        The candidates are ordered by period (increasing). When several members have the value
        (x0, z0 and the Jacobi constant are not monotonic along a halo family), ``ValueError``
        lists them with their periods and ``which`` (an index into that list) picks one; with a
        single candidate ``which`` may be omitted or 0. Raises ``ValueError`` when the value is
        outside the family's range. A member that passes within a primary's radius (see
        :attr:`inside_primary`) raises :class:`librate.CollisionError` naming the primary, the
        closest approach and the radius.
        """
        return check_outside_primaries(self._member(x0=x0, z0=z0, period=period, period_days=period_days, jacobi=jacobi, which=which))

    def _member(self, *, x0, z0, period, period_days, jacobi, which) -> PeriodicOrbit:
        given = {k: v for k, v in dict(x0=x0, z0=z0, period=period, period_days=period_days, jacobi=jacobi).items() if v is not None}
        if len(given) != 1:
            names = ", ".join(f"`{k}`" for k in ("x0", "z0", "period", "period_days", "jacobi"))
            raise ValueError(f"invalid arguments {names}: give exactly one of them, got {', '.join(given) or 'none'}")
        (name, value), = given.items()
        user = name
        value = as_real(value, name)
        if name == "period_days":
            name, value = "period", self.system.from_days(value)
        if name == "z0" and not self.spatial:
            raise ValueError("invalid argument `z0`: this family is planar (z0 = 0)")
        if which is not None and (isinstance(which, (bool, np.bool_)) or not isinstance(which, (int, np.integer))):
            raise ValueError(f"invalid argument `which`: must be an integer index into the candidates (ordered by period), got {which!r}")
        q = {"x0": self.state0[:, 0], "z0": self.state0[:, 2], "period": self.period, "jacobi": self.jacobi}[name]
        d = q - value
        cands = []  # (period, state0) interpolated at the crossing of the value
        for i in range(len(d) - 1):
            if d[i] == 0 or d[i] * d[i + 1] < 0:
                w = 0.0 if d[i] == 0 else d[i] / (d[i] - d[i + 1])
                cands.append((float(self.period[i] + w * (self.period[i + 1] - self.period[i])), self.state0[i] + w * (self.state0[i + 1] - self.state0[i]), i))
        if len(d) and d[-1] == 0:
            cands.append((float(self.period[-1]), self.state0[-1], len(d) - 1))
        if not cands:
            shown = self.system.period_days(q) if user == "period_days" else q
            where = " (at state0, the crossing in the branch's hemisphere)" if self.spatial and name in ("x0", "z0") else ""
            raise ValueError(
                f"invalid argument `{user}`: {float(given[user])!r} is outside the {self.kind} family's range "
                f"[{np.min(shown):.10g}, {np.max(shown):.10g}]{where} (family end: {self.end_reason})"
            )
        cands.sort(key=lambda c: c[0])
        listing = "; ".join(f"which={k}: period {t:.10g} TU ({self.system.period_days(t):.6g} d), x0 {s[0]:.10g}, z0 {s[2]:.10g}"
                            for k, (t, s, _) in enumerate(cands))
        if which is None and len(cands) > 1:
            err = ValueError(f"ambiguous `{user}` = {float(given[user])!r}: {len(cands)} members of the {self.kind} family have it "
                             f"(values interpolated between members, ordered by period); pass which= to pick one: {listing}")
            err.candidates = [{"period": t, "state0": s.copy()} for t, s, _ in cands]  # type: ignore[attr-defined]
            raise err
        k = 0 if which is None else int(which)
        if not 0 <= k < len(cands):
            raise ValueError(f"invalid argument `which`: {len(cands)} member(s) have {user} = {float(given[user])!r}, so which must be in "
                             f"0..{len(cands) - 1} (ordered by period: {listing}); got {which!r}")
        _, guess, i = cands[k]
        if i == len(self) - 1:  # the value is the last member's
            return self._correct_at(guess, name, value)
        a, b = self.state0[i], self.state0[i + 1]
        try:
            orbit = self._correct_at(guess, name, value)
            if _between(orbit.state0, a, b):
                return orbit
        except ConvergenceError:
            pass
        # The correction left the bracket (near a fold of the quantity the two solutions are
        # close) or failed: continue the family finely from member i past member i + 1 (the
        # continuation driver, pseudo-arclength) and correct from the fine bracket.
        start = correct_symmetric(self.system, a, spatial=self.spatial, fix="x0", family=self.kind, collision=None)
        pa, chord = a[[0, 2, 4]], b[[0, 2, 4]] - a[[0, 2, 4]]
        length = float(np.linalg.norm(chord))

        def past(o, _g):
            return "past the next member" if np.dot(np.array([o.x0, o.z0, o.vy0]) - pa, chord) >= 1.05 * length**2 else None

        fine = continue_arclength(self.system, start, spatial=self.spatial, orient=chord, ds=length / 10, ds_min=length * 1e-6,
                                  ds_max=length / 5, max_members=80, family=self.kind, check_geometry=False, stop=past).members
        col = {"x0": lambda o: o.x0, "z0": lambda o: o.z0, "period": lambda o: o.period, "jacobi": lambda o: o.jacobi}[name]
        fq = np.array([col(o) for o in fine]) - value
        for j in range(len(fine) - 1):
            if fq[j] == 0:
                return fine[j]
            if fq[j] * fq[j + 1] < 0:
                w = fq[j] / (fq[j] - fq[j + 1])
                fa, fb = fine[j].state0, fine[j + 1].state0
                orbit = self._correct_at(fa + w * (fb - fa), name, value)
                if _between(orbit.state0, fa, fb):
                    return orbit
                break
        raise ConvergenceError(f"{self.kind} member at {name} = {value!r} between members {i} and {i + 1}: the correction converged "
                               "outside that interval, also from the family continued finely between them")

    def _correct_at(self, guess: np.ndarray, name: str, value: float) -> PeriodicOrbit:
        g = np.array(guess, dtype=float)
        kw = {"x0": dict(fix="x0"), "z0": dict(fix="z0"), "period": dict(period=value), "jacobi": dict(jacobi=value)}[name]
        if name == "x0":
            g[0] = value
        elif name == "z0":
            g[2] = value
        return correct_symmetric(self.system, g, spatial=self.spatial, family=self.kind, collision=None, **kw)

    def resonant(self, k: int, kind: str = "synodic") -> PeriodicOrbit:
        """The 1:k resonant member: synodic T = 2 pi / k, or Sun-resonant T = Ts / k
        (Ts = 2 pi / (1 - n_sun), the apparent solar period in the synodic frame)."""
        k = as_count(k, "k", 1, maximum=10_000)
        if kind not in ("synodic", "sun"):
            raise ValueError(f"invalid argument `kind`: must be 'synodic' or 'sun', got {kind!r}")
        base = 2 * math.pi if kind == "synodic" else SUN_SYNODIC_PERIOD
        lo, hi = float(np.min(self.period)), float(np.max(self.period))
        if not lo <= base / k <= hi:
            raise ValueError(f"invalid argument `k`: the 1:{k} {kind} resonant period {base / k:.6g} TU is outside the {self.kind} family's "
                             f"range [{lo:.6g}, {hi:.6g}], got {k!r}")
        return self.member(period=base / k)

    # --- the JPL catalog format ---------------------------------------------------------------
    @classmethod
    def from_jpl(cls, source) -> OrbitFamily:
        """A family from a JPL Three-Body Periodic Orbits API response (a dict, or the path of
        its JSON file, e.g. ``https://ssd-api.jpl.nasa.gov/periodic_orbits.api?sys=earth-moon&family=halo&libr=2&branch=S``),
        any family and system the format carries.

        The system is the file's: mass ratio ``mass_ratio``, units ``lunit`` (km) and ``tunit``
        (s); a preset when they match one (``earth-moon-jpl`` for the Earth-Moon catalog, whose
        radii are then used), otherwise a new :class:`System` with the secondary's radius from
        the file. Every row is re-corrected in librate's dynamics, except rows that pass within
        a primary's radius (flagged) and rows not at a perpendicular x-z-plane crossing (see
        :func:`librate.orbits.jpl.recorrect`). The members keep the catalog's crossing as
        ``state0`` and are ordered along the family (the catalog sorts rows by Jacobi constant;
        :func:`librate.orbits.jpl.order_along_family`).

        ``import_report`` (an xarray Dataset over the file's rows) records each row's closure
        before and after the correction, its status and flags, and its member index;
        ``parameters`` keep the catalog's family, libration point, branch and signature.
        Raises ``ValueError`` for a file that is not such a response and
        :class:`librate.LibrateError` when no row could be re-corrected.
        """
        from .jpl import kind_from_jpl, order_along_family, read_jpl, recorrect

        cat = read_jpl(source)
        kind = kind_from_jpl(cat.family, cat.libration_point, cat.branch)
        spatial = bool(np.any(np.abs(cat.states[:, 2]) > 1e-9) or np.any(np.abs(cat.states[:, 5]) > 1e-9))
        members, rows, report = recorrect(cat, kind, spatial)
        if not members:
            raise LibrateError(f"no row of the JPL {kind} file could be re-corrected ({len(cat.period)} rows): "
                               f"{sorted(set(str(s) for s in report['status'].values))}")
        order = order_along_family(np.array([m.state0 for m in members]), np.array([m.period for m in members]))
        members = [members[i] for i in order]
        rows = [rows[i] for i in order]
        member = np.full(len(cat.period), -1, dtype=np.int64)
        member[np.array(rows, dtype=np.intp)] = np.arange(len(rows))
        report["member"] = ("row", member)
        n_in = int(report["within_primary1_radius"].sum() + report["within_primary2_radius"].sum())
        params = {"jpl_family": cat.family, "jpl_libration_point": cat.libration_point, "jpl_branch": cat.branch,
                  "jpl_signature": cat.header.get("signature"), "jpl_count": cat.header.get("count"), "jpl_rows": rows}
        if cat.libration_point and cat.libration_point.isdigit():
            params["point"] = int(cat.libration_point)
        if cat.branch in ("N", "S"):
            params["branch"] = "north" if cat.branch == "N" else "south"
        end = (f"imported from the JPL catalog: {len(members)} of {len(cat.period)} rows re-corrected, "
               f"{n_in} passing within a primary's radius flagged")
        fam = cls.from_members(cat.system, kind, spatial, members, end, params)
        fam.import_report = report
        return fam

    def to_jpl(self, path) -> None:
        """Write the family as a JPL Three-Body Periodic Orbits API response (JSON; the format
        :meth:`from_jpl` reads): the system block (mass ratio, units, radius of the secondary,
        L1..L5), family / libration point / branch (the catalog's names, e.g. halo, 2, S),
        limits, and one row per member: ``state0``, Jacobi constant, period and the catalog's
        stability index (|lambda| + 1/|lambda|)/2 of the largest multiplier
        (:func:`librate.orbits.jpl.jpl_stability`). The signature names librate as the source."""
        import json
        from pathlib import Path

        from .._core import __version__
        from .jpl import jpl_document, jpl_stability

        p = Path(path)
        if p.suffix.lower() != ".json":
            raise ValueError(f"invalid argument `path`: must end in .json, got {str(path)!r}")
        doc = jpl_document(self.system, self.kind, self.parameters, self.state0, self.jacobi, self.period, jpl_stability(self.eigenvalues), __version__)
        from ..results.atomic import atomic_write_text

        atomic_write_text(p, json.dumps(doc))

    # --- I/O -------------------------------------------------------------------------------
    def to_dataset(self):
        """The family as an xarray Dataset with units and the system's constants as attributes."""
        import xarray as xr

        from .._core import __version__

        comp = ["x", "y", "z", "xd", "yd", "zd"]
        ds = xr.Dataset(
            {
                "state0": (("member", "component"), self.state0, {"units": "LU, LU/TU", "long_name": "initial state on the x-z plane"}),
                "state_half": (("member", "component"), self.state_half, {"units": "LU, LU/TU", "long_name": "state at the half-period crossing"}),
                "period": ("member", self.period, {"units": "TU"}),
                "period_days": ("member", self.period_days, {"units": "d"}),
                "jacobi": ("member", self.jacobi, {"units": "LU^2/TU^2", "long_name": "Jacobi constant"}),
                "eigenvalues_real": (("member", "eig"), self.eigenvalues.real),
                "eigenvalues_imag": (("member", "eig"), self.eigenvalues.imag),
                "stability_real": (("member", "pair"), self.stability_indices.real, {"long_name": "stability index (lambda + 1/lambda)/2, real part"}),
                "stability_imag": (("member", "pair"), self.stability_indices.imag),
            },
            coords={"member": np.arange(len(self)), "component": comp, "pair": [0, 1], "eig": np.arange(6)},
            attrs={
                "title": f"librate {self.kind} family",
                "kind": self.kind,
                "spatial": int(self.spatial),
                "end_reason": self.end_reason,
                "system_name": self.system.name,
                "mu": self.system.mu,
                "lu_km": self.system.lu_km,
                "tu_s": self.system.tu_s,
                "r1_km": self.system.r1_km,
                "r2_km": self.system.r2_km,
                "librate_version": __version__,
                "bifurcations": repr(self.bifurcations),
                "parameters": repr(self.parameters),
                "conventions": "CR3BP synodic frame, nondimensional; Earth at (-mu,0,0), Moon at (1-mu,0,0)",
                STATE0_ATTR: self._state0_convention(),
            },
        )
        return ds

    def _state0_convention(self) -> str:
        if not self.spatial:
            return "planar"
        return "jpl" if "jpl_family" in self.parameters else "hemisphere"

    def save(self, path, attrs: dict | None = None) -> None:
        """Write to netCDF (``.nc``) or Zarr (``.zarr``) through librate's result store
        (:mod:`librate.results`), with digests of every variable's values, names, dtypes and
        attributes and of the root attributes (the system constants) that :meth:`load` checks.
        ``attrs``: extra root attributes (e.g. the study).

        All or nothing, under the path's writer lock (a second process saving to the same path
        waits for the first, up to 30 s): written to a temporary sibling, flushed, and moved
        onto ``path``; an old file is removed only once the new one holds the name. An existing
        ``path`` is replaced only when it is a librate family file; anything else there (a
        foreign file, a folder with other files) is refused with ``FileExistsError``."""
        from pathlib import Path

        from ..results.files import write_dataset
        from ..results.lock import writer_lock

        p = Path(path)
        if p.suffix not in (".zarr", ".nc"):
            raise ValueError(f"invalid argument `path`: must end in .nc (netCDF) or .zarr (Zarr), got {str(path)!r}")
        ds = self.to_dataset()
        ds.attrs.update({"librate_result": "family", **(attrs or {})})
        p.parent.mkdir(parents=True, exist_ok=True)
        with writer_lock(p, wait=30.0) as lock:
            if (p.exists() or p.is_symlink()) and not (p.is_dir() and not any(p.iterdir())):
                try:
                    OrbitFamily.load(p)
                except (ValueError, OSError) as err:
                    raise FileExistsError(f"{str(p)!r} exists and is not a valid librate family file ({err}): refusing to overwrite it; "
                                          "remove it or choose another path") from None
            write_dataset(ds, p, lock=lock)

    @classmethod
    def load(cls, path) -> OrbitFamily:
        """Read a family written by :meth:`save`; the numbers are identical.

        Raises ``FileNotFoundError``, or ``ValueError`` saying why ``path`` is not a (valid)
        librate family file: unreadable (empty, truncated, garbage, not netCDF or Zarr), another
        kind of file (no family variables or attributes), or damaged (a missing chunk, or a
        variable that does not match its stored checksum).

        Files written before librate stored spatial families at the branch's hemisphere
        crossing (no attribute ``state0_convention``) held ``state0`` at the other crossing;
        a halo family's is converted on loading (each member's two crossings swapped, which
        ``parameters["state0_converted"]`` records). A spatial family without a known branch
        cannot be converted and is refused with ``ValueError``."""
        import ast
        from pathlib import Path

        from ..results.checksum import CHECKSUM_ATTR, check_dataset
        from ..results.files import open_dataset
        from ..results.zarrcheck import chunk_problems, quiet_zarr

        p = Path(path)
        name = str(path)
        if not p.exists():
            raise FileNotFoundError(f"no librate family file at {name!r}")
        if p.suffix not in (".zarr", ".nc"):
            raise ValueError(f"{name!r} is not a librate family file: the name must end in .nc (netCDF) or .zarr (Zarr)")
        not_family = f"{name!r} is not a librate family file"
        try:
            if p.suffix == ".zarr":
                if not p.is_dir():
                    raise ValueError("a .zarr family must be a folder")
                if not any((p / n).exists() for n in (".zgroup", ".zattrs", ".zmetadata")):
                    raise ValueError("no Zarr group metadata (.zgroup) in the folder")
            else:
                if not p.is_file():
                    raise ValueError("a .nc family must be a file")
                if p.stat().st_size == 0:
                    raise ValueError("the file is empty")
            ds = open_dataset(p)
        except Exception as err:  # noqa: BLE001 - whatever the reader says, it is not a family file
            raise ValueError(f"{not_family}: it cannot be read as {'Zarr' if p.suffix == '.zarr' else 'netCDF 3'} "
                             f"({type(err).__name__}: {str(err).strip().splitlines()[0] if str(err).strip() else 'no details'})") from None
        with ds:
            a = ds.attrs
            kind = a.get("librate_result")
            if kind is not None and kind != "family":
                raise ValueError(f"{not_family}: it is a librate {kind} result")
            need_vars = ("state0", "state_half", "period", "jacobi", "eigenvalues_real", "eigenvalues_imag", "stability_real", "stability_imag")
            need_attrs = ("mu", "lu_km", "tu_s", "r1_km", "r2_km", "system_name", "kind", "spatial", "end_reason", "bifurcations", "parameters")
            miss = [v for v in need_vars if v not in ds.variables] + [f"attribute {k}" for k in need_attrs if k not in a]
            if miss:
                raise ValueError(f"{not_family}: missing {', '.join(miss)}")
            if p.suffix == ".zarr":
                gone = [c.split()[1] for v in ds.variables for c in chunk_problems(p, str(v)) if c.endswith(" is missing")]
                if gone:
                    raise ValueError(f"{name!r} is a damaged librate family file: chunk(s) {', '.join(gone)} missing")
                bad = [c for v in ds.variables for c in chunk_problems(p, str(v))]
                if bad:  # checked before a codec sees it (a truncated Blosc chunk may crash it)
                    raise ValueError(f"{name!r} is a damaged librate family file: {'; '.join(bad)}")
            try:
                with quiet_zarr():
                    values = {v: np.asarray(ds[v].values) for v in ds.variables}
            except Exception as err:  # noqa: BLE001 - a garbled chunk: named, never a decompressor traceback
                raise ValueError(f"{name!r} is a damaged librate family file: a variable cannot be read ({type(err).__name__}: {err})") from None
            if isinstance(a.get(CHECKSUM_ATTR), str):
                problems, _ = check_dataset(ds, values)
                bad = [q.split()[1] for q in problems if q.startswith("variable ") and q.endswith("does not match its checksum")]
                if bad:
                    raise ValueError(f"{name!r} is a damaged librate family file: {', '.join(bad)} do(es) not match the stored checksum(s)")
                if problems:
                    raise ValueError(f"{name!r} is a damaged librate family file: {'; '.join(problems)}")
            n = values["period"].shape[0] if values["period"].ndim == 1 else -1
            shapes = {"state0": (n, 6), "state_half": (n, 6), "period": (n,), "jacobi": (n,), "eigenvalues_real": (n, 6), "eigenvalues_imag": (n, 6),
                      "stability_real": (n, 2), "stability_imag": (n, 2)}
            wrong = [f"{v} {values[v].shape} (expected {s})" for v, s in shapes.items() if values[v].shape != s]
            if wrong:
                raise ValueError(f"{not_family}: inconsistent shapes: {'; '.join(wrong)}")
            try:
                system = System(mu=float(a["mu"]), lu_km=float(a["lu_km"]), tu_s=float(a["tu_s"]), r1_km=float(a["r1_km"]), r2_km=float(a["r2_km"]),
                                name=str(a["system_name"]))
                spatial = bool(int(a["spatial"]))
                bif = ast.literal_eval(str(a["bifurcations"]))
                params = ast.literal_eval(str(a["parameters"]))
            except (ValueError, TypeError, SyntaxError, LibrateError) as err:
                raise ValueError(f"{not_family}: invalid attributes ({type(err).__name__}: {err})") from None
            convention = a.get(STATE0_ATTR)
            if spatial and convention is None and params.get("branch") not in ("north", "south"):
                raise ValueError(f"{name!r} holds a spatial family written by an older librate, with state0 at the crossing continued from "
                                 "its first member; without a halo branch (parameters['branch'] = 'north' or 'south') it cannot be converted "
                                 "to the branch-hemisphere convention: recompute the family and save it again")
            fam = cls(
                system, str(a["kind"]), spatial,
                values["state0"].copy(), values["state_half"].copy(), values["period"].copy(), values["jacobi"].copy(),
                values["eigenvalues_real"] + 1j * values["eigenvalues_imag"],
                real_if_real(values["stability_real"] + 1j * values["stability_imag"]),
                str(a["end_reason"]), bif, params,
            )
            if spatial and convention is None:
                fam._hemisphere_first(_check_branch(params["branch"]))
                fam.parameters["state0_converted"] = "file written before the branch-hemisphere convention: crossings swapped on loading"
            return fam


def _between(state: np.ndarray, a: np.ndarray, b: np.ndarray, margin: float = 0.1) -> bool:
    """Whether ``state`` lies on the family between members ``a`` and ``b``: its (x0, z0, vy0)
    projects onto the chord a -> b within [-margin, 1 + margin] of its length and lies within
    half a chord of it."""
    p, pa, pb = state[[0, 2, 4]], a[[0, 2, 4]], b[[0, 2, 4]]
    c = pb - pa
    cc = float(np.dot(c, c))
    if cc == 0.0:
        return bool(np.allclose(p, pa, rtol=0, atol=1e-9))
    u = float(np.dot(p - pa, c)) / cc
    off = float(np.linalg.norm(p - pa - u * c))
    return -margin <= u <= 1 + margin and off <= 0.5 * math.sqrt(cc)


#: Dataset attribute naming where a spatial family's state0 lies: "hemisphere" (the crossing in
#: the branch's hemisphere), "jpl" (the catalog's crossing, for imported families), "planar".
STATE0_ATTR = "state0_convention"


# --- DROs ------------------------------------------------------------------------------------
def _collision_stop(system: System, radii_km: tuple[float, float]):
    """Stop reason when the orbit passes within a primary's radius (point-mass model: only
    radii > 0 count, and only if the first member was outside)."""
    radii = [r / system.lu_km for r in radii_km]
    state = {"inside": None}

    def stop(orbit, g):
        if g is None:
            return None
        inside = [r > 0 and d < r for d, r in zip(g.min_distance, radii)]
        if state["inside"] is None:
            state["inside"] = inside
            return None
        for k, name in ((0, "larger primary (Earth)"), (1, "smaller primary (Moon)")):
            if inside[k] and not state["inside"][k]:
                return f"collision: the orbit passes within the {name}'s radius ({radii_km[k]} km)"
        return None

    return stop


#: Winding numbers (turns about the Earth, about the Moon; negative = clockwise in the synodic
#: frame) shared by every DRO: once clockwise about the Moon, not about the Earth.
DRO_WINDING = (0, -1)


def correct_dro(
    system: System | str,
    x0: float,
    ydot0: float | None = None,
    *,
    tol: float = 1e-12,
    max_iter: int = 30,
    rtol: float = SHOOT_RTOL,
    atol: float = SHOOT_ATOL,
    collision: str | None = "radius",
) -> PeriodicOrbit:
    """Correct the distant retrograde orbit through (x0, 0, 0) with ydot0 > 0 (docs/physics.md, periodic orbits).

    Single shooting on the half period (thesis eq. 19): integrate with the STM to the next
    y = 0 crossing, located in time, and drive xdot there to zero by correcting ydot0 with x0
    fixed. ``x0`` must lie between the primaries (-mu < x0 < 1 - mu). Without ``ydot0`` the
    guess is a retrograde circle about the Moon seen in the rotating frame, sqrt(mu/d) + d with
    d = 1 - mu - x0, where it is good (d <= 0.2); farther from the Moon the family is continued
    (guarded natural continuation) from x0 = 0.95 to ``x0``.

    The result is always a DRO: it winds once clockwise about the Moon and not about the Earth
    (winding numbers (0, -1)); a correction that lands on another orbit (e.g. one about the
    Earth, from a poor ``ydot0``) raises :class:`librate.ConvergenceError` naming what it found.

    ``collision`` as in :func:`librate.correct_symmetric`: by default a DRO that passes within a
    primary's radius (in the Earth-Moon system the Moon's for x0 near 0.985, the Earth's for
    x0 near 0) raises :class:`librate.CollisionError` naming the primary, the closest approach
    and the radius; ``None`` returns the point-mass orbit anyway.
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    collision_mode(collision)
    if not (isinstance(x0, (int, float, np.integer, np.floating)) and not isinstance(x0, (bool, np.bool_)) and math.isfinite(x0) and -mu < x0 < 1.0 - mu):
        raise ValueError(f"invalid argument `x0`: a DRO starts between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}), got {x0!r}")
    x0 = float(x0)
    if ydot0 is not None:
        ydot0 = as_real(ydot0, "ydot0", positive=True)
    as_count(max_iter, "max_iter", 1)
    as_tolerance(tol, "tol")
    as_tolerance(rtol, "rtol")
    as_tolerance(atol, "atol")
    d = 1.0 - mu - x0
    if ydot0 is None and d > 0.2:
        start = _correct_dro_at(sys_, 0.95, None, tol, max_iter, rtol, atol)
        res = continue_natural(sys_, start, "x0", [x0], family="dro")
        if not res.members:
            raise ConvergenceError(f"DRO at x0 = {x0}: the family continued from x0 = 0.95 did not reach it ({res.end_reason})")
        orbit = res.members[-1]
    else:
        orbit = _correct_dro_at(sys_, x0, ydot0, tol, max_iter, rtol, atol)
    g = geometry(orbit)
    if g.winding != DRO_WINDING:
        raise ConvergenceError(
            f"DRO correction at x0 = {x0} converged to an orbit that is not a DRO: ydot0 = {orbit.vy0:.6g}, period {orbit.period:.6g} TU, "
            f"winding numbers about (Earth, Moon) {g.winding} instead of {DRO_WINDING}; omit ydot0 (the family is then continued) "
            "or use librate.dro(system, x0=...)")
    return check_outside_primaries(orbit, collision)


def _correct_dro_at(sys_, x0, ydot0, tol, max_iter, rtol, atol) -> PeriodicOrbit:
    if ydot0 is None:
        d = 1.0 - sys_.mu - x0
        ydot0 = math.sqrt(sys_.mu / d) + d
    return correct_symmetric(sys_, (x0, 0.0, ydot0), fix="x0", family="dro", tol=tol, max_iter=max_iter, rtol=rtol, atol=atol, collision=None)


#: The default DRO family's members: x0 from 0.985 near the Moon to 0.005 near the Earth, every 0.005.
DRO_DEFAULT_X0 = np.round(np.arange(0.985, 0.0049, -0.005), 10)


def dro_family(system: System | str = "earth-moon", x0=None, *, check_geometry: bool = True, allow_partial: bool = False,
               progress=None) -> OrbitFamily:
    """The planar DRO family by natural-parameter continuation in x0 (thesis eq. 20-22).

    ``x0``: the members wanted (any order along the family; default the whole family from
    0.985 near the Moon to 0.005 near the Earth, every 0.005, :data:`DRO_DEFAULT_X0`). Each
    step is guarded against silent jumps (Jacobi constant and period continuity, winding
    numbers about both primaries) and halved when needed; the run ends cleanly, with
    ``end_reason``, at a collision with the Earth's surface or a step floor, keeping every
    member found. Members that pass within a primary's radius (near the Moon, x0 = 0.985 in
    the Earth-Moon system) are kept and flagged (:attr:`OrbitFamily.inside_primary`).

    Requested members are reached the default way: the continuation starts at x0 = 0.985 (or
    the largest requested x0 above it) and walks the default members down to the smallest
    requested x0, with every requested x0 inserted as a target and corrected exactly there; the
    family holds the requested members only, in the requested order. So every member the
    default family reaches is reachable on request. When ``x0`` is given, every requested
    member must be reached: otherwise :class:`librate.LibrateError` lists the missing x0 values
    and why the continuation ended (attributes ``missing``, ``found`` and ``end_reason``),
    unless ``allow_partial=True``, which returns the members found
    (``parameters["missing_x0"]`` lists the others). ``progress(done, total)`` is called as the
    requested members are reached (total: their number).
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    xs = DRO_DEFAULT_X0.copy() if x0 is None else np.atleast_1d(as_float_array(x0, "x0")).ravel()
    if xs.size == 0 or not np.all(np.isfinite(xs)) or np.any(xs <= -mu) or np.any(xs >= 1 - mu):
        raise ValueError(f"invalid argument `x0`: DROs start between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}); got {x0!r}")
    progress = as_progress(progress, "dro family", "member")
    top = max(float(xs.max()), float(DRO_DEFAULT_X0[0]))
    ds_min = 1e-6  # the natural continuation's step floor: default members closer to a request are left out
    grid = [g for g in DRO_DEFAULT_X0 if float(xs.min()) < g <= top and np.min(np.abs(xs - g)) > ds_min]
    path = np.array(sorted(set(float(v) for v in xs) | set(float(g) for g in grid), reverse=True))
    wanted = np.isin(path, xs)
    n_wanted = int(np.unique(xs).size)
    counted = np.concatenate([[0], np.cumsum(wanted)])

    def along(done, total):  # the run's progress over the path, as requested members reached
        if progress is not None:
            progress(int(counted[min(int(done), path.size)]), n_wanted)

    first = correct_dro(sys_, float(path[0]), collision=None)
    stop = _collision_stop(sys_, (sys_.r1_km, 0.0))
    res = continue_natural(sys_, first, "x0", path, family="dro", check_geometry=check_geometry, stop=stop,
                           progress=along if progress is not None else None)
    params: dict = {"rejected_jumps": res.rejected_jumps}
    members, bifurcations = res.members, res.bifurcations
    if x0 is not None:
        got = np.array([m.x0 for m in res.members])
        pick = [int(np.flatnonzero(got == x)[0]) for x in xs if np.any(got == x)]
        missing = [float(x) for x in xs if not np.any(got == x)]
        if missing:
            if not allow_partial:
                err = LibrateError(f"dro_family: {len(missing)} of the {xs.size} requested members were not reached, x0 = {missing} "
                                   f"(the continuation ended: {res.end_reason}); {len(pick)} found; pass allow_partial=True to keep them")
                err.missing, err.found, err.end_reason = missing, [float(got[i]) for i in pick], res.end_reason
                raise err
            params["missing_x0"] = missing
        members = [res.members[i] for i in pick]
        bifurcations = _kept_bifurcations(res.bifurcations, pick)
    return OrbitFamily.from_members(sys_, "dro", False, members, res.end_reason, params, bifurcations=bifurcations)


def _kept_bifurcations(bifurcations, pick: list[int]):
    """The driver's bifurcations for a family of the members ``pick`` (indices into the run's
    members): those between two kept members, their ``after`` renumbered, when the kept members
    are in the run's order; otherwise None (the family then detects them between its members)."""
    if any(b <= a for a, b in zip(pick, pick[1:])):
        return None
    out = []
    for b in bifurcations:
        j = int(np.searchsorted(pick, b.after, side="right")) - 1  # the last kept member at or before b.after
        if 0 <= j < len(pick) - 1:
            out.append(dataclasses.replace(b, after=j))
    return out


@functools.lru_cache(maxsize=8)
def _default_dro_family(system: System) -> OrbitFamily:
    return dro_family(system)


def _one_target(kw: dict) -> tuple[str, float]:
    given = {k: v for k, v in kw.items() if v is not None}
    if len(given) != 1:
        raise ValueError(f"invalid arguments {', '.join(f'`{k}`' for k in kw)}: give exactly one of them, got {', '.join(given) or 'none'}")
    return next(iter(given.items()))


def dro(system: System | str = "earth-moon", *, x0: float | None = None, period: float | None = None,
        period_days: float | None = None, jacobi: float | None = None, which: int | None = None) -> PeriodicOrbit:
    """One corrected DRO, chosen by x0, period (TU or days) or Jacobi constant.

    Near the Moon (x0 >= 0.8) x0 is corrected directly; otherwise the member is found on the
    whole family (computed once per system and cached); ``which`` as in
    :meth:`OrbitFamily.member`, for a value that several members have."""
    sys_ = resolve_system(system)
    name, value = _one_target(dict(x0=x0, period=period, period_days=period_days, jacobi=jacobi))
    value = as_real(value, name)
    if name == "x0":
        if not (math.isfinite(value) and -sys_.mu < value < 1 - sys_.mu):
            raise ValueError(f"invalid argument `x0`: DROs start between the primaries, -mu < x0 < 1 - mu; got {value!r}")
        if value >= 0.8:
            return correct_dro(sys_, value)
    return _default_dro_family(sys_).member(**{name: value}, which=which)


# --- Lyapunov and halo orbits -----------------------------------------------------------------
def _check_point(point) -> int:
    if isinstance(point, (bool, np.bool_)) or point not in (1, 2):
        raise ValueError(f"invalid argument `point`: must be 1 (L1) or 2 (L2), got {point!r}")
    return int(point)


def _lyapunov_start(sys_: System, point: int, amplitude: float) -> PeriodicOrbit:
    """Small planar Lyapunov orbit from the linearisation at L1/L2: x = L - A cos(w t),
    ydot0 = (w^2 + Uxx) A / 2, with w the in-plane centre frequency."""
    mu = sys_.mu
    xl = float(sys_.lagrange_points()[point - 1, 0])
    c2 = (1 - mu) / abs(xl + mu) ** 3 + mu / abs(xl - 1 + mu) ** 3
    uxx, uyy = 1 + 2 * c2, 1 - c2
    b = 4 - uxx - uyy
    w2 = 0.5 * (b + math.sqrt(b * b - 4 * uxx * uyy))
    a = -amplitude
    vy0 = -(w2 + uxx) * a / 2
    return correct_symmetric(sys_, (xl + a, 0.0, vy0), fix="x0", family=f"lyapunov-L{point}", collision=None)


def lyapunov_family(system: System | str = "earth-moon", point: int = 1, *, max_members: int = 150,
                    ds_max: float = 0.02, check_geometry: bool = True, progress=None) -> OrbitFamily:
    """Planar Lyapunov family at L1 or L2 by pseudo-arclength continuation from a small
    orbit (x0 = L - 0.002, on the side of L toward the larger primary), growing in amplitude.
    Ends at a collision with the Moon's surface, a step floor or ``max_members``. ``progress(done,
    total)`` after each member (total: max_members until the end)."""
    sys_ = resolve_system(system)
    point = _check_point(point)
    max_members, ds_max = as_count(max_members, "max_members", 2), as_between(ds_max, "ds_max", 1e-5, 0.5)
    first = _lyapunov_start(sys_, point, 2e-3)
    res = continue_arclength(
        sys_, first, spatial=False, orient=np.array([-1.0, 0.0, 0.0]), ds=2e-3, ds_max=ds_max, max_members=max_members,
        family=f"lyapunov-L{point}", check_geometry=check_geometry, stop=_collision_stop(sys_, (sys_.r1_km, sys_.r2_km)), progress=progress,
    )
    return OrbitFamily.from_members(sys_, f"lyapunov-L{point}", False, res.members, res.end_reason, {"point": point},
                                    bifurcations=res.bifurcations)


@functools.lru_cache(maxsize=8)
def _cached_lyapunov(system: System, point: int) -> OrbitFamily:
    return lyapunov_family(system, point)


def lyapunov(system: System | str = "earth-moon", point: int = 1, *, x0: float | None = None,
             period: float | None = None, period_days: float | None = None, jacobi: float | None = None,
             which: int | None = None) -> PeriodicOrbit:
    """One planar Lyapunov orbit at L1/L2, by x0, period (TU or days) or Jacobi constant
    (``which`` as in :meth:`OrbitFamily.member`, for a value that several members have)."""
    sys_ = resolve_system(system)
    name, value = _one_target(dict(x0=x0, period=period, period_days=period_days, jacobi=jacobi))
    return _cached_lyapunov(sys_, _check_point(point)).member(**{name: value}, which=which)


def _check_branch(branch) -> float:
    if not isinstance(branch, str) or branch not in ("north", "south"):
        raise ValueError(f"invalid argument `branch`: must be 'north' or 'south', got {branch!r}")
    return 1.0 if branch == "north" else -1.0


def halo_family(system: System | str = "earth-moon", point: int = 2, branch: str = "south", *, max_members: int = 400,
                ds_max: float = 0.02, check_geometry: bool = True, progress=None) -> OrbitFamily:
    """Halo family at L1/L2, started at its bifurcation from the planar Lyapunov family (where
    the out-of-plane stability index crosses +1) and continued by pseudo-arclength in
    (x0, z0, vy0) into the near-rectilinear halo orbits (NRHOs), until the orbit reaches the
    Moon's surface, a step floor or ``max_members``.

    ``branch`` follows the usual convention (and the JPL catalog's): a southern halo has its
    largest excursion from the x-y plane (apolune, for L2) below it, z < 0; a northern one
    above. The two are mirror images under z -> -z, so one is computed and mirrored. ``state0``
    is each member's x-z-plane crossing in the branch's hemisphere (the one with the smaller z
    for south, the larger for north), as the JPL catalog lists them; ``state_half`` the other
    one. Neither x0 nor z0 is monotonic along the family; the period is, for L2. ``progress(done,
    total)`` after each member (total: max_members until the end).
    """
    sys_ = resolve_system(system)
    point = _check_point(point)
    sign = _check_branch(branch)
    max_members, ds_max = as_count(max_members, "max_members", 2), as_between(ds_max, "ds_max", 1e-5, 0.5)
    lyap = _cached_lyapunov(sys_, point)
    cands = [b for b in lyap.bifurcations if b["index"] == "out-of-plane" and b["level"] == 1.0]
    if not cands:
        raise LibrateError(f"no halo bifurcation found on the L{point} Lyapunov family ({len(lyap)} members, end: {lyap.end_reason})")
    bif = cands[0]
    i = bif["member"]
    w = (bif["x0"] - lyap.x0[i]) / (lyap.x0[i + 1] - lyap.x0[i])
    p = lyap.state0[i] + w * (lyap.state0[i + 1] - lyap.state0[i])
    planar = correct_symmetric(sys_, p, fix="x0", family=f"lyapunov-L{point}", collision=None)
    name = f"halo-L{point}-{branch}"
    first = correct_symmetric(sys_, (planar.x0, 2e-3, planar.vy0), spatial=True, fix="z0", family=name, collision=None)
    res = continue_arclength(
        sys_, first, spatial=True, orient=np.array([0.0, 1.0, 0.0]), ds=2e-3, ds_max=ds_max, max_members=max_members,
        family=name, check_geometry=check_geometry, stop=_collision_stop(sys_, (sys_.r1_km, sys_.r2_km)), progress=progress,
    )
    fam = OrbitFamily.from_members(sys_, name, True, res.members, res.end_reason,
                                   {"point": point, "branch": branch, "bifurcation_x0": bif["x0"]}, bifurcations=res.bifurcations)
    # Name the branch by the sign of z where |z| is largest along the family (apolune).
    both = np.concatenate([fam.state0[:, 2], fam.state_half[:, 2]])
    if np.sign(both[np.argmax(np.abs(both))]) != sign:
        flip = np.array([1.0, 1.0, -1.0, 1.0, 1.0, -1.0])
        fam.state0 = fam.state0 * flip
        fam.state_half = fam.state_half * flip
        for b in fam.bifurcations:
            b["z0"], b["z0_half"] = -b["z0"], -b["z0_half"]
    fam._hemisphere_first(sign)
    return fam


@functools.lru_cache(maxsize=8)
def _cached_halo(system: System, point: int, branch: str) -> OrbitFamily:
    return halo_family(system, point, branch)


def halo(system: System | str = "earth-moon", point: int = 2, branch: str = "south", *, x0: float | None = None,
         z0: float | None = None, period: float | None = None, period_days: float | None = None,
         jacobi: float | None = None, which: int | None = None) -> PeriodicOrbit:
    """One halo orbit at L1/L2 (north or south branch) by x0, z0, period (TU or days) or Jacobi
    constant, found on the family (computed once per system and cached).

    ``x0`` and ``z0`` are those of ``state0``, the x-z-plane crossing in the branch's
    hemisphere (the JPL catalog's). When several members have the value, ``ValueError`` lists
    them with their periods; ``which`` (an index, ordered by period) picks one
    (:meth:`OrbitFamily.member`)."""
    sys_ = resolve_system(system)
    point = _check_point(point)
    _check_branch(branch)
    name, value = _one_target(dict(x0=x0, z0=z0, period=period, period_days=period_days, jacobi=jacobi))
    return _cached_halo(sys_, point, branch).member(**{name: value}, which=which)
