"""Benchmark: the 3-D attitude map engine vs heyoka's batch Taylor integrator (issue 15, item 5).

What it measures (all in one process, same machine, same run)
    A 3-D attitude map of 2000 trajectories over one period of an Earth-Moon L2 southern halo
    (mid-family, 12 days): the body 0.8 : 0.9 : 1, q0 = identity, wy0 = 0, 40 inertial rates wx0
    in [-0.2, 0.2] x 50 rates wz0 in [w_tf - 0.5, w_tf + 0.5] (w_tf = 1 - 2 pi / T, the
    torque-free rate that turns once backwards per orbit). Per trajectory the physical system
    has 13 states: the spatial CR3BP orbit (6), the quaternion of the body relative to the
    synodic frame (4) and the inertial rate in body axes (3), with
        qdot = 1/2 Xi(q) (w - A e_Z),  I wdot = T - w x I w,  T = 3 sum_i mu_i / r_i^5 (r_i x I r_i).
    librate's engine integrates only (q, w), 7 states, with the orbit's tidal tensor tabulated
    once per orbit (piecewise Chebyshev, `TidalTable`); heyoka integrates all 13 states for every
    trajectory (as in bench/bench_map.py: it has no way to share the orbit between trajectories).

Reference and accuracy metric
    Reference: heyoka's scalar Taylor integrator in extended precision (x87 long double) at
    tol = 1e-19 on the 13-state system, on an evenly spaced subset of the map (200 trajectories;
    --quick 40). Metric ("accuracy"): max over the subset of max(|q(T) - q_ref|, |w(T) - w_ref|)
    / max(1, |w_ref|). Target: <= 1e-9.

Methods
    * librate: `_core.map_sweep_3d` (the Rust SIMD-lane engine, the one `attitude_map_3d` runs) on
      the tidal table; tolerance = the loosest rung of a 1-2-5 ladder meeting the target; timed on
      all cores and on 1 thread. The one-off table is timed separately and added to the total.
    * heyoka: `taylor_adaptive_batch` on the 13-state system, tolerance from the same ladder, then
      batch 4 and 8, compact_mode off, 1 and 2 threads (one integrator per thread, each running a
      contiguous share of the batches; heyoka releases the GIL in propagate_until). JIT compile
      time (heyoka's memory and disk caches bypassed) is reported separately and excluded from the
      run time.

Timing protocol: librate and every heyoka configuration run round-robin (one call of each per
round, 10 rounds; --quick 3), best and median reported; load average printed at start and end.
No timing is asserted anywhere.

How to run (heyoka is not a librate dependency; install it privately):
    pip install --target /tmp/heyoka-site heyoka
    PYTHONPATH=/tmp/heyoka-site:$PYTHONPATH python bench/bench_map3d.py [--quick]
"""
import argparse
import copy
import math
import os
import platform
import sys
import threading
import time

import librate
import numpy as np
from librate import _core
from timing import cpu_name, race

try:
    import heyoka as hy
except ImportError:
    hy = None

PERIOD_DAYS = 12.0
BODY = (0.8, 0.9, 1.0)
TARGET = 1e-9
LADDER = tuple(float(f"{m}e{e}") for e in range(-8, -15, -1) for m in (5, 2, 1))[1:]  # 2e-8, ..., 1e-14
REF_TOL = 1e-19


def problem(nx, nz):
    """(system, the 12-day L2 southern halo, the (nx * nz, 3) initial rates: nx wx0 in
    [-0.2, 0.2] x nz wz0 in [w_tf - 0.5, w_tf + 0.5], wy0 = 0)."""
    em = librate.System.preset("earth-moon")
    halo = librate.halo(em, 2, "south", period_days=PERIOD_DAYS)
    w_tf = 1 - 2 * math.pi / halo.period
    wx, wz = np.linspace(-0.2, 0.2, nx), np.linspace(w_tf - 0.5, w_tf + 0.5, nz)
    return em, halo, np.stack(np.meshgrid(wx, [0.0], wz, indexing="ij"), axis=-1).reshape(-1, 3)


def accuracy(q, w, ref):
    """max over trajectories of max(|dq|, |dw|) / max(1, |w_ref|) (NaN -> inf)."""
    qr, wr = ref
    e = np.maximum(np.max(np.abs(q - qr), axis=1), np.max(np.abs(w - wr), axis=1)) / np.maximum(1.0, np.max(np.abs(wr), axis=1))
    return float(np.max(np.where(np.isfinite(e), e, np.inf)))


def heyoka_system(mu, inertia, fp=float):
    """Spatial CR3BP orbit + rigid-body attitude (quaternion scalar last, body relative to the
    synodic frame; inertial rate in body axes), gravity gradient of both primaries."""
    x, y, z, vx, vy, vz, q1, q2, q3, q4, wx, wy, wz = hy.make_vars("x", "y", "z", "vx", "vy", "vz", "q1", "q2",
                                                                   "q3", "q4", "wx", "wy", "wz")
    m, omm = fp(mu), fp(1) - fp(mu)
    one, two, half, three = fp(1), fp(2), fp(0.5), fp(3)
    ix, iy, iz = (fp(v) for v in inertia)
    # orbit
    d1 = [x + m, y, z]
    d2 = [x - omm, y, z]
    r1s = d1[0] * d1[0] + y * y + z * z
    r2s = d2[0] * d2[0] + y * y + z * z
    i13, i23 = r1s ** fp(-1.5), r2s ** fp(-1.5)
    ax = two * vy + x - omm * d1[0] * i13 - m * d2[0] * i23
    ay = -two * vx + y - (omm * i13 + m * i23) * y
    az = -(omm * i13 + m * i23) * z
    # attitude matrix A(q)/|q|^2 (synodic -> body)
    n = one / (q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4)
    a, b, c, d = q1 * q1, q2 * q2, q3 * q3, q4 * q4
    A = [[(a - b - c + d) * n, two * (q1 * q2 + q3 * q4) * n, two * (q1 * q3 - q2 * q4) * n],
         [two * (q1 * q2 - q3 * q4) * n, (-a + b - c + d) * n, two * (q2 * q3 + q1 * q4) * n],
         [two * (q1 * q3 + q2 * q4) * n, two * (q2 * q3 - q1 * q4) * n, (-a - b + c + d) * n]]
    wr = [wx - A[0][2], wy - A[1][2], wz - A[2][2]]
    dq = [half * (q4 * wr[0] - q3 * wr[1] + q2 * wr[2]), half * (q3 * wr[0] + q4 * wr[1] - q1 * wr[2]),
          half * (-q2 * wr[0] + q1 * wr[1] + q4 * wr[2]), half * (-q1 * wr[0] - q2 * wr[1] - q3 * wr[2])]
    # gravity gradient: 3 mu_i / r_i^5 (r_i x I r_i), r_i in body axes
    tq = [fp(0), fp(0), fp(0)]
    for dd, gm, i3, rs in ((d1, omm, i13, r1s), (d2, m, i23, r2s)):
        rb = [A[k][0] * dd[0] + A[k][1] * dd[1] + A[k][2] * dd[2] for k in range(3)]
        k3 = three * gm * i3 / rs
        tq = [tq[0] + k3 * (iz - iy) * rb[1] * rb[2], tq[1] + k3 * (ix - iz) * rb[2] * rb[0], tq[2] + k3 * (iy - ix) * rb[0] * rb[1]]
    dw = [(tq[0] - (iz - iy) * wy * wz) / ix, (tq[1] - (ix - iz) * wz * wx) / iy, (tq[2] - (iy - ix) * wx * wy) / iz]
    return [(x, vx), (y, vy), (z, vz), (vx, ax), (vy, ay), (vz, az), (q1, dq[0]), (q2, dq[1]), (q3, dq[2]), (q4, dq[3]),
            (wx, dw[0]), (wy, dw[1]), (wz, dw[2])]


def reference(mu, orbit_state, T, w0, idx):
    ld = np.longdouble
    t0 = time.perf_counter()
    ta = hy.taylor_adaptive(heyoka_system(mu, BODY, ld), np.zeros(13, dtype=ld), tol=ld(REF_TOL), fp_type=ld, compact_mode=True)
    q, w = np.empty((len(idx), 4)), np.empty((len(idx), 3))
    for j, i in enumerate(idx):
        ta.time = ld(0)
        s = np.zeros(13, dtype=ld)
        s[:6] = np.asarray(orbit_state, dtype=ld)
        s[9] = ld(1)
        s[10:] = np.asarray(w0[i], dtype=ld)
        ta.state[:] = s
        oc, *_ = ta.propagate_until(ld(T))
        if oc != hy.taylor_outcome.time_limit:
            raise RuntimeError(f"reference failed at trajectory {i}: {oc}")
        q[j], w[j] = ta.state[6:10].astype(float), ta.state[10:].astype(float)
    return (q, w), time.perf_counter() - t0


class HeyokaRunner:
    def __init__(self, mu, orbit_state, T):
        self.T = T
        self.orbit = np.asarray(orbit_state, dtype=float)
        self.sys = heyoka_system(mu, BODY)
        self.cache = {}

    def integrator(self, tol, batch, compact=False):
        key = (tol, batch, compact)
        if key not in self.cache:
            hy.llvm_state.clear_memcache()
            t0 = time.perf_counter()
            ta = hy.taylor_adaptive_batch(self.sys, np.zeros((13, batch)), tol=tol, compact_mode=compact)
            self.cache[key] = (ta, time.perf_counter() - t0)
        return self.cache[key]

    def states(self, w0, batch):
        n = len(w0)
        nb = -(-n // batch)
        w = np.concatenate([w0, np.repeat(w0[-1:], nb * batch - n, axis=0)]).reshape(nb, batch, 3)
        st = np.zeros((nb, 13, batch))
        st[:, :6, :] = self.orbit[None, :, None]
        st[:, 9, :] = 1.0
        st[:, 10:, :] = w.transpose(0, 2, 1)
        return st

    def run(self, tas, st, n):
        nb, T = st.shape[0], self.T
        out = np.empty((nb, 7, st.shape[2]))

        def work(ta, lo, hi):
            for k in range(lo, hi):
                ta.set_time(0.0)
                ta.state[:] = st[k]
                ta.propagate_until(T)
                out[k] = ta.state[6:]

        bounds = [round(i * nb / len(tas)) for i in range(len(tas) + 1)]
        th = [threading.Thread(target=work, args=(tas[i], bounds[i], bounds[i + 1])) for i in range(len(tas))]
        for t in th:
            t.start()
        for t in th:
            t.join()
        flat = out.transpose(0, 2, 1).reshape(-1, 7)[:n]
        return flat[:, :4], flat[:, 4:]


def main():
    if hy is None:
        print("heyoka is not installed (it is not a librate dependency). Install it privately and put it on the path:\n"
              "    pip install --target /tmp/heyoka-site heyoka\n"
              "    PYTHONPATH=/tmp/heyoka-site:$PYTHONPATH python bench/bench_map3d.py")
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: 400 trajectories, 40 reference ones, 3 rounds")
    args = ap.parse_args()
    nx, nz = (10, 40) if args.quick else (40, 50)
    n_ref = 40 if args.quick else 200
    rounds = 3 if args.quick else 10
    cores = os.cpu_count()

    em, halo, w0 = problem(nx, nz)
    mu, T, n = em.mu, halo.period, len(w0)
    print(f"librate {librate.__version__}, heyoka {hy.__version__}, numpy {np.__version__}, python {platform.python_version()}")
    print(f"CPU: {cpu_name()}, cores = {cores}, librate SIMD level = {_core.build_info()['simd_active']}, "
          f"load average at start = {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    print(f"map: earth-moon mu = {mu}, L2 southern halo x0 = {halo.state0[0]:.6f}, z0 = {halo.state0[2]:.6f}, T = {T:.6f} TU = "
          f"{halo.period_days:.3f} d; body {BODY}, q0 = identity, {nx} wx0 x {nz} wz0 = {n} trajectories, wy0 = 0, one period")
    print(f"accuracy = max over {n_ref} reference trajectories of max(|dq|, |dw|) / max(1, |w_ref|); target <= {TARGET:.0e}")

    idx = np.unique(np.linspace(0, n - 1, n_ref).round().astype(int))
    ref, t_ref = reference(mu, halo.state0, T, w0, idx)
    print(f"\n[reference] heyoka scalar Taylor, long double, tol = {REF_TOL:.0e}: {len(idx)} trajectories in {t_ref:.1f} s")

    state0 = [float(v) for v in halo.state0]
    t0 = time.perf_counter()
    table = _core.TidalTable(mu, state0, float(T), tol=1e-13)
    t_table = time.perf_counter() - t0
    print(f"\n[librate] tidal table: {table.segments} segments, max rel. error {table.max_error:.1e}, built in {t_table * 1e3:.1f} ms")
    q0 = np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))
    inertia = np.tile(BODY, (n, 1))

    def lib(tol, threads=None):
        return _core.map_sweep_3d(table, float(T), q0, w0, inertia, lanes=_core.LaneOptions(rtol=tol, atol=tol, threads=threads))

    lib(1e-10)
    lib_tol = None
    for tol in LADDER:
        r = lib(tol)
        acc = accuracy(r.q_t[idx], r.w_t[idx], ref)
        print(f"  librate rtol = atol = {tol:.0e}: accuracy {acc:.2e}, steps/traj {r.steps.sum(axis=1).mean():.1f}")
        if acc <= TARGET:
            lib_tol = tol
            break
    if lib_tol is None:
        lib_tol = LADDER[-1]
        print(f"  NOTE: no librate tolerance met the target; using {lib_tol:.0e}")

    hy.llvm_state.set_diskcache_enabled(False)
    hyr = HeyokaRunner(mu, halo.state0, T)
    hy_tol = None
    print("\n[heyoka] tolerance ladder (batch 8, compact_mode off, 1 thread)")
    st8 = hyr.states(w0, 8)
    for tol in LADDER:
        ta, tc = hyr.integrator(tol, 8)
        q, w = hyr.run([ta], st8, n)
        acc = accuracy(q[idx], w[idx], ref)
        print(f"  heyoka tol = {tol:.0e}: order {ta.order}, accuracy {acc:.2e} (JIT {tc:.1f} s)")
        if acc <= TARGET:
            hy_tol = tol
            break
    if hy_tol is None:
        hy_tol = LADDER[-1]
        print(f"  NOTE: no heyoka tolerance met the target; using {hy_tol:.0e}")

    cands = {"librate, all cores": lambda: lib(lib_tol), "librate, 1 thread": lambda: lib(lib_tol, threads=1)}
    jit = {}
    for batch in (4, 8):
        st = hyr.states(w0, batch)
        ta, tc = hyr.integrator(hy_tol, batch)
        tas = [ta, copy.deepcopy(ta)]
        for nt in (1, 2):
            name = f"heyoka batch {batch}, {nt} thread{'s' if nt > 1 else ''}"
            jit[name] = tc
            cands[name] = (lambda tas=tas[:nt], st=st: hyr.run(tas, st, n))
    res = race(cands, rounds)
    print(f"\n[timing] {rounds} rounds round-robin; best (median)")
    rows = []
    for name, (out, best, med) in res.items():
        if name.startswith("librate"):
            acc = accuracy(out.q_t[idx], out.w_t[idx], ref)
            tol, extra = lib_tol, f"(+ table {t_table * 1e3:.1f} ms once per orbit)"
        else:
            acc = accuracy(out[0][idx], out[1][idx], ref)
            tol, extra = hy_tol, f"(+ JIT {jit[name]:.1f} s once per system and tolerance)"
        rows.append((name, best, acc))
        print(f"  {name:<26} tol {tol:.0e}  {best * 1e3:9.1f} ms ({med * 1e3:.1f})  accuracy {acc:.2e}  {extra}")
    same = np.array_equal(res["librate, all cores"][0].residual, res["librate, 1 thread"][0].residual)
    print(f"  librate bit-identical across thread counts: {same}")
    lib_best = min(b for nm, b, _ in rows if nm.startswith("librate"))
    hy_name, hy_best, _ = min((r for r in rows if r[0].startswith("heyoka")), key=lambda r: r[1])
    ratio = hy_best / (lib_best + t_table)
    print(f"\nspeed ratio t(heyoka best: {hy_name}, JIT excluded) / t(librate best, table included) = {ratio:.2f} "
          f"({'librate faster' if ratio > 1 else 'librate SLOWER'}); excluding the table: {hy_best / lib_best:.2f}")
    print(f"target >= 2x on {cores} cores: {'MET' if ratio >= 2 else 'NOT MET'}")
    print(f"load average at end = {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
