"""Older names of :mod:`librate.results` (digests and the atomic writer), kept for callers."""

from __future__ import annotations

from .results.atomic import remove_path
from .results.checksum import CHECKSUM_ATTR, array_digest, dataset_checksums
from .results.files import write_dataset
from .results.zarrcheck import missing_zarr_chunks

__all__ = ["CHECKSUM_ATTR", "array_digest", "dataset_checksums", "missing_zarr_chunks", "remove_path", "write_atomically"]


def write_atomically(ds, p) -> None:
    """Write ``ds`` to ``p`` as it is (its own checksum attributes, if any), all or nothing
    (:func:`librate.results.files.write_dataset`)."""
    write_dataset(ds, p, checksums=False)
