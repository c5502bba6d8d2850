"""librate.plotting: the thesis ch. 2, sec. 3.3 and ch. 4 figures, rendered with Agg and checked against
the data.

Each figure is written to a PNG (non-trivial: over 10 kB, not one colour) and its artists are
compared with the numbers they show: one line per requested orbit starting at the member's x0,
the colour scale spanning the family's Jacobi range, resonance lines at 2 pi / K and Ts / K in
days through the system's TU, stability curves equal to the family's indices, ECI curves
starting |r0 - r_earth| LU from the Earth and 1:K resonant orbits closing after K periods;
residual curves equal to the periodicity map's values, solution markers at the solutions' rates,
map contours through the solutions, family curves holding exactly the solutions of their N and
Kz, periodic motions ending at phi0 + 2 pi N. Chapter 4 (SRP): Sun directions at omega_sun t + theta0
(omega_sun from the sidereal month and year), Sun-resonant DROs of period Ts / K found
independently, SRP map markers at the map's solutions (which repeat after K revolutions when
re-propagated), fold crosses where the branches' monodromy trace is 2 and scaling as 1 / (1 + Cs),
comparison curves ending at an independent propagation's phi(KT) and wz(KT), Sun-pointing
accelerations equal to the written-out formulas and to the engine's wzdot.
"""

import math
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import librate  # noqa: E402
import librate.plotting as lp  # noqa: E402
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from helpers import dro_with_period  # noqa: E402
from librate.constants import SUN_SYNODIC_PERIOD  # noqa: E402
from librate.plotting import _solutions as lp_solutions  # noqa: E402


@pytest.fixture(scope="module")
def fam(em):
    """17 DROs, x0 = 0.95 ... 0.15 (the 1:1 resonance at x0 = 0.1521 and the out-of-plane
    bifurcation near 0.27 inside)."""
    return librate.dro_family(em, x0=np.arange(0.95, 0.1, -0.05))


@pytest.fixture(scope="module")
def halos(em):
    return librate.halo_family(em, 2, "south")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def gid(ax, name):
    return [a for a in ax.get_children() if getattr(a, "get_gid", lambda: None)() == name]


def assert_png(fig, path):
    out = lp.save_figure(fig, path)
    assert out == path and path.is_file() and path.stat().st_size > 10_000
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] > 200 and img.shape[1] > 200 and float(img[..., :3].std()) > 0.02


def colorbar_axes(fig):
    return [a for a in fig.axes if a.get_label() == "<colorbar>"]


def test_import_librate_does_not_import_matplotlib():
    """Fresh interpreter: ``import librate`` leaves matplotlib out; ``import librate.plotting``
    imports matplotlib but not pyplot (only creating a figure does)."""
    code = (
        "import sys, librate; assert 'matplotlib' not in sys.modules, 'librate imported matplotlib'; "
        "import librate.plotting; assert 'matplotlib' in sys.modules; "
        "assert 'matplotlib.pyplot' not in sys.modules, 'librate.plotting imported pyplot'; print('ok')"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr


def test_plot_family_lines_colours_and_markers(fam, tmp_path):
    """Thesis Fig. 3: n_orbits lines spread over the family (first and last members included),
    each starting at its member's (x0, 0) and closing after one period; colours from the family's
    Jacobi range, which the colorbar spans; Earth, Moon, L1 and L2 marked."""
    fig = lp.plot_family(fam, n_orbits=6)
    assert_png(fig, tmp_path / "family.png")
    ax = fig.axes[0]
    lines = gid(ax, "orbit")
    assert len(lines) == 6
    starts = np.array([[ln.get_xdata()[0], ln.get_ydata()[0]] for ln in lines])
    sel = np.round(np.linspace(0, len(fam) - 1, 6)).astype(int)
    assert sel[0] == 0 and sel[-1] == len(fam) - 1
    np.testing.assert_allclose(starts[:, 0], fam.x0[sel], atol=1e-12)
    np.testing.assert_allclose(starts[:, 1], 0.0, atol=1e-12)
    for ln in lines:  # one closed period
        assert math.hypot(ln.get_xdata()[-1] - ln.get_xdata()[0], ln.get_ydata()[-1] - ln.get_ydata()[0]) < 1e-9
    (cax,) = colorbar_axes(fig)
    assert cax.get_ylim() == pytest.approx((fam.jacobi.min(), fam.jacobi.max()), rel=1e-12)
    cmap = matplotlib.colormaps["turbo"]
    c = fam.jacobi[sel]
    want = [cmap((ci - fam.jacobi.min()) / (fam.jacobi.max() - fam.jacobi.min())) for ci in c]
    np.testing.assert_allclose([matplotlib.colors.to_rgba(ln.get_color()) for ln in lines], want, atol=1e-12)
    assert "Jacobi" in cax.get_ylabel()
    assert ax.get_xlabel() == "x (LU)" and ax.get_ylabel() == "y (LU)"
    (earth,) = gid(ax, "earth")
    (moon,) = gid(ax, "moon")
    assert earth.get_xdata()[0] == pytest.approx(-fam.system.mu) and moon.get_xdata()[0] == pytest.approx(1 - fam.system.mu)
    (l1,) = gid(ax, "L1")
    assert l1.get_xdata()[0] == pytest.approx(fam.system.lagrange_points()[0, 0])


def test_plot_family_all_members_into_given_axes_in_km(fam):
    fig0, ax = plt.subplots()
    fig = lp.plot_family(fam, ax, n_orbits=None, units="km", color_by="period", lagrange_points=())
    assert fig is fig0 and ax.get_title() == ""  # no title forced on the caller's axes
    lines = gid(ax, "orbit")
    assert len(lines) == len(fam)
    np.testing.assert_allclose([ln.get_xdata()[0] for ln in lines], fam.x0 * fam.system.lu_km, rtol=1e-12)
    assert ax.get_xlabel() == "x (km)" and not gid(ax, "L1")
    (cax,) = colorbar_axes(fig)
    assert cax.get_ylim() == pytest.approx((fam.period_days.min(), fam.period_days.max()), rel=1e-12)


def test_plot_family_spatial_projections(halos, tmp_path):
    """A spatial family gets x-y and x-z panels by default; the Earth, far from the L2 halos,
    is marked without widening the view; the 3-D option draws (x, y, z)."""
    fig = lp.plot_family(halos, n_orbits=8)
    assert_png(fig, tmp_path / "halo.png")
    ax_xy, ax_xz = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    assert len(gid(ax_xy, "orbit")) == 8 and len(gid(ax_xz, "orbit")) == 8
    assert ax_xz.get_ylabel() == "z (LU)"
    z = np.concatenate([ln.get_ydata() for ln in gid(ax_xz, "orbit")])
    assert np.ptp(z) > 0.1  # the halos leave the plane
    assert ax_xy.get_xlim()[0] > 0.5  # the Earth at -mu is outside
    fig3 = lp.plot_family(halos, n_orbits=5, projection="3d")
    assert_png(fig3, tmp_path / "halo3d.png")
    ax3 = fig3.axes[0]
    assert ax3.name == "3d" and len(gid(ax3, "orbit")) == 5
    x, y, zz = gid(ax3, "orbit")[0].get_data_3d()
    np.testing.assert_allclose([x[0], y[0], zz[0]], halos.state0[0, :3], atol=1e-12)


def test_plot_period_resonances(fam, em, tmp_path):
    """Thesis Fig. 6: the period in days against x0, synodic resonances at 2 pi / K and
    Sun-resonant ones at Ts / K converted with the system's TU; the 1:1 marker at the resonant
    member's x0 (0.1521) to the linear interpolation's accuracy on a 0.05 grid (1e-3)."""
    fig = lp.plot_period(fam)
    assert_png(fig, tmp_path / "period.png")
    ax = fig.axes[0]
    (per,) = gid(ax, "period")
    np.testing.assert_allclose(per.get_xdata(), fam.x0)
    np.testing.assert_allclose(per.get_ydata(), fam.period * em.tu_s / 86400.0, rtol=1e-14)
    for k in (1, 2, 3, 4):
        (h,) = gid(ax, f"resonance-synodic-{k}")
        assert h.get_ydata()[0] == pytest.approx(2 * math.pi / k * em.tu_s / 86400.0, rel=1e-14)
    assert gid(ax, "resonance-synodic-1")[0].get_ydata()[0] == pytest.approx(27.28, abs=0.01)
    for k in (2, 4):
        (h,) = gid(ax, f"resonance-sun-{k}")
        assert h.get_ydata()[0] == pytest.approx(SUN_SYNODIC_PERIOD / k * em.tu_days, rel=1e-14)
    assert not gid(ax, "resonance-synodic-5") and not gid(ax, "resonance-sun-1")
    (m1,) = gid(ax, "resonant-member-synodic-1")
    assert m1.get_xdata()[0] == pytest.approx(fam.resonant(1).x0, abs=1e-3)
    assert m1.get_xdata()[0] == pytest.approx(0.1521, abs=1e-3)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("1:2 synodic") for t in legend) and any(t.startswith("1:4 Sun") for t in legend)
    assert ax.get_ylabel() == "period $T$ (days)"
    (earth,) = gid(ax, "earth")
    assert earth.get_xdata()[0] == pytest.approx(-em.mu)

    ax_tu = lp.plot_period(fam, units="TU", resonances=(3,), sun_resonances=()).axes[0]
    assert gid(ax_tu, "resonance-synodic-3")[0].get_ydata()[0] == pytest.approx(2 * math.pi / 3)
    assert not gid(ax_tu, "resonance-sun-2") and ax_tu.get_ylabel() == "period $T$ (TU)"


def test_plot_period_halo_view_fits_the_data(halos, tmp_path):
    """Issue 23 #7: the L2 south halos' periods (5.9-14.8 d, x0 1.01-1.18) fill the view (at
    least 60 % of each axis; they filled 15 % of x when the Earth and the 1:1 line at 27.3 d
    were kept in view), the Moon (within 35 % of the x0 span) stays in view, and every line
    in the legend is inside the view (the 1:1 resonance is not listed)."""
    fig = lp.plot_period(halos)
    assert_png(fig, tmp_path / "halo_period.png")
    ax = fig.axes[0]
    (per,) = gid(ax, "period")
    x, y = per.get_xdata(), per.get_ydata()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert np.ptp(x) / (x1 - x0) > 0.6 and np.ptp(y) / (y1 - y0) > 0.6
    assert x0 <= gid(ax, "moon")[0].get_xdata()[0] <= x1
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert not any(t.startswith("1:1 ") or t.startswith("Earth") for t in legend)
    for h in ax.get_lines():
        if h.get_label() in legend and (h.get_gid() or "").startswith("resonance-"):
            assert y0 <= h.get_ydata()[0] <= y1


def test_plot_stability_curves_and_bifurcation(fam, tmp_path):
    """Thesis Fig. 5: the curves are the family's stability indices (real parts) against x0,
    the stable band is |nu| <= 1, and the out-of-plane +1 crossing near x0 = 0.27 is marked."""
    fig = lp.plot_stability(fam)
    assert_png(fig, tmp_path / "stability.png")
    ax = fig.axes[0]
    for j in (0, 1):
        (h,) = gid(ax, f"stability-{j}")
        np.testing.assert_array_equal(h.get_xdata(), fam.x0)
        np.testing.assert_array_equal(h.get_ydata(), fam.stability_indices[:, j].real)
    assert "in-plane" in gid(ax, "stability-0")[0].get_label() and "out-of-plane" in gid(ax, "stability-1")[0].get_label()
    (band,) = gid(ax, "stable-band")
    ys = ax.transData.inverted().transform(band.get_transform().transform(band.get_path().vertices))[:, 1]
    assert min(ys) == pytest.approx(-1.0) and max(ys) == pytest.approx(1.0)
    bif = gid(ax, "bifurcation")
    assert len(bif) == len(fam.bifurcations) == 1
    assert bif[0].get_xdata()[0] == pytest.approx(fam.bifurcations[0]["x0"]) == pytest.approx(0.27, abs=0.01)
    assert not gid(ax, "stability-imag-0") and ax.get_yscale() == "linear"
    ax_i = lp.plot_stability(fam, imag=True).axes[0]
    np.testing.assert_array_equal(gid(ax_i, "stability-imag-1")[0].get_ydata(), fam.stability_indices[:, 1].imag)


def test_plot_stability_halo_indices_follow_continuity(halos, tmp_path):
    """Issue 23 #7: between members 35 and 36 of the L2 south halos the family lists the two
    indices in the other order ((0.68, -0.65) then (-0.64, 0.48)); the curves follow each index
    by nearest value instead: every drawn pair is the member's pair (exact, as a set), at every
    step the drawn pairing is the nearer of the two (sum of |difference|), and no curve steps by
    more than 0.25 from member 35 to 36 (the listed order steps by 1.3 there; the neighbouring
    steps are 0.2-0.6), and each bifurcation label names the drawn curve crossing its level
    between the member and the next."""
    fig = lp.plot_stability(halos)
    assert_png(fig, tmp_path / "halo_stability.png")
    ax = fig.axes[0]
    y = np.column_stack([gid(ax, f"stability-{j}")[0].get_ydata() for j in (0, 1)])
    nu = np.asarray(halos.stability_indices).real
    np.testing.assert_array_equal(np.sort(y, axis=1), np.sort(nu, axis=1))
    d = np.abs(np.diff(y, axis=0)).sum(axis=1)
    d_swap = np.abs(y[1:, ::-1] - y[:-1]).sum(axis=1)
    assert np.all(d <= d_swap)
    assert np.abs(y[36] - y[35]).max() < 0.25
    texts = [t.get_text() for t in ax.texts if "at $x_0$" in t.get_text()]  # each names the curve crossing there
    assert len(texts) == len(halos.bifurcations)
    for t, b in zip(texts, halos.bifurcations):
        i, j = int(b["member"]), int("nu_2" in t)
        assert (y[i, j] - b["level"]) * (y[i + 1, j] - b["level"]) <= 0, t


def test_plot_stability_symlog_for_large_indices(halos):
    ax = lp.plot_stability(halos, against="jacobi").axes[0]
    assert ax.get_yscale() == "symlog"
    np.testing.assert_array_equal(gid(ax, "stability-0")[0].get_xdata(), halos.jacobi)
    assert len(gid(ax, "bifurcation")) == len(halos.bifurcations)


def test_plot_eci_resonant_dros(fam, em, tmp_path):
    """Thesis Figs. 7a and 10: the 1:1, 1:2, 1:3 resonant DROs in the Earth-centred inertial
    frame, in km: each curve starts |r0 - r_earth| * LU from the Earth, a 1:K orbit covers K
    periods (one synodic revolution) and closes on itself (to 1 km); the 1:1 orbit reaches
    about a (1 + e) = 392070 * 1.8312 km (thesis Table 1) at apogee."""
    orbits = [fam.resonant(k) for k in (1, 2, 3)]
    fig = lp.plot_eci(orbits)
    assert_png(fig, tmp_path / "eci.png")
    ax = fig.axes[0]
    lines = gid(ax, "orbit")
    assert len(lines) == 3 and [ln.get_label() for ln in lines] == ["1:1", "1:2", "1:3"]
    earth = np.array([-em.mu, 0.0, 0.0])
    for ln, o in zip(lines, orbits):
        x, y = ln.get_xdata(), ln.get_ydata()
        assert math.hypot(x[0], y[0]) == pytest.approx(np.linalg.norm(o.state0[:3] - earth) * em.lu_km, rel=1e-12)
        assert math.hypot(x[-1] - x[0], y[-1] - y[0]) < 1.0
    r1 = np.hypot(lines[0].get_xdata(), lines[0].get_ydata())
    assert r1.max() == pytest.approx(392070 * (1 + 0.8312), rel=0.02)
    (moon,) = gid(ax, "moon-path")
    np.testing.assert_allclose(np.hypot(moon.get_xdata(), moon.get_ydata()), em.lu_km, rtol=1e-12)
    assert gid(ax, "earth")[0].get_xdata()[0] == 0.0
    assert "km" in ax.get_xlabel() and "km" in ax.get_ylabel()


def test_plot_eci_separate_panels_and_lu(fam, em, tmp_path):
    near = fam[len(fam) - 2]  # x0 = 0.2: not resonant, labelled by x0 and period
    fig = lp.plot_eci([fam.resonant(4), near], separate=True, units="LU", n_periods=2)
    assert_png(fig, tmp_path / "eci2.png")
    a4, an = fig.axes
    assert len(gid(a4, "orbit")) == 1 and len(gid(an, "orbit")) == 1
    assert a4.get_title() == "1:4" and an.get_title().startswith("$x_0$ = 0.2000")
    x, y = gid(an, "orbit")[0].get_xdata(), gid(an, "orbit")[0].get_ydata()
    assert math.hypot(x[0], y[0]) == pytest.approx(near.x0 + em.mu, rel=1e-12)
    t_end = 2 * near.period  # n_periods = 2: the last point is the ECI state after two periods
    end = near.propagate(2.0).y_final
    want = librate.synodic_to_eci(em, t_end, end)[:2] / em.lu_km
    np.testing.assert_allclose([x[-1], y[-1]], want, atol=1e-9)


def test_save_figure_paths_and_axes(fam, tmp_path):
    ax = lp.plot_period(fam).axes[0]
    out = lp.save_figure(ax, tmp_path / "deep" / "dir" / "p.pdf", close=True)
    assert out.is_file() and out.read_bytes()[:4] == b"%PDF"
    assert not plt.get_fignums()


@pytest.mark.parametrize(
    "call, text",
    [
        (lambda f: lp.plot_family("dro"), "`family`"),
        (lambda f: lp.plot_family(f, n_orbits=0), "`n_orbits`"),
        (lambda f: lp.plot_family(f, projection="xw"), "`projection`"),
        (lambda f: lp.plot_family(f, color_by="energy"), "`color_by`"),
        (lambda f: lp.plot_family(f, units="mi"), "`units`"),
        (lambda f: lp.plot_family(f, plt.subplots(1, 2)[1], projection="xy"), "`ax`"),
        (lambda f: lp.plot_family(f, plt.subplots()[1], projection="3d"), "`ax`"),
        (lambda f: lp.plot_period(f, units="weeks"), "`units`"),
        (lambda f: lp.plot_period(f, resonances=(0,)), "resonance"),
        (lambda f: lp.plot_period(f, sun_resonances=(2.5,)), "resonance"),
        (lambda f: lp.plot_stability(f, against="y0"), "`against`"),
        (lambda f: lp.plot_eci([]), "`orbits`"),
        (lambda f: lp.plot_eci(f[0], n_periods=-1), "`n_periods`"),
        (lambda f: lp.plot_eci([f[0]], labels=["a", "b"]), "`labels`"),
        (lambda f: lp.save_figure("fig", "x.png"), "`fig`"),
    ],
)
def test_bad_arguments(fam, call, text):
    with pytest.raises(ValueError, match=text):
        call(fam)


def test_plot_attitude_response(tmp_path):
    """Attitude response (thesis Fig. 16-18 layout): rate and angle curves carry the
    trajectory's data, against revolutions."""
    import librate.plotting as lp

    em = librate.System.preset("earth-moon")
    a = 10050.0 / em.lu_km
    n = math.sqrt((1 - em.mu) / a**3)
    s0 = [-em.mu + a, 0, 0, 0, math.sqrt((1 - em.mu) / a) - a, 0]
    T = 2 * math.pi / n
    q0 = librate.quaternion_from_euler([0.0, 0.0, 0.01])
    tr = librate.propagate_attitude(em, s0, (q0, [0, 0, n]), librate.RigidBody(12.12e6, 89.68e6, 96.95e6), 3 * T,
                                    torques=("gravity_gradient_earth",), t_eval=np.linspace(0, 3 * T, 300))
    fig = lp.plot_attitude(tr, period=T, relative_to="earth")
    lines = {ln.get_gid(): ln for a in fig.axes for ln in a.get_lines() if ln.get_gid()}
    np.testing.assert_allclose(lines["rate-2"].get_ydata(), tr.w[:, 2])
    np.testing.assert_allclose(lines["angle-2"].get_xdata()[-1], 3.0)
    pitch = np.degrees(np.unwrap(tr.relative_to_vertical("earth")[:, 2]))
    np.testing.assert_allclose(lines["angle-2"].get_ydata(), pitch)
    assert abs(pitch[0] - np.degrees(0.01)) < 1e-9
    path = lp.save_figure(fig, tmp_path / "att.png")
    assert path.stat().st_size > 10_000
    with pytest.raises(ValueError, match="traj"):
        lp.plot_attitude("nope")


# --- periodic attitude motions (thesis sec. 3.3, Figs. 23-31) ------------------------------------
# Rates are plotted relative to the synodic frame by default (phidot0 = wz0 - 1, what the thesis
# figures show under the label wz(0)); every check below compares the drawn data with the
# Dataset / solutions they come from.


@pytest.fixture(scope="module")
def dro1266(em):
    return librate.dro(em, period_days=12.66)


@pytest.fixture(scope="module")
def map_rates():
    return np.linspace(-2.5, 2.5, 300)  # inertial; phidot0 in [-3.5, 1.5]


@pytest.fixture(scope="module")
def small_map(em, map_rates):
    """6 DRO members x 300 rates, Kz = 0.8, with solutions."""
    fam6 = librate.dro_family(em, x0=np.linspace(0.9, 0.6, 6))
    return librate.periodicity_map(fam6, kz=0.8, wz0=map_rates)


@pytest.fixture(scope="module")
def kz_map(em, map_rates):
    """The same 6 members for Kz = 0.2, 0.5, 0.8."""
    fam6 = librate.dro_family(em, x0=np.linspace(0.9, 0.6, 6))
    return librate.periodicity_map(fam6, kz=[0.2, 0.5, 0.8], wz0=map_rates)


def marker_points(ax):
    """(x, y, filled) of every solution marker drawn with gid "solutions", sorted by (x, y)."""
    pts = []
    for h in gid(ax, "solutions"):
        filled = h.get_markerfacecolor() != "none" and matplotlib.colors.to_rgba(h.get_markerfacecolor())[3] > 0
        pts += [(x, y, filled) for x, y in zip(h.get_xdata(), h.get_ydata())]
    return sorted(pts)


def contour_vertices(ax, name):
    (cs,) = gid(ax, name)
    return np.vstack([p.vertices for p in cs.get_paths() if len(p.vertices)])


def test_plot_residuals_fig23(dro1266, map_rates, tmp_path):
    """Thesis Fig. 23 on the 12.66-day DRO, Kz = 0.8, phidot0 in [-3.5, 1.5]: the curves carry
    the map's Dwz and Dphi against phidot0 = wz0 - 1 (the Dphi line broken by NaNs at the +-pi
    wrap: no segment jumps by more than pi); the solution markers sit at (phidot0, 0) of the
    map's solutions, filled exactly for the stable ones, the N = -1 one at -2.4545. The figure
    takes the data: the map of the one orbit is computed first."""
    ds = librate.periodicity_map(dro1266, kz=0.8, wz0=map_rates)
    fig = lp.plot_residuals(ds)
    assert_png(fig, tmp_path / "fig23.png")
    ax = fig.axes[0]
    (hw,) = gid(ax, "residual-dwz")
    np.testing.assert_array_equal(hw.get_xdata(), ds.phidot0.values)
    np.testing.assert_array_equal(hw.get_ydata(), ds.dwz.values[0, 0])
    (hp,) = gid(ax, "residual-dphi")
    x, y = np.asarray(hp.get_xdata()), np.asarray(hp.get_ydata())
    ok = np.isfinite(y)
    np.testing.assert_array_equal(x[ok], ds.phidot0.values)
    np.testing.assert_array_equal(y[ok], ds.dphi.values[0, 0])
    assert (~ok).sum() >= 1  # the wrap at -0.7 is broken ...
    steps = np.diff(y)
    assert np.all(np.abs(steps[np.isfinite(steps)]) < math.pi)  # ... and no drawn segment spans it
    assert gid(ax, "zero")[0].get_ydata()[0] == 0.0
    pts = marker_points(ax)
    want = sorted(zip(ds.sol_phidot0.values, np.zeros(ds.sizes["solution"]), ds.sol_stable.values))
    assert len(pts) == len(want) >= 3
    np.testing.assert_allclose([p[:2] for p in pts], [w[:2] for w in want], atol=1e-12)
    assert [p[2] for p in pts] == [bool(w[2]) for w in want]
    n_minus_1 = float(ds.sol_phidot0.values[(ds.sol_n.values == -1) & (ds.sol_kind.values == "periodic")][0])
    assert round(n_minus_1, 4) == -2.4545 and any(abs(p[0] - n_minus_1) < 1e-12 for p in pts)
    assert "relative to the synodic frame" in ax.get_xlabel()
    # the same figure on the inertial axis
    ax2 = lp.plot_residuals(ds, rate="inertial").axes[0]
    np.testing.assert_array_equal(gid(ax2, "residual-dwz")[0].get_xdata(), map_rates)
    np.testing.assert_allclose(sorted(p[0] for p in marker_points(ax2)), sorted(ds.sol_wz0.values), atol=1e-12)
    assert "inertial" in ax2.get_xlabel() and "relative" not in ax2.get_xlabel()
    ax3 = lp.plot_residuals(ds, kinds=("periodic",)).axes[0]
    assert len(marker_points(ax3)) == int((ds.sol_kind.values == "periodic").sum())


def test_plot_residuals_picks_orbit_and_kz(kz_map):
    ax = lp.plot_residuals(kz_map, orbit_index=2, kz=0.5).axes[0]
    np.testing.assert_array_equal(gid(ax, "residual-dwz")[0].get_ydata(), kz_map.dwz.values[2, 1])
    sel = (kz_map.sol_orbit.values == 2) & (kz_map.sol_kz.values == 0.5)
    np.testing.assert_allclose(sorted(p[0] for p in marker_points(ax)), sorted(kz_map.sol_phidot0.values[sel]), atol=1e-12)


def test_plot_map_fig24(small_map, tmp_path):
    """Thesis Fig. 24: the Dphi = 0 contour passes through every periodic solution (on the
    solution's orbit column a contour vertex lies within one grid step, 0.017, of its rate, the
    error of linear interpolation in a cell), and so does the Dwz = 0 contour wherever the grid resolves it: a miss is allowed only
    where the Dwz row has no sign change within two cells of the solution (the thin Dwz < 0 dip,
    ~0.004 wide, beside a stable solution, narrower than the grid); no Dphi contour runs along the
    +-pi wrap (the unwrapped phi(T) interpolated at each column vertex is a multiple of 2 pi); the
    markers sit at (period in days, phidot0) of the periodic solutions, filled exactly for the
    stable ones."""
    ds = small_map
    fig = lp.plot_map(ds)
    assert_png(fig, tmp_path / "fig24.png")
    ax = fig.axes[0]
    periodic = ds.sol_kind.values == "periodic"
    orb, rate = ds.sol_orbit.values[periodic], ds.sol_phidot0.values[periodic]
    xcol, grid = ds.period_days.values, ds.phidot0.values
    assert periodic.sum() >= 8
    for name in ("contour-dwz", "contour-dphi"):
        v = contour_vertices(ax, name)
        hits = 0
        for o, r in zip(orb, rate):
            on_col = v[np.abs(v[:, 0] - xcol[o]) < 1e-9]
            if on_col.size and np.min(np.abs(on_col[:, 1] - r)) < grid[1] - grid[0]:
                hits += 1
                continue
            assert name == "contour-dwz", (name, o, r)
            j = np.searchsorted(grid, r)
            near = ds.dwz.values[o, 0, max(j - 3, 0):j + 3]
            assert np.all(near > 0) or np.all(near < 0), (o, r)  # unresolved by the grid, not a missing contour
        assert hits >= 0.75 * len(orb)
    v = contour_vertices(ax, "contour-dphi")
    for o in range(ds.sizes["orbit"]):
        col = v[np.abs(v[:, 0] - xcol[o]) < 1e-9, 1]
        phi_t = np.interp(col, ds.phidot0.values, ds.phi_T.values[o, 0])
        assert np.all(np.cos(phi_t) > 0.999)
    pts = marker_points(ax)
    want = sorted(zip(xcol[orb], rate, ds.sol_stable.values[periodic]))
    np.testing.assert_allclose([p[:2] for p in pts], [w[:2] for w in want], atol=1e-12)
    assert [p[2] for p in pts] == [bool(w[2]) for w in want]
    for h in gid(ax, "solutions"):  # one colour per N
        ns = {int(n) for o, r, n in zip(orb, rate, ds.sol_n.values[periodic]) if abs(r - h.get_ydata()[0]) < 1e-12}
        assert len(ns) == 1 and h.get_color() == lp.n_color(ns.pop())
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "$N$ = -1" in legend and "$N$ = 0" in legend
    assert ax.get_xlabel() == "orbit period $T$ (days)" and "relative to the synodic frame" in ax.get_ylabel()
    assert not gid(ax, "contour-dphi-half")


def test_plot_map_inertial_x0_and_half_turns(small_map):
    ds = small_map
    ax = lp.plot_map(ds, against="x0", rate="inertial", kinds=("periodic", "half-turn")).axes[0]
    pts = marker_points(ax)
    want = sorted(zip(ds.x0.values[ds.sol_orbit.values], ds.sol_wz0.values))
    np.testing.assert_allclose([p[:2] for p in pts], want, atol=1e-12)
    assert gid(ax, "contour-dphi-half") and "inertial" in ax.get_ylabel()
    # half-turn solutions sit on Dphi = pi: phi(T) - phi0 an odd multiple of pi
    v = contour_vertices(ax, "contour-dphi-half")
    for o in range(ds.sizes["orbit"]):
        col = v[np.abs(v[:, 0] - ds.x0.values[o]) < 1e-9, 1]
        assert np.all(np.cos(np.interp(col, ds.wz0.values, ds.phi_T.values[o, 0])) < -0.999)


def test_plot_solution_families(kz_map, tmp_path):
    """Thesis Figs. 27-29: one panel per N (1, 0, -1); in each, the lines of each Kz hold exactly
    that (N, Kz)'s solutions at (period in days, phidot0), each line visiting consecutive orbits
    once (no zigzag); the stable ones are overdrawn; the single-panel variant holds the same."""
    ds = kz_map
    fig = lp.plot_solution_families(ds, n=(1, 0, -1))
    assert_png(fig, tmp_path / "families.png")
    axes = [a for a in fig.axes]
    assert len(axes) == 3 and [a.get_title().split(":")[0] for a in axes] == ["$N$ = 1", "$N$ = 0", "$N$ = -1"]
    xcol = ds.period_days.values
    total = singles = 0
    for a, n in zip(axes, (1, 0, -1)):
        fam_lines = [h for h in a.get_lines() if (h.get_gid() or "").startswith("family-periodic-")]
        assert all(h.get_gid().startswith(f"family-periodic-N{n:+d}-") for h in fam_lines)
        for kz in (0.2, 0.5, 0.8):
            lines = gid(a, f"family-periodic-N{n:+d}-kz{kz:g}")
            got = sorted((x, y) for h in lines for x, y in zip(h.get_xdata(), h.get_ydata()))
            sel = (ds.sol_n.values == n) & (ds.sol_kind.values == "periodic") & (ds.sol_kz.values == kz)
            want = sorted(zip(xcol[ds.sol_orbit.values[sel]], ds.sol_phidot0.values[sel]))
            assert len(got) == len(want)
            if want:
                np.testing.assert_allclose(got, want, atol=1e-12)
            total += len(want)
            for h in lines:
                o = np.searchsorted(xcol, h.get_xdata())
                assert np.all(np.diff(o) == 1)
            o = np.sort(ds.sol_orbit.values[sel])
            if o.size > 1 and np.all(np.diff(o) == 1):  # one solution on each of consecutive orbits: one curve
                assert len(lines) == 1
                singles += 1
        stable = sorted((x, y) for h in gid(a, "family-stable") for x, y in zip(h.get_xdata(), h.get_ydata()))
        sel = (ds.sol_n.values == n) & (ds.sol_kind.values == "periodic") & ds.sol_stable.values
        np.testing.assert_allclose(stable, sorted(zip(xcol[ds.sol_orbit.values[sel]], ds.sol_phidot0.values[sel])), atol=1e-12)
    assert total >= 10 and singles >= 2
    one = lp.plot_solution_families(ds, n=(1, 0, -1), separate=False, against="x0", rate="inertial").axes
    assert len(one) == 1
    lines = gid(one[0], "family-periodic-N-1-kz0.8")
    sel = (ds.sol_n.values == -1) & (ds.sol_kind.values == "periodic") & (ds.sol_kz.values == 0.8)
    got = sorted((x, y) for h in lines for x, y in zip(h.get_xdata(), h.get_ydata()))
    np.testing.assert_allclose(got, sorted(zip(ds.x0.values[ds.sol_orbit.values[sel]], ds.sol_wz0.values[sel])), atol=1e-12)
    assert {h.get_linestyle() for h in gid(one[0], "family-periodic-N+0-kz0.2")} == {"-"}
    assert {h.get_linestyle() for h in gid(one[0], "family-periodic-N+0-kz0.5")} == {"--"}


def test_solution_branches_follow_the_nearest_rate():
    """Two solutions per orbit, crossing ranks: each branch keeps one per consecutive orbit and
    follows the nearest rate; a gap in the orbits ends a branch; ``max_jump`` cuts a long step."""
    orbit = np.array([0, 0, 1, 1, 2, 2, 4])
    rate = np.array([0.0, 1.0, 0.1, 0.9, 0.25, 0.8, 0.3])
    br = sorted(lp_solutions._branches(orbit, rate, None))
    assert br == [[0, 2, 4], [1, 3, 5], [6]]
    assert sorted(lp_solutions._branches(np.array([0, 1]), np.array([0.0, 2.0]), 1.0)) == [[0], [1]]


def test_plot_attitude_motion_fig30_31(dro1266, tmp_path):
    """Thesis Figs. 30-31 for N = 1, 0, -1 on the 12.66-day DRO (Kz = 0.8): each angle curve
    starts at phi0 and ends at phi0 + 360 N deg after one period (to 1e-6 deg), each rate curve
    starts and ends at the solution's phidot0 (1e-8); time in orbital periods; two periods end at
    720 N deg."""
    sols = [librate.periodic_attitude(dro1266, kz=0.8, n=n) for n in (1, 0, -1)]
    fig = lp.plot_attitude_motion(sols)
    assert_png(fig, tmp_path / "motion.png")
    a_ang, a_rate = fig.axes
    angles, rates = gid(a_ang, "angle"), gid(a_rate, "rate")
    assert len(angles) == len(rates) == 3
    for s, ha, hr in zip(sols, angles, rates):
        x, y = ha.get_xdata(), ha.get_ydata()
        assert x[0] == 0.0 and x[-1] == pytest.approx(1.0, abs=1e-12)
        assert y[0] == pytest.approx(math.degrees(s.phi0), abs=1e-9)
        assert y[-1] == pytest.approx(math.degrees(s.phi0 + 2 * math.pi * s.n), abs=1e-6)
        r = hr.get_ydata()
        assert r[0] == pytest.approx(s.phidot0, abs=1e-12) and r[-1] == pytest.approx(s.phidot0, abs=1e-8)
        assert ha.get_color() == lp.n_color(s.n) and f"$N$ = {s.n}" in ha.get_label()
    assert "relative to the synodic frame" in a_rate.get_ylabel() and "orbital periods" in a_ang.get_xlabel()
    fig2 = lp.plot_attitude_motion(sols[2], n_periods=2, rate="inertial", degrees=False)
    a2, r2 = fig2.axes
    (h,) = gid(a2, "angle")
    assert h.get_xdata()[-1] == pytest.approx(2.0) and h.get_ydata()[-1] == pytest.approx(-4 * math.pi, abs=1e-7)
    assert gid(r2, "rate")[0].get_ydata()[-1] == pytest.approx(sols[2].wz0, abs=1e-7) and "inertial" in r2.get_ylabel()


@pytest.fixture(scope="module")
def unsolved(small_map, map_rates, em):
    return librate.periodicity_map(librate.dro_family(em, x0=[0.9, 0.8]), kz=0.8, wz0=map_rates, solve=False)


MAP_BAD = [
    (lambda m, u, o: lp.plot_residuals(o), "`ds`"),  # an orbit is not data: its map is computed first
    (lambda m, u, o: lp.plot_residuals(m, orbit_index=0, rate="synodic"), "`rate`"),
    (lambda m, u, o: lp.plot_residuals(m), "`orbit_index`"),
    (lambda m, u, o: lp.plot_residuals(m, orbit_index=0, kz=0.3), "`kz`"),
    (lambda m, u, o: lp.plot_residuals(m, orbit_index=9), "`orbit_index`"),
    (lambda m, u, o: lp.plot_residuals("map"), "`ds`"),
    (lambda m, u, o: lp.plot_map("map"), "`ds`"),
    (lambda m, u, o: lp.plot_map(m, kz_index=1), "`kz_index`"),
    (lambda m, u, o: lp.plot_map(m, against="jacobi"), "`against`"),
    (lambda m, u, o: lp.plot_map(m, kinds=("quarter",)), "`kinds`"),
    (lambda m, u, o: lp.plot_map(m.isel(orbit=[0])), "`ds`"),
    (lambda m, u, o: lp.plot_map(m, plt.subplots(1, 2)[1]), "`ax`"),
    (lambda m, u, o: lp.plot_solution_families(u), "`ds`"),
    (lambda m, u, o: lp.plot_solution_families(m, n="one"), "`n`"),
    (lambda m, u, o: lp.plot_solution_families(m, max_jump=-1), "`max_jump`"),
    (lambda m, u, o: lp.plot_solution_families(m, n=(0, 1), ax=plt.subplots()[1]), "`ax`"),
    (lambda m, u, o: lp.plot_attitude_motion([]), "`solutions`"),
    (lambda m, u, o: lp.plot_attitude_motion(o), "`solutions`"),
    (lambda m, u, o: lp.plot_attitude_motion(librate.periodic_attitude(o, kz=0.8, n=0), n_periods=0), "`n_periods`"),
    (lambda m, u, o: lp.plot_attitude_motion(librate.periodic_attitude(o, kz=0.8, n=0), ax=plt.subplots()[1]), "`ax`"),
]


@pytest.mark.parametrize("call, text", MAP_BAD, ids=[f"{i}-{b[1].strip('`')}" for i, b in enumerate(MAP_BAD)])
def test_bad_arguments_attitude_figures(small_map, unsolved, dro1266, call, text):
    with pytest.raises(ValueError, match=text):
        call(small_map, unsolved, dro1266)


def test_plot_map_of_a_subset_of_orbits(small_map):
    """A map cut with ``isel(orbit=...)`` keeps its solutions on the right orbits (sol_orbit
    holds orbit labels, not positions)."""
    sub = small_map.isel(orbit=[3, 4, 5])
    ax = lp.plot_map(sub).axes[0]
    sel = np.isin(small_map.sol_orbit.values, [3, 4, 5]) & (small_map.sol_kind.values == "periodic")
    want = sorted(zip(small_map.period_days.values[small_map.sol_orbit.values[sel]], small_map.sol_phidot0.values[sel]))
    np.testing.assert_allclose([p[:2] for p in marker_points(ax)], want, atol=1e-12)
    ax = lp.plot_residuals(small_map.isel(orbit=[4])).axes[0]
    sel = (small_map.sol_orbit.values == 4)
    np.testing.assert_allclose(sorted(p[0] for p in marker_points(ax)), sorted(small_map.sol_phidot0.values[sel]), atol=1e-12)


# --- solar radiation pressure (thesis ch. 4, Figs. 33-41) ----------------------------------------
# The apparent solar period from the sidereal month and year (independent of librate.constants):
# the Sun direction turns clockwise in the synodic frame at -(1 - n_sun).
_N_SUN = 27.321661 / 365.25636
_OMEGA_SUN = -(1.0 - _N_SUN)
_TS = 2 * math.pi / (1.0 - _N_SUN)


@pytest.fixture(scope="module")
def fam_sun(em):
    """16 DROs, x0 = 0.90 ... 0.75: the 1:2, 1:3 and 1:4 Sun-resonant members inside."""
    return librate.dro_family(em, x0=np.arange(0.90, 0.745, -0.01))


@pytest.fixture(scope="module")
def sun12_orbit(fam_sun):
    return fam_sun.resonant(2, "sun")


@pytest.fixture(scope="module")
def eps_map(sun12_orbit):
    """1:2 Sun-resonant DRO, Kz = 0.6, Cs = 0.4, Cd = 0.1: 6 eps x 120 rates, with branches."""
    return lp.srp_map(sun12_orbit, kz=0.6, wz0=np.linspace(-1.25, 0.05, 120), eps=np.linspace(0.0, 0.5, 6), cs=0.4, cd=0.1)


def test_plot_sun_motion_fig33(em, tmp_path):
    """Thesis Fig. 33: each Sun-direction ray k points at omega_sun t_k + theta0 (t_k = k Ts / 8,
    omega_sun from the sidereal month and year), clockwise, the first at theta0; the angle curve
    equals omega_sun t + theta0 (deg) against t in days and falls by 360 deg per Ts = 29.49 d; a
    line at each multiple of Ts; the Earth-Moon line joins the primaries."""
    theta0 = 0.7
    fig = lp.plot_sun_motion(em, theta_sun0=theta0, n_periods=2)
    assert_png(fig, tmp_path / "fig33.png")
    a_geo, a_ang = fig.axes
    rays = gid(a_geo, "sun-direction")
    assert len(rays) == 8
    for k, h in enumerate(rays):
        (x0, x1), (y0, y1) = h.get_xdata(), h.get_ydata()
        assert x0 == y0 == 0.0
        want = _OMEGA_SUN * k * _TS / 8 + theta0
        assert abs(math.remainder(math.atan2(y1, x1) - want, 2 * math.pi)) < 1e-9
    ang = [math.atan2(h.get_ydata()[1], h.get_xdata()[1]) for h in rays]
    assert all(math.remainder(b - a, 2 * math.pi) < 0 for a, b in zip(ang, ang[1:]))  # clockwise
    suns = gid(a_geo, "sun")
    assert len(suns) == 8 and all(s.get_xdata()[0] == r.get_xdata()[1] for s, r in zip(suns, rays))
    (em_line,) = gid(a_geo, "earth-moon-line")
    np.testing.assert_allclose(em_line.get_xdata(), [-em.mu, 1 - em.mu], atol=1e-15)
    np.testing.assert_allclose(em_line.get_ydata(), [0.0, 0.0], atol=1e-15)
    (curve,) = gid(a_ang, "sun-angle")
    t_days, deg = np.asarray(curve.get_xdata()), np.asarray(curve.get_ydata())
    np.testing.assert_allclose(deg, np.degrees(_OMEGA_SUN * t_days / em.tu_days + theta0), rtol=0, atol=1e-9)
    ts_days = _TS * em.tu_days
    assert round(ts_days, 2) == 29.49 and t_days[-1] == pytest.approx(2 * ts_days, rel=1e-12)
    assert np.interp(ts_days, t_days, deg) == pytest.approx(math.degrees(theta0) - 360.0, abs=1e-6)
    np.testing.assert_allclose([v.get_xdata()[0] for v in gid(a_ang, "solar-period")], [ts_days, 2 * ts_days], rtol=1e-12)
    assert {h.get_ydata()[0] for h in gid(a_ang, "sun-beyond-moon")} == {0.0, -360.0}
    assert {h.get_ydata()[0] for h in gid(a_ang, "sun-behind-earth")} == {-180.0, -540.0}


def test_plot_sun_resonant_fig34(em, fam_sun, tmp_path):
    """Thesis Fig. 34: the 1:2, 1:3, 1:4 Sun-resonant DROs; each curve starts at (x0, 0), closes
    after its propagation time and crosses y = 0 once in between, and x0 is that of the DRO of
    period Ts / K found independently (continuation and a secant on the period, 1e-8); the 1:1
    member (29.49 d) is longer than any DRO and is named in the note."""
    fig = lp.plot_sun_resonant(fam_sun)
    assert_png(fig, tmp_path / "fig34.png")
    ax = fig.axes[0]
    assert not gid(ax, "sun-resonant-1")
    for k in (2, 3, 4):
        (h,) = gid(ax, f"sun-resonant-{k}")
        x, y = np.asarray(h.get_xdata()), np.asarray(h.get_ydata())
        assert y[0] == 0.0 and abs(x[-1] - x[0]) < 1e-8 and abs(y[-1]) < 1e-8
        assert np.count_nonzero(np.diff(np.sign(y[1:-1])) != 0) == 1
        o = dro_with_period(em, _TS / k, np.arange(0.90, 0.77, -0.01))  # secant on T(x0), continued independently
        assert x[0] == pytest.approx(o.x0, abs=1e-8)
        assert f"1:{k} Sun" in h.get_label() and f"{o.period_days:.2f} d" in h.get_label()
    (note,) = gid(ax, "missing-resonances")
    assert "1:1" in note.get_text() and "29.49" in note.get_text()
    with pytest.raises(ValueError, match="`ks`"):
        lp.plot_sun_resonant(fam_sun, ks=(1,))


def test_srp_map_solutions_and_plot_fig35(eps_map, sun12_orbit, tmp_path):
    """Thesis Figs. 35-36: over (eps, phidot0) on the 1:2 Sun-resonant DRO. The markers sit at
    (eps, phidot0) of the map's solutions, filled exactly for the stable ones; at eps = 0 they
    are the gravity-only solutions (phi0 = 0) and the Dphi = 0 contour passes through them (a
    vertex on the eps = 0 column within one rate step); solutions re-propagated independently
    with their plate over K = 2 revolutions repeat (1e-9); the branch lines hold the continuation
    points; each fold cross sits at its branch's end, where the monodromy trace is 2 (0.05)."""
    ds = eps_map
    assert ds.attrs["n_periods"] == 2 and ds.sizes["solution"] >= 10
    fig = lp.plot_srp_map(ds, reference=(0.25, "plate of A/m = 0.016"))
    assert_png(fig, tmp_path / "fig35.png")
    ax = fig.axes[0]
    pts = marker_points(ax)
    want = sorted(zip(ds.sol_eps.values, ds.sol_phidot0.values, ds.sol_stable.values))
    np.testing.assert_allclose([p[:2] for p in pts], [w[:2] for w in want], atol=1e-12)
    assert [p[2] for p in pts] == [bool(w[2]) for w in want]
    gravity = librate.find_periodic_attitudes(sun12_orbit, kz=0.6, wz0_range=(-1.25, 0.05), n_periods=2, kinds=("periodic",))
    at0 = (ds.sol_eps.values == 0.0) & np.isin(ds.sol_branch.values, np.flatnonzero(ds.branch_origin.values == "gravity"))
    np.testing.assert_allclose(np.sort(ds.sol_wz0.values[at0]), [s.wz0 for s in gravity], atol=1e-12)
    v = contour_vertices(ax, "contour-dphi")
    col = v[np.abs(v[:, 0]) < 1e-12, 1]
    step = ds.phidot0.values[1] - ds.phidot0.values[0]
    for s in gravity:
        assert np.min(np.abs(col - s.phidot0)) < step
    rng = np.random.default_rng(3)
    for i in rng.choice(ds.sizes["solution"], 4, replace=False):
        plate = librate.FlatPlate(float(ds.sol_eps.values[i]), cs=0.4, cd=0.1)
        phi0, wz0, n = float(ds.sol_phi0.values[i]), float(ds.sol_wz0.values[i]), int(ds.sol_n_total.values[i])
        T = 2 * sun12_orbit.period
        tr = librate.propagate_attitude(sun12_orbit.system, sun12_orbit.state0, (phi0, wz0), librate.RigidBody.from_kz(0.6), T,
                                        planar=True, srp=plate, rtol=1e-13, atol=1e-13, t_eval=[T])
        assert abs(tr.phi[-1] - phi0 - 2 * math.pi * n) < 1e-9 and abs(tr.wz[-1] - wz0) < 1e-9
    for b in range(ds.sizes["branch"]):
        sel = ds.path_branch.values == b
        lines = gid(ax, f"branch-{ds.branch_kind.values[b]}-N{float(ds.branch_n.values[b]):+g}")
        assert any(len(h.get_xdata()) == sel.sum() and np.array_equal(h.get_xdata(), ds.path_eps.values[sel])
                   and np.array_equal(h.get_ydata(), ds.path_wz0.values[sel] - 1.0) for h in lines)
    folds = gid(ax, "fold")
    assert len(folds) == int(ds.branch_fold.values.sum()) >= 2
    for b in np.flatnonzero(ds.branch_fold.values):
        sel = ds.path_branch.values == b
        e = ds.path_eps.values[sel]
        end = e[np.argmax(np.abs(e - ds.branch_start_eps.values[b]))]  # the point farthest from the branch's start
        assert abs(end - ds.branch_end_eps.values[b]) < 1e-6
        assert abs(ds.path_trace.values[sel][np.argmax(np.abs(e - ds.branch_start_eps.values[b]))] - 2.0) < 0.05
        assert any(abs(f.get_xdata()[0] - ds.branch_end_eps.values[b]) < 1e-12 for f in folds)
    (ref,) = gid(ax, "eps-reference")
    assert ref.get_xdata()[0] == 0.25
    assert "plate of A/m = 0.016" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert ax.get_xlim() == (0.0, 0.5) and "relative to the synodic frame" in ax.get_ylabel()


def test_srp_map_without_solutions(sun12_orbit):
    ds = lp.srp_map(sun12_orbit, kz=0.6, wz0=np.linspace(-1.0, 0.0, 30), eps=[-0.1, 0.0, 0.1], solve=False)
    assert ds.dwz.shape == (3, 30) and "sol_wz0" not in ds.variables and ds.attrs["n_periods"] == 2
    ax = lp.plot_srp_map(ds, rate="inertial").axes[0]
    assert not gid(ax, "solutions") and "inertial" in ax.get_ylabel() and ax.get_xlim() == (-0.1, 0.1)


@pytest.fixture(scope="module")
def srp_pair(sun12_orbit):
    g = librate.periodic_attitude(sun12_orbit, kz=0.6, n=0, n_periods=2, wz0=1 - 0.066)
    s = librate.continue_srp(g, librate.FlatPlate(0.1, cs=0.4, cd=0.1)).solutions[-1]
    return g, s


def test_plot_srp_comparison_fig37_38(srp_pair, tmp_path):
    """Thesis Figs. 37-38: the curves span K = 2 revolutions and end at phi(KT), wz(KT) of an
    independent propagation of each solution (1e-8), which are phi0 + 2 pi N and wz0 (periodic)."""
    g, s = srp_pair
    assert s.srp.eps == 0.1 and g.srp is None and s.n_periods == 2
    fig = lp.plot_srp_comparison(g, s)
    assert_png(fig, tmp_path / "fig37.png")
    a_ang, a_rate = fig.axes
    for key, sol in (("gravity", g), ("srp", s)):
        T = 2 * sol.orbit.period
        tr = librate.propagate_attitude(sol.orbit.system, sol.orbit.state0, (sol.phi0, sol.wz0), librate.RigidBody.from_kz(sol.kz),
                                        T, planar=True, srp=sol.srp, rtol=1e-13, atol=1e-13, t_eval=[T])
        (ha,) = gid(a_ang, f"{key}-angle")
        (hr,) = gid(a_rate, f"{key}-rate")
        assert ha.get_xdata()[-1] == pytest.approx(2.0, abs=1e-12)
        assert ha.get_ydata()[-1] == pytest.approx(math.degrees(tr.phi[-1]), abs=1e-7)
        assert hr.get_ydata()[-1] == pytest.approx(tr.wz[-1] - 1.0, abs=1e-9)
        assert ha.get_ydata()[-1] == pytest.approx(math.degrees(sol.phi0 + 2 * math.pi * sol.n), abs=1e-6)
        assert hr.get_ydata()[0] == pytest.approx(sol.phidot0, abs=1e-12)
    assert "0.1" in gid(a_ang, "srp-angle")[0].get_label() and "gravity only" in gid(a_ang, "gravity-angle")[0].get_label()
    fig2 = lp.plot_srp_comparison(g, s, n_periods=4, rate="inertial", degrees=False)
    (h,) = gid(fig2.axes[1], "srp-rate")
    assert h.get_xdata()[-1] == pytest.approx(4.0) and h.get_ydata()[-1] == pytest.approx(s.wz0, abs=1e-8)
    assert len(gid(fig2.axes[0], "repeat")) == 2


def test_plot_sun_pointing_fig39(em, sun12_orbit, tmp_path):
    """Thesis Fig. 39, phi(t) = theta_s(t) + offset: at sample times the curves equal the gravity
    gradient 1.5 Kz (S cos 2phi - C sin 2phi) (S, C of the orbit's forcing) and the plate's SRP
    eps [(1 + Cs) cos a |cos a| + 2/3 Cd cos a], a = -offset, written out here; their sum is the
    engine's angular acceleration (finite difference of a short propagation from the pointing
    state); a two-sided facet panel of the same geometry gives the same SRP curve."""
    from librate.periodicity import orbit_forcing

    sun = librate.Sun(theta0=0.4)
    plate = librate.FlatPlate(0.3, cs=0.4, cd=0.1, sun=sun)
    offset, kz = 0.2, 0.6
    fig = lp.plot_sun_pointing(em, plate, orbit=sun12_orbit, kz=kz, offset=offset)
    assert_png(fig, tmp_path / "fig39.png")
    ax = fig.axes[0]
    (hg,) = gid(ax, "gravity-gradient")
    (hs,) = gid(ax, "srp")
    (ht,) = gid(ax, "total")
    t = np.asarray(hg.get_xdata()) / em.tu_days
    assert t[-1] == pytest.approx(2 * sun12_orbit.period, rel=1e-12)  # default: ceil(Ts / T) = 2 periods
    idx = np.array([0, 137, 911, len(t) - 1])
    S, C = orbit_forcing(sun12_orbit).sc(t[idx])
    phi = _OMEGA_SUN * t[idx] + 0.4 + offset
    np.testing.assert_allclose(np.asarray(hg.get_ydata())[idx], 1.5 * kz * (S * np.cos(2 * phi) - C * np.sin(2 * phi)), atol=1e-12)
    ca = math.cos(-offset)
    srp = 0.3 * ((1 + 0.4) * ca * abs(ca) + 2 / 3 * 0.1 * ca)
    np.testing.assert_allclose(np.asarray(hs.get_ydata())[idx], srp, atol=1e-12)
    np.testing.assert_allclose(ht.get_ydata(), np.asarray(hg.get_ydata()) + np.asarray(hs.get_ydata()), atol=1e-15)
    h = 1e-4
    tr = librate.propagate_attitude(em, sun12_orbit.state0, (0.4 + offset, 1.0 + _OMEGA_SUN), librate.RigidBody.from_kz(kz), h,
                                    planar=True, srp=plate, rtol=1e-13, atol=1e-13, t_eval=[0.0, h])
    assert (tr.wz[-1] - tr.wz[0]) / h == pytest.approx(ht.get_ydata()[0], abs=1e-3)
    # the facet model of the same plate: the same SRP acceleration
    area, d, iz = 100.0, 0.02, 1.0e7
    ix, iy = 0.5 * (1 - kz) * iz, 0.5 * (1 + kz) * iz
    body = librate.FacetBody.two_sided_panel(area, center=(0, d, 0), ca=0.5, cs=0.4, cd=0.1, inertia=(ix, iy, iz))
    plate2 = librate.FlatPlate.from_geometry(em, area_m2=area, offset_m=d, iz_kgm2=iz, cs=0.4, cd=0.1, sun=sun)
    gg_p, srp_p = lp.sun_pointing_accelerations(em, plate2, t[idx], orbit=sun12_orbit, offset=offset, kz=kz)
    gg_b, srp_b = lp.sun_pointing_accelerations(em, body, t[idx], orbit=sun12_orbit, offset=offset, sun=sun)
    np.testing.assert_allclose(srp_b, srp_p, rtol=1e-12)
    np.testing.assert_allclose(gg_b, gg_p, rtol=1e-12, atol=1e-15)
    ax2 = lp.plot_sun_pointing(em, body, orbit=sun12_orbit, offset=offset, sun=sun, n_periods=1, units="TU").axes[0]
    assert gid(ax2, "srp")[0].get_xdata()[-1] == pytest.approx(sun12_orbit.period)


def test_plot_srp_maps_fig40_41(eps_map, sun12_orbit, kz_map, tmp_path):
    """Thesis Figs. 40-41: one panel per map, titled with the value that differs (Cs, or Kz), each
    holding its own map's solutions, the legend beside the last panel only; periodicity_map
    Datasets are drawn by plot_map. With Cd = 0 the plate's torque is eps (1 + Cs) cos|cos|: the
    fold of the stable N = 0 branch on the Cs = 0 panel lies at 1.5 times its eps on the Cs = 0.5
    panel (1e-5)."""
    maps = [lp.srp_map(sun12_orbit, kz=0.6, wz0=np.linspace(0.8, 1.1, 40), eps=[0.0, 0.5, 1.0], cs=c, cd=0.0) for c in (0.0, 0.5)]
    fig = lp.plot_srp_maps(maps, reference=0.7)
    assert_png(fig, tmp_path / "fig40.png")
    a1, a2 = fig.axes
    assert a1.get_title() == "$C_s$ = 0" and a2.get_title() == "$C_s$ = 0.5"
    assert a1.get_legend() is None and a2.get_legend() is not None
    for a, m in zip((a1, a2), maps):
        assert len(marker_points(a)) == m.sizes["solution"] > 0 and gid(a, "eps-reference")
    (f1,), (f2,) = gid(a1, "fold"), gid(a2, "fold")
    assert f1.get_xdata()[0] / f2.get_xdata()[0] == pytest.approx(1.5, rel=1e-5)
    assert "$K_z$ = 0.6" in fig._suptitle.get_text() and "$C_d$ = 0" in fig._suptitle.get_text()
    fig = lp.plot_srp_maps([kz_map.isel(kz=[0]), kz_map.isel(kz=[2])], reference=0.1, against="x0")  # reference: SRP maps only
    b1, b2 = fig.axes
    assert b1.get_title() == "$K_z$ = 0.2" and b2.get_title() == "$K_z$ = 0.8"
    sel = (kz_map.sol_kz.values == 0.8) & (kz_map.sol_kind.values == "periodic")
    assert len(marker_points(b2)) == int(sel.sum())
    fig = lp.plot_srp_maps([eps_map], titles=["one"])
    assert fig.axes[0].get_title() == "one" and len(marker_points(fig.axes[0])) == eps_map.sizes["solution"]


SRP_BAD = [
    (lambda m, o: lp.plot_sun_motion("earth-moon"), "`system`"),
    (lambda m, o: lp.plot_sun_motion(o.system, theta_sun0=math.nan), "`theta_sun0`"),
    (lambda m, o: lp.plot_sun_motion(o.system, n_periods=0), "`n_periods`"),
    (lambda m, o: lp.plot_sun_motion(o.system, n_directions=0), "`n_directions`"),
    (lambda m, o: lp.plot_sun_motion(o.system, ax=plt.subplots()[1]), "`ax`"),
    (lambda m, o: lp.plot_sun_resonant(o), "`family`"),
    (lambda m, o: lp.plot_sun_resonant(librate.dro_family(o.system, x0=[0.9, 0.8]), ks=(0,)), "`ks`"),
    (lambda m, o: lp.srp_map(o, kz=0.6, wz0=[0.0, 1.0], eps=[0.1, 0.0]), "`eps`"),
    (lambda m, o: lp.srp_map(o, kz=0.6, wz0=[1.0, 0.0], eps=[0.0, 0.1]), "`wz0`"),
    (lambda m, o: lp.srp_map(o, kz=2.0, wz0=[0.0, 1.0], eps=[0.0, 0.1]), "`kz`"),
    (lambda m, o: lp.srp_map(o, kz=0.6, wz0=[0.0, 1.0], eps=[0.0, 0.1], cs=0.8, cd=0.5), "`cs`"),
    (lambda m, o: lp.srp_map(librate.correct_dro(o.system, 0.85), kz=0.6, wz0=[0.0, 1.0], eps=[0.0, 0.1]), "`n_periods`"),
    (lambda m, o: lp.plot_srp_map("map"), "`ds`"),
    (lambda m, o: lp.plot_srp_map(m, rate="synodic"), "`rate`"),
    (lambda m, o: lp.plot_srp_map(m, reference="x"), "`reference`"),
    (lambda m, o: lp.plot_srp_maps([]), "`maps`"),
    (lambda m, o: lp.plot_srp_maps([m, "map"]), "`maps`"),
    (lambda m, o: lp.plot_srp_maps([m, m], titles=["a"]), "`titles`"),
    (lambda m, o: lp.plot_srp_maps([m, m], ax=plt.subplots()[1]), "`ax`"),
    (lambda m, o: lp.plot_srp_maps([m, m], colour="red"), "`colour`"),
    (lambda m, o: lp.plot_srp_comparison("g", "s"), "`gravity_solution`"),
    (lambda m, o: lp.plot_srp_comparison(librate.periodic_attitude(o, kz=0.6, n=0, n_periods=2),
                                         librate.periodic_attitude(librate.dro(o.system, period_days=12.66), kz=0.8, n=0)),
     "`srp_solution`"),
    (lambda m, o: lp.plot_sun_pointing(o.system, librate.FlatPlate(0.1), orbit=o), "`kz`"),
    (lambda m, o: lp.plot_sun_pointing(o.system, librate.RigidBody(1, 2, 2.5), orbit=o), "`body_or_plate`"),
    (lambda m, o: lp.plot_sun_pointing(o.system, librate.FlatPlate(0.1), orbit=o, kz=0.5, sun=librate.Sun()), "`sun`"),
    (lambda m, o: lp.plot_sun_pointing(o.system, librate.FlatPlate(0.1), orbit="dro", kz=0.5), "`orbit`"),
    (lambda m, o: lp.plot_sun_pointing(o.system, librate.FlatPlate(0.1), orbit=o, kz=0.5, n_periods=-1), "`n_periods`"),
    (lambda m, o: lp.plot_sun_pointing(o.system, librate.FacetBody.flat_plate(1.0, inertia=(1, 2, 2.5)), orbit=o, kz=0.5), "`kz`"),
]


@pytest.mark.parametrize("call, text", SRP_BAD, ids=[f"{i}-{b[1].strip('`')}" for i, b in enumerate(SRP_BAD)])
def test_bad_arguments_srp_figures(eps_map, sun12_orbit, call, text):
    with pytest.raises(ValueError, match=text):
        call(eps_map, sun12_orbit)


def test_solution_legend_prints_integer_n():
    """Issue 23 #7: ``sol_n`` stored as float64 must not show as "4.0" in a legend; exact
    string check on the legend labels (no tolerance)."""
    from librate.plotting import _style

    labels = [h.get_label() for h in _style.solution_legend(np.array([4.0, 13.0, 7.0, 0.0]),
                                                            np.array(["periodic"] * 4), np.array([True] * 4))]
    assert "other $N$ (4 ... 13)" in labels and "$N$ = 0" in labels
    assert not any(".0" in lab for lab in labels)


def test_map_sol_n_is_integer_and_keeps_its_attributes(small_map):
    """Issue 23 #7: N is a whole number of turns per period with n_periods=1, so the map stores
    ``sol_n`` as an integer dtype (exact: equal to each AttitudeSolution's ``n_total``), keeps its
    long_name, and the Fig. 24 legend prints it without a decimal point."""
    n = small_map["sol_n"]
    assert n.dtype.kind == "i" and n.attrs["long_name"] == "net body turns per orbit period"
    assert np.array_equal(n.values, small_map["sol_n_total"].values)
    from librate.periodicity.solutions import turns_array

    assert turns_array([1, 0.5]).dtype == np.float64 and turns_array([]).dtype == np.int64  # n_total / K not whole: float
    fig = lp.plot_map(small_map)
    labels = [t.get_text() for a in fig.axes if a.get_legend() for t in a.get_legend().get_texts()]
    ns = [lab for lab in labels if lab.startswith("$N$ =")]
    assert ns and not any(".0" in lab for lab in ns)


def test_one_colour_per_n_in_families_and_solve_scatter(kz_map, small_map, tmp_path):
    """Issue 23 #7: the solution-family lines are coloured by N (``n_color``, exact RGBA), Kz
    told by line style; the CLI's ``solve`` scatter colours each N as the map figures do and
    marks periodic (circle) and half-turn (diamond) motions apart, filled exactly when stable
    (``lp.plot_solution_scatter``, the figure the CLI draws)."""
    from matplotlib.colors import to_rgba

    fig = lp.plot_solution_families(kz_map, n=(1, 0, -1))
    for a in fig.axes:
        lines = [h for h in a.get_lines() if (h.get_gid() or "").startswith("family-periodic-")]
        assert lines
        for h in lines:
            n = int(h.get_gid().split("-N")[1].split("-kz")[0])
            assert to_rgba(h.get_color()) == to_rgba(lp.n_color(n))
        styles = {h.get_gid().split("-kz")[1]: h.get_linestyle() for h in lines}
        assert len(set(styles.values())) == len(styles)  # one line style per Kz

    ds = small_map
    sols = ds[[v for v in ds.data_vars if v.startswith("sol_")]].drop_vars("orbit", errors="ignore")
    sols["sol_x0"] = ("solution", ds.x0.values[ds.sol_orbit.values])
    fig = lp.plot_solution_scatter(sols)
    assert_png(fig, tmp_path / "solve_solutions.png")
    ax = fig.axes[0]
    pts = np.column_stack([sols.sol_x0.values, sols.sol_phidot0.values])
    nverts = {}
    seen = 0
    for c in gid(ax, "solutions"):
        off = c.get_offsets()
        idx = [int(np.flatnonzero(np.all(np.isclose(pts, p, rtol=0, atol=1e-14), axis=1))[0]) for p in off]
        seen += len(idx)
        (n,), (kind,), (stable,) = ({v.item() for v in sols[k].values[idx]} for k in ("sol_n", "sol_kind", "sol_stable"))
        assert tuple(c.get_edgecolor()[0]) == to_rgba(lp.n_color(n))
        face = c.get_facecolor()
        assert (len(face) and tuple(face[0]) == to_rgba(lp.n_color(n))) if stable else (not len(face) or face[0][3] == 0)
        nverts.setdefault(str(kind), set()).add(len(c.get_paths()[0].vertices))
    assert seen == sols.sizes["solution"]
    assert set(nverts) == {"periodic", "half-turn"} and not nverts["periodic"] & nverts["half-turn"]


def test_example_03_legend_tells_gravity_from_srp(tmp_path, monkeypatch):
    """Issue 23 #7: example 03's figure (run in-process, Agg) labels the gravity-only and the
    SRP motion apart in each panel's legend (exact label prefixes, the SRP one with its eps)."""
    import runpy
    from pathlib import Path

    figs = []
    save = lp.save_figure
    monkeypatch.setattr(lp, "save_figure", lambda fig, path, **kw: (figs.append(fig), save(fig, path))[1])
    monkeypatch.setattr(sys, "argv", ["03_srp_solution.py", str(tmp_path)])
    runpy.run_path(str(Path(__file__).resolve().parents[1] / "examples" / "03_srp_solution.py"), run_name="__main__")
    (fig,) = figs
    assert_png(fig, tmp_path / "srp" / "srp_motion.png")
    for a in fig.axes:
        labels = [t.get_text() for t in a.get_legend().get_texts()]
        assert sum(lab.startswith("gravity only:") for lab in labels) == 1
        assert sum(lab.startswith("SRP $\\varepsilon$ = 0.02:") for lab in labels) == 1
