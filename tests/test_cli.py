"""The `librate` command line end to end, in a temporary folder (click's CliRunner).

init -> map from the study on a tiny grid (3 DROs x 50 rates) -> plot from the saved file; the
map runner's interface (a fake `librate.app.runner.run_map` via monkeypatch, and the
`periodicity_map` fallback when the runner is absent); family, solve, invalid studies (exit 2,
nothing written), foreign output folders refused; demo, dros and info unchanged.
"""

import json
import sys
import types

import librate
import numpy as np
import pytest
from click.testing import CliRunner
from librate.app.cli import main

TINY = ["--set", "orbits.x0={start = 0.9, stop = 0.5, num = 3}", "--set", "rates.wz0.num=50"]


@pytest.fixture
def run(tmp_path, monkeypatch):
    """Invoke the CLI in tmp_path; returns the click Result (stdout and stderr separate)."""
    monkeypatch.chdir(tmp_path)
    runner = CliRunner()

    def invoke(*args, code=0):
        res = runner.invoke(main, [str(a) for a in args], catch_exceptions=False)
        assert res.exit_code == code, res.output
        return res

    return invoke


@pytest.fixture
def no_runner(monkeypatch):
    """Make `import librate.app.runner` fail: the periodicity_map fallback."""
    monkeypatch.setitem(sys.modules, "librate.app.runner", None)


@pytest.fixture
def fake_runner(monkeypatch):
    """A stand-in `librate.app.runner` with the agreed `run_map` signature, recording its calls."""
    calls = []
    mod = types.ModuleType("librate.app.runner")

    def run_map(orbits, *, kz, wz0, phi0=0.0, n_periods=1, srp=None, out=None, resume=True, scheduler=None, progress=None, solve=True, attrs=None):
        calls.append(dict(orbits=orbits, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, out=out, resume=resume,
                          scheduler=scheduler, progress=progress, solve=solve, attrs=attrs))
        ds = librate.periodicity_map(orbits, kz=kz, wz0=wz0, phi0=phi0, n_periods=n_periods, srp=srp, solve=solve)
        ds.attrs.update(attrs or {})
        ds.to_zarr(out, mode="w", zarr_format=2, consolidated=True)
        return ds

    mod.run_map = run_map
    monkeypatch.setitem(sys.modules, "librate.app.runner", mod)
    return calls


# --- help ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("cmd, words", [
    ([], ["librate init", "librate map", "librate plot", "1/TU"]),
    (["init"], ["commented example", "Kz = 0.8", "1/TU"]),
    (["family"], ["continuation", "family.zarr", "Jacobi", "LU/TU", "--x0", "START:STOP:NUM"]),
    (["solve"], ["wz(T) = wz0", "phi(T) = phi0 + 2 pi N", "solutions.zarr", "1/TU", "residual", "stable"]),
    (["map"], ["wz(T) - wz0 (1/TU)", "map.zarr", "resumable", "--scheduler", "--quiet", "map.png", "residuals.png"]),
    (["plot"], ["without recomputing", "family.png", "map.png", "residuals.png"]),
    (["info"], ["presets"]),
])
def test_help_teaches(run, cmd, words):
    out = run(*cmd, "--help").output
    for w in words:
        assert w in out, (w, out)


# --- the main path --------------------------------------------------------------------------------
def test_init_map_plot_end_to_end(run, tmp_path, no_runner):
    res = run("init")
    assert "written: study.toml" in res.output
    assert "exists" in run("init", code=1).output  # never overwrites silently
    run("init", "--force")

    res = run("map", "study.toml", *TINY)
    out = tmp_path / "librate-out"
    assert "periodicity map: 3 orbits x 1 Kz x 50 rates = 150 attitude trajectories" in res.output
    assert "solutions (wz(T) = wz0" in res.output
    store = out / "map.zarr"
    ds = librate.open_result(store)
    assert ds.sizes["orbit"] == 3 and ds.sizes["wz0"] == 50 and ds.sizes["solution"] > 0
    study = json.loads(ds.attrs["study"])
    assert study["rates"]["wz0"] == {"start": -3.0, "stop": 2.0, "num": 50} and study["body"]["kz"] == 0.8
    assert ds.attrs["librate_version"] == librate.__version__ and ds.attrs["librate_result"] == "map"
    for png in ("map.png", "residuals.png"):
        assert (out / png).stat().st_size > 10_000
        (out / png).unlink()

    res = run("plot", "librate-out/map.zarr")
    for png in ("map.png", "residuals.png", "solutions.png"):
        assert (out / png).stat().st_size > 10_000, png
    # the figures come from the file: the same numbers as the run
    ref = librate.periodicity_map(librate.dro_family("earth-moon", x0=np.linspace(0.9, 0.5, 3)), kz=0.8, wz0=np.linspace(-3, 2, 50))
    assert np.array_equal(ref["dwz"].values, ds["dwz"].values, equal_nan=True)


def test_map_drives_the_runner_interface(run, tmp_path, fake_runner):
    run("init")
    run("map", "study.toml", "--quiet", "--out", "runs/a", "--no-resume", *TINY)
    (call,) = fake_runner
    assert isinstance(call["orbits"], librate.OrbitFamily) and len(call["orbits"]) == 3
    assert call["kz"].tolist() == [0.8] and call["wz0"].tolist() == np.linspace(-3, 2, 50).tolist()
    assert (call["phi0"], call["n_periods"], call["srp"], call["solve"], call["resume"], call["scheduler"]) == (0.0, 1, None, True, False, None)
    assert call["out"] == str(tmp_path / "runs" / "a" / "map.zarr")
    assert call["progress"] is None  # --quiet (and not a terminal)
    study = json.loads(call["attrs"]["study"])
    assert study["orbits"]["x0"] == {"start": 0.9, "stop": 0.5, "num": 3}
    assert call["attrs"]["librate_version"] == librate.__version__
    run("map", "study.toml", "--quiet", "--scheduler", "tcp://127.0.0.1:8786", *TINY)
    assert fake_runner[1]["scheduler"] == "tcp://127.0.0.1:8786" and fake_runner[1]["resume"] is True


def test_fallback_without_the_runner(run, tmp_path, no_runner):
    run("init")
    run("map", "study.toml", "--quiet", *TINY)
    store = tmp_path / "librate-out" / "map.zarr"
    first = librate.open_result(store)["dwz"].values.copy()
    stamp = (store / ".zattrs").stat().st_mtime_ns
    # the same study again: the complete map is reused, not recomputed
    run("map", "study.toml", "--quiet", *TINY)
    assert (store / ".zattrs").stat().st_mtime_ns == stamp
    # another study into the same folder is refused, unless --no-resume
    res = run("map", "study.toml", "--quiet", "--set", "body.kz=0.5", *TINY, code=1)
    assert "different study" in res.output
    run("map", "study.toml", "--quiet", "--no-resume", "--set", "body.kz=0.5", *TINY)
    again = librate.open_result(store)
    assert again["kz"].values.tolist() == [0.5] and not np.array_equal(again["dwz"].values, first, equal_nan=True)
    # a scheduler needs the runner
    res = run("map", "study.toml", "--scheduler", "tcp://127.0.0.1:8786", *TINY, code=1)
    assert "librate.app.runner" in res.output


def test_foreign_output_folder_is_refused(run, tmp_path, no_runner):
    run("init")
    foreign = tmp_path / "librate-out" / "map.zarr"
    foreign.mkdir(parents=True)
    (foreign / "thesis.tex").write_text("precious")
    res = run("map", "study.toml", *TINY, code=1)
    assert "not a librate map" in res.output and "refusing to overwrite" in res.output
    assert (foreign / "thesis.tex").read_text() == "precious"
    assert sorted(p.name for p in foreign.iterdir()) == ["thesis.tex"]


def test_invalid_study_exits_2_lists_every_problem_and_writes_nothing(run, tmp_path):
    (tmp_path / "bad.toml").write_text(
        '[orbits]\nkind = "dro"\nx0 = [0.9, 1.5]\n[body]\nkz = 1.5\nkzz = 0.2\n[rates]\nwz0 = { start = 2.0, stop = -3.0, num = 50 }\n'
        '[solver]\nrtol = "tight"\n[output]\nfolder = "out"\n'
    )
    for cmd in ("map", "solve"):
        res = run(cmd, "bad.toml", code=2)
        err = res.stderr
        assert "invalid study bad.toml: 5 problems" in err
        for line in ('body.kz = 1.5: input should be less than or equal to 1; allowed: a number in [-1, 1]',
                     "body.kzz = 0.2: unknown key; allowed keys in [body]:",
                     'solver.rtol = "tight": input should be a valid number; allowed: a number in [1e-15, 1e-3]',
                     "rates.wz0.stop = -3.0: must be greater than rates.wz0.start = 2.0",
                     "orbits.x0 = [0.9, 1.5]: DROs start between the primaries"):
            assert line in err, (line, err)
    res = run("map", "bad.toml", "--set", "body.kz=0.5", "--set", "rates.wz0.stop=3", code=2)
    assert "3 problems" in res.stderr
    assert not (tmp_path / "out").exists()  # nothing half-written
    res = run("map", "nope.toml", code=2)
    assert "does not exist" in res.output
    res = run("map", "bad.toml", "--set", "novalue", code=2)
    assert "KEY=VALUE" in res.output
    (tmp_path / "syntax.toml").write_text("[body\nkz = 0.8\n")
    assert "not valid TOML" in run("family", "syntax.toml", code=2).stderr


def test_family_from_options_and_from_a_study(run, tmp_path):
    res = run("family", "--kind", "dro", "--x0", "0.9:0.8:3", "--out", "fam")
    assert "dro family: 3 members, x0 0.9 -> 0.8 LU" in res.output
    fam = librate.open_result(tmp_path / "fam" / "family.zarr")
    assert isinstance(fam, librate.OrbitFamily) and fam.x0.tolist() == pytest.approx([0.9, 0.85, 0.8], abs=1e-15)
    for png in ("family.png", "period.png", "stability.png"):
        assert (tmp_path / "fam" / png).exists()
    run("init")
    res = run("family", "study.toml", "--x0", "0.9,0.7", "--format", "netcdf", "--quiet")
    path = tmp_path / "librate-out" / "family.nc"
    assert f"written: {path}" in res.output and "dro family" not in res.output
    back = librate.open_result(path)
    assert back.x0.tolist() == pytest.approx([0.9, 0.7], abs=1e-15)
    attrs = librate.app.results.read_attrs(path)
    assert json.loads(attrs["study"])["orbits"]["x0"] == [0.9, 0.7]
    # a halo family by options (a spatial family: fine for `family`, refused by `map`)
    res = run("family", "--kind", "halo", "--point", "2", "--branch", "north", "--set", "orbits.max_members=30", "--out", "halo")
    assert "halo-L2-north family: 30 members" in res.output
    # options are validated like the study
    res = run("family", "--kind", "nrho", "--x0", "0.9:0.8", code=2)
    assert 'orbits.kind = "nrho"' in res.stderr and 'orbits.x0 = "0.9:0.8"' in res.stderr


def test_solve_prints_and_saves_the_table(run, tmp_path):
    run("init")
    res = run("solve", "study.toml", *TINY, "--set", "orbits.x0=[0.85]")
    ds = librate.open_result(tmp_path / "librate-out" / "solutions.zarr")
    n = ds.sizes["solution"]
    assert f"{n} periodic solution(s) over 1 orbit(s) x 1 Kz" in res.output
    orbit = librate.dro_family("earth-moon", x0=[0.85])[0]  # as the study computes it
    direct = librate.find_periodic_attitudes(orbit, kz=0.8, wz0_range=(-3.0, 2.0), n_grid=50)
    assert n == len(direct) > 0
    assert ds["sol_wz0"].values.tolist() == [s.wz0 for s in direct]
    for s in direct:
        assert f"{s.wz0:>13.8f}" in res.output
    assert (tmp_path / "librate-out" / "solutions.png").exists()
    (tmp_path / "librate-out" / "solutions.png").unlink()
    run("plot", "librate-out/solutions.zarr")
    assert (tmp_path / "librate-out" / "solutions.png").exists()


def test_plot_a_family_and_refuse_non_results(run, tmp_path):
    fam = librate.dro_family("earth-moon", x0=[0.9, 0.8, 0.7])
    (tmp_path / "f").mkdir()
    fam.save(tmp_path / "f" / "dro.nc")  # a family saved by the Python API, no study attribute
    res = run("plot", "f/dro.nc")
    assert "dro family: 3 members" in res.output
    for png in ("family.png", "period.png", "stability.png"):
        assert (tmp_path / "f" / png).exists()
    (tmp_path / "junk.nc").write_bytes(b"not netcdf")
    assert "cannot be read as a librate result" in run("plot", "junk.nc", code=1).output
    (tmp_path / "empty").mkdir()
    assert "no librate result" in run("plot", "empty", code=1).output


def test_demo_dros_and_info_still_work(run, tmp_path):
    res = run("demo", "--orbits", "3", "--rates", "50", "--out", "d")
    assert "periodicity map: 3 orbits x 50 rates" in res.output
    assert (tmp_path / "d" / "dro_map_kz0.8.nc").exists()
    assert "closure" in run("dros", "--x0", "0.9").output
    out = run("info").output
    assert f"librate {librate.__version__}" in out and "earth-moon-jpl" in out and "matplotlib" in out


def test_srp_study_solve_and_map(run, tmp_path, no_runner):
    (tmp_path / "srp.toml").write_text(
        '[orbits]\nsun_resonance = [2]\n[body]\nkz = 0.8\n[torques.srp]\neps = 0.02\ncs = 0.4\n'
        '[rates]\nwz0 = { start = -1.4, stop = -1.1, num = 40 }\n[output]\nfigures = []\n'
    )
    res = run("solve", "srp.toml")
    ds = librate.open_result(tmp_path / "librate-out" / "solutions.zarr")
    assert ds.sizes["solution"] >= 1 and set(ds["sol_n_periods"].values.tolist()) == {2}
    # the gravity-gradient N = -2 motion continued to eps = 0.02 (examples/03) is among them
    orbit = librate.dro_family("earth-moon").resonant(2, "sun")
    ref = librate.continue_srp(librate.periodic_attitude(orbit, kz=0.8, n=-1, n_periods=2), librate.FlatPlate(0.02, cs=0.4)).solutions[-1]
    assert np.min(np.abs(ds["sol_wz0"].values - ref.wz0)) < 1e-9
    assert f"{ref.wz0:>13.8f}" in res.output
    run("map", "srp.toml", "--quiet")
    mp = librate.open_result(tmp_path / "librate-out" / "map.zarr")
    assert (mp.attrs["srp_eps"], mp.attrs["srp_cs"], mp.attrs["n_periods"]) == (0.02, 0.4, 2)
    assert not list((tmp_path / "librate-out").glob("*.png"))  # output.figures = []


def test_progress_only_in_a_terminal(monkeypatch, capsys):
    from librate.app import cli

    monkeypatch.setattr(sys.stderr, "isatty", lambda: False, raising=False)
    assert cli._progress(False) is None
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert cli._progress(True) is None  # --quiet
    report = cli._progress(False)
    report(1, 4)
    report(4, 4)
    err = capsys.readouterr().err
    assert "1/4 ( 25%)" in err and "4/4 (100%)" in err and "ETA" in err and "/s" in err
