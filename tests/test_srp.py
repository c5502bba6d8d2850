"""Solar radiation pressure: the facet and flat-plate models (docs/physics.md, solar radiation pressure), Sun-resonant
periodic solutions, continuation in the SRP amplitude with folds."""

import math

import librate
import numpy as np
import pytest
from librate.constants import SUN_SYNODIC_PERIOD


@pytest.fixture(scope="module")
def sun12(em):
    """The 1:2 Sun-resonant DRO: T = Ts / 2 (14.75 d), periodicity checked after K = 2 orbits."""
    o = librate.dro_family(em).resonant(2, "sun")
    assert o.period == pytest.approx(SUN_SYNODIC_PERIOD / 2, abs=1e-10)
    return o


@pytest.fixture(scope="module")
def gravity_solution(sun12):
    return librate.periodic_attitude(sun12, kz=0.8, n=-1, n_periods=2)


def test_plate_model_equals_the_facet_model_in_3d(em, sun12):
    """The simplified plate (planar model) and a two-sided facet panel (3-D model, inertia in
    kg m^2, the same geometry) give the same attitude over two orbits of the Sun-resonant DRO,
    to 1e-9: two independent models and integration paths (both stop at the terminators)."""
    area, d, iz = 100.0, 3.0, 2.0e8  # eps = 0.96
    ix, iy = 0.5 * (1 - 0.6) * iz, 0.5 * (1 + 0.6) * iz  # Kz = 0.6, triangle inequality with equality
    body = librate.FacetBody.two_sided_panel(area, normal=(1, 0, 0), center=(0, d, 0), ca=0.5, cs=0.4, cd=0.1, inertia=(ix, iy, iz))
    sun = librate.Sun(theta0=0.7)
    plate = librate.FlatPlate.from_geometry(em, area_m2=area, offset_m=d, iz_kgm2=iz, cs=0.4, cd=0.1, sun=sun)
    assert 0.01 < plate.eps < 10
    T = 2 * sun12.period
    t = np.linspace(0, T, 9)
    p = librate.propagate_attitude(em, sun12.state0, (0.3, -0.9), librate.RigidBody(ix, iy, iz), T, planar=True, srp=plate,
                                   t_eval=t, rtol=1e-13, atol=1e-13)
    q0 = librate.quaternion_from_euler([0, 0, 0.3])
    s = librate.propagate_attitude(em, sun12.state0, (q0, [0, 0, -0.9]), body, T, torques=("gravity_gradient", "srp"), sun=sun,
                                   t_eval=t, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(s.w[:, 2], p.wz, atol=1e-9)
    np.testing.assert_allclose(np.unwrap(s.euler_angles()[:, 2]), np.unwrap(p.phi), atol=1e-9)


def test_srp_solutions_tend_to_the_gravity_solution(sun12, gravity_solution):
    """Continuity (issue 7): as eps -> 0 the SRP solutions converge to the gravity-only one,
    linearly: the distance halves when eps halves (ratio 2 within 2 %)."""
    g = gravity_solution
    dist = []
    for eps in (4e-3, 2e-3, 1e-3):
        s = librate.periodic_attitude(sun12, kz=0.8, n=-1, n_periods=2, srp=librate.FlatPlate(eps, cs=0.4, cd=0.1),
                                      phi0=g.phi0, wz0=g.wz0, method="newton")
        dist.append(math.hypot(s.wz0 - g.wz0, s.phi0 - g.phi0))
    assert dist[0] / dist[1] == pytest.approx(2, rel=0.02) and dist[1] / dist[2] == pytest.approx(2, rel=0.02)


def test_srp_solution_repeats_over_k_revolutions_in_the_facet_model(em, sun12, gravity_solution):
    """Every periodic SRP solution re-propagated over K revolutions repeats to 1e-9: here the
    plate solution re-propagated with the 3-D facet model of the same panel (independent)."""
    area, d, iz = 20.0, 2.0, 1.5e8  # eps = P A d TU^2 / Iz = 0.17, below the branch's fold at 0.52
    ix, iy = 0.1 * iz, 0.9 * iz  # Kz = 0.8
    sun = librate.Sun()
    plate = librate.FlatPlate.from_geometry(em, area_m2=area, offset_m=d, iz_kgm2=iz, cs=0.4, cd=0.1, sun=sun)
    g = gravity_solution
    s = librate.continue_srp(g, plate).solutions[-1]
    assert s.srp.eps == plate.eps and s.residual < 1e-9
    body = librate.FacetBody.two_sided_panel(area, center=(0, d, 0), ca=0.5, cs=0.4, cd=0.1, inertia=(ix, iy, iz))
    q0 = librate.quaternion_from_euler([0, 0, s.phi0])
    tr = librate.propagate_attitude(em, sun12.state0, (q0, [0, 0, s.wz0]), body, 2 * sun12.period,
                                    torques=("gravity_gradient", "srp"), sun=sun, rtol=1e-13, atol=1e-13)
    phi_T = 2 * math.atan2(tr.q[-1, 2], tr.q[-1, 3])
    assert abs(math.remainder(phi_T - s.phi0, 2 * math.pi)) < 1e-9
    assert abs(tr.w[-1, 2] - s.wz0) < 1e-9


def test_continuation_reports_the_fold(gravity_solution):
    """Continuing to a large eps, the branch folds: the turning point in eps is located (1e-8),
    the monodromy trace is 2 there (Phi - I singular, 1e-3), and no solution past it (from
    another branch) is returned. On the way the trace passes 2 once WITHOUT a turning point,
    near eps = 0.52: with the Sun phase 0 the plate keeps the mirror symmetry, and that point is
    a symmetry-breaking branch point (the continuation before issue 11 took it for the fold).
    Reference: every returned solution re-propagated independently (1e-9), eps increasing up
    to the fold, the fold's eps the largest reached, and a direct correction at eps just below
    the fold from the last point converging onto the branch."""
    c = librate.continue_srp(gravity_solution, librate.FlatPlate(1.0, cs=0.4, cd=0.1))
    assert not c.reached and c.fold is not None and c.fold["located"] and "fold" in c.end_reason
    assert 0 < c.fold["eps"] < 1.0 and abs(c.fold["trace"] - 2.0) < 1e-3
    assert np.all(np.diff(c.eps) > 0) and abs(c.eps[-1] - c.fold["eps"]) < 1e-8  # the last point is the fold
    assert all(s.residual < 1e-9 for s in c.solutions)
    branch_points = [b for b in c.bifurcations if b["test"].startswith("trace = 2")]
    assert len(branch_points) == 1 and 0.5 < branch_points[0]["eps"] < 0.55 < c.fold["eps"]
    last = c.solutions[-1]
    near = librate.periodic_attitude(gravity_solution.orbit, kz=0.8, n=-1, n_periods=2, phi0=last.phi0, wz0=last.wz0,
                                     srp=librate.FlatPlate(c.fold["eps"] - 1e-4, cs=0.4, cd=0.1))
    assert near.residual < 1e-9 and abs(near.wz0 - last.wz0) < 0.05
    # Regression: on the unstable N = 0 branch at Kz = 0.6 the continuation used to jump to
    # another branch at eps = 0.43 and run on to 0.66; the branch folds at eps = 0.3775.
    orbit = gravity_solution.orbit
    n0 = [x for x in librate.find_periodic_attitudes(orbit, kz=0.6, wz0_range=(0.0, 0.5), n_periods=2, kinds=("periodic",)) if x.n == 0][0]
    c0 = librate.continue_srp(n0, librate.FlatPlate(1.0, cs=0.4, cd=0.1))
    assert c0.fold["eps"] == pytest.approx(0.3775, abs=1e-3) and c0.eps[-1] < 0.378
    ok = librate.continue_srp(gravity_solution, librate.FlatPlate(0.05, cs=0.4, cd=0.1))
    assert ok.reached and ok.eps[-1] == 0.05 and all(s.residual < 1e-9 for s in ok.solutions)


def test_srp_map_on_the_sun_resonant_orbit(sun12):
    """A periodicity map with SRP over K = 2 revolutions: its refined solutions repeat (1e-9) and
    the parameters are stored."""
    plate = librate.FlatPlate(0.02, cs=0.4, cd=0.1, sun=librate.Sun(theta0=0.3))
    ds = librate.periodicity_map(sun12, kz=0.8, wz0=np.linspace(-1.6, 1.2, 400), n_periods=2, srp=plate)
    assert ds.sizes["solution"] > 0 and np.all(ds.sol_residual.values < 1e-9)
    assert ds.attrs["srp_eps"] == 0.02 and ds.attrs["theta_sun0"] == 0.3 and ds.attrs["n_periods"] == 2
    # the symmetry is broken: the solutions' phi0 are free (not all zero)
    assert np.max(np.abs(ds.sol_phi0.values)) > 1e-6


def test_srp_force_on_the_orbit(em, sun12):
    """The SRP force (switchable, off by default) moves the orbit by a small but non-zero amount:
    A/m = 0.016 m^2/kg gives ~2.7e-5 nondimensional acceleration (Table 2: ~1e-5), a drift of
    order a t^2 / 2 over one orbit (between 1e-7 and 1e-3 LU)."""
    mass = 1.0e5
    body = librate.FacetBody.flat_plate(0.016 * mass, normal=(1, 0, 0), inertia=(1e8, 1.5e8, 2e8), mass_kg=mass)
    args = (em, sun12.state0, ([0, 0, 0, 1], [0, 0, 1.0]), body, sun12.period)
    off = librate.propagate_attitude(*args, torques=("gravity_gradient", "srp"))
    on = librate.propagate_attitude(*args, torques=("gravity_gradient", "srp"), srp_force=True)
    dev = np.max(np.abs(on.orbit[-1, :3] - off.orbit[-1, :3]))
    assert 1e-7 < dev < 1e-3


BAD = [
    ("coefficients not summing to one", lambda: librate.Facet(1.0, (1, 0, 0), ca=0.5, cs=0.5, cd=0.5), "sum"),
    ("negative area", lambda: librate.Facet(-1.0, (1, 0, 0)), "area"),
    ("zero normal", lambda: librate.Facet(1.0, (0, 0, 0)), "normal"),
    ("plate cs + cd > 1", lambda: librate.FlatPlate(0.1, cs=0.8, cd=0.5), "cs"),
    ("plate eps not finite", lambda: librate.FlatPlate(math.inf), "eps"),
    ("facet body without facets", lambda: librate.FacetBody(1.0, 2.0, 2.5), "facets"),
    ("negative pressure", lambda: librate.Sun(pressure=-1.0), "pressure"),
]


@pytest.mark.parametrize("desc, call, text", BAD, ids=[b[0] for b in BAD])
def test_bad_srp_parameters(desc, call, text):
    with pytest.raises(ValueError) as info:
        call()
    assert text in str(info.value)


def test_srp_needs_a_facet_body(em):
    with pytest.raises(ValueError, match="FacetBody"):
        librate.propagate_attitude(em, [0.8, 0, 0, 0, 0.5, 0], ([0, 0, 0, 1], [0, 0, 1]),
                                   librate.RigidBody(1, 2, 2.5), 1.0, torques=("srp",))


def test_free_sun_phase_finds_the_symmetric_phases(sun12, gravity_solution):
    """docs/physics.md, solar radiation pressure: with phi0 = 0 kept, solutions survive only for special Sun phases (a
    multiple of pi/K for this plate). Freeing the Sun phase from 0.3 converges to such a phase
    (K = 2: a multiple of pi/2, to 1e-9), and the solution repeats (1e-9)."""
    plate = librate.FlatPlate(0.05, cs=0.4, cd=0.1, sun=librate.Sun(theta0=0.3))
    s = librate.periodic_attitude(sun12, kz=0.8, n=-1, n_periods=2, srp=plate, wz0=gravity_solution.wz0, free="theta_sun0")
    assert s.phi0 == 0.0 and s.residual < 1e-9
    k = s.srp.sun.theta0 / (math.pi / 2)
    assert abs(k - round(k)) < 1e-9
    # the old spelling free="sun_phase" still works, with a DeprecationWarning
    with pytest.warns(DeprecationWarning, match="theta_sun0"), pytest.raises(ValueError, match="needs srp"):
        librate.periodic_attitude(sun12, kz=0.8, n=-1, n_periods=2, free="sun_phase")


def test_map_over_several_plates(sun12):
    """A list of plates adds an srp dimension; the eps = 0 slice equals the gravity-only map bit
    for bit; solutions carry their plate index."""
    wz = np.linspace(-1.6, 1.2, 150)
    plates = [librate.FlatPlate(e, cs=0.4, cd=0.1) for e in (0.0, 0.03)]
    ds = librate.periodicity_map(sun12, kz=0.8, wz0=wz, n_periods=2, srp=plates)
    assert ds.dwz.dims == ("orbit", "srp", "kz", "wz0") and ds.srp_eps.values.tolist() == [0.0, 0.03]
    grav = librate.periodicity_map(sun12, kz=0.8, wz0=wz, n_periods=2, solve=False)
    np.testing.assert_array_equal(ds.dwz.values[:, 0], grav.dwz.values)
    assert set(ds.sol_srp.values.tolist()) == {0, 1} and np.all(ds.sol_residual.values < 1e-9)


def test_branches_in_lock_step_equal_each_branch_alone(sun12):
    """srp_map continues its branches in lock step (every branch's corrections in one Rust call
    per round). Reference: the same branches continued one at a time (eps_branch): the same
    points reached, every marked solution equal to 1e-9 in (phi0, wz0) (lock-step lanes share
    their step size: only the integration's last digits differ), the same end reasons (a fold at
    the same eps to 1e-8, the driver's fold tolerance)."""
    from librate.periodicity.branches import eps_branch, eps_branches

    starts = [s for s in librate.find_periodic_attitudes(sun12, kz=0.6, wz0_range=(-0.6, 1.0), n_periods=2, kinds=("periodic",))][:4]
    assert len(starts) >= 3
    plate = librate.FlatPlate(0.4, cs=0.4, cd=0.1)
    marks = [0.1, 0.2, 0.3, 0.4]
    together = eps_branches([(s, plate, marks) for s in starts], steps=4)
    for s, b in zip(starts, together):
        a = eps_branch(s, plate, steps=4, marks=marks)
        # the same kind of end; a fold at the same eps to the driver's fold tolerance (1e-8)
        assert a.end_reason.split(":")[0].split("=")[0] == b.end_reason.split(":")[0].split("=")[0]
        assert len(a.folds) == len(b.folds) and all(abs(f.parameter - g.parameter) <= 1e-8 for f, g in zip(a.folds, b.folds))
        assert [round(m.x[0], 12) for m in a.marked] == [round(m.x[0], 12) for m in b.marked]
        for p, q in zip(a.marked, b.marked):
            assert np.allclose(p.x, q.x, rtol=0, atol=1e-9)


def test_unstable_motion_converges_at_the_noise_floor(sun12):
    """Strongly unstable SRP-dominated motions (|trace| ~ 1e3 over K = 2 orbits) corrected in one
    batch with their companions (the lock-step continuation's first step): their residual
    cannot fall below ~1e-12 for every step sequence the shared lanes take; the corrector
    accepts a point where no Newton step descends and the residual is within tol x the largest
    |dF/dx| (the unknowns known to ~tol). Every one converges, the criterion is exercised (some
    residual above tol = 1e-12), and the independent re-propagation confirms each (1e-9)."""
    from librate.periodicity.branches import EpsBranch, branch_solutions
    from librate.solving.continuation import Constraint

    plate = librate.FlatPlate(2.0, cs=0.4, cd=0.1)
    found = [s for seed in (0.0, 0.5 * math.pi, math.pi, -0.5 * math.pi)
             for s in librate.find_periodic_attitudes(sun12, kz=0.6, wz0_range=(-1.6, 1.2), phi0=seed, n_periods=2, srp=plate)]
    assert sum(abs(s.trace) > 500 for s in found) >= 3
    pbs = [EpsBranch(sun12, 0.6, s.n_total, s.kind, 2, plate) for s in found]
    requests = [(p, np.array([2.0, s.phi0, s.wz0]), Constraint.fix(3, 0, 2.0)) for p, s in zip(pbs, found)]
    b = pbs[0].corrections(requests)
    assert all(b.converged), [r for r in b.reason if r != "converged"]
    worst = np.max(np.abs(b.jacobian[:, :, :2]), axis=(1, 2))
    assert np.any(b.residual_norm > 1e-12) and np.all(b.residual_norm <= 1e-12 * np.maximum(1.0, worst))
    for p, s in zip(pbs, found):
        pt = p.correct_many([(p, np.array([2.0, s.phi0, s.wz0]), Constraint.fix(3, 0, 2.0))])[0]
        assert branch_solutions(s, plate, [pt])[0].residual < 1e-9


def test_srp_map_reports_progress_per_branch(sun12):
    """issue 14: srp_map ran ~20 s with no progress. progress(done, total) comes after each
    branch and after the sweep (which runs beside the branches), never with done > total, and ends at done == total == 2 + the number
    of branches (the sweep, the branches, the assembly); the map is the same with or without it."""
    calls = []
    args = dict(kz=0.6, wz0=np.linspace(-1.25, 0.05, 60), eps=np.linspace(0.0, 0.5, 4), cs=0.4, cd=0.1)
    ds = librate.srp_map(sun12, progress=lambda done, total: calls.append((done, total)), **args)
    assert ds.sizes["branch"] >= 1
    assert calls[-1] == (2 + ds.sizes["branch"],) * 2
    assert all(d <= t for d, t in calls) and [d for d, _ in calls] == sorted(d for d, _ in calls)
    dones = [0] + [d for d, _ in calls]
    assert sum(1 for a, b in zip(dones, dones[1:]) if b > a) == 2 + ds.sizes["branch"]  # the sweep, each branch, the end: once each
    plain = librate.srp_map(sun12, **args)
    for v in ("dwz", "sol_wz0", "path_eps"):
        np.testing.assert_array_equal(ds[v].values, plain[v].values)
    with pytest.raises(ValueError, match="invalid argument `progress`"):
        librate.srp_map(sun12, progress=3, **args)


def test_scans_from_several_attitudes_share_one_sweep(sun12):
    """find_periodic_attitudes with a sequence of phi0: the scans run in one engine sweep and one
    corrector call, and give what the scans give one by one (reference: the single-phi0 calls):
    per scan the same motions (turns, kind; wz0 and phi0 to 1e-9: the candidates share SIMD
    groups with other scans' candidates, so only the last bits may differ), listed together by
    wz0. A motion found from two starts is listed twice."""
    plate = librate.FlatPlate(0.3, cs=0.4, cd=0.1)
    seeds = (0.0, 0.5 * math.pi)
    args = dict(kz=0.6, wz0_range=(-0.6, 1.0), n_periods=2, srp=plate, kinds=("periodic",))
    alone = [librate.find_periodic_attitudes(sun12, phi0=s, **args) for s in seeds]
    both = librate.find_periodic_attitudes(sun12, phi0=list(seeds), **args)
    assert all(len(a) >= 2 for a in alone)
    assert len(both) == sum(len(a) for a in alone)
    assert [s.wz0 for s in both] == sorted(s.wz0 for s in both)
    for a in alone:
        for s in a:
            assert any(b.n_total == s.n_total and b.kind == s.kind and abs(b.wz0 - s.wz0) < 1e-9
                       and abs(math.remainder(b.phi0 - s.phi0, 2 * math.pi)) < 1e-9 for b in both), (s.wz0, s.phi0)
    with pytest.raises(ValueError, match="`phi0`"):
        librate.find_periodic_attitudes(sun12, phi0=[], **args)
    with pytest.raises(ValueError, match="`phi0`"):
        librate.find_periodic_attitudes(sun12, phi0=[0.0, float("nan")], **args)


def test_srp_map_branches_follow_their_start(sun12):
    """The README's srp_map (41 eps x 400 rates, K = 2): every branch is the branch of its start.
    Reference: the same starts (the gravity-only solutions at eps = 0 and the far end's scan at
    eps = 2) continued with ten times shorter steps (eps_branches, steps = 200) mark the same
    solutions at the grid's eps values (1e-8 in wz0 and phi0). librate 0.1.4 failed this: with
    its 4 steps, a long first step from eps = 2 converged onto a neighbouring branch (wz0 0.157
    at eps = 1.85, then 0.268 at 1.8) within the jump guard, and another (wz0 -0.013 at 1.9,
    then -0.045 at 1.85)."""
    from librate.periodicity.branches import eps_branches

    es = np.linspace(0, 2, 41)
    ds = librate.srp_map(sun12, kz=0.6, wz0=np.linspace(-1.6, 1.2, 400), eps=es, cs=0.4, cd=0.1)
    plate = librate.FlatPlate(2.0, cs=0.4, cd=0.1)
    window = dict(kz=0.6, wz0_range=(-1.6, 1.2), kinds=("periodic",), n_periods=2)
    far = librate.find_periodic_attitudes(sun12, phi0=[0.0, 0.5 * math.pi, math.pi, -0.5 * math.pi], srp=plate, **window)  # srp_map's scan
    starts = {"gravity": (0.0, librate.find_periodic_attitudes(sun12, phi0=0.0, **window), plate, es[1:]),
              "end": (2.0, far, plate.with_eps(0.0), es[:-1][::-1])}
    sol_b, sol_e, sol_w, sol_p = (ds[k].values for k in ("sol_branch", "sol_eps", "sol_wz0", "sol_phi0"))
    branches, jobs = [], []
    for b, origin in enumerate(ds.branch_origin.values):
        e0, found, target, marks = starts[str(origin)]
        at = np.flatnonzero((sol_b == b) & (sol_e == e0))[0]
        s = next(s for s in found if abs(s.wz0 - sol_w[at]) < 1e-8 and abs(math.remainder(s.phi0 - sol_p[at], 2 * math.pi)) < 1e-8)
        branches.append(b)
        jobs.append((s, target, marks))
    assert len(branches) == ds.sizes["branch"] >= 25
    compared = 0
    for b, br in zip(branches, eps_branches(jobs, steps=200)):
        ref = {round(float(p.x[0]), 12): p for p in br.marked}
        for i in np.flatnonzero(sol_b == b):
            p = ref.get(round(float(sol_e[i]), 12))
            if p is None:
                continue
            assert abs(sol_w[i] - p.x[2]) < 1e-8, f"branch {b} at eps = {sol_e[i]}: wz0 {sol_w[i]} against {p.x[2]}"
            assert abs(math.remainder(sol_p[i] - p.x[1], 2 * math.pi)) < 1e-8, f"branch {b} at eps = {sol_e[i]}: phi0"
            compared += 1
    assert compared >= 0.9 * ds.sizes["solution"]
