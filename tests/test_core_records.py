"""The Rust/Python boundary is typed: the bindings return frozen records (librate._core classes
with NumPy arrays handed over without copies), never dicts or positional tuples."""

import math

import librate
import numpy as np
import pytest
from librate import _core
from librate.orbits.propagation import integration_options

OPTS = integration_options(1e-12, 1e-12, None, 0.0, math.inf, 1_000_000, 0.8, None)
S0 = np.array([0.8, 0.0, 0.0, 0.0, 0.5, 0.0])


def _frozen(record, field):
    with pytest.raises(AttributeError):
        setattr(record, field, None)


def test_propagate_returns_a_trajectory_record(em):
    """One output row per accepted step plus the start (every step is output without t_eval);
    the y = 0 crossings are located to 1e-12 (the event tolerance of librate.propagate)."""
    r = _core.propagate(em.mu, S0, (0.0, 3.0), options=OPTS, stm=True, t_eval=None, events=[("crossing", [1.0, 0.0], 0, False)])
    assert isinstance(r, _core.Trajectory) and r.status == "completed" and r.event_index is None and r.collision is None
    assert isinstance(r.stats, _core.Stats) and len(r) == r.stats.accepted + 1 == r.y.shape[0]
    assert r.y.shape == (len(r), 6) and r.stm.shape == (6, 6) and r.t_final == 3.0
    assert r.y is r.y and r.t is r.t  # the stored arrays, not copies
    assert r.events and all(isinstance(e, _core.EventHit) and e.index == 0 and abs(e.y[1]) < 1e-12 for e in r.events)
    assert all(e.stm.shape == (6, 6) for e in r.events)
    _frozen(r, "y")
    assert repr(r).startswith("Trajectory(n=")


def test_propagate_many_returns_a_batch_record(em):
    """A member starting inside the Moon's collision sphere fails (status 2, primary 2) while the
    other completes, bit-identical to propagate (the batch runs each member exactly so)."""
    states = np.array([S0, [1.0 - em.mu, 0.0, 0.0, 0.0, 0.1, 0.0]])
    b = _core.propagate_many(em.mu, states, 0.0, np.array([1.0, 1.0]), options=OPTS, stm=False, threads=None,
                             collision=(em.r1_km / em.lu_km, em.r2_km / em.lu_km))
    assert isinstance(b, _core.BatchResult) and len(b) == 2 and b.stm is None
    assert list(b.ok) == [True, False] and list(b.status) == [0, 2] and b.stats.shape == (2, 3)
    assert set(b.errors) == {1} and isinstance(b.errors[1], _core.CollisionError) and b.errors[1].primary == 2
    one = _core.propagate(em.mu, S0, (0.0, 1.0), options=OPTS, stm=False, t_eval=None, events=[])
    np.testing.assert_array_equal(b.y[0], one.y_final)
    assert np.all(np.isnan(b.y[1]))
    _frozen(b, "ok")


def test_symmetric_correct_returns_an_orbit_record(dro_085):
    """The half-period crossing is on the x-z plane (x-z symmetry: y = xdot = zdot = 0 there, to
    the corrector's 1e-12 residual plus the propagation error, 1e-10 allowed)."""
    o = dro_085
    r = _core.symmetric_correct(o.system.mu, [o.x0, 0.0, o.vy0], spatial=False, constraint="fix", values=[0.0, o.x0], t_max=20.0,
                                newton=_core.NewtonOptions(tol=1e-12, max_iter=25),
                                options=_core.IntegrationOptions(rtol=1e-13, atol=1e-13))
    assert isinstance(r, _core.SymmetricOrbit) and isinstance(r.evaluation, _core.ShootingEvaluation)
    e = r.evaluation
    assert r.period == pytest.approx(o.period, rel=1e-10) and e.half_period == pytest.approx(0.5 * r.period, rel=1e-12)
    assert e.dcond.shape == (2, 3) and e.crossing.shape == (6,) and e.p.shape == (3,)
    assert np.max(np.abs(e.crossing[[1, 3, 5]])) < 1e-10 and np.max(np.abs(e.cond)) < 1e-10
    assert r.evaluation is r.evaluation
    _frozen(r, "period")


def test_family_from_members_without_shooting_evaluation(dros_small):
    """Members not from the symmetric corrector (multiple shooting, or taken from a family) carry
    no shooting evaluation: their half-period states are propagated instead. They lie on the x-z
    plane (x-z symmetry: y = xdot = 0 there; 1e-10 for orbits closed to 1e-10) and agree with the
    symmetric corrector's crossings of the continuation (1e-8)."""
    fam = dros_small
    ms = librate.correct_periodic(fam.system, fam[1].state0, fam[1].period)
    built = librate.OrbitFamily.from_members(fam.system, fam.kind, fam.spatial, [fam[0], ms, fam[2]], "test")
    np.testing.assert_allclose(built.state_half, fam.state_half, atol=1e-8)
    assert np.max(np.abs(built.state_half[:, [1, 3]])) < 1e-10


@pytest.fixture(scope="module")
def dros_small(em):
    return librate.dro_family(em, x0=[0.9, 0.85, 0.8])


def test_attitude_and_flexible_records(em, dro_085):
    """The attitude and flexible bindings return records; a rigid body is a flexible one with
    stiff appendages, so both start from the same attitude."""
    p = _core.planar_propagate(_core.PlanarModel(em.mu, 0.5), list(dro_085.state0), (0.1, -1.0), (0.0, 1.0),
                               options=OPTS, stm=True, t_eval=np.linspace(0.0, 1.0, 5))
    assert isinstance(p, _core.PlanarTrajectory) and len(p) == 5 and p.orbit.shape == (5, 6) and p.stm.shape == (2, 2)
    assert p.phi[0] == 0.1 and p.wz[0] == -1.0 and isinstance(p.stats, _core.Stats)
    a = _core.attitude_propagate(_core.AttitudeModel(em.mu, [1.0, 2.0, 3.0], ["gravity_gradient"], orbit=_core.OrbitMode.INTEGRATE),
                                 [*dro_085.state0, 0, 0, 0, 1, 0, 0, 1], (0.0, 1.0), options=OPTS, stm=False, t_eval=None)
    assert isinstance(a, _core.AttitudeTrajectory) and a.states.shape == (len(a), 13) and a.stm is None
    body = (100.0, [10.0, 20.0, 30.0], [(1.0, [1.0, 0.0], [0.0, 1.0], 1e6, 0.0), (1.0, [-1.0, 0.0], [0.0, 1.0], 1e6, 0.0)])
    c = _core.flexible_body_check(body)
    assert isinstance(c, _core.FlexibleBodyConstants) and c.total_mass == 102.0 and c.mass_matrix.shape == (2, 2)
    assert isinstance(c.asymmetry, complex) and abs(c.asymmetry) == pytest.approx(c.kz * c.inertia, rel=1e-14)
    model = _core.FlexibleModel(em.mu, body, primaries=[True, True], held=False)
    f = _core.flexible_propagate(model, list(dro_085.state0), (0.1, -1.0), [0.0, 0.0], [0.0, 0.0], (0.0, 0.5),
                                 options=OPTS, t_eval=np.linspace(0.0, 0.5, 4))
    assert isinstance(f, _core.FlexibleTrajectory) and f.q.shape == (4, 2) and f.phi[0] == 0.1
    e = _core.flexible_energies(model, f.orbit, f.phi, f.wz, f.q, f.qdot)
    assert isinstance(e, _core.FlexibleEnergies) and len(e) == 4 and e.inertia.shape == (4,)
    q = _core.flexible_quasi_static(model, list(dro_085.state0), (0.1, -1.0), (0.0, 0.5),
                                    options=OPTS, t_eval=np.linspace(0.0, 0.5, 4))
    assert isinstance(q, _core.QuasiStaticTrajectory) and q.qddot.shape == (4, 2) and q.dtau.shape == (4,)
    pt = _core.flexible_quasi_static_point(model, list(dro_085.state0), 0.1, -1.0)
    assert isinstance(pt, _core.QuasiStaticPoint)
    np.testing.assert_array_equal(pt.q, q.q[0])  # the closed form at the start of the solution
    for r in (p, a, c, f, e, q, pt):
        _frozen(r, "t")


def test_system_constants_record(em):
    """The preset's constants come back as a record (thesis: mu = 0.01215 for the Earth-Moon
    system), and the validation names the offending constant."""
    c = _core.system_preset("earth-moon")
    assert isinstance(c, _core.SystemConstants) and c.name == "earth-moon" and c.mu == 0.01215
    assert (c.mu, c.lu_km, c.tu_s, c.r1_km, c.r2_km) == (em.mu, em.lu_km, em.tu_s, em.r1_km, em.r2_km)
    with pytest.raises(ValueError, match="mu"):
        _core.system_validate("bad", 0.7, c.lu_km, c.tu_s, 0.0, 0.0)
    _frozen(c, "mu")
