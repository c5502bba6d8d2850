"""Packaging: public API, stubs, command line."""

import importlib.resources

import librate
import pytest
from click.testing import CliRunner
from librate.app.cli import main


def test_public_api_is_declared():
    for name in librate.__all__:
        assert hasattr(librate, name), name
    assert librate.__version__.count(".") == 2
    files = importlib.resources.files("librate")
    assert files.joinpath("py.typed").is_file() and files.joinpath("_core.pyi").is_file()


@pytest.mark.parametrize(("old", "new"), [("FlatPlateSRP", "FlatPlate"), ("SunModel", "Sun")])
def test_renamed_classes_keep_a_deprecated_alias(old, new):
    """The old names still import from librate, with a DeprecationWarning naming the new one."""
    with pytest.warns(DeprecationWarning, match=f"librate.{new}"):
        assert getattr(librate, old) is getattr(librate, new)
    assert old not in librate.__all__ and new in librate.__all__
    with pytest.raises(AttributeError):
        librate.NoSuchName  # noqa: B018


def test_cli_info_dros_and_demo(tmp_path):
    runner = CliRunner()
    info = runner.invoke(main, ["info"])
    assert info.exit_code == 0 and "earth-moon-jpl" in info.output and "0.836915125772357" in info.output
    dros = runner.invoke(main, ["dros", "--x0", "0.9", "--x0", "0.85"])
    assert dros.exit_code == 0, dros.output
    rows = [line.split() for line in dros.output.splitlines() if line.strip().startswith("0.8")]
    assert len(rows) == 1 and float(rows[0][6]) < 1e-10  # closure after one period
    demo = runner.invoke(main, ["demo", "--orbits", "4", "--rates", "200", "--out", str(tmp_path)])
    assert demo.exit_code == 0, demo.output
    assert "5 orbits x 200 rates" in demo.output  # 4 and the 12.66-day DRO
    import xarray as xr

    ds = xr.open_dataset(tmp_path / "demo.nc", engine="scipy")
    assert ds.dwz.shape == (5, 1, 200) and ds.sizes["solution"] > 0
    assert float(ds.sol_residual.max()) < 1e-9
    bad = runner.invoke(main, ["demo", "--kz", "2"])
    assert bad.exit_code != 0 and "kz" in bad.output.lower()


def test_import_librate_leaves_the_application_layer_unloaded():
    """`import librate` loads neither the app package nor its dependencies (pydantic, click,
    tqdm); `librate.Study` loads them on first use (issue 20: the root is the bottom layer)."""
    import subprocess
    import sys

    code = ("import sys, librate; heavy = ('librate.app', 'pydantic', 'click', 'tqdm');"
            "print(sorted({m.split('.')[0] if not m.startswith('librate') else 'librate.app' for m in sys.modules if "
            "m.startswith(heavy)}));librate.Study; print('librate.app.study' in sys.modules, 'Study' in dir(librate))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[]", out
    assert out[1] == "True True"


def test_no_module_is_over_700_lines():
    """Issue 20's rule for a package a newcomer can read: no Python module of librate is over 700
    lines (the largest, app/schema.py, holds 687)."""
    from pathlib import Path

    root = Path(librate.__file__).parent
    long = {str(p.relative_to(root)): n for p in root.rglob("*.py") if (n := len(p.read_text(encoding="utf-8").splitlines())) > 700}
    assert not long, long
