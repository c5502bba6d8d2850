"""Collisions with a primary are a typed outcome (issue 12 #5: a state at the Moon's centre
"completed" with speeds of 1e8 and a Jacobi constant of -7e16; propagate_many said ok=True)."""

import librate
import numpy as np
import pytest


def test_state_at_the_moons_centre_raises_collision(em):
    mu = em.mu
    with pytest.raises(librate.CollisionError, match="collision with the Moon \\(primary 2\\)") as info:
        librate.propagate(em, [1 - mu, 0, 0, 0, 0, 0], 1.0)
    e = info.value
    assert isinstance(e, librate.IntegrationError) and isinstance(e, librate.LibrateError)
    assert (e.primary, e.t, e.kind) == (2, 0.0, "collision")
    assert e.trajectory.status == "collision" and e.trajectory.collision_primary == 2


def test_fall_onto_the_moon_stops_on_its_surface(em):
    mu = em.mu
    r_moon = em.r2_km / em.lu_km
    with pytest.raises(librate.CollisionError) as info:
        librate.propagate(em, [1 - mu + 0.02, 0, 0, 0, 0, 0], 1.0)
    e = info.value
    assert e.primary == 2 and 0 < e.t < 1
    tr = e.trajectory
    assert tr.t_final == pytest.approx(e.t) and np.all(np.isfinite(tr.y))
    assert np.linalg.norm(tr.y_final[:3] - [1 - mu, 0, 0]) == pytest.approx(r_moon, abs=1e-9)
    assert np.max(np.abs(tr.y[:, 3:])) < 10  # no 1e8 speeds
    assert np.all(np.abs(tr.jacobi) < 10)


def test_earth_collision_and_backward(em):
    mu = em.mu
    with pytest.raises(librate.CollisionError, match="the Earth \\(primary 1\\)") as info:
        librate.propagate(em, [-mu + 0.03, 0, 0, 0, 0, 0], -1.0)
    assert info.value.primary == 1 and -1 < info.value.t < 0


def test_point_masses_and_no_check(em):
    mu = em.mu
    s = [1 - mu + 0.003, 0, 0, 0, 0.02, 0]  # inside the Moon's radius, but not at its centre
    with pytest.raises(librate.CollisionError):
        librate.propagate(em, s, 0.01)
    tr = librate.propagate(em, s, 0.01, collision="point")  # a point-mass Moon: no collision yet
    assert tr.status == "completed"
    with pytest.raises(librate.CollisionError, match="collision radius 1.000e-8"):
        librate.propagate(em, [1 - mu, 0, 0, 0, 0, 0], 1.0, collision="point")
    pm = librate.System(mu=mu, lu_km=em.lu_km, tu_s=em.tu_s, name="points")  # no radii: the tiny sphere
    with pytest.raises(librate.CollisionError, match="smaller primary"):
        librate.propagate(pm, [1 - mu, 0, 0, 0, 0, 0], 1.0)
    with pytest.raises(ValueError, match="invalid argument `collision`"):
        librate.propagate(em, s, 0.01, collision="surface")


def test_events_are_kept_apart_from_the_collision(em):
    mu = em.mu
    ev = librate.Event.crossing("y", 0.0)
    with pytest.raises(librate.CollisionError) as info:
        librate.propagate(em, [1 - mu + 0.02, 0.001, 0, 0, 0, 0], 1.0, events=[ev])
    assert all(h.index == 0 for h in info.value.trajectory.events)


def test_propagate_many_reports_collisions_per_row(em):
    mu = em.mu
    states = [[0.8, 0, 0, 0, 0.5, 0], [1 - mu, 0, 0, 0, 0, 0], [-mu + 0.03, 0, 0, 0, 0, 0]]
    b = librate.propagate_many(em, states, 1.0, on_error="mask")
    assert b.ok.tolist() == [True, False, False]
    assert b.status.tolist() == ["completed", "collision_primary2", "collision_primary1"]
    assert isinstance(b.errors[1], librate.CollisionError) and b.errors[1].primary == 2
    assert np.all(np.isnan(b.y[1:]))
    single = librate.propagate(em, states[0], 1.0)
    np.testing.assert_array_equal(b.y[0], single.y_final)
    with pytest.raises(librate.CollisionError):
        librate.propagate_many(em, states, 1.0)


def test_dro_near_the_moon_is_still_a_point_mass_orbit(em):
    """The DRO family starts inside the Moon's radius (x0 = 0.985): periodic orbits are
    propagated as point-mass solutions (collision="point") by their own methods. Issue 24 #8:
    correct_dro refuses it by default (see test_families), collision=None keeps it."""
    o = librate.correct_dro(em, 0.985, collision=None)
    assert o.propagate().status == "completed"
    assert np.all(np.isfinite(o.monodromy))
    with pytest.raises(librate.CollisionError):
        o.propagate(collision="radius")
