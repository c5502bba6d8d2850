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
    assert ("3 epoch(s), 2 converged" in lines[0] and lines[3].endswith("did not converge")
            and lines[-1].startswith("  epoch 1: ConvergenceError"))
