"""Digests of saved arrays, independent of the file format (base layer: the orbit families and
the application's result files both use them)."""

from __future__ import annotations

import hashlib
import json

import numpy as np

__all__ = ["CHECKSUM_ATTR", "array_digest", "dataset_checksums", "missing_zarr_chunks", "remove_path", "write_atomically"]

#: The attribute of a saved Dataset holding the digests of its variables (JSON).
CHECKSUM_ATTR = "librate_checksums"


def array_digest(values) -> str:
    """A hex digest of an array's shape and values, independent of how a file format stores
    them (numbers as float64 with one NaN, text as UTF-8)."""
    a = np.asarray(values)
    h = hashlib.blake2b(digest_size=16)
    h.update(repr(a.shape).encode())
    if a.dtype.kind in "biuf":
        f = np.ascontiguousarray(a, dtype=np.float64)
        h.update(np.where(np.isnan(f), np.nan, f).tobytes())  # one NaN, whatever its payload
    else:
        h.update("\0".join(x.decode() if isinstance(x, bytes) else str(x) for x in a.ravel().tolist()).encode())
    return h.hexdigest()


def dataset_checksums(ds) -> str:
    """The JSON digests of every variable (coordinates included) of an xarray Dataset."""
    return json.dumps({str(k): array_digest(np.asarray(ds[k].values)) for k in ds.variables})


def missing_zarr_chunks(store, name: str) -> list[str]:
    """The chunk files a Zarr v2 array ``name`` of the local store folder ``store`` should have
    and has not (a missing chunk silently reads as the fill value)."""
    import itertools
    from pathlib import Path

    p = Path(store)
    try:
        meta = json.loads((p / name / ".zarray").read_text())
        shape, chunks, sep = meta["shape"], meta["chunks"], meta.get("dimension_separator", ".")
    except (OSError, ValueError, KeyError, TypeError):
        return []
    if any(n == 0 for n in shape):
        return []
    counts = [-(-n // c) for n, c in zip(shape, chunks)]
    keys = [sep.join(map(str, idx)) for idx in itertools.product(*[range(c) for c in counts])] if counts else ["0"]
    return [f"{name}/{k}" for k in keys if not (p / name / k).is_file()]


def remove_path(p) -> None:
    """Remove a file, a link or a folder tree, if there."""
    import shutil
    from pathlib import Path

    q = Path(p)
    if q.is_dir() and not q.is_symlink():
        shutil.rmtree(q)
    elif q.exists() or q.is_symlink():
        q.unlink()


def write_atomically(ds, p) -> None:
    """Write the xarray Dataset ``ds`` to ``p`` (``.zarr``: Zarr v2 folder, consolidated; else
    netCDF 3 via scipy), all or nothing: into a temporary sibling, then renamed over ``p``. The
    caller decides whether ``p`` may be replaced."""
    import os
    from pathlib import Path

    p = Path(p)
    tmp = p.with_name(f".{p.name}.tmp-{os.getpid()}")
    remove_path(tmp)
    try:
        if p.suffix == ".zarr":
            import zarr

            # every chunk on disk, even one equal to the fill value (e.g. a status array of all
            # 0 = ok): a missing chunk is what damage looks like
            with zarr.config.set({"array.write_empty_chunks": True}):
                ds.to_zarr(tmp, mode="w-", zarr_format=2, consolidated=True)
        else:
            ds.to_netcdf(tmp, engine="scipy")
        remove_path(p)
        os.replace(tmp, p)
    finally:
        remove_path(tmp)
