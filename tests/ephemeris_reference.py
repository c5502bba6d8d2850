"""Test reference for the ephemeris model, written here on purpose (not librate's code): the
relative equations of a spacecraft about the Moon under Earth, Moon and Sun point masses, with
jplephem's positions read from the same SPK file, integrated by scipy's DOP853."""

import numpy as np

DAY = 86400.0
J2000_JD = 2451545.0
GM_EARTH, GM_MOON, GM_SUN = 398600.435507, 4902.800118, 132712440041.279419
#: NAIF chains to the solar-system barycentre (0)
CHAINS = {10: [(0, 10)], 3: [(0, 3)], 301: [(0, 3), (3, 301)], 399: [(0, 3), (3, 399)], 0: []}


def ref_state(kernel, target, center, t):
    """(km, km/s) of target relative to center from jplephem, through the SSB/EMB chains."""

    def ssb(body):
        p, v = np.zeros(3), np.zeros(3)
        for c, tg in CHAINS[body]:
            pos, vel = kernel[c, tg].compute_and_differentiate(J2000_JD, t / DAY)
            p, v = p + pos, v + vel / DAY
        return p, v

    (pt, vt), (pc, vc) = ssb(target), ssb(center)
    return np.concatenate([pt - pc, vt - vc])


def ref_position(kernel, target, center, t):
    """km of target relative to center (positions only: faster)."""

    def ssb(body):
        p = np.zeros(3)
        for c, tg in CHAINS[body]:
            p = p + kernel[c, tg].compute(J2000_JD, t / DAY)
        return p

    return ssb(target) - ssb(center)


def _third(gm, d, rho):
    # acceleration of the spacecraft relative to the Moon by a body at d (from the Moon)
    return gm * ((d - rho) / np.linalg.norm(d - rho) ** 3 - d / np.linalg.norm(d) ** 3)


def ref_propagate(kernel, state_km, epoch_tdb, duration_s, rtol=1e-13, atol=1e-10):
    """The Moon-centred ICRF state after ``duration_s`` (scipy DOP853 on the relative equations)."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        rho = y[:3]
        e = ref_position(kernel, 399, 301, epoch_tdb + t)
        s = ref_position(kernel, 10, 301, epoch_tdb + t)
        a = -GM_MOON * rho / np.linalg.norm(rho) ** 3 + _third(GM_EARTH, e, rho) + _third(GM_SUN, s, rho)
        return np.concatenate([y[3:], a])

    sol = solve_ivp(rhs, (0.0, duration_s), np.asarray(state_km, dtype=float), method="DOP853", rtol=rtol, atol=atol)
    assert sol.success, sol.message
    return sol.y[:, -1]
