"""Periodic orbit-attitude solutions and periodicity maps: thesis sec. 3.3 / docs/physics.md, periodic attitude motions."""

import math

import librate
import numpy as np
import pytest


@pytest.fixture(scope="module")
def dro1266(em):
    return librate.dro(em, period_days=12.66)


def test_thesis_fig23_n_minus_one(dro1266):
    """Thesis Fig. 23 (docs/physics.md, periodic attitude motions): on the 12.66-day DRO with Kz = 0.8 the N = -1 solution
    sits at phidot0 = -2.4545 (inertial wz0 = -1.4545; 4 digits), and both residual curves cross
    zero there with slopes of opposite sign, staying within +-0.15 over [-2.55, -2.35]."""
    sol = librate.periodic_attitude(dro1266, kz=0.8, n=-1)
    assert round(sol.phidot0, 4) == -2.4545 and round(sol.wz0, 4) == -1.4545
    assert sol.residual < 1e-9 and sol.kind == "periodic"
    ds = librate.periodicity_map(dro1266, kz=0.8, wz0=np.linspace(-1.55, -1.35, 201), solve=False)
    dwz, dphi = ds.dwz.values[0, 0], ds.dphi.values[0, 0]
    assert np.max(np.abs(dwz)) < 0.15 and np.max(np.abs(dphi)) < 0.15
    assert np.sign(dwz[0]) != np.sign(dwz[-1]) and np.sign(dphi[0]) != np.sign(dphi[-1])
    slope_wz = np.polyfit(ds.wz0.values, dwz, 1)[0]
    slope_phi = np.polyfit(ds.wz0.values, dphi, 1)[0]
    assert slope_wz * slope_phi < 0


def test_torque_free_solutions_are_exact(dro1266):
    """Kz = 0: the solutions are exactly wz0 = 1 + 2 pi N / T for every N in the window (and the
    half-turn ones 1 + 2 pi (N + 1/2) / T), to 1e-12."""
    T = dro1266.period
    sols = librate.find_periodic_attitudes(dro1266, kz=0.0, wz0_range=(-4.0, 6.0))
    per = [s for s in sols if s.kind == "periodic"]
    half = [s for s in sols if s.kind == "half-turn"]
    expect = [1 + 2 * math.pi * n / T for n in range(-3, 3) if -4 < 1 + 2 * math.pi * n / T < 6]
    assert [s.n for s in per] == [n for n in range(-3, 3) if -4 < 1 + 2 * math.pi * n / T < 6]
    np.testing.assert_allclose([s.wz0 for s in per], expect, atol=1e-12)
    for s in half:
        assert s.wz0 == pytest.approx(1 + 2 * math.pi * (s.n + 0.5) / T, abs=1e-12)
    # free rotation: monodromy [[1, T], [0, 1]], trace 2 (marginal)
    np.testing.assert_allclose(per[0].monodromy, [[1, T], [0, 1]], atol=1e-10)


def test_solutions_repeat_when_repropagated(dro1266, em):
    """Every reported solution, re-propagated independently (3-D model this time, started
    planar), repeats after one period to 1e-9 in wz and phi (half-turn: phi + pi)."""
    sols = librate.find_periodic_attitudes(dro1266, kz=0.8, wz0_range=(-3.0, 2.0))
    assert {(s.n, s.kind) for s in sols} >= {(-1, "periodic"), (0, "periodic")}
    body = librate.RigidBody.from_kz(0.8)
    for s in sols:
        q0 = librate.quaternion_from_euler([0, 0, s.phi0])
        tr = librate.propagate_attitude(em, dro1266.state0, (q0, [0, 0, s.wz0]), body, dro1266.period, rtol=1e-13, atol=1e-13)
        turns = s.n + (0.5 if s.kind == "half-turn" else 0.0)
        phi_T = 2 * math.atan2(tr.q[-1, 2], tr.q[-1, 3])
        dphi = math.remainder(phi_T - s.phi0 - 2 * math.pi * turns, 2 * math.pi)
        assert abs(dphi) < 1e-9 and abs(tr.w[-1, 2] - s.wz0) < 1e-9, (s.n, s.kind)


def test_newton_matches_half_period_method(dro1266):
    """docs/physics.md: the correct Newton step [Phi(T) - I] d = -F on (phi0, wz0) converges for N = -1
    and N = -2, where the thesis's eq. 53 fails, and agrees with the half-period method (1e-9);
    phi0 stays at the symmetric 0."""
    for n in (-1, -2):
        a = librate.periodic_attitude(dro1266, kz=0.8, n=n, method="half")
        b = librate.periodic_attitude(dro1266, kz=0.8, n=n, method="newton")
        assert b.wz0 == pytest.approx(a.wz0, abs=1e-9) and abs(b.phi0) < 1e-9
        assert b.residual < 1e-9


def test_coarse_map_finds_the_direct_solutions(dro1266):
    """A coarse map (250 rates) finds the same solutions as the direct solver (1e-9)."""
    direct = librate.find_periodic_attitudes(dro1266, kz=0.8, wz0_range=(-3.0, 2.0))
    ds = librate.periodicity_map(dro1266, kz=0.8, wz0=np.linspace(-3.0, 2.0, 250))
    assert ds.sizes["solution"] == len(direct)
    got = sorted(zip(ds.sol_wz0.values, ds.sol_n.values, ds.sol_kind.values))
    for (w, n, k), s in zip(got, direct):
        assert (n, k) == (s.n, s.kind) and w == pytest.approx(s.wz0, abs=1e-9)
    assert np.all(ds.sol_residual.values < 1e-9)
    # zero contours of both residuals pass through each periodic solution
    for var in ("dwz", "dphi"):
        pts = librate.periodicity.zero_contours(ds, var)
        for s in direct:
            if s.kind == "periodic":
                assert np.min(np.abs(pts[:, 1] - s.wz0)) < 0.03


def test_map_over_the_family_and_kz_is_deterministic(em):
    """Residual arrays bit-identical with 1 or 2 threads and any chunk size; dims and units."""
    fam = librate.dro_family(em, x0=[0.9, 0.8, 0.7])
    wz = np.linspace(-3, 2, 120)
    a = librate.periodicity_map(fam, kz=[0.3, 0.8], wz0=wz, threads=1, chunk=64, solve=False)
    b = librate.periodicity_map(fam, kz=[0.3, 0.8], wz0=wz, threads=2, chunk=5, solve=False)
    for v in ("dwz", "dphi", "phi_T"):
        np.testing.assert_array_equal(a[v].values, b[v].values)
    assert a.dwz.dims == ("orbit", "kz", "wz0") and a.wz0.attrs["units"] == "1/TU"
    np.testing.assert_allclose(a.phidot0.values, wz - 1)
    assert a.attrs["complete"] == 1 and a.attrs["librate_version"] == librate.__version__
    # dphi is phi_T - phi0 wrapped to (-pi, pi]
    np.testing.assert_allclose(np.angle(np.exp(1j * a.phi_T.values)), a.dphi.values, atol=1e-12)
    assert np.all(a.dphi.values > -math.pi) and np.all(a.dphi.values <= math.pi)


def test_interrupted_map_keeps_finished_orbits(em):
    """Ctrl-C (KeyboardInterrupt) between orbits: the finished rows are kept and flagged."""
    fam = librate.dro_family(em, x0=[0.9, 0.8, 0.7])

    def stop_after_two(done, total):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.warns(UserWarning, match="2 of 3"):
        ds = librate.periodicity_map(fam, kz=0.8, wz0=np.linspace(-3, 2, 50), progress=stop_after_two)
    assert ds.attrs["complete"] == 0 and ds.computed.values.tolist() == [True, True, False]
    full = librate.periodicity_map(fam, kz=0.8, wz0=np.linspace(-3, 2, 50))
    np.testing.assert_array_equal(ds.dwz.values[:2], full.dwz.values[:2])
    assert np.isnan(ds.dwz.values[2]).all()


def test_half_turn_solutions_are_their_own_class(dro1266):
    """Half-turn motions (phi(T) = phi0 + pi + 2 pi N) are found and labelled, never as periodic."""
    sols = librate.find_periodic_attitudes(dro1266, kz=0.8, wz0_range=(-3.0, 2.0))
    half = [s for s in sols if s.kind == "half-turn"]
    assert half
    for s in half:
        tr = s.propagate()
        d = tr.phi[-1] - s.phi0
        assert abs(math.remainder(d - math.pi, 2 * math.pi)) < 1e-9
        assert abs(math.remainder(d, 2 * math.pi)) > 3.0


BAD = [
    ("kz out of range", lambda o: librate.periodic_attitude(o, kz=1.5, n=0), "kz"),
    ("n not an integer", lambda o: librate.periodic_attitude(o, kz=0.5, n=0.5), "n"),
    ("unknown kind", lambda o: librate.periodic_attitude(o, kz=0.5, n=0, kind="quarter"), "kind"),
    ("bad window", lambda o: librate.find_periodic_attitudes(o, kz=0.5, wz0_range=(2, 1)), "wz0_range"),
    ("rates not increasing", lambda o: librate.periodicity_map(o, kz=0.5, wz0=[1.0, 0.5]), "wz0"),
    ("kz array out of range", lambda o: librate.periodicity_map(o, kz=[0.5, 2.0], wz0=[0.0, 1.0]), "kz"),
    ("not an orbit", lambda o: librate.periodicity_map("dro", kz=0.5, wz0=[0.0, 1.0]), "orbits"),
]


@pytest.mark.parametrize("desc, call, text", BAD, ids=[b[0] for b in BAD])
def test_bad_requests(dro1266, desc, call, text):
    with pytest.raises(ValueError) as info:
        call(dro1266)
    assert text in str(info.value)


def test_attitude_family_across_kz(dro1266):
    """Continuing the N = -1 solution of the 12.66-day DRO in Kz (pseudo-arclength): every point
    is a solution (re-solved independently at its Kz, 1e-9), and where the curve crosses Kz = 0
    its rate is the torque-free 1 - 2 pi / T (1e-6, cubic-spline interpolation between points)."""
    from librate.periodicity import attitude_family

    fam = attitude_family(dro1266, kz=0.8, n=-1, direction=-1, ds=0.05)
    assert fam.parameter_name == "kz" and fam.parameter[0] == 0.8 and fam.parameter[-1] < -0.99
    for i in range(0, len(fam), 9):
        s = librate.periodic_attitude(dro1266, kz=float(fam.parameter[i]), n=-1, wz0=float(fam.wz0[i]))
        assert s.wz0 == pytest.approx(fam.wz0[i], abs=1e-9)
    from scipy.interpolate import CubicSpline

    w_at_0 = float(CubicSpline(fam.parameter[::-1], fam.wz0[::-1])(0.0))
    assert w_at_0 == pytest.approx(1 - 2 * math.pi / dro1266.period, abs=1e-6)


def test_attitude_family_across_the_orbit_family_through_folds(em):
    """The N = 1 family across the DRO family (thesis Fig. 27) turns back (folds) and is followed
    past the fold: points on both branches next to the fold are solutions of their orbits
    (re-solved directly, 1e-8), and on the map of one member the family's rate is a solution."""
    from librate.periodicity import attitude_family

    dros = librate.dro_family(em)
    fam = attitude_family(dros, kz=0.8, n=1, start=0.9, direction=-1, max_points=140)
    assert fam.folds, "expected a fold of the N = 1 family"
    x_fold = fam.folds[0]["x0"]
    k = int(np.argmin(np.abs(fam.parameter - x_fold)))
    for i in (k - 2, k + 2):
        orbit = dros.member(x0=float(fam.parameter[i]))
        s = librate.periodic_attitude(orbit, kz=0.8, n=1, wz0=float(fam.wz0[i]))
        assert s.wz0 == pytest.approx(fam.wz0[i], abs=1e-8)
    dp = np.diff(fam.parameter)
    assert np.any(dp > 0) and np.any(dp < 0)  # the curve turns back in x0
    # the member x0 = 0.85 lies on the first branch: the map of that orbit has the solution
    i = int(np.argmin(np.abs(fam.parameter[:k] - 0.85)))
    orbit = dros.member(x0=float(fam.parameter[i]))
    sols = librate.find_periodic_attitudes(orbit, kz=0.8, wz0_range=(fam.wz0[i] - 0.1, fam.wz0[i] + 0.1))
    assert any(s.n == 1 and abs(s.wz0 - fam.wz0[i]) < 1e-8 for s in sols)


@pytest.mark.parametrize("method", ["dp87", "rkn86"])
def test_map_methods_agree_with_rkf78(method):
    """Every lane integrator gives the same map: the standard map's residuals (DRO x0 = 0.70,
    Kz = 0.8) from Prince-Dormand RK8(7)13M and the Nystrom RKN8(6) against Fehlberg RKF7(8), all
    at rtol 1e-13, agree to 1e-10 relative to the residual scale (measured: 4e-12), and the
    dataset names its integrator."""
    em = librate.System.preset("earth-moon")
    o = librate.correct_dro(em, 0.70)
    wz = np.linspace(-3.0, 2.0, 64)
    ref = librate.periodicity_map(o, kz=0.8, wz0=wz, rtol=1e-13, atol=1e-13, solve=False)
    got = librate.periodicity_map(o, kz=0.8, wz0=wz, rtol=1e-13, atol=1e-13, solve=False, method=method)
    assert got.attrs["integrator"] == method and ref.attrs["integrator"] == "rkf78"
    for v in ("dwz", "dphi"):
        a, b = ref[v].values, got[v].values
        assert np.all(np.isfinite(b))
        assert np.max(np.abs(a - b)) < 1e-10 * max(1.0, np.max(np.abs(a))), v


def test_a_long_refinement_reports_progress_between_batches(em, monkeypatch):
    """Issue 24 #12: a 16-rate map over 1000 periods refined for 14 minutes in one corrector
    call, without a progress note. A batch past REFINE_BATCH_PERIODS candidate-periods is split
    (here the limit is lowered so that 91 candidates over 2 periods make 6 batches of 16): the
    progress callback runs after each batch, and the solutions are those of the single batch
    (the same 23, wz0 to 1e-10: only the batch companions' last bits, ~1e-13, differ)."""
    import librate.periodicity.maps as maps

    o = librate.correct_dro(em, 0.6)
    wz = np.linspace(-3.0, 2.0, 200)
    row = librate.periodicity_map([o], kz=0.8, wz0=wz, n_periods=2, solve=False).phi_T.values[0]
    one = maps.solutions_from_rows(o, [0.8], 0.0, wz, row, 2)
    monkeypatch.setattr(maps, "REFINE_BATCH_PERIODS", 16)
    calls = []
    split = maps.solutions_from_rows(o, [0.8], 0.0, wz, row, 2, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(16, 91), (32, 91), (48, 91), (64, 91), (80, 91), (91, 91)]
    assert len(one) == len(split) == 23
    assert [(a.n, a.kind) for a in one] == [(b.n, b.kind) for b in split]
    assert max(abs(a.wz0 - b.wz0) for a, b in zip(one, split)) < 1e-10


def test_a_rate_grid_that_does_not_resolve_the_angle_is_named_not_refined(em):
    """Issue 24 #12: 16 rates over K = 1000 periods gave 94,000 candidates on the example study's
    12 DROs (up to ~2000 half-turns of phi(KT) between neighbouring rates): linear guesses of
    nothing, refined for hours. An interval of more than MAX_CROSSINGS half-turns is left out
    with a RuntimeWarning naming `wz0` and the orbit (here x0 = 0.9, K = 200: 7 of 15 intervals,
    667 crossings in all, with AVX2). A grid that resolves the angle (300 rates, K = 1: at most 1.4
    half-turns an interval) keeps every candidate, as before."""
    import math

    import librate.periodicity.maps as maps
    from librate.periodicity.solutions import candidates

    o = librate.correct_dro(em, 0.9)
    wz = np.linspace(-3.0, 2.0, 16)
    # phi(KT) after 200 periods depends on the last bits of the arithmetic (the SIMD level: 7
    # intervals and 667 crossings with AVX2, 8 with the baseline), so the counts are bounded
    with pytest.warns(RuntimeWarning,
                      match=r"does not resolve phi\(KT\) on the orbit x0 = 0.9 LU \(K = 200 periods\): \d+ interval\(s\) of `wz0`") as rec:
        ds = librate.periodicity_map([o], kz=0.8, wz0=wz, n_periods=200)
    row = ds.phi_T.values[0]
    assert len(candidates(row[0], 0.0, wz, math.pi)) > 300
    kept, _, unresolved = maps.row_candidates([0.8], 0.0, wz, row)
    named = int(str(rec[-1].message).split("periods): ")[1].split(" interval")[0])
    assert rec[-1].filename == __file__  # the warning names the caller's line
    assert unresolved == named and 5 <= unresolved <= 10 and len(kept) <= 8 * (15 - unresolved)
    fine = np.linspace(-3.0, 2.0, 300)
    row = librate.periodicity_map([o], kz=0.8, wz0=fine, solve=False).phi_T.values[0]
    kept, _, unresolved = maps.row_candidates([0.8], 0.0, fine, row)
    assert unresolved == 0 and kept == candidates(row[0], 0.0, fine, math.pi)


def test_a_resolved_maps_crossings_are_refined_in_their_windows(em):
    """Issue 22 (c): the standard map (DRO x0 = 0.70, Kz = 0.8, 2000 rates) has 13 crossings of
    phi(T) through multiples of pi and 6 solutions. Refined without windows, 7 crossings travel
    0.13-1.06 in wz0 (50-425 rate intervals) to a solution another crossing found in place, or to
    none, taking three times the rounds. The grid resolves phi(T) (at most RESOLVED pi per
    interval), so each crossing gets the window of its interval +- QUICK_WINDOW intervals:
    exactly the 6 that converge in place converge (one or two Newton steps), the 7 others stop at
    their first step ("left_window"), and the map's solutions are the same 6 as without windows
    (wz0 to 1e-11: only the batch companions' last bits differ). A coarse grid (60 rates) keeps
    the windows where it resolves phi(T) and searches without them elsewhere."""
    import librate.periodicity.maps as maps
    from librate.periodicity import solutions

    o = librate.dro(em, x0=0.70)
    wz = np.linspace(-3.0, 2.0, 2000)
    row = librate.periodicity_map(o, kz=0.8, wz0=wz, solve=False).phi_T.values[0]
    cands, kk, unresolved, (lo, hi) = maps.crossing_windows([0.8], 0.0, wz, row)
    assert (len(cands), unresolved) == (13, 0)
    w0 = np.array([w for _, w in cands])
    h = wz[1] - wz[0]
    assert np.all(lo <= w0) and np.all(w0 <= hi) and np.all(hi - lo <= (2 * maps.QUICK_WINDOW + 1) * h * (1 + 1e-9))
    ks = np.array([k for k, _ in cands])
    kw = dict(kz=0.8, n_total=ks // 2, kind=np.where(ks % 2 == 0, "periodic", "half-turn"), phi0=0.0, wz0=w0, closure="half",
              monodromy=False, max_iter=solutions.STEP_MAX_ITER, max_halvings=3)
    free, boxed = solutions.correct(o, **kw), solutions.correct(o, search=(lo, hi), **kw)
    moved = np.abs(free.wz0 - w0) / h
    assert np.sum(moved < 1.0) == 6 and np.all(moved[moved >= 1.0] > 40)
    assert list(boxed.converged) == list(moved < 1.0)
    assert set(boxed.reason[i] for i in np.flatnonzero(moved >= 1.0)) == {"left_window"}
    assert np.all(boxed.iterations[boxed.converged] <= 2)
    sols = maps.solutions_from_rows(o, [0.8], 0.0, wz, row, 1)
    ref = solutions.refine(o, np.full(13, 0.8), 0.0, cands, n_periods=1, srp=None, closure="half", window=(wz[0], wz[-1]))
    assert len(sols) == len(ref) == 6
    assert max(abs(a.wz0 - b.wz0) for a, b in zip(sols, ref)) < 1e-11
    coarse = np.linspace(-4.0, 3.0, 60)
    row = librate.periodicity_map(o, kz=-0.9, wz0=coarse, solve=False).phi_T.values[0]
    _, _, _, (lo, hi) = maps.crossing_windows([-0.9], 0.0, coarse, row)
    assert np.any(np.isfinite(lo)) and np.any(np.isinf(lo))
