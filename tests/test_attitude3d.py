"""Periodic 3-D attitude motions (issue 15, item 1): the planar embedding (thesis Fig. 23), the
torque-free sphere's closed-form monodromy, the symplectic structure of the multipliers, and
independent re-propagation; the out-of-plane stability of planar motions (item 2)."""

import ast
import math

import librate
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation


@pytest.fixture(scope="module")
def dro(em):
    """The 12.66-day DRO of thesis Fig. 23."""
    return librate.dro(em, period_days=12.66)


@pytest.fixture(scope="module")
def planar_n_minus_1(dro):
    return librate.periodic_attitude(dro, kz=0.8, n=-1)


def reciprocal_gap(m):
    """A symplectic monodromy's multipliers come in pairs (m, 1/m): the largest, over the
    multipliers z, of min over the others m of |z m - 1| (the product form, which stays meaningful
    when |z| is large or small)."""
    m = np.asarray(m)
    return max(np.min(np.abs(z * np.delete(m, i) - 1)) for i, z in enumerate(m))


def bracketed_changes(ds) -> list:
    """The family's listed stability changes (at least one), each checked against its two
    members: their counts of multipliers on the unit circle (to 1e-6) are the listed ones.
    Returns (change, (period before, period after)) pairs."""
    changes = ast.literal_eval(ds.attrs["stability_changes"])
    assert changes
    on_circle = {round(float(p), 9): int(np.sum(np.abs(np.abs(m) - 1) < 1e-6))
                 for p, m in zip(ds.period_days.values, ds.multipliers.values)}
    out = []
    for c in changes:
        a, b = (round(float(p), 9) for p in c["between"])
        assert (on_circle[a], on_circle[b]) == tuple(c["on_unit_circle"])
        out.append((c, (a, b)))
    return out


def test_planar_embedding_fig23(dro, planar_n_minus_1):
    """Thesis Fig. 23 (12.66-day DRO, Kz = 0.8, N = -1): started from the planar solution, the 3-D
    corrector returns it (wz0 to 1e-10, q0 a rotation about z, w0 along z); its in-plane
    multiplier pair equals the planar 2x2 monodromy's to 1e-8; multipliers come in reciprocal
    pairs (1e-8); the independent re-propagation repeats to 1e-9; one turn backwards."""
    p = planar_n_minus_1
    s = librate.periodic_attitude_3d(dro, librate.RigidBody.from_kz(0.8), guess=p)
    assert s.w0[2] == pytest.approx(p.wz0, abs=1e-10)
    assert np.max(np.abs(s.q0[:2])) < 1e-12 and np.max(np.abs(s.w0[:2])) < 1e-12
    assert s.phi0 == pytest.approx(p.phi0, abs=1e-10)
    assert s.planar
    np.testing.assert_allclose(np.sort_complex(s.in_plane_multipliers), np.sort_complex(p.multipliers.astype(complex)), atol=1e-8)
    assert reciprocal_gap(s.multipliers) < 1e-8
    assert s.residual < 1e-9
    assert s.turns == pytest.approx(-1.0, abs=1e-9)


def test_perturbed_guess_returns_to_the_planar_solution(dro, planar_n_minus_1):
    """A guess tilted by ~0.03 rad out of the plane with out-of-plane rates of 1e-3 converges
    back onto the Fig. 23 solution (wz0 to 1e-10, no tilt left)."""
    p = planar_n_minus_1
    q = Rotation.from_rotvec([0.02, -0.015, 0.01]).as_quat()
    s = librate.periodic_attitude_3d(dro, librate.RigidBody.from_kz(0.8), guess=(q, [1e-3, -2e-3, p.wz0 + 1e-3]))
    assert s.w0[2] == pytest.approx(p.wz0, abs=1e-10)
    assert np.max(np.abs(s.q0[:2])) < 1e-10 and np.max(np.abs(s.w0[:2])) < 1e-10
    assert s.iterations >= 1 and s.residual < 1e-9


@pytest.mark.parametrize("n", [-1, 0, 2])
def test_torque_free_sphere_closed_form(dro, n):
    """A sphere feels no torque: w is constant in body axes, and the periodic motions are the
    spins w = (1 + 2 pi N / T) e_Z (inertial), at any attitude. The linearised motion is
    theta' = -w x theta + dw, dw' = 0, so the monodromy is expm([[-[w x] T, T I], [0, 0]]) (a tilted
    spin axis, fixed in inertial space, turns by -T per orbit in the synodic frame). The computed
    monodromy matches it to 1e-10, and the multipliers are exp(+-i T) and four 1s: all 1 only
    when T is a multiple of 2 pi (it is not: T = 2.93)."""
    T = dro.period
    wz = 1 + 2 * math.pi * n / T
    q = Rotation.from_rotvec([0.1, -0.05, 0.2]).as_quat()
    guess_w = Rotation.from_quat(q).as_matrix().T @ [0.0, 1e-3, wz]
    s = librate.periodic_attitude_3d(dro, librate.RigidBody(1.0, 1.0, 1.0), guess=(q, guess_w))
    np.testing.assert_allclose(Rotation.from_quat(s.q0).as_matrix() @ s.w0, [0, 0, wz], atol=1e-12)
    w = s.w0
    wx = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    a = np.zeros((6, 6))
    a[:3, :3] = -wx * T
    a[:3, 3:] = T * np.eye(3)
    assert np.max(np.abs(s.monodromy - expm(a))) < 1e-10
    for z in (np.exp(1j * T), np.exp(-1j * T)):
        assert np.min(np.abs(s.multipliers - z)) < 1e-10
    assert np.sum(np.abs(s.multipliers - 1) < 1e-6) == 4
    assert abs(np.exp(1j * T) - 1) > 0.1
    assert s.residual < 1e-9


def test_spatial_halo_solution(em):
    """A 3-D periodic motion along the 13-day southern L2 halo (body 0.8 : 0.9 : 1, N = -1,
    started from the torque-free rate): converged, re-propagated independently to 1e-9,
    multipliers in reciprocal pairs to 1e-8, one turn backwards about Z."""
    h = librate.halo(em, 2, "south", period_days=13.0)
    T = h.period
    s = librate.periodic_attitude_3d(h, librate.RigidBody(0.8, 0.9, 1.0), guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / T]))
    assert s.residual < 1e-9
    assert reciprocal_gap(s.multipliers) < 1e-8
    assert s.turns == pytest.approx(-1.0, abs=1e-9)
    assert not s.planar and s.in_plane_multipliers is None


def test_invalid_arguments(dro, planar_n_minus_1):
    body = librate.RigidBody.from_kz(0.8)
    with pytest.raises(ValueError, match="guess"):
        librate.periodic_attitude_3d(dro, body, guess=([0, 0, 0, 2.0], [0, 0, 1]))
    with pytest.raises(ValueError, match="guess"):
        librate.periodic_attitude_3d(dro, body, guess="x")
    with pytest.raises(ValueError, match="n_periods"):
        librate.periodic_attitude_3d(dro, body, guess=planar_n_minus_1, n_periods=2)
    with pytest.raises(ValueError, match="body"):
        librate.periodic_attitude_3d(dro, librate.RigidBody.from_kz(1.0), guess=planar_n_minus_1)
    with pytest.raises(ValueError, match="tol"):
        librate.periodic_attitude_3d(dro, body, guess=planar_n_minus_1, tol=-1)
    with pytest.raises(librate.ConvergenceError):
        librate.periodic_attitude_3d(dro, body, guess=([0, 0, 0, 1.0], [0.0, 0.0, 5.0]), max_iter=2)


@pytest.fixture(scope="module")
def dro_family(em):
    return librate.dro_family(em)


@pytest.mark.parametrize("n", [1, 0, -1])
def test_out_of_plane_stability_across_the_dro_family(dro_family, n):
    """Thesis Figs. 27-29 (N = 1, 0, -1, Kz = 0.8, across the DRO family from x0 = 0.9): every
    member continued in the plane is a 3-D periodic motion of the Kz = 0.8 plate (re-propagated to
    1e-9). Its in-plane multipliers are those of the planar family (trace to 1e-8), and all six
    come in reciprocal pairs (1e-8). In every family some member is stable in the plane but
    unstable out of it in the N = 0 and N = -1 families (the roll/yaw block has a multiplier off the
    unit circle by more than 1e-3); along N = 1 the members stable in the plane are stable out of
    it too (on this range, every other member)."""
    from librate.periodicity import attitude_family, out_of_plane_family

    fam = attitude_family(dro_family, kz=0.8, n=n, start=0.9, direction=-1, max_points=60)
    ds = out_of_plane_family(dro_family, fam, every=2)
    assert ds.sizes["member"] == len(range(0, len(fam), 2))
    assert float(ds.residual.max()) < 1e-9
    np.testing.assert_allclose(ds.in_plane.values.sum(axis=1).real, ds.trace.values, atol=1e-8)
    for i in range(ds.sizes["member"]):
        m = np.concatenate([ds.in_plane.values[i], ds.out_of_plane.values[i]])
        assert reciprocal_gap(m) < 1e-8
    new = ds.stable_in_plane.values & (ds.out_of_plane_modulus.values > 1 + 1e-3)
    assert new.any() == (n != 1)
    assert ds.attrs["n"] == n and ds.attrs["kz"] == 0.8


def test_out_of_plane_figure(dro_family):
    """The figure shows each member's class (gid class-<in>-<out>) and the roll/yaw modulus."""
    import matplotlib

    matplotlib.use("Agg")
    import librate.plotting as lp
    import matplotlib.pyplot as plt
    from librate.periodicity import attitude_family, out_of_plane_family

    fam = attitude_family(dro_family, kz=0.8, n=0, start=0.9, direction=-1, max_points=12)
    ds = out_of_plane_family(dro_family, fam)
    fig = lp.plot_out_of_plane_stability([ds])
    gids = {ln.get_gid() for a in fig.axes for ln in a.get_lines()}
    assert "out-of-plane-modulus" in gids and any(g and g.startswith("class-") for g in gids)
    plt.close(fig)
    with pytest.raises(ValueError, match="datasets"):
        lp.plot_out_of_plane_stability([object()])
    with pytest.raises(ValueError, match="family"):
        out_of_plane_family(dro_family, librate.periodicity.attitude_family(dro_family.member(x0=0.9), kz=0.8, n=0, max_points=3))


@pytest.mark.slow
def test_family_along_the_l2_southern_halos_reaches_the_9_2_nrho(em):
    """Issue 15 acceptance (family): the motion of the body 0.8 : 0.9 : 1 on the 14-day L2
    southern halo corrected from the torque-free N = -1 rate, continued along the halo family in the
    period (pseudo-arclength on the bordered corrector, the default), reaches the 9:2 NRHO (6.56 days; Zimovan-Spreen et al. 2020). Every
    member repeats to 1e-9 on independent re-propagation (tol = 1e-10 for the close lunar passes),
    multipliers in reciprocal pairs (product form, 1e-7 at the NRHO's |m| ~ 50), and the
    stability changes are listed, each where the count of multipliers on the unit circle (to
    1e-6) changes between its two members. Which changes occur depends on the orbit's phase at
    t = 0: with state0 at the crossing in the branch's hemisphere (the JPL convention), this
    family has multipliers passing -1 near 9.1 days (with state0 at the other crossing it had
    two Krein collisions between 13.25 and 11 days)."""
    from librate.periodicity import attitude_family_3d

    hf = librate.halo_family(em, 2, "south")
    body = librate.RigidBody(0.8, 0.9, 1.0)
    h = hf.member(period_days=14.0)
    s = librate.periodic_attitude_3d(h, body, guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / h.period]))
    periods = np.r_[np.linspace(14.0, 6.75, 30), 6.7, 6.65, 6.6, 6.56]
    ds = attitude_family_3d(hf, body, guess=(s.q0, s.w0), period_days=periods, tol=1e-10)
    assert ds.attrs["end_reason"].startswith("completed")
    assert ds.sizes["member"] == periods.size
    assert ds.period_days.values[-1] == pytest.approx(6.56, abs=1e-9)
    assert float(ds.residual.max()) < 1e-9
    for m in ds.multipliers.values:
        assert reciprocal_gap(m) < 1e-7
    for c, (a, b) in bracketed_changes(ds):
        assert c["located"] and min(a, b) < c["at"] < max(a, b)
    # turns of the body x axis about synodic Z: whole numbers wherever defined (this family's
    # motions are tilted: the count depends on the tilt, 0, -1 or -2 along it)
    t = ds.turns.values[np.isfinite(ds.turns.values)]
    np.testing.assert_allclose(t, np.round(t), atol=1e-9)


def test_half_period_symmetric_form(em, dro, planar_n_minus_1):
    """The mirror-symmetric half-period form (3 unknowns, closure at T/2) finds the same
    solutions as the full form: on the Fig. 23 DRO (wz0 to 1e-10, full-period multipliers to
    1e-8) and on the 13-day L2 southern halo from a perturbed symmetric guess (q0, w0 to 1e-9,
    monodromy to 1e-8); both re-propagate to 1e-9. A guess that is not symmetric is refused."""
    body = librate.RigidBody.from_kz(0.8)
    p = planar_n_minus_1
    full = librate.periodic_attitude_3d(dro, body, guess=p)
    half = librate.periodic_attitude_3d(dro, body, guess=([0, 0, 0, 1.0], [0, 0, p.wz0 + 0.01]), symmetric=True)
    assert half.w0[2] == pytest.approx(p.wz0, abs=1e-10)
    assert np.max(np.abs(half.monodromy - full.monodromy)) < 1e-8
    assert half.residual < 1e-9

    h = librate.halo(em, 2, "south", period_days=13.0)
    b2 = librate.RigidBody(0.8, 0.9, 1.0)
    full = librate.periodic_attitude_3d(h, b2, guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / h.period]))
    a = Rotation.from_quat(full.q0).as_matrix().T
    assert abs(a[1, 0]) < 1e-9 and abs(a[1, 2]) < 1e-9 and abs(full.w0[1]) < 1e-9  # the full form's solution is mirror symmetric
    tilt = Rotation.from_quat(full.q0).as_rotvec()[1] + 0.05
    half = librate.periodic_attitude_3d(h, b2, guess=(Rotation.from_rotvec([0, tilt, 0]).as_quat(),
                                                      [full.w0[0] + 0.02, 0, full.w0[2] - 0.02]),
                                        symmetric=True)
    assert np.max(np.abs(half.q0 - full.q0)) < 1e-9 and np.max(np.abs(half.w0 - full.w0)) < 1e-9
    assert np.max(np.abs(half.monodromy - full.monodromy)) < 1e-8
    assert half.residual < 1e-9 and full.residual < 1e-9
    with pytest.raises(ValueError, match="symmetric"):
        librate.periodic_attitude_3d(h, b2, guess=(Rotation.from_rotvec([0.1, 0, 0]).as_quat(), [0, 0, 1.0]), symmetric=True)


def test_family_multipliers_figure(em):
    """A 3-D family along the L2 southern halos (14 to 8.5 days) and its Floquet figure: the six
    moduli and the complex-plane panel, with the stability change (multipliers through -1 near
    9.1 days, state0 at the crossing in the branch's hemisphere) shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import librate.plotting as lp
    import matplotlib.pyplot as plt
    from librate.periodicity import attitude_family_3d

    hf = librate.halo_family(em, 2, "south")
    body = librate.RigidBody(0.8, 0.9, 1.0)
    h = hf.member(period_days=14.0)
    s = librate.periodic_attitude_3d(h, body, guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / h.period]))
    ds = attitude_family_3d(hf, body, guess=(s.q0, s.w0), period_days=np.linspace(14.0, 8.5, 12))
    assert ds.sizes["member"] == 12 and float(ds.residual.max()) < 1e-9
    bracketed_changes(ds)
    fig = lp.plot_family_multipliers(ds)
    gids = {c.get_gid() for a in fig.axes for c in a.get_children()}
    assert {"modulus", "multipliers", "stability-change"} <= gids
    plt.close(fig)
    with pytest.raises(ValueError, match="ds"):
        lp.plot_family_multipliers(object())


def test_continuation_in_the_inertia_from_the_sphere(em):
    """Continued in the inertia from the torque-free sphere (where the spin 1 - 2 pi / T about
    Z is periodic at any attitude) to the body 0.8 : 0.9 : 1 along the 13-day L2 southern halo:
    the run completes, every member re-propagates to 1e-9 with reciprocal multipliers (1e-8),
    the sphere's six unit multipliers split at once (a +1 crossing right after s = 0), and the last
    member is a solution of the target body (re-corrected from itself: same q0, w0 to 1e-9)."""
    from librate.periodicity import attitude_family_3d_inertia

    h = librate.halo(em, 2, "south", period_days=13.0)
    target = librate.RigidBody(0.8, 0.9, 1.0)
    ds = attitude_family_3d_inertia(h, (librate.RigidBody(1.0, 1.0, 1.0), target),
                                    guess=([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / h.period]),
                                    steps=6)
    assert ds.attrs["end_reason"].startswith("completed") and ds.sizes["member"] == 7
    np.testing.assert_allclose(ds.moments.values[-1], target.moments)
    assert float(ds.residual.max()) < 1e-9
    for m in ds.multipliers.values:
        assert reciprocal_gap(m) < 1e-8
    assert "'between': (0.0," in ds.attrs["stability_changes"]
    again = librate.periodic_attitude_3d(h, target, guess=(ds.q0.values[-1], ds.w0.values[-1]))
    assert np.max(np.abs(again.q0 - ds.q0.values[-1])) < 1e-9 and np.max(np.abs(again.w0 - ds.w0.values[-1])) < 1e-9


def test_two_periods(dro, planar_n_minus_1):
    """A one-period solution is a two-period one: corrected over K = 2 from its own (q0, w0) it
    stays (wz0 to 1e-10) and its monodromy is the square of the one-period monodromy (1e-8),
    with two turns backwards."""
    body = librate.RigidBody.from_kz(0.8)
    one = librate.periodic_attitude_3d(dro, body, guess=planar_n_minus_1)
    two = librate.periodic_attitude_3d(dro, body, guess=(one.q0, one.w0), n_periods=2)
    assert two.w0[2] == pytest.approx(one.w0[2], abs=1e-10)
    assert np.max(np.abs(two.monodromy - one.monodromy @ one.monodromy)) < 1e-8 * np.max(np.abs(two.monodromy))
    assert two.turns == pytest.approx(-2.0, abs=1e-9) and two.residual < 1e-9


def test_floquet_test_functions():
    """The test functions of the 3-D families' stability changes, against the multipliers they
    come from (a 6x6 matrix built with three reciprocal pairs: a real pair lambda = 3, a pair
    e^(+-0.7i) on the unit circle and a real pair through -1 at lambda = -2): Q(u) at u = +-2
    equals prod_k (+-2 - u_k) with u_k = lambda_k + 1/lambda_k, and the discriminant of Q equals
    prod_{j<k} (u_j - u_k)^2; to 1e-10 relative (the traces of M^3 lose a few digits)."""
    from librate.periodicity.attitude3d import floquet_tests

    rng = np.random.default_rng(7)
    lam = np.array([3.0, 1 / 3.0, np.exp(0.7j), np.exp(-0.7j), -2.0, -0.5])
    v = rng.normal(size=(6, 6))
    # a real matrix with these eigenvalues: the complex pair as a 2x2 rotation block
    d = np.zeros((6, 6))
    d[0, 0], d[1, 1], d[4, 4], d[5, 5] = 3.0, 1 / 3.0, -2.0, -0.5
    d[2:4, 2:4] = [[np.cos(0.7), -np.sin(0.7)], [np.sin(0.7), np.cos(0.7)]]
    m = v @ d @ np.linalg.inv(v)
    u = np.array([3 + 1 / 3, 2 * np.cos(0.7), -2.5])
    t = floquet_tests(m)
    assert t["Q(2)"] == pytest.approx(np.prod(2 - u), rel=1e-10)
    assert t["Q(-2)"] == pytest.approx(np.prod(-2 - u), rel=1e-10)
    disc = ((u[0] - u[1]) * (u[0] - u[2]) * (u[1] - u[2])) ** 2
    assert t["discriminant"] == pytest.approx(disc, rel=1e-10)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(m)), np.sort_complex(lam))


def test_body_axes_figure(em, tmp_path):
    """Issue 15's figure of the body axes over the orbit, on the thesis Fig. 23 motion embedded
    in 3-D (12.66-day DRO, Kz = 0.8, N = -1): two panels (x-y, x-z); the orbit line is the
    orbit's trajectory; the arrows sit on it, one per sample, their x-y projections are the body
    axes (from the propagated attitude, 1e-12) scaled to 6 % of the orbit's extent, and the body
    z axis stays on synodic Z (a planar motion: its x-y arrows have zero length, 1e-12)."""
    import matplotlib

    matplotlib.use("Agg")
    import librate.plotting as lp
    import matplotlib.pyplot as plt

    d = librate.dro(em, period_days=12.66)
    body = librate.RigidBody(12.12e6, 89.68e6, 96.95e6)
    sol = librate.periodic_attitude_3d(d, body, guess=librate.periodic_attitude(d, kz=0.8, n=-1))
    fig = lp.plot_body_axes(sol, samples=8)
    assert len(fig.axes) == 2
    a = fig.axes[0]
    gid = lambda g: [c for c in a.get_children() if c.get_gid() == g]  # noqa: E731
    (orbit,) = gid("orbit")
    tr = sol.propagate(t_eval=np.linspace(0.0, d.period, 8, endpoint=False))
    qx = gid("axis-x")[0]
    np.testing.assert_allclose(qx.get_offsets(), tr.orbit[:, :2], atol=1e-12)
    ext = float(np.max(np.ptp(orbit.get_xydata(), axis=0)))
    length = np.hypot(qx.U, qx.V)
    np.testing.assert_allclose(length, 0.06 * max(ext, float(np.ptp(sol.propagate(t_eval=np.linspace(0, d.period, 400)).orbit[:, 2]))),
                               rtol=1e-9)
    np.testing.assert_allclose(np.c_[qx.U, qx.V] / length[:, None],
                               tr.dcm()[:, 0, :2] / np.linalg.norm(tr.dcm()[:, 0, :2], axis=1)[:, None], atol=1e-12)
    qz = gid("axis-z")[0]
    assert np.max(np.hypot(qz.U, qz.V)) < 1e-12
    fig.savefig(tmp_path / "axes.png")
    plt.close(fig)
    with pytest.raises(ValueError, match="solution"):
        lp.plot_body_axes(object())
    with pytest.raises(ValueError, match="planes"):
        lp.plot_body_axes(sol, planes=("xx",))


# Issue 15, item 4: the bordered correction across an orbit family and folds in the period. The
# reference fold is the planar N = 1 family of the body of Kz = 0.8 across the DROs (thesis
# Fig. 27), which turns back in x0 near x0 = 0.518 (T = 25.74 d); its planar embedding is a 3-D
# family with the same fold in the period.
_FOLD_START_DAYS = 25.4927400194  # the DRO of x0 = 0.53855 on the fold's first branch
_FOLD_START_WZ0 = 3.9254597


def test_bordered_across_the_family_at_a_fixed_period_is_the_plain_solution(dro_family):
    """With the period fixed, the bordered corrector (OrbitFamilyBranch3D, from a guess tilted by
    ~3e-4 rad) returns periodic_attitude_3d's solution on that member: q0 and w0 to 1e-10, its
    orbit the member's period to 1e-12 TU; re-propagation to 1e-9."""
    from librate.periodicity.attitude3d import OrbitFamilyBranch3D
    from librate.solving.continuation import Constraint

    body = librate.RigidBody.from_kz(0.8)
    orbit = dro_family.member(period_days=_FOLD_START_DAYS)
    s = librate.periodic_attitude_3d(orbit, body, guess=([0, 0, 0, 1.0], [0, 0, _FOLD_START_WZ0]))
    x = np.concatenate([[_FOLD_START_DAYS], Rotation.from_quat(s.q0).as_rotvec(), s.w0])
    pt = OrbitFamilyBranch3D(dro_family, body).correct(x + np.r_[0, 1e-4, -2e-4, 3e-4, 1e-4, 1e-4, 1e-3], Constraint.fix(7, 0, x[0]))
    b = pt.data.solution
    assert pt.x[0] == _FOLD_START_DAYS and abs(b.orbit.period - orbit.period) < 1e-12
    assert np.max(np.abs(_rotvec(s.q0, b.q0))) < 1e-10 and np.max(np.abs(b.w0 - s.w0)) < 1e-10
    assert b.residual < 1e-9


def _rotvec(q_from, q_to):
    return (Rotation.from_quat(q_from).inv() * Rotation.from_quat(q_to)).as_rotvec()


@pytest.mark.parametrize("orbits", ["dro", "halo"])
def test_bordered_tangent_matches_central_differences(em, dro_family, orbits):
    """The exact d F / d T of the bordered corrector: the family's tangent (null vector of
    [M - I, dF/dT], mapped to x = (period_days, rotvec(q0), w0)) equals central differences of
    plain periodic_attitude_3d solutions on the members at T +- h (h = 1e-4 d: O(h^2) ~ 1e-8),
    relative 1e-6. On the planar DRO motion above, and on a tilted motion of the body
    0.8 : 0.9 : 1 along the 12-day L2 southern halo (a spatial family: d(x0, z0, vy0)/dT)."""
    from librate.periodicity.attitude3d import OrbitFamilyBranch3D
    from librate.solving.continuation import Constraint

    if orbits == "dro":
        fam, body, p = dro_family, librate.RigidBody.from_kz(0.8), _FOLD_START_DAYS
        guess = ([0, 0, 0, 1.0], [0, 0, _FOLD_START_WZ0])
    else:
        fam, body, p = librate.halo_family(em, 2, "south"), librate.RigidBody(0.8, 0.9, 1.0), 12.0
        guess = ([0, 0, 0, 1.0], [0, 0, 1 - 2 * math.pi / fam.member(period_days=p).period])
    s = librate.periodic_attitude_3d(fam.member(period_days=p), body, guess=guess)
    br = OrbitFamilyBranch3D(fam, body)
    pt = br.correct(np.concatenate([[p], Rotation.from_quat(s.q0).as_rotvec(), s.w0]), Constraint.fix(7, 0, p))
    tan = br.tangent(pt)
    tan = tan / tan[0]
    h = 1e-4
    side = [librate.periodic_attitude_3d(fam.member(period_days=p + d), body, guess=(s.q0, s.w0)) for d in (h, -h)]
    xs = [np.concatenate([[o.orbit.period_days], Rotation.from_quat(o.q0).as_rotvec(), o.w0]) for o in side]
    fd = (xs[0] - xs[1]) / (xs[0][0] - xs[1][0])
    assert np.max(np.abs(tan - fd)) <= 1e-6 * np.max(np.abs(fd))


@pytest.mark.slow
def test_family_followed_through_a_fold_in_the_period(em, dro_family):
    """A 3-D family that folds in the period (the planar embedding of the N = 1 family across the
    DROs, Kz = 0.8, body 0.1 : 0.9 : 1): attitude_family_3d (pseudo-arclength on the bordered
    corrector) passes the fold, locates it to 1e-8 and it equals the planar family's located fold
    (attitude_family in x0, thesis Fig. 27) taken to the period, to 1e-6 d. The requested periods
    below the fold get two members, one on each branch (distinct wz0), every member repeats to
    1e-9 on independent re-propagation, a multiplier passes +1 at the fold, and natural
    continuation stops before the fold instead."""
    from librate.periodicity import attitude_family

    body = librate.RigidBody.from_kz(0.8)
    periods = np.linspace(_FOLD_START_DAYS, 25.80, 8)
    ds = librate.attitude_family_3d(dro_family, body, guess=([0, 0, 0, 1.0], [0, 0, _FOLD_START_WZ0]), period_days=periods)
    folds = ast.literal_eval(ds.attrs["folds"])
    assert len(folds) == 1 and folds[0]["located"]
    planar = attitude_family(dro_family, kz=0.8, n=1, start=0.5385453306274934, wz0=_FOLD_START_WZ0, direction=-1, max_points=40)
    assert planar.folds and planar.folds[0]["located"]
    fold_days = dro_family.member(x0=planar.folds[0]["x0"]).period_days
    assert folds[0]["period_days"] == pytest.approx(fold_days, abs=1e-6)
    below = periods[periods < folds[0]["period_days"]]
    assert ds.sizes["member"] == 2 * below.size and ast.literal_eval(ds.attrs["unmarked_periods"]) == []
    p, wz = ds.period_days.values, ds.w0.values[:, 2]
    for t in below:
        k = np.flatnonzero(np.abs(p - t) <= 1e-12)
        assert k.size == 2 and abs(wz[k[0]] - wz[k[1]]) > 1e-3
    assert float(ds.residual.max()) < 1e-9
    assert np.max(np.abs(ds.w0.values[:, :2])) < 1e-10  # the planar embedding stays planar
    # at the fold a multiplier passes +1 (M - I singular): Q(2) changes sign there too (1e-7)
    changes = ast.literal_eval(ds.attrs["stability_changes"])
    assert any(c["kind"] == "+1" and abs(c["at"] - folds[0]["period_days"]) < 1e-7 for c in changes)
    nat = librate.attitude_family_3d(dro_family, body, guess=([0, 0, 0, 1.0], [0, 0, _FOLD_START_WZ0]),
                                     period_days=periods, method="natural")
    assert nat.sizes["member"] < periods.size and float(nat.period_days.max()) < folds[0]["period_days"]


def test_family_3d_method_arguments(dro_family):
    """attitude_family_3d refuses an unknown method, and non-monotonic periods for the
    arclength method (ValueError naming the parameter)."""
    body = librate.RigidBody.from_kz(0.8)
    g = ([0, 0, 0, 1.0], [0, 0, _FOLD_START_WZ0])
    with pytest.raises(ValueError, match="method"):
        librate.attitude_family_3d(dro_family, body, guess=g, period_days=[25.5, 25.6], method="secant")
    with pytest.raises(ValueError, match="period_days"):
        librate.attitude_family_3d(dro_family, body, guess=g, period_days=[25.5, 25.6, 25.55])
