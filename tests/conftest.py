import librate
import pytest


@pytest.fixture(scope="session")
def em():
    return librate.System.preset("earth-moon")


@pytest.fixture(scope="session")
def dro_085(em):
    return librate.correct_dro(em, 0.85)
