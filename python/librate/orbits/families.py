"""Families of symmetric periodic orbits: DROs, planar Lyapunov orbits, halos and NRHOs.

A family is computed by continuation (``librate.orbits.continuation``), every member's stability from
its monodromy matrix (batch-propagated on all cores), and bifurcations located where a
stability index crosses +1 or -1. :class:`OrbitFamily` holds the members, finds members by x0,
z0, period or Jacobi constant by root finding on the family (returning a corrected orbit),
and saves to / loads from a self-describing netCDF or Zarr file (xarray Dataset).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_real
from .._errors import ConvergenceError, LibrateError
from ..constants import SUN_SYNODIC_PERIOD
from .continuation import continue_arclength, continue_natural, geometry
from .periodic import SHOOT_ATOL, SHOOT_RTOL, PeriodicOrbit, correct_symmetric
from .propagation import propagate_many
from .system import System, resolve_system

__all__ = ["OrbitFamily", "correct_dro", "dro", "dro_family", "lyapunov", "lyapunov_family", "halo", "halo_family"]


@dataclass
class OrbitFamily:
    """Members of one family of x-z-symmetric periodic orbits.

    Arrays over members: ``state0`` (n, 6) initial states on the x-z plane, ``state_half`` (n, 6)
    the states at the half-period crossing (the other symmetric point of the same orbit),
    ``period`` (TU), ``jacobi``, ``eigenvalues`` (n, 6) complex, ``stability_indices`` (n, 2)
    complex ([in-plane, out-of-plane] for planar families). ``end_reason`` says why the
    continuation stopped; ``bifurcations`` lists the members where an index crosses +1 or -1.
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

    # --- construction ----------------------------------------------------------------------
    @classmethod
    def from_members(cls, system: System, kind: str, spatial: bool, members: list[PeriodicOrbit], end_reason: str, parameters=None) -> OrbitFamily:
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
        fam = cls(system, kind, spatial, state0, half, period, np.array([m.jacobi for m in members]), eig, nu, end_reason, [], dict(parameters or {}))
        fam.bifurcations = fam._find_bifurcations()
        return fam

    def _find_bifurcations(self) -> list[dict]:
        names = ("in-plane", "out-of-plane") if not self.spatial else ("index 1", "index 2")
        out = []
        for j in range(2):
            nu = self.stability_indices[:, j]
            for i in range(len(nu) - 1):
                a, b = nu[i], nu[i + 1]
                if abs(a.imag) > 1e-6 or abs(b.imag) > 1e-6 or not (np.isfinite(a) and np.isfinite(b)):
                    continue
                for level, kind in ((1.0, "tangent (+1): a new family branches off, or a fold"), (-1.0, "period-doubling (-1)")):
                    if (a.real - level) * (b.real - level) < 0:
                        w = (level - a.real) / (b.real - a.real)
                        out.append(
                            {"member": i, "index": names[j], "type": kind, "level": level,
                             "x0": float(self.state0[i, 0] + w * (self.state0[i + 1, 0] - self.state0[i, 0]))}
                        )
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

    @property
    def stable(self) -> np.ndarray:
        """Linearly stable members (both indices real with |nu| <= 1)."""
        nu = self.stability_indices
        return np.all((np.abs(nu.imag) < 1e-9) & (np.abs(nu.real) <= 1 + 1e-9), axis=1)

    # --- lookup ----------------------------------------------------------------------------
    def member(self, *, x0: float | None = None, z0: float | None = None, period: float | None = None,
               period_days: float | None = None, jacobi: float | None = None, which: int = 0) -> PeriodicOrbit:
        """The corrected member with the given x0, z0, period (TU or days) or Jacobi constant.

        Root finding on the family: the target is bracketed between two members (for halos,
        also among the half-period crossing states), the guess interpolated linearly, and the
        orbit corrected with that quantity imposed. ``which`` picks among several brackets.
        Raises ``ValueError`` when the value is outside the family's range.
        """
        given = {k: v for k, v in dict(x0=x0, z0=z0, period=period, period_days=period_days, jacobi=jacobi).items() if v is not None}
        if len(given) != 1:
            raise ValueError("invalid argument: give exactly one of x0, z0, period, period_days, jacobi")
        (name, value), = given.items()
        value = as_real(value, name)
        if name == "period_days":
            name, value = "period", self.system.from_days(value)
        if name == "z0" and not self.spatial:
            raise ValueError("invalid argument `z0`: this family is planar (z0 = 0)")
        sets = [self.state0] + ([self.state_half] if self.spatial else [])
        brackets = []
        for states in sets:
            q = {"x0": states[:, 0], "z0": states[:, 2], "period": self.period, "jacobi": self.jacobi}[name]
            d = q - value
            for i in range(len(d) - 1):
                if d[i] == 0 or d[i] * d[i + 1] < 0:
                    w = 0.0 if d[i] == 0 else d[i] / (d[i] - d[i + 1])
                    brackets.append((states[i] + w * (states[i + 1] - states[i]), i))
            if d[-1] == 0:
                brackets.append((states[-1], len(d) - 1))
        if not brackets:
            # the ranges searched: for halos, z0 at the half-period crossing too (the other
            # side of the x-y plane), so the accepted values may form two intervals
            user = next(iter(given))
            spans = []
            for st, what in zip(sets, ("initial states", "half-period crossings")):
                q = {"x0": st[:, 0], "z0": st[:, 2], "period": self.period, "jacobi": self.jacobi}[name]
                if user == "period_days":
                    q = self.system.period_days(q)
                spans.append(f"[{np.min(q):.10g}, {np.max(q):.10g}]" + (f" ({what})" if len(sets) > 1 and name in ("x0", "z0") else ""))
                if name not in ("x0", "z0"):
                    break
            raise ValueError(
                f"invalid argument `{user}`: {float(given[user])!r} is outside the {self.kind} family's range "
                f"{' or '.join(spans)} (family end: {self.end_reason})"
            )
        if not 0 <= which < len(brackets):
            raise ValueError(f"invalid argument `which`: the value is bracketed {len(brackets)} time(s); which must be in 0..{len(brackets) - 1}")
        guess, _ = brackets[which]
        kw = {"x0": dict(fix="x0"), "z0": dict(fix="z0"), "period": dict(period=value), "jacobi": dict(jacobi=value)}[name]
        g = guess.copy()
        if name == "x0":
            g[0] = value
        elif name == "z0":
            g[2] = value
        return correct_symmetric(self.system, g, spatial=self.spatial, family=self.kind, **kw)

    def resonant(self, k: int, kind: str = "synodic") -> PeriodicOrbit:
        """The 1:k resonant member: synodic T = 2 pi / k, or Sun-resonant T = Ts / k
        (Ts = 2 pi / (1 - n_sun), the apparent solar period in the synodic frame)."""
        if not isinstance(k, (int, np.integer)) or k < 1:
            raise ValueError(f"invalid argument `k`: must be an integer >= 1, got {k!r}")
        if kind not in ("synodic", "sun"):
            raise ValueError(f"invalid argument `kind`: must be 'synodic' or 'sun', got {kind!r}")
        base = 2 * math.pi if kind == "synodic" else SUN_SYNODIC_PERIOD
        return self.member(period=base / k)

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
            },
        )
        return ds

    def save(self, path) -> None:
        """Write to netCDF (``.nc``) or Zarr (``.zarr``), with a digest of every variable
        (attribute ``librate_checksums``) that :meth:`load` checks.

        All or nothing: written to a temporary sibling, then renamed. An existing ``path`` is
        replaced only when it is a librate family file; anything else there (a foreign file,
        a folder with other files) is refused with ``FileExistsError``, never overwritten."""
        from pathlib import Path

        from .._integrity import CHECKSUM_ATTR, dataset_checksums, write_atomically

        p = Path(path)
        if p.suffix not in (".zarr", ".nc"):
            raise ValueError(f"invalid argument `path`: must end in .nc (netCDF) or .zarr (Zarr), got {str(path)!r}")
        if (p.exists() or p.is_symlink()) and not (p.is_dir() and not any(p.iterdir())):
            try:
                OrbitFamily.load(p)
            except (ValueError, OSError) as err:
                raise FileExistsError(f"{str(p)!r} exists and is not a valid librate family file ({err}): refusing to overwrite it; "
                                      "remove it or choose another path") from None
        ds = self.to_dataset()
        ds.attrs[CHECKSUM_ATTR] = dataset_checksums(ds)
        p.parent.mkdir(parents=True, exist_ok=True)
        write_atomically(ds, p)

    @classmethod
    def load(cls, path) -> OrbitFamily:
        """Read a family written by :meth:`save`; the numbers are identical.

        Raises ``FileNotFoundError``, or ``ValueError`` saying why ``path`` is not a (valid)
        librate family file: unreadable (empty, truncated, garbage, not netCDF or Zarr), another
        kind of file (no family variables or attributes), or damaged (a missing chunk, or a
        variable that does not match its stored checksum)."""
        import ast
        import json
        from pathlib import Path

        import xarray as xr

        from .._integrity import CHECKSUM_ATTR, array_digest, missing_zarr_chunks

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
                ds = xr.open_zarr(p, consolidated=None, chunks=None)
            else:
                if not p.is_file():
                    raise ValueError("a .nc family must be a file")
                if p.stat().st_size == 0:
                    raise ValueError("the file is empty")
                ds = xr.open_dataset(p, engine="scipy")
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
                gone = [c for v in ds.variables for c in missing_zarr_chunks(p, str(v))]
                if gone:
                    raise ValueError(f"{name!r} is a damaged librate family file: chunk(s) {', '.join(gone)} missing")
            try:
                values = {v: np.asarray(ds[v].values) for v in ds.variables}
            except Exception as err:  # noqa: BLE001 - a garbled chunk: named, never a decompressor traceback
                raise ValueError(f"{name!r} is a damaged librate family file: a variable cannot be read ({type(err).__name__}: {err})") from None
            sums = a.get(CHECKSUM_ATTR)
            if isinstance(sums, str):
                try:
                    sums = json.loads(sums)
                except ValueError:
                    raise ValueError(f"{name!r} is a damaged librate family file: attribute {CHECKSUM_ATTR} is not valid JSON") from None
                bad = [v for v, want in sums.items() if v in values and array_digest(values[v]) != want]
                if bad:
                    raise ValueError(f"{name!r} is a damaged librate family file: {', '.join(bad)} do(es) not match the stored checksum(s)")
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
            return cls(
                system, str(a["kind"]), spatial,
                values["state0"].copy(), values["state_half"].copy(), values["period"].copy(), values["jacobi"].copy(),
                values["eigenvalues_real"] + 1j * values["eigenvalues_imag"],
                values["stability_real"] + 1j * values["stability_imag"],
                str(a["end_reason"]), bif, params,
            )


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
) -> PeriodicOrbit:
    """Correct the distant retrograde orbit through (x0, 0, 0) with ydot0 > 0 (PHYSICS.md sec. 3).

    Single shooting on the half period (thesis eq. 19): integrate with the STM to the next
    y = 0 crossing, located in time, and drive xdot there to zero by correcting ydot0 with x0
    fixed. ``x0`` must lie between the primaries (-mu < x0 < 1 - mu). Without ``ydot0`` the
    guess is a retrograde circle about the Moon seen in the rotating frame, sqrt(mu/d) + d with
    d = 1 - mu - x0, where it is good (d <= 0.2); farther from the Moon the family is continued
    (guarded natural continuation) from x0 = 0.95 to ``x0``.

    The result is always a DRO: it winds once clockwise about the Moon and not about the Earth
    (winding numbers (0, -1)); a correction that lands on another orbit (e.g. one about the
    Earth, from a poor ``ydot0``) raises :class:`librate.ConvergenceError` naming what it found.
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    if not (isinstance(x0, (int, float, np.integer, np.floating)) and not isinstance(x0, (bool, np.bool_)) and math.isfinite(x0) and -mu < x0 < 1.0 - mu):
        raise ValueError(f"invalid argument `x0`: a DRO starts between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}), got {x0!r}")
    x0 = float(x0)
    if ydot0 is not None:
        ydot0 = as_real(ydot0, "ydot0", positive=True)
    as_count(max_iter, "max_iter", 1)
    as_real(tol, "tol", positive=True)
    as_real(rtol, "rtol", positive=True)
    as_real(atol, "atol", positive=True)
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
    return orbit


def _correct_dro_at(sys_, x0, ydot0, tol, max_iter, rtol, atol) -> PeriodicOrbit:
    if ydot0 is None:
        d = 1.0 - sys_.mu - x0
        ydot0 = math.sqrt(sys_.mu / d) + d
    return correct_symmetric(sys_, (x0, 0.0, ydot0), fix="x0", family="dro", tol=tol, max_iter=max_iter, rtol=rtol, atol=atol)


def dro_family(system: System | str = "earth-moon", x0=None, *, check_geometry: bool = True, allow_partial: bool = False) -> OrbitFamily:
    """The planar DRO family by natural-parameter continuation in x0 (thesis eq. 20-22).

    ``x0``: the members wanted (any order along the family; default the whole family from
    0.985 near the Moon to 0.005 near the Earth, every 0.005). Each step is guarded against
    silent jumps (Jacobi constant and period continuity, winding numbers about both primaries)
    and halved when needed; the run ends cleanly, with ``end_reason``, at a collision with the
    Earth's surface or a step floor, keeping every member found.

    When ``x0`` is given, every requested member must be reached: otherwise
    :class:`librate.LibrateError` lists the missing x0 values and why the continuation ended
    (attributes ``missing``, ``found`` and ``end_reason``), unless ``allow_partial=True``, which
    returns the members found (``parameters["missing_x0"]`` lists the others).
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    xs = np.round(np.arange(0.985, 0.0049, -0.005), 10) if x0 is None else np.atleast_1d(np.asarray(x0, dtype=float))
    if xs.size == 0 or not np.all(np.isfinite(xs)) or np.any(xs <= -mu) or np.any(xs >= 1 - mu):
        raise ValueError(f"invalid argument `x0`: DROs start between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}); got {x0!r}")
    start = 0.95 if xs[0] < 0.9 else float(xs[0])
    first = correct_dro(sys_, start)
    stop = _collision_stop(sys_, (sys_.r1_km, 0.0))
    if start != xs[0]:
        lead = continue_natural(sys_, first, "x0", np.linspace(start, xs[0], 9)[1:], family="dro", check_geometry=False)
        if len(lead.members) < 8:
            raise LibrateError(f"could not reach the first requested DRO at x0 = {xs[0]}: {lead.end_reason}")
        first = lead.members[-1]
    res = continue_natural(sys_, first, "x0", xs, family="dro", check_geometry=check_geometry, stop=stop)
    params: dict = {"rejected_jumps": res.rejected_jumps}
    if x0 is not None:
        got = np.array([m.x0 for m in res.members])
        missing = [float(x) for x in xs if not np.any(np.abs(got - x) <= 1e-12 * max(1.0, abs(x)))]
        if missing:
            if not allow_partial:
                err = LibrateError(f"dro_family: {len(missing)} of the {xs.size} requested members were not reached, x0 = {missing} "
                                   f"(the continuation ended: {res.end_reason}); {len(res.members)} found; pass allow_partial=True to keep them")
                err.missing, err.found, err.end_reason = missing, [float(v) for v in got], res.end_reason
                raise err
            params["missing_x0"] = missing
    return OrbitFamily.from_members(sys_, "dro", False, res.members, res.end_reason, params)


@functools.lru_cache(maxsize=8)
def _default_dro_family(system: System) -> OrbitFamily:
    return dro_family(system)


def _one_target(kw: dict) -> tuple[str, float]:
    given = {k: v for k, v in kw.items() if v is not None}
    if len(given) != 1:
        raise ValueError(f"invalid argument: give exactly one of {', '.join(kw)}")
    return next(iter(given.items()))


def dro(system: System | str = "earth-moon", *, x0: float | None = None, period: float | None = None,
        period_days: float | None = None, jacobi: float | None = None) -> PeriodicOrbit:
    """One corrected DRO, chosen by x0, period (TU or days) or Jacobi constant.

    Near the Moon (x0 >= 0.8) x0 is corrected directly; otherwise the member is found on the
    whole family (computed once per system and cached)."""
    sys_ = resolve_system(system)
    name, value = _one_target(dict(x0=x0, period=period, period_days=period_days, jacobi=jacobi))
    value = as_real(value, name)
    if name == "x0":
        if not (math.isfinite(value) and -sys_.mu < value < 1 - sys_.mu):
            raise ValueError(f"invalid argument `x0`: DROs start between the primaries, -mu < x0 < 1 - mu; got {value!r}")
        if value >= 0.8:
            return correct_dro(sys_, value)
    return _default_dro_family(sys_).member(**{name: value})


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
    return correct_symmetric(sys_, (xl + a, 0.0, vy0), fix="x0", family=f"lyapunov-L{point}")


def lyapunov_family(system: System | str = "earth-moon", point: int = 1, *, max_members: int = 150,
                    ds_max: float = 0.02, check_geometry: bool = True) -> OrbitFamily:
    """Planar Lyapunov family at L1 or L2 by pseudo-arclength continuation from a small
    orbit (x0 = L - 0.002, on the side of L toward the larger primary), growing in amplitude.
    Ends at a collision with the Moon's surface, a step floor or ``max_members``."""
    sys_ = resolve_system(system)
    point = _check_point(point)
    first = _lyapunov_start(sys_, point, 2e-3)
    res = continue_arclength(
        sys_, first, spatial=False, orient=np.array([-1.0, 0.0, 0.0]), ds=2e-3, ds_max=ds_max, max_members=max_members,
        family=f"lyapunov-L{point}", check_geometry=check_geometry, stop=_collision_stop(sys_, (sys_.r1_km, sys_.r2_km)),
    )
    return OrbitFamily.from_members(sys_, f"lyapunov-L{point}", False, res.members, res.end_reason, {"point": point})


@functools.lru_cache(maxsize=8)
def _cached_lyapunov(system: System, point: int) -> OrbitFamily:
    return lyapunov_family(system, point)


def lyapunov(system: System | str = "earth-moon", point: int = 1, *, x0: float | None = None,
             period: float | None = None, period_days: float | None = None, jacobi: float | None = None) -> PeriodicOrbit:
    """One planar Lyapunov orbit at L1/L2, by x0, period (TU or days) or Jacobi constant."""
    sys_ = resolve_system(system)
    name, value = _one_target(dict(x0=x0, period=period, period_days=period_days, jacobi=jacobi))
    return _cached_lyapunov(sys_, _check_point(point)).member(**{name: value})


def _check_branch(branch) -> float:
    if not isinstance(branch, str) or branch not in ("north", "south"):
        raise ValueError(f"invalid argument `branch`: must be 'north' or 'south', got {branch!r}")
    return 1.0 if branch == "north" else -1.0


def halo_family(system: System | str = "earth-moon", point: int = 2, branch: str = "south", *, max_members: int = 400,
                ds_max: float = 0.02, check_geometry: bool = True) -> OrbitFamily:
    """Halo family at L1/L2, started at its bifurcation from the planar Lyapunov family (where
    the out-of-plane stability index crosses +1) and continued by pseudo-arclength in
    (x0, z0, vy0) into the near-rectilinear halo orbits (NRHOs), until the orbit reaches the
    Moon's surface, a step floor or ``max_members``.

    ``branch`` follows the usual convention (and the JPL catalog's): a southern halo has its
    largest excursion from the x-y plane (apolune, for L2) below it, z < 0; a northern one
    above. The two are mirror images under z -> -z, so one is computed and mirrored. ``state0``
    is the symmetric crossing continued from the Lyapunov start (the side of L toward the
    larger primary); ``state_half`` the other one.
    """
    sys_ = resolve_system(system)
    point = _check_point(point)
    sign = _check_branch(branch)
    lyap = _cached_lyapunov(sys_, point)
    cands = [b for b in lyap.bifurcations if b["index"] == "out-of-plane" and b["level"] == 1.0]
    if not cands:
        raise LibrateError(f"no halo bifurcation found on the L{point} Lyapunov family ({len(lyap)} members, end: {lyap.end_reason})")
    bif = cands[0]
    i = bif["member"]
    w = (bif["x0"] - lyap.x0[i]) / (lyap.x0[i + 1] - lyap.x0[i])
    p = lyap.state0[i] + w * (lyap.state0[i + 1] - lyap.state0[i])
    planar = correct_symmetric(sys_, p, fix="x0", family=f"lyapunov-L{point}")
    name = f"halo-L{point}-{branch}"
    first = correct_symmetric(sys_, (planar.x0, 2e-3, planar.vy0), spatial=True, fix="z0", family=name)
    res = continue_arclength(
        sys_, first, spatial=True, orient=np.array([0.0, 1.0, 0.0]), ds=2e-3, ds_max=ds_max, max_members=max_members,
        family=name, check_geometry=check_geometry, stop=_collision_stop(sys_, (sys_.r1_km, sys_.r2_km)),
    )
    fam = OrbitFamily.from_members(sys_, name, True, res.members, res.end_reason,
                                   {"point": point, "branch": branch, "bifurcation_x0": bif["x0"]})
    # Name the branch by the sign of z where |z| is largest along the family (apolune).
    both = np.concatenate([fam.state0[:, 2], fam.state_half[:, 2]])
    if np.sign(both[np.argmax(np.abs(both))]) != sign:
        flip = np.array([1.0, 1.0, -1.0, 1.0, 1.0, -1.0])
        fam.state0 = fam.state0 * flip
        fam.state_half = fam.state_half * flip
    return fam


@functools.lru_cache(maxsize=8)
def _cached_halo(system: System, point: int, branch: str) -> OrbitFamily:
    return halo_family(system, point, branch)


def halo(system: System | str = "earth-moon", point: int = 2, branch: str = "south", *, x0: float | None = None,
         z0: float | None = None, period: float | None = None, period_days: float | None = None,
         jacobi: float | None = None, which: int = 0) -> PeriodicOrbit:
    """One halo orbit at L1/L2 (north or south branch) by x0, z0, period (TU or days) or Jacobi
    constant, found on the family (computed once per system and cached)."""
    sys_ = resolve_system(system)
    point = _check_point(point)
    _check_branch(branch)
    name, value = _one_target(dict(x0=x0, z0=z0, period=period, period_days=period_days, jacobi=jacobi))
    return _cached_halo(sys_, point, branch).member(**{name: value}, which=which)
