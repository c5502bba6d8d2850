"""Benchmark: librate batch propagation vs scipy ``solve_ivp(method="DOP853")``.

What it measures
    Wall time to propagate n CR3BP (Earth-Moon) states over one period of a distant
    retrograde orbit (DRO, x0 = 0.85), for librate and for scipy DOP853, on the same
    machine in the same run, at *equal accuracy*:

    * a tight reference is computed on a subset of states with librate (rtol=atol=1e-14)
      and cross-checked against scipy DOP853 (rtol=1e-13, atol=1e-15);
    * librate runs at rtol=atol=1e-11 and its max final-state error vs the reference is
      measured;
    * scipy's tolerance is the loosest rung of a ladder (1e-10 ... 1e-13) whose error is
      <= librate's, so scipy is never timed at a looser accuracy than librate.

    librate is timed on all cores and with threads=1 (scipy is single-threaded, so the
    1-thread ratio is the like-for-like comparison). scipy gets a pure-Python scalar RHS
    (no numpy in the hot loop), which is the fast typical way to call it.

How to run
    python bench/bench_propagate.py            # n = 1000 trajectories
    python bench/bench_propagate.py --n 200
    python bench/bench_propagate.py --quick    # n = 50
"""
import argparse
import os
import time

import librate
import numpy as np
from scipy.integrate import solve_ivp

LIBRATE_TOL = 1e-11
SCIPY_LADDER = (1e-10, 1e-11, 1e-12, 1e-13)
N_REF = 20


def make_rhs(mu):
    """CR3BP right-hand side using Python floats only (fast path for solve_ivp)."""
    omm = 1.0 - mu

    def rhs(t, s):
        x, y, z, xd, yd, zd = s
        dx1, dx2 = x + mu, x - omm
        yz2 = y * y + z * z
        r1 = (dx1 * dx1 + yz2) ** -1.5
        r2 = (dx2 * dx2 + yz2) ** -1.5
        a = omm * r1 + mu * r2
        return [xd, yd, zd,
                2.0 * yd + x - omm * dx1 * r1 - mu * dx2 * r2,
                -2.0 * xd + y - a * y,
                -a * z]

    return rhs


def initial_states(orbit, n, seed=12345):
    """n bounded states near the DRO: x0 in 0.85 +- 0.01, small z/zd, DRO ydot0."""
    rng = np.random.default_rng(seed)
    s = np.tile(orbit.state0, (n, 1))
    s[:, 0] += rng.uniform(-0.01, 0.01, n)
    s[:, 2] += rng.uniform(-0.01, 0.01, n)
    s[:, 5] += rng.uniform(-0.01, 0.01, n)
    return s


def scipy_batch(rhs, states, tf, rtol, atol):
    """Final states (n, 6) and mean RHS evaluations per trajectory."""
    out, nfev = np.empty_like(states), 0
    for i, s0 in enumerate(states):
        sol = solve_ivp(rhs, (0.0, tf), s0.tolist(), method="DOP853", rtol=rtol, atol=atol)
        if not sol.success:
            raise RuntimeError(f"scipy failed on state {i}: {sol.message}")
        out[i], nfev = sol.y[:, -1], nfev + sol.nfev
    return out, nfev / len(states)


def max_err(y, ref):
    return float(np.max(np.abs(y - ref)))


def timed(fn, repeat=1):
    """Result of fn() and its best wall time over `repeat` runs (perf_counter)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=1000, help="number of trajectories (default 1000)")
    ap.add_argument("--quick", action="store_true", help="use n=50")
    args = ap.parse_args()
    n = 50 if args.quick else args.n

    system = librate.System.preset("earth-moon")
    orbit = librate.correct_dro(system, 0.85)
    tf = orbit.period
    rhs = make_rhs(system.mu)
    states = initial_states(orbit, n)
    sub = states[: min(N_REF, n)]
    print(f"CR3BP earth-moon, mu={system.mu}, DRO x0=0.85, t_final={tf:.6f} (one period)")
    print(f"n={n} trajectories, reference subset={len(sub)}, cores={os.cpu_count()}")

    # 1. Reference on the subset, cross-checked between two independent integrators.
    ref = librate.propagate_many(system, sub, tf, rtol=1e-14, atol=1e-14).y
    ref_sp, _ = scipy_batch(rhs, sub, tf, 1e-13, 1e-15)
    print(f"reference: librate 1e-14 vs scipy DOP853 (1e-13/1e-15) max diff = "
          f"{max_err(ref, ref_sp):.2e}")

    # 2. Equal accuracy: librate's error, then the loosest scipy tolerance that matches it.
    lib_err = max_err(librate.propagate_many(system, sub, tf, rtol=LIBRATE_TOL,
                                             atol=LIBRATE_TOL).y, ref)
    print(f"librate rtol=atol={LIBRATE_TOL:.0e}: max error = {lib_err:.2e}")
    sp_tol = sp_err = None
    for tol in SCIPY_LADDER:
        err = max_err(scipy_batch(rhs, sub, tf, tol, tol)[0], ref)
        print(f"  scipy DOP853 rtol=atol={tol:.0e}: max error = {err:.2e}")
        sp_tol, sp_err = tol, err
        if err <= lib_err:
            break
    else:
        print(f"  NOTE: no scipy tolerance reached librate's error; using tightest {sp_tol:.0e}")
    print(f"chosen scipy tolerance: {sp_tol:.0e}")

    # 3. Timing over all n states (librate: best of 5, it takes milliseconds; scipy: once).
    librate.propagate_many(system, sub, tf, rtol=LIBRATE_TOL, atol=LIBRATE_TOL)  # warm-up
    res_all, t_all = timed(lambda: librate.propagate_many(
        system, states, tf, rtol=LIBRATE_TOL, atol=LIBRATE_TOL, threads=None), repeat=5)
    res_one, t_one = timed(lambda: librate.propagate_many(
        system, states, tf, rtol=LIBRATE_TOL, atol=LIBRATE_TOL, threads=1), repeat=5)
    (y_sp, sp_nfev), t_sp = timed(lambda: scipy_batch(rhs, states, tf, sp_tol, sp_tol))
    lib_nfev = float(np.mean(res_one.stats[:, 2]))
    if not (np.all(res_all.ok) and np.all(res_one.ok)):
        print("WARNING: some librate trajectories failed")
    print(f"librate all-cores vs 1-thread max diff = {max_err(res_all.y, res_one.y):.1e}; "
          f"librate vs scipy (all n) max diff = {max_err(res_all.y, y_sp):.2e}")

    # 4. Report.
    rows = [
        (f"librate RKF7(8), {os.cpu_count()} cores", LIBRATE_TOL, lib_err, lib_nfev, t_all),
        ("librate RKF7(8), 1 thread", LIBRATE_TOL, lib_err, lib_nfev, t_one),
        ("scipy solve_ivp DOP853", sp_tol, sp_err, sp_nfev, t_sp),
    ]
    print()
    print(f"{'method':<30} {'rtol=atol':>9} {'max err':>9} {'RHS/traj':>8} {'wall [s]':>9} "
          f"{'traj/s':>10}")
    for name, tol, err, nfev, t in rows:
        print(f"{name:<30} {tol:>9.0e} {err:>9.2e} {nfev:>8.0f} {t:>9.3f} {n / t:>10.1f}")
    print()
    print(f"librate (1 thread) vs scipy DOP853: {t_sp / t_one:.1f} times faster")
    print(f"librate (all cores) vs scipy DOP853: {t_sp / t_all:.1f} times faster")
    print("(scipy uses a pure-Python float RHS; errors are max |final state - reference| "
          f"over the {len(sub)}-state subset)")


if __name__ == "__main__":
    main()
