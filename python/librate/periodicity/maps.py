"""Periodicity maps: residual grids over (orbit, Kz, wz0) and the solutions they contain
(thesis sec. 3.3, docs/physics.md, periodic attitude motions), and the map Dataset builders shared with
:func:`librate.app.runner.run_map`.

Grids run in the Rust engine (:func:`~librate.periodicity.solutions.sweep`, one orbit at a
time); the candidates of each full-period row are refined by
:func:`~librate.periodicity.solutions.periodic_attitude`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np

from .. import _core
from .._checks import as_count, as_float_array, as_number, as_threads, as_tolerance, check_map_cells
from .._core import __version__
from .._errors import LibrateError
from .._progress import as_progress
from ..orbits.families import OrbitFamily
from ..orbits.periodic import PeriodicOrbit
from ..results.kinds import MAP_VARIABLES
from .solutions import (
    MAP_ATOL,
    MAP_METHOD,
    MAP_RTOL,
    AttitudeSolution,
    Refining,
    check_orbit,
    check_srp,
    is_symmetric,
    orbit_forcing,
    start_refine,
    sweep,
    turns_array,
    turns_of,
)

__all__ = ["periodicity_map", "zero_contours", "orbits_of", "map_grid", "map_coords", "map_coordinates", "map_dataset",
           "solutions_from_row", "solutions_from_rows", "start_row_solutions", "row_candidates", "crossing_windows",
           "map_solutions_dataset", "solution_variables", "REFINE_BATCH_PERIODS", "MAX_CROSSINGS", "QUICK_WINDOW", "RESOLVED"]


def orbits_of(orbits) -> tuple[list[PeriodicOrbit], OrbitFamily | None]:
    if isinstance(orbits, OrbitFamily):
        return list(orbits), orbits
    if isinstance(orbits, PeriodicOrbit):
        return [orbits], None
    try:
        lst = list(orbits)
    except TypeError:
        raise ValueError("invalid argument `orbits`: must be an OrbitFamily, a PeriodicOrbit or a list of them, got "
                         f"{type(orbits).__name__}") from None
    if not lst or not all(isinstance(o, PeriodicOrbit) for o in lst):
        raise ValueError("invalid argument `orbits`: must be a non-empty list of librate.PeriodicOrbit")
    return lst, None


def periodicity_map(
    orbits,
    *,
    kz,
    wz0,
    phi0: float = 0.0,
    n_periods: int = 1,
    solve: bool = True,
    progress: Callable[[int, int], None] | bool | None = None,
    rtol: float = MAP_RTOL,
    atol: float = MAP_ATOL,
    chunk: int = 64,
    threads: int | None = None,
    srp=None,
    method: str = MAP_METHOD,
):
    """The attitude periodicity map: residual grids over (orbit, Kz, wz0) and the periodic solutions
    they contain (thesis Fig. 24).

    Every grid point is one attitude trajectory over K orbit periods (the SIMD engine); the zero
    crossings of the residuals along wz0 are refined by Newton into periodic solutions (with
    ``solve``). Work is done one orbit at a time; on KeyboardInterrupt the finished orbits are
    kept and returned, with ``attrs["complete"] = 0``. Results are bit-identical for any ``chunk``
    and ``threads``.

    Parameters
    ----------
    orbits : OrbitFamily, list of PeriodicOrbit or PeriodicOrbit
        Planar periodic orbits.
    kz : float or array_like
        Inertia ratio(s) Kz = (Iy - Ix) / Iz in [-1, 1].
    wz0 : array_like
        Inertial initial rates (1/TU), strictly increasing; phidot0 = wz0 - 1 relative to the
        synodic frame.
    phi0 : float, default 0.0
        Initial angle (rad).
    n_periods : int, default 1
        K, the orbit periods per attitude period.
    solve : bool, default True
        Refine every crossing into a periodic solution (the ``sol_*`` variables).
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)`` called after each orbit.
    rtol, atol : float, default 1e-12
        Integration tolerances.
    chunk : int, default 64
        Trajectories per work unit.
    threads : int, optional
        Worker threads (default: all cores).
    srp : FlatPlate or list of FlatPlate, optional
        Solar radiation pressure (with ``n_periods`` = K for Sun-resonant orbits, T = Ts / K). A
        list adds an ``srp`` dimension; solutions are then refined in (phi0, wz0) together (the
        mirror symmetry is broken).
    method : {"rkf78", "dp87", "rkn86"}
        The engine's integrator, stored as ``attrs["integrator"]``.

    Returns
    -------
    xarray.Dataset
        ``dwz`` = wz(T) - wz0, ``dphi`` = phi(T) - phi0 wrapped to (-pi, pi] and the unwrapped
        ``phi_T`` over (orbit, kz, wz0) with units; coordinates x0, period, period_days per orbit
        and phidot0; with ``solve`` the solutions along ``solution`` (``sol_orbit``, ``sol_kz``,
        ``sol_wz0``, ``sol_n``, ``sol_kind``, ``sol_stable``, ...).

    Raises
    ------
    ValueError
        A bad argument, naming it and the allowed range.
    IntegrationError
        A trajectory could not be integrated.

    Examples
    --------
    >>> import librate, numpy as np
    >>> fam = librate.dro_family(librate.System.preset("earth-moon"), x0=np.linspace(0.9, 0.7, 3))
    >>> ds = librate.periodicity_map(fam, kz=0.8, wz0=np.linspace(-3.0, 2.0, 50))
    >>> dict(ds["dwz"].sizes)
    {'orbit': 3, 'kz': 1, 'wz0': 50}
    """


    progress = as_progress(progress, "periodicity map", "orbit")
    olist, family = orbits_of(orbits)
    for o in olist:
        check_orbit(o)
    if isinstance(srp, (list, tuple)):
        if not srp:
            raise ValueError("invalid argument `srp`: an empty list of plates")
        plates = [check_srp(p) for p in srp]
        maps = [periodicity_map(olist if family is None else family, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, solve=solve,
                                progress=progress, rtol=rtol, atol=atol, chunk=chunk, threads=threads, srp=p,
                                method=method) for p in plates]
        return _stack_srp(maps, plates)
    srp = check_srp(srp)
    kzs, wz = map_grid(kz, wz0, n_periods)
    phi0 = as_number(phi0, "phi0")
    check_map_cells((len(olist), kzs.size, wz.size), "`orbits`, `kz`, `wz0`")
    chunk = as_count(chunk, "chunk", 1)
    threads = as_threads(threads)
    rtol, atol = as_tolerance(rtol, "rtol"), as_tolerance(atol, "atol")
    no, nk, nw = len(olist), kzs.size, wz.size
    dwz = np.full((no, nk, nw), np.nan)
    dphi = np.full((no, nk, nw), np.nan)
    phi_t = np.full((no, nk, nw), np.nan)
    status = np.full((no, nk, nw), 255, dtype=np.uint8)
    done = np.zeros(no, dtype=bool)
    sols: list[tuple[int, AttitudeSolution]] = []
    kz_grid, wz_grid = np.meshgrid(kzs, wz, indexing="ij")
    complete = True
    coords = None
    # the last orbit's solutions are refined on the core's pool while the coordinates are built
    # (the others' at once); a row counts as computed once its solutions are in
    pending: tuple[int, Refining] | None = None

    def finish(p: tuple[int, Refining]) -> None:
        j, refining = p
        sols.extend((j, s) for s in refining.result())
        done[j] = True
        if progress is not None:
            progress(j + 1, no)

    try:
        for i, o in enumerate(olist):
            try:
                forcing = orbit_forcing(o)
            except LibrateError as err:  # e.g. an orbit through a primary (CollisionError): its row stays uncomputed
                complete = False
                warnings.warn(f"periodicity_map: orbit {i} (x0 = {o.x0:.10g}) skipped, its row left uncomputed: {err}", stacklevel=2)
                continue
            r = sweep(forcing, n_periods * o.period, phi0, wz_grid, kz_grid, rtol=rtol, atol=atol, chunk=chunk,
                      threads=threads, srp=srp, method=method)
            dwz[i], dphi[i], phi_t[i] = (r[k].reshape(nk, nw) for k in ("dwz", "dphi", "phi_t"))
            status[i] = r["status"].reshape(nk, nw)
            if solve:
                pending = (i, start_row_solutions(o, kzs, phi0, wz, phi_t[i], n_periods, srp))
                if i < no - 1:
                    p, pending = pending, None
                    finish(p)
            else:
                done[i] = True
                if progress is not None:
                    progress(i + 1, no)
        coords = map_coordinates(olist, kzs, wz)
        if pending is not None:
            p, pending = pending, None
            finish(p)
    except KeyboardInterrupt:
        complete = False
        if pending is not None:  # the last orbit's refinement may have finished (else Ctrl-C stopped it too)
            try:
                finish(pending)
            except KeyboardInterrupt:
                pass
        warnings.warn(f"periodicity_map interrupted: {int(done.sum())} of {no} orbits finished and kept", stacklevel=2)
    grid = {"dwz": dwz, "dphi": dphi, "phi_T": phi_t, "status": status}
    return map_dataset(olist, family, kzs, wz, grid, done, phi0=phi0, n_periods=n_periods, rtol=rtol, atol=atol, srp=srp, complete=complete,
                       solutions=sols if solve else None, attrs={"integrator": str(method)}, coords=coords)


def map_grid(kz, wz0, n_periods):
    """Validated Kz values and (strictly increasing) inertial rates of a map."""
    if isinstance(kz, (bool, np.bool_)) or (isinstance(kz, (list, tuple)) and any(isinstance(v, (bool, np.bool_)) for v in kz)):
        raise ValueError(f"invalid argument `kz`: values must be numbers in [-1, 1], got {kz!r}")
    kzs = np.atleast_1d(as_float_array(kz, "kz"))
    if kzs.ndim != 1 or kzs.size == 0 or not np.all(np.isfinite(kzs)) or np.any(np.abs(kzs) > 1):
        raise ValueError(f"invalid argument `kz`: values must be finite and in [-1, 1], got {kz!r}")
    wz = as_float_array(wz0, "wz0").ravel()
    if wz.size < 2 or not np.all(np.isfinite(wz)) or np.any(np.diff(wz) <= 0):
        raise ValueError("invalid argument `wz0`: must be a finite, strictly increasing array of at least 2 rates")
    n_periods = as_count(n_periods, "n_periods", 1)
    return kzs, wz


def map_coordinates(olist, kzs, wz):
    """A map's coordinates (:func:`map_coords`) as an xarray Coordinates, with their indexes."""
    import xarray as xr

    return xr.Coordinates(map_coords(olist, kzs, wz))


def map_coords(olist, kzs, wz) -> dict:
    """name -> (dimension, values, attributes) of a map's coordinates."""
    return {
        "orbit": ("orbit", np.arange(len(olist)), {}),
        "x0": ("orbit", np.array([o.x0 for o in olist]), {"units": "LU"}),
        "period": ("orbit", np.array([o.period for o in olist]), {"units": "TU"}),
        "period_days": ("orbit", np.array([o.period_days for o in olist]), {"units": "d"}),
        "kz": ("kz", kzs, {"long_name": "(Iy - Ix) / Iz"}),
        "wz0": ("wz0", wz, {"units": "1/TU", "long_name": "initial inertial angular rate"}),
        "phidot0": ("wz0", wz - 1.0, {"units": "1/TU", "long_name": "initial rate relative to the synodic frame"}),
    }


def _common_family(olist) -> str:
    """The family name the orbits share (a study's members, which come without their family), else ""."""
    names = {getattr(o, "family", "") for o in olist}
    return names.pop() if len(names) == 1 and "symmetric" not in names else ""


def map_dataset(olist, family, kzs, wz, grid, done, *, phi0, n_periods, rtol, atol, srp, complete, attrs=None, solutions=None, coords=None):
    """The map's Dataset: residual grids over (orbit, kz, wz0), coordinates with units and the
    parameters as attributes (shared by periodicity_map and run_map); ``solutions``: (orbit
    index, AttitudeSolution) pairs, the ``sol_*`` variables along ``solution``; ``coords``: the
    :func:`map_coordinates` of these orbits and grid, when built already."""
    import xarray as xr

    dims = ("orbit", "kz", "wz0")
    return xr.Dataset(
        {
            **(solution_variables(solutions) if solutions is not None else {}),
            # units and long names: one place, shared with the map store (librate.results.kinds)
            **{k: (dims, grid[k], dict(MAP_VARIABLES[k])) for k in ("dwz", "dphi", "phi_T", "status")},
            "computed": ("orbit", np.asarray(done, dtype=bool).copy()),
        },
        coords=map_coordinates(olist, kzs, wz) if coords is None else coords,
        attrs={
            "title": "librate attitude periodicity map",
            "phi0": float(phi0),
            "n_periods": int(n_periods),
            "rtol": float(rtol),
            "atol": float(atol),
            "complete": int(complete),
            "mu": olist[0].system.mu,
            "lu_km": olist[0].system.lu_km,
            "tu_s": olist[0].system.tu_s,
            "system_name": olist[0].system.name,
            "family": family.kind if family is not None else _common_family(olist),
            "librate_version": __version__,
            "srp_eps": float(srp.eps) if srp is not None else 0.0,
            "srp_cs": float(srp.cs) if srp is not None else 0.0,
            "srp_cd": float(srp.cd) if srp is not None else 0.0,
            "theta_sun0": float(srp.sun.theta0) if srp is not None else 0.0,
            **(attrs or {}),
        },
    )

def _stack_srp(maps, plates):
    """Maps for several plates stacked along an ``srp`` dimension (coordinates srp_eps, srp_cs,
    srp_cd and the Sun phase theta_sun0); solutions gain ``sol_srp``."""
    import xarray as xr

    grid_vars = ["dwz", "dphi", "phi_T", "status"]
    out = xr.concat([m[grid_vars + ["computed"]] for m in maps], dim="srp")
    out = out.transpose("orbit", "srp", "kz", "wz0")
    out = out.assign_coords(
        srp=np.arange(len(plates)),
        srp_eps=("srp", np.array([p.eps for p in plates])),
        srp_cs=("srp", np.array([p.cs for p in plates])),
        srp_cd=("srp", np.array([p.cd for p in plates])),
        theta_sun0=("srp", np.array([p.sun.theta0 for p in plates])),
    )
    out["computed"] = out["computed"].all("srp")
    out.attrs = {k: v for k, v in maps[0].attrs.items() if not k.startswith("srp_") and k != "theta_sun0"}
    out.attrs["complete"] = int(all(m.attrs["complete"] for m in maps))
    if "solution" in maps[0].dims:
        sols = []
        for i, m in enumerate(maps):
            if m.sizes.get("solution", 0):
                part = m[[v for v in m.data_vars if v.startswith("sol_")]]
                sols.append(part.assign(sol_srp=("solution", np.full(m.sizes["solution"], i))))
        if sols:
            out = out.merge(xr.concat(sols, dim="solution"))
    return out


#: The most candidate-periods (candidates x orbit periods each) refined in one corrector call.
#: A longer batch is split, in order, into batches of at most that work (and at least
#: REFINE_BATCH_MIN candidates: two lock-step lane groups), so that progress is reported between
#: them: 1504 candidates over 20 periods took 19 s in one call, and a 16-rate map over 1000
#: periods refined for 14 minutes without a note. Batches within the limit are refined in one
#: call, as before (a candidate's last bits, ~1e-14, depend on its batch companions).
REFINE_BATCH_PERIODS = 4096
REFINE_BATCH_MIN = 16


#: The most multiples of pi that phi(KT) - phi0 may cross between two neighbouring rates of a
#: map row for its crossings to be candidates. Past that the rate grid does not resolve the
#: angle and the linear guesses are noise: a grid that resolves it crosses at most 1.4 (the demo,
#: 1000 rates; the tutorial, 300), while 16 rates over 1000 periods cross up to ~2000 per interval
#: (29,392 candidates on one DRO, 94,000 on the example study's 12) and 16 rates over 20 periods
#: gave 1504 candidates that refined in 19 s to no solution.
MAX_CROSSINGS = 8


#: A map's crossing is refined within its rate interval widened by this many intervals on each
#: side, where the map resolves phi(KT) there (:data:`RESOLVED`): a solution there converges in
#: one or two Newton steps, and a candidate whose Newton step leaves that neighbourhood has none
#: nearby. The standard map's 13 crossings: 6 converge in place; the other 7 travelled 0.13-1.06
#: in wz0 (50-425 intervals) to a solution another crossing found in place, or to none, and
#: took three times the corrector's rounds.
QUICK_WINDOW = 4

#: The most phi(KT) may change between neighbouring rates, in multiples of pi, for the map to
#: resolve it: then every solution (phi(KT) = phi0 + k pi with wz(KT) = wz0) lies at a crossing
#: of its own and the crossings are refined in their windows (:data:`QUICK_WINDOW`). Where the
#: grid is coarser they are searched for without a window, as a solution the grid does not
#: resolve may be found from a crossing far away (14 DROs x 3 Kz on 50-400 rates: the only
#: two found more than 4 intervals from their crossing lay where phi(KT) changed by 0.65 and
#: 1.1 pi per interval; the crossings that travelled that far to no new solution, by a median of
#: 0.03-0.6 pi).
RESOLVED = 0.25


def row_candidates(kzs, phi0, wz, phi_t_rows) -> tuple[list, list[float], int]:
    """The candidates of one orbit's rows (one per Kz: where phi(KT) - phi0 crosses a multiple of
    pi), the Kz of each, and the number of rate intervals left out as unresolved (more than
    :data:`MAX_CROSSINGS` crossings)."""
    cands, kk, unresolved, _ = crossing_windows(kzs, phi0, wz, phi_t_rows)
    return cands, kk, unresolved


def crossing_windows(kzs, phi0, wz, phi_t_rows) -> tuple[list, list[float], int, tuple[np.ndarray, np.ndarray]]:
    """:func:`row_candidates` with each candidate's search window (lo, hi) of wz0: its rate
    interval widened by :data:`QUICK_WINDOW` intervals on each side where phi(KT) changes by at
    most :data:`RESOLVED` pi per interval there, else (-inf, inf) (librate_core::map::windows)."""
    kzs = np.atleast_1d(np.asarray(kzs, dtype=float))
    rows = np.atleast_2d(np.asarray(phi_t_rows, dtype=float))
    wz = np.ascontiguousarray(wz, dtype=float)
    cands, kk, unresolved, lo, hi = [], [], 0, [], []
    for j, k in enumerate(kzs.tolist()):
        c = _core.row_crossings(np.ascontiguousarray(rows[j]), wz, phi0=float(phi0), level=math.pi, max_crossings=MAX_CROSSINGS,
                                window=(QUICK_WINDOW, RESOLVED))
        cands += zip(c.k.tolist(), c.wz0.tolist())
        kk += [k] * len(c.k)
        unresolved += c.unresolved
        lo.append(c.window[:, 0])
        hi.append(c.window[:, 1])
    return cands, kk, unresolved, (np.concatenate(lo), np.concatenate(hi))


def solutions_from_rows(orbit, kzs, phi0, wz, phi_t_rows, n_periods, srp=None,
                        progress: Callable[[int, int], None] | None = None) -> list[AttitudeSolution]:
    """The solutions of one orbit's rows (one per Kz): the candidates where phi(KT) - phi0 crosses
    a multiple of pi (:func:`row_candidates`), refined in ONE call of the Rust corrector (the
    half-period form where the orbit and phi0 are symmetric and there is no SRP, each crossing
    within its window of :func:`crossing_windows`; else the full-period form with phi0 free)
    and verified in one more; kept inside the row's rate window.
    A batch of more than :data:`REFINE_BATCH_PERIODS` candidate-periods is refined in several
    calls, in order (solutions found twice kept once). ``progress(done, total)``: after each
    call, in candidates."""
    return start_row_solutions(orbit, kzs, phi0, wz, phi_t_rows, n_periods, srp, progress).result()


def start_row_solutions(orbit, kzs, phi0, wz, phi_t_rows, n_periods, srp=None,
                        progress: Callable[[int, int], None] | None = None) -> Refining:
    """:func:`solutions_from_rows`, started: a batch within :data:`REFINE_BATCH_PERIODS` runs on
    the core's pool while the caller goes on, and ``result()`` waits for it (and reports
    ``progress``); a longer one is refined here, batch by batch."""
    cands, kk, unresolved, (lo, hi) = crossing_windows(kzs, phi0, wz, phi_t_rows)
    if unresolved:
        warnings.warn(f"the rate grid does not resolve phi(KT) on the orbit x0 = {orbit.x0:.6g} LU (K = {int(n_periods)} periods): "
                      f"{unresolved} interval(s) of `wz0` where it turns through more than {MAX_CROSSINGS} half-turns are left out "
                      "of the solutions; a finer wz0 grid finds them", RuntimeWarning, stacklevel=3)
    symmetric = is_symmetric(orbit, phi0) and (srp is None or srp.eps == 0.0)
    size = max(REFINE_BATCH_MIN, REFINE_BATCH_PERIODS // max(int(n_periods), 1))
    def batch(a: int) -> Refining:
        return start_refine(orbit, np.array(kk[a:a + size]), phi0, cands[a:a + size], n_periods=n_periods, srp=srp,
                            closure="half" if symmetric else "full", window=(float(wz[0]), float(wz[-1])),
                            search=(lo[a:a + size], hi[a:a + size]) if symmetric else None)

    first = batch(0)  # under way while the caller goes on; later batches start in turn

    def finish() -> list[AttitudeSolution]:
        sols: list[AttitudeSolution] = []
        for a in range(0, len(cands), size):
            b = first if a == 0 else batch(a)
            sols += [s for _, s in b.result()]
            if progress is not None:
                progress(min(a + size, len(cands)), len(cands))
        if len(cands) > size:  # candidates of two batches that converged onto one solution: kept once
            sols = _distinct(sols)
        return sorted(sols, key=lambda s: (s.kz, s.wz0))

    return Refining(finish)


def _distinct(sols: list[AttitudeSolution]) -> list[AttitudeSolution]:
    """The first of each solution, in order, by the rule a batch's refinement merges by
    (``_core.distinct_solutions``: the same Kz and turns with wz0 within 1e-8)."""
    if not sols:
        return []
    kz, wz0 = np.array([s.kz for s in sols], dtype=float), np.array([s.wz0 for s in sols], dtype=float)
    turns = turns_of([s.n_total for s in sols], [s.kind for s in sols])
    keep = _core.distinct_solutions(np.zeros(len(sols), dtype=np.int64), kz, turns, wz0)
    return [sols[i] for i in keep.tolist()]


def solutions_from_row(orbit, kz, phi0, wz, phi_t_row, n_periods, srp=None) -> list[AttitudeSolution]:
    """Candidates from one full-period row (phi(T) - phi0 through multiples of pi), refined
    (:func:`solutions_from_rows` with one Kz)."""
    return solutions_from_rows(orbit, [kz], phi0, wz, [phi_t_row], n_periods, srp)


def solution_variables(sols) -> dict:
    """The ``sol_*`` variables (name -> (dimension, values[, attributes])) of (orbit index,
    AttitudeSolution) pairs."""
    idx = np.array([i for i, _ in sols], dtype=np.int64)
    s = [x for _, x in sols]
    return {
        "sol_orbit": ("solution", idx),
        "sol_kz": ("solution", np.array([x.kz for x in s], dtype=float)),
        "sol_wz0": ("solution", np.array([x.wz0 for x in s], dtype=float), {"units": "1/TU"}),
        "sol_phidot0": ("solution", np.array([x.phidot0 for x in s], dtype=float), {"units": "1/TU"}),
        "sol_phi0": ("solution", np.array([x.phi0 for x in s], dtype=float), {"units": "rad"}),
        "sol_n": ("solution", turns_array(x.n for x in s), {"long_name": "net body turns per orbit period"}),
        "sol_n_total": ("solution", np.array([x.n_total for x in s], dtype=np.int64),
                        {"long_name": "net body turns over the n_periods orbit periods"}),
        "sol_kind": ("solution", np.array([x.kind for x in s], dtype="<U9")),
        "sol_residual": ("solution", np.array([x.residual for x in s], dtype=float)),
        "sol_trace": ("solution", np.array([x.trace for x in s], dtype=float)),
        "sol_stable": ("solution", np.array([x.stable for x in s], dtype=bool)),
    }


def map_solutions_dataset(sols):
    import xarray as xr

    return xr.Dataset(solution_variables(sols))


def zero_contours(ds, var: str = "dwz", kz_index: int = 0) -> np.ndarray:
    """The points where a residual of a periodicity map crosses zero along wz0, orbit by orbit.

    Parameters
    ----------
    ds : xarray.Dataset
        A map of `periodicity_map`.
    var : {"dwz", "dphi"}
        The residual; for ``"dphi"`` the wrap jumps at +-pi are not crossings.
    kz_index : int, default 0
        The Kz of the map.

    Returns
    -------
    numpy.ndarray, shape (m, 2)
        (orbit x0, wz0) of each crossing, by linear interpolation between grid points.

    Raises
    ------
    ValueError
        ``var`` is neither "dwz" nor "dphi".
    """
    if var not in ("dwz", "dphi"):
        raise ValueError(f"invalid argument `var`: must be 'dwz' or 'dphi', got {var!r}")
    a = ds[var].values[:, kz_index, :]
    wz = ds["wz0"].values
    x0 = ds["x0"].values
    pts = []
    for i in range(a.shape[0]):
        row = a[i]
        for j in range(len(row) - 1):
            u, v = row[j], row[j + 1]
            if not (np.isfinite(u) and np.isfinite(v)) or (u > 0) == (v > 0) or u == v:
                continue
            if var == "dphi" and abs(u - v) > math.pi:
                continue
            pts.append((x0[i], wz[j] + u / (u - v) * (wz[j + 1] - wz[j])))
    return np.array(pts).reshape(-1, 2)
