"""The 3-D attitude map (issue 15, item 5): the planar embedding against the planar periodicity map,
a 3-D periodic motion found from a map on an L2 halo, the Dataset layout and chunking, and bad
input."""

import math

import librate
import numpy as np
import pytest
from librate.periodicity.map3d import LANES, map3d_chunk, map3d_grid


@pytest.fixture(scope="module")
def dro(em):
    """The 12.66-day DRO of thesis Fig. 23."""
    return librate.dro(em, period_days=12.66)


@pytest.fixture(scope="module")
def halo13(em):
    """The 13-day southern L2 halo."""
    return librate.halo(em, 2, "south", period_days=13.0)


def test_planar_embedding_equals_periodicity_map(dro):
    """A body with Kz = 0.8 started with its z axis on synodic Z (q0 = identity, wx0 = wy0 = 0)
    stays in the plane: the 3-D map's rz and dwz equal the planar map's dphi (phi(T) - phi0
    wrapped to (-pi, pi]) and dwz to 1e-9 (both integrated at rtol = atol = 1e-13), and rx, ry,
    dwx, dwy are exactly zero."""
    wz = np.linspace(-2.0, 2.0, 41)
    p = librate.periodicity_map(dro, kz=0.8, wz0=wz, solve=False, rtol=1e-13, atol=1e-13)
    m = librate.attitude_map_3d(dro, librate.RigidBody.from_kz(0.8), wx0=0.0, wy0=0.0, wz0=wz, tol=1e-13)
    assert m["residual"].dims == ("wz0", "component")
    assert np.all(m["status"].values == 0)
    r = m["residual"]
    for c in ("rx", "ry", "dwx", "dwy"):
        assert np.all(r.sel(component=c).values == 0.0)
    dphi, dwz = p["dphi"].values[0, 0], p["dwz"].values[0, 0]
    assert np.max(np.abs(r.sel(component="dwz").values - dwz)) < 1e-9
    away = np.abs(dphi) < math.pi - 1e-6  # at a half turn the two wraps may differ in sign
    assert away.sum() > 30
    assert np.max(np.abs(r.sel(component="rz").values[away] - dphi[away])) < 1e-9


def test_dataset_layout_and_chunking(halo13):
    """Dims (body, wx0, wz0) for a list of bodies and two array-valued rates, the component names,
    coordinates and attributes; residual_norm is the max-norm of the six; chunks starting at
    multiples of LANES and any thread count give the one-call results bit for bit."""
    bodies = [librate.RigidBody(0.8, 0.9, 1.0), librate.RigidBody(0.5, 0.7, 1.0)]
    wx = np.array([-0.05, 0.0, 0.05])
    wz = np.linspace(-1.0, -0.8, 5)
    m = librate.attitude_map_3d(halo13, bodies, wx0=wx, wy0=0.01, wz0=wz, tol=1e-10)
    assert m["residual"].dims == ("body", "wx0", "wz0", "component")
    assert list(m["component"].values) == ["rx", "ry", "rz", "dwx", "dwy", "dwz"]
    assert m["residual_norm"].dims == ("body", "wx0", "wz0")
    assert float(m["wy0"]) == 0.01 and "wy0" not in m.dims
    np.testing.assert_array_equal(m["ix_iz"].values, [0.8, 0.5])
    np.testing.assert_allclose(m["kz"].values, [0.1, 0.2], rtol=0, atol=1e-15)
    assert m.attrs["n_periods"] == 1 and m.attrs["tol"] == 1e-10 and m.attrs["q0"] == [0.0, 0.0, 0.0, 1.0]
    assert m.attrs["orbit_period"] == halo13.period and m.attrs["simd_level"] and m.attrs["complete"] == 1
    assert np.all(m["status"].values == 0)
    np.testing.assert_array_equal(m["residual_norm"].values, np.max(np.abs(m["residual"].values), axis=-1))
    # one trajectory against the scalar 3-D model (rtol = atol = 1e-13): the residual to 1e-8
    tr = librate.propagate_attitude(halo13.system, halo13.state0, ([0, 0, 0, 1.0], [wx[2], 0.01, wz[1]]), bodies[1],
                                    halo13.period, rtol=1e-13, atol=1e-13)
    dw = tr.w[-1] - np.array([wx[2], 0.01, wz[1]])
    assert np.max(np.abs(m["residual"].values[1, 2, 1, 3:] - dw)) < 1e-8
    # chunks and threads
    g = map3d_grid(bodies, wx0=wx, wy0=0.01, wz0=wz)
    flat = m["residual"].values.reshape(-1, 6)
    parts = [map3d_chunk(halo13, g, a, min(a + 2 * LANES, g.n_cases), tol=1e-10, threads=1).residual
             for a in range(0, g.n_cases, 2 * LANES)]
    np.testing.assert_array_equal(np.concatenate(parts), flat)
    with pytest.raises(ValueError, match="start"):
        map3d_chunk(halo13, g, 3, 10)


def test_halo_solution_found_from_a_map(em, halo13):
    """A map over (wx0, wz0) on the 13-day southern L2 halo (body 0.8 : 0.9 : 1, q0 a quarter turn
    about synodic Y, wy0 = 0) seeds the 3-D corrector: a motion is found that re-propagates
    independently to 1e-9 and is the one periodic_attitude_3d finds from the torque-free N = -1
    rate (q0 and w0 to 1e-8; tests/test_attitude3d.py)."""
    body = librate.RigidBody(0.8, 0.9, 1.0)
    q0 = [0.0, math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4)]
    m = librate.attitude_map_3d(halo13, body, q0=q0, wx0=np.linspace(0.5, 1.2, 11), wy0=0.0, wz0=np.linspace(-0.9, -0.2, 11))
    assert float(m["residual_norm"].min()) > 0.1  # the grid itself holds no zero: the corrector frees all six unknowns
    sols = librate.find_periodic_attitudes_3d(halo13, body, m, max_seeds=4)
    assert sols and all(s.residual < 1e-9 for s in sols)
    w_tf = 1 - 2 * math.pi / halo13.period
    ref = librate.periodic_attitude_3d(halo13, body, guess=([0, 0, 0, 1.0], [0, 0, w_tf]))
    d = [min(np.max(np.abs(s.q0 - ref.q0)), np.max(np.abs(s.q0 + ref.q0))) + np.max(np.abs(s.w0 - ref.w0)) for s in sols]
    assert min(d) < 1e-8


def test_bad_inputs(dro, halo13):
    body = librate.RigidBody(0.8, 0.9, 1.0)
    wz = np.linspace(-1, 1, 3)
    cases = [
        (dict(orbit="x"), "orbit"),
        (dict(body=librate.RigidBody.from_kz(1.0)), "body"),
        (dict(body=[]), "body"),
        (dict(wx0=np.array([0.1, 0.0])), "wx0"),
        (dict(wy0=np.zeros((2, 2))), "wy0"),
        (dict(wz0=[0.0, np.nan]), "wz0"),
        (dict(wz0="fast"), "wz0"),
        (dict(q0=[0, 0, 0, 2.0]), "q0"),
        (dict(q0=[0, 0, 1.0]), "q0"),
        (dict(n_periods=0), "n_periods"),
        (dict(tol=-1.0), "tol"),
        (dict(tol=0.1), "tol"),
    ]
    for change, name in cases:
        kw = dict(orbit=dro, body=body, wx0=0.0, wy0=0.0, wz0=wz) | change
        with pytest.raises(ValueError, match=name):
            librate.attitude_map_3d(kw.pop("orbit"), kw.pop("body"), **kw)
    m = librate.attitude_map_3d(dro, body, wx0=0.0, wy0=0.0, wz0=wz)
    with pytest.raises(ValueError, match="orbit"):
        librate.find_periodic_attitudes_3d(halo13, body, m)
    with pytest.raises(ValueError, match="body"):
        librate.find_periodic_attitudes_3d(dro, librate.RigidBody(0.5, 0.7, 1.0), m)
    with pytest.raises(ValueError, match="dataset"):
        librate.find_periodic_attitudes_3d(dro, body, {"a": 1})
    with pytest.raises(ValueError, match="max_seeds"):
        librate.find_periodic_attitudes_3d(dro, body, m, max_seeds=0)
