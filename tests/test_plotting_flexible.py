"""librate.plotting, flexible spacecraft (thesis Figs. 42-46), rendered with Agg and checked
against the data: one arm, spring, mass and direction per appendage at the body's positions
and directions, a dashpot exactly where c_j > 0; the plotted flexible coordinates equal the
closed form and the full model; the body rate equals the trajectory's and the rigid reference's."""

import math

import matplotlib

matplotlib.use("Agg")

import librate  # noqa: E402
import librate.plotting as lp  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from test_plotting import assert_png, gid  # noqa: E402

EM = librate.System.preset("earth-moon")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def case():
    """The low-frequency station along the stable N = 0 solution of the 12.66-day DRO."""
    dro = librate.dro(EM, period_days=12.66)
    low = librate.FlexibleBody.sample_station(low_frequency=True)
    sol = librate.periodic_attitude(dro, kz=low.kz, n=0)
    return dro, low, (sol.phi0, sol.wz0)


def test_schematic_from_the_parameters(tmp_path):
    """Figs. 42-43: one arm, spring, mass and direction arrow per appendage; each mass drawn at
    b_j, each arm ending at b_j, each arrow along t_j; dashpots only where c_j > 0; the hub
    rectangle has the hub's second moments (half-widths sqrt(3 Q / m0)); the table lists every
    appendage; a deformed shape puts the masses at b_j + scale q_j t_j."""
    body = librate.FlexibleBody.sample_station()
    apps = list(body.appendages)
    apps[0] = librate.Appendage(apps[0].mass, apps[0].position, apps[0].direction, apps[0].stiffness, 0.0, "undamped")
    body = librate.FlexibleBody(body.hub, apps, "test")
    fig = lp.plot_flexible_body(body)
    ax = fig.axes[0]
    for j, a in enumerate(body.appendages):
        (mk,) = gid(ax, f"mass-{j}")
        np.testing.assert_allclose(mk.get_xydata()[0], a.position)
        arm = gid(ax, f"arm-{j}")[0].get_xydata()
        np.testing.assert_allclose(arm[-1], a.position)
        np.testing.assert_allclose(arm[0], body.hub_position)
        assert len(gid(ax, f"spring-{j}")) == 1
        (arrow,) = gid(ax, f"direction-{j}")
        xy = arrow.get_xy()
        tip = xy[np.argmax(xy @ np.array(a.direction))]
        base = np.array(a.position) - 0.06 * 47.5 * np.array(a.position) / math.hypot(*a.position)
        np.testing.assert_allclose(tip - base, 0.08 * 47.5 * np.array(a.direction), atol=1e-9)
        assert (len(gid(ax, f"damper-{j}")) > 0) == (a.damping > 0)
    (hub,) = gid(ax, "hub")
    h = body.hub
    assert hub.get_width() == pytest.approx(2 * math.sqrt(3 * 0.5 * (h.iy + h.iz - h.ix) / h.mass_kg))
    assert hub.get_height() == pytest.approx(2 * math.sqrt(3 * 0.5 * (h.ix + h.iz - h.iy) / h.mass_kg))
    assert len(gid(ax, "cm")) == 1 and len(gid(ax, "axes")) == 2
    (table,) = gid(ax, "table")
    assert all(a.name in table.get_text() for a in body.appendages) and "K_z" in table.get_text()
    assert_png(fig, tmp_path / "schematic.png")
    q = np.array([0.5, -0.2, 1.0, 0.1, 0.0, 0.3])
    fig2 = lp.plot_flexible_body(body, deflection=q, scale=10.0)
    for j, a in enumerate(body.appendages):
        pts = [ln.get_xydata()[-1] for ln in gid(fig2.axes[0], f"deformed-{j}")]
        np.testing.assert_allclose(pts[-1], np.array(a.position) + 10.0 * q[j] * np.array(a.direction))


def test_flexible_coordinate_against_the_closed_form(tmp_path, case):
    """Fig. 44: the closed-form curves are QuasiStaticResponse.q, the full-model curves the
    trajectory's deflections, the error panel their difference; time in revolutions."""
    dro, low, att = case
    body = low.scaled(10.0)
    te = np.linspace(0, dro.period, 301)
    qs = librate.quasi_static(EM, dro.state0, att, body, dro.period, t_eval=te)
    tr = librate.propagate_attitude(EM, dro.state0, att, body, dro.period, t_eval=te, deflection="quasi-static")
    fig = lp.plot_flexible_coordinate(qs, tr, index=[1, 4], period=dro.period)
    a0, a1 = fig.axes[:2]
    for j in (1, 4):
        (c,) = gid(a0, f"closed-form-{j}")
        (f,) = gid(a0, f"full-{j}")
        (e,) = gid(a1, f"error-{j}")
        np.testing.assert_allclose(c.get_xdata(), te / dro.period)
        np.testing.assert_allclose(c.get_ydata(), qs.q[:, j])
        np.testing.assert_allclose(f.get_ydata(), tr.flex.q[:, j])
        np.testing.assert_allclose(e.get_ydata(), tr.flex.q[:, j] - qs.q[:, j])
    assert not gid(a0, "closed-form-0")
    assert_png(fig, tmp_path / "coordinate.png")
    only = lp.plot_flexible_coordinate(qs)
    assert len(only.axes) == 1 and len(gid(only.axes[0], "closed-form-5")) == 1


def test_structural_response_and_body_rate(tmp_path, case):
    """Figs. 45-46: the deflections and the flexible body rate are the trajectory's, the dashed
    reference the rigid composite body's from the same state; over two periods the low-frequency
    station's rate departs visibly from the rigid one (by more than 1e-3 /TU)."""
    dro, low, att = case
    T = 2 * dro.period
    te = np.linspace(0, T, 801)
    tr = librate.propagate_attitude(EM, dro.state0, att, low, T, t_eval=te, deflection="quasi-static")
    rigid = librate.propagate_attitude(EM, dro.state0, att, low.rigid_body(), T, planar=True, t_eval=te)
    fig = lp.plot_flexible_response(tr, rigid, period=dro.period)
    aq, aw = fig.axes[:2]
    for j in range(low.n):
        np.testing.assert_allclose(gid(aq, f"q-{j}")[0].get_ydata(), tr.flex.q[:, j])
    np.testing.assert_allclose(gid(aw, "wz")[0].get_ydata(), tr.wz)
    np.testing.assert_allclose(gid(aw, "wz-rigid")[0].get_ydata(), rigid.wz)
    assert np.max(np.abs(tr.wz - rigid.wz)) > 1e-3
    assert_png(fig, tmp_path / "response.png")
    qs = librate.quasi_static(EM, dro.state0, att, low, T, t_eval=te)
    fig2 = lp.plot_flexible_response(tr, qs, index=0)
    np.testing.assert_allclose(gid(fig2.axes[1], "wz-rigid")[0].get_ydata(), qs.wz)
    assert len(gid(fig2.axes[0], "q-0")) == 1 and not gid(fig2.axes[0], "q-1")


def test_frequency_scan_figure(tmp_path, case):
    dro, low, att = case
    sc = librate.frequency_scan(EM, dro.state0, att, low, 0.5 * dro.period, [1.0, 10.0, 100.0], samples=201)
    fig = lp.plot_frequency_scan(sc, index=[0, 4])
    aa, ad = fig.axes[:2]
    np.testing.assert_allclose(gid(aa, "amplification-4")[0].get_ydata(), sc.amplification[:, 4])
    np.testing.assert_allclose(gid(aa, "amplification-0")[0].get_xdata(), sc.frequency[:, 0])
    np.testing.assert_allclose(gid(ad, "dphi")[0].get_ydata(), sc.max_dphi)
    assert_png(fig, tmp_path / "scan.png")


BAD = [
    ("schematic of a rigid body", lambda: lp.plot_flexible_body(librate.RigidBody.from_kz(0.5)), "FlexibleBody"),
    ("deflection of wrong size", lambda: lp.plot_flexible_body(librate.FlexibleBody.sample_station(), deflection=[1.0]), "deflection"),
    ("negative scale", lambda: lp.plot_flexible_body(librate.FlexibleBody.sample_station(), deflection=np.zeros(6), scale=-1.0), "scale"),
    ("closed form not a QuasiStaticResponse", lambda: lp.plot_flexible_coordinate(None), "quasi"),
    ("response of a rigid run", lambda: lp.plot_flexible_response(
        librate.propagate_attitude(EM, [0.8, 0, 0, 0, 0.5, 0], (0, 1), librate.RigidBody.from_kz(0.5), 0.1, planar=True)), "traj"),
    ("scan of the wrong type", lambda: lp.plot_frequency_scan([1, 2]), "scan"),
]


@pytest.mark.parametrize("desc, call, text", BAD, ids=[b[0] for b in BAD])
def test_bad_flexible_figure_input(desc, call, text):
    with pytest.raises(ValueError) as info:
        call()
    assert text in str(info.value)


def test_bad_index_and_mismatched_times(case):
    dro, low, att = case
    te = np.linspace(0, 0.2, 11)
    qs = librate.quasi_static(EM, dro.state0, att, low, 0.2, t_eval=te)
    tr = librate.propagate_attitude(EM, dro.state0, att, low, 0.2, t_eval=np.linspace(0, 0.2, 12))
    with pytest.raises(ValueError, match="index"):
        lp.plot_flexible_coordinate(qs, index=6)
    with pytest.raises(ValueError, match="t_eval"):
        lp.plot_flexible_coordinate(qs, tr)
