"""`progress=` on every long Python call (issue 23 #6): True draws the CLI's tqdm bar on stderr,
a callable still receives (done, total), anything else is a ValueError naming `progress`."""

import librate
import numpy as np
import pytest


@pytest.fixture(scope="module")
def dro(em):
    return librate.dro(em, x0=0.8)


def _calls():
    seen = []
    return seen, lambda done, total: seen.append((done, total))


def _bar(err: str, desc: str) -> None:
    # the tqdm bar: its description and a finished count "k/k"
    assert desc in err, err
    assert "100%" in err, err


def test_periodicity_map_progress_true_draws_a_bar(capsys, dro):
    """The README's map call with progress=True (TypeError before: 'bool' object is not callable)."""
    m = librate.periodicity_map([dro, dro], kz=0.5, wz0=np.linspace(0.5, 1.5, 16), solve=False, progress=True)
    assert m.dwz.shape == (2, 1, 16)
    _bar(capsys.readouterr().err, "periodicity map")
    seen, cb = _calls()
    librate.periodicity_map([dro, dro], kz=0.5, wz0=np.linspace(0.5, 1.5, 16), solve=False, progress=cb)
    assert seen == [(1, 2), (2, 2)]
    with pytest.raises(ValueError, match="`progress`"):
        librate.periodicity_map(dro, kz=0.5, wz0=np.linspace(0.5, 1.5, 16), progress="yes")


def test_family_continuations_take_progress_true(capsys, em):
    fam = librate.dro_family(em, x0=[0.9, 0.85, 0.8], progress=True)
    assert len(fam) == 3
    _bar(capsys.readouterr().err, "dro family")
    seen, cb = _calls()
    librate.dro_family(em, x0=[0.9, 0.85, 0.8], progress=cb)
    assert seen[-1] == (3, 3) and all(d <= t for d, t in seen)


def test_find_periodic_attitudes_and_attitude_family_take_progress(capsys, dro):
    sols = librate.find_periodic_attitudes(dro, kz=0.8, wz0_range=(0.0, 2.0), progress=True)
    assert sols
    _bar(capsys.readouterr().err, "periodic attitudes")
    seen, cb = _calls()
    librate.find_periodic_attitudes(dro, kz=0.8, wz0_range=(0.0, 2.0), progress=cb)
    assert seen == [(1, 2), (2, 2)]  # the scan, then the refinement (symmetric closure)
    fam = librate.attitude_family(dro, kz=0.8, n=0, max_points=4, progress=True)
    _bar(capsys.readouterr().err, "attitude family N = 0")
    seen, cb = _calls()
    librate.attitude_family(dro, kz=0.8, n=0, max_points=4, progress=cb)
    assert seen[-1] == (len(fam.wz0), len(fam.wz0))


def test_attitude_map_3d_takes_progress_true(capsys, dro):
    m = librate.attitude_map_3d(dro, librate.RigidBody.from_kz(0.8), wx0=0.0, wy0=0.0, wz0=np.linspace(0.5, 1.5, 8), progress=True)
    assert m.residual_norm.shape == (8,)
    _bar(capsys.readouterr().err, "3-D map")
