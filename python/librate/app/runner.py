"""Long periodicity maps run safely: written chunk by chunk to a Zarr store, resumable after an
interrupt (Ctrl-C or even SIGKILL) with a bit-identical final result, with a progress bar, and
optionally spread over a Dask cluster.

Each orbit's row (all Kz and rates) is one chunk of work. A row's data are written first and its
``done`` flag after, so a kill at any moment loses at most the row in flight. Re-running the same
call on the same folder skips the finished rows; a folder that is not a librate map store, or
one written for different inputs (a fingerprint of every input is stored), is refused, never
overwritten. Rows are computed by the deterministic engine (independent of threads and
chunking), so a resumed or distributed run equals an uninterrupted local one bit for bit.
The rows run through :func:`librate.app.distribute.run_tasks` (locally, or on Dask: each row
checksummed on arrival, written by the worker itself on a shared filesystem).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import warnings
from pathlib import Path

import numpy as np

from ..periodicity.maps import map_coords, map_dataset, map_grid, map_solutions_dataset, orbits_of, row_candidates, solutions_from_rows
from ..periodicity.solutions import MAP_ATOL, MAP_RTOL, check_orbit, check_srp, orbit_forcing, sweep
from ..results.atomic import clean_orphans, remove_path, replace_path, temporary_sibling
from ..results.kinds import map_schema
from ..results.lock import writer_lock
from ..results.store import PartStore
from .distribute import PartCommits, Region, Task, run_tasks
from .progress import bar as progress_bar

__all__ = ["run_map"]

_GRID = ("dwz", "dphi", "phi_T")


def _row(orbit, kzs, wz, phi0, n_periods, srp, rtol, atol):
    """One orbit's residual grids (kz x wz0): the unit of work (picklable for Dask)."""
    kz_grid, wz_grid = np.meshgrid(kzs, wz, indexing="ij")
    r = sweep(orbit_forcing(orbit), n_periods * orbit.period, phi0, wz_grid, kz_grid, rtol=rtol, atol=atol, srp=srp)
    shape = (len(kzs), len(wz))
    return {k: r[src].reshape(shape) for k, src in (("dwz", "dwz"), ("dphi", "dphi"), ("phi_T", "phi_t"), ("status", "status"))}


def _fingerprint(olist, kzs, wz, phi0, n_periods, srp, rtol, atol) -> str:
    from .._core import __version__

    h = hashlib.sha256()
    for o in olist:
        h.update(np.asarray(o.state0, dtype=np.float64).tobytes())
        h.update(np.float64(o.period).tobytes())
        h.update(np.float64(o.system.mu).tobytes())
    for a in (kzs, wz):
        h.update(np.asarray(a, dtype=np.float64).tobytes())
    plate = None if srp is None else (srp.eps, srp.cs, srp.cd, srp.sun.theta0, srp.sun.pressure)
    h.update(json.dumps([phi0, int(n_periods), plate, rtol, atol, __version__]).encode())
    return h.hexdigest()


def run_map(
    orbits,
    *,
    kz,
    wz0,
    phi0: float = 0.0,
    n_periods: int = 1,
    srp=None,
    out=None,
    resume: bool = True,
    scheduler=None,
    progress: bool | None = None,
    solve: bool = True,
    attrs: dict | None = None,
    rtol: float = MAP_RTOL,
    atol: float = MAP_ATOL,
    replace: bool = False,
):
    """Compute a periodicity map (as `librate.periodicity_map`) row by row into a Zarr store,
    resumable, and return it.

    Each orbit row is written with its checksum as it completes; a run interrupted (or killed)
    resumes from the rows already in the store, and the result is the same as an uninterrupted
    run.

    Parameters
    ----------
    orbits : OrbitFamily, list of PeriodicOrbit or PeriodicOrbit
        Planar periodic orbits.
    kz : float or array_like
        Inertia ratio(s) Kz in [-1, 1].
    wz0 : array_like
        Inertial initial rates (1/TU), strictly increasing.
    phi0 : float, default 0.0
        Initial angle (rad).
    n_periods : int, default 1
        K, the orbit periods per attitude period.
    srp : FlatPlate, optional
        Solar radiation pressure.
    out : str or pathlib.Path, optional
        The Zarr store; without it nothing is written (and nothing can be resumed).
    resume : bool, default True
        Resume a store of the same inputs.
    scheduler : None, distributed.Client or str
        None: local, all cores; a Dask client or its address ("tcp://host:port"): each orbit row
        becomes a task.
    progress : bool, optional
        Progress bars (the rows, then the solutions) with rate and ETA on stderr (default: only
        when stderr is a terminal).
    solve : bool, default True
        Refine the periodic solutions.
    attrs : dict, optional
        Extra attributes (e.g. the study as JSON).
    rtol, atol : float
        Integration tolerances.
    replace : bool, default False
        An existing librate result at ``out`` is replaced all or nothing: the new map is computed
        into a temporary sibling under ``out``'s writer lock and takes the name only once
        complete.

    Returns
    -------
    xarray.Dataset
        The map, as `periodicity_map` returns it.

    Raises
    ------
    ValueError
        A bad argument, naming it.
    ResultExists
        ``out`` holds a map of other inputs (the message names what changed), unless ``replace``.
    StoreBusyError
        Another process is writing the same store (it holds its writer lock).
    """
    olist, family = orbits_of(orbits)
    for o in olist:
        check_orbit(o)
    if isinstance(srp, (list, tuple)):
        raise ValueError("invalid argument `srp`: run_map takes one plate; use periodicity_map for a list")
    srp = check_srp(srp)
    kzs, wz = map_grid(kz, wz0, n_periods)
    coords = map_coords(olist, kzs, wz)
    fp = _fingerprint(olist, kzs, wz, phi0, n_periods, srp, rtol, atol)
    args = (kzs, wz, float(phi0), int(n_periods), srp, float(rtol), float(atol))
    with contextlib.ExitStack() as stack:
        lock = None
        target = out
        if out is not None:
            import zarr

            lock = stack.enter_context(writer_lock(Path(out)))  # before anything is created or removed
            clean_orphans(Path(out))
            if replace and Path(out).exists():
                _check_replaceable(Path(out))
                target = temporary_sibling(Path(out))
                remove_path(target)
            # every chunk on disk, even one equal to the fill value: a missing chunk is damage
            stack.enter_context(zarr.config.set({"array.write_empty_chunks": True}))
        ds = _run(olist, family, kzs, wz, coords, fp, args, target, resume, scheduler, progress, solve, attrs,
                  phi0=phi0, n_periods=n_periods, srp=srp, rtol=rtol, atol=atol, lock=lock)
        if target is not out and target is not None:
            lock.check()
            if int(ds.attrs.get("complete", 0)) == 1:
                replace_path(target, Path(out))
            else:  # interrupted: the old map stays, the new one is not resumable under another name
                remove_path(target)
        return ds


def _run(olist, family, kzs, wz, coords, fp, args, out, resume, scheduler, progress, solve, attrs, *, phi0, n_periods,
         srp, rtol, atol, lock=None):
    no, nk, nw = len(olist), kzs.size, wz.size
    if out is not None:
        store, damaged = PartStore.open(Path(out), map_schema(no, nk, nw, coords), fp, resume=resume, attrs=attrs, lock=lock)
        done = store.done_flags(damaged)
        if damaged:
            warnings.warn(f"{out}: {len(damaged)} damaged row(s) are recomputed: "
                          + "; ".join(f"row {i}: {why}" for i, why in sorted(damaged.items())), RuntimeWarning, stacklevel=3)
    else:
        store = None
        done = np.zeros(no, dtype=bool)
        mem = {k: np.full((no, nk, nw), np.nan) for k in _GRID}
        mem["status"] = np.full((no, nk, nw), 255, dtype=np.uint8)

    def remember(i, row):
        for k in (*_GRID, "status"):
            mem[k][i] = row[k]
        done[i] = True

    # a stored row: its data, digests, then the done flag (or a worker's own write, checked)
    commits = PartCommits(store, done) if store is not None else None
    todo = [i for i in range(no) if not done[i]]
    bar = progress_bar(no, "periodicity map", "orbit", progress, initial=no - len(todo))
    region = None if store is None or lock is None or scheduler is None else Region.of(store, lock)
    try:
        run_tasks([Task(i, _row, (olist[i], *args)) for i in todo], remember if commits is None else commits.commit, scheduler=scheduler,
                  bar=bar, region=region, commit_written=None if commits is None else commits.commit_written)
    finally:
        bar.close()

    grid = {k: (store.g[k][:] if store is not None else mem[k]) for k in (*_GRID, "status")}
    ds = map_dataset(olist, family, kzs, wz, grid, done, phi0=phi0, n_periods=n_periods, rtol=rtol, atol=atol, srp=srp,
                      complete=done.all(), attrs={"fingerprint": fp, **(attrs or {})})
    if solve:
        sols = []
        total = sum(len(row_candidates(kzs, float(phi0), wz, grid["phi_T"][i])[0]) for i in range(no))
        with progress_bar(total, "solutions (Newton)", "candidate", progress) as sbar:
            for i, o in enumerate(olist):
                # the batches of periodicity_map (the same lock-step companions: the same bits); the
                # bar moves after each batch, also within a long orbit's refinement
                start = sbar.n
                sols += [(i, s) for s in solutions_from_rows(o, kzs, float(phi0), wz, grid["phi_T"][i], int(n_periods), srp,
                                                             progress=lambda done, _, start=start: sbar.update(start + done - sbar.n))]
        ds = ds.merge(map_solutions_dataset(sols))
    if store is not None:
        sol = {v: (("solution",), np.ascontiguousarray(ds[v].values), dict(ds[v].attrs)) for v in ds.data_vars if v.startswith("sol_")}
        store.finalise(sol, dict(ds.attrs), complete=bool(ds.attrs.get("complete", 0)))
    return ds


def _check_replaceable(out: Path) -> None:
    """Only a librate result may be replaced (a foreign folder is refused, never overwritten)."""
    from ..results.files import open_dataset
    from ..results.kinds import kind_of
    from ..results.store import store_kind

    if out.is_dir() and (not any(out.iterdir()) or store_kind(out) is not None):
        return
    try:
        ds = open_dataset(out)
    except ValueError:
        ds = None
    kind = None if ds is None else kind_of(ds)
    if ds is not None:
        ds.close()
    if kind is None:
        raise ValueError(f"invalid argument `out`: {out} exists and is not a librate result; refusing to replace it")
