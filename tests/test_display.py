"""Notebook display (librate._display): the short repr and the HTML summary of the main objects.

Reference: issue 23 item 5 (``repr(OrbitFamily)`` was 7-15 thousand characters and
``AttitudeSolution`` nested the whole orbit and system). Checks: each repr is one line under a
stated length; each ``_repr_html_`` parses as well-formed HTML (every opened tag closed, in order,
by the standard library's html.parser) and names the object's key values, formatted as shown.
"""

from html.parser import HTMLParser

import librate
import numpy as np
import pytest
from librate.periodicity.map3d import map3d_grid

VOID = {"br", "hr", "img", "meta", "link", "input", "col", "wbr"}


class _Checker(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.text = [], [], []

    def handle_starttag(self, tag, attrs):
        if tag not in VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:] or 'nothing'}")
        else:
            self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def parsed_text(markup: str) -> str:
    """The text of ``markup``, asserting it is well formed."""
    c = _Checker()
    c.feed(markup)
    c.close()
    assert not c.errors, c.errors
    assert not c.stack, f"unclosed tags: {c.stack}"
    return " ".join(c.text)


@pytest.fixture(scope="module")
def em():
    return librate.System.preset("earth-moon")


@pytest.fixture(scope="module")
def fam(em):
    return librate.dro_family(em, x0=np.linspace(0.9, 0.3, 15))


@pytest.fixture(scope="module")
def sol(fam):
    return librate.periodic_attitude(fam.member(period_days=12.66), kz=0.8, n=-1)  # thesis Fig. 23


def test_system(em):
    r = repr(em)
    assert r.startswith("System(") and len(r) < 120 and "0.01215" in r
    text = parsed_text(em._repr_html_())
    for key in ("earth-moon", "0.01215", "384400", "375190", "L1", "L5"):
        assert key in text


def test_periodic_orbit(em):
    dro = librate.correct_dro(em, 0.85)
    r = repr(dro)
    assert len(r) < 200 and "\n" not in r
    assert "9.9765" in r and "2.29742" in r  # period_days and period (README: 9.9765 d, 2.29742 TU)
    assert "System(" not in r  # the system is not nested in the one-line repr
    text = parsed_text(dro._repr_html_())
    for key in ("9.9765", "2.29742", "2.96087", "earth-moon", "state0"):
        assert key in text


def test_orbit_family(fam):
    r = repr(fam)
    assert len(r) < 300, len(r)  # issue 23: was 7-15 thousand characters
    assert "members=15" in r and "[0.3 .. 0.9]" in r
    html = fam._repr_html_()
    assert len(html) < 10_000
    text = parsed_text(html)
    for key in ("15 members", "dro", "stability_indices", "end_reason", f"{fam.period_days.max():.6g}"):
        assert key in text
    assert html.count("<details>") >= 2  # the arrays and the rest collapsed


def test_attitude_solution(sol):
    r = repr(sol)
    assert len(r) < 250, len(r)
    assert "state0" not in r and "System(" not in r and "PeriodicOrbit(" not in r  # no nested orbit or system
    assert "n=-1" in r and "-2.45453" in r  # README: phidot0 = -2.4545 for N = -1
    text = parsed_text(sol._repr_html_())
    for key in ("N = -1", "Kz = 0.8", "-2.45453", "trace", "12.66"):
        assert key in text


def test_attitude_solution_3d(sol):
    s3 = librate.out_of_plane_stability(sol)
    r = repr(s3)
    assert len(r) < 250 and "PeriodicOrbit(" not in r
    text = parsed_text(s3._repr_html_())
    for key in ("AttitudeSolution3D", "multipliers", "q0", "w0", "12.66"):
        assert key in text


def test_map3d_grid():
    g = map3d_grid(librate.RigidBody(1.0, 1.5, 2.0), wx0=np.linspace(-1, 1, 201), wy0=0.0, wz0=np.linspace(-3, 2, 301))
    r = repr(g)
    assert len(r) < 300 and "n_cases=60501" in r
    text = parsed_text(g._repr_html_())
    assert "60501 cases" in text and "wz0" in text and "(301,) float64 [-3 .. 2]" in text


def test_escaping():
    from librate._display import html_summary

    text = parsed_text(html_summary("a <b> & c", [("x", "<script>", "")]))
    assert "a <b> & c" in text and "<script>" in text  # escaped markup reads back as text
