"""The ephemeris model (issue 21, items 1-2): the Rust Chebyshev evaluation of the embedded DE440
excerpt against jplephem reading the same file, the Earth-Moon rotating frame against its
definition, and the Moon-centred point-mass propagation against an independent integration
(scipy DOP853 on jplephem positions: a test reference, written here on purpose)."""

import librate
import numpy as np
import pytest
from librate.ephemeris.epochs import tdb_seconds

jplephem_spk = pytest.importorskip("jplephem.spk")

from ephemeris_reference import DAY, GM_MOON, ref_propagate, ref_state  # noqa: E402


@pytest.fixture(scope="module")
def eph():
    return librate.Ephemeris()


def test_states_equal_jplephem_on_the_same_file(eph, kernel):
    """Chebyshev series evaluated in Rust vs jplephem (numpy) on the embedded excerpt, over
    2020-2070: the same series, so round-off only: 1e-6 km + 2e-13 relative in position (the Sun
    is 1.5e8 km away), 1e-9 km/s + 2e-13 relative in velocity."""
    rng = np.random.default_rng(7)
    lo, hi = eph.span
    for t in rng.uniform(lo + DAY, hi - DAY, 60):
        for target, center in ((399, 301), (10, 301), (301, 3), (10, 3)):
            got, ref = eph.state(target, center, t), ref_state(kernel, target, center, t)
            assert np.max(np.abs(got[:3] - ref[:3])) < 1e-6 + 2e-13 * np.linalg.norm(ref[:3]), (target, center, t)
            assert np.max(np.abs(got[3:] - ref[3:])) < 1e-9 + 2e-13 * np.linalg.norm(ref[3:]), (target, center, t)


def test_span_covers_2020_to_2070_and_outside_is_a_value_error(eph):
    lo, hi = eph.span
    assert lo <= tdb_seconds("2020-01-01T00:00:00 TDB") and hi >= tdb_seconds("2070-01-01T00:00:00 TDB")
    with pytest.raises(ValueError, match="span|outside|cover"):
        eph.state(399, 301, hi + 30 * DAY)


def test_rotating_frame_is_the_earth_moon_frame(eph, kernel):
    """Definition (issue 21): x along Earth -> Moon, z along the Earth-Moon angular momentum,
    y = z x x; distance |r| and rate |r x v| / |r|^2 from jplephem's states, to 1e-9 relative."""
    t = tdb_seconds("2026-01-01T00:00:00 TDB")
    f = eph.rotating_frame(t)
    s = ref_state(kernel, 301, 399, t)
    r, v = s[:3], s[3:]
    h = np.cross(r, v)
    assert np.allclose(f.axes @ f.axes.T, np.eye(3), atol=1e-14)
    assert np.allclose(f.axes[0], r / np.linalg.norm(r), atol=1e-12)
    assert np.allclose(f.axes[2], h / np.linalg.norm(h), atol=1e-12)
    assert np.allclose(f.axes[1], np.cross(f.axes[2], f.axes[0]), atol=1e-12)
    assert f.distance_km == pytest.approx(np.linalg.norm(r), rel=1e-12)
    assert f.rate_rad_s == pytest.approx(np.linalg.norm(h) / (r @ r), rel=1e-9)
    # the figures: 361,026 km on 2026-01-01, rates within 2.58e-6 .. 3.02e-6 rad/s
    assert abs(f.distance_km - 361026) < 50
    assert 2.5e-6 < f.rate_rad_s < 3.1e-6


def test_sun_at_epoch_is_the_sun_phase_in_the_rotating_frame(eph, kernel):
    """theta0 = the Sun's angle seen from the Earth-Moon barycentre in the frame's x-y plane."""
    t = tdb_seconds("2030-06-01T00:00:00 TDB")
    sun = librate.Sun.at_epoch(t, eph)
    axes = eph.rotating_frame(t).axes
    s = ref_state(kernel, 10, 3, t)[:3]
    assert sun.theta0 == pytest.approx(np.arctan2(axes[1] @ s, axes[0] @ s) % (2 * np.pi), abs=1e-12)
    # one synodic month later the phase comes back (the Sun's synodic period, 29.53 d) to 1 deg
    later = librate.Sun.at_epoch(t + 29.530589 * DAY, eph)
    assert abs((later.theta0 - sun.theta0 + np.pi) % (2 * np.pi) - np.pi) < np.radians(1.0)


@pytest.mark.slow
def test_propagation_matches_scipy_dop853_on_jplephem(eph, kernel):
    """Reference: scipy DOP853 (rtol 1e-13) on the relative equations with jplephem's Earth and
    Sun positions about the Moon (test reference). Over one 9:2 NRHO period (6.56 d) from a
    Moon-centred orbit of 10,000 km: agreement within 1e-3 km (issue 21 acceptance)."""
    t0 = tdb_seconds("2030-01-01T00:00:00 TDB")
    r0 = 10000.0
    x0 = np.array([r0, 0.0, 2000.0, 0.0, 0.9 * np.sqrt(GM_MOON / r0), 0.15])
    duration = 6.56 * DAY
    ref = ref_propagate(kernel, x0, t0, duration)
    tr = librate.propagate_ephemeris(x0, t0, duration, ephemeris=eph)
    assert tr.t_tdb[0] == pytest.approx(t0) and tr.t_tdb[-1] == pytest.approx(t0 + duration)
    assert np.max(np.abs(tr.states_km[-1, :3] - ref[:3])) < 1e-3
    assert np.max(np.abs(tr.states_km[-1, 3:] - ref[3:])) < 1e-8


def test_synodic_maps_round_trip(eph):
    """CR3BP synodic state -> Moon-centred ICRF at an epoch -> back: the identity to 1e-12."""
    em = librate.System.preset("earth-moon")
    d = librate.dro(em, period_days=12.66)
    t = tdb_seconds("2031-03-15T12:00:00 UTC")
    x = eph.synodic_to_ephemeris(d.state0, t, em.mu)
    back = eph.ephemeris_to_synodic(x, t, em.mu)
    assert np.allclose(back, d.state0, rtol=0, atol=1e-12)
    # the Moon-centred distance is the synodic distance from the Moon times the Earth-Moon distance
    f = eph.rotating_frame(t)
    rho = np.linalg.norm(np.asarray(d.state0[:3]) - [1 - em.mu, 0, 0])
    assert np.linalg.norm(x[:3]) == pytest.approx(rho * f.distance_km, rel=1e-12)


def test_batch_propagation_equals_one_leg_at_a_time_and_keeps_the_good_legs(eph):
    """librate.propagate_ephemeris_many: 9:2 NRHO states at 6 daily epochs, each over half a
    period, with the STM: the same bits as propagate_ephemeris run leg by leg (each leg is
    integrated alone, on rayon); a leg that cannot be integrated (started 1 m from the Moon's
    centre) is reported in ``errors`` with NaN rows and ``ok`` False, the other legs kept."""
    em = librate.System.preset("earth-moon")
    nrho = librate.halo(em, 2, "south", period_days=29.530589 / 4.5)
    t0 = tdb_seconds("2030-01-01T00:00:00 TDB")
    epochs = [t0 + k * DAY for k in range(6)]
    states = np.array([eph.synodic_to_ephemeris(nrho.state0, t, em.mu) for t in epochs])
    half = 0.5 * nrho.period * em.tu_s
    batch = librate.propagate_ephemeris_many(states, epochs, half, ephemeris=eph, stm=True)
    assert batch.ok.all() and not batch.errors and batch.stm.shape == (6, 6, 6)
    for i, t in enumerate(epochs):
        one = librate.propagate_ephemeris(states[i], t, half, ephemeris=eph, stm=True, t_eval=[half])
        assert np.array_equal(batch.states_km[i], one.states_km[-1]) and np.array_equal(batch.stm[i], one.stm)
    bad = states.copy()
    bad[2] = [1e-3, 0.0, 0.0, 0.0, 0.0, 0.0]
    out = librate.propagate_ephemeris_many(bad, epochs, [half] * 6, ephemeris=eph)
    assert list(out.errors) == [2] and isinstance(out.errors[2], librate.IntegrationError)
    assert out.ok.tolist() == [True, True, False, True, True, True] and np.isnan(out.states_km[2]).all()
    plain = librate.propagate_ephemeris_many(states, epochs, half, ephemeris=eph)  # no STM: its own steps
    assert np.array_equal(np.delete(out.states_km, 2, axis=0), np.delete(plain.states_km, 2, axis=0))
    with pytest.raises(ValueError, match="`epochs`, `durations_s`"):
        librate.propagate_ephemeris_many(states, epochs[:5], half, ephemeris=eph)
    with pytest.raises(ValueError, match="`rtol`"):
        librate.propagate_ephemeris_many(states, epochs, half, ephemeris=eph, rtol=1.0)
