"""Digests of saved results, independent of the file format: over the data of every variable,
its name, dtype, shape and attributes, and the result's root attributes (the system constants
among them), so that a changed number, a flipped bit in a name or in ``mu``, or a decoding
attribute such as ``scale_factor`` slipped into an array's metadata is detected and named."""

from __future__ import annotations

import hashlib
import json

import numpy as np

__all__ = ["CHECKSUM_ATTR", "META_ATTR", "array_digest", "attrs_digest", "check_dataset", "dataset_checksums",
           "dataset_meta", "meta_digest",
           "plain", "value_digest"]

#: The attribute of a saved Dataset holding the digests of its variables' values (JSON).
CHECKSUM_ATTR = "librate_checksums"
#: The attribute holding the digests of the names, dtypes, shapes and attributes of its
#: variables and of the root attributes (JSON; results written before it have only the first).
META_ATTR = "librate_checksums_meta"


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


def value_digest(value) -> str:
    """An exact hex digest of a task's result (the bytes, dtype and shape of every array, every
    number's bits, text; nested in dicts, lists and tuples), to check it on arrival from another
    process. TypeError for anything else (a result must be plain data to be checked)."""
    h = hashlib.blake2b(digest_size=16)
    _feed(h, value)
    return h.hexdigest()


def _feed(h, v) -> None:
    if isinstance(v, dict):
        h.update(b"{%d" % len(v))
        for k in sorted(v, key=str):
            _feed(h, str(k))
            _feed(h, v[k])
    elif isinstance(v, (list, tuple)):
        h.update(b"[%d" % len(v))
        for x in v:
            _feed(h, x)
    elif isinstance(v, (np.ndarray, np.generic)):
        a = np.ascontiguousarray(v)
        if a.dtype.hasobject:
            raise TypeError("value_digest: an object array cannot be checksummed")
        h.update(f"a{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    elif v is None or isinstance(v, (bool, int, float, complex, str, bytes)):
        h.update(f"{type(v).__name__}:".encode())
        h.update(v if isinstance(v, bytes) else np.float64(v).tobytes() if isinstance(v, float) else repr(v).encode())
    else:
        raise TypeError(f"value_digest: cannot checksum a {type(v).__name__} (return arrays, numbers, text, dicts or lists)")


def plain(v):
    """An attribute value in a form that survives every file format (numbers as float64 lists,
    text as text, mappings as sorted JSON)."""
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, str):
        return v
    if isinstance(v, dict):
        return json.dumps({str(k): plain(x) for k, x in v.items()}, sort_keys=True)
    try:
        a = np.atleast_1d(np.asarray(v))
    except Exception:  # noqa: BLE001 - anything else: its text
        return str(v)
    if a.dtype.kind in "biuf":
        return [float(x) if x == x else "nan" for x in a.astype(np.float64).ravel()]
    return [plain(x) for x in a.ravel().tolist()]


def _dtype_class(dtype) -> str:
    d = np.dtype(dtype)
    if d.kind in "USO":
        return "text"
    # by kind only: netCDF 3 stores int64 as int32 and uint8 as int8 (fixed dtypes are the
    # result classes' business, see librate.results.kinds)
    return {"b": "bool", "i": "int", "u": "int", "f": "float", "c": "complex"}.get(d.kind, d.str)


def _h(text: str) -> str:
    return hashlib.blake2b(text.encode(), digest_size=16).hexdigest()


def meta_digest(name: str, dtype, shape, attrs: dict, dims=()) -> str:
    """A digest of a variable's name, dtype, shape, dimensions and attributes."""
    return _h(json.dumps([str(name), _dtype_class(dtype), [int(n) for n in shape], [str(d) for d in dims],
                          {str(k): plain(v) for k, v in sorted(attrs.items()) if not str(k).startswith("_")}], sort_keys=True))


def attrs_digest(attrs: dict, skip=(CHECKSUM_ATTR, META_ATTR)) -> str:
    """A digest of a result's root attributes (except the digests themselves)."""
    return _h(json.dumps({str(k): plain(v) for k, v in sorted(attrs.items()) if k not in skip}, sort_keys=True))


def dataset_checksums(ds) -> str:
    """The JSON digests of every variable (coordinates included) of an xarray Dataset."""
    return json.dumps({str(k): array_digest(np.asarray(ds[k].values)) for k in ds.variables})


def dataset_meta(ds) -> str:
    """The JSON digests of the names, dtypes, shapes and attributes of every variable of ``ds``
    and of its root attributes (:data:`META_ATTR`)."""
    return json.dumps({"names": sorted(str(k) for k in ds.variables),
                       "vars": {str(k): meta_digest(str(k), ds[k].dtype, ds[k].shape, dict(ds[k].attrs), ds[k].dims) for k in ds.variables},
                       "attrs": attrs_digest(dict(ds.attrs))})


def _loads(raw):
    if not isinstance(raw, str):
        return None
    try:
        d = json.loads(raw)
    except ValueError:
        return "bad"
    return d if isinstance(d, dict) else "bad"


def check_dataset(ds, values: dict | None = None) -> tuple[list[str], bool]:
    """Check ``ds`` against its stored digests. ``values``: its variables already read (name ->
    array), else they are read here. Returns ``(problems, checked)``: each problem names the
    damaged variable or attribute; ``checked`` is False when the result has no digests (written
    by an older librate)."""
    sums, meta = _loads(ds.attrs.get(CHECKSUM_ATTR)), _loads(ds.attrs.get(META_ATTR))
    problems: list[str] = []
    if sums is None:
        return problems, False
    if sums == "bad":
        return [f"attribute {CHECKSUM_ATTR} is not valid JSON"], True
    names = {str(k) for k in ds.variables}
    for name in sorted(set(sums) - names):
        problems.append(f"variable {name} is missing (its name or the file is damaged)")
    if meta == "bad":
        problems.append(f"attribute {META_ATTR} is not valid JSON")
        meta = None
    if meta is not None:
        for name in sorted(names - set(meta.get("names", []))):
            problems.append(f"variable {name} is not one the result was saved with (a damaged name?)")
        if meta.get("attrs") != attrs_digest(dict(ds.attrs)):
            problems.append("the root attributes (system constants, study, kind) do not match their checksum")
    for name in sorted(names & set(sums)):
        v = ds[name]
        if meta is not None and name in meta.get("vars", {}):
            if meta_digest(name, v.dtype, v.shape, dict(v.attrs), v.dims) != meta["vars"][name]:
                problems.append(f"variable {name}: its dtype, shape or attributes do not match their checksum")
        if values is not None and name not in values:
            continue  # unreadable: already named by the caller
        try:
            a = values[name] if values is not None else np.asarray(v.values)
        except Exception as err:  # noqa: BLE001 - a damaged chunk: named
            problems.append(f"variable {name} is unreadable ({type(err).__name__})")
            continue
        if array_digest(a) != sums[name]:
            problems.append(f"variable {name} does not match its checksum")
    return problems, True
