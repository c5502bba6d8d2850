"""Results as one capability (base layer: imports nothing of librate above it).

* :mod:`~librate.results.atomic`: the one atomic writer (fsynced; replace by exchange; orphans
  of dead processes cleaned up).
* :mod:`~librate.results.lock`: the one writer lock, for every result path.
* :mod:`~librate.results.checksum`: digests over data, names, dtypes, attributes and constants.
* :mod:`~librate.results.store`: the one resumable store (parts with done flags and digests).
* :mod:`~librate.results.files`: whole results written at once, read back defensively.
* :mod:`~librate.results.kinds`: one class per result kind.
"""

from .atomic import atomic_path, atomic_write_text, clean_orphans, replace_path
from .checksum import CHECKSUM_ATTR, META_ATTR, array_digest, dataset_checksums
from .files import open_dataset, verify_dataset, write_dataset
from .kinds import KINDS, kind_of
from .lock import StoreBusyError, writer_lock
from .store import PartStore, StoreReport, verify_store

__all__ = ["CHECKSUM_ATTR", "KINDS", "META_ATTR", "PartStore", "StoreBusyError", "StoreReport", "array_digest",
           "atomic_path", "atomic_write_text",
           "clean_orphans", "dataset_checksums", "kind_of", "open_dataset", "replace_path", "verify_dataset",
           "verify_store", "write_dataset",
           "writer_lock"]
