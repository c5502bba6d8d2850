"""Integrity of the resumable map store (a Zarr v2 folder written by :mod:`librate.app.runner`).

* **One writer.** A writer holds an exclusive lock on a sibling file ``.<name>.lock`` (through
  ``filelock``) and records who it is (pid, host, start time) in ``.<name>.lock.owner``; a
  second writer is refused with :class:`StoreBusyError` naming that process.
* **Atomic files.** Every file of the store is written to a temporary name and renamed (Zarr's
  local store does so for chunks and metadata; :func:`atomic_write_text` for the rest), the
  store itself is created in a temporary sibling folder and renamed into place, so its
  ``librate_store`` marker is there from the first moment, and the root attributes are always
  rewritten whole, marker included.
* **Checksums.** Each finished row (one orbit: dwz, dphi, phi_T, status) has a 64-bit BLAKE2b
  digest per variable in ``row_checksum`` (orbit x 4), written after the row's data and before
  its ``done`` flag; the coordinates and the solution table have digests in the root attributes
  (``coord_checksums``, ``sol_checksums``).
* **Verification.** :func:`verify_map_store` reads every chunk and names each damaged row
  (missing, unreadable or altered chunk), each row not computed yet, and any damaged
  coordinate or solution array. A resumed run recomputes the damaged rows instead of trusting
  their ``done`` flags.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import socket
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._integrity import array_digest

__all__ = [
    "ROW_VARS",
    "StoreBusyError",
    "StoreReport",
    "array_digest",
    "atomic_write_text",
    "check_rows",
    "quiet_zarr",
    "row_checksum",
    "verify_map_store",
    "writer_lock",
]

#: The per-row variables of a map store, in the order of the columns of ``row_checksum``.
ROW_VARS = ("dwz", "dphi", "phi_T", "status")


class StoreBusyError(RuntimeError):
    """Another process is writing the same store (it holds the store's lock)."""


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to a temporary sibling, flush it to disk and rename it onto ``path``."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


@contextlib.contextmanager
def writer_lock(out: Path) -> Iterator[None]:
    """Hold the exclusive writer lock of the store ``out`` (a sibling ``.<name>.lock`` file)."""
    from filelock import FileLock, Timeout

    out.parent.mkdir(parents=True, exist_ok=True)
    owner = out.parent / f".{out.name}.lock.owner"
    lock = FileLock(str(out.parent / f".{out.name}.lock"), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        who = "a process that has not recorded its pid yet"
        for _ in range(40):  # the holder writes its pid just after taking the lock
            try:
                who = owner.read_text(encoding="utf-8").strip() or who
                break
            except OSError:
                time.sleep(0.05)
        raise StoreBusyError(f"{out} is being written by another librate process ({who}); "
                             "wait for it to finish or stop it, or choose another folder") from None
    try:
        atomic_write_text(owner, f"pid {os.getpid()} on {socket.gethostname()}, since {time.strftime('%Y-%m-%d %H:%M:%S')}")
        yield
    finally:
        with contextlib.suppress(OSError):
            owner.unlink()
        lock.release()


def _digest(values) -> int:
    a = np.ascontiguousarray(values)
    return int.from_bytes(hashlib.blake2b(a.tobytes(), digest_size=8).digest(), "little")


def row_checksum(row: dict) -> np.ndarray:
    """The (4,) uint64 digests of one row's ``ROW_VARS`` (as they are stored)."""
    return np.array([_digest(np.asarray(row[k], dtype=np.uint8 if k == "status" else np.float64)) for k in ROW_VARS], dtype=np.uint64)


@contextlib.contextmanager
def quiet_zarr() -> Iterator[None]:
    """Silence the asyncio/zarr loggers while reading possibly damaged chunks (their failures
    are reported by name instead)."""
    loggers = [logging.getLogger(n) for n in ("asyncio", "zarr")]
    old = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, lv in zip(loggers, old):
            lg.setLevel(lv)


def _short(err: Exception) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0] if text else ''}".rstrip(": ")


def _chunk_key(name: str, i: int, ndim: int) -> str:
    return ".".join([str(i)] + ["0"] * (ndim - 1))


def _blosc_problem(chunk: Path) -> str | None:
    """A Blosc-compressed chunk whose header disagrees with its file (truncated or padded):
    Blosc itself may decode such a chunk from memory past its end instead of failing."""
    try:
        meta = json.loads((chunk.parent / ".zarray").read_text())
        if (meta.get("compressor") or {}).get("id") != "blosc":
            return None
        data = chunk.read_bytes()
    except (OSError, ValueError):
        return None
    if len(data) < 16:
        return f"is truncated ({len(data)} bytes, shorter than its Blosc header)"
    cbytes = int.from_bytes(data[12:16], "little")
    if cbytes != len(data):
        return f"is truncated or padded ({len(data)} bytes, its Blosc header says {cbytes})"
    return None


def check_rows(g, path: Path) -> tuple[dict[int, str], list[int]]:
    """Check every row of the map store ``g`` (at ``path``) against its checksum.

    Returns ``(damaged, not_done)``: ``damaged`` maps a row index to what is wrong with it (a
    missing, unreadable or altered chunk, or an unreadable flag or checksum); ``not_done`` lists
    the rows not computed yet."""
    n = int(g["done"].shape[0])
    damaged: dict[int, str] = {}
    not_done: list[int] = []
    with quiet_zarr():
        for i in range(n):
            try:
                flag = bool(np.asarray(g["done"][i]))
            except Exception as err:  # noqa: BLE001 - a damaged chunk: named, and the row recomputed
                damaged[i] = f"its done flag (chunk done/{i}) is unreadable ({_short(err)})"
                continue
            if not flag:
                not_done.append(i)
                continue
            reasons = []
            ckey = f"row_checksum/{_chunk_key('row_checksum', i, 2)}"
            stored = None
            if not (path / ckey).is_file():
                reasons.append(f"its checksum chunk {ckey} is missing")
            elif _blosc_problem(path / ckey):
                reasons.append(f"its checksum chunk {ckey} {_blosc_problem(path / ckey)}")
            else:
                try:
                    stored = np.asarray(g["row_checksum"][i], dtype=np.uint64)
                except Exception as err:  # noqa: BLE001
                    reasons.append(f"its checksum chunk {ckey} is unreadable ({_short(err)})")
            mismatch = []
            for j, k in enumerate(ROW_VARS):
                key = f"{k}/{_chunk_key(k, i, 3)}"
                if not (path / key).is_file():
                    reasons.append(f"chunk {key} is missing")
                    continue
                bad = _blosc_problem(path / key)
                if bad:
                    reasons.append(f"chunk {key} {bad}")
                    continue
                try:
                    values = np.asarray(g[k][i])
                except Exception as err:  # noqa: BLE001
                    reasons.append(f"chunk {key} is unreadable ({_short(err)})")
                    continue
                if stored is not None and _digest(values) != int(stored[j]):
                    mismatch.append(key)
            if mismatch:
                reasons.append(f"chunk{'s' if len(mismatch) > 1 else ''} {', '.join(mismatch)} "
                               f"{'do' if len(mismatch) > 1 else 'does'} not match the checksum in {ckey} (one or the other is damaged)")
            if reasons:
                damaged[i] = "; ".join(reasons)
    return damaged, not_done


def read_array(g, name: str):
    """The whole array ``name`` of ``g``, or raise ValueError naming it when it is unreadable."""
    try:
        with quiet_zarr():
            return np.asarray(g[name][...])
    except Exception as err:  # noqa: BLE001
        raise ValueError(f"array {name} is unreadable ({_short(err)})") from None


@dataclass
class StoreReport:
    """What :func:`verify_map_store` found. ``ok`` when the map is complete and undamaged."""

    path: Path
    rows: int = 0
    damaged: dict[int, str] = field(default_factory=dict)
    not_done: list[int] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    complete: bool = False

    @property
    def ok(self) -> bool:
        return not (self.damaged or self.not_done or self.problems) and self.complete

    def describe(self) -> str:
        if self.ok:
            return f"{self.path}: ok: {self.rows} rows, every chunk matches its checksum"
        lines = [f"{self.path}: damaged or incomplete librate map store"]
        lines += [f"  {p}" for p in self.problems]
        lines += [f"  row {i} (orbit {i}): {why}" for i, why in sorted(self.damaged.items())]
        if self.not_done:
            lines.append(f"  rows not computed yet: {self.not_done} (re-run the same map to resume it)")
        elif not self.complete and not self.problems and not self.damaged:
            lines.append("  the map was interrupted during its finalisation (re-run the same map to finish it)")
        if self.damaged:
            lines.append(f"  damaged rows: {sorted(self.damaged)} (re-running the same map recomputes them)")
        return "\n".join(lines)


def open_map_group(path: Path, mode: str = "r"):
    """The Zarr group of a librate map store, or raise ValueError saying why it is not one."""
    import zarr

    try:
        with quiet_zarr():
            g = zarr.open_group(str(path), mode=mode, use_consolidated=False)
            kind = g.attrs.get("librate_store")
    except Exception as err:  # noqa: BLE001 - anything unreadable is foreign or corrupt
        raise ValueError(f"{path} is not a librate map store (foreign or corrupt: {_short(err)})") from None
    if kind != "periodicity_map":
        raise ValueError(f"{path} is not a librate map store (no librate_store marker in its root attributes)")
    return g


def verify_map_store(path: str | Path) -> StoreReport:
    """Check a map store written by :func:`librate.app.runner.run_map`: its marker, every
    array's metadata, every row against its checksum and done flag, the coordinates and (when
    complete) the solutions against their digests. Never raises for damage: see the report."""
    p = Path(path)
    rep = StoreReport(path=p)
    try:
        g = open_map_group(p)
    except ValueError as err:
        rep.problems.append(str(err))
        return rep
    attrs = dict(g.attrs)
    rep.complete = int(attrs.get("complete", 0)) == 1
    for k in (*ROW_VARS, "done", "row_checksum"):
        try:
            with quiet_zarr():
                g[k]  # noqa: B018 - reads the metadata
        except Exception as err:  # noqa: BLE001
            rep.problems.append(f"array {k} is missing or its metadata is unreadable ({_short(err)})")
    if rep.problems:
        if any("row_checksum" in q for q in rep.problems):
            rep.problems.append("(a store without row_checksum was written by an older librate and cannot be verified)")
        return rep
    rep.rows = int(g["done"].shape[0])
    rep.damaged, rep.not_done = check_rows(g, p)
    for key in ("coord_checksums", "sol_checksums"):
        sums = attrs.get(key)
        if key == "sol_checksums" and not rep.complete:
            continue
        if not isinstance(sums, dict):
            rep.problems.append(f"root attribute {key} is missing")
            continue
        for name, want in sums.items():
            try:
                got = array_digest(read_array(g, name))
            except (ValueError, KeyError) as err:
                rep.problems.append(f"{'coordinate' if key == 'coord_checksums' else 'solution array'} {name}: {err}")
                continue
            if got != want:
                rep.problems.append(f"{'coordinate' if key == 'coord_checksums' else 'solution array'} {name} does not match its checksum")
    return rep
