"""A map row's crossings and their search windows (``_core.row_crossings``, behind
``periodicity.solutions.candidates`` and ``periodicity.maps.crossing_windows``), and the map's
refinement started on the pool (``periodicity.solutions.start_refine``).

The reference below is the numpy form these functions had before they moved into the core
(kept here as a test reference only): the core's crossings, windows and unresolved counts must
equal it exactly, bit for bit, on random rows with NaN, flat and steep intervals (hypothesis).
"""

import math

import librate
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from librate import _core
from librate.periodicity import maps
from librate.periodicity.solutions import candidates, start_refine

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True, database=None)


def reference_candidates(phi_t, phi0, wz, level, max_crossings=None):
    """Test reference: the former numpy/Python form of ``candidates``."""
    u = (np.asarray(phi_t, dtype=float) - phi0) / level
    wz = np.asarray(wz, dtype=float)
    a, b = u[:-1], u[1:]
    ok = np.isfinite(a) & np.isfinite(b) & (a != b)
    lo, hi = np.ceil(np.minimum(a, b)), np.floor(np.maximum(a, b))
    if max_crossings is not None:
        ok &= hi - lo + 1 <= max_crossings
    out = []
    for i in np.flatnonzero(ok & (hi >= lo)).tolist():
        ai, bi, w0, w1 = float(a[i]), float(b[i]), float(wz[i]), float(wz[i + 1])
        for k in range(int(lo[i]), int(hi[i]) + 1):
            out.append((k, w0 + (k - ai) / (bi - ai) * (w1 - w0)))
    return out


def reference_windows(row, phi0, wz, cands, quick, resolved, max_crossings):
    """Test reference: the former numpy form of ``crossing_windows``' windows and its count of
    unresolved intervals."""
    u = (np.asarray(row, dtype=float) - phi0) / math.pi
    a, b = u[:-1], u[1:]
    with np.errstate(invalid="ignore"):
        crossed = np.floor(np.maximum(a, b)) - np.ceil(np.minimum(a, b)) + 1
    unresolved = int(np.sum(np.isfinite(crossed) & (crossed > max_crossings)))
    if not cands:
        return np.empty(0), np.empty(0), unresolved
    at = np.clip(np.searchsorted(wz, [w for _, w in cands], side="right") - 1, 0, wz.size - 2)
    first, last = np.maximum(at - quick, 0), np.minimum(at + quick, wz.size - 2)
    near = np.minimum(first[:, None] + np.arange(2 * quick + 1), last[:, None])
    with np.errstate(invalid="ignore"):
        ok = np.all(np.abs(b - a)[near] <= resolved, axis=1)
    return np.where(ok, wz[first], -np.inf), np.where(ok, wz[last + 1], np.inf), unresolved


@st.composite
def rows(draw):
    """A row of unwrapped angles over increasing rates: smooth drifts, steep jumps, flat runs,
    NaN (a failed trajectory) and values exactly on a level."""
    n = draw(st.integers(2, 60))
    steps = draw(st.lists(st.one_of(st.floats(-0.3, 0.3), st.floats(-40.0, 40.0), st.just(0.0)), min_size=n - 1, max_size=n - 1))
    start = draw(st.one_of(st.floats(-20.0, 20.0), st.integers(-6, 6).map(lambda k: k * math.pi)))
    row = np.concatenate([[start], start + np.cumsum(steps)])
    for i in draw(st.lists(st.integers(0, n - 1), max_size=3)):
        row[i] = math.nan
    wz = np.cumsum(draw(st.lists(st.floats(1e-3, 0.5), min_size=n, max_size=n))) - 3.0
    return row, wz


@SETTINGS
@given(rows(), st.sampled_from([0.0, 0.5 * math.pi, 1.0]), st.sampled_from([math.pi, 0.5 * math.pi]), st.sampled_from([None, 1, 8]))
def test_candidates_equal_the_reference(data, phi0, level, max_crossings):
    row, wz = data
    assert candidates(row, phi0, wz, level, max_crossings=max_crossings) == reference_candidates(row, phi0, wz, level, max_crossings)


@SETTINGS
@given(rows(), st.sampled_from([0.0, 0.5 * math.pi]))
def test_windows_and_unresolved_equal_the_reference(data, phi0):
    row, wz = data
    cands, kk, unresolved, (lo, hi) = maps.crossing_windows([0.3], phi0, wz, [row])
    ref = reference_candidates(row, phi0, wz, math.pi, maps.MAX_CROSSINGS)
    rlo, rhi, runresolved = reference_windows(row, phi0, wz, ref, maps.QUICK_WINDOW, maps.RESOLVED, maps.MAX_CROSSINGS)
    assert cands == ref and kk == [0.3] * len(ref) and unresolved == runresolved
    np.testing.assert_array_equal(lo, rlo)
    np.testing.assert_array_equal(hi, rhi)


def test_row_crossings_checks_its_arguments():
    row, wz = np.array([0.5, 4.0]), np.array([0.0, 1.0])
    with pytest.raises(ValueError, match="`phi_t`"):
        _core.row_crossings(row, np.array([0.0, 1.0, 2.0]), phi0=0.0, level=math.pi)
    for level in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="`level`"):
            _core.row_crossings(row, wz, phi0=0.0, level=level)
    c = _core.row_crossings(row, wz, phi0=0.0, level=math.pi, max_crossings=8, window=(4, 0.25))
    assert c.k.tolist() == [1] and c.interval.tolist() == [0] and c.unresolved == 0 and c.window.shape == (1, 2)


def test_started_refinement_is_the_refinement(em):
    """start_refine(...).result() is refine_groups(...), and a refinement is joined once: later
    calls return the same solutions (the standard DRO x0 0.70, Kz 0.8, the candidates of a
    200-rate row)."""
    o = librate.dro(em, x0=0.70)
    wz = np.linspace(-3.0, 2.0, 200)
    ds = librate.periodicity_map(o, kz=0.8, wz0=wz, solve=False)
    cands, kk, _, (lo, hi) = maps.crossing_windows([0.8], 0.0, wz, ds.phi_T.values[0])
    r = start_refine(o, np.array(kk), 0.0, cands, n_periods=1, srp=None, closure="half", window=(wz[0], wz[-1]), search=(lo, hi))
    first = r.result()
    assert r.result() is first and len(first) >= 4
    again = librate.periodicity_map(o, kz=0.8, wz0=wz)
    np.testing.assert_array_equal([s.wz0 for _, s in first], again.sol_wz0.values)
    assert all(s.residual <= 1e-8 for _, s in first)


def test_interrupt_while_the_last_solutions_are_refined_keeps_them(em, monkeypatch):
    """Ctrl-C while the map's last orbit has its solutions refined on the pool (here raised in the
    coordinates' construction, which runs meanwhile): the refinement is still joined and its
    solutions kept, the row computed, the map flagged incomplete."""
    o = librate.dro(em, x0=0.70)
    wz = np.linspace(-3.0, 2.0, 300)
    full = librate.periodicity_map(o, kz=0.8, wz0=wz)
    real, calls = maps.map_coordinates, []

    def interrupted_once(*args):
        calls.append(1)
        if len(calls) == 1:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(maps, "map_coordinates", interrupted_once)
    with pytest.warns(UserWarning, match="1 of 1 orbits"):
        ds = librate.periodicity_map(o, kz=0.8, wz0=wz)
    assert ds.attrs["complete"] == 0 and ds.computed.values.tolist() == [True] and len(calls) == 2
    for v in ("dwz", "sol_wz0", "sol_residual", "sol_trace"):
        np.testing.assert_array_equal(ds[v].values, full[v].values)


def test_distinct_solutions_merge_by_group_kz_turns_and_wz0():
    """The merge rule of a batch's refinement (and of solutions from several batches): the same
    group, Kz and turns with wz0 within 1e-8 are one solution, the first kept; a key is compared
    with the kept ones only."""
    g = np.array([0, 0, 0, 1, 0, 0, 0, 0], dtype=np.int64)
    kz = np.array([0.8, 0.8, 0.8, 0.8, 0.5, 0.8, 0.8, 0.8])
    turns = np.array([-1.0, -1.0, -1.0, -1.0, -1.0, -0.5, -1.0, -1.0])
    wz0 = np.array([1.0, 1.0 + 5e-9, 1.0 + 1.2e-8, 1.0, 1.0, 1.0, 1.0 + 1.6e-8, 1.0 + 2.3e-8])
    # 1: within 1e-8 of 0; 2: 1.2e-8 from 0 (kept); 3: another group; 4: another Kz; 5: another
    # turns; 6: 0.4e-8 from 2 (merged); 7: 1.1e-8 from 2 and 2.3e-8 from 0 (kept)
    assert _core.distinct_solutions(g, kz, turns, wz0).tolist() == [0, 2, 3, 4, 5, 7]
    with pytest.raises(ValueError, match="`kz`"):
        _core.distinct_solutions(g, kz[:3], turns, wz0)
