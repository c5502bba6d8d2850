"""Regression tests of issue 12's input failures outside the periodicity package: Kz = +-1,
studies and DRO families that silently dropped requested orbits, and inputs that were accepted
then failed, read character by character, or reported with misleading errors."""

import librate
import numpy as np
import pytest
from librate.app.jobs import run_map

# --- Kz = +-1 (issue 12 #6: RigidBody.from_kz(1.0) built a zero moment and failed) ---------


@pytest.mark.parametrize("kz", [1.0, -1.0, 1, np.float64(-1.0)])
def test_from_kz_at_the_ends_of_the_range(kz):
    b = librate.RigidBody.from_kz(kz)
    assert b.kz == float(kz) and b.is_rod
    assert min(b.moments) == 0 and b.iz == 1


def test_kz_one_runs_the_planar_model_and_refuses_3d_clearly(em, dro_085):
    b = librate.RigidBody.from_kz(1.0)
    tr = librate.propagate_attitude(em, dro_085.state0, (0.0, 1.2), b, dro_085.period, planar=True)
    assert np.all(np.isfinite(tr.phi)) and np.all(np.isfinite(tr.wz))
    with pytest.raises(ValueError, match="invalid argument `body`: a body with a zero principal moment"):
        librate.propagate_attitude(em, dro_085.state0, ([0, 0, 0, 1], [0, 0, 1.2]), b, 1.0)


def test_thin_rod_and_invalid_moments():
    assert librate.RigidBody(0, 2, 2).kz == 1.0
    for args, name in (((0, 1, 2), "iz"), ((1, 1, 0), "iz"), ((-1, 1, 1), "ix"), ((1, 2, 4), "iz")):
        with pytest.raises(ValueError, match=f"invalid argument `{name}`"):
            librate.RigidBody(*args)


def test_study_map_at_kz_one(tmp_path):
    """The CLI/study path: a study with body.kz = 1 builds its body before any map work and
    runs (before: it failed only after the whole map)."""
    st = librate.Study.from_dict({"orbits": {"kind": "dro", "x0": [0.9, 0.85]}, "body": {"kz": 1.0},
                                  "rates": {"wz0": {"start": -1.0, "stop": 1.5, "num": 20}}}, purpose="map")
    assert st.build_body().kz == 1.0
    ds, path = run_map(st, tmp_path)
    assert int(ds.attrs["complete"]) == 1 and np.all(np.isfinite(ds.dwz.values))


# --- requested orbits silently dropped (issue 12 #7) ----------------------------------------


def test_dro_family_raises_with_the_missing_members(em):
    # Issue 24 #9: x0 = 0.5 is on the default family, so it is reached whatever the request's
    # order; x0 = 0.001 (past the DRO that grazes the Earth) is the one missing.
    with pytest.raises(librate.LibrateError, match=r"1 of the 3 requested members were not reached, x0 = \[0.001\]") as info:
        librate.dro_family(em, x0=[0.9, 0.001, 0.5])
    assert info.value.missing == [0.001] and info.value.found == [0.9, 0.5]
    fam = librate.dro_family(em, x0=[0.9, 0.001, 0.5], allow_partial=True)
    assert fam.x0.tolist() == [0.9, 0.5] and fam.parameters["missing_x0"] == [0.001]


def test_study_names_the_orbits_it_cannot_reach():
    """Before: `orbits.x0 = [0.9, 0.001, 0.5]` ran "1 orbits" and exited 0."""
    st = librate.Study.from_dict({"orbits": {"kind": "dro", "x0": [0.9, 0.001, 0.5]}, "body": {"kz": 0.8},
                                  "rates": {"wz0": {"start": -1.0, "stop": 1.5, "num": 20}}}, purpose="map")
    with pytest.raises(librate.StudyError, match=r"orbits.x0 = \[0.9, 0.001, 0.5\]: no DRO reached at x0 = 0.001 \("):
        st.build_orbits()


def test_cli_exits_with_the_study_error(tmp_path, monkeypatch):
    from click.testing import CliRunner
    from librate.app.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text('[orbits]\nkind = "dro"\nx0 = [0.9, 0.001, 0.5]\n[body]\nkz = 0.8\n[rates]\n'
                                     'wz0 = {start = -1.0, stop = 1.5, num = 20}\n')
    r = CliRunner().invoke(main, ["map", "s.toml", "-q"])
    assert r.exit_code != 0 and "orbits.x0" in r.output and "0.001, 0.5" in r.output, r.output


# --- bad types and misleading errors (issue 12, "Inconsistent or ignored input") -----------


def test_numpy_integers_are_counts(em):
    """Guard (already held in the orbits layer; the issue's np.int64 rejections are in the
    periodicity package, which is being rewritten): numpy integers are counts."""
    o = librate.correct_dro(em, 0.85, max_iter=np.int64(30))
    assert o.period > 0
    o2 = librate.correct_symmetric(em, [0.85, 0.0, o.state0[4]], max_iter=np.int32(30))
    assert abs(o2.period - o.period) < 1e-9
    b = librate.propagate_many(em, [o.state0], o.period, threads=np.int64(1), max_steps=np.int64(100000))
    assert b.ok.all()


def test_rigid_body_rejects_strings():
    """Before: RigidBody("1", "2", "2.5") was accepted, then failed later."""
    with pytest.raises(ValueError, match="invalid argument `ix`"):
        librate.RigidBody("1", "2", "2.5")
    with pytest.raises(ValueError, match="invalid argument `kz`"):
        librate.RigidBody.from_kz("0.5")


def test_torques_as_one_name(em, dro_085):
    """Before: torques="gravity_gradient" was read character by character ("unknown torque 'g'")."""
    b = librate.RigidBody.from_kz(0.8)
    one = librate.propagate_attitude(em, dro_085.state0, (0.0, 1.2), b, 1.0, planar=True, torques="gravity_gradient")
    two = librate.propagate_attitude(em, dro_085.state0, (0.0, 1.2), b, 1.0, planar=True, torques=["gravity_gradient"])
    np.testing.assert_array_equal(one.phi, two.phi)
    with pytest.raises(ValueError, match="unknown torque 'gravity'"):
        librate.propagate_attitude(em, dro_085.state0, (0.0, 1.2), b, 1.0, planar=True, torques="gravity")
    with pytest.raises(ValueError, match="invalid argument `torques`: unknown torque 3"):
        librate.propagate_attitude(em, dro_085.state0, (0.0, 1.2), b, 1.0, planar=True, torques=[3])


@pytest.mark.parametrize("threads", [-1, -(2**70), 0])
def test_negative_threads_is_a_value_error(em, threads):
    """Guard: negative counts are ValueErrors naming the parameter (propagate_many already
    checked `threads`; the issue's OverflowErrors come from the periodicity package)."""
    with pytest.raises(ValueError, match="invalid argument `threads`"):
        librate.propagate_many(em, [[0.8, 0, 0, 0, 0.5, 0]], 1.0, threads=threads)


@pytest.mark.parametrize("kw,name", [({"tol": 0.0}, "tol"), ({"tol": -1e-9}, "tol"), ({"max_iter": 0}, "max_iter"),
                                     ({"max_iter": -5}, "max_iter"),
                                     ({"tol": float("nan")}, "tol"), ({"max_iter": 2.5}, "max_iter"), ({"t_max": -1.0}, "t_max")])
def test_tol_and_max_iter_are_checked(em, kw, name):
    """Before: tol <= 0 or max_iter <= 0 gave "did not converge after -5 iterations"."""
    with pytest.raises(ValueError, match=f"invalid argument `{name}`"):
        librate.correct_symmetric(em, [0.85, 0.0, 0.5], **kw)
    if name != "t_max":
        with pytest.raises(ValueError, match=f"invalid argument `{name}`"):
            librate.correct_dro(em, 0.85, **kw)
        with pytest.raises(ValueError, match=f"invalid argument `{name}`"):
            librate.correct_periodic(em, [0.85, 0, 0, 0, 0.5, 0], 3.0, **kw)


@pytest.mark.parametrize("dc", [5.0, 10.0])
def test_an_unreachable_jacobi_target_fails_at_once(em, dc):
    """Issue 24: correct_periodic from the x0 = 0.3 DRO with its Jacobi constant raised by 5 or
    10 took 26 s and 139 s to end in a ConvergenceError (Newton drives the state toward the
    Earth, whose trajectories run to the step limit). The target exceeds 2U(r) at the guess's
    position (6.4547: C = 2U - |v|^2 is at most 2U there, an analytic bound), so no state of the
    member wanted is there: a ValueError names `jacobi` and the bound, in well under a second
    (tolerance: 1 s on a loaded machine). A reachable far target (+1) still converges."""
    import time

    dro = librate.correct_dro(em, 0.3)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"invalid argument `jacobi`: .* out of reach of the guess: .* above 2U\(r\) = 6\.4546563"):
        librate.correct_periodic(em, dro.state0, dro.period, jacobi=dro.jacobi + dc)
    assert time.perf_counter() - t0 < 1.0
    far = librate.correct_periodic(em, dro.state0, dro.period, jacobi=dro.jacobi + 1.0)
    assert far.jacobi == pytest.approx(dro.jacobi + 1.0, abs=1e-9)


def test_errors_name_the_users_parameters(em):
    """Guard: the user's parameter names, not the core's (already so for these two)."""
    with pytest.raises(ValueError, match="invalid argument `t_span`"):
        librate.propagate(em, [0.8, 0, 0, 0, 0.5, 0], float("nan"))
    with pytest.raises(ValueError, match="invalid argument `t_final`"):
        librate.propagate_many(em, [[0.8, 0, 0, 0, 0.5, 0]], [1.0, 2.0, 3.0])


def test_halo_z0_message_shows_the_accepted_range(em):
    """Before: the message showed only the initial states' z0 range, [0.002, 0.0756], while
    z0 = -0.1 (a half-period crossing) is accepted."""
    import re

    with pytest.raises(ValueError, match="invalid argument `z0`: 0.75 is outside") as info:
        librate.halo(em, 2, z0=0.75)
    spans = [(float(a), float(b)) for a, b in re.findall(r"\[([-\d.e]+), ([-\d.e]+)\]", str(info.value))]
    assert any(a <= -0.1 <= b for a, b in spans), str(info.value)
    assert abs(librate.halo(em, 2, z0=-0.1).state_half[2] if hasattr(librate.PeriodicOrbit, "state_half") else 0) >= 0


# --- silently ignored keywords (issue 12: srp_force or sun in planar runs, sun with a plain
# RigidBody, step options when fixed_step is given) -------------------------------------------


def test_ignored_attitude_keywords_are_refused(em, dro_085):
    b = librate.RigidBody.from_kz(0.8)
    args = (em, dro_085.state0, (0.0, 1.2), b, 1.0)
    with pytest.raises(ValueError, match="invalid argument `srp_force`: planar runs"):
        librate.propagate_attitude(*args, planar=True, srp_force=True)
    with pytest.raises(ValueError, match="invalid argument `sun`: planar runs take the Sun from the plate"):
        librate.propagate_attitude(*args, planar=True, sun=librate.Sun(0.3))
    with pytest.raises(ValueError, match="invalid argument `sun`: only a librate.FacetBody"):
        librate.propagate_attitude(em, dro_085.state0, ([0, 0, 0, 1], [0, 0, 1.2]), librate.RigidBody(1, 2, 2.5), 1.0, sun=librate.Sun(0.3))


@pytest.mark.parametrize("kw", [{"h0": 1e-3}, {"h_min": 1e-9}, {"h_max": 0.1}, {"safety": 0.5}])
def test_step_options_with_fixed_step_are_refused(em, dro_085, kw):
    name = next(iter(kw))
    with pytest.raises(ValueError, match=f"invalid argument `{name}`: adaptive step options do not apply with fixed_step"):
        librate.propagate(em, dro_085.state0, 1.0, fixed_step=0.01, **kw)
    with pytest.raises(ValueError, match=f"invalid argument `{name}`"):
        librate.propagate_attitude(em, dro_085.state0, (0.0, 1.2), librate.RigidBody.from_kz(0.8), 1.0, planar=True, fixed_step=0.01, **kw)
