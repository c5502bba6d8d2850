"""Generate tests/data/kz_branches.json: the independent reference table of periodic attitude
solutions continued in Kz from Kz = 0 (where the solution of the N family is wz0 = 1 + 2 pi N/T).

Independent of librate's attitude code: scipy's DOP853 (rtol = atol = 1e-12) on the 6-state
planar system (x, y, xd, yd, phi, wz) with the gravity gradient in its angle form
    wzdot = (3/2) Kz sum_i mu_i / r_i^3 sin 2(theta_i - phi),  theta_i = atan2(y_i, x_i)
(librate uses the atan2-free S, C form and a tabulated orbit). Only the orbits' initial states
and periods are taken from librate (they are inputs here, stored in the table).

Method (a test reference, not library code): symmetric half-period shooting, phi(K T / 2) =
pi N K for phi0 = 0 on an x-symmetric orbit, by the secant method; natural continuation in Kz
from 0 (a first step of 1e-3, then steps of 0.01) with linear extrapolation of wz0 from the last two points. A branch
that cannot be followed (the secant fails, or the solution lands more than 0.05 from the extrapolated guess)
is recorded as folding before the next Kz.

Run: python tests/data/make_kz_branches.py   (about two minutes)
"""

import json
import math
from pathlib import Path

import librate
import numpy as np
from scipy.integrate import solve_ivp

MU = librate.System.preset("earth-moon").mu
KZ_TARGETS = (0.2, 0.5, 0.6, 0.8)
DKZ = 0.01


def rhs(kz):
    mu = MU

    def f(t, s):
        x, y, xd, yd, phi, wz = s
        x1, x2 = x + mu, x - 1 + mu
        r1 = math.hypot(x1, y)
        r2 = math.hypot(x2, y)
        a1, a2 = (1 - mu) / r1**3, mu / r2**3
        ax = x - a1 * x1 - a2 * x2 + 2 * yd
        ay = y - a1 * y - a2 * y - 2 * xd
        th1, th2 = math.atan2(y, x1), math.atan2(y, x2)
        wzd = 1.5 * kz * (a1 * math.sin(2 * (th1 - phi)) + a2 * math.sin(2 * (th2 - phi)))
        return [xd, yd, ax, ay, wz - 1.0, wzd]

    return f


def half_residual(state0, t_half, kz, wz0, turns_half):
    s = [state0[0], state0[1], state0[3], state0[4], 0.0, wz0]
    sol = solve_ivp(rhs(kz), (0.0, t_half), s, method="DOP853", rtol=1e-12, atol=1e-12)
    return sol.y[4, -1] - math.pi * turns_half


def secant(g, w0, w1, tol=1e-11, max_iter=30):
    g0, g1 = g(w0), g(w1)
    for _ in range(max_iter):
        if g1 == g0:
            return None
        w2 = w1 - g1 * (w1 - w0) / (g1 - g0)
        w0, g0, w1 = w1, g1, w2
        g1 = g(w1)
        if abs(g1) < tol:
            return w1
    return None


def branch(state0, period, k, n):
    """wz0 at each Kz target along the branch continued from Kz = 0 (None past a fold)."""
    t_half = 0.5 * k * period
    turns_half = n * k  # phi(KT/2) = pi N K
    w = 1.0 + 2 * math.pi * n * k / (k * period)
    hist = [(0.0, w)]
    out = {}
    kz = 0.0
    fold_after = None
    while kz < max(KZ_TARGETS) - 1e-12:
        nxt = 1e-3 if kz == 0.0 else round(min(kz + DKZ, round(kz / DKZ) * DKZ + DKZ), 10)
        if len(hist) >= 2:
            (k0, w0), (k1, w1) = hist[-2], hist[-1]
            guess = w1 + (w1 - w0) * (nxt - k1) / (k1 - k0)
        else:
            guess = hist[-1][1]
        wn = secant(lambda v, kz_=nxt: half_residual(state0, t_half, kz_, v, turns_half), guess, guess + 1e-4)
        if wn is None or abs(wn - guess) > 0.05:
            fold_after = kz
            break
        hist.append((nxt, wn))
        kz = nxt
        for kt in KZ_TARGETS:
            if abs(kt - kz) < 1e-9:
                out[f"{kt:g}"] = wn
    return out, fold_after


def main():
    em = librate.System.preset("earth-moon")
    fam = librate.dro_family(em)
    orbits = [("dro x0=0.85", librate.dro(em, x0=0.85), 1), ("dro x0=0.7", librate.dro(em, x0=0.7), 1),
              ("dro x0=0.5", librate.dro(em, x0=0.5), 1), ("dro x0=0.3", librate.dro(em, x0=0.3), 1),
              ("sun 1:2", fam.resonant(2, "sun"), 2), ("sun 1:4", fam.resonant(4, "sun"), 4)]
    rows = []
    for name, o, k in orbits:
        for n in (-1, 0, 1):
            wz, fold = branch(np.asarray(o.state0, dtype=float), float(o.period), k, n)
            rows.append({"orbit": name, "state0": [float(v) for v in o.state0], "period": float(o.period), "n_periods": k, "n": n,
                         "wz0": wz, "fold_after_kz": fold})
            print(name, n, wz, fold, flush=True)
    doc = {"source": __doc__.strip().splitlines()[0], "mu": MU,
           "method": "scipy DOP853 rtol=atol=1e-12, angle form, secant half-period shooting",
           "kz_step": DKZ, "rows": rows}
    Path(__file__).with_name("kz_branches.json").write_text(json.dumps(doc, indent=1))


if __name__ == "__main__":
    main()
