"""Results on disk: orbit families, periodic-solution tables and periodicity maps.

Every result is an xarray Dataset written as Zarr (a ``.zarr`` folder, chunked) or netCDF (a
``.nc`` file) whose attributes carry ``librate_result`` ("family", "solutions" or "map"), the
full study as JSON (``study``) and the package version (``librate_version``), next to the units
of every variable. :func:`open_result` reloads any of them without recomputing. Writing is
all-or-nothing (into a temporary sibling, then renamed), and an existing path that is not a
librate result is refused, never overwritten.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .._integrity import write_atomically

__all__ = ["RESULT_KINDS", "open_result", "read_attrs", "result_kind", "run_map_to", "save_dataset", "save_family", "solutions_dataset",
           "verify_result"]

#: The kinds of result, as stored in the ``librate_result`` attribute.
RESULT_KINDS = ("family", "solutions", "map")
_NAMES = ("map.zarr", "family.zarr", "solutions.zarr", "map.nc", "family.nc", "solutions.nc")


def _is_zarr(p: Path) -> bool:
    return p.is_dir() and any((p / n).exists() for n in (".zgroup", ".zattrs", ".zmetadata", "zarr.json"))


def result_kind(ds) -> str | None:
    """"family", "solutions" or "map" for a librate result Dataset (from its ``librate_result``
    attribute, or recognised from its variables for files written by ``OrbitFamily.save`` or
    ``periodicity_map``), else None."""
    k = ds.attrs.get("librate_result")
    if k in RESULT_KINDS:
        return str(k)
    if "state0" in ds.variables and "kind" in ds.attrs:
        return "family"
    if "dwz" in ds.variables:
        return "map"
    if "sol_wz0" in ds.variables:
        return "solutions"
    return None


def resolve_result_path(path: str | Path) -> Path:
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"no result at {str(p)!r}")
    if p.is_dir() and not _is_zarr(p):
        found = [p / n for n in _NAMES if (p / n).exists()]
        if len(found) == 1:
            return found[0]
        if not found:
            raise ValueError(f"{str(p)!r} is a folder with no librate result in it (looked for {', '.join(_NAMES)}) and not a Zarr store")
        raise ValueError(f"{str(p)!r} holds several results ({', '.join(f.name for f in found)}): give one of them")
    return p


def _open_dataset(p: Path):
    import xarray as xr

    try:
        if p.is_file() and p.suffix == ".nc":
            return xr.open_dataset(p, engine="scipy")
        if _is_zarr(p):
            return xr.open_dataset(p, engine="zarr", chunks=None)
    except (OSError, TypeError, ValueError, KeyError) as err:
        raise ValueError(f"{str(p)!r} cannot be read as a librate result: {type(err).__name__}: {str(err).splitlines()[0]}") from None
    raise ValueError(f"{str(p)!r} is neither a netCDF file (.nc) nor a Zarr store (.zarr folder)")


def read_attrs(path: str | Path) -> dict:
    """The attributes of a saved result (``librate_result``, ``study`` as JSON,
    ``librate_version``, units and constants), without loading its data."""
    p = resolve_result_path(path)
    ds = _open_dataset(p)
    try:
        return dict(ds.attrs)
    finally:
        ds.close()


def open_result(path: str | Path, *, verify: bool = False):
    """Reload a saved result without recomputing: an :class:`~librate.OrbitFamily` for a family
    (through :meth:`OrbitFamily.load`), an ``xarray.Dataset`` for a periodicity map or a table
    of periodic solutions (its ``attrs["study"]`` is the study as JSON).

    ``path``: a ``.zarr`` folder or a ``.nc`` file, or an output folder holding exactly one of
    map/family/solutions. ``verify``: first check the result as :func:`verify_result` does
    (every chunk against its checksum, every map row computed) and raise ``ValueError`` naming
    the damage. Raises ``FileNotFoundError`` or ``ValueError`` (not a librate result, or damaged).
    """
    from ..orbits.families import OrbitFamily

    p = resolve_result_path(path)
    if verify:
        ok, report = verify_result(p)
        if not ok:
            raise ValueError(report)
    ds = _open_dataset(p)
    kind = result_kind(ds)
    if kind is None:
        ds.close()
        raise ValueError(f"{str(p)!r} is not a librate result (no librate_result attribute; neither a family, a map nor solutions)")
    if kind == "family":
        ds.close()
        if p.suffix not in (".zarr", ".nc"):
            raise ValueError(f"{str(p)!r}: a saved family must be a .zarr folder or a .nc file")
        return OrbitFamily.load(p)
    if "row_checksum" in ds.variables:  # the map store's integrity data, not a result
        ds = ds.drop_vars("row_checksum")
    return ds


def verify_result(path: str | Path) -> tuple[bool, str]:
    """Check a saved result without recomputing it. A map store written by ``librate map``:
    every row against its checksum and ``done`` flag, the coordinates and the solutions (see
    :func:`librate.app.store.verify_map_store`). Other results: every variable is read (a
    missing, truncated or garbled chunk is named) and compared with the digests stored in
    its ``librate_checksums`` attribute when it has them. Returns ``(ok, report)``: the report
    names every damaged row or variable."""
    from .._integrity import array_digest, missing_zarr_chunks
    from .store import verify_map_store

    p = resolve_result_path(path)
    if _is_zarr(p):
        import zarr

        try:
            marker = zarr.open_group(str(p), mode="r", use_consolidated=False).attrs.get("librate_store")
        except Exception:  # noqa: BLE001 - judged below, by reading it as a result
            marker = None
        if marker == "periodicity_map":
            rep = verify_map_store(p)
            return rep.ok, rep.describe()
    try:
        ds = _open_dataset(p)
    except ValueError as err:
        return False, str(err)
    problems = []
    try:
        kind = result_kind(ds)
        if kind is None:
            return False, f"{str(p)!r} is not a librate result (no librate_result attribute; neither a family, a map nor solutions)"
        sums = _stored_checksums(ds)
        from .store import quiet_zarr

        for name in ds.variables:
            try:
                with quiet_zarr():
                    values = np.asarray(ds[name].values)
            except Exception as err:  # noqa: BLE001 - named, never a traceback
                problems.append(f"variable {name} is unreadable ({type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''})")
                continue
            if _is_zarr(p):
                chunks_missing = missing_zarr_chunks(p, str(name))
                if chunks_missing:
                    problems.append(f"variable {name}: chunk(s) {', '.join(chunks_missing)} missing")
            if sums is not None and name in sums and array_digest(values) != sums[name]:
                problems.append(f"variable {name} does not match its checksum")
        if sums is None:
            note = " (no checksums stored: written by an older librate; only readability was checked)"
        else:
            note = ", every variable matches its checksum"
    finally:
        ds.close()
    if problems:
        return False, f"{p}: damaged librate result\n" + "\n".join(f"  {q}" for q in problems)
    return True, f"{p}: ok: a librate {kind} result{note}"


def _stored_checksums(ds) -> dict | None:
    import json

    raw = ds.attrs.get("librate_checksums")
    if not isinstance(raw, str):
        return None
    try:
        sums = json.loads(raw)
    except ValueError:
        return None
    return sums if isinstance(sums, dict) else None


def _check_target(p: Path) -> None:
    """Refuse to replace anything that is not a librate result."""
    if not p.exists():
        return
    try:
        ds = _open_dataset(p)
    except Exception as err:  # corrupt or foreign
        raise FileExistsError(f"{str(p)!r} exists and is not a readable librate result ({type(err).__name__}): refusing to overwrite it; remove it or choose another output folder") from None
    try:
        if result_kind(ds) is None:
            raise FileExistsError(f"{str(p)!r} exists and is not a librate result: refusing to overwrite it; remove it or choose another output folder")
    finally:
        ds.close()


def save_dataset(ds, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (``.zarr``: Zarr v2 folder, consolidated; ``.nc``: netCDF 3 via
    scipy), creating the folder. All or nothing: written to a temporary sibling and renamed.
    An existing ``path`` is replaced only if it is a librate result. Returns the path."""
    p = Path(path)
    if p.suffix not in (".zarr", ".nc"):
        raise ValueError(f"invalid argument `path`: must end in .zarr (Zarr) or .nc (netCDF), got {str(p)!r}")
    p.parent.mkdir(parents=True, exist_ok=True)
    _check_target(p)
    write_atomically(_with_checksums(ds), p)
    return p


def _with_checksums(ds):
    """``ds`` with the digests of every variable in its ``librate_checksums`` attribute (JSON),
    which :func:`verify_result` and :meth:`OrbitFamily.load` check."""
    from .._integrity import CHECKSUM_ATTR, dataset_checksums

    ds = ds.copy()
    ds.attrs[CHECKSUM_ATTR] = dataset_checksums(ds)
    return ds


def save_family(family, path: str | Path, attrs: dict | None = None) -> Path:
    """Save an :class:`~librate.OrbitFamily` (``family.to_dataset()``) with extra ``attrs``
    (e.g. the study); :meth:`OrbitFamily.load` and :func:`open_result` read it back."""
    ds = family.to_dataset()
    ds.attrs.update({"librate_result": "family", **(attrs or {})})
    return save_dataset(ds, path)


def solutions_dataset(rows, orbits, kz, attrs: dict | None = None):
    """The periodic solutions ``rows`` ((orbit index, AttitudeSolution) pairs) as a Dataset over
    ``solution``, with the orbits (x0, period) and Kz values as coordinates and units."""

    from ..periodicity.maps import map_solutions_dataset

    olist = list(orbits)
    ds = map_solutions_dataset(rows)
    idx = ds["sol_orbit"].values
    x0 = np.array([o.x0 for o in olist])
    per = np.array([o.period for o in olist])
    ds["sol_x0"] = ("solution", x0[idx] if idx.size else np.zeros(0), {"units": "LU"})
    ds["sol_period_days"] = ("solution", np.array([olist[i].period_days for i in idx], dtype=float), {"units": "d"})
    ds["sol_kind"] = ds["sol_kind"].astype("<U9")
    ds = ds.assign_coords(
        orbit=np.arange(len(olist)),
        x0=("orbit", x0, {"units": "LU"}),
        period=("orbit", per, {"units": "TU"}),
        period_days=("orbit", np.array([o.period_days for o in olist]), {"units": "d"}),
        kz=("kz", np.atleast_1d(np.asarray(kz, dtype=float)), {"long_name": "(Iy - Ix) / Iz"}),
    )
    s = [x for _, x in rows]
    ds["sol_n_periods"] = ("solution", np.array([x.n_periods for x in s], dtype=np.int64))
    ds["sol_kz"].attrs["long_name"] = "(Iy - Ix) / Iz"
    ds["sol_n"].attrs["long_name"] = "net body turns per orbit period relative to the synodic frame"
    ds["sol_trace"].attrs["long_name"] = "trace of the 2x2 attitude monodromy (stable when |trace| < 2)"
    ds["sol_residual"].attrs["long_name"] = "max(|Dphi|, |Dwz|) after the n_periods periods, independent re-propagation"
    sys_ = olist[0].system if olist else None
    ds.attrs.update({
        "title": "librate periodic attitude solutions",
        **({"mu": sys_.mu, "lu_km": sys_.lu_km, "tu_s": sys_.tu_s, "system_name": sys_.name} if sys_ else {}),
        **(attrs or {}),
    })
    return ds


def run_map_to(
    orbits,
    store: str | Path,
    *,
    kz,
    wz0,
    phi0: float = 0.0,
    n_periods: int = 1,
    srp=None,
    rtol: float | None = None,
    atol: float | None = None,
    resume: bool = True,
    scheduler=None,
    progress: Callable[[int, int], None] | None = None,
    attrs: dict[str, Any] | None = None,
):
    """A periodicity map written to the Zarr ``store`` (a ``.zarr`` folder). Uses
    ``librate.app.runner.run_map`` (chunked, resumable, optionally on a Dask scheduler) when it is
    installed; otherwise :func:`librate.periodicity_map` in this process, written with
    ``to_zarr`` (an existing store with the same study and complete is reused; a store of
    another study is refused unless ``resume=False``; a foreign folder is always refused).
    Returns ``(dataset, store_path)``."""
    store = Path(store)
    attrs = dict(attrs or {})
    try:
        from .runner import run_map
    except ImportError:
        run_map = None
    if run_map is not None:
        kw: dict[str, Any] = dict(kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, out=str(store), resume=resume,
                                  scheduler=scheduler, progress=progress, solve=True, attrs=attrs)
        params = inspect.signature(run_map).parameters
        for name, value in (("rtol", rtol), ("atol", atol)):
            if value is not None and name in params:
                kw[name] = value
        return run_map(orbits, **kw), store
    if scheduler is not None:
        raise RuntimeError("a Dask scheduler needs librate.app.runner (chunked, distributed maps), which is not installed in this librate")
    from ..periodicity.maps import periodicity_map

    if store.exists():
        try:
            old = _open_dataset(store)
        except Exception:
            old = None
        if old is None or result_kind(old) != "map":
            if old is not None:
                old.close()
            raise FileExistsError(f"{str(store)!r} exists and is not a librate map: refusing to overwrite it; remove it or choose another --out")
        same = old.attrs.get("study") == attrs.get("study")
        complete = int(old.attrs.get("complete", 0)) == 1
        if resume and same and complete:
            ds = old.load()
            old.close()
            return ds, store
        old.close()
        if resume and not same:
            raise FileExistsError(f"{str(store)!r} holds a map of a different study: refusing to overwrite it; remove it, choose another --out, or run with --no-resume to replace it")
    kw = {} if rtol is None else {"rtol": rtol}
    if atol is not None:
        kw["atol"] = atol
    ds = periodicity_map(orbits, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, solve=True, progress=progress, **kw)
    ds.attrs.update(attrs)
    save_dataset(ds, store)
    return ds, store
