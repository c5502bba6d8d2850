"""Argument conversion with errors that name the parameter and what is allowed."""

from __future__ import annotations

import math

import numpy as np

#: The allowed range of each tolerance of the public API, by parameter name (issue 24 #6).
#: Relative tolerances below 1e-15 ask for less than the double-precision round-off of the
#: state (the step-size control then shrinks the steps to the floor); above 1e-3 the embedded
#: error estimates of the 7(8) and 8(7) pairs no longer bound the error (rtol = 1000 let the
#: map integrator take steps of whole periods and never finish). Absolute tolerances go lower:
#: states that are small by construction (a deflection of 1e-4) are integrated at atol = 1e-16.
#: Newton and fit tolerances (``tol``, ``jacobi_tol``, ``closure_tol``) are relative too.
TOLERANCES = {"rtol": (1e-15, 1e-3), "atol": (1e-18, 1e-3), "tol": (1e-15, 1e-3), "jacobi_tol": (1e-15, 1e-1),
              "closure_tol": (1e-15, 1e-1)}
#: The largest value of each count of the public API, by parameter name; a count not named here
#: is bounded by MAX_COUNT (the core's 32-bit counters). ``threads``: more worker threads than
#: this only queue (1024 is well past any machine's cores; 2**31 hung the thread pool's start).
#: ``max_iter``: Newton converges quadratically or not at all, 10,000 iterations is far past
#: either. ``max_steps``: 1e9 integrator steps are hours of work for one trajectory.
#: ``n_periods``: attitude motions over up to 1000 orbit periods. ``n_harmonics``: a Fourier fit
#: of N harmonics samples 8 N times (its design matrix: 128 N**2 bytes, 128 MB at N = 1000).
COUNT_LIMITS = {"threads": 1024, "max_iter": 10_000, "max_steps": 10**9, "n_periods": 1000, "chunk": 1 << 20,
                "max_members": 100_000, "max_points": 100_000, "steps": 100_000, "max_seeds": 100_000,
                "n_harmonics": 1000, "max_harmonics": 1000}
MAX_COUNT = 2**31 - 1
#: The most memory (bytes) the arrays sized by one grid-size argument may take (the same limit
#: as a study's map arrays, app/budget.py): 2 GiB.
MAX_ARRAY_BYTES = 2 * 1024**3
#: Bytes per (orbit, kz, wz0) cell of a planar map's result arrays, held for the whole map by
#: ``periodicity_map``, the study runner and the ``librate map`` store alike: dwz, dphi and
#: phi_T (float64) and status (uint8), 3 * 8 + 1 = 25.
MAP_CELL_BYTES = 3 * 8 + 1
#: Bytes per case of the one row (an orbit's kz x wz0 cases) in flight: its case grids (two
#: float64 meshgrids), the engine's per-case records and outputs (phi_T, wz_T, dwz, dphi, status,
#: steps). Measured: the peak RSS of a one-orbit map grows by 278 B per case from 2e5 to 1e6
#: cases (25 B of them the result arrays), i.e. 253 B; rounded up.
MAP_ROW_CELL_BYTES = 256
#: Bytes per (body, wx0, wy0, wz0) case of a 3-D map's result arrays: six closure residuals and
#: their norm (float64) and status (uint8), 7 * 8 + 1 = 57 (the cases run in chunks of a bounded
#: size, so the results are what grows with the grid).
MAP3D_CELL_BYTES = 7 * 8 + 1


def map_bytes(n_orbits: int, row_cells: int) -> int:
    """The peak memory of a planar map of ``n_orbits`` rows of ``row_cells`` cases each (bytes):
    the result arrays of every row and the working set of the row in flight. The one estimate
    behind the API's refusal (:func:`check_map_cells`) and a study's budget
    (``librate.app.budget``)."""
    return int(n_orbits) * int(row_cells) * MAP_CELL_BYTES + int(row_cells) * MAP_ROW_CELL_BYTES


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


def as_count(value, name: str, minimum: int, maximum: float | None = None) -> int:
    """An integer in [minimum, maximum] (``maximum`` by default from COUNT_LIMITS by name, else
    MAX_COUNT); not a bool, a float or a string. Else a ValueError naming it and the range."""
    hi = COUNT_LIMITS.get(name, MAX_COUNT) if maximum is None else maximum
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not minimum <= value <= hi:
        raise ValueError(f"invalid argument `{name}`: must be an integer "
                         + (f">= {minimum}" if hi == math.inf else f"in [{minimum}, {hi:,}]") + f", got {value!r}")
    return int(value)


def as_threads(value, name: str = "threads") -> int | None:
    """A worker-thread count in [1, COUNT_LIMITS["threads"]], or None (all cores)."""
    if value is None:
        return None
    hi = COUNT_LIMITS["threads"]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or not 1 <= value <= hi:
        raise ValueError(f"invalid argument `{name}`: must be an integer in [1, {hi}] or None (all cores), got {value!r}")
    return int(value)


def as_tolerance(value, name: str) -> float:
    """A tolerance in its range of TOLERANCES (by name; a Newton tolerance's by default), else a
    ValueError naming it and the range."""
    lo, hi = TOLERANCES.get(name, TOLERANCES["tol"])
    return as_between(value, name, lo, hi)


def as_between(value, name: str, lo: float, hi: float) -> float:
    """A real number in [lo, hi] (not a bool, a string or NaN), else a ValueError naming it."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
    v = float(value) if ok else math.nan
    if not lo <= v <= hi:  # NaN fails too
        raise ValueError(f"invalid argument `{name}`: must be a number in [{lo:g}, {hi:g}], got {value!r}")
    return v


def _bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"  # pragma: no cover


def as_size(value, name: str, minimum: int, *, item_bytes: float, what: str = "arrays") -> int:
    """A grid size (count of samples, grid points, cases) whose ``what`` take ``item_bytes`` per
    unit: an integer in [minimum, MAX_ARRAY_BYTES / item_bytes], checked before anything is
    allocated. Else a ValueError naming it, the range and the memory it would take."""
    hi = max(int(MAX_ARRAY_BYTES // item_bytes), minimum)
    n = as_count(value, name, minimum, maximum=math.inf)  # the type and the minimum
    if n > hi:
        raise ValueError(f"invalid argument `{name}`: must be an integer in [{minimum}, {hi:,}]: {n:,} would need about "
                         f"{_bytes(n * item_bytes)} of {what} (limit {_bytes(MAX_ARRAY_BYTES)}), got {value!r}")
    return n


def check_cells(shape, names: str, *, item_bytes: float, what: str = "result arrays") -> int:
    """The number of cells of a grid of ``shape`` (the product, in Python integers: never
    overflows), refused with a ValueError naming ``names`` when its ``what`` would take more than
    MAX_ARRAY_BYTES at ``item_bytes`` per cell."""
    n = math.prod(int(k) for k in shape)
    _refuse(shape, names, n, n * item_bytes, what)
    return n


def check_map_cells(shape, names: str) -> int:
    """:func:`check_cells` for a planar map of ``shape`` = (orbits, *row): its memory is
    :func:`map_bytes` (the results of every row and the working set of one)."""
    n = math.prod(int(k) for k in shape)
    row = math.prod(int(k) for k in shape[1:])
    _refuse(shape, names, n, map_bytes(int(shape[0]), row), "memory (result arrays and the row in flight)")
    return n


def _refuse(shape, names: str, n: int, nbytes: float, what: str) -> None:
    if nbytes > MAX_ARRAY_BYTES:
        dims = " x ".join(f"{int(k):,}" for k in shape)
        raise ValueError(f"invalid arguments {names}: a grid of {dims} = {n:,} cases would need about {_bytes(nbytes)} of "
                         f"{what} (limit {_bytes(MAX_ARRAY_BYTES)}); use fewer values")
