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

import contextlib
import hashlib
import json
import os
import warnings
from pathlib import Path

import numpy as np

from .._integrity import array_digest
from ..periodicity.maps import map_coords, map_dataset, map_grid, map_solutions_dataset, orbits_of, solutions_from_rows
from ..periodicity.solutions import MAP_ATOL, MAP_RTOL, check_orbit, check_srp, orbit_forcing, sweep
from .progress import bar as progress_bar
from .store import ROW_VARS, check_rows, open_map_group, read_array, row_checksum, writer_lock

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


def _create_store(out: Path, fingerprint: str, shape, coords: dict, attrs: dict | None = None):
    """A new store, built in a temporary sibling folder and renamed into place: ``out`` is
    either absent (or an empty folder) or a complete, marked, empty store; never half-made."""
    import shutil

    import zarr

    tmp = out.with_name(f".{out.name}.creating-{os.getpid()}")
    if tmp.exists():
        shutil.rmtree(tmp)
    g = zarr.open_group(str(tmp), mode="w", zarr_format=2)
    no, nk, nw = shape
    dims3 = ["orbit", "kz", "wz0"]
    extra_coords = "x0 period period_days phidot0"
    grid_attrs = {"_ARRAY_DIMENSIONS": dims3, "coordinates": extra_coords}
    for name in _GRID:
        g.create_array(name, shape=shape, chunks=(1, nk, nw), dtype="f8", fill_value=np.nan, attributes=grid_attrs)
    g.create_array("status", shape=shape, chunks=(1, nk, nw), dtype="u1", fill_value=255, attributes=grid_attrs)
    g.create_array("done", shape=(no,), chunks=(1,), dtype="bool", fill_value=False, attributes={"_ARRAY_DIMENSIONS": ["orbit"]})
    g.create_array("row_checksum", shape=(no, len(ROW_VARS)), chunks=(1, len(ROW_VARS)), dtype="u8", fill_value=None,
                   attributes={"_ARRAY_DIMENSIONS": ["orbit", "checksum_of"], "columns": " ".join(ROW_VARS),
                               "long_name": "64-bit BLAKE2b digest of each row of dwz, dphi, phi_T, status"})
    _write_coords(g, coords)
    g.attrs.put(_base_attrs(fingerprint, coords, complete=0, attrs=attrs))
    if out.exists():
        out.rmdir()  # an empty folder (checked by the caller)
    os.replace(tmp, out)
    return zarr.open_group(str(out), mode="r+", use_consolidated=False)


def _write_coords(g, coords: dict) -> None:
    for name, (dim, values, attrs) in coords.items():
        # no fill value: xarray would read a fill value of 0 as "missing" (orbit 0, Kz = 0)
        a = g.create_array(name, shape=values.shape, chunks=values.shape, dtype=values.dtype, fill_value=None, overwrite=True,
                           attributes={"_ARRAY_DIMENSIONS": [dim], **attrs})
        a[:] = values


def _base_attrs(fingerprint: str, coords: dict, complete: int, attrs: dict | None = None) -> dict:
    """The root attributes every state of the store carries (the marker first of all), with the
    caller's text attributes (e.g. the study), so that an unfinished store says what it holds."""
    extra = {k: v for k, v in (attrs or {}).items() if isinstance(v, str)}
    return {**extra, "librate_store": "periodicity_map", "fingerprint": fingerprint, "complete": int(complete),
            "coord_checksums": {name: array_digest(values) for name, (_, values, _) in coords.items()}}


def _open_store(out: Path, fingerprint: str, shape, resume: bool, coords: dict, attrs: dict | None = None):
    """Open (resume) or create the store at ``out``; the caller holds the writer lock.
    Returns ``(group, damaged)``: the rows whose data do not match their checksums."""
    if out.exists() and not out.is_dir():
        raise ValueError(f"invalid argument `out`: {out} exists and is not a folder; refusing to overwrite it")
    for stale in out.parent.glob(f".{out.name}.creating-*"):  # left by a creation killed before its rename
        import shutil

        shutil.rmtree(stale, ignore_errors=True)
    if not out.exists() or not any(out.iterdir()):
        return _create_store(out, fingerprint, shape, coords, attrs), {}
    try:
        g = open_map_group(out, mode="r+")
    except ValueError as err:
        raise ValueError(f"invalid argument `out`: {err}; refusing to overwrite it") from None
    if g.attrs.get("fingerprint") != fingerprint:
        raise ValueError(f"invalid argument `out`: {out} holds a map of different inputs (fingerprint mismatch); use another folder")
    if not resume:
        raise ValueError(f"invalid argument `out`: {out} already holds this map; pass resume=True to continue it or choose another folder")
    bad = []
    for k in (*_GRID, "status", "done", "row_checksum"):
        try:
            a = g[k]
            ok = a.shape == (shape if k in (*_GRID, "status") else (shape[0],) if k == "done" else (shape[0], len(ROW_VARS)))
        except Exception as err:  # noqa: BLE001 - a missing or unreadable .zarray
            bad.append(f"{k} ({'missing' if isinstance(err, KeyError) else 'metadata unreadable'})")
            continue
        if not ok:
            bad.append(f"{k} (wrong shape {a.shape})")
    if bad:
        raise ValueError(f"invalid argument `out`: {out} is a corrupt librate map store (arrays {', '.join(bad)}); "
                         "refusing to overwrite it; remove it or choose another folder")
    # From here on the store is ours and being written: stale consolidated metadata goes first,
    # then the root attributes say "incomplete" (marker kept) until the finalisation ends.
    zmeta = out / ".zmetadata"
    if zmeta.exists():
        zmeta.unlink()
    g.attrs.put(_base_attrs(fingerprint, coords, complete=0, attrs=attrs))
    for name, (_, values, _) in coords.items():  # the coordinates are known: repair, never trust
        try:
            same = name in g and np.array_equal(read_array(g, name), values)
        except ValueError:
            same = False
        if not same:
            _write_coords(g, {name: coords[name]})
    damaged, _ = check_rows(g, out)
    return g, damaged


def _finalise(g, out: Path, ds, fingerprint: str, coords: dict) -> None:
    """Write the solution table and the final attributes. Every step leaves a store that a
    re-run resumes: the marker never leaves the root attributes, ``complete`` becomes 1 only
    with the last attribute write, and the consolidated metadata (a cache) comes after."""
    import zarr

    sol_vars = [v for v in ds.data_vars if v.startswith("sol_")]
    existing = set(g.array_keys())
    for name in existing:
        if name.startswith("sol_") and name not in sol_vars:
            del g[name]
    sums = {}
    for v in sol_vars:
        values = np.ascontiguousarray(ds[v].values)
        a = g.create_array(v, shape=values.shape, chunks=(max(1, values.shape[0]),), dtype=values.dtype, fill_value=None,
                           overwrite=v in existing, attributes={"_ARRAY_DIMENSIONS": ["solution"], **ds[v].attrs})
        if values.size:
            a[:] = values
        sums[v] = array_digest(values)
    attrs = {k: v for k, v in ds.attrs.items() if isinstance(v, (int, float, str))}
    attrs.update(_base_attrs(fingerprint, coords, complete=int(ds.attrs.get("complete", 0))))
    attrs["sol_checksums"] = sums
    g.attrs.put(attrs)
    try:
        zarr.consolidate_metadata(str(out), zarr_format=2)
    except Exception:  # noqa: BLE001 - consolidation is an optimisation only
        pass


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
    ("tcp://host:port"): each orbit row becomes a task. ``progress``: progress bars (the rows,
    then the solutions) with rate and ETA on stderr (default: only when stderr is a terminal). ``attrs``: extra attributes
    (e.g. the study as JSON). Without ``out`` nothing is written (and nothing can be resumed).
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
        if out is not None:
            import zarr

            stack.enter_context(writer_lock(Path(out)))
            # every chunk on disk, even one equal to the fill value: a missing chunk is damage
            stack.enter_context(zarr.config.set({"array.write_empty_chunks": True}))
        return _run(olist, family, kzs, wz, coords, fp, args, out, resume, scheduler, progress, solve, attrs,
                    phi0=phi0, n_periods=n_periods, srp=srp, rtol=rtol, atol=atol)


def _run(olist, family, kzs, wz, coords, fp, args, out, resume, scheduler, progress, solve, attrs, *, phi0, n_periods, srp, rtol, atol):
    no, nk, nw = len(olist), kzs.size, wz.size
    if out is not None:
        store, damaged = _open_store(Path(out), fp, (no, nk, nw), resume, coords, attrs)
        done = _done_flags(store, damaged)
        if damaged:
            warnings.warn(f"{out}: {len(damaged)} damaged row(s) are recomputed: "
                          + "; ".join(f"row {i}: {why}" for i, why in sorted(damaged.items())), RuntimeWarning, stacklevel=3)
    else:
        store = None
        done = np.zeros(no, dtype=bool)
        mem = {k: np.full((no, nk, nw), np.nan) for k in _GRID}
        mem["status"] = np.full((no, nk, nw), 255, dtype=np.uint8)

    def write(i, row):
        if store is not None:
            for k in (*_GRID, "status"):
                store[k][i] = row[k]
            store["row_checksum"][i] = row_checksum(row)  # after the data, before the flag
            store["done"][i] = True  # after the data: a kill in between recomputes the row
        else:
            for k in (*_GRID, "status"):
                mem[k][i] = row[k]
        done[i] = True

    todo = [i for i in range(no) if not done[i]]
    bar = progress_bar(no, "periodicity map", "orbit", progress, initial=no - len(todo))
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
        with progress_bar(no, "solutions (Newton)", "orbit", progress) as sbar:
            for i, o in enumerate(olist):
                # one batch per orbit, as periodicity_map does (the same lock-step companions: the same bits)
                sols += [(i, s) for s in solutions_from_rows(o, kzs, float(phi0), wz, grid["phi_T"][i], int(n_periods), srp)]
                sbar.update(1)
        ds = ds.merge(map_solutions_dataset(sols))
    if store is not None:
        _finalise(store, Path(out), ds, fp, coords)
    return ds


def _done_flags(store, damaged: dict) -> np.ndarray:
    """The rows to skip: done and undamaged (a row with an unreadable flag counts as not done)."""
    no = int(store["done"].shape[0])
    done = np.zeros(no, dtype=bool)
    for i in range(no):
        if i in damaged:
            continue
        try:
            done[i] = bool(store["done"][i])
        except Exception:  # noqa: BLE001 - already reported by check_rows
            done[i] = False
    return done


