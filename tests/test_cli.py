"""The `librate` command line end to end, in a temporary folder (click's CliRunner).

init -> map from the study on a tiny grid (3 DROs x 50 rates) -> plot from the saved file; the
map runner's interface (a fake `librate.app.runner.run_map` via monkeypatch, and the
`periodicity_map` fallback when the runner is absent); family, solve, invalid studies (exit 2,
nothing written), foreign output folders refused; demo, dros and info.

The command-line model (issue 14): every command writes <command>.zarr/.nc and
<command>_<figure>.png, so no command overwrites another's output; `plot` reads what any command
wrote; a result of other inputs is refused naming the changed keys (exit 2) unless --force, which
says what it replaces; every user mistake exits 2 with a one-line reason and no traceback.
"""

import json
import sys
import types

import librate
import numpy as np
import pytest

TINY = ["--set", "orbits.x0={start = 0.9, stop = 0.5, num = 3}", "--set", "rates.wz0.num=50"]



@pytest.fixture
def run(cli):
    """The command line in tmp_path (conftest's ``cli``)."""
    return cli


@pytest.fixture
def no_runner(monkeypatch):
    """Make `import librate.app.runner` fail: the periodicity_map fallback."""
    monkeypatch.setitem(sys.modules, "librate.app.runner", None)


@pytest.fixture
def fake_runner(monkeypatch):
    """A stand-in `librate.app.runner` with the agreed `run_map` signature, recording its calls."""
    calls = []
    mod = types.ModuleType("librate.app.runner")

    def run_map(orbits, *, kz, wz0, phi0=0.0, n_periods=1, srp=None, out=None, resume=True, scheduler=None, progress=None,
                solve=True, attrs=None):
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
    ([], ["librate init", "librate map", "librate plot", "1/TU", "librate dros", "librate info", "librate demo", "--force"]),
    (["init"], ["commented example", "Kz = 0.8", "1/TU"]),
    (["family"], ["continuation", "family.zarr", "Jacobi", "LU/TU", "--x0", "START:STOP:NUM"]),
    (["solve"], ["wz(T) = wz0", "phi(T) = phi0 + 2 pi N", "solve.zarr", "1/TU", "residual", "stable"]),
    (["map"], ["wz(T) - wz0 (1/TU)", "map.zarr", "resumable", "--scheduler", "--quiet", "map_contours.png",
               "map_residuals.png", "--force"]),
    (["plot"], ["without recomputing", "STEM_orbits.png", "STEM_contours.png", "STEM_residuals.png", "demo"]),
    (["info"], ["presets"]),
    (["transition"], ["[ephemeris]", "DE440", "multiple shooting", "transition.zarr", "Moon-centred ICRF", "--scheduler",
                      "transition_rotating.png"]),
])
def test_help_teaches(run, cmd, words):
    out = run(*cmd, "--help").output
    for w in words:
        assert w in out, (w, out)


def test_command_list_is_not_cut_mid_word(run):
    """`librate --help` lists every command with a whole one-line description (click cuts long
    first sentences with "..."; issue 14: `map` was cut at "(thesis Fig.")."""
    out = run("--help").output
    listing = out[out.index("Commands:"):].splitlines()[1:]
    names = [line.split()[0] for line in listing if line.strip()]
    assert names == ["demo", "dros", "family", "info", "init", "map", "plot", "solve", "transition", "verify"]
    for line in listing:
        if line.strip():
            assert line.rstrip().endswith(".") and not line.rstrip().endswith("...") and not line.rstrip().endswith("Fig."), line


# --- the main path --------------------------------------------------------------------------------
def test_init_map_plot_end_to_end(run, tmp_path, no_runner):
    res = run("init")
    assert "written: study.toml" in res.output
    assert "exists" in run("init", code=2).output  # never overwrites silently
    run("init", "--force")

    res = run("map", "study.toml", *TINY)
    out = tmp_path / "librate-out"
    assert "periodicity map: 3 orbits x 1 Kz x 50 rates = 150 attitude trajectories" in res.output
    # the size, before the run
    assert "map: 3 (orbits.x0) x 1 (body.kz) x 50 (rates.wz0) = 150 trajectories of 1 orbit period" in res.output
    assert "solutions (wz(T) = wz0" in res.output
    store = out / "map.zarr"
    ds = librate.open_result(store)
    assert ds.sizes["orbit"] == 3 and ds.sizes["wz0"] == 50 and ds.sizes["solution"] > 0
    study = json.loads(ds.attrs["study"])
    assert study["rates"]["wz0"] == {"start": -3.0, "stop": 2.0, "num": 50} and study["body"]["kz"] == 0.8
    assert ds.attrs["librate_version"] == librate.__version__ and ds.attrs["librate_result"] == "map"
    for png in ("map_contours.png", "map_residuals.png"):
        assert (out / png).stat().st_size > 10_000
        (out / png).unlink()

    res = run("plot", "librate-out/map.zarr")
    for png in ("map_contours.png", "map_residuals.png", "map_solutions.png"):
        assert (out / png).stat().st_size > 10_000, png
    # the figures come from the file: the same numbers as the run
    ref = librate.periodicity_map(librate.dro_family("earth-moon", x0=np.linspace(0.9, 0.5, 3)), kz=0.8, wz0=np.linspace(-3, 2, 50))
    assert np.array_equal(ref["dwz"].values, ds["dwz"].values, equal_nan=True)


def test_map_drives_the_runner_interface(run, tmp_path, fake_runner):
    run("init")
    run("map", "study.toml", "--quiet", "--out", "runs/a", "--force", *TINY)
    (call,) = fake_runner
    assert isinstance(call["orbits"], librate.OrbitFamily) and len(call["orbits"]) == 3
    assert call["kz"].tolist() == [0.8] and call["wz0"].tolist() == np.linspace(-3, 2, 50).tolist()
    assert (call["phi0"], call["n_periods"], call["srp"], call["solve"], call["resume"],
            call["scheduler"]) == (0.0, 1, None, True, True, None)
    assert call["out"] == str(tmp_path / "runs" / "a" / "map.zarr")
    assert call["progress"] is False  # --quiet: no bars
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
    # another study into the same folder is refused, naming the changed key, unless --force
    res = run("map", "study.toml", "--quiet", "--set", "body.kz=0.5", *TINY, code=2)
    assert "changed: body.kz: 0.8 -> 0.5" in res.stderr and "--force" in res.stderr and "resume=" not in res.stderr
    assert (store / ".zattrs").stat().st_mtime_ns == stamp
    res = run("map", "study.toml", "--quiet", "--force", "--set", "body.kz=0.5", *TINY)
    assert "--force: replacing" in res.stderr and "map.zarr" in res.stderr and "body.kz: 0.8 -> 0.5" in res.stderr
    again = librate.open_result(store)
    assert again["kz"].values.tolist() == [0.5] and not np.array_equal(again["dwz"].values, first, equal_nan=True)
    # a scheduler needs the runner
    res = run("map", "study.toml", "--scheduler", "tcp://127.0.0.1:8786", "--out", "sched", *TINY, code=1)
    assert "librate.app.runner" in res.output


def test_foreign_output_folder_is_refused(run, tmp_path, no_runner):
    run("init")
    foreign = tmp_path / "librate-out" / "map.zarr"
    foreign.mkdir(parents=True)
    (foreign / "thesis.tex").write_text("precious")
    res = run("map", "study.toml", *TINY, code=2)
    assert "not a librate result" in res.output and "refusing to overwrite" in res.output
    res = run("map", "study.toml", "--force", *TINY, code=2)  # --force replaces only librate results
    assert "refusing to overwrite" in res.output
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
    for png in ("family_orbits.png", "family_period.png", "family_stability.png"):
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
    ds = librate.open_result(tmp_path / "librate-out" / "solve.zarr")
    n = ds.sizes["solution"]
    assert f"{n} periodic solution(s) over 1 orbit(s) x 1 Kz" in res.output
    orbit = librate.dro_family("earth-moon", x0=[0.85])[0]  # as the study computes it
    direct = librate.find_periodic_attitudes(orbit, kz=0.8, wz0_range=(-3.0, 2.0), n_grid=50)
    assert n == len(direct) > 0
    assert ds["sol_wz0"].values.tolist() == [s.wz0 for s in direct]
    for s in direct:
        assert f"{s.wz0:>13.8f}" in res.output
    assert (tmp_path / "librate-out" / "solve_solutions.png").exists()
    (tmp_path / "librate-out" / "solve_solutions.png").unlink()
    run("plot", "librate-out/solve.zarr")
    assert (tmp_path / "librate-out" / "solve_solutions.png").exists()


def test_plot_a_family_and_refuse_non_results(run, tmp_path):
    fam = librate.dro_family("earth-moon", x0=[0.9, 0.8, 0.7])
    (tmp_path / "f").mkdir()
    fam.save(tmp_path / "f" / "dro.nc")  # a family saved by the Python API, no study attribute
    res = run("plot", "f/dro.nc")
    assert "dro family: 3 members" in res.output
    for png in ("dro_orbits.png", "dro_period.png", "dro_stability.png"):  # named after the file
        assert (tmp_path / "f" / png).exists()
    (tmp_path / "junk.nc").write_bytes(b"not netcdf")
    assert "cannot be read as a librate result" in run("plot", "junk.nc", code=2).output
    (tmp_path / "empty").mkdir()
    assert "no librate result" in run("plot", "empty", code=2).output


def test_demo_dros_and_info_still_work(run, tmp_path):
    res = run("demo", "--orbits", "3", "--rates", "50", "--out", "d")
    assert "periodicity map: 4 orbits x 50 rates" in res.output  # 3 and the 12.66-day DRO
    assert (tmp_path / "d" / "demo.nc").exists()
    assert "closure" in run("dros", "--x0", "0.9").output
    out = run("info").output
    assert f"librate {librate.__version__}" in out and "earth-moon-jpl" in out and "matplotlib" in out


def test_srp_study_solve_and_map(run, tmp_path, no_runner):
    (tmp_path / "srp.toml").write_text(
        '[orbits]\nsun_resonance = [2]\n[body]\nkz = 0.8\n[torques.srp]\neps = 0.02\ncs = 0.4\n'
        '[rates]\nwz0 = { start = -1.4, stop = -1.1, num = 40 }\n[output]\nfigures = []\n'
    )
    res = run("solve", "srp.toml")
    ds = librate.open_result(tmp_path / "librate-out" / "solve.zarr")
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
    """One progress style (tqdm on stderr) for every long step; silent when stderr is not a
    terminal or with --quiet."""
    from librate.app import progress

    monkeypatch.setattr(sys.stderr, "isatty", lambda: False, raising=False)
    assert progress.reporter("map", "orbit") is None and progress.bar(3, "figures", "figure").disable
    assert progress.reporter("map", "orbit", False) is None  # --quiet
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert progress.reporter("map", "orbit", False) is None  # --quiet, even in a terminal
    report = progress.reporter("periodicity map", "orbit")
    report(1, 4)
    report(4, 4)
    err = capsys.readouterr().err
    assert "periodicity map" in err and "4/4" in err and "100%" in err and "orbit/s" in err


# --- the command-line model (issue 14) -------------------------------------------------------------
@pytest.fixture
def blocker(tmp_path):
    """A plain file: an --out below it can never be created (also as root, unlike chmod)."""
    (tmp_path / "blocker").write_text("a file, not a folder")
    return "blocker/out"


@pytest.mark.parametrize("args", [
    ["dros", "--x0", "1.2"],                       # issue 14: a raw traceback before
    ["dros", "--x0", "-0.5"],
    ["demo", "--system", "foo"],                   # issue 14
    ["dros", "--system", "foo"],
    ["demo", "--out", "BLOCKER"],                  # issue 14: unwritable --out
    ["family", "--kind", "dro", "--x0", "0.9:0.8:3", "--out", "BLOCKER"],
    ["solve", "study.toml", "--out", "BLOCKER", *TINY],
    ["map", "study.toml", "--out", "BLOCKER", *TINY],
    ["init", "study.toml"],                        # exists
    ["plot", "study.toml"],                        # not a result
    ["verify", "study.toml"],
    ["map", "study.toml", "--no-resume"],          # the old flag: an unknown option, named
])
def test_user_mistakes_exit_2_with_one_line_and_no_traceback(run, blocker, args):
    run("init")
    res = run(*[blocker if a == "BLOCKER" else a for a in args], code=2)
    errors = [line for line in res.stderr.splitlines() if line.startswith("Error:")]
    assert len(errors) == 1 and len(errors[0]) > 20, res.stderr
    assert "Traceback" not in res.stderr and "invalid argument `" not in res.stderr  # CLI words, not the Python API's
    if "BLOCKER" in args:
        assert errors[0].startswith("Error: --out ") and f"{blocker}: cannot write there (Not a directory)" in errors[0]
    if args[:2] == ["dros", "--x0"]:
        assert errors[0].startswith(f"Error: --x0 {args[2]}: a DRO starts between the primaries")


def test_a_mistake_in_a_real_process_prints_no_traceback():
    """The same check outside CliRunner: the installed entry point, as a user runs it."""
    import subprocess

    res = subprocess.run([sys.executable, "-m", "librate", "dros", "--x0", "1.2"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr.strip().splitlines() == [res.stderr.strip()] and "--x0 1.2" in res.stderr


def test_commands_never_overwrite_each_other(run, tmp_path, no_runner):
    """demo, family, solve and map into one folder: every file is named after its command, and
    `plot` on each result re-draws only that result's figures (issue 14: `solve` and `map`
    both wrote solutions.png; `plot` could not read the demo's output)."""
    run("init")
    run("demo", "--orbits", "3", "--rates", "40", "--out", "librate-out")
    run("family", "study.toml", "--x0", "0.9,0.7")
    run("solve", "study.toml", *TINY, "--set", "orbits.x0=[0.85]")
    run("map", "study.toml", *TINY)
    out = tmp_path / "librate-out"
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(["demo.nc", "demo_contours.png", "demo_residuals.png", "demo_solutions.png", "demo_orbits.png",
                            "family.zarr", "family_orbits.png", "family_period.png", "family_stability.png",
                            "solve.zarr", "solve_solutions.png",
                            "map.zarr", "map_contours.png", "map_residuals.png", "map_solutions.png"]), names
    for stem, kind in (("demo.nc", "map"), ("family.zarr", "family"), ("solve.zarr", "solutions"), ("map.zarr", "map")):
        before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
        res = run("plot", f"librate-out/{stem}")
        redrawn = {p.name for p in out.iterdir() if p.stat().st_mtime_ns != before[p.name]}
        prefix = stem.split(".")[0] + "_"
        assert redrawn and all(n.startswith(prefix) and n.endswith(".png") for n in redrawn), (stem, redrawn)
        assert kind in res.output
    assert librate.app.results.read_attrs(out / "demo.nc")["librate_command"] == "demo"


def test_plot_reads_the_demo_folder_and_the_old_demo_file(run, tmp_path):
    run("demo", "--orbits", "3", "--rates", "40", "--out", "d")
    (tmp_path / "d" / "demo_contours.png").unlink()
    assert "map: " in run("plot", "d").output  # the folder: its one result, demo.nc
    assert (tmp_path / "d" / "demo_contours.png").exists()
    # a map saved by librate demo before 0.2 (no librate_result attribute)
    ds = librate.open_result(tmp_path / "d" / "demo.nc")
    for k in ("librate_result", "librate_command", "study", "librate_checksums"):
        ds.attrs.pop(k, None)
    (tmp_path / "old").mkdir()
    ds.to_netcdf(tmp_path / "old" / "dro_map_kz0.8.nc", engine="scipy")
    run("plot", "old")
    assert (tmp_path / "old" / "dro_map_kz0.8_contours.png").exists()


def test_a_changed_study_is_refused_by_key_and_force_says_what_it_replaces(run, tmp_path):
    """issue 14: `librate family` silently overwrote a DRO family.zarr with a halo family."""
    run("family", "--kind", "dro", "--x0", "0.9:0.8:3", "--out", "o")
    path = tmp_path / "o" / "family.zarr"
    stamp = path.stat().st_mtime_ns
    res = run("family", "--kind", "halo", "--point", "2", "--set", "orbits.max_members=10", "--out", "o", code=2)
    err = res.stderr
    assert 'orbits.kind: "dro" -> "halo"' in err and 'orbits.point: (unset) -> 2' in err and "--force" in err
    assert path.stat().st_mtime_ns == stamp and librate.open_result(path).kind == "dro"
    # the same inputs: reused, said so, nothing recomputed
    res = run("family", "--kind", "dro", "--x0", "0.9:0.8:3", "--out", "o")
    assert "reused" in res.stderr and path.stat().st_mtime_ns == stamp
    # a key this result does not depend on (the body, the output format) leaves it valid
    run("family", "--kind", "dro", "--x0", "0.9:0.8:3", "--out", "o", "--set", "body.kz=0.3")
    assert path.stat().st_mtime_ns == stamp
    res = run("family", "--kind", "halo", "--point", "2", "--set", "orbits.max_members=10", "--out", "o", "--force")
    assert "--force: replacing" in res.stderr and "family.zarr (a librate family: member 3" in res.stderr
    assert librate.open_result(path).kind == "halo-L2-south"


def test_a_map_resumes_after_an_output_only_change(run, tmp_path, no_runner):
    run("init")
    run("map", "study.toml", "--quiet", *TINY)
    store = tmp_path / "librate-out" / "map.zarr"
    stamp = (store / ".zattrs").stat().st_mtime_ns
    res = run("map", "study.toml", "--quiet", "--set", "output.figures=[]", *TINY)  # [output] does not change the map
    assert (store / ".zattrs").stat().st_mtime_ns == stamp and "Error" not in res.output


def test_demo_summary_says_what_it_omits(run, tmp_path):
    """issue 14: "solutions: 402" over a table of only |N| <= 3 (348 of them)."""
    res = run("demo", "--orbits", "4", "--rates", "50", "--out", "d")
    ds = librate.open_result(tmp_path / "d" / "demo.nc")
    total, n = ds.sizes["solution"], ds.sol_n.values
    listed = int((np.abs(n) <= 3).sum())
    assert total > listed  # this grid has solutions with |N| > 3 (4 orbits x 50 rates)
    assert f"{total}; listed below: |N| <= 3 ({listed}), {total - listed} with |N| > 3 omitted" in res.output
    rows = [line for line in res.output.splitlines() if line.split()[:1] and line.split()[0].lstrip("-").isdigit()]
    assert sum(int(line.split()[2]) for line in rows) == listed
    res = run("demo", "--orbits", "4", "--rates", "50", "--out", "d", "--kz", "0.5", code=2)
    assert "changed: --kz 0.8 -> 0.5" in res.stderr and "--force" in res.stderr


def test_demo_residuals_figure_is_on_the_12_66_day_dro(run, tmp_path, monkeypatch):
    """Issue 23: thesis Fig. 23 draws the residuals of the 12.66-day DRO (period within 0.01 d,
    the thesis's two decimals), which the demo's family holds beside its x0 grid; its residual
    dwz crosses zero there (the figure shows the crossings). The study records that member, so
    a demo map stored without it (librate before this) is refused naming the key."""
    import librate.plotting as lp

    drawn = []
    draw = lp.plot_residuals

    def spy(ds, *args, **kwargs):
        drawn.append(kwargs["orbit_index"])
        return draw(ds, *args, **kwargs)

    monkeypatch.setattr(lp, "plot_residuals", spy)
    run("demo", "--orbits", "3", "--rates", "50", "--out", "d")
    ds = librate.open_result(tmp_path / "d" / "demo.nc").load()
    period = ds["period_days"].values
    assert ds.sizes["orbit"] == 4 and len(drawn) == 1
    assert abs(period[drawn[0]] - 12.66) <= 0.01, period
    grid = np.delete(ds["x0"].values, drawn[0])
    np.testing.assert_allclose(grid, np.linspace(0.95, 0.15, 3), rtol=0, atol=1e-12)  # x0 held by the continuation
    dwz = ds["dwz"].values[drawn[0], 0]
    assert np.count_nonzero(np.diff(np.sign(dwz)) != 0) >= 2
    assert json.loads(ds.attrs["study"])["orbits"]["period_days"] == [12.66]

    old = json.loads(ds.attrs["study"])
    del old["orbits"]["period_days"]
    ds.attrs["study"] = json.dumps(old, sort_keys=True)
    ds.to_netcdf(tmp_path / "d" / "demo.nc")
    res = run("demo", "--orbits", "3", "--rates", "50", "--out", "d", code=2)
    assert "changed: orbits.period_days: (unset) -> [12.66]" in res.stderr and "--force" in res.stderr


def test_a_giant_map_is_refused_with_the_keys_and_exit_2(run, tmp_path):
    """Issue 24 #7: 1000 Kz x 1e6 rates is refused before anything is computed or written
    (exit 2, the keys and the limit named, --force offered), never a numpy MemoryError."""
    run("init")
    res = run("map", "study.toml", "--set", "body.kz={start = -1, stop = 1, num = 1000}", "--set", "rates.wz0.num=1000000", code=2)
    for text in ("orbits.x0 = 12 values", "body.kz = 1,000 values", "rates.wz0 = 1,000,000 values", "too large", "--force"):
        assert text in res.output, (text, res.output)
    assert "MemoryError" not in res.output and not (tmp_path / "librate-out").exists()
