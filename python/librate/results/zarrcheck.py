"""Defensive reading of Zarr v2 folders: every chunk a array should have is there, and every
Blosc chunk's header agrees with its file before the codec sees it (Blosc may otherwise decode
a truncated chunk from memory past its end, or crash the process)."""

from __future__ import annotations

import contextlib
import itertools
import json
import logging
from collections.abc import Iterator
from pathlib import Path

__all__ = ["blosc_problem", "chunk_problems", "missing_zarr_chunks", "quiet_zarr", "short"]


def short(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0] if text else ''}".rstrip(": ")


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


def _meta(store: Path, name: str) -> dict | None:
    try:
        meta = json.loads((store / name / ".zarray").read_text())
    except (OSError, ValueError):
        return None
    return meta if isinstance(meta, dict) else None


def missing_zarr_chunks(store, name: str) -> list[str]:
    """The chunk files a Zarr v2 array ``name`` of the local store folder ``store`` should have
    and has not (a missing chunk silently reads as the fill value)."""
    p = Path(store)
    meta = _meta(p, name)
    try:
        shape, chunks, sep = meta["shape"], meta["chunks"], meta.get("dimension_separator", ".")  # type: ignore[index]
    except (KeyError, TypeError):
        return []
    if any(n == 0 for n in shape):
        return []
    counts = [-(-n // c) for n, c in zip(shape, chunks)]
    keys = [sep.join(map(str, idx)) for idx in itertools.product(*[range(c) for c in counts])] if counts else ["0"]
    return [f"{name}/{k}" for k in keys if not (p / name / k).is_file()]


def blosc_problem(chunk: Path, meta: dict | None = None) -> str | None:
    """What is wrong with a Blosc-compressed chunk whose header disagrees with its file
    (truncated or padded), or None."""
    if meta is None:
        meta = _meta(chunk.parent.parent, chunk.parent.name) or {}
    comp = meta.get("compressor") or {}
    if not isinstance(comp, dict) or comp.get("id") != "blosc":
        return None
    try:
        data = chunk.read_bytes()
    except OSError as err:
        return f"is unreadable ({short(err)})"
    if len(data) < 16:
        return f"is truncated ({len(data)} bytes, shorter than its Blosc header)"
    nbytes = int.from_bytes(data[4:8], "little")
    cbytes = int.from_bytes(data[12:16], "little")
    if cbytes != len(data):
        return f"is truncated or padded ({len(data)} bytes, its Blosc header says {cbytes})"
    try:
        import numpy as np

        itemsize = np.dtype(meta["dtype"]).itemsize
        want = itemsize * int(np.prod(meta["chunks"]))
    except (KeyError, TypeError, ValueError):
        want = None
    if want is not None and nbytes != want:
        return f"has a damaged Blosc header (it decompresses to {nbytes} bytes, the array's chunks hold {want})"
    return None


def chunk_problems(store, name: str) -> list[str]:
    """Every missing or malformed chunk of array ``name`` (named), before any codec reads it."""
    p = Path(store)
    out = [f"chunk {c} is missing" for c in missing_zarr_chunks(p, name)]
    meta = _meta(p, name)
    if meta is None:
        return out
    d = p / name
    try:
        files = sorted(f for f in d.iterdir() if not f.name.startswith("."))
    except OSError:
        return out
    for f in files:
        bad = blosc_problem(f, meta)
        if bad:
            out.append(f"chunk {name}/{f.name} {bad}")
    return out
