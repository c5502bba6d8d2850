"""Argument conversion with errors that name the parameter and what is allowed."""

from __future__ import annotations

import math

import numpy as np


def as_real(value, name: str, *, positive: bool = False, nonnegative: bool = False, allow_inf: bool = False) -> float:
    """A real number (Python or numpy; not a bool, a string or an array), not NaN, finite unless
    ``allow_inf``; > 0 with ``positive``, >= 0 with ``nonnegative``. Else a ValueError naming it."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
    v = float(value) if ok else math.nan
    if not ok or math.isnan(v) or (math.isinf(v) and not allow_inf) or (positive and not v > 0) or (nonnegative and not v >= 0):
        what = "a number" if allow_inf else "a finite number"
        what += " > 0" if positive else " >= 0" if nonnegative else ""
        raise ValueError(f"invalid argument `{name}`: must be {what}, got {value!r}")
    return v


def as_float_array(value, name: str) -> np.ndarray:
    """A float64 array of ``value``, or a ValueError naming ``name`` (strings, objects, ragged)."""
    if isinstance(value, (str, bytes)) or value is None:
        raise ValueError(f"invalid argument `{name}`: must be numbers, got {value!r}")
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):  # ragged
        raise ValueError(f"invalid argument `{name}`: must be numbers, got {value!r}") from None
    if raw.dtype.kind not in "iuf":  # strings (even '0'), bools, objects
        raise ValueError(f"invalid argument `{name}`: must be numbers, got {value!r}")
    return raw.astype(np.float64)


def as_state(value, name: str = "state") -> np.ndarray:
    """A (6,) float array (x, y, z, xd, yd, zd); a planar (4,) (x, y, xd, yd) is not accepted."""
    arr = np.ascontiguousarray(as_float_array(value, name))
    if arr.shape != (6,):
        raise ValueError(f"invalid argument `{name}`: must have shape (6,) = (x, y, z, xd, yd, zd), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"invalid argument `{name}`: must be finite, got {arr.tolist()}")
    return arr


def as_states(value, name: str = "states") -> np.ndarray:
    """An (n, 6) float array; a single (6,) state becomes (1, 6)."""
    arr = np.ascontiguousarray(as_float_array(value, name))
    if arr.ndim == 1 and arr.shape == (6,):
        arr = arr.reshape(1, 6)
    if arr.ndim != 2 or arr.shape[1] != 6:
        raise ValueError(f"invalid argument `{name}`: must have shape (n, 6), got shape {arr.shape}")
    return arr


def as_time_span(t_span, name: str = "t_span") -> tuple[float, float]:
    """(t0, tf) from a pair, or (0, tf) from a single number."""
    ts = as_float_array(t_span, name)
    if ts.ndim == 0:
        t0, tf = 0.0, float(ts)
    else:
        ts = ts.ravel()
        if ts.shape != (2,):
            raise ValueError(f"invalid argument `{name}`: must be tf or a pair (t0, tf), got {t_span!r}")
        t0, tf = float(ts[0]), float(ts[1])
    if not (np.isfinite(t0) and np.isfinite(tf)):
        raise ValueError(f"invalid argument `{name}`: times must be finite, got ({t0}, {tf})")
    return t0, tf


def as_direction(direction, name: str = "direction") -> int:
    if direction not in (-1, 0, 1):
        raise ValueError(f"invalid argument `{name}`: must be -1 (decreasing), 0 (both) or +1 (increasing), got {direction!r}")
    return int(direction)


def as_number(value, name: str, *, positive: bool = False) -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_)) and math.isfinite(value)
    if not ok or (positive and value <= 0):
        raise ValueError(f"invalid argument `{name}`: must be a finite number{' > 0' if positive else ''}, got {value!r}")
    return float(value)


def as_count(value, name: str, minimum: int) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"invalid argument `{name}`: must be an integer >= {minimum}, got {value!r}")
    return int(value)
