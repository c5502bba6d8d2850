"""`librate transition` and the [ephemeris] study section (issue 21 item 5): the study's bad input
named by key with its allowed range, the example study end to end through the command line, the
result self-describing and checksummed, resumed epoch by epoch, refused when its inputs changed.

References: each transition's continuity is checked by an independent re-propagation from every
node (librate.propagate_ephemeris, tolerance 1 m and 1e-8 km/s: issue 21's acceptance), and the
rotating-frame node states against Ephemeris.ephemeris_to_synodic of the ICRF node states (the
same map, exact to 1e-12 LU). The figures are checked panel by panel as in test_plotting_outputs."""

import json
import shutil
from pathlib import Path

import librate
import numpy as np
import pytest
from librate.app.results import verify_result
from librate.app.study import Study, StudyError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "transition.toml"
TOL_KM, TOL_KM_S = 1e-3, 1e-8


def _problems(eph: dict, orbits=None) -> list[str]:
    with pytest.raises(StudyError) as err:
        Study.from_dict({"orbits": orbits or {"kind": "dro", "x0": [0.8]}, "ephemeris": eph}, purpose="transition")
    return err.value.problems


@pytest.mark.parametrize("eph, key, allowed", [
    ({"epoch": "2019-06-01T00:00:00 TDB"}, "ephemeris.epoch = ",
     "epochs from 2020-01-01T00:00:00.000000 TDB to 2071-01-01T00:00:00.000000 TDB"),
    ({"epoch": ["2030-01-01T00:00:00 TDB", "2030-13-01T00:00:00 TDB"]}, "ephemeris.epoch[1] = ", "an ISO string with a time scale"),
    ({"epoch": "2030-01-01 noon"}, "ephemeris.epoch = ", "an ISO string with a time scale"),
    ({"epoch": {"start": "2031-01-01T00:00:00 TDB", "stop": "2030-01-01T00:00:00 TDB", "step_days": 1}}, "ephemeris.epoch.stop = ",
     "an epoch not before ephemeris.epoch.start"),
    ({"epoch": {"start": 9e8, "stop": 1.9e9, "step_days": 0.5}}, "ephemeris.epoch.step_days = ", "at most 10000 epochs"),
    ({"epoch": {"start": 9e8, "stop": 1.9e9, "step_days": 0}}, "ephemeris.epoch.step_days = ", "(0, 36525]"),
    ({"epoch": 9e8, "revolutions": 0}, "ephemeris.revolutions = 0", "an integer in [1, 100]"),
    ({"epoch": 9e8, "nodes_per_rev": 1}, "ephemeris.nodes_per_rev = 1", "an integer in [2, 100]"),
    ({"epoch": 9e8, "node_per_rev": 4}, "ephemeris.node_per_rev = 4: unknown key", "did you mean `ephemeris.nodes_per_rev`"),
    ({"epoch": True}, "ephemeris.epoch = true", "a table {start, stop, step_days}"),
    ({}, "ephemeris.epoch: missing", "an epoch"),
])
def test_bad_ephemeris_input_names_the_key_and_the_allowed_range(eph, key, allowed):
    problems = _problems(eph)
    assert len(problems) == 1 and problems[0].startswith(key) and allowed in problems[0], problems


def test_a_transition_needs_its_section_and_one_orbit():
    with pytest.raises(StudyError, match=r"missing section \[ephemeris\]"):
        Study.from_dict({"orbits": {"kind": "dro", "x0": [0.8]}}, purpose="transition")
    (p,) = _problems({"epoch": 9e8}, {"kind": "dro", "x0": [0.8, 0.7]})
    assert p.startswith("orbits.x0 = [0.8, 0.7]: selects 2 orbits") and "allowed: exactly one value" in p
    (p,) = _problems({"epoch": 9e8}, {"kind": "dro"})
    assert p.startswith("orbits.x0: missing: a transition carries one orbit")
    # the other commands do not need [ephemeris], and a study with it still solves
    raw = {"orbits": {"kind": "dro", "x0": [0.8]}, "body": {"kz": 0.8}, "rates": {"wz0": [0.0, 1.0]}, "ephemeris": {"epoch": 9e8}}
    assert Study.from_dict(raw, purpose="solve").ephemeris.revolutions == 10


def test_epochs_of_a_range_a_list_and_mixed_scales():
    """A range runs from start every step_days up to stop (included on a step); UTC is TDB less
    69.184 s in 2030 (37 s of leap seconds + 32.184 s TT - TAI, TDB - TT < 2 ms)."""
    e = Study.from_dict({"ephemeris": {"epoch": {"start": "2030-01-01T00:00:00 TDB", "stop": "2030-01-21T00:00:00 TDB",
                                                 "step_days": 10}}}).ephemeris
    t = e.epochs_tdb()
    assert t.size == 3 and np.allclose(np.diff(t), 10 * 86400.0, rtol=0, atol=1e-6)
    lst = Study.from_dict({"ephemeris": {"epoch": ["2030-01-01T00:00:00 UTC", float(t[0])]}}).ephemeris.epochs_tdb()
    assert abs(lst[0] - t[0] - 69.184) < 2e-3 and lst[1] == t[0]


def test_the_end_of_the_revolutions_must_be_in_the_file(tmp_path):
    from librate.app.jobs import run_transition

    st = Study.from_dict({"orbits": {"kind": "dro", "x0": [0.8]}, "ephemeris": {"epoch": "2070-12-20T00:00:00 TDB", "revolutions": 2}},
                         purpose="transition", base_dir=tmp_path)
    with pytest.raises(StudyError) as err:
        run_transition(st)
    (p,) = err.value.problems
    assert p.startswith('ephemeris.epoch = "2070-12-20T00:00:00 TDB": 2070-12-20T00:00:00.000000 TDB and its 2 revolutions (28.81 d) leave')
    assert "allowed: epochs from 2020-01-01T00:00:00.000000 TDB to 2070-12-03T" in p
    st = Study.from_dict({"orbits": {"kind": "dro", "x0": [0.8]}, "ephemeris": {"epoch": 9e8, "file": "nowhere.bsp"}}, purpose="transition",
                         base_dir=tmp_path)
    with pytest.raises(StudyError, match=r"ephemeris.file = \"nowhere.bsp\": no such file"):
        run_transition(st)


# --- the example study, end to end ------------------------------------------------------------
@pytest.fixture(scope="module")
def example(tmp_path_factory):
    """examples/transition.toml run through the command line (in a copy of examples/)."""
    from click.testing import CliRunner
    from librate.app.cli import main

    d = tmp_path_factory.mktemp("example")
    shutil.copy(EXAMPLE, d / "transition.toml")
    res = CliRunner().invoke(main, ["transition", str(d / "transition.toml")], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return d, res


def test_example_runs_and_every_epoch_is_continuous(example):
    d, res = example
    path = d / "librate-out" / "transition.zarr"
    ok, report = verify_result(path)
    assert ok, report
    ds = librate.open_result(path)
    eph = librate.Ephemeris()
    mu = float(ds.attrs["mu"])
    assert ds.sizes["epoch"] == 3 and (ds["status"].values == 0).all()
    for j in range(ds.sizes["epoch"]):
        t, x = ds["node_epochs_tdb"].values[j], ds["states_km"].values[j]
        assert t[0] == ds["epoch"].values[j]
        assert ds["defects_km"].values[j].max() < TOL_KM and ds["defects_km_s"].values[j].max() < TOL_KM_S
        for i in range(t.size - 1):  # independent re-propagation from every node
            end = librate.propagate_ephemeris(x[i], t[i], t[i + 1] - t[i], t_eval=[t[i + 1] - t[i]]).states_km[-1]
            assert np.linalg.norm(end[:3] - x[i + 1, :3]) < TOL_KM and np.linalg.norm(end[3:] - x[i + 1, 3:]) < TOL_KM_S, (j, i)
        syn = np.array([eph.ephemeris_to_synodic(x[i], t[i], mu) for i in range(t.size)])
        np.testing.assert_allclose(ds["synodic"].values[j], syn, rtol=0, atol=1e-12)
        assert 0 < ds["max_departure_km"].values[j] < 1e5 and (ds["perilune_km"].values[j] > 1737.4).all()
    # self-describing: the epochs, frames, constants and the file in the attributes
    a = ds.attrs
    assert json.loads(a["epochs_iso"]) == ["2030-01-01T00:00:00.000000 TDB", "2030-01-11T00:00:00.000000 TDB",
                                           "2030-01-21T00:00:00.000000 TDB"]
    assert a["gm_km3_s2"] == [398600.435507, 4902.800118, 132712440041.279419] and "Moon-centred ICRF" in a["frames"]
    assert a["ephemeris_file"].startswith("embedded DE440") and json.loads(a["study"])["ephemeris"]["revolutions"] == 4
    assert a["revolutions"] == 4 and a["librate_result"] == "transition"
    lines = res.output.splitlines()
    assert "3 epoch(s), 3 converged, 4 revolutions" in lines[0]
    assert [ln.split()[0] for ln in lines[2:5]] == ["2030-01-01T00:00:00", "2030-01-11T00:00:00", "2030-01-21T00:00:00"]
    assert {p.name for p in (d / "librate-out").glob("*.png")} == {"transition_rotating.png",
                                                                   "transition_defects.png", "transition_sweep.png"}


def test_the_same_run_reuses_a_changed_one_is_refused_by_key(example, tmp_path):
    from click.testing import CliRunner
    from librate.app.cli import main

    d, _ = example
    run = CliRunner()
    out = d / "librate-out" / "transition.zarr"
    before = librate.open_result(out)
    res = run.invoke(main, ["transition", str(d / "transition.toml"), "-q", "--set", "output.figures=[]"], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    again = librate.open_result(out)
    for v in before.data_vars:
        np.testing.assert_array_equal(again[v].values, before[v].values, err_msg=v)
    res = run.invoke(main, ["transition", str(d / "transition.toml"), "--set", "ephemeris.revolutions=3"], catch_exceptions=False)
    assert res.exit_code == 2 and "changed: ephemeris.revolutions: 4 -> 3" in res.output and "--force" in res.output


def test_plot_of_a_transition_without_attitude_says_nothing_of_the_attitude_figures(example, tmp_path):
    """The example has no ephemeris.attitude_n: `librate plot` redraws its three figures and
    mentions no attitude figure (not asked for, as a map without solutions leaves out its
    solutions figure); asked for by name, each attitude figure is skipped with its reason."""
    from click.testing import CliRunner
    from librate.app.cli import main
    from librate.results.kinds import TransitionResult

    d, _ = example
    path = tmp_path / "transition.zarr"
    shutil.copytree(d / "librate-out" / "transition.zarr", path)
    res = CliRunner().invoke(main, ["plot", str(path)], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    assert "skipped" not in res.output and "attitude" not in res.stderr, res.output
    assert {p.name for p in tmp_path.glob("*.png")} == {"transition_rotating.png", "transition_defects.png", "transition_sweep.png"}
    told: list[tuple[str, str]] = []
    assert TransitionResult.figures(librate.open_result(path), ["attitude", "pointing"], skip=lambda *a: told.append(a)) == []
    assert told == [("attitude", "the transition carries no attitude (ephemeris.attitude_n)"),
                    ("pointing", "the transition carries no attitude (ephemeris.attitude_n)")]


def test_a_killed_run_keeps_its_epochs_and_resumes_to_the_same_arrays(example, tmp_path, monkeypatch):
    """An interruption after the first epoch (its commit done): the store keeps that epoch, and
    the same call finishes the others, equal to the uninterrupted run bit for bit (the kill by
    SIGKILL is in test_store_faults' campaign)."""
    from librate.app import transition as tr
    from librate.app.jobs import run_transition
    from librate.results import verify_store

    d, _ = example
    ref = librate.open_result(d / "librate-out" / "transition.zarr")
    st = Study.from_toml(EXAMPLE, purpose="transition")
    real, calls = tr._transition_epoch, []

    def cut(*args):
        if calls:
            raise KeyboardInterrupt("test")
        calls.append(args)
        return real(*args)

    monkeypatch.setattr(tr, "_transition_epoch", cut)
    with pytest.raises(KeyboardInterrupt, match="1 finished epoch"):
        run_transition(st, tmp_path)
    rep = verify_store(tmp_path / "transition.zarr")
    assert rep.not_done == [1, 2] and not rep.damaged
    monkeypatch.setattr(tr, "_transition_epoch", real)
    ds, _ = run_transition(st, tmp_path)
    for v in ref.data_vars:
        np.testing.assert_array_equal(ds[v].values, ref[v].values, err_msg=v)


def test_netcdf_output_is_the_same_result(example, tmp_path):
    from librate.app.jobs import run_transition

    d, _ = example
    ref = librate.open_result(d / "librate-out" / "transition.zarr")
    st = Study.from_toml(EXAMPLE, purpose="transition", overrides={"output.format": "netcdf"})
    ds, path = run_transition(st, tmp_path)
    assert path.suffix == ".nc" and not (tmp_path / "transition.nc.parts").exists()
    assert verify_result(path)[0]
    for v in ("states_km", "defects_km", "perilune_km", "status"):
        np.testing.assert_array_equal(librate.open_result(path)[v].values, ref[v].values, err_msg=v)


def test_an_epoch_that_does_not_converge_is_kept_as_such_and_the_sweep_goes_on(tmp_path, monkeypatch):
    """The second of three epochs stopped after one Newton step (the transition's own
    ConvergenceError, as from a hard epoch): stored with status 1, NaN arrays and its reason;
    the others converge; the summary and the figures say so."""
    from librate.app.jobs import run_transition
    from librate.app.transition import transition_summary
    from librate.orbits import transition

    real = transition.to_ephemeris
    second = Study.from_toml(EXAMPLE, purpose="transition").ephemeris.epochs_tdb()[1]

    def hard(orbit, epoch, **kw):
        return real(orbit, epoch, **kw, max_iter=1) if epoch == second else real(orbit, epoch, **kw)

    monkeypatch.setattr(transition, "to_ephemeris", hard)
    st = Study.from_toml(EXAMPLE, purpose="transition", overrides={"ephemeris.revolutions": 2})
    ds, path = run_transition(st, tmp_path)
    assert ds["status"].values.tolist() == [0, 1, 0] and verify_result(path)[0]
    assert np.isnan(ds["states_km"].values[1]).all() and ds["iterations"].values[1] == -1
    assert np.isfinite(ds["states_km"].values[[0, 2]]).all()
    (why,) = json.loads(ds.attrs["failures"]).values()
    assert why.startswith("ConvergenceError: ephemeris transition of the dro") and "max iterations" in why
    lines = transition_summary(ds, 1.0)
    assert "3 epoch(s), 2 converged" in lines[0] and lines[3].endswith("did not converge") and lines[-1].startswith("  "
                                                                                                                    "epoch 1: "
                                                                                                                    "ConvergenceError")


# --- attitude in the transition (ephemeris.attitude_n) -----------------------------------------
# The 70,000 km DRO at one epoch over 2 revolutions, Kz = 0.8, the N = 0 solution of the planar
# scan (wz0 in [0, 2] 1/TU, 60 rates). References: the API itself (librate.attitude_to_ephemeris
# on the same orbit and solution, bit for bit: the application calls the same functions), and the
# continuity goal of issue 21 (1e-6 rad, 1e-6 relative in rate).
ATTITUDE_STUDY = {
    "title": "70,000 km DRO with its N = 0 attitude in the ephemeris model",
    "orbits": {"kind": "dro", "x0": [0.8057]}, "body": {"kz": 0.8}, "rates": {"wz0": {"start": 0.0, "stop": 2.0, "num": 60}},
    "ephemeris": {"epoch": "2030-01-01T00:00:00 TDB", "revolutions": 2, "attitude_n": [0]}, "output": {"folder": "out"},
}


def _toml(d: dict) -> str:
    def val(v):
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {val(x)}" for k, x in v.items()) + " }"
        return json.dumps(v)

    top = "".join(f"{k} = {val(v)}\n" for k, v in d.items() if not isinstance(v, dict))
    return top + "".join(f"[{k}]\n" + "".join(f"{kk} = {val(x)}\n" for kk, x in v.items()) for k, v in d.items() if isinstance(v, dict))


@pytest.fixture(scope="module")
def attitude_run(tmp_path_factory):
    """The attitude study run through the command line."""
    from click.testing import CliRunner
    from librate.app.cli import main

    d = tmp_path_factory.mktemp("attitude")
    (d / "study.toml").write_text(_toml(ATTITUDE_STUDY))
    res = CliRunner().invoke(main, ["transition", str(d / "study.toml")], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    return d, res


def test_the_store_holds_the_attitude_and_the_summary_reports_it(attitude_run):
    d, res = attitude_run
    path = d / "out" / "transition.zarr"
    assert verify_result(path)[0]
    ds = librate.open_result(path)
    assert ds.sizes["attitude"] == 1 and ds.sizes["attitude_sample"] == ds.sizes["leg"] * 8 + 1
    assert ds["attitude_q"].dims == ("epoch", "attitude", "node", "quaternion") and ds["attitude_w"].attrs["units"] == "rad/s"
    for v in ("attitude_pointing_deg", "attitude_angles_deg", "attitude_defect_rad", "attitude_t_tdb"):
        assert ds[v].attrs.get("long_name") and ds[v].attrs.get("units"), v
    assert ds["attitude_status"].values.tolist() == [[0]] and ds["attitude_n"].values.tolist() == [0]
    assert ds["attitude_defect_rad"].values.max() < 1e-6 and ds["attitude_defect_rate"].values.max() < 1e-6
    assert ds["attitude_t_tdb"].values[0, 0] == ds["epoch"].values[0] and json.loads(ds.attrs["attitude_failures"]) == {}
    # the N = 0 CR3BP solution stays planar (roll = pitch = 0) and its yaw is phi (phi0 = 0 at the first sample)
    cr = ds["attitude_cr3bp_angles_deg"].values[0, 0]
    assert np.abs(cr[:, :2]).max() < 1e-9 and abs(cr[0, 2]) < 1e-9 and np.ptp(cr[:, 2]) > 1.0
    err = float(ds["attitude_max_pointing_deg"].values[0, 0])
    line = next(ln for ln in res.output.splitlines() if ln.startswith("  N = 0"))
    assert f"largest pointing error {err:.3g} deg" in line and "corrected at 1/1 epochs" in line and "rad" in line
    assert {p.name for p in (d / "out").glob("transition_*.png")} >= {"transition_attitude.png", "transition_pointing.png"}


def test_the_attitude_equals_the_api_called_directly(attitude_run):
    """The stored numbers are librate.attitude_to_ephemeris's on the same orbit, epoch and
    solution (found by find_periodic_attitudes as librate solve finds it), bit for bit."""
    d, _ = attitude_run
    ds = librate.open_result(d / "out" / "transition.zarr")
    st = Study.from_dict(ATTITUDE_STUDY, purpose="transition")
    (orbit,) = list(st.build_orbits())
    sols = librate.find_periodic_attitudes(orbit, kz=0.8, wz0_range=(0.0, 2.0), n_grid=60, phi0=0.0, n_periods=1)
    sol = next(s for s in sols if s.kind == "periodic" and s.n == 0)
    assert ds["attitude_wz0"].values[0] == sol.wz0
    eo = librate.to_ephemeris(orbit, float(st.ephemeris.epochs_tdb()[0]), revolutions=2, ephemeris=librate.Ephemeris())
    a = librate.attitude_to_ephemeris(sol, eo, correct=True)
    np.testing.assert_array_equal(ds["attitude_q"].values[0, 0], a.q)
    np.testing.assert_array_equal(ds["attitude_w"].values[0, 0], a.w)
    np.testing.assert_array_equal(ds["attitude_pointing_deg"].values[0, 0], a.pointing_error_deg)
    np.testing.assert_array_equal(ds["attitude_defect_rad"].values[0, 0], a.defect_rad)
    np.testing.assert_array_equal(ds["attitude_t_tdb"].values[0], a.t_tdb)
    assert ds["attitude_max_pointing_deg"].values[0, 0] == a.max_pointing_error_deg and ds["attitude_growth"].values[0, 0] == a.growth
    cr, eph = a.angles_deg()
    np.testing.assert_array_equal(ds["attitude_angles_deg"].values[0, 0], eph)
    np.testing.assert_array_equal(ds["attitude_cr3bp_angles_deg"].values[0, 0], cr)


def test_the_attitude_figures_hold_data_and_plot_redraws_them(attitude_run):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from click.testing import CliRunner
    from librate.app.cli import main
    from librate.results.kinds import TransitionResult

    d, _ = attitude_run
    path = d / "out" / "transition.zarr"
    ds = librate.open_result(path)
    figs = dict(TransitionResult.figures(ds, ["attitude", "pointing"]))
    assert set(figs) == {"attitude", "pointing"}
    fig = figs["attitude"]()
    assert len(fig.axes) == 3
    for ax, j in zip(fig.axes, range(3)):
        ephem = next(ln for ln in ax.lines if ln.get_gid() == "ephemeris")
        np.testing.assert_array_equal(ephem.get_ydata(), ds["attitude_angles_deg"].values[0, 0, :, j])
    plt.close(fig)
    fig = figs["pointing"]()
    lines = [ln for ln in fig.axes[0].lines if (ln.get_gid() or "").startswith("pointing-")]
    assert len(lines) == 3 and all(np.isfinite(ln.get_ydata()).all() and len(ln.get_ydata()) == ds.sizes["attitude_sample"] for ln in lines)
    plt.close(fig)
    for p in (d / "out").glob("transition_*.png"):
        p.unlink()
    res = CliRunner().invoke(main, ["plot", str(path)], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    assert {p.name for p in (d / "out").glob("transition_*.png")} == {"transition_rotating.png", "transition_defects.png",
                                                                       "transition_attitude.png", "transition_pointing.png"}


def test_the_attitude_run_is_reused_and_a_changed_attitude_input_refused(attitude_run):
    from click.testing import CliRunner
    from librate.app.cli import main

    d, _ = attitude_run
    path = d / "out" / "transition.zarr"
    before = librate.open_result(path)
    run = CliRunner()
    res = run.invoke(main, ["transition", str(d / "study.toml"), "-q", "--set", "output.figures=[]"], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    again = librate.open_result(path)
    for v in before.data_vars:
        np.testing.assert_array_equal(again[v].values, before[v].values, err_msg=v)
    res = run.invoke(main, ["transition", str(d / "study.toml"), "--set", "ephemeris.attitude_n=[1]"], catch_exceptions=False)
    assert res.exit_code == 2 and "changed: ephemeris.attitude_n: [0] -> [1]" in res.output
    res = run.invoke(main, ["transition", str(d / "study.toml"), "--set", "body.kz=0.5"], catch_exceptions=False)
    assert res.exit_code == 2 and "changed: body.kz: 0.8 -> 0.5" in res.output


def test_the_attitude_inputs_count_only_with_attitude_n():
    """A transition without attitude_n depends on [system], [orbits], [ephemeris] only (a changed
    [body] leaves it valid, as before attitude_n existed); with it on the solution's sections too;
    and its store's fingerprint is the one it had before (old stores resume)."""
    from librate.app import transition as tr
    from librate.app.results import study_changes
    from librate.results.kinds import TransitionResult

    plain = {"ephemeris": {"epoch": 9e8}, "body": {"kz": 0.8}}
    assert TransitionResult.inputs_of(plain) == ("system", "orbits", "ephemeris")
    assert "body" in TransitionResult.inputs_of({"ephemeris": {"epoch": 9e8, "attitude_n": [0]}})
    assert study_changes(plain, {**plain, "body": {"kz": 0.5}}, TransitionResult.inputs_of(plain)) == []
    (orbit,) = list(Study.from_dict(ATTITUDE_STUDY).build_orbits())
    fp = tr._fingerprint(orbit, np.array([9e8]), 2, 9, "d")
    assert fp == tr._fingerprint(orbit, np.array([9e8]), 2, 9, "d", ()) and tr.transition_sizes(2, 9) == tr.transition_sizes(2, 9, 0)


@pytest.fixture
def one_revolution(tmp_path):
    """The attitude study over one revolution, its output under tmp_path (the runs that fail on purpose)."""
    return Study.from_dict({**ATTITUDE_STUDY, "ephemeris": {**ATTITUDE_STUDY["ephemeris"], "revolutions": 1}}, purpose="transition",
                           base_dir=tmp_path)


def test_a_failed_attitude_correction_keeps_the_orbit_and_says_why(one_revolution, monkeypatch):
    from librate import ConvergenceError
    from librate.app.jobs import run_transition
    from librate.app.transition import transition_summary
    from librate.periodicity import ephemeris_attitude

    def fails(*args, **kw):
        raise ConvergenceError("attitude_to_ephemeris: the multiple-shooting corrector stopped (test)")

    monkeypatch.setattr(ephemeris_attitude, "attitude_to_ephemeris", fails)
    ds, path = run_transition(one_revolution)
    assert verify_result(path)[0] and ds["status"].values.tolist() == [0] and np.isfinite(ds["states_km"].values).all()
    assert ds["attitude_status"].values.tolist() == [[1]] and np.isnan(ds["attitude_q"].values).all()
    assert json.loads(ds.attrs["attitude_failures"]) == {"0/0": "ConvergenceError: attitude_to_ephemeris: the multiple-shooting corrector "
                                                                "stopped (test)"}
    lines = transition_summary(ds, 1.0)
    assert "corrected at no epoch of 1" in lines[-2] and lines[-1].startswith("  epoch 0, N = 0: ConvergenceError")


@pytest.mark.parametrize("change, key, allowed", [
    ({"body": None}, "body: missing section [body]", "body.kz"),
    ({"rates": None}, "rates: missing section [rates]", "rates.wz0"),
    ({"torques": {"srp": {"eps": 0.1}}}, "torques.srp = ", "no [torques.srp] with ephemeris.attitude_n"),
    ({"body": {"kz": [0.5, 0.8]}}, "body.kz = [0.5, 0.8]", "one number in [-1, 1]"),
    ({"ephemeris": {"epoch": 9e8, "attitude_n": [0, 0]}}, "ephemeris.attitude_n = [0, 0]: an N is listed twice",
     "at most 8 distinct integers"),
    ({"ephemeris": {"epoch": 9e8, "attitude_n": []}}, "ephemeris.attitude_n = []", "at most 8 distinct integers"),
])
def test_bad_attitude_input_names_the_key_and_the_allowed_range(change, key, allowed):
    raw = {k: v for k, v in {**ATTITUDE_STUDY, **change}.items() if v is not None}
    with pytest.raises(StudyError) as err:
        Study.from_dict(raw, purpose="transition")
    hits = [p for p in err.value.problems if p.startswith(key)]
    assert len(hits) == 1 and allowed in hits[0], err.value.problems


@pytest.mark.parametrize("start", ["planar", "spin"])
def test_a_3d_transition_takes_its_n_from_attitude_n_and_a_solve_still_needs_attitude_n(start):
    """With ephemeris.attitude_n, a 3-D [attitude] needs no attitude.n (as the planar model needs
    none): the transition starts each 3-D motion with n = N. A solve of the same study starts
    from attitude.n, and its absence is named by key; without attitude_n it is required as before."""
    raw = {**ATTITUDE_STUDY, "body": {"ix": 100.0, "iy": 900.0, "iz": 1000.0}, "attitude": {"model": "3d", "start": start}}
    for purpose in (None, "transition"):
        assert Study.from_dict(raw, purpose=purpose).attitude.n is None
    plain = {k: v for k, v in raw.items() if k != "ephemeris"}
    for study, purpose in ((raw, "solve"), (plain, None), (plain, "solve")):
        with pytest.raises(StudyError) as err:
            Study.from_dict(study, purpose=purpose)
        hits = [p for p in err.value.problems if p.startswith("attitude.n: missing")]
        assert len(hits) == 1 and f'attitude.start = "{start}" needs the net turns n' in hits[0], err.value.problems


def test_an_n_without_a_solution_is_named(tmp_path):
    from librate.app.jobs import run_transition

    st = Study.from_dict({**ATTITUDE_STUDY, "ephemeris": {**ATTITUDE_STUDY["ephemeris"], "attitude_n": [0, 7]}}, purpose="transition",
                         base_dir=tmp_path)
    with pytest.raises(StudyError) as err:
        run_transition(st)
    (p,) = err.value.problems
    assert p.startswith("ephemeris.attitude_n = [0, 7]: no periodic solution with N = 7") and "found: N = -1 (half-turn)" in p
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_killed_attitude_run_resumes_to_the_same_arrays(tmp_path, monkeypatch):
    """Two epochs, interrupted after the first (its part, attitude included, committed): the
    same call finishes the second, and the arrays equal an uninterrupted run's bit for bit. The
    task's arguments (the solutions on the orbit) pickle, as a Dask task's must."""
    import pickle

    from librate.app import transition as tr
    from librate.app.jobs import run_transition

    raw = {**ATTITUDE_STUDY, "ephemeris": {**ATTITUDE_STUDY["ephemeris"], "revolutions": 1,
                                           "epoch": ["2030-01-01T00:00:00 TDB", "2030-01-11T00:00:00 TDB"]}}
    st = Study.from_dict(raw, purpose="transition", base_dir=tmp_path / "a")
    ref, _ = run_transition(st)
    real, calls = tr._transition_epoch, []

    def cut(*args):
        if calls:
            raise KeyboardInterrupt("test")
        calls.append(pickle.loads(pickle.dumps(args)))
        return real(*args)

    monkeypatch.setattr(tr, "_transition_epoch", cut)
    st = Study.from_dict(raw, purpose="transition", base_dir=tmp_path / "b")
    with pytest.raises(KeyboardInterrupt, match="1 finished epoch"):
        run_transition(st)
    monkeypatch.setattr(tr, "_transition_epoch", real)
    ds, _ = run_transition(st)
    assert ds["attitude_status"].values.tolist() == [[0], [0]]
    for v in ref.data_vars:
        np.testing.assert_array_equal(ds[v].values, ref[v].values, err_msg=v)


def test_a_3d_study_carries_the_3d_motion_and_agrees_with_the_planar_one(attitude_run, tmp_path):
    """[attitude] model = "3d" with the moments of Kz = 0.8 (100, 900, 1000 kg m^2) and the planar
    start: the 3-D motion corrected from the N = 0 planar solution (periodic_attitude_3d, as the
    3-D solve starts) is the planar motion (an in-plane solution of the 3-D model), so its
    ephemeris counterpart has the planar run's pointing error, to 1e-9 deg (the 3-D corrector's
    closure tolerance is 1e-12)."""
    from librate.app.jobs import run_transition

    d, _ = attitude_run
    planar = librate.open_result(d / "out" / "transition.zarr")
    # no attitude.n: each 3-D motion takes its n from ephemeris.attitude_n
    raw = {**ATTITUDE_STUDY, "body": {"ix": 100.0, "iy": 900.0, "iz": 1000.0}, "attitude": {"model": "3d", "start": "planar"}}
    ds, _ = run_transition(Study.from_dict(raw, purpose="transition", base_dir=tmp_path))
    assert ds.attrs["attitude_model"] == "3d" and ds.attrs["attitude_body_moments"] == [100.0, 900.0, 1000.0]
    assert ds["attitude_status"].values.tolist() == [[0]] and ds["attitude_q0"].dims == ("attitude", "quaternion")
    np.testing.assert_allclose(ds["attitude_w0"].values[0], [0.0, 0.0, planar["attitude_wz0"].values[0]], rtol=0, atol=1e-10)
    np.testing.assert_allclose(ds["attitude_pointing_deg"].values, planar["attitude_pointing_deg"].values, rtol=0, atol=1e-9)
    with pytest.raises(StudyError, match=r"ephemeris.attitude_n = \[0\]: with attitude.start = \"given\" the 3-D motion has no N"):
        Study.from_dict({**raw, "attitude": {"model": "3d", "start": "given", "w0": [0.0, 0.0, 1.0]}}, purpose="transition")


def test_an_epoch_whose_orbit_fails_marks_its_attitude_not_computed(one_revolution, monkeypatch):
    from librate.app.jobs import run_transition
    from librate.orbits import transition

    real = transition.to_ephemeris
    monkeypatch.setattr(transition, "to_ephemeris", lambda orbit, epoch, **kw: real(orbit, epoch, **kw, max_iter=1))
    ds, path = run_transition(one_revolution)
    assert verify_result(path)[0] and ds["status"].values.tolist() == [1] and ds["attitude_status"].values.tolist() == [[2]]
    assert np.isnan(ds["attitude_pointing_deg"].values).all() and json.loads(ds.attrs["attitude_failures"]) == {}
