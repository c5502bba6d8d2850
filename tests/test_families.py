"""Periodic-orbit families against the thesis (ch. 2), docs/physics.md, periodic orbits and the JPL catalog."""

import math

import librate
import numpy as np
import pytest
from librate.orbits.orbit_continuation import geometry


@pytest.fixture(scope="module")
def dros(em):
    return librate.dro_family(em)


def test_dro_family_spans_moon_to_earth(dros, em):
    """The whole family from x0 = 0.985 to 0.005, monotone in period and Jacobi constant; every
    member winds once clockwise about the Moon and not about the Earth (no silent jump)."""
    assert dros.x0[0] == 0.985 and dros.x0[-1] == pytest.approx(0.005)
    assert len(dros) == 197 and dros.end_reason.startswith("completed")
    assert np.all(np.diff(dros.period) > 0) and np.all(np.diff(dros.jacobi) < 0)
    for i in range(0, len(dros), 24):
        assert geometry(dros[i]).winding == (0, -1)


def test_dro_stability_facts(dros):
    """docs/physics.md, periodic orbits / thesis Fig. 5: the planar (in-plane) family is linearly stable for
    0.02 <= x0 <= 0.985; the out-of-plane index crosses +1 near x0 = 0.27 (bifurcation to 3-D
    DROs), detected and reported. Tolerance on the crossing: 0.01 (the thesis reads it off a plot)."""
    sel = (dros.x0 >= 0.02) & (dros.x0 <= 0.985)
    nu_in = dros.stability_indices[sel, 0]
    assert np.all(np.abs(nu_in.imag) < 1e-9) and np.all(np.abs(nu_in.real) <= 1 + 1e-9)
    out = [b for b in dros.bifurcations if b["index"] == "out-of-plane" and b["level"] == 1.0]
    assert len(out) == 1 and out[0]["x0"] == pytest.approx(0.27, abs=0.01)
    nu_out = dros.stability_indices[:, 1].real
    assert np.all(np.abs(nu_out[dros.x0 > 0.28]) <= 1) and np.all(nu_out[dros.x0 < 0.26] > 1)


def test_dro_period_tends_to_the_limit_near_the_earth(dros, em):
    """docs/physics.md: the period tends to 2 pi / sqrt(1 - mu) (27.45 d) as x0 -> -mu; at x0 = 0.005
    it is within 0.5 % and still increasing towards it."""
    limit = 2 * math.pi / math.sqrt(1 - em.mu)
    assert em.period_days(limit) == pytest.approx(27.45, abs=0.01)
    assert dros.period[-1] < limit and dros.period[-1] == pytest.approx(limit, rel=5e-3)


def test_members_close_and_conserve_jacobi(dros, em):
    """Every sampled member closes on itself to 1e-10 after one period at rtol = atol = 1e-14 and
    its Jacobi constant stays constant (1e-11) along it: DROs, L1/L2 Lyapunov and the L2
    halo/NRHO family. Closure is relative to max(1, |state0|) and, for unstable members, to the
    largest monodromy multiplier |lambda| (a shooting residual of 1e-11 grows by |lambda|, up to
    ~500 on the Lyapunov families, over one period). Exception, measured and documented: members
    that pass within 2 Earth radii of the Earth's centre (DROs with x0 < 0.03: speed ~10 LU/TU
    at perigee) are corrected just as accurately (|xdot| at the half period ~1e-13) but the
    integration through the flyby limits their full-period closure to ~1e-8."""
    fams = [dros, librate.lyapunov_family(em, 1), librate.lyapunov_family(em, 2), librate.halo_family(em, 2, "south")]
    earth = em.primary_positions()[0]
    for fam in fams:
        for i in np.linspace(0, len(fam) - 1, 9).astype(int):
            o = fam[i]
            tr = o.propagate(rtol=1e-14, atol=1e-14)
            scale = max(1.0, np.linalg.norm(o.state0)) * max(1.0, np.max(np.abs(fam.eigenvalues[i])))
            closure = np.max(np.abs(tr.y_final - o.state0)) / scale
            perigee = np.min(np.linalg.norm(tr.y[:, :3] - earth, axis=1))
            bound = 1e-10 if perigee > 2 * em.r1_km / em.lu_km else 1e-8
            assert closure < bound, (fam.kind, i, closure)
            assert np.max(np.abs(tr.jacobi - o.jacobi)) < 1e-11, (fam.kind, i)


def test_one_to_one_resonant_member(dros, em):
    """Thesis Table 1 / Fig. 7: the 1:1 synodic-resonant DRO (T = 2 pi) starts at x0 = 0.1521."""
    o = dros.resonant(1)
    assert o.period == pytest.approx(2 * math.pi, abs=1e-10)
    assert round(o.x0, 4) == 0.1521


def test_member_lookup_round_trips(dros, em):
    """Lookup by period in days (the thesis's 12.66-day DRO, Fig. 23), by Jacobi constant and by
    x0 returns corrected members with the requested value (1e-10), between its neighbours."""
    o = librate.dro(em, period_days=12.66)
    assert o.period_days == pytest.approx(12.66, abs=1e-9)
    i = np.searchsorted(dros.period, o.period)
    assert dros.x0[i - 1] > o.x0 > dros.x0[i]
    c = dros.member(jacobi=3.0)
    assert c.jacobi == pytest.approx(3.0, abs=1e-10)
    x = librate.dro(em, x0=0.3333)
    assert x.x0 == 0.3333 and x.residual < 1e-10
    # Sun-resonant members exist on the family: T = Ts / K
    for k in (2, 4):
        s = dros.resonant(k, "sun")
        assert s.period == pytest.approx(librate.constants.SUN_SYNODIC_PERIOD / k, abs=1e-10)


def test_jpl_catalog_l2_southern_halo():
    """JPL three-body periodic-orbit catalog, Earth-Moon L2 southern halo: the member with
    x0 = 1.0829551779304256 has z0 = -0.20231744561698364, vy0 = -0.20102644884016102, period
    2.3834910105144469 and Jacobi constant 3.01517767456737. Tolerance 1e-8."""
    jpl = librate.System.preset("earth-moon-jpl")
    fam = librate.halo_family(jpl, 2, "south")
    o = fam.member(x0=1.0829551779304256)  # state0 at the catalog's crossing: one member has this x0
    assert o.z0 == pytest.approx(-0.20231744561698364, abs=1e-8)
    assert o.vy0 == pytest.approx(-0.20102644884016102, abs=1e-8)
    assert o.period == pytest.approx(2.3834910105144469, abs=1e-8)
    assert o.jacobi == pytest.approx(3.01517767456737, abs=1e-8)
    # The family reaches the near-rectilinear regime: it ends at the Moon's surface, with
    # members of period below 7 days (NRHOs).
    assert fam.end_reason.startswith("collision") and fam.period_days.min() < 7.0
    # North and south are mirror images.
    north = librate.halo_family(jpl, 2, "north")
    np.testing.assert_allclose(north.state0[:, 2], -fam.state0[:, 2])


def test_halo_bifurcates_from_lyapunov(em):
    """The halo family starts where the L2 Lyapunov family's out-of-plane index crosses +1: its
    first member (|z| = 2e-3) crosses the x-z plane within 1e-4 in x of the bifurcating Lyapunov
    orbit's two x-axis crossings (state0 is the crossing in the branch's hemisphere, here the
    far side of L2; state_half the one continued from the Lyapunov start)."""
    lyap = librate.lyapunov_family(em, 2)
    bif = [b for b in lyap.bifurcations if b["index"] == "out-of-plane"][0]
    halo = librate.halo_family(em, 2, "north")
    i = bif["member"]
    w = (bif["x0"] - lyap.x0[i]) / (lyap.x0[i + 1] - lyap.x0[i])
    far = lyap.state_half[i, 0] + w * (lyap.state_half[i + 1, 0] - lyap.state_half[i, 0])
    assert abs(halo.state_half[0, 0] - bif["x0"]) < 1e-4 and abs(halo.x0[0] - far) < 1e-4
    assert halo.z0[0] > 0 > halo.state_half[0, 2]
    assert halo.parameters["bifurcation_x0"] == bif["x0"]
    # Lyapunov orbits circulate about their point: their initial x0 lies on L's Earth side.
    assert np.all(lyap.x0 < em.lagrange_points()[1, 0])


def test_save_and_load_identical(dros, tmp_path):
    """netCDF and Zarr round trips give identical numbers and keep units and constants."""
    for name in ("fam.nc", "fam.zarr"):
        path = tmp_path / name
        dros.save(path)
        back = librate.OrbitFamily.load(path)
        np.testing.assert_array_equal(back.state0, dros.state0)
        np.testing.assert_array_equal(back.period, dros.period)
        np.testing.assert_array_equal(back.stability_indices, dros.stability_indices)
        assert back.system == dros.system and back.end_reason == dros.end_reason
        assert back.bifurcations == dros.bifurcations
    ds = dros.to_dataset()
    assert ds["period"].attrs["units"] == "TU" and ds.attrs["mu"] == 0.01215


BAD = [
    ("x0 on the Moon", lambda em: librate.dro(em, x0=1 - em.mu), ValueError, "x0"),
    ("x0 on the Earth", lambda em: librate.dro_family(em, x0=[-em.mu]), ValueError, "x0"),
    ("period beyond the family", lambda em: librate.dro(em, period_days=40.0), ValueError, "outside"),
    ("two targets", lambda em: librate.dro(em, x0=0.9, period=1.0), ValueError, "exactly one"),
    ("L3 Lyapunov", lambda em: librate.lyapunov(em, 3, x0=-1.0), ValueError, "point"),
    ("bad branch", lambda em: librate.halo(em, 2, "east", z0=0.01), ValueError, "branch"),
    ("resonance k = 0", lambda em: librate.dro_family(em, x0=[0.9, 0.8]).resonant(0), ValueError, "k"),
    ("family that cannot start", lambda em: librate.correct_symmetric(em, (0.5, 0, 0.0), fix="x0", max_iter=3),
     librate.ConvergenceError, "converge"),
]


@pytest.mark.parametrize("desc, call, exc, text", BAD, ids=[b[0] for b in BAD])
def test_bad_requests(em, desc, call, exc, text):
    with pytest.raises(exc) as info:
        call(em)
    assert text in str(info.value)


def test_multiple_shooting_on_an_unstable_lyapunov_orbit(em):
    """General corrector (no symmetry assumed, free period, Poincare phase condition) with 8
    patches on an L1 Lyapunov orbit with |lambda| ~ 450: from patches perturbed by 1e-6 it
    converges to continuity residuals below its tolerance 1e-10, with the symmetric-shooting period (1e-9) at
    the imposed Jacobi constant; with the period fixed instead, it recovers that Jacobi constant."""
    fam = librate.lyapunov_family(em, 1)
    i = int(np.argmax(np.abs(fam.eigenvalues).max(axis=1) > 300))
    ref = fam[i]
    pts = ref.propagate(t_eval=np.arange(8) * ref.period / 8).y
    pts = pts + 1e-6 * np.sin(np.arange(48)).reshape(8, 6) * np.array([1, 1, 0, 1, 1, 0])
    shot = librate.correct_periodic(em, pts, ref.period * (1 + 1e-6), jacobi=ref.jacobi)
    assert shot.residual < 1e-10
    assert shot.period == pytest.approx(ref.period, abs=1e-9)
    assert shot.jacobi == pytest.approx(ref.jacobi, abs=1e-12)
    fixed = librate.correct_periodic(em, pts, ref.period, fixed_period=True)
    assert fixed.period == ref.period and fixed.jacobi == pytest.approx(ref.jacobi, abs=1e-8)
    with pytest.raises(ValueError, match="states"):
        librate.correct_periodic(em, np.zeros((3, 5)), 1.0)
    with pytest.raises(ValueError, match="period"):
        librate.correct_periodic(em, pts, -1.0)


def test_dro_family_in_the_jpl_preset():
    """Both presets: in earth-moon-jpl the whole family is found too, with the out-of-plane
    bifurcation still near x0 = 0.27 and the 1:1 member near x0 = 0.1521 (mu differs by 5e-7)."""
    jpl = librate.System.preset("earth-moon-jpl")
    fam = librate.dro_family(jpl)
    assert len(fam) == 197 and fam.end_reason.startswith("completed")
    assert fam.bifurcations[0]["x0"] == pytest.approx(0.27, abs=0.01)
    assert fam.resonant(1).x0 == pytest.approx(0.1521, abs=1e-4)


def test_l1_northern_halo_family(em):
    """L1 northern halos: largest excursion above the plane (z > 0), continued from the Lyapunov
    bifurcation until the perilune reaches the Moon's surface (the L1 NRHOs, periods of 8 to 12
    days); every member closes (relative to its largest multiplier, as above)."""
    fam = librate.halo_family(em, 1, "north")
    both = np.concatenate([fam.state0[:, 2], fam.state_half[:, 2]])
    assert both[np.argmax(np.abs(both))] > 0
    assert fam.end_reason.startswith("collision") and "Moon" in fam.end_reason
    assert 7.0 < fam.period_days.min() < 9.0 and fam.period_days.max() < 13.0
    for i in (0, len(fam) // 2, len(fam) - 1):
        o = fam[i]
        tr = o.propagate(rtol=1e-14, atol=1e-14)
        scale = max(1.0, np.linalg.norm(o.state0)) * max(1.0, np.max(np.abs(fam.eigenvalues[i])))
        assert np.max(np.abs(tr.y_final - o.state0)) / scale < 1e-10


def test_bifurcations_located_by_the_driver(dros, em):
    """The continuation driver locates the DRO family's bifurcation (out-of-plane index = +1,
    thesis Fig. 5, near x0 = 0.27) to 1e-8 in x0 with its test function nu - 1. Reference: the DRO
    corrected at that x0, its index from an independent full-period propagation with the STM:
    |nu - 1| <= 1e-6 (1e-8 in x0 times d nu / d x0 ~ 10, plus the propagation's accuracy)."""
    (b,) = [b for b in dros.bifurcations if b["index"] == "out-of-plane"]
    assert b["located"] and dros.x0[b["member"]] > b["x0"] > dros.x0[b["member"] + 1]
    nu = librate.dro(em, x0=b["x0"]).stability_indices[1]
    assert abs(nu - 1.0) <= 1e-6


@pytest.mark.parametrize("which", ["dro", "halo"])
def test_monodromy_from_the_half_period_stm(em, which):
    """The monodromy the corrector derives from the half-period STM, S Phi(T/2)^-1 S Phi(T/2)
    (mirror symmetry with time reversal), equals the full-period propagation's to 1e-9 relative
    to its largest entry, on a stable DRO and an unstable halo (|lambda| ~ 1e2)."""
    from librate.orbits.periodic import symmetric_monodromy

    o = librate.dro(em, x0=0.7) if which == "dro" else librate.halo(em, 2, "south", which=0, period=3.0)
    m = symmetric_monodromy(librate.correct_symmetric(em, o.state0[[0, 2, 4]], spatial=which == "halo", fix="x0"))
    ref = o.monodromy
    assert np.max(np.abs(m - ref)) <= 1e-9 * np.max(np.abs(ref))


def test_family_progress(em):
    """Issue 14: the families report progress(done, total) after each member (one progress
    style on every step longer than a second): done never decreases, never exceeds total, and
    the last call has done == total == the members found (DROs: the requested members;
    Lyapunov: the members found, total max_members until the end)."""
    for build in (lambda cb: librate.dro_family(em, x0=np.linspace(0.9, 0.5, 9), progress=cb),
                  lambda cb: librate.lyapunov_family(em, 1, max_members=30, progress=cb)):
        calls: list = []

        def record(d, t, calls=calls):
            calls.append((d, t))

        fam = build(record)
        assert calls and all(d <= t for d, t in calls) and all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))
        assert calls[-1] == (len(fam), len(fam))


# --- issue 24 #8: orbits through a primary are refused or flagged ----------------------------------


def test_single_orbits_through_a_primary_are_refused(em):
    """Issue 24 #8: the DRO at x0 = 0.985 never leaves the Moon's radius (1737.4 km) and the one
    at x0 = 0 starts 4670 km from the Earth's centre (radius 6371.0084 km), yet both were
    returned as valid while propagate() of the same states raises CollisionError. Reference
    (analytic): both start on the x axis at their closest approach, |x0 - x_primary| * lu_km:
    (1 - mu - 0.985) * 384400 = 1095.54 km and mu * 384400 = 4670.46 km (tolerance 1 km: the
    closest approach is sampled at the integrator's steps)."""
    for x0, k, closest, radius in ((0.985, 2, (1 - em.mu - 0.985) * em.lu_km, em.r2_km), (0.0, 1, em.mu * em.lu_km, em.r1_km)):
        with pytest.raises(librate.CollisionError,
                           match=rf"{['Earth', 'Moon'][k - 1]}'s radius.*closest approach.*km.*{radius} km") as info:
            librate.correct_dro(em, x0)
        err = info.value
        assert err.primary == k and err.radius_km == radius and err.closest_km == pytest.approx(closest, abs=1.0)
        kept = librate.correct_dro(em, x0, collision=None)  # the point-mass orbit, on request
        np.testing.assert_array_equal(kept.state0, err.orbit.state0)
        with pytest.raises(librate.CollisionError):  # the same verdict as propagate's collision check
            librate.propagate(em, kept.state0, kept.period)
    guess = librate.correct_dro(em, 0.985, collision=None).state0
    with pytest.raises(librate.CollisionError, match="Moon"):
        librate.correct_symmetric(em, guess)
    with pytest.raises(librate.CollisionError, match="Moon"):
        librate.correct_periodic(em, guess, librate.correct_dro(em, 0.985, collision=None).period)
    with pytest.raises(librate.CollisionError, match="Moon"):
        librate.dro(em, x0=0.985)
    with pytest.raises(ValueError, match="`collision`"):
        librate.correct_dro(em, 0.9, collision="surface")
    assert librate.correct_dro(em, 0.98).x0 == 0.98  # 3018 km from the Moon's centre: outside


def test_point_mass_systems_never_collide(em):
    """Issue 24 #8: a system with radii 0 (point masses) keeps the orbit: only a real radius refuses it."""
    pm = librate.System(em.mu, em.lu_km, em.tu_s, name="earth-moon point masses")
    o = librate.correct_dro(pm, 0.985)
    np.testing.assert_allclose(o.state0, librate.correct_dro(em, 0.985, collision=None).state0, rtol=0, atol=1e-12)


def test_families_flag_members_through_a_primary(dros, em):
    """Issue 24 #8: a default family call still works and flags the members that pass within a
    primary's radius, by the collision check propagate() uses (checked member by member):
    the DRO family's first member (x0 = 0.985, inside the Moon), the last member of the L2
    Lyapunov and L2 halo families (their continuation stops there, at the Moon's surface).
    member() refuses a value in a flagged stretch."""
    ip = dros.inside_primary
    assert ip[0] == 2 and np.all(ip[1:] == 0) and not dros.outside_primaries[0]
    assert dros.closest_km[0, 1] == pytest.approx((1 - em.mu - 0.985) * em.lu_km, abs=1.0)
    for i in (0, 1, 2, len(dros) - 1):
        o = dros[i]
        try:
            librate.propagate(em, o.state0, o.period, rtol=1e-13, atol=1e-13)
            assert ip[i] == 0
        except librate.CollisionError as err:
            assert ip[i] == err.primary
    with pytest.raises(librate.CollisionError, match="Moon's radius"):
        dros.member(x0=0.984)
    assert dros.member(x0=0.98).x0 == pytest.approx(0.98, abs=1e-12)
    lyap = librate.lyapunov_family(em, 2)
    assert lyap.end_reason.startswith("collision") and lyap.inside_primary[-1] == 2 and np.all(lyap.inside_primary[:-1] == 0)
    with pytest.raises(librate.CollisionError, match="Moon"):
        librate.lyapunov(em, 2, x0=float(lyap.x0[-1]))


# --- issue 24 #9: requested DRO members are reachable whenever the default family reaches them -----


def test_requested_dro_members_reach_what_the_default_family_reaches(dros, em):
    """Issue 24 #9: dro_family(em, x0=[0.01]) failed ("step floor ... past x0 = 0.5975") while the
    default family reaches x0 = 0.01. Reference: the default family's members (the same
    correction at the same x0, tolerance 1e-10 on the state and period, the corrector's 1e-12
    closure amplified near the Earth), and its located out-of-plane bifurcation (1e-8, the
    driver's location tolerance) for a request that brackets it."""
    for req in ([0.01], [0.01, 0.5], [0.5, 0.01], [0.0123]):
        fam = librate.dro_family(em, x0=req)
        assert fam.x0.tolist() == req
        for o in fam:
            i = np.flatnonzero(dros.x0 == o.x0)
            if i.size:
                np.testing.assert_allclose(o.state0, dros.state0[i[0]], rtol=0, atol=1e-10)
                assert o.period == pytest.approx(dros.period[i[0]], rel=1e-10)
    ref = [b for b in dros.bifurcations if b["index"] == "out-of-plane"]
    fam = librate.dro_family(em, x0=[0.3, 0.25])
    got = [b for b in fam.bifurcations if b["index"] == "out-of-plane"]
    assert len(got) == 1 and got[0]["member"] == 0 and got[0]["x0"] == pytest.approx(ref[0]["x0"], abs=1e-8) and got[0]["located"]
