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
