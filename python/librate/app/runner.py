"""Long periodicity maps run safely: written chunk by chunk to a Zarr store, resumable after an
interrupt (Ctrl-C or even SIGKILL) with a bit-identical final result, with a progress bar, and
optionally spread over a Dask cluster.

Each orbit's row (all Kz and rates) is one chunk of work. A row's data are written first and its
``done`` flag after, so a kill at any moment loses at most the row in flight. Re-running the same
call on the same folder skips the finished rows; a folder that is not a librate map store, or
one written for different inputs (a fingerprint of every input is stored), is refused, never
overwritten. Rows are computed by the deterministic engine (independent of threads and
chunking), so a resumed or distributed run equals an uninterrupted local one bit for bit.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

from ..periodicity.maps import map_coords, map_dataset, map_grid, map_solutions_dataset, orbits_of, solutions_from_rows
from ..periodicity.solutions import MAP_ATOL, MAP_RTOL, check_orbit, check_srp, orbit_forcing, sweep

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


def _open_store(out: Path, fingerprint: str, shape, resume: bool, coords: dict):
    import zarr

    if out.exists():
        if not out.is_dir():
            raise ValueError(f"invalid argument `out`: {out} exists and is not a folder; refusing to overwrite it")
        try:
            g = zarr.open_group(str(out), mode="r+")
            kind = g.attrs.get("librate_store")
        except Exception:  # noqa: BLE001 - anything unreadable is foreign or corrupt
            g, kind = None, None
        if g is None or kind != "periodicity_map":
            if any(out.iterdir()):
                raise ValueError(f"invalid argument `out`: {out} is not a librate map store (foreign or corrupt); refusing to overwrite it")
        else:
            if g.attrs.get("fingerprint") != fingerprint:
                raise ValueError(f"invalid argument `out`: {out} holds a map of different inputs (fingerprint mismatch); use another folder")
            if not resume:
                raise ValueError(f"invalid argument `out`: {out} already holds this map; pass resume=True to continue it or choose another folder")
            missing = [k for k in (*_GRID, "status", "done") if k not in g]
            if missing:
                raise ValueError(f"invalid argument `out`: {out} is a corrupt librate map store (missing {missing}); refusing to overwrite it")
            return g
    g = zarr.open_group(str(out), mode="w", zarr_format=2)
    g.attrs.update({"librate_store": "periodicity_map", "fingerprint": fingerprint})
    no, nk, nw = shape
    dims3 = ["orbit", "kz", "wz0"]
    extra_coords = "x0 period period_days phidot0"
    for name in _GRID:
        a = g.create_array(name, shape=shape, chunks=(1, nk, nw), dtype="f8", fill_value=np.nan)
        a.attrs.update({"_ARRAY_DIMENSIONS": dims3, "coordinates": extra_coords})
    a = g.create_array("status", shape=shape, chunks=(1, nk, nw), dtype="u1", fill_value=255)
    a.attrs.update({"_ARRAY_DIMENSIONS": dims3, "coordinates": extra_coords})
    a = g.create_array("done", shape=(no,), chunks=(1,), dtype="bool", fill_value=False)
    a.attrs["_ARRAY_DIMENSIONS"] = ["orbit"]
    for name, (dim, values, attrs) in coords.items():
        # no fill value: xarray would read a fill value of 0 as "missing" (orbit 0, Kz = 0)
        a = g.create_array(name, shape=values.shape, chunks=values.shape, dtype=values.dtype, fill_value=None)
        a[:] = values
        a.attrs.update({"_ARRAY_DIMENSIONS": [dim], **attrs})
    return g


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
):
    """Compute a periodicity map (as :func:`librate.periodicity_map`) row by row into a Zarr
    store at ``out`` (resumable; see the module docs), and return it as an xarray Dataset.

    ``scheduler``: None (local, all cores), a Dask ``distributed.Client``, or its address
    ("tcp://host:port"): each orbit row becomes a task. ``progress``: a progress bar with rate
    and ETA on stderr (default: only when stderr is a terminal). ``attrs``: extra attributes
    (e.g. the study as JSON). Without ``out`` nothing is written (and nothing can be resumed).
    """
    olist, family = orbits_of(orbits)
    for o in olist:
        check_orbit(o)
    if isinstance(srp, (list, tuple)):
        raise ValueError("invalid argument `srp`: run_map takes one plate; use periodicity_map for a list")
    srp = check_srp(srp)
    kzs, wz = map_grid(kz, wz0, n_periods)
    no, nk, nw = len(olist), kzs.size, wz.size
    coords = map_coords(olist, kzs, wz)
    fp = _fingerprint(olist, kzs, wz, phi0, n_periods, srp, rtol, atol)
    args = (kzs, wz, float(phi0), int(n_periods), srp, float(rtol), float(atol))
    if out is not None:
        store = _open_store(Path(out), fp, (no, nk, nw), resume, coords)
        done = np.asarray(store["done"][:], dtype=bool)
    else:
        store = None
        done = np.zeros(no, dtype=bool)
        mem = {k: np.full((no, nk, nw), np.nan) for k in _GRID}
        mem["status"] = np.full((no, nk, nw), 255, dtype=np.uint8)

    def write(i, row):
        if store is not None:
            for k in (*_GRID, "status"):
                store[k][i] = row[k]
            store["done"][i] = True  # after the data: a kill in between recomputes the row
        else:
            for k in (*_GRID, "status"):
                mem[k][i] = row[k]
        done[i] = True

    todo = [i for i in range(no) if not done[i]]
    show = sys.stderr.isatty() if progress is None else bool(progress)
    from tqdm.auto import tqdm

    bar = tqdm(total=no, initial=no - len(todo), disable=not show, unit="orbit", desc="periodicity map", file=sys.stderr)
    try:
        if scheduler is None:
            for i in todo:
                write(i, _row(olist[i], *args))
                bar.update(1)
        else:
            from distributed import Client, as_completed

            client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
            try:
                futures = {client.submit(_row, olist[i], *args, pure=False): i for i in todo}
                for fut in as_completed(futures):
                    write(futures[fut], fut.result())
                    bar.update(1)
            finally:
                if client is not scheduler:
                    client.close()
    finally:
        bar.close()

    grid = {k: (store[k][:] if store is not None else mem[k]) for k in (*_GRID, "status")}
    ds = map_dataset(olist, family, kzs, wz, grid, done, phi0=phi0, n_periods=n_periods, rtol=rtol, atol=atol, srp=srp,
                      complete=done.all(), attrs={"fingerprint": fp, **(attrs or {})})
    if solve:
        sols = []
        for i, o in enumerate(olist):
            # one batch per orbit, as periodicity_map does (the same lock-step companions: the same bits)
            sols += [(i, s) for s in solutions_from_rows(o, kzs, float(phi0), wz, grid["phi_T"][i], int(n_periods), srp)]
        ds = ds.merge(map_solutions_dataset(sols))
    if store is not None:
        sol_vars = [v for v in ds.data_vars if v.startswith("sol_")]
        if sol_vars:
            ds[sol_vars].to_zarr(str(out), mode="a")
        import zarr

        g = zarr.open_group(str(out), mode="r+")
        g.attrs.update({k: v for k, v in ds.attrs.items() if isinstance(v, (int, float, str))})
        g.attrs["librate_store"] = "periodicity_map"
        g.attrs["fingerprint"] = fp
        try:
            zarr.consolidate_metadata(str(out))
        except Exception:  # noqa: BLE001 - consolidation is an optimisation only
            pass
    return ds


