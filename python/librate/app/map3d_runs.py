"""The work behind a 3-D ``librate map``: the 3-D attitude map of a study's orbits written orbit by
orbit (or chunk by chunk of the rate grids) to a part store (:class:`librate.results.PartStore`,
``librate_result = "map_3d"``), resumable and crash-proof like the planar maps
(:mod:`librate.app.runner`), on a Dask cluster through :func:`librate.app.distribute.run_tasks`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..results.atomic import clean_orphans, remove_path, temporary_sibling
from ..results.kinds import map3d_schema
from ..results.lock import writer_lock
from ..results.store import PartStore, store_kind
from .results import check_output, open_result, publish_parts

__all__ = ["MIN_TASKS_3D", "run_map_3d_to"]


def _fingerprint_3d(olist, grid, n_periods: int, tol: float) -> str:
    import hashlib
    import json

    from .._core import __version__

    h = hashlib.sha256()
    for o in olist:
        h.update(np.asarray(o.state0, dtype=np.float64).tobytes())
        h.update(np.float64(o.period).tobytes())
        h.update(np.float64(o.system.mu).tobytes())
    for a in grid.rates:
        h.update(np.asarray(a, dtype=np.float64).tobytes())
    h.update(json.dumps([[list(b.moments) for b in grid.bodies], [float(v) for v in grid.q0], int(n_periods),
                         float(tol), __version__]).encode())
    return h.hexdigest()


def _orbit_map_3d(orbit, body, rates: dict, q0, n_periods: int, tol: float, names: tuple) -> dict:
    """One orbit's part of a 3-D map (the unit of work, picklable for Dask): its arrays ``names``."""
    from ..periodicity.map3d import attitude_map_3d

    ds = attitude_map_3d(orbit, body, wx0=rates["wx0"], wy0=rates["wy0"], wz0=rates["wz0"], q0=q0, n_periods=n_periods, tol=tol)
    if int(ds.attrs.get("complete", 0)) != 1:
        raise KeyboardInterrupt(f"in the orbit of x0 = {orbit.state0[0]:.6g} LU")
    return {k: np.asarray(ds[k].values) for k in names}


def _chunk_map_3d(orbit, grid, start: int, stop: int, n_periods: int, tol: float) -> dict:
    """The flat cases [start, stop) of one orbit's 3-D map (a task): residual (m, 6), status (m,)."""
    from ..periodicity.map3d import map3d_chunk

    r = map3d_chunk(orbit, grid, start, stop, n_periods=n_periods, tol=tol)
    return {"residual": np.asarray(r.residual), "status": np.asarray(r.status)}


def _chunk_step(n_cases: int, n_orbits: int, chunk_cases) -> int | None:
    """Cases per task of a 3-D map (a multiple of the engine's lanes), or None for one task per
    orbit. ``chunk_cases``: None (locally: per orbit), "auto" (on a cluster: orbits split until
    there are at least :data:`MIN_TASKS_3D` tasks, each of at least 1024 cases), or a count."""
    from ..periodicity.map3d import LANES

    if chunk_cases is None:
        return None
    if chunk_cases == "auto":
        if n_orbits == 0 or n_orbits >= MIN_TASKS_3D:
            return None
        per = -(-MIN_TASKS_3D // n_orbits)
        chunk_cases = max(1024, -(-n_cases // per))
    from .._checks import as_count

    n = as_count(chunk_cases, "chunk_cases", 1)
    step = -(-n // LANES) * LANES
    return None if step >= n_cases else step


#: On a cluster, a 3-D map of fewer orbits is split into chunks of their rate grids until it has
#: at least this many tasks (each of at least 1024 cases).
MIN_TASKS_3D = 16


def run_map_3d_to(orbits, store: str | Path, *, body, rates: dict, q0, n_periods: int = 1, tol: float = 1e-12, resume: bool = True,
                  scheduler=None, progress: bool | None = None, attrs: dict[str, Any] | None = None, chunk_cases: int | str = "auto"):
    """The 3-D attitude map of a ``[attitude] model = "3d"`` study, written to ``store`` (a
    ``.zarr`` or ``.nc`` result, ``librate_result = "map_3d"``): for every orbit, the six closure
    residuals (:func:`librate.attitude_map_3d`, integration tolerance ``tol``) over the rate
    grids of ``rates`` (``{"wx0", "wy0", "wz0"}``: arrays or single values) from the attitude
    ``q0``, along a dimension ``orbit`` (coordinates ``x0``, ``z0``, ``period_days``).

    The map is a part store (:class:`librate.results.PartStore`, one part per orbit, under the
    writer lock): ``<store>`` itself for ``.zarr``, ``<store>.parts`` for ``.nc`` (exported
    whole at the end, then removed). A run stopped at any moment (Ctrl-C, a kill) loses at most
    the orbit in flight, and the same call again reuses the finished orbits (a damaged one is
    named in a warning and recomputed). An existing ``store`` of the same study is reused; of
    another study it is refused unless ``resume`` is False: then the new map is computed
    aside and replaces the old one only once complete. Returns ``(dataset, store_path)``.

    ``scheduler``: None (this process, all cores), a Dask ``distributed.Client`` or its address:
    each orbit is one task (:func:`librate.app.distribute.run_tasks`: checksummed on arrival,
    written by the worker itself where it shares the store's filesystem, resubmitted when lost
    with its worker); the map equals the local one bit for bit. ``chunk_cases``: on a cluster,
    the cases (trajectories) per task: "auto" (fewer than 16 orbits are split into chunks of
    their rate grids, at least 1024 cases each, until there are 16 tasks), a count (rounded up to
    a multiple of the engine's 8 lanes; then locally too), or None (one task per orbit). A chunked
    orbit is gathered and committed whole (any chunking gives the same bits)."""
    import warnings

    from ..periodicity.map3d import COMPONENTS, map3d_dataset, map3d_grid
    from ..periodicity.maps import orbits_of
    from .distribute import PartCommits, Region, Task, run_tasks
    from .progress import bar as progress_bar

    store = Path(store)
    attrs = dict(attrs or {})
    study = attrs.get("study")
    olist, _ = orbits_of(orbits)
    # a rate given as one value is fixed (a number, not a dimension of length 1)
    rates = {k: float(np.ravel(v)[0]) if np.size(v) == 1 else np.asarray(v, dtype=float) for k, v in rates.items()}
    grid = map3d_grid(body, wx0=rates["wx0"], wy0=rates["wy0"], wz0=rates["wz0"], q0=q0)
    state = check_output(store, "map_3d", study, force=not resume)
    with writer_lock(store) as lock:
        clean_orphans(store)
        if state == "resume" and store_kind(store) is None:  # written whole (older librate): reused
            return open_result(store, verify=True).load(), store
        parts = store if store.suffix == ".zarr" else store.with_name(store.name + ".parts")
        if state == "replace" and parts == store:
            parts = temporary_sibling(store)
        if state == "replace":
            remove_path(parts)
        tpl = map3d_dataset(olist[0], grid, np.full((grid.n_cases, 6), np.nan), np.full(grid.n_cases, 255, dtype=np.uint8),
                            n_periods=n_periods, tol=tol)
        coords = {str(k): (tuple(c.dims) if c.ndim != 1 else c.dims[0], np.asarray(c.values), dict(c.attrs)) for k, c in tpl.coords.items()}
        coords.update({"orbit": ("orbit", np.arange(len(olist)), {}),
                       "x0": ("orbit", np.array([o.state0[0] for o in olist]), {"units": "LU"}),
                       "z0": ("orbit", np.array([o.state0[2] for o in olist]), {"units": "LU"}),
                       "period_days": ("orbit", np.array([o.period_days for o in olist]), {"units": "d"})})
        for k in ("component",):
            coords[k] = (k, np.array(COMPONENTS), {})
        schema = map3d_schema(len(olist), grid.shape, grid.dims, coords)
        pstore, damaged = PartStore.open(parts, schema, _fingerprint_3d(olist, grid, n_periods, tol), attrs=attrs, lock=lock)
        if damaged:
            warnings.warn(f"{parts}: {len(damaged)} damaged orbit(s) are recomputed: "
                          + "; ".join(f"orbit {i}: {why}" for i, why in sorted(damaged.items())), RuntimeWarning, stacklevel=2)
        done = pstore.done_flags(damaged)
        left = [i for i in range(len(olist)) if not done[i]]
        step = _chunk_step(grid.n_cases, len(left), chunk_cases if scheduler is not None or chunk_cases != "auto" else None)
        if step is None:  # one task per orbit
            todo = [Task(i, _orbit_map_3d, (olist[i], body, rates, q0, n_periods, tol, tuple(schema.variables))) for i in left]
        else:  # one task per chunk of an orbit's rate grids; the orbit is committed whole
            todo = [Task((i, a), _chunk_map_3d, (olist[i], grid, a, min(a + step, grid.n_cases), n_periods, tol))
                    for i in left for a in range(0, grid.n_cases, step)]
        pieces: dict[int, dict] = {}

        def gather(key, part):
            """A chunk's result kept until its orbit is complete, then the orbit's part (None before)."""
            if step is None:
                return key, part
            i, a = key
            pieces.setdefault(i, {})[a] = part
            if len(pieces[i]) < -(-grid.n_cases // step):
                return None
            mine = pieces.pop(i)
            got = [mine[a] for a in range(0, grid.n_cases, step)]
            ds_i = map3d_dataset(olist[i], grid, np.concatenate([g["residual"] for g in got]),
                                 np.concatenate([g["status"] for g in got]),
                                 n_periods=n_periods, tol=tol)
            return i, {k: np.asarray(ds_i[k].values) for k in schema.variables}

        with progress_bar(len(olist), "3-D attitude map", "orbit", progress, initial=int(done.sum())) as bar:
            commits = PartCommits(pstore, done, "orbit", bar, gather)
            try:
                run_tasks(todo, commits.commit, scheduler=scheduler,
                          region=None if scheduler is None or step is not None else Region.of(pstore, lock),
                          commit_written=commits.commit_written)
            except KeyboardInterrupt as err:  # the finished orbits are kept
                raise KeyboardInterrupt(f"3-D map interrupted ({err}); {int(done.sum())} finished orbit(s) kept in {parts}") from None
        # the same for every orbit
        shared = ("mu", "lu_km", "tu_s", "system_name", "n_periods", "tol", "q0", "simd_level", "librate_version")
        final = {k: tpl.attrs[k] for k in shared if k in tpl.attrs}
        final.update({"librate_result": "map_3d", **attrs, "title": "librate 3-D attitude map"})
        state0 = np.array([np.asarray(o.state0, dtype=float) for o in olist])
        pstore.finalise({"orbit_state0": (("orbit", "state"), state0, {"units": "LU, LU/TU", "long_name": "orbit initial state"})},
                        final, complete=True)
        publish_parts(parts, store, lock)
        return open_result(store).load(), store
