"""Regenerate the gallery's figures: the thesis figures librate reproduces.

    python docs/gallery/gallery.py FIGURE [OUT]     e.g. fig24, or "all"
    python docs/gallery/gallery.py --list

Each figure is written to OUT (default: docs/gallery/img) as FIGURE.png and its runtime
(computation and drawing, after the imports) is printed. The gallery pages state the command and
the runtime measured with it.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import librate  # noqa: E402
import librate.plotting as lp  # noqa: E402
import numpy as np  # noqa: E402

EM = librate.System.preset("earth-moon")


def _dro_family():
    return librate.dro_family(EM)


def fig03():
    """Fig. 3: the DRO family, orbits coloured by Jacobi constant."""
    return lp.plot_family(_dro_family(), n_orbits=30)


def fig05():
    """Fig. 5: stability indices of the DRO family, the out-of-plane bifurcation marked."""
    return lp.plot_stability(_dro_family())


def fig06():
    """Fig. 6: period of the DRO family with the synodic and Sun resonances."""
    return lp.plot_period(_dro_family())


def fig07():
    """Figs. 7 and 10: the 1:1 to 1:4 synodic-resonant DROs in the Earth-centred inertial frame."""
    fam = _dro_family()
    return lp.plot_eci([fam.resonant(k) for k in (1, 2, 3, 4)], separate=True)


def fig23():
    """Fig. 23: residual curves of the 12.66-day DRO at Kz = 0.8 (N = -1 at phidot0 = -2.4545)."""
    d = librate.dro(EM, period_days=12.66)
    return lp.plot_residuals(librate.periodicity_map(d, kz=0.8, wz0=np.linspace(-2.5, 2.5, 2001)))


def _map():
    fam = librate.dro_family(EM, x0=np.linspace(0.9, 0.3, 40))
    return librate.periodicity_map(fam, kz=[0.2, 0.5, 0.8], wz0=np.linspace(-2.5, 2.5, 800))


def fig24():
    """Fig. 24: the periodicity map of the DRO family at Kz = 0.8."""
    return lp.plot_map(_map(), kz_index=2)


def fig27():
    """Figs. 27-29: the solution families N = 1, 0, -1 across the DRO family, Kz = 0.2, 0.5, 0.8."""
    return lp.plot_solution_families(_map(), n=(1, 0, -1))


def fig30():
    """Figs. 30-31: phi(t) and the rate of the periodic motions N = 1, 0, -1 (12.66-day DRO, Kz = 0.8)."""
    d = librate.dro(EM, period_days=12.66)
    return lp.plot_attitude_motion([librate.periodic_attitude(d, kz=0.8, n=k) for k in (1, 0, -1)])


def fig33():
    """Fig. 33: the apparent motion of the Sun in the synodic frame."""
    return lp.plot_sun_motion(EM)


def fig34():
    """Fig. 34: the Sun-resonant DROs 1:2, 1:3, 1:4."""
    return lp.plot_sun_resonant(_dro_family(), ks=(2, 3, 4))


def _o2():
    return _dro_family().resonant(2, "sun")


def fig35():
    """Figs. 35-36: the flat-plate SRP map over (eps, rate) on the 1:2 Sun-resonant DRO, Kz = 0.6."""
    m = librate.srp_map(_o2(), kz=0.6, wz0=np.linspace(-1.6, 1.2, 400), eps=np.linspace(0, 2, 41), cs=0.4, cd=0.1)
    return lp.plot_srp_map(m, reference=1.03)


def fig37():
    """Figs. 37-38: a gravity-only periodic motion and the same motion with SRP."""
    g = librate.periodic_attitude(_o2(), kz=0.6, n=0, n_periods=2, wz0=0.934)
    s = librate.continue_srp(g, librate.FlatPlate(0.6, cs=0.4, cd=0.1)).solutions[-1]
    return lp.plot_srp_comparison(g, s)


def fig39():
    """Fig. 39: the accelerations on a Sun-pointing spacecraft along the 1:2 Sun-resonant DRO."""
    return lp.plot_sun_pointing(EM, librate.FlatPlate(1.03, cs=0.4, cd=0.1), orbit=_o2(), kz=0.6)


def fig40():
    """Figs. 40-41: SRP maps for Cs = 0, 0.5, 1."""
    o2 = _o2()
    maps = [librate.srp_map(o2, kz=0.6, wz0=np.linspace(-1.6, 1.2, 300), eps=np.linspace(0, 2, 21), cs=c) for c in (0.0, 0.5, 1.0)]
    return lp.plot_srp_maps(maps, reference=1.03)


def fig42():
    """Figs. 42-43: the sample station's lumped-parameter model."""
    return lp.plot_flexible_body(librate.FlexibleBody.sample_station())


def _flex_case():
    d = librate.dro(EM, period_days=12.66)
    low = librate.FlexibleBody.sample_station(low_frequency=True)
    sol = librate.periodic_attitude(d, kz=low.kz, n=0)
    return d, low, (sol.phi0, sol.wz0)


def fig44():
    """Fig. 44: flexible coordinates, closed quasi-static form against the full model."""
    d, low, att = _flex_case()
    body = low.scaled(10.0)
    te = np.linspace(0, d.period, 301)
    qs = librate.quasi_static(EM, d.state0, att, body, d.period, t_eval=te)
    tr = librate.propagate_attitude(EM, d.state0, att, body, d.period, t_eval=te, deflection="quasi-static")
    return lp.plot_flexible_coordinate(qs, tr, index=[1, 4], period=d.period)


def fig45():
    """Fig. 45: the low-frequency station's structural response and body rate against the rigid body."""
    d, low, att = _flex_case()
    te = np.linspace(0, d.period, 601)
    tr = librate.propagate_attitude(EM, d.state0, att, low, d.period, t_eval=te, deflection="quasi-static")
    rigid = librate.propagate_attitude(EM, d.state0, att, low.rigid_body(), d.period, planar=True, t_eval=te)
    return lp.plot_flexible_response(tr, rigid, period=d.period)


def fig46():
    """Fig. 46: the response against the appendage stiffness (frequency scan)."""
    d, low, att = _flex_case()
    sc = librate.frequency_scan(EM, d.state0, att, low, 0.5 * d.period, [1.0, 10.0, 100.0], samples=201)
    return lp.plot_frequency_scan(sc, index=[0, 4])


# --- the ephemeris model (librate transition) -------------------------------------------------------
def _dro_70000():
    """The 70,000 km DRO (x0 = 0.8057 LU: 70,000 km from the Moon on the Earth side)."""
    return librate.correct_dro(EM, 0.8057)


def fig_ephemeris_orbit():
    """The 70,000 km DRO at 2030-01-01 TDB over 10 revolutions, CR3BP and ephemeris, rotating frame."""
    from librate.orbits.transition import to_ephemeris

    eph, orbit = librate.Ephemeris(), _dro_70000()
    r = to_ephemeris(orbit, "2030-01-01T00:00:00 TDB", revolutions=10, ephemeris=eph)
    track = r.synodic(r.sample())  # every integration step, in the rotating frame
    cr3bp = librate.propagate(EM, orbit.state0, orbit.period, t_eval=np.linspace(0.0, orbit.period, 400)).y
    return lp.plot_transition_orbit(cr3bp, track, r.synodic(), mu=EM.mu, lu_km=EM.lu_km, label="2030-01-01, 10 revolutions")


def _sweep_2030():
    """The 70,000 km DRO at 14 epochs four weeks apart through 2030, 4 revolutions each (librate transition's store)."""
    import tempfile

    from librate.app.transition import run_transition_to

    epochs = librate.Ephemeris().rotating_frame("2030-01-01T00:00:00 TDB").epoch_tdb + 28 * 86400.0 * np.arange(14)
    with tempfile.TemporaryDirectory() as d:
        ds, _ = run_transition_to(_dro_70000(), Path(d) / "transition.zarr", epochs_tdb=epochs, revolutions=4, progress=False)
    return ds.where(ds["status"] == 0, drop=True)


def fig_ephemeris_defects():
    """The node defects of the 2030 epoch sweep of the 70,000 km DRO, every epoch below 1 m and 1e-8 km/s."""
    ds = _sweep_2030()
    return lp.plot_node_defects(ds["defects_km"].values, ds["defects_km_s"].values, epochs_tdb=ds["epoch"].values)


def fig_ephemeris_sweep():
    """The 2030 epoch sweep of the 70,000 km DRO: departure from the CR3BP orbit, perilune range, iterations."""
    ds = _sweep_2030()
    return lp.plot_transition_sweep(ds["epoch"].values, ds["max_departure_km"].values, ds["perilune_km"].values, ds["iterations"].values)


def _attitude_2030():
    """The N = 0 periodic attitude motion (Kz = 0.8) of the 70,000 km DRO carried into the ephemeris
    model along the DRO's transition at 2030-01-01 TDB over 4 revolutions, corrected."""
    from librate.orbits.transition import to_ephemeris

    orbit = _dro_70000()
    sols = librate.find_periodic_attitudes(orbit, kz=0.8, wz0_range=(-3.0, 2.0), kinds=("periodic",))
    sol = min((s for s in sols if s.n == 0), key=lambda s: abs(s.wz0))
    eo = to_ephemeris(orbit, "2030-01-01T00:00:00 TDB", revolutions=4)
    return librate.attitude_to_ephemeris(sol, eo)


def fig_ephemeris_attitude():
    """The attitude angles of the DRO's N = 0 motion in both models (relative to the rotating frame), 2030, 4 revolutions."""
    a = _attitude_2030()
    cr3bp, eph = a.angles_deg()
    return lp.plot_ephemeris_attitude((a.t_tdb - a.t_tdb[0]) / 86400.0, cr3bp, eph)


def fig_ephemeris_pointing():
    """The pointing error of each body axis of the DRO's N = 0 motion carried into the ephemeris model, 2030, 4 revolutions."""
    a = _attitude_2030()
    return lp.plot_pointing_error((a.t_tdb - a.t_tdb[0]) / 86400.0, a.pointing_error_deg)


FIGURES = {name: f for name, f in sorted(globals().items()) if name.startswith("fig") and callable(f)}


def _shrink(path: Path) -> None:
    """A palette PNG (96 colours): about a third of the size, for the committed gallery."""
    from PIL import Image

    Image.open(path).convert("RGB").quantize(colors=96, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0
    if argv[0] == "--list":
        for name, f in FIGURES.items():
            print(f"{name}  {f.__doc__}")
        return 0
    names = list(FIGURES) if argv[0] == "all" else [argv[0]]
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        print(f"unknown figure {unknown[0]!r}; one of: {', '.join(FIGURES)} or all", file=sys.stderr)
        return 2
    out = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parent / "img"
    out.mkdir(parents=True, exist_ok=True)
    for name in names:
        t0 = time.perf_counter()
        fig = FIGURES[name]()
        path = lp.save_figure(fig, out / f"{name}.png", dpi=80, close=True)
        elapsed = time.perf_counter() - t0
        _shrink(path)
        print(f"{name}: {elapsed:.1f} s  -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
