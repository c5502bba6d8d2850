"""Benchmark: the ephemeris model's speed goals (issue 21, item 6), side by side in one script.

i.  Ephemeris propagation: the 9:2 L2 southern NRHO (6.56 days, placed in the Earth-Moon-Sun
    model with ``Ephemeris.synodic_to_ephemeris``) at a series of daily epochs from 2030-01-01
    TDB, each propagated over one period by ``librate.propagate_ephemeris`` (Rust: Chebyshev
    evaluation and right-hand side) and by scipy's ``solve_ivp(method="DOP853")`` on a numpy
    right-hand side written below with jplephem's positions (the reference implementation, the
    same relative point-mass equations as the test reference in tests/test_ephemeris_model.py).
    Equal accuracy: both are compared with one tight run (scipy DOP853 at rtol 1e-13), and each
    runs at the loosest rung of a 1-2-5 tolerance ladder (rtol; atol = 1e-3 rtol km, km/s) whose final
    position error is below 1e-4 km (10 cm) on every epoch. librate runs the epochs one after the
    other, and as one batch on every core (``librate.propagate_ephemeris_many``, the same bits);
    scipy one after the other. Goal >= 300x on 2 cores (the batch).
ii. An NRHO transition over 20 revolutions, ``librate.to_ephemeris`` (multiple shooting from the
    CR3BP orbit, default nodes and tolerances: continuity within 1 m and 1e-8 km/s): goal < 1 s.
iii. An epoch sweep: the NRHO over 10 revolutions at 365 daily epochs (``--quick``: 8) by
    ``librate.ephemeris_sweep``, its epochs one at a time (``workers=1``) and concurrently (the
    default, one per core), each transition's legs on every core in both: the time per epoch and
    the ratio (the results are bit-identical, checked).

No timing is asserted; the CPU is named. Run:

    python bench/bench_ephemeris.py [--quick] [--json FILE]
"""

import argparse
import json
import os
import sys
import time

import librate
import numpy as np
from librate.ephemeris.epochs import tdb_seconds
from librate.ephemeris.spk import embedded_spk_path
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import cpu_name, race  # noqa: E402

DAY = 86400.0
J2000_JD = 2451545.0
GM_EARTH, GM_MOON, GM_SUN = 398600.435507, 4902.800118, 132712440041.279419  # DE440, km^3/s^2
EPOCH = "2030-01-01T00:00:00 TDB"
NRHO_DAYS = 6.56
TARGET_KM = 1e-4
LADDER = (1e-9, 5e-10, 2e-10, 1e-10, 5e-11, 2e-11, 1e-11, 5e-12, 2e-12, 1e-12)
REF_RTOL = 1e-13


def reference_rhs(kernel, t0):
    """The reference right-hand side (numpy, jplephem): a spacecraft about the Moon under the
    Earth, Moon and Sun point masses, the Moon's own acceleration by Earth and Sun subtracted;
    ICRF axes, km, km/s, t in seconds from the TDB epoch t0 (seconds past J2000)."""
    emb_moon, emb_earth, ssb_emb, ssb_sun = kernel[3, 301], kernel[3, 399], kernel[0, 3], kernel[0, 10]

    def third(gm, d, rho):
        return gm * ((d - rho) / np.linalg.norm(d - rho) ** 3 - d / np.linalg.norm(d) ** 3)

    def rhs(t, y):
        days = (t0 + t) / DAY
        moon = emb_moon.compute(J2000_JD, days)
        earth = emb_earth.compute(J2000_JD, days) - moon
        sun = ssb_sun.compute(J2000_JD, days) - ssb_emb.compute(J2000_JD, days) - moon
        rho = y[:3]
        a = -GM_MOON * rho / np.linalg.norm(rho) ** 3 + third(GM_EARTH, earth, rho) + third(GM_SUN, sun, rho)
        return np.concatenate([y[3:], a])

    return rhs


def propagation(n_epochs, rounds):
    """(i): librate against scipy DOP853 + jplephem, at equal accuracy."""
    from jplephem.spk import SPK

    em = librate.System.preset("earth-moon")
    nrho = librate.halo(em, 2, "south", period_days=NRHO_DAYS)
    eph = librate.Ephemeris()
    epochs = tdb_seconds(EPOCH) + DAY * np.arange(n_epochs)
    states = [eph.synodic_to_ephemeris(nrho.state0, t, em.mu) for t in epochs]
    duration = nrho.period_days * DAY
    kernel = SPK.open(str(embedded_spk_path()))
    rhss = [reference_rhs(kernel, t) for t in epochs]

    def scipy_run(rtol):
        return np.array([solve_ivp(f, (0.0, duration), s, method="DOP853", rtol=rtol, atol=1e-3 * rtol).y[:, -1]
                         for f, s in zip(rhss, states)])

    def lib_run(rtol):
        return np.array([librate.propagate_ephemeris(s, t, duration, ephemeris=eph, rtol=rtol, atol=1e-3 * rtol,
                                                     t_eval=[duration]).states_km[-1]
                         for s, t in zip(states, epochs)])

    def batch_run(rtol):
        out = librate.propagate_ephemeris_many(np.array(states), list(epochs), duration, ephemeris=eph, rtol=rtol, atol=1e-3 * rtol)
        return out.states_km

    t0 = time.perf_counter()
    ref = scipy_run(REF_RTOL)
    print(f"  reference: scipy DOP853 + jplephem at rtol {REF_RTOL:.0e}, {n_epochs} epochs in {time.perf_counter() - t0:.1f} s")

    def err(y):
        return float(np.max(np.linalg.norm(y[:, :3] - ref[:, :3], axis=1)))

    print(f"  librate at rtol 1e-13 against the reference: {err(lib_run(1e-13)):.1e} km (two codes, one model)")
    chosen = {}
    for name, run in (("librate", lib_run), ("scipy", scipy_run)):
        for rtol in LADDER:
            e = err(run(rtol))
            print(f"  {name} rtol {rtol:.0e}: final position error {e:.1e} km")
            if e <= TARGET_KM:
                break
        chosen[name] = (rtol, e)
    same = np.array_equal(batch_run(chosen["librate"][0]), lib_run(chosen["librate"][0]))
    runs = (("librate", lib_run, "librate"), ("librate batch", batch_run, "librate"), ("scipy", scipy_run, "scipy"))
    res = race({k: (lambda run=run, tol=chosen[c][0]: run(tol)) for k, run, c in runs}, rounds)
    kernel.close()
    t_lib, t_batch, t_sp = res["librate"][1], res["librate batch"][1], res["scipy"][1]
    print(f"  librate {t_lib / n_epochs * 1e3:.2f} ms per NRHO period serial, {t_batch / n_epochs * 1e3:.2f} ms in one batch on "
          f"{os.cpu_count()} cores (propagate_ephemeris_many, the same bits: {same}) (rtol {chosen['librate'][0]:.0e}); "
          f"scipy DOP853 + jplephem {t_sp / n_epochs * 1e3:.0f} ms (rtol {chosen['scipy'][0]:.0e}), serial")
    if not same:
        raise SystemExit("the batch propagation differs from the serial one")
    return dict(what=f"ephemeris propagation ({n_epochs} epochs x one 9:2 NRHO period, one batch on {os.cpu_count()} cores) "
                     "against scipy DOP853 + jplephem",
                ratio=t_sp / t_batch, serial_ratio=t_sp / t_lib, goal=">= 300x", met=t_sp / t_batch >= 300, librate_s=t_batch,
                librate_serial_s=t_lib, scipy_s=t_sp,
                librate_rtol=chosen["librate"][0], scipy_rtol=chosen["scipy"][0], librate_error_km=chosen["librate"][1],
                scipy_error_km=chosen["scipy"][1])


def transition(revolutions, rounds):
    """(ii): the 9:2 NRHO carried into the ephemeris model over `revolutions` revolutions."""
    what = f"NRHO transition over {revolutions} revolutions (librate.to_ephemeris)"
    if not hasattr(librate, "to_ephemeris"):
        print("  to_ephemeris not available")
        return dict(what=what, seconds=None, goal="< 1 s", met=None, note="to_ephemeris not available")
    nrho = librate.halo("earth-moon", 2, "south", period_days=NRHO_DAYS)
    res = race({"to_ephemeris": lambda: librate.to_ephemeris(nrho, EPOCH, revolutions=revolutions)}, rounds)
    out, t = res["to_ephemeris"][0], res["to_ephemeris"][1]
    d_km, d_kms = float(out.defects_km.max()), float(out.defects_km_s.max())
    print(f"  to_ephemeris from {EPOCH}: {t:.3f} s (best of {rounds}), {len(out.epochs_tdb)} nodes, {out.iterations} Newton steps, "
          f"largest defect {d_km * 1e3:.1e} m and {d_kms:.1e} km/s, largest departure from the CR3BP orbit {out.max_departure_km:.0f} km")
    return dict(what=what, seconds=t, goal="< 1 s", met=t < 1.0, nodes=len(out.epochs_tdb), iterations=out.iterations,
                max_defect_km=d_km, max_defect_km_s=d_kms, max_departure_km=float(out.max_departure_km))


def sweep(n_epochs):
    """(iii): the 9:2 NRHO over 10 revolutions at ``n_epochs`` daily epochs, serial and concurrent."""
    nrho = librate.halo("earth-moon", 2, "south", period_days=NRHO_DAYS)
    epochs = [tdb_seconds(EPOCH) + DAY * k for k in range(n_epochs)]
    times, outs = {}, {}
    for name, workers in (("serial", 1), ("concurrent", None)):
        t0 = time.perf_counter()
        outs[name] = librate.ephemeris_sweep(nrho, epochs, revolutions=10, workers=workers)
        times[name] = time.perf_counter() - t0
    same = all(type(a) is type(b) and (not isinstance(a, librate.EphemerisOrbit) or np.array_equal(a.states_km, b.states_km))
               for a, b in zip(outs["serial"], outs["concurrent"]))
    ok = sum(isinstance(o, librate.EphemerisOrbit) for o in outs["concurrent"])
    ratio = times["serial"] / times["concurrent"]
    print(f"  {n_epochs} epochs ({ok} converged): serial {times['serial'] / n_epochs * 1e3:.0f} ms per epoch, concurrent "
          f"{times['concurrent'] / n_epochs * 1e3:.0f} ms per epoch ({ratio:.2f}x); bit-identical: {same}")
    if not same:
        raise SystemExit("the concurrent sweep differs from the serial one")
    return dict(what=f"epoch sweep ({n_epochs} daily epochs x NRHO over 10 revolutions), concurrent against serial", ratio=ratio,
                seconds_per_epoch=times["concurrent"] / n_epochs, serial_seconds_per_epoch=times["serial"] / n_epochs, converged=ok)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 epochs and 2 rounds (CI)")
    ap.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    args = ap.parse_args(argv)
    n_epochs, rounds = (2, 2) if args.quick else (8, 5)
    info = librate.build_info()
    cpu = cpu_name()
    print(f"librate {librate.__version__} ({info['profile']} build), CPU: {cpu}, {os.cpu_count()} cores, SIMD level "
          f"{info['simd_active']}, load average {os.getloadavg()[0]:.2f}")
    print("\n[i] ephemeris propagation")
    prop = propagation(n_epochs, rounds)
    print("\n[ii] NRHO transition")
    trans = transition(20, rounds)
    print("\n[iii] epoch sweep")
    swp = sweep(8 if args.quick else 365)
    print(f"\n{'what':<100s} {'result':>10s} {'goal':>8s}")
    print(f"{prop['what']:<100s} {prop['ratio']:>9.0f}x {prop['goal']:>8s}  {'met' if prop['met'] else 'NOT MET'}")
    r = "n/a" if trans["seconds"] is None else f"{trans['seconds']:.2f} s"
    m = trans.get("note") if trans["met"] is None else ("met" if trans["met"] else "NOT MET")
    print(f"{trans['what']:<100s} {r:>10s} {trans['goal']:>8s}  {m}")
    print(f"{swp['what']:<100s} {swp['ratio']:>9.2f}x {'':>8s}  {swp['seconds_per_epoch'] * 1e3:.0f} ms per epoch")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(cpu=cpu, cores=os.cpu_count(), simd=info["simd_active"], build=info, librate=librate.__version__,
                           sizes="quick" if args.quick else "full", goals=dict(propagation=prop, transition=trans, sweep=swp)), f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
