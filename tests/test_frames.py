"""ECI conversion and osculating elements: analytic two-body states, round trips, and the
near-1:1 DROs of thesis Table 1 (docs/physics.md, periodic orbits)."""

import math

import librate
import numpy as np
import pytest
from helpers import continue_dros, dro_with_period


def rot_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def kepler_state(gm, a, e, i, raan, argp, nu):
    """Position and velocity from classical elements (perifocal frame rotated by
    Rz(raan) Rx(i) Rz(argp)): the textbook formulas, independent of librate."""
    p = a * (1 - e * e)
    r_pf = p / (1 + e * math.cos(nu)) * np.array([math.cos(nu), math.sin(nu), 0.0])
    v_pf = math.sqrt(gm / p) * np.array([-math.sin(nu), e + math.cos(nu), 0.0])
    ci, si = math.cos(i), math.sin(i)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ci, -si], [0.0, si, ci]])
    q = rot_z(raan) @ rx @ rot_z(argp)
    return q @ r_pf, q @ v_pf


def eci_to_synodic_by_hand(mu, t, r_i, v_i, theta0=0.0):
    """Earth-relative inertial (nondimensional) to synodic: undo the frame rotation theta0 + t,
    subtract the transport velocity z x r, shift the origin to the barycentre."""
    rt = rot_z(-(theta0 + t))
    r = rt @ r_i
    v = rt @ v_i - np.cross([0.0, 0.0, 1.0], r)
    return np.concatenate([r - [mu, 0.0, 0.0], v])


@pytest.fixture(scope="module")
def dro_1to1(em):
    """The 1:1 synodic-resonant DRO (T = 2 pi), x0 = 0.15213 (docs/physics.md: 0.1521)."""
    return dro_with_period(em, 2 * math.pi, np.arange(0.95, 0.14, -0.02))


def test_circular_orbit_about_the_earth_has_a_r_and_e_0(em):
    """Analytic: a circular orbit of radius r about the Earth with GM = 1 - mu, seen in the
    synodic frame (built by hand: the Earth-relative position turns at n - 1 with n = sqrt(GM/r^3)),
    has osculating a = r and e = 0 at every time. Tolerance: a to 1e-12 relative, e < 1e-12;
    the ECI radius and speed to 1e-12 relative in km and km/s with GM_earth = (1 - mu) LU^3/TU^2."""
    gm = 1.0 - em.mu
    gm_km = gm * em.lu_km**3 / em.tu_s**2  # km^3/s^2
    for r in (0.05, 0.3, 0.7):
        n = math.sqrt(gm / r**3)
        t = np.linspace(-3.0, 11.0, 57)
        ang = (n - 1.0) * t + 0.4
        states = np.column_stack([
            -em.mu + r * np.cos(ang), r * np.sin(ang), np.zeros_like(t),
            -(n - 1.0) * r * np.sin(ang), (n - 1.0) * r * np.cos(ang), np.zeros_like(t),
        ])
        el = librate.osculating_elements(em, t, states)
        assert np.allclose(el.a_km, r * em.lu_km, rtol=1e-12, atol=0)
        assert np.max(el.e) < 1e-12 and np.all(el.i == 0) and np.all(el.raan == 0)
        eci = librate.synodic_to_eci(em, t, states, theta0=0.3)
        rad = np.linalg.norm(eci[:, :3], axis=1)
        speed = np.linalg.norm(eci[:, 3:], axis=1)
        assert np.allclose(rad, r * em.lu_km, rtol=1e-12, atol=0)
        assert np.allclose(speed, math.sqrt(gm_km / (r * em.lu_km)), rtol=1e-12, atol=0)
        # Inertial angle = theta0 + t + synodic angle = 0.3 + 0.4 + n t: uniform rotation at n.
        dphase = np.arctan2(eci[:, 1], eci[:, 0]) - (0.7 + n * t)
        assert np.max(np.abs((dphase + math.pi) % (2 * math.pi) - math.pi)) < 1e-11


@pytest.mark.parametrize(
    "elements",
    [(0.9, 0.3, 0.0, 0.0, 1.1, 2.0), (0.9, 0.3, math.pi, 0.0, 1.1, 2.0), (0.5, 0.72, 0.6, -2.3, 0.8, -1.2),
     (1.4, 0.05, 2.5, 1.9, -0.4, 0.3)],
)
def test_elements_recovered_from_a_kepler_state(em, elements):
    """A state built from known elements (textbook perifocal formulas, GM = 1 - mu), placed in
    the synodic frame by hand at t = 1.7 with theta0 = -0.5: osculating_elements returns the
    elements to 1e-11 (angles in rad, a relative). Planar cases (i = 0 and i = pi, retrograde)
    report raan = 0 and argp = the angle of the eccentricity vector from the inertial X axis."""
    a, e, i, raan, argp, nu = elements
    r_i, v_i = kepler_state(1.0 - em.mu, a, e, i, raan, argp, nu)
    t, theta0 = 1.7, -0.5
    s = eci_to_synodic_by_hand(em.mu, t, r_i, v_i, theta0)
    el = librate.osculating_elements(em, t, s, theta0=theta0)
    wrap = lambda x: (x + math.pi) % (2 * math.pi) - math.pi  # noqa: E731
    assert el.a_km[0] == pytest.approx(a * em.lu_km, rel=1e-11)
    assert el.e[0] == pytest.approx(e, abs=1e-11)
    assert el.i[0] == pytest.approx(i, abs=1e-11)
    assert abs(wrap(el.true_anomaly[0] - nu)) < 1e-11
    if math.sin(i) == pytest.approx(0, abs=1e-15):
        # Rz(raan) Rx(i) Rz(argp) applied to the perifocal x axis: at i = 0 the eccentricity
        # vector lies at raan + argp, at i = pi (Rx = diag(1, -1, -1)) at raan - argp.
        evec_angle = raan + argp if i == 0 else raan - argp
        assert el.raan[0] == 0 and abs(wrap(el.argp[0] - evec_angle)) < 1e-11
    else:
        assert abs(wrap(el.raan[0] - raan)) < 1e-11 and abs(wrap(el.argp[0] - argp)) < 1e-11


def test_eci_round_trip_and_known_values(em):
    """synodic -> ECI -> synodic is the identity to 1e-15 (relative to the state's size), for one
    state and for many, with theta0. Known value: a point at rest on the Moon's position is, in
    ECI at t, at distance LU and moving at LU/TU = 1.0245 km/s along the frame's y axis rotated by
    theta0 + t (exact up to rounding, 1e-12 relative)."""
    rng = np.random.default_rng(3)
    states = rng.normal(size=(50, 6))
    t = rng.uniform(-10, 10, 50)
    back = librate.eci_to_synodic(em, t, librate.synodic_to_eci(em, t, states, theta0=0.7), theta0=0.7)
    assert np.max(np.abs(back - states)) < 1e-14
    one = librate.synodic_to_eci(em, 0.25, states[0])
    assert one.shape == (6,)
    assert np.allclose(librate.eci_to_synodic(em, 0.25, one), states[0], rtol=0, atol=1e-14)
    moon = np.array([1 - em.mu, 0, 0, 0, 0, 0])
    for tt in (0.0, 1.0, 4.0):
        s = librate.synodic_to_eci(em, tt, moon, theta0=0.2)
        ang = 0.2 + tt
        assert np.allclose(s[:3], em.lu_km * np.array([math.cos(ang), math.sin(ang), 0]), rtol=1e-12, atol=1e-9)
        assert np.allclose(s[3:], em.vu_km_s * np.array([-math.sin(ang), math.cos(ang), 0]), rtol=1e-12, atol=1e-15)
    assert em.vu_km_s == pytest.approx(1.0245, abs=1e-4)


def test_one_to_one_dro_mean_elements_table1(em, dro_1to1):
    """Thesis Table 1 / docs/physics.md, periodic orbits: the 1:1 resonant DRO (x0 = 0.1521) has mean
    osculating a = 392070 km and e = 0.8312 in the ECI frame, and no apsidal drift.

    Measured (time average over 2000 uniform samples per period, 3 periods): a = 392065.1 km
    (-0.0013 %), e = 0.831243 (+0.005 %); osculating a in [390219, 393325] km, e in
    [0.8247, 0.8386], argp within +-0.0155 rad (thesis Fig. 8: 1.01-1.03 LU, 0.82-0.84,
    +-0.02 rad); drift -1.9e-13 rad per period. Tolerances: a and e within 0.1 % (the table
    prints 5 and 4 digits); drift below 1e-9 rad per period. Why 1e-9: a synodic-periodic orbit
    returns rotated by exactly T - 2 pi in the ECI frame, and T is found to 1e-12 and the
    propagation is good to ~1e-11, so 1e-9 is a loose bound on a zero drift, seven orders below
    the neighbours' 1e-2 (1e-9 rad/period is one degree in 5e4 years)."""
    assert round(dro_1to1.x0, 4) == 0.1521
    me = librate.mean_elements(em, dro_1to1.state0, dro_1to1.period, n_periods=3)
    assert me.a_km == pytest.approx(392070, rel=1e-3)
    assert me.e == pytest.approx(0.8312, rel=1e-3)
    assert abs(me.argp_drift) < 1e-9
    assert np.all(np.abs(me.argp_drift_per_period) < 1e-9)
    # The osculating elements oscillate (short-period terms) but do not drift.
    el = me.elements
    assert 0.005 < np.ptp(el.e) < 0.03 and np.max(np.abs(el.argp)) < 0.02
    assert np.ptp(me.a_km_per_period) < 1e-3 and np.ptp(me.e_per_period) < 1e-9
    assert me.argp_rate == me.argp_drift / dro_1to1.period


def test_near_one_to_one_dros_drift_in_opposite_directions_table1(em):
    """Thesis Table 1: DROs with x0 = 0.1 and 0.2 precess in opposite directions, +0.011 and
    -0.014 rad per period, with mean a = 391590 and 392500 km, e = 0.8830 and 0.7844.

    Measured: x0 = 0.1: drift +0.011004 rad/period, a = 391584.9 km, e = 0.88298; x0 = 0.2:
    drift -0.013655, a = 392500.9 km, e = 0.78441. Tolerances: drift to the table's last digit
    (5e-4 rad), a and e within 0.1 %. The drift equals T - 2 pi to 1e-9 (the ECI picture of a
    synodic-periodic orbit rotates by T per period; T(0.1) > 2 pi > T(0.2))."""
    orbits = {round(o.x0, 4): o for o in continue_dros(em, np.arange(0.95, 0.09, -0.01)) if round(o.x0, 4) in (0.1, 0.2)}
    table = {0.1: (0.011, 391590, 0.8830), 0.2: (-0.014, 392500, 0.7844)}
    for x0, (drift, a_km, e) in table.items():
        o = orbits[x0]
        me = librate.mean_elements(em, o.state0, o.period, n_periods=3)
        assert me.argp_drift == pytest.approx(drift, abs=5e-4)
        assert me.argp_drift == pytest.approx(o.period - 2 * math.pi, abs=1e-9)
        assert np.allclose(me.argp_drift_per_period, o.period - 2 * math.pi, rtol=0, atol=1e-9)
        assert me.a_km == pytest.approx(a_km, rel=1e-3)
        assert me.e == pytest.approx(e, rel=1e-3)


def test_bad_arguments(em):
    s = np.zeros(6)
    with pytest.raises(ValueError, match="`states`"):
        librate.synodic_to_eci(em, 0.0, np.zeros((3, 5)))
    with pytest.raises(ValueError, match="`t`"):
        librate.synodic_to_eci(em, [0.0, 1.0], np.zeros((3, 6)))
    with pytest.raises(ValueError, match="`t`"):
        librate.osculating_elements(em, [0.0, 1.0], s)
    with pytest.raises(ValueError, match="`theta0`"):
        librate.synodic_to_eci(em, 0.0, s, theta0=math.inf)
    with pytest.raises(ValueError, match="`states_km`"):
        librate.eci_to_synodic(em, 0.0, [1.0, 2.0])
    with pytest.raises(ValueError, match="`period`"):
        librate.mean_elements(em, [0.5, 0, 0, 0, 0.5, 0], 0.0)
    with pytest.raises(ValueError, match="`n_periods`"):
        librate.mean_elements(em, [0.5, 0, 0, 0, 0.5, 0], 1.0, n_periods=0)
    with pytest.raises(ValueError, match="`orbit_state0`"):
        librate.mean_elements(em, [0.5, 0, 0], 1.0)
