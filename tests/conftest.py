import librate
import pytest
from click.testing import CliRunner


@pytest.fixture(scope="session")
def em():
    return librate.System.preset("earth-moon")


@pytest.fixture(scope="session")
def dro_085(em):
    return librate.correct_dro(em, 0.85)


@pytest.fixture
def cli(tmp_path, monkeypatch):
    """Invoke the command line in tmp_path: cli(*args, code=0) returns the click Result (stdout
    and stderr separate), after checking the exit code and that no traceback was printed."""
    from librate.app.cli import main

    monkeypatch.chdir(tmp_path)
    runner = CliRunner()

    def invoke(*args, code=0):
        res = runner.invoke(main, [str(a) for a in args], catch_exceptions=False)
        assert res.exit_code == code, res.output
        assert "Traceback" not in res.output
        return res

    return invoke


@pytest.fixture(scope="session")
def kernel():
    """The embedded DE440 excerpt opened by jplephem: the independent reader of the ephemeris tests'
    references (tests/ephemeris_reference.py)."""
    from jplephem.spk import SPK
    from librate.ephemeris.spk import embedded_spk_path

    k = SPK.open(str(embedded_spk_path()))
    yield k
    k.close()
