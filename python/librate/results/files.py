"""Whole results written at once (a family, a table of solutions, an exported map): an xarray
Dataset with its digests, written all or nothing by :mod:`librate.results.atomic`, and read
back defensively (every chunk checked before a codec sees it)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .atomic import atomic_path
from .checksum import CHECKSUM_ATTR, META_ATTR, check_dataset, dataset_checksums, dataset_meta
from .zarrcheck import chunk_problems, quiet_zarr, short

__all__ = ["is_zarr", "open_dataset", "verify_dataset", "with_checksums", "write_dataset"]


def is_zarr(p: Path) -> bool:
    p = Path(p)
    return p.is_dir() and any((p / n).exists() for n in (".zgroup", ".zattrs", ".zmetadata", "zarr.json"))


def with_checksums(ds):
    """``ds`` with the digests of its values (:data:`CHECKSUM_ATTR`) and of its names, dtypes,
    attributes and root attributes (:data:`META_ATTR`)."""
    ds = ds.copy()
    ds.attrs.pop(CHECKSUM_ATTR, None)
    ds.attrs.pop(META_ATTR, None)
    ds.attrs[CHECKSUM_ATTR] = dataset_checksums(ds)
    ds.attrs[META_ATTR] = dataset_meta(ds)
    return ds


def write_dataset(ds, path, *, lock=None, checksums: bool = True) -> Path:
    """Write ``ds`` to ``path`` (``.zarr``: Zarr v2 folder, consolidated; else netCDF 3 via
    scipy), all or nothing, flushed to disk, with its digests. ``lock``: the writer lock of
    ``path`` (checked just before the new result takes the name). The caller decides whether
    ``path`` may be replaced."""
    p = Path(path)
    if checksums:
        ds = with_checksums(ds)
    with atomic_path(p) as tmp:
        if p.suffix == ".zarr":
            import zarr

            # every chunk on disk, even one equal to the fill value: a missing chunk is damage
            with zarr.config.set({"array.write_empty_chunks": True}):
                ds.to_zarr(tmp, mode="w-", zarr_format=2, consolidated=True)
        else:
            ds.to_netcdf(tmp, engine="scipy")
        if lock is not None:
            lock.check()
    return p


def open_dataset(p: Path):
    """The lazily opened Dataset at ``p``, or ValueError saying why it cannot be read."""
    import xarray as xr

    p = Path(p)
    try:
        with quiet_zarr():
            if p.is_file() and p.suffix == ".nc":
                return xr.open_dataset(p, engine="scipy")
            if is_zarr(p):
                import warnings

                with warnings.catch_warnings():  # no consolidated metadata (e.g. a store in progress): read without
                    warnings.simplefilter("ignore", RuntimeWarning)
                    return xr.open_dataset(p, engine="zarr", chunks=None)
    except Exception as err:  # noqa: BLE001 - whatever the reader raises, named
        raise ValueError(f"{str(p)!r} cannot be read as a librate result: {short(err)}") from None
    raise ValueError(f"{str(p)!r} is neither a netCDF file (.nc) nor a Zarr store (.zarr folder)")


def verify_dataset(ds, p: Path) -> tuple[list[str], bool, dict]:
    """Check the opened result ``ds`` (at ``p``): every chunk present and well formed (Zarr),
    every variable readable, and everything against its digests. Returns ``(problems,
    checked, values)``; never raises for damage."""
    problems: list[str] = []
    values: dict = {}
    zarr_folder = is_zarr(p)
    for name in ds.variables:
        if zarr_folder:
            bad = chunk_problems(p, str(name))
            if bad:
                problems += [f"variable {name}: {b}" for b in bad]
                continue
        try:
            with quiet_zarr():
                values[str(name)] = np.asarray(ds[name].values)
        except Exception as err:  # noqa: BLE001 - named, never a traceback
            problems.append(f"variable {name} is unreadable ({short(err)})")
    damaged = {q.split()[1] for q in problems}
    more, checked = check_dataset(ds, values)
    problems += [q for q in more if not (q.startswith("variable ") and q.split()[1] in damaged)]
    return problems, checked, values
