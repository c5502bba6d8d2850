"""The one resumable store of librate: a grid of independent parts (a planar map's orbit rows, a
3-D map's orbits, and the coming ephemeris runs), each with a done flag and a checksum.

A store is a Zarr v2 folder. Each variable of the schema is an array whose first dimension is
the part (one chunk per part), with a fixed dtype (``status`` is always uint8, whatever was
resumed). Protocol:

* **One writer**, holding :func:`librate.results.lock.writer_lock` (taken before anything is
  created, repaired or removed, and checked before every commit).
* **Creation** in a temporary sibling folder, flushed and renamed into place: ``path`` is either
  absent or a complete, marked, empty store.
* **A part** is committed as its data, then its digests (``row_checksum``, part x variable; a "row" of the grid of parts),
  then its ``done`` flag: a kill at any moment loses at most the part in flight.
* **The root attributes** carry the marker (``librate_store``), the fingerprint of every input,
  ``complete`` (1 only with the last write), the digests of the coordinates and of the arrays
  added at the end, of every array's metadata (dtype, shape, attributes: a ``scale_factor``
  slipped in is named) and of the root attributes themselves (the system constants among
  them).
* **Verification** (:func:`verify_store`) checks every chunk's presence and Blosc header before a
  codec reads it, then every part against its digests; a resumed run recomputes the damaged
  parts instead of trusting their flags.
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .atomic import clean_orphans, fsync_tree, remove_path, temporary_sibling
from .checksum import array_digest, attrs_digest, meta_digest
from .zarrcheck import blosc_problem, quiet_zarr, short

__all__ = ["STORE_ATTRS", "PartStore", "StoreReport", "StoreSchema", "Var", "open_group", "part_digest", "verify_store", "write_region"]

_SKIP_ATTRS = ("attrs_checksum",)
#: The root attributes a part store keeps for itself (not part of an exported result).
STORE_ATTRS = ("librate_store", "fingerprint", "coord_checksums", "extra_checksums", "sol_checksums", "array_meta", "attrs_checksum")


@dataclass(frozen=True)
class Var:
    """One per-part variable: its dtype, its shape within a part, the names of those dimensions,
    its fill value and attributes."""

    dtype: str
    shape: tuple[int, ...]
    dims: tuple[str, ...]
    fill: object
    attrs: dict = field(default_factory=dict)


@dataclass(frozen=True)
class StoreSchema:
    """What a store holds: its marker ``kind``, the part dimension and count, the per-part
    variables (in checksum-column order) and the coordinates ``{name: (dim, values, attrs)}``."""

    kind: str
    part_dim: str
    n_parts: int
    variables: dict
    coords: dict

    def shape(self, name: str) -> tuple[int, ...]:
        return (self.n_parts, *self.variables[name].shape)


def part_digest(values, dtype) -> int:
    """The 64-bit digest of one part of one variable, as stored (in the schema's dtype)."""
    a = np.ascontiguousarray(np.asarray(values, dtype=dtype))
    return int.from_bytes(hashlib.blake2b(a.tobytes(), digest_size=8).digest(), "little")


def write_region(path: Path, dtypes: dict, i: int, part: dict) -> list[int]:
    """Write the data of part ``i`` into the store at ``path`` from another process of the writer
    (a worker on the same filesystem; variables ``dtypes`` by name), and return its digests in
    column order. Neither digests nor the done flag are written: the writer checks the region
    against these digests and commits it (:meth:`PartStore.commit_written`)."""
    import zarr

    sums = []
    with zarr.config.set({"array.write_empty_chunks": True}), quiet_zarr():
        g = zarr.open_group(str(path), mode="r+", use_consolidated=False)
        for k, dtype in dtypes.items():
            values = np.asarray(part[k]).astype(dtype, copy=False)
            g[k][i] = values
            sums.append(part_digest(values, dtype))
    return sums


def open_group(path: Path, kind: str, mode: str = "r"):
    """The Zarr group of a librate store of ``kind``, or ValueError saying why it is not one."""
    import zarr

    try:
        with quiet_zarr():
            g = zarr.open_group(str(path), mode=mode, use_consolidated=False)
            marker = g.attrs.get("librate_store")
    except Exception as err:  # noqa: BLE001 - anything unreadable is foreign or corrupt
        raise ValueError(f"{path} is not a librate {_what(kind)} (foreign or corrupt: {short(err)})") from None
    if marker != kind:
        why = "no librate_store marker in its root attributes" if marker is None else f"it is a librate {marker} store"
        raise ValueError(f"{path} is not a librate {_what(kind)} ({why})")
    return g


def _what(kind: str) -> str:
    return {"periodicity_map": "map store", "map_3d": "3-D map store",
            "ephemeris_transition": "transition store"}.get(kind, f"{kind} store")


def _array_meta(g, name: str) -> str:
    a = g[name]
    attrs = {k: v for k, v in dict(a.attrs).items()}
    return meta_digest(name, a.dtype, a.shape, attrs, attrs.get("_ARRAY_DIMENSIONS", ()))


def _zarray(path: Path, name: str) -> dict:
    import json

    try:
        meta = json.loads((path / name / ".zarray").read_text())
    except (OSError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}


def _chunk_key(i: int, ndim: int) -> str:
    return ".".join([str(i)] + ["0"] * (ndim - 1))


class PartStore:
    """An open store (use :meth:`open`); ``lock``: the writer lock held by the caller."""

    def __init__(self, g, path: Path, schema: StoreSchema, fingerprint: str, lock=None):
        self.g, self.path, self.schema, self.fingerprint, self.lock = g, Path(path), schema, fingerprint, lock

    # --- opening -------------------------------------------------------------------------
    @classmethod
    def open(cls, path, schema: StoreSchema, fingerprint: str, *, resume: bool = True, attrs: dict | None = None, lock=None):
        """Open (resume) or create the store at ``path`` (the caller holds ``lock``). Returns
        ``(store, damaged)``: the parts whose data do not match their digests, by index."""
        path = Path(path)
        if path.exists() and not path.is_dir():
            raise ValueError(f"invalid argument `out`: {path} exists and is not a folder; refusing to overwrite it")
        clean_orphans(path)
        if not path.exists() or not any(path.iterdir()):
            return cls._create(path, schema, fingerprint, attrs, lock), {}
        try:
            g = open_group(path, schema.kind, mode="r+")
        except ValueError as err:
            raise ValueError(f"invalid argument `out`: {err}; refusing to overwrite it") from None
        if g.attrs.get("fingerprint") != fingerprint:
            raise ValueError(f"invalid argument `out`: {path} holds a map of different inputs (fingerprint mismatch); use another folder")
        if not resume:
            raise ValueError(f"invalid argument `out`: {path} already holds this map; pass resume=True to continue it or "
                             "choose another folder")
        bad = []
        want = {**{k: (schema.shape(k), np.dtype(v.dtype)) for k, v in schema.variables.items()},
                "done": ((schema.n_parts,), np.dtype(bool)), "row_checksum": ((schema.n_parts, len(schema.variables)), np.dtype("u8"))}
        for k, (shape, dtype) in want.items():
            try:
                a = g[k]
            except Exception as err:  # noqa: BLE001 - a missing or unreadable .zarray
                bad.append(f"{k} ({'missing' if isinstance(err, KeyError) else 'metadata unreadable'})")
                continue
            if a.shape != shape:
                bad.append(f"{k} (wrong shape {a.shape})")
            elif a.dtype != dtype:
                bad.append(f"{k} (dtype {a.dtype}, this store kind stores {dtype})")
        if bad:
            raise ValueError(f"invalid argument `out`: {path} is a corrupt librate {_what(schema.kind)} (arrays {', '.join(bad)}); "
                             "refusing to overwrite it; remove it or choose another folder")
        store = cls(g, path, schema, fingerprint, lock)
        if lock is not None:
            lock.check()
        # ours and being written: stale consolidated metadata first, then "incomplete" attributes
        zmeta = path / ".zmetadata"
        if zmeta.exists():
            zmeta.unlink()
        store._put_attrs({**store._base_attrs(attrs), "complete": 0})
        for name, (_, values, _) in schema.coords.items():  # the coordinates are known: repair, never trust
            try:
                same = name in g and np.array_equal(store.read(name), values) and g[name].dtype == values.dtype
            except ValueError:
                same = False
            if not same:
                store._write_coords({name: schema.coords[name]})
        for name in schema.variables:  # a changed array attribute (e.g. scale_factor) is put back
            if dict(g[name].attrs) != store._var_attrs(name):
                g[name].attrs.put(store._var_attrs(name))
        damaged, _ = store.check_parts()
        return store, damaged

    @classmethod
    def _create(cls, path: Path, schema: StoreSchema, fingerprint: str, attrs: dict | None, lock):
        import zarr

        tmp = temporary_sibling(path, "creating")
        remove_path(tmp)
        g = zarr.open_group(str(tmp), mode="w", zarr_format=2)
        store = cls(g, tmp, schema, fingerprint, lock)
        for name, v in schema.variables.items():
            g.create_array(name, shape=schema.shape(name), chunks=(1, *v.shape), dtype=v.dtype, fill_value=v.fill,
                           attributes=store._var_attrs(name))
        n, nv = schema.n_parts, len(schema.variables)
        g.create_array("done", shape=(n,), chunks=(1,), dtype="bool", fill_value=False, attributes={"_ARRAY_DIMENSIONS": [schema.part_dim]})
        g.create_array("row_checksum", shape=(n, nv), chunks=(1, nv), dtype="u8", fill_value=None,
                       attributes={"_ARRAY_DIMENSIONS": [schema.part_dim, "checksum_of"], "columns": " ".join(schema.variables),
                                   "long_name": "64-bit BLAKE2b digest of each part of " + ", ".join(schema.variables)})
        store._write_coords(schema.coords)
        store._put_attrs({**store._base_attrs(attrs), "complete": 0})
        fsync_tree(tmp)
        if lock is not None:
            lock.check()
        if path.exists():
            path.rmdir()  # an empty folder (checked by the caller)
        os.replace(tmp, path)
        return cls(zarr.open_group(str(path), mode="r+", use_consolidated=False), path, schema, fingerprint, lock)

    # --- attributes ------------------------------------------------------------------------
    def _var_attrs(self, name: str) -> dict:
        v = self.schema.variables[name]
        return {"_ARRAY_DIMENSIONS": [self.schema.part_dim, *v.dims], **v.attrs}

    def _base_attrs(self, attrs: dict | None) -> dict:
        """The root attributes every state of the store carries (the marker first of all), with
        the caller's text attributes (e.g. the study)."""
        extra = {k: v for k, v in (attrs or {}).items() if isinstance(v, str)}
        return {**extra, "librate_store": self.schema.kind, "fingerprint": self.fingerprint,
                "coord_checksums": {name: array_digest(values) for name, (_, values, _) in self.schema.coords.items()}}

    def _put_attrs(self, attrs: dict) -> None:
        attrs = dict(attrs)
        names = [*self.schema.variables, "done", "row_checksum", *self.schema.coords, *attrs.get("extra_checksums", {})]
        attrs["array_meta"] = {k: _array_meta(self.g, k) for k in names if k in self.g}
        attrs["attrs_checksum"] = attrs_digest(attrs, skip=_SKIP_ATTRS)
        self.g.attrs.put(attrs)

    def _write_coords(self, coords: dict) -> None:
        for name, (dim, values, attrs) in coords.items():
            # no fill value: xarray would read a fill value of 0 as "missing" (orbit 0, Kz = 0)
            a = self.g.create_array(name, shape=values.shape, chunks=tuple(max(1, n) for n in values.shape), dtype=values.dtype,
                                    fill_value=None, overwrite=True,
                                    attributes={"_ARRAY_DIMENSIONS": [dim] if values.ndim == 1 else list(dim), **attrs})
            a[...] = values

    # --- parts -----------------------------------------------------------------------------
    def write_part(self, i: int, part: dict) -> None:
        """Commit part ``i``: its data, its digests, then its done flag."""
        if self.lock is not None:
            self.lock.check()
        import zarr

        sums = []
        # every chunk written, also one equal to the fill value (a part of NaN: an epoch that did
        # not converge), or the check would find it missing
        with zarr.config.set({"array.write_empty_chunks": True}):
            for k, v in self.schema.variables.items():
                values = np.asarray(part[k]).astype(v.dtype, copy=False)
                self.g[k][i] = values
                sums.append(part_digest(values, v.dtype))
        self.g["row_checksum"][i] = np.array(sums, dtype=np.uint64)  # after the data, before the flag
        self.g["done"][i] = True

    def commit_written(self, i: int, digests) -> bool:
        """Commit part ``i`` whose data another process wrote (:func:`write_region`): its region
        is read back and checked against ``digests``, then the digests and the done flag are
        written. Returns False, committing nothing, when the region does not match."""
        if self.lock is not None:
            self.lock.check()
        if len(digests) != len(self.schema.variables):
            return False
        with quiet_zarr():
            for (k, v), want in zip(self.schema.variables.items(), digests):
                try:
                    got = part_digest(np.asarray(self.g[k][i]), v.dtype)
                except Exception:  # noqa: BLE001 - an unreadable chunk: not committed
                    return False
                if got != int(want):
                    return False
        self.g["row_checksum"][i] = np.array([int(d) for d in digests], dtype=np.uint64)
        self.g["done"][i] = True
        return True

    def read(self, name: str):
        """The whole array ``name``, or ValueError naming it when it is unreadable."""
        try:
            with quiet_zarr():
                return np.asarray(self.g[name][...])
        except Exception as err:  # noqa: BLE001
            raise ValueError(f"array {name} is unreadable ({short(err)})") from None

    def done_flags(self, damaged: dict) -> np.ndarray:
        """The parts to skip: done and undamaged (an unreadable flag counts as not done)."""
        done = np.zeros(self.schema.n_parts, dtype=bool)
        for i in range(self.schema.n_parts):
            if i in damaged:
                continue
            try:
                done[i] = bool(self.g["done"][i])
            except Exception:  # noqa: BLE001 - already reported by check_parts
                done[i] = False
        return done

    def check_parts(self) -> tuple[dict[int, str], list[int]]:
        return check_parts(self.g, self.path, list(self.schema.variables))

    def finalise(self, arrays: dict, attrs: dict, complete: bool) -> None:
        """Write the arrays computed at the end ``{name: (dims, values, attrs)}`` (e.g. the
        solution table) and the final root attributes; ``complete`` becomes 1 with the last
        attribute write, and the consolidated metadata (a cache) comes after."""
        import zarr

        if self.lock is not None:
            self.lock.check()
        existing = set(self.g.array_keys())
        keep = set(self.schema.variables) | {"done", "row_checksum"} | set(self.schema.coords)
        for name in existing - keep - set(arrays):
            del self.g[name]
        sums = {}
        for name, (dims, values, a_attrs) in arrays.items():
            values = np.ascontiguousarray(values)
            a = self.g.create_array(name, shape=values.shape, chunks=tuple(max(1, n) for n in values.shape), dtype=values.dtype,
                                    fill_value=None, overwrite=name in existing, attributes={"_ARRAY_DIMENSIONS": list(dims), **a_attrs})
            if values.size:
                a[...] = values
            sums[name] = array_digest(values)
        final = {k: v for k, v in attrs.items()
                 if isinstance(v, (int, float, str)) or (isinstance(v, list) and all(isinstance(x, (int, float)) for x in v))}
        final.update(self._base_attrs(None))
        final.update({"complete": int(complete), "extra_checksums": sums})
        if self.lock is not None:
            self.lock.check()
        self._put_attrs(final)
        try:
            zarr.consolidate_metadata(str(self.path), zarr_format=2)
        except Exception:  # noqa: BLE001 - consolidation is an optimisation only
            pass
        fsync_tree(self.path)


def check_parts(g, path: Path, names: list[str]) -> tuple[dict[int, str], list[int]]:
    """Check every part of the store ``g`` (at ``path``) against its digests: ``(damaged,
    not_done)``; ``damaged`` maps a part index to what is wrong with it (a missing, malformed,
    unreadable or altered chunk, or an unreadable flag or checksum)."""
    n = int(g["done"].shape[0])
    damaged: dict[int, str] = {}
    not_done: list[int] = []
    metas = {k: _zarray(path, k) for k in (*names, "row_checksum", "done")}
    with quiet_zarr():
        for i in range(n):
            fkey = f"done/{i}"
            bad = blosc_problem(path / fkey, metas["done"]) if (path / fkey).is_file() else None
            try:
                flag = False if bad else bool(np.asarray(g["done"][i]))
            except Exception as err:  # noqa: BLE001 - a damaged chunk: named, and the part recomputed
                bad = f"is unreadable ({short(err)})"
            if bad:
                damaged[i] = f"its done flag (chunk {fkey}) {bad}"
                continue
            if not flag:
                not_done.append(i)
                continue
            reasons = []
            ckey = f"row_checksum/{_chunk_key(i, 2)}"
            stored = None
            if not (path / ckey).is_file():
                reasons.append(f"its checksum chunk {ckey} is missing")
            elif blosc_problem(path / ckey, metas["row_checksum"]):
                reasons.append(f"its checksum chunk {ckey} {blosc_problem(path / ckey, metas['row_checksum'])}")
            else:
                try:
                    stored = np.asarray(g["row_checksum"][i], dtype=np.uint64)
                except Exception as err:  # noqa: BLE001
                    reasons.append(f"its checksum chunk {ckey} is unreadable ({short(err)})")
            mismatch = []
            for j, k in enumerate(names):
                key = f"{k}/{_chunk_key(i, len(g[k].shape))}"
                if not (path / key).is_file():
                    reasons.append(f"chunk {key} is missing")
                    continue
                bad = blosc_problem(path / key, metas[k])
                if bad:
                    reasons.append(f"chunk {key} {bad}")
                    continue
                try:
                    values = np.asarray(g[k][i])
                except Exception as err:  # noqa: BLE001
                    reasons.append(f"chunk {key} is unreadable ({short(err)})")
                    continue
                if stored is not None and part_digest(values, values.dtype) != int(stored[j]):
                    mismatch.append(key)
            if mismatch:
                reasons.append(f"chunk{'s' if len(mismatch) > 1 else ''} {', '.join(mismatch)} "
                               f"{'do' if len(mismatch) > 1 else 'does'} not match the checksum in {ckey} (one or the other is damaged)")
            if reasons:
                damaged[i] = "; ".join(reasons)
    return damaged, not_done


@dataclass
class StoreReport:
    """What :func:`verify_store` found. ``ok`` when the store is complete and undamaged."""

    path: Path
    kind: str = "periodicity_map"
    rows: int = 0
    damaged: dict[int, str] = field(default_factory=dict)
    not_done: list[int] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    complete: bool = False

    @property
    def ok(self) -> bool:
        return not (self.damaged or self.not_done or self.problems) and self.complete

    def describe(self) -> str:
        what = {"periodicity_map": "map", "ephemeris_transition": "transition"}.get(self.kind, "3-D map")
        if self.ok:
            return f"{self.path}: ok: {self.rows} rows, every chunk matches its checksum"
        lines = [f"{self.path}: damaged or incomplete librate {_what(self.kind)}"]
        lines += [f"  {p}" for p in self.problems]
        part = "epoch" if self.kind == "ephemeris_transition" else "orbit"
        lines += [f"  row {i} ({part} {i}): {why}" for i, why in sorted(self.damaged.items())]
        if self.not_done:
            lines.append(f"  rows not computed yet: {self.not_done} (re-run the same {what} to resume it)")
        elif not self.complete and not self.problems and not self.damaged:
            lines.append(f"  the {what} was interrupted during its finalisation (re-run the same {what} to finish it)")
        if self.damaged:
            lines.append(f"  damaged rows: {sorted(self.damaged)} (re-running the same {what} recomputes them)")
        return "\n".join(lines)


def store_kind(path) -> str | None:
    """The ``librate_store`` marker of a Zarr folder, or None."""
    import zarr

    try:
        with quiet_zarr():
            return zarr.open_group(str(path), mode="r", use_consolidated=False).attrs.get("librate_store")
    except Exception:  # noqa: BLE001
        return None


def verify_store(path, names: list[str] | None = None) -> StoreReport:
    """Check a part store: its marker, every array's metadata against its digest, the root
    attributes, every part against its digests and done flag, the coordinates and (when
    complete) the arrays added at the end. Never raises for damage: see the report."""
    p = Path(path)
    kind = store_kind(p) or "periodicity_map"
    rep = StoreReport(path=p, kind=kind)
    try:
        g = open_group(p, kind)
    except ValueError as err:
        rep.problems.append(str(err))
        return rep
    attrs = dict(g.attrs)
    rep.complete = int(attrs.get("complete", 0)) == 1
    ck = "row_checksum"
    if names is None:
        try:
            names = str(g[ck].attrs.get("columns", "")).split()
        except Exception:  # noqa: BLE001
            names = []
    for k in (*names, "done", ck):
        try:
            with quiet_zarr():
                g[k]  # noqa: B018 - reads the metadata
        except Exception as err:  # noqa: BLE001
            rep.problems.append(f"array {k} is missing or its metadata is unreadable ({short(err)})")
    if not names:
        rep.problems.append(f"array {ck} is missing or names no columns")
    if rep.problems:
        if any(ck in q for q in rep.problems):
            rep.problems.append("(a store without row_checksum was written by an older librate and cannot be verified)")
        return rep
    want = attrs.get("attrs_checksum")
    if want is not None and want != attrs_digest(attrs, skip=_SKIP_ATTRS):
        rep.problems.append("the root attributes (system constants, fingerprint, study) do not match their checksum")
    for name, digest in (attrs.get("array_meta") or {}).items():
        try:
            got = _array_meta(g, name)
        except Exception as err:  # noqa: BLE001
            rep.problems.append(f"array {name}: metadata unreadable ({short(err)})")
            continue
        if got != digest:
            rep.problems.append(f"array {name}: its dtype, shape or attributes do not match their checksum (e.g. an added scale_factor)")
    known = (set(names) | {"done", ck} | set(attrs.get("coord_checksums") or {})
             | set(attrs.get("extra_checksums") or attrs.get("sol_checksums") or {}))
    if rep.complete:
        for name in sorted(set(g.array_keys()) - known):
            rep.problems.append(f"array {name} is not one the store was written with (a damaged name?)")
    rep.rows = int(g["done"].shape[0])
    rep.damaged, rep.not_done = check_parts(g, p, names)
    for key in ("coord_checksums", "extra_checksums", "sol_checksums"):
        sums = attrs.get(key)
        if key != "coord_checksums" and (not rep.complete or key not in attrs):
            continue
        if not isinstance(sums, dict):
            rep.problems.append(f"root attribute {key} is missing")
            continue
        label = "coordinate" if key == "coord_checksums" else "solution array" if name_is_sol(sums) else "array"
        for name, want in sums.items():
            try:
                with quiet_zarr():
                    got = array_digest(np.asarray(g[name][...]))
            except Exception as err:  # noqa: BLE001
                rep.problems.append(f"{label} {name}: array {name} is "
                                    f"{'missing' if isinstance(err, KeyError) else 'unreadable'} ({short(err)})")
                continue
            if got != want:
                rep.problems.append(f"{label} {name} does not match its checksum")
    return rep


def name_is_sol(sums: dict) -> bool:
    return bool(sums) and all(str(k).startswith("sol_") for k in sums)
