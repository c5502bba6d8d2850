"""Packaging: public API, stubs, command line."""

import importlib.resources

from click.testing import CliRunner

import librate
from librate.cli import main


def test_public_api_is_declared():
    for name in librate.__all__:
        assert hasattr(librate, name), name
    assert librate.__version__.count(".") == 2
    files = importlib.resources.files("librate")
    assert files.joinpath("py.typed").is_file() and files.joinpath("_core.pyi").is_file()


def test_cli_info_and_demo():
    runner = CliRunner()
    info = runner.invoke(main, ["info"])
    assert info.exit_code == 0 and "earth-moon-jpl" in info.output and "0.836915125772357" in info.output
    demo = runner.invoke(main, ["demo", "--x0", "0.9", "--x0", "0.85"])
    assert demo.exit_code == 0, demo.output
    rows = [line.split() for line in demo.output.splitlines() if line.strip().startswith("0.8")]
    assert len(rows) == 1 and float(rows[0][6]) < 1e-10  # closure after one period
