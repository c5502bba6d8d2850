"""Runtime SIMD dispatch (librate_core::simd): build_info, LIBRATE_SIMD, and the map engine at
every level this CPU supports.

References and tolerances:
- on one level the engine is bit-identical for any thread count and chunking (lane-wise
  arithmetic; a trajectory depends only on its lock-step group): tested with ==;
- between levels the only difference is fused (avx2, avx512, neon) against unfused (baseline)
  multiply-adds, one rounding per operation, grown along each trajectory like its sensitivity:
  phi(T), wz(T) agree to 1e-12 relative to max(1, |value|), divided by max(1, max |STM entry|)
  (measured on the standard map: ~1e-14 scaled, 2.6e-12 unscaled at the most sensitive rate);
  the two FMA levels compute the same operations and agree bit for bit.
"""

import os
import subprocess
import sys

import librate
import numpy as np
import pytest
from librate import _core
from librate.periodicity import orbit_forcing, sweep

LEVELS = librate.build_info()["simd_available"]


@pytest.fixture(scope="module")
def standard_map(em):
    """The standard map's orbit (DRO x0 = 0.70) and a 240-rate subset of its 2000 rates."""
    orbit = librate.correct_dro(em, 0.70)
    return orbit_forcing(orbit), orbit.period, np.linspace(-3.0, 2.0, 240)


@pytest.fixture
def level():
    """Switch levels in this process; restore the one active at import afterwards."""
    before = librate.build_info()["simd_active"]
    yield _core.simd_set_active
    _core.simd_set_active(before)


def test_build_info():
    b = librate.build_info()
    assert set(b) >= {"simd_available", "simd_active", "version", "profile"}
    assert b["version"] == librate.__version__
    assert b["profile"] in ("dev", "release", "dist")
    # the profile is the one cargo built with: debug assertions are on in dev builds only
    assert (b["profile"] == "dev") == b["debug_assertions"]
    assert b["simd_active"] in b["simd_available"]
    assert b["simd_available"] == [lv for lv in b["simd_known"] if lv in b["simd_available"]]
    if b["target_arch"] == "x86_64":
        assert b["simd_known"] == ["baseline", "avx2", "avx512"] and "baseline" in b["simd_available"]
    assert "build_info" in librate.__all__


def _import_with(value):
    env = dict(os.environ, LIBRATE_SIMD=value)
    code = "import librate; print(librate.build_info()['simd_active'])"
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)


def test_env_var_forces_a_level_or_fails_at_import():
    forced = LEVELS[0]
    r = _import_with(forced.upper())
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == forced
    r = _import_with("sse9")
    assert r.returncode != 0
    assert "ValueError" in r.stderr and "LIBRATE_SIMD" in r.stderr and "auto" in r.stderr and "baseline" in r.stderr
    missing = [lv for lv in librate.build_info()["simd_known"] if lv not in LEVELS]
    if missing:  # a level this CPU lacks: refused, naming what it has
        r = _import_with(missing[-1])
        assert r.returncode != 0 and "not supported by this CPU" in r.stderr and "LIBRATE_SIMD" in r.stderr


def test_set_active_refuses_unknown_levels(level):
    with pytest.raises(ValueError, match="LIBRATE_SIMD"):
        level("avx1024")


def test_map_at_every_level(standard_map, level):
    forcing, period, wz0 = standard_map
    runs = {}
    for lv in LEVELS:
        assert level(lv) == lv
        r = sweep(forcing, period, 0.0, wz0, 0.8, stm=True, threads=1)
        for threads, chunk in ((2, 8), (None, 24)):
            o = sweep(forcing, period, 0.0, wz0, 0.8, stm=True, threads=threads, chunk=chunk)
            for k in ("phi_t", "wz_t", "stm"):
                assert np.array_equal(o[k], r[k]), (lv, threads, chunk, k)
        runs[lv] = r
    ref = next((lv for lv in LEVELS if lv != "baseline"), LEVELS[0])
    r0 = runs[ref]
    sens = np.maximum(1.0, np.abs(np.asarray(r0["stm"]).reshape(len(wz0), -1)).max(axis=1))
    for lv, r in runs.items():
        for k in ("phi_t", "wz_t"):
            d = np.abs(r[k] - r0[k]) / np.maximum(1.0, np.abs(r0[k]))
            assert np.max(d / sens) <= 1e-12, (lv, k, np.max(d / sens))
        if lv != "baseline":
            for k in ("phi_t", "wz_t", "stm"):
                assert np.array_equal(r[k], r0[k]), (lv, ref, k)


def test_info_prints_the_levels():
    from click.testing import CliRunner
    from librate.app.cli import main

    out = CliRunner().invoke(main, ["info"], catch_exceptions=False).output
    b = librate.build_info()
    assert f"SIMD level {b['simd_active']}" in out and ", ".join(b["simd_available"]) in out
    assert f"threads: {b['threads']} workers" in out and f"LIBRATE_BIND_THREADS={b['threads_binding']}" in out


def test_scalar_integrator_at_every_level(dro_085, level):
    """The scalar RKF7(8) stepper (propagate, with the STM) is dispatched too: the FMA levels
    agree bit for bit; baseline within 1e-11 relative (the DRO's monodromy has entries ~1e2:
    rounding grows like it)."""
    runs = {}
    for lv in LEVELS:
        level(lv)
        tr = librate.propagate(dro_085.system, dro_085.state0, dro_085.period, stm=True)
        runs[lv] = (np.asarray(tr.y[-1]), np.asarray(tr.stm))
    ref = next((lv for lv in LEVELS if lv != "baseline"), LEVELS[0])
    for lv, (y, stm) in runs.items():
        assert np.max(np.abs(y - runs[ref][0])) <= 1e-11 * max(1.0, np.max(np.abs(y)))
        assert np.max(np.abs(stm - runs[ref][1])) <= 1e-11 * np.max(np.abs(stm))
        if lv != "baseline":
            assert np.array_equal(y, runs[ref][0]) and np.array_equal(stm, runs[ref][1]), lv
