"""Every figure that the demo, the examples and the command line write (issue 23): rendered with
Agg and each panel checked to hold data, so a figure cannot go out empty or half drawn.

`librate.plotting.save_figure` is wrapped to keep every Figure it writes. A panel (an Axes that is
not a colour bar) holds data when one of its artists in data coordinates has finite values: a line
with at least two finite points (reference lines such as axhline, drawn in axes coordinates, do not
count), a scatter with a point, a mesh or image with a finite cell, a contour with a segment. The
figures written are exactly the PNG files the run leaves, each checked non-trivial (> 10 kB, not
one colour). The 3-D map figure (`librate map` on a 3-D study) is checked against the map it draws:
its red star sits on the grid point of the smallest residual. Reduced grids keep the runs short;
the examples run as written.
"""

import runpy
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import librate  # noqa: E402
import librate.plotting as lp  # noqa: E402
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import Collection, QuadMesh  # noqa: E402
from matplotlib.image import AxesImage  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _finite_points(line: Line2D) -> int:
    data = line.get_data_3d() if hasattr(line, "get_data_3d") else line.get_data()
    pts = np.column_stack([np.asarray(d, dtype=float).ravel() for d in data])
    return int(np.all(np.isfinite(pts), axis=1).sum())


def holds_data(ax) -> bool:
    """Whether the panel shows data (see the module docstring)."""
    for art in ax.get_children():
        if isinstance(art, Line2D) and art.get_transform().contains_branch(ax.transData) and _finite_points(art) >= 2:
            return True
        if isinstance(art, QuadMesh | AxesImage):
            if np.isfinite(np.ma.filled(np.asarray(art.get_array(), dtype=float), np.nan)).any():
                return True
        elif isinstance(art, Collection):
            offsets = np.asarray(art.get_offsets())
            if offsets.size and np.isfinite(offsets).all(axis=-1).any() and type(art).__name__ == "PathCollection":
                return True
            if any(len(p.vertices) >= 2 for p in art.get_paths()) and type(art).__name__ in ("LineCollection", "Line3DCollection"):
                return True
        if type(art).__name__ in ("ContourSet", "QuadContourSet") and any(len(p.vertices) >= 2 for p in art.get_paths()):
            return True
    return False


@pytest.fixture
def written(monkeypatch):
    """{file name: Figure} of every figure save_figure writes during the test."""
    figures: dict[str, object] = {}
    save = lp.save_figure

    def keep(fig, path, **kwargs):
        figures[Path(path).name] = fig
        kwargs.pop("close", None)  # kept open until checked; closed at the end of the test
        return save(fig, path, **kwargs)

    monkeypatch.setattr(lp, "save_figure", keep)
    yield figures
    plt.close("all")


def check_figures(figures: dict, folder: Path, expected: set[str]) -> None:
    pngs = {p.name for p in folder.rglob("*.png")}
    assert set(figures) == pngs == expected, (sorted(figures), sorted(pngs))
    for name, fig in figures.items():
        panels = [a for a in fig.axes if a.get_label() != "<colorbar>" and a.get_visible()]
        assert panels, name
        empty = [i for i, a in enumerate(panels) if not holds_data(a)]
        assert not empty, f"{name}: panels {empty} of {len(panels)} hold no data"
        path = next(folder.rglob(name))
        img = mpimg.imread(path)
        assert path.stat().st_size > 10_000 and float(img[..., :3].std()) > 0.02, name


def test_holds_data_tells_an_empty_panel():
    """The check itself: an Axes with only a reference line and a legend holds no data; one
    finite point is not a line; a line of two finite points is data."""
    fig, (a, b, c) = plt.subplots(1, 3)
    a.axhline(1.0)
    a.axvline(0.5)
    b.plot([1.0, np.nan], [2.0, np.nan])
    c.plot([0.0, 1.0], [0.0, 1.0])
    assert [holds_data(x) for x in (a, b, c)] == [False, False, True]
    plt.close(fig)


@pytest.mark.slow
def test_demo_figures(cli, tmp_path, written):
    """`librate demo`: the map (Fig. 24), the residuals on the 12.66-day DRO (Fig. 23), the N = 1,
    0, -1 families (Figs. 27-29) and the orbits."""
    cli("demo", "--out", tmp_path / "demo")
    check_figures(written, tmp_path / "demo", {"demo_contours.png", "demo_residuals.png", "demo_solutions.png", "demo_orbits.png"})
    assert "orbit T = 12.66 d" in written["demo_residuals.png"].axes[0].get_title()  # the title's period, to 0.01 d


@pytest.mark.slow
def test_cli_figures_family_solve_map(cli, tmp_path, written):
    """`librate family`, `solve` and `map` on the commented example study (`librate init`), with
    6 DROs and 120 rates."""
    cli("init", "study.toml")
    study = tmp_path / "study.toml"
    text = study.read_text().replace("num = 12 }", "num = 6 }").replace("num = 300 }", "num = 120 }")
    study.write_text(text)
    for command in ("family", "solve", "map"):
        cli(command, study)
    check_figures(written, tmp_path / "librate-out", {
        "family_orbits.png", "family_period.png", "family_stability.png", "solve_solutions.png",
        "map_contours.png", "map_residuals.png", "map_solutions.png",
    })


@pytest.mark.slow
def test_cli_figures_3d(cli, tmp_path, written):
    """`librate solve` and `librate map` on 3-D studies (examples/study_3d_dro.toml; the map
    with 2 DROs, wx0 over 11 and wz0 over 24 rates, wy0 = 0): the multipliers and body axes of
    the 3-D family, and the 3-D map's residual figure, whose red star marks the grid point of
    the smallest residual max-norm of its orbit."""
    cli("solve", EXAMPLES / "study_3d_dro.toml", "--out", tmp_path / "out")
    study = tmp_path / "m.toml"
    text = (EXAMPLES / "study_3d_dro.toml").read_text().replace("# wx0 = {", "wx0 = {").replace("# wy0 = 0.0", "wy0 = 0.0")
    text = text.replace("x0 = [0.85, 0.83, 0.8]", "x0 = [0.85, 0.83]").replace("num = 101", "num = 11").replace("num = 300", "num = 24")
    study.write_text(text)
    cli("map", study, "--out", tmp_path / "out")
    check_figures(written, tmp_path / "out", {"solve_multipliers.png", "solve_body_axes.png", "map_residual_norm.png"})
    ds = librate.open_result(tmp_path / "out" / "map.zarr")
    fig = written["map_residual_norm.png"]
    panels = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    assert len(panels) == ds.sizes["orbit"] == 2
    for i, a in enumerate(panels):
        r = ds["residual_norm"].isel(orbit=i).transpose("wz0", "wx0").values
        iy, ix = np.unravel_index(np.nanargmin(r), r.shape)
        (star,) = [ln for ln in a.get_lines() if ln.get_gid() == "minimum"]
        assert (star.get_xdata()[0], star.get_ydata()[0]) == (ds["wx0"].values[ix], ds["wz0"].values[iy])
        assert f"{float(np.nanmin(r)):.2e}" in a.get_title()
    assert "wy0 = 0 1/TU" in fig.get_suptitle()
    # a study whose output.figures names none of the command's figures says so (was silent)
    study.write_text(text.replace('figures = ["multipliers", "body_axes", "map"]', 'figures = ["multipliers"]'))
    res = cli("map", study, "--out", tmp_path / "out2")
    assert "figures: none drawn: output.figures = ['multipliers'] names none of this command's (map)" in res.stderr
    assert not list((tmp_path / "out2").glob("*.png"))


EXAMPLE_FIGURES = {
    "01_dro_map_tutorial.py": {"family.png", "residuals.png", "map.png"},
    "02_halo_family.py": {"halo_family.png", "halo_period.png", "halo_stability.png"},
    "03_srp_solution.py": {"srp_motion.png"},
    "04_study_from_python.py": {"map_kz0.8.png"},
}


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(EXAMPLE_FIGURES))
def test_example_figures(script, tmp_path, written, monkeypatch, capsys):
    """Each example, run in this process as written (tests/test_examples.py runs them as scripts)."""
    assert sorted(EXAMPLE_FIGURES) == sorted(p.name for p in EXAMPLES.glob("[0-9][0-9]_*.py"))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [script, str(tmp_path)])
    runpy.run_path(str(EXAMPLES / script), run_name="__main__")
    assert "written:" in capsys.readouterr().out
    check_figures(written, tmp_path, EXAMPLE_FIGURES[script])


def test_cli_figures_transition(cli, tmp_path, written):
    """`librate transition` on examples/transition.toml (2 revolutions): the orbit in the rotating
    frame in both models (its ephemeris line is the stored track of the first epoch, in km about
    the Moon), the node defects and the epoch sweep."""
    import shutil

    shutil.copy(EXAMPLES / "transition.toml", tmp_path / "t.toml")
    cli("transition", tmp_path / "t.toml", "--set", "ephemeris.revolutions=2")
    out = tmp_path / "librate-out"
    check_figures(written, out, {"transition_rotating.png", "transition_defects.png", "transition_sweep.png"})
    ds = librate.open_result(out / "transition.zarr")
    (line,) = [ln for ln in written["transition_rotating.png"].axes[0].get_lines() if ln.get_gid() == "ephemeris"]
    track = (ds["track_synodic"].values[0, :, 0] - (1 - float(ds.attrs["mu"]))) * float(ds.attrs["lu_km"])
    np.testing.assert_allclose(line.get_xdata(), track, rtol=1e-12)
    (defects,) = [a for a in written["transition_defects.png"].axes if "position" in a.get_ylabel()]
    assert len([ln for ln in defects.get_lines() if ln.get_gid() == "defects"]) == ds.sizes["epoch"]


def test_ephemeris_attitude_figures_hold_their_data(tmp_path):
    """plot_ephemeris_attitude and plot_pointing_error draw the arrays they are given (angles of
    two models, the pointing error of each body axis), one panel per angle; bad shapes are
    refused naming the argument."""
    t = np.linspace(0.0, 30.0, 200)
    a = np.column_stack([10 * np.sin(t), 5 * np.cos(t), t])
    b = a + 0.01 * t[:, None]
    fig = lp.plot_ephemeris_attitude(t, a, b)
    assert len(fig.axes) == 3 and all(holds_data(x) for x in fig.axes)
    for j, x in enumerate(fig.axes):
        (eph,) = [ln for ln in x.get_lines() if ln.get_gid() == "ephemeris"]
        np.testing.assert_array_equal(eph.get_ydata(), b[:, j])
    err = lp.plot_pointing_error(t, np.abs(b - a))
    assert holds_data(err.axes[0]) and {ln.get_gid() for ln in err.axes[0].get_lines()} == {"pointing-x", "pointing-y", "pointing-z"}
    with pytest.raises(ValueError, match="`error_deg`"):
        lp.plot_pointing_error(t, np.ones((3, 3)))
    with pytest.raises(ValueError, match="the angles must be"):
        lp.plot_ephemeris_attitude(t, a[:, :2], b)
    plt.close("all")
