"""3-D attitude maps (issue 15, item 5): residual grids of the rigid body's 3-D attitude along one
periodic orbit (planar or spatial) over initial inertial rates and bodies, and the periodic 3-D
motions seeded from their near-zeros.

A trajectory starts at the attitude ``q0`` (scalar last, the body relative to the synodic frame;
the same for the whole map) with the inertial rate w0 = (wx0, wy0, wz0) in body axes, and is
integrated over K = ``n_periods`` orbit periods. Its six residuals are those of the 3-D corrector
(:func:`~librate.periodic_attitude_3d`): the rotation vector r = (rx, ry, rz) of R(0)' R(KT) in
body axes at t = 0 (Log(q0* (x) q(KT)), angle in [0, pi]) and dw = w(KT) - w0. The grid runs in
the Rust engine's SIMD lanes (eight trajectories in lock step, over the orbit's tidal tensor
tabulated once; docs/physics/periodic-attitude-3d.md).

- :func:`attitude_map_3d`: the map as an xarray Dataset;
- :func:`map3d_grid`, :func:`map3d_chunk`, :func:`map3d_dataset`: its validated grid, one chunk
  of its flat cases, and its Dataset, for runners that compute a map in chunks and resume;
- :func:`find_periodic_attitudes_3d`: corrected periodic motions from the map's near-zeros.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import _core
from .._checks import MAP3D_CELL_BYTES, as_count, as_float_array, as_number, as_threads, as_tolerance, check_cells
from .._core import __version__
from .._display import fmt, html_summary, short_repr
from .._progress import as_progress
from ..attitude.body import RigidBody
from ..orbits.periodic import PeriodicOrbit
from ..results.kinds import MAP_3D_VARIABLES
from .attitude3d import SOLVE_RTOL, AttitudeSolution3D, verified_solution_3d

__all__ = ["attitude_map_3d", "find_periodic_attitudes_3d", "Map3DGrid", "map3d_grid", "map3d_chunk", "map3d_dataset", "tidal_table",
           "COMPONENTS", "LANES"]

#: The six residual components.
COMPONENTS = ("rx", "ry", "rz", "dwx", "dwy", "dwz")
#: Case alignment of the engine's lock-step groups (every SIMD level's group size divides it:
#: sixteen trajectories at AVX-512, eight elsewhere): chunks starting at multiples of LANES give
#: results bit-identical to one call over all cases.
LANES: int = _core.MAP3D_ALIGN
_RATES = ("wx0", "wy0", "wz0")


@dataclass(frozen=True)
class Map3DGrid:
    """The validated grid of a 3-D map: the bodies, the three initial rates (each a scalar or a
    strictly increasing 1-D array) and the initial attitude. ``dims`` are the array-valued
    dimensions in the order (body, wx0, wy0, wz0); the flat cases run over all four (scalars as
    length 1) in C order."""

    bodies: tuple[RigidBody, ...]
    body_dim: bool
    rates: tuple[np.ndarray, np.ndarray, np.ndarray]
    rate_dims: tuple[bool, bool, bool]
    q0: np.ndarray

    # --- display (librate._display): the rates by size and range, not in full -------------------
    def _rows(self):
        return [("dims", ", ".join(self.dims) or "none", ""), ("shape", self.shape, ""), ("n_cases", self.n_cases, ""),
                ("bodies", len(self.bodies), "")] + [(n, r, "rad/TU") for n, r in zip(_RATES, self.rates)]

    def __repr__(self) -> str:
        return short_repr("Map3DGrid", self._rows(), digits=4)

    def _repr_html_(self) -> str:
        bodies = [(f"body {i}", f"ix={fmt(b.ix)}, iy={fmt(b.iy)}, iz={fmt(b.iz)}", "") for i, b in enumerate(self.bodies)]
        return html_summary(f"librate.Map3DGrid ({self.n_cases} cases)", self._rows(),
                            {"bodies": bodies, "initial attitude": [("q0", self.q0, "scalar last")]})

    @property
    def dims(self) -> tuple[str, ...]:
        return (("body",) if self.body_dim else ()) + tuple(n for n, d in zip(_RATES, self.rate_dims) if d)

    @property
    def full_shape(self) -> tuple[int, int, int, int]:
        return (len(self.bodies), *(r.size for r in self.rates))

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(n for n, d in zip(self.full_shape, (self.body_dim, *self.rate_dims)) if d)

    @property
    def n_cases(self) -> int:
        return math.prod(self.full_shape)

    def cases(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(inertia (m, 3), w0 (m, 3)) of the flat cases [start, stop)."""
        stop = self.n_cases if stop is None else stop
        idx = np.unravel_index(np.arange(start, stop), self.full_shape)
        moments = np.array([b.moments for b in self.bodies], dtype=float)
        w0 = np.stack([self.rates[k][idx[k + 1]] for k in range(3)], axis=1)
        return np.ascontiguousarray(moments[idx[0]]), np.ascontiguousarray(w0)


def _bodies(body) -> tuple[tuple[RigidBody, ...], bool]:
    lst = list(body) if isinstance(body, (list, tuple)) else [body]
    if not lst:
        raise ValueError("invalid argument `body`: an empty list of bodies")
    for b in lst:
        if not isinstance(b, RigidBody) or b.is_rod:
            raise ValueError("invalid argument `body`: must be a librate.RigidBody with every principal moment > 0 (or a "
                             f"list of them), got {b!r}")
    return tuple(lst), isinstance(body, (list, tuple))


def _rate(v, name: str) -> tuple[np.ndarray, bool]:
    if isinstance(v, (bool, np.bool_)):
        raise ValueError(f"invalid argument `{name}`: must be a finite number or a strictly increasing 1-D array (rad/TU), got {v!r}")
    a = as_float_array(v, name)
    if a.ndim > 1 or a.size == 0 or not np.all(np.isfinite(a)) or (a.ndim == 1 and np.any(np.diff(a) <= 0)):
        raise ValueError(f"invalid argument `{name}`: must be a finite number or a non-empty, finite, strictly increasing 1-D "
                         f"array (rad/TU), got {v!r}")
    return np.atleast_1d(a).astype(float), a.ndim == 1


def _quaternion(q0) -> np.ndarray:
    if q0 is None:
        return np.array([0.0, 0.0, 0.0, 1.0])
    q = as_float_array(q0, "q0").ravel()
    n = float(np.linalg.norm(q)) if q.shape == (4,) and np.all(np.isfinite(q)) else math.nan
    if not abs(n - 1) <= 1e-6:
        raise ValueError(f"invalid argument `q0`: must be a unit quaternion (4 finite numbers, scalar last, |q0| = 1 to 1e-6), got {q0!r}")
    return q / n


def map3d_grid(body, *, wx0, wy0, wz0, q0=None) -> Map3DGrid:
    """The validated grid of :func:`attitude_map_3d` (a ValueError naming the argument)."""
    bodies, body_dim = _bodies(body)
    rates, dims = zip(*(_rate(v, n) for v, n in ((wx0, "wx0"), (wy0, "wy0"), (wz0, "wz0"))))
    check_cells((len(bodies), *(r.size for r in rates)), "`body`, `wx0`, `wy0`, `wz0`", item_bytes=MAP3D_CELL_BYTES)
    return Map3DGrid(bodies, body_dim, tuple(rates), tuple(dims), _quaternion(q0))


_TABLES: dict = {}


def tidal_table(orbit: PeriodicOrbit):
    """The orbit's tidal-tensor table (both primaries; computed once per orbit and cached)."""
    key = (orbit.system.mu, tuple(np.asarray(orbit.state0).tolist()), float(orbit.period))
    t = _TABLES.get(key)
    if t is None:
        if len(_TABLES) > 64:
            _TABLES.clear()
        t = _core.TidalTable(orbit.system.mu, [float(v) for v in orbit.state0], float(orbit.period), tol=1e-13)
        _TABLES[key] = t
    return t


def _check(orbit, n_periods, tol) -> tuple[int, float]:
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    n_periods = as_count(n_periods, "n_periods", 1)
    tol = as_tolerance(tol, "tol")
    return n_periods, tol


def map3d_chunk(orbit: PeriodicOrbit, grid: Map3DGrid, start: int, stop: int, *, n_periods: int = 1, tol: float = 1e-10,
                threads: int | None = None):
    """Integrate the flat cases [start, stop) of ``grid`` (C order over (body, wx0, wy0, wz0)) along
    ``orbit`` over ``n_periods`` periods at rtol = atol = ``tol``. ``start`` must be a multiple of
    :data:`LANES`, so that any chunking gives the results of one call, bit for bit. Returns the
    engine's Sweep3DResult: ``residual`` (m, 6), ``q_t`` (m, 4), ``w_t`` (m, 3), ``status`` (m,) uint8 (0 ok, 1 max steps,
    2 failed) and ``steps`` (m, 2)."""
    n_periods, tol = _check(orbit, n_periods, tol)
    start, stop = as_count(start, "start", 0), as_count(stop, "stop", 0)
    if start % LANES or not start <= stop <= grid.n_cases:
        raise ValueError(f"invalid argument `start`: need a multiple of {LANES} with start <= stop <= {grid.n_cases}, "
                         f"got ({start}, {stop})")
    inertia, w0 = grid.cases(start, stop)
    q = np.ascontiguousarray(np.broadcast_to(grid.q0, (stop - start, 4)))
    lanes = _core.LaneOptions(rtol=tol, atol=tol, threads=threads)
    return _core.map_sweep_3d(tidal_table(orbit), n_periods * float(orbit.period), q, w0, inertia, lanes=lanes)


def map3d_dataset(orbit: PeriodicOrbit, grid: Map3DGrid, residual: np.ndarray, status: np.ndarray, *, n_periods: int, tol: float,
                  complete: bool = True):
    """The 3-D map's Dataset from its flat ``residual`` (n, 6) and ``status`` (n,) (NaN and 255
    where not computed)."""
    import xarray as xr

    dims = grid.dims
    res = np.asarray(residual, dtype=float).reshape(*grid.shape, 6)
    st = np.asarray(status, dtype=np.uint8).reshape(grid.shape)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        norm = np.max(np.abs(res), axis=-1)
    coords: dict = {"component": ("component", list(COMPONENTS))}
    for name, a, d in zip(_RATES, grid.rates, grid.rate_dims):
        coords[name] = (((name,), a, {"units": "1/TU", "long_name": f"initial inertial rate, body {name[1]}"}) if d
                        else ((), float(a[0]), {"units": "1/TU"}))
    m = np.array([b.moments for b in grid.bodies])
    ratios = {"ix_iz": m[:, 0] / m[:, 2], "iy_iz": m[:, 1] / m[:, 2], "kz": (m[:, 1] - m[:, 0]) / m[:, 2]}
    for name, v in ratios.items():
        coords[name] = (("body",), v) if grid.body_dim else ((), float(v[0]))
    if grid.body_dim:
        coords["body"] = ("body", np.arange(len(grid.bodies)))
    s = orbit.system
    return xr.Dataset(
        {"residual": ((*dims, "component"), res, dict(MAP_3D_VARIABLES["residual"])),
         "residual_norm": (dims, norm, dict(MAP_3D_VARIABLES["residual_norm"])),
         "status": (dims, st, dict(MAP_3D_VARIABLES["status"]))},
        coords=coords,
        attrs={"title": "librate 3-D attitude map", "mu": s.mu, "lu_km": s.lu_km, "tu_s": s.tu_s, "system_name": s.name,
               "orbit_state0": [float(v) for v in orbit.state0], "orbit_period": float(orbit.period),
               "orbit_period_days": float(orbit.period_days),
               "n_periods": int(n_periods), "tol": float(tol), "q0": [float(v) for v in grid.q0],
               "simd_level": _core.build_info()["simd_active"],
               "complete": int(complete), "librate_version": __version__},
    )


def attitude_map_3d(orbit: PeriodicOrbit, body, *, wx0, wy0, wz0, q0=None, n_periods: int = 1, tol: float = 1e-10,
                    progress: Callable[[int, int], None] | bool | None = None, threads: int | None = None):
    """The 3-D attitude map of a body along an orbit: the six closure residuals over a grid of
    initial rates.

    Work is done in chunks; on KeyboardInterrupt the finished chunks are kept, with
    ``attrs["complete"] = 0``. Results are bit-identical for any ``threads``.

    Parameters
    ----------
    orbit : PeriodicOrbit
        The orbit (planar or spatial).
    body : RigidBody or list of RigidBody
        The body; a list adds a ``body`` dimension with coordinates ix_iz, iy_iz, kz.
    wx0, wy0, wz0 : float or array_like
        Initial inertial rates in body axes (1/TU): each a number or a strictly increasing 1-D
        array.
    q0 : array_like, shape (4,), optional
        The initial attitude of every trajectory (scalar last, body relative to the synodic
        frame; default identity).
    n_periods : int, default 1
        K, the orbit periods per attitude period.
    tol : float, default 1e-10
        The integration tolerance (rtol = atol).
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)`` after each chunk.
    threads : int, optional
        Worker threads.

    Returns
    -------
    xarray.Dataset
        Over (body?, wx0?, wy0?, wz0?) (the array-valued ones, in that order): ``residual``
        (..., component: rx, ry, rz, dwx, dwy, dwz; the rotation vector of R(0)' R(KT) and
        w(KT) - w0), ``residual_norm`` (its max-norm) and ``status`` (0 ok, 1 max steps, 2 failed,
        255 not computed); the orbit, n_periods, tol, q0 and the SIMD level as attributes.

    Raises
    ------
    ValueError
        A bad argument, naming it.

    See Also
    --------
    - [`find_periodic_attitudes_3d`][librate.periodicity.map3d.find_periodic_attitudes_3d]: periodic motions
      seeded from the map's near-zeros.
    """
    progress = as_progress(progress, "3-D map", "case")
    n_periods, tol = _check(orbit, n_periods, tol)
    threads = as_threads(threads)
    grid = map3d_grid(body, wx0=wx0, wy0=wy0, wz0=wz0, q0=q0)
    n = grid.n_cases
    residual = np.full((n, 6), np.nan)
    status = np.full(n, 255, dtype=np.uint8)
    step = max(LANES, (max(n // 20, 512) // LANES) * LANES)
    complete = True
    try:
        for start in range(0, n, step):
            stop = min(n, start + step)
            r = map3d_chunk(orbit, grid, start, stop, n_periods=n_periods, tol=tol, threads=threads)
            residual[start:stop], status[start:stop] = r.residual, r.status
            if progress is not None:
                progress(stop, n)
    except KeyboardInterrupt:
        complete = False
        warnings.warn(f"attitude_map_3d interrupted: {int(np.sum(status != 255))} of {n} trajectories finished and kept", stacklevel=2)
    return map3d_dataset(orbit, grid, residual, status, n_periods=n_periods, tol=tol, complete=complete)


def _same(a: AttitudeSolution3D, b: AttitudeSolution3D, tol: float) -> bool:
    dq = abs(float(np.dot(a.q0, b.q0)))  # q and -q are one attitude
    return 2 * math.acos(min(1.0, dq)) <= tol and float(np.max(np.abs(a.w0 - b.w0))) <= tol


def find_periodic_attitudes_3d(orbit: PeriodicOrbit, body: RigidBody, dataset, *, max_seeds: int = 16, threshold: float = 0.5,
                               tol: float = 1e-12, n_periods: int | None = None, max_iter: int = 40) -> list[AttitudeSolution3D]:
    """Periodic 3-D attitude motions seeded from the near-zeros of a 3-D map.

    Six residuals over a grid of one to three rates generally have no exact zeros, so the seeds
    are the grid's local minima of ``residual_norm`` below ``threshold``, the ``max_seeds``
    smallest. Each seed is corrected with all six unknowns free, in one batched call of the 3-D
    corrector, to ``tol``; converged motions that coincide (attitude and rates to 1e-8) are
    merged, and each is re-propagated independently.

    Parameters
    ----------
    orbit : PeriodicOrbit
        The orbit of the map.
    body : RigidBody
        One of the map's bodies.
    dataset : xarray.Dataset
        The map (`attitude_map_3d` of that orbit).
    max_seeds : int, default 16
        The most seeds corrected.
    threshold : float, default 0.5
        The largest ``residual_norm`` of a seed.
    tol : float, default 1e-12
        The corrector's tolerance.
    n_periods : int, optional
        K (default the map's).
    max_iter : int, default 40
        Newton iterations per seed.

    Returns
    -------
    list of AttitudeSolution3D
        Sorted by w0.

    Raises
    ------
    ValueError
        A bad argument (e.g. a body not in the map), naming it.
    """
    from scipy.ndimage import minimum_filter

    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if not isinstance(body, RigidBody) or body.is_rod:
        raise ValueError(f"invalid argument `body`: must be a librate.RigidBody with every principal moment > 0, got {body!r}")
    if not hasattr(dataset, "attrs") or dataset.attrs.get("title") != "librate 3-D attitude map":
        raise ValueError("invalid argument `dataset`: must be a Dataset from librate.attitude_map_3d")
    if (dataset.attrs["mu"] != orbit.system.mu or float(dataset.attrs["orbit_period"]) != float(orbit.period)
            or list(np.asarray(dataset.attrs["orbit_state0"], dtype=float)) != [float(v) for v in orbit.state0]):
        raise ValueError("invalid argument `orbit`: not the orbit of the map (its state0 and period are in the dataset's attributes)")
    max_seeds = as_count(max_seeds, "max_seeds", 1)
    max_iter = as_count(max_iter, "max_iter", 1)
    threshold = as_number(threshold, "threshold", positive=True)
    tol = as_tolerance(tol, "tol")
    n_periods = int(dataset.attrs["n_periods"]) if n_periods is None else as_count(n_periods, "n_periods", 1)
    ds = dataset
    m = np.array(body.moments)
    ratios = (m[0] / m[2], m[1] / m[2])
    if "body" in ds.dims:
        hit = np.flatnonzero(np.isclose(ds["ix_iz"].values, ratios[0], rtol=0, atol=1e-12)
                             & np.isclose(ds["iy_iz"].values, ratios[1], rtol=0, atol=1e-12))
        if hit.size == 0:
            raise ValueError(f"invalid argument `body`: its inertia ratios {ratios} are not among the map's bodies")
        ds = ds.isel(body=int(hit[0]))
    elif abs(float(ds["ix_iz"]) - ratios[0]) > 1e-12 or abs(float(ds["iy_iz"]) - ratios[1]) > 1e-12:
        raise ValueError(f"invalid argument `body`: its inertia ratios {ratios} are not the map's ({float(ds['ix_iz'])}, "
                         f"{float(ds['iy_iz'])})")
    dims = [d for d in _RATES if d in ds["residual_norm"].dims]
    norm = ds["residual_norm"].transpose(*dims).values if dims else np.atleast_1d(ds["residual_norm"].values)
    filled = np.where(np.isfinite(norm), norm, np.inf)
    is_min = (filled == minimum_filter(filled, size=3, mode="nearest")) & (filled < threshold)
    idx = np.argwhere(is_min)
    idx = idx[np.argsort(filled[is_min], kind="stable")][:max_seeds]
    if idx.size == 0:
        return []
    rates = [np.atleast_1d(ds[d].values) for d in _RATES]
    w = np.zeros((len(idx), 3))
    for k, d in enumerate(_RATES):
        w[:, k] = rates[k][idx[:, dims.index(d)]] if d in dims else rates[k][0]
    q0 = np.asarray(ds.attrs["q0"], dtype=float)
    q = np.ascontiguousarray(np.broadcast_to(q0 / np.linalg.norm(q0), (len(idx), 4)))
    T = n_periods * float(orbit.period)
    options = _core.CorrectorOptions3D(_core.NewtonOptions(tol=float(tol), max_iter=int(max_iter)), rtol=SOLVE_RTOL, atol=SOLVE_RTOL)
    r = _core.attitude_correct_3d(orbit.system.mu, list(body.moments), [float(v) for v in orbit.state0], T, _core.AttitudeCases3D(q, w),
                                  options=options)
    sols: list[AttitudeSolution3D] = []
    for i, reason in enumerate(r.reason):
        if reason != "converged":
            continue
        s = verified_solution_3d(orbit, body, n_periods, r.q0[i], r.w0[i], r.monodromy[i], int(r.iterations[i]))
        if not any(_same(s, o, 1e-8) for o in sols):
            sols.append(s)
    return sorted(sols, key=lambda s: tuple(s.w0))
