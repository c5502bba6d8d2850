"""The family of periodic orbits as a result: :class:`OrbitFamily`, its members and their
stability, lookup of a member by x0, z0, period or Jacobi constant (root finding on the family,
then a correction), and its files: a self-describing netCDF or Zarr file through librate's result
store (:mod:`librate.results`) and the JPL Three-Body Periodic Orbits catalog's JSON format
(:mod:`librate.orbits.jpl`). The families are built in :mod:`librate.orbits.families`.

Where ``state0`` lies: planar families start on the x axis. Spatial families (halos, NRHOs)
start at the x-z-plane crossing in the branch's hemisphere, as the JPL catalog lists them: a
southern halo at its crossing with z < 0 (apolune for the NRHOs), a northern one at z > 0.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_real
from .._display import fmt, html_summary, short_repr
from .._errors import ConvergenceError, LibrateError
from ..constants import SUN_SYNODIC_PERIOD
from ..solving.continuation import sign_changes
from .orbit_continuation import continue_arclength, geometry
from .periodic import (
    INDEX_TESTS,
    SHOOT_ATOL,
    SHOOT_RTOL,
    PeriodicOrbit,
    check_outside_primaries,
    correct_symmetric,
    index_tests,
    inside_primary_index,
    primary_passes,
    real_if_real,
)
from .propagation import propagate_many
from .system import System

__all__ = ["OrbitFamily", "check_branch"]

#: Dataset attribute naming where a spatial family's state0 lies: "hemisphere" (the crossing in
#: the branch's hemisphere), "jpl" (the catalog's crossing, for imported families), "planar".
STATE0_ATTR = "state0_convention"


def check_branch(branch) -> float:
    """The sign of a halo branch's hemisphere: +1 for 'north', -1 for 'south'; ``ValueError`` otherwise."""
    if not isinstance(branch, str) or branch not in ("north", "south"):
        raise ValueError(f"invalid argument `branch`: must be 'north' or 'south', got {branch!r}")
    return 1.0 if branch == "north" else -1.0



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
    """The members of one family of x-z-symmetric periodic orbits, with their stability.

    Made by :func:`librate.dro_family`, :func:`librate.lyapunov_family`,
    :func:`librate.halo_family`, :meth:`from_jpl` and :meth:`load`. The arrays run over the n
    members, in order along the family; ``len(fam)`` is n, ``fam[i]`` the i-th member as a
    :class:`PeriodicOrbit`, and iterating gives every member. :meth:`member` finds the member
    of a given x0, z0, period or Jacobi constant, :meth:`resonant` a resonant one;
    :meth:`save`, :meth:`load`, :meth:`to_dataset`, :meth:`from_jpl` and :meth:`to_jpl` are
    its files.

    In spatial families ``state0`` is each member's crossing in the branch's hemisphere (z < 0
    for a southern halo, z > 0 for a northern one), the JPL catalog's convention, and ``x0``
    and ``z0`` are its components. A family read by :meth:`from_jpl` keeps the catalog's
    crossing instead.

    Parameters
    ----------
    system : System
        The system.
    kind : str
        The family's name ("dro", "lyapunov-L1", "halo-L2-south", ...).
    spatial : bool
        Whether the members are 3-D (halos, NRHOs) rather than planar.
    state0 : numpy.ndarray, shape (n, 6)
        The initial states, on the x-z plane.
    state_half : numpy.ndarray, shape (n, 6)
        The states at the half-period crossing: the other symmetric point of the same orbit.
    period : numpy.ndarray, shape (n,)
        The periods (TU).
    jacobi : numpy.ndarray, shape (n,)
        The Jacobi constants.
    eigenvalues : numpy.ndarray, shape (n, 6), complex
        The eigenvalues of each member's monodromy (NaN where its propagation failed).
    stability_indices : numpy.ndarray, shape (n, 2)
        The stability indices nu of each member: [in-plane, out-of-plane] for planar families,
        [index 1, index 2] for spatial ones. Float when every index is real; complex only when
        some member has a complex pair.
    end_reason : str, default ""
        Why the continuation stopped.
    bifurcations : list of dict, default []
        The places between members where a stability index crosses +1 or -1, each a dict:
        "member" (the member before it), "index", "type", "level" (+1 or -1), "x0" and "z0" (at
        the crossing of ``state0``), "x0_half" and "z0_half" (at the other crossing), "located"
        (located by the continuation driver, or else interpolated linearly between members).
    parameters : dict, default {}
        How the family was made: e.g. "point", "branch", "bifurcation_x0", "rejected_jumps",
        "missing_x0", or the catalog's "jpl_family", "jpl_libration_point", "jpl_branch",
        "jpl_signature" for an import.
    import_report : xarray.Dataset, optional
        Only for a family read by :meth:`from_jpl`: the per-row record of the import. It is
        not saved by :meth:`save`.

    Attributes
    ----------
    x0, z0 : numpy.ndarray, shape (n,)
        The components x and z of ``state0``.
    period_days : numpy.ndarray, shape (n,)
        The periods in days.
    stable : numpy.ndarray, shape (n,), bool
        The linearly stable members: both indices real with |nu| <= 1 (to 1e-9).
    inside_primary : numpy.ndarray, shape (n,), int8
        For each member, 1 or 2 when the orbit passes within that primary's radius over its
        period, 0 when it stays outside both, -1 when its propagation failed; computed on first
        use (see the property).
    closest_km : numpy.ndarray, shape (n, 2)
        Each member's closest approach to the larger and the smaller primary's centre (km);
        computed on first use.
    outside_primaries : numpy.ndarray, shape (n,), bool
        The members that stay outside both primaries' radii (``inside_primary == 0``).

    Examples
    --------
    >>> import librate
    >>> fam = librate.dro_family("earth-moon", x0=[0.95, 0.9, 0.85])
    >>> len(fam), fam.x0.tolist(), fam.stable.tolist()
    (3, [0.95, 0.9, 0.85], [True, True, True])
    >>> fam[1].family, round(fam[1].period_days, 3)
    ('dro', 5.545)
    >>> round(fam.member(x0=0.875).period_days, 4)
    7.7226
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
            half[missing] = propagate_many(system, state0[missing], 0.5 * period[missing], rtol=SHOOT_RTOL,
                                           atol=SHOOT_ATOL, collision="point").y
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
                cands.append((float(self.period[i] + w * (self.period[i + 1] - self.period[i])),
                              self.state0[i] + w * (self.state0[i + 1] - self.state0[i]), i))
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
            raise ValueError(f"invalid argument `k`: the 1:{k} {kind} resonant period {base / k:.6g} TU is outside the "
                             f"{self.kind} family's range [{lo:.6g}, {hi:.6g}], got {k!r}")
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
        doc = jpl_document(self.system, self.kind, self.parameters, self.state0, self.jacobi, self.period,
                           jpl_stability(self.eigenvalues), __version__)
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
                "state_half": (("member", "component"), self.state_half,
                               {"units": "LU, LU/TU", "long_name": "state at the half-period crossing"}),
                "period": ("member", self.period, {"units": "TU"}),
                "period_days": ("member", self.period_days, {"units": "d"}),
                "jacobi": ("member", self.jacobi, {"units": "LU^2/TU^2", "long_name": "Jacobi constant"}),
                "eigenvalues_real": (("member", "eig"), self.eigenvalues.real),
                "eigenvalues_imag": (("member", "eig"), self.eigenvalues.imag),
                "stability_real": (("member", "pair"), self.stability_indices.real,
                                   {"long_name": "stability index (lambda + 1/lambda)/2, real part"}),
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
            need_vars = ("state0", "state_half", "period", "jacobi", "eigenvalues_real", "eigenvalues_imag",
                         "stability_real", "stability_imag")
            need_attrs = ("mu", "lu_km", "tu_s", "r1_km", "r2_km", "system_name", "kind", "spatial", "end_reason",
                          "bifurcations", "parameters")
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
                raise ValueError(f"{name!r} is a damaged librate family file: a variable cannot be read "
                                 f"({type(err).__name__}: {err})") from None
            if isinstance(a.get(CHECKSUM_ATTR), str):
                problems, _ = check_dataset(ds, values)
                bad = [q.split()[1] for q in problems if q.startswith("variable ") and q.endswith("does not match its checksum")]
                if bad:
                    raise ValueError(f"{name!r} is a damaged librate family file: {', '.join(bad)} do(es) not match the stored checksum(s)")
                if problems:
                    raise ValueError(f"{name!r} is a damaged librate family file: {'; '.join(problems)}")
            n = values["period"].shape[0] if values["period"].ndim == 1 else -1
            shapes = {"state0": (n, 6), "state_half": (n, 6), "period": (n,), "jacobi": (n,), "eigenvalues_real": (n, 6),
                      "eigenvalues_imag": (n, 6),
                      "stability_real": (n, 2), "stability_imag": (n, 2)}
            wrong = [f"{v} {values[v].shape} (expected {s})" for v, s in shapes.items() if values[v].shape != s]
            if wrong:
                raise ValueError(f"{not_family}: inconsistent shapes: {'; '.join(wrong)}")
            try:
                system = System(mu=float(a["mu"]), lu_km=float(a["lu_km"]), tu_s=float(a["tu_s"]), r1_km=float(a["r1_km"]),
                                r2_km=float(a["r2_km"]),
                                name=str(a["system_name"]))
                spatial = bool(int(a["spatial"]))
                bif = ast.literal_eval(str(a["bifurcations"]))
                params = ast.literal_eval(str(a["parameters"]))
            except (ValueError, TypeError, SyntaxError, LibrateError) as err:
                raise ValueError(f"{not_family}: invalid attributes ({type(err).__name__}: {err})") from None
            convention = a.get(STATE0_ATTR)
            if spatial and convention is None and params.get("branch") not in ("north", "south"):
                raise ValueError(f"{name!r} holds a spatial family written by an older librate, with state0 at the crossing continued from "
                                 "its first member; without a halo branch (parameters['branch'] = 'north' or 'south') it "
                                 "cannot be converted to the branch-hemisphere convention: recompute the family and save it again")
            fam = cls(
                system, str(a["kind"]), spatial,
                values["state0"].copy(), values["state_half"].copy(), values["period"].copy(), values["jacobi"].copy(),
                values["eigenvalues_real"] + 1j * values["eigenvalues_imag"],
                real_if_real(values["stability_real"] + 1j * values["stability_imag"]),
                str(a["end_reason"]), bif, params,
            )
            if spatial and convention is None:
                fam._hemisphere_first(check_branch(params["branch"]))
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
