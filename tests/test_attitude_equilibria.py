"""Equilibrium attitudes at the collinear Lagrange points (issue 15, item 3): the linearisation of
the Rust 3-D model (exact Jacobian) against the closed-form characteristic polynomial derived in
docs/physics/attitude-equilibria.md, and the stability diagram against the classical one of
Robinson (1974, Celest. Mech. 10, 17-33; thesis Fig. 19) and Kane & Marsh (1971, Celest. Mech. 4,
78-90)."""

import itertools

import librate
import numpy as np
import pytest
from librate.attitude.equilibria import closed_form_eigenvalues, moments_from_ratios
from scipy.spatial.transform import Rotation

IZ = 96.95e6  # thesis Table 3, kg m^2


def match(a, b):
    """Largest distance between two sets of complex numbers paired greedily (nearest first)."""
    b = list(b)
    worst = 0.0
    for z in sorted(a, key=lambda z: (z.imag, z.real)):
        k = int(np.argmin([abs(z - w) for w in b]))
        worst = max(worst, abs(z - b.pop(k)))
    return worst


def grid():
    """Robinson's ratios on a 9 x 9 grid of the open square, skipping the points where two
    eigenvalues nearly coincide (a double root is ill-conditioned: a perturbation eps moves it by
    sqrt(eps), so the 1e-10 comparison is meaningless there)."""
    ks = np.linspace(-0.95, 0.95, 9) + 0.013  # off the axes, where K1 K2 = 0 gives double zeros
    yield from itertools.product(ks, ks)


@pytest.mark.parametrize("point", [1, 2, 3])
def test_eigenvalues_match_the_closed_form(em, point):
    """The six eigenvalues of the linearised Rust model equal the roots of the closed-form
    polynomial (s^2 + 3 sigma K3)(s^4 + (1 + 3 sigma K2 + K1 K2) s^2 + (1 + 3 sigma) K1 K2) to
    1e-10 over a grid of inertia ratios; the equilibrium residual is at rounding level."""
    checked = 0
    for kx, ky in grid():
        ix, iy, iz = (float(v) for v in moments_from_ratios(kx, ky))
        e = librate.attitude_equilibrium(em, point, librate.RigidBody(ix, iy, iz))
        ref = closed_form_eigenvalues(e.sigma, (ix, iy, iz))
        gaps = np.abs(ref[:, None] - ref[None, :]) + np.eye(6)
        if gaps.min() < 1e-3:
            continue
        assert e.residual < 1e-14
        assert match(e.eigenvalues, ref) < 1e-10, (kx, ky)
        checked += 1
    assert checked > 60


@pytest.mark.parametrize("point", [1, 2, 3])
def test_permuted_axes_use_the_moments_about_the_synodic_axes(em, point):
    """Any signed permutation of the body axes onto the synodic axes is an equilibrium; its
    eigenvalues are those of the closed form with the moments about the synodic X, Y, Z (to
    1e-10). The body x axis on synodic Z (a quarter turn about y) swaps the roles of Ix and Iz."""
    body = librate.RigidBody(40.39e6, 72.71e6, IZ)
    for rotvec in ([0, 0.5 * np.pi, 0], [0.5 * np.pi, 0, 0], [0, 0, 0.5 * np.pi], [np.pi, 0, 0]):
        q = Rotation.from_rotvec(rotvec).as_quat()
        e = librate.attitude_equilibrium(em, point, body, q0=q)
        a = Rotation.from_quat(q).as_matrix()  # body -> synodic
        moments = np.diag(a @ np.diag(body.moments) @ a.T)
        np.testing.assert_allclose(e.moments_synodic, moments, rtol=1e-12)
        assert match(e.eigenvalues, closed_form_eigenvalues(e.sigma, moments)) < 1e-10
        np.testing.assert_allclose(e.w0, a.T @ [0, 0, 1], atol=1e-15)  # turning with the frame


def test_h_is_the_thesis_table4(em):
    """Thesis Table 4: h = 3 sigma = 15.44, 9.57, 3.03 at L1, L2, L3 (to its two decimals)."""
    body = librate.RigidBody(12.12e6, 89.68e6, IZ)
    for point, h in ((1, 15.44), (2, 9.57), (3, 3.03)):
        assert librate.attitude_equilibrium(em, point, body).h == pytest.approx(h, abs=0.006)


@pytest.mark.parametrize("point", [1, 2, 3])
def test_classical_regions(em, point):
    """The classical diagram (Kane & Marsh 1971, Robinson 1974; thesis Fig. 19 at L1): the
    Lagrange region Iz > Iy > Ix (pitch axis the major one, roll-yaw K1, K2 > 0) is stable at every
    collinear point; Iy < Ix (K3 < 0) is unstable in pitch; K1 K2 < 0 diverges in roll-yaw. The
    thesis's Fig. 20 body (Lagrange region) and Fig. 21 body (the thin strip below k_y = 0, the
    DeBra-Delp-like region) are stable at L1."""
    ds = librate.equilibrium_stability(em, point, n=201)
    kx, ky = np.meshgrid(ds.k_x.values, ds.k_y.values)
    ix, iy, iz = moments_from_ratios(kx, ky)
    stable = ds.stable.values
    lagrange = (iz > iy) & (iy > ix)
    assert np.all(stable[lagrange])
    assert not np.any(stable[iy < ix])
    assert not np.any(stable[kx * ky > 0])  # K1 K2 = -k_x k_y < 0
    # the strip below k_y = 0 exists, is thin, and shrinks as h grows (L3 -> L2 -> L1)
    strip = stable & (ky < 0)
    assert 0 < strip.mean() < 0.05
    if point == 1:
        for ix_, iy_ in ((12.12e6, 89.68e6), (97.77e6, 140.13e6)):
            assert librate.attitude_equilibrium(em, 1, librate.RigidBody(ix_, iy_, IZ)).stable


def test_strip_shrinks_with_h(em):
    """The roll-yaw strip (K1, K2 < 0) narrows as h = 3 sigma grows: L3 (h = 3.03, close to the
    circular-orbit DeBra-Delp case h = 3) has the widest, L1 the narrowest."""
    area = [(librate.equilibrium_stability(em, p, n=201).stable.values & (np.arange(201)[:, None] < 100)).mean() for p in (1, 2, 3)]
    assert area[0] < area[1] < area[2]


@pytest.mark.parametrize("point", [1, 2, 3])
def test_diagram_agrees_with_the_linearised_model(em, point):
    """The diagram's closed-form classification agrees with the stability of the Rust model's
    linearisation at every grid point clearly inside a region (largest real part > 1e-3, or
    stable with eigenvalues separated by > 1e-3)."""
    ds = librate.equilibrium_stability(em, point, n=25)
    for j, ky in enumerate(ds.k_y.values):
        for i, kx in enumerate(ds.k_x.values):
            ix, iy, iz = (float(v) for v in moments_from_ratios(kx, ky))
            e = librate.attitude_equilibrium(em, point, librate.RigidBody(ix, iy, iz))
            mr = float(ds.max_real.values[j, i])
            assert abs(np.max(np.abs(e.eigenvalues.real)) - mr) < 1e-8
            ref = closed_form_eigenvalues(e.sigma, (ix, iy, iz))
            gap = (np.abs(ref[:, None] - ref[None, :]) + np.eye(6)).min()
            if mr > 1e-3 or gap > 1e-3:
                assert e.stable == bool(ds.stable.values[j, i]), (kx, ky)


def test_invalid_arguments(em):
    body = librate.RigidBody(1.0, 2.0, 2.5)
    with pytest.raises(ValueError, match="point"):
        librate.attitude_equilibrium(em, 4, body)
    with pytest.raises(ValueError, match="q0"):
        librate.attitude_equilibrium(em, 1, body, q0=Rotation.from_rotvec([0.1, 0, 0]).as_quat())
    with pytest.raises(ValueError, match="body"):
        librate.attitude_equilibrium(em, 1, librate.RigidBody.from_kz(1.0))
    with pytest.raises(ValueError, match="k_range"):
        librate.equilibrium_stability(em, 1, k_range=(0.5, -0.5))


def test_stability_figure(em):
    """The figure draws the stable regions and the three boundaries, labelled by gid."""
    import matplotlib

    matplotlib.use("Agg")
    import librate.plotting as lp
    import matplotlib.pyplot as plt

    fig = lp.plot_equilibrium_stability(librate.equilibrium_stability(em, 2, n=81))
    gids = {a.get_gid() for a in fig.axes[0].get_children()}
    assert {"stable", "boundary-k1k2", "boundary-flutter", "boundary-pitch"} <= gids
    plt.close(fig)
    with pytest.raises(ValueError, match="ds"):
        lp.plot_equilibrium_stability(object())
