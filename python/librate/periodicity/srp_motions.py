"""Solar radiation pressure on periodic attitude motions (thesis ch. 4, docs/physics.md, solar radiation pressure):
the flat-plate amplitude eps continued by :func:`librate.continue_srp`, the
(eps, rate) periodicity map with its solution branches (:func:`srp_map`) and the accelerations on
a Sun-pointing body (:func:`sun_pointing_accelerations`)."""

from __future__ import annotations

import math
from collections import namedtuple
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .. import _core
from .._checks import as_count, as_float_array, as_number, check_map_cells
from .._core import __version__
from .._progress import as_progress
from ..attitude.srp import FacetBody, FlatPlate, Sun, force_torque
from ..constants import SOLAR_PRESSURE_1AU, SUN_SYNODIC_PERIOD
from ..orbits.periodic import PeriodicOrbit
from ..orbits.system import check_system
from .branches import branch_fold, eps_branches
from .solutions import (
    check_kinds,
    check_kz,
    check_orbit,
    find_periodic_attitudes,
    orbit_forcing,
    sweep,
    turns_array,
    verified,
)

__all__ = ["srp_map", "sun_pointing_accelerations", "sun_resonance", "sun_angle"]


#: Marked points re-propagated per task of srp_map's pool (four lock-step groups of eight; a
#: piece takes about 1 ms at K = 2).
VERIFY_PIECE = 32


def sun_resonance(orbit: PeriodicOrbit, tol: float = 1e-6) -> int | None:
    """K when the orbit is Sun-resonant, K T = Ts (relative tolerance ``tol``), else None."""
    k = SUN_SYNODIC_PERIOD / orbit.period
    return int(round(k)) if round(k) >= 1 and abs(k - round(k)) < tol * k else None


def sun_angle(theta_sun0: float, t) -> np.ndarray:
    """The Sun's angle from the synodic X axis at times t (TU), unwrapped (rad), from its phase at t = 0."""
    return Sun(theta0=float(theta_sun0)).angle(t)


#: A motion a branch reached at some eps: what srp_map compares new far-end solutions with.
Known = namedtuple("Known", "n_total kind wz0 phi0")


def srp_map(
    orbit: PeriodicOrbit,
    *,
    kz: float,
    wz0,
    eps,
    cs: float = 0.0,
    cd: float = 0.0,
    theta_sun0: float = 0.0,
    phi0: float = 0.0,
    n_periods: int | None = None,
    solve: bool = True,
    kinds: Sequence[str] = ("periodic",),
    steps: int = 20,
    progress: Callable[[int, int], None] | None = None,
):
    """A flat-plate SRP periodicity map of one orbit over (eps, initial rate), with the solution
    branches (thesis Figs. 35-36, 40-41; drawn by `librate.plotting.plot_srp_map`).

    The grid runs in one engine sweep. With ``solve``: SRP breaks the mirror symmetry, so with
    phi0 fixed there is no curve of solutions in the plane; the solutions shown are branches with
    phi0 free (docs/physics.md, solar radiation pressure), continued by `continue_srp` through the
    grid's eps values (first step: the eps range over ``steps``) until the grid ends or the branch folds: from eps =
    0, the gravity-only solutions of the listed ``kinds`` in the window (``branch_origin =
    "gravity"``); and from each far end of the grid, the solutions found there that no branch from
    eps = 0 reached, back towards 0 (``"end"``: e.g. the SRP-dominated motions of large eps).

    Parameters
    ----------
    orbit : PeriodicOrbit
        A planar orbit, normally Sun-resonant (T = Ts / K, from ``family.resonant(K, "sun")``).
    kz : float
        Inertia ratio Kz.
    wz0 : array_like
        Increasing inertial initial rates (1/TU).
    eps : array_like
        Increasing plate amplitudes (any sign).
    cs, cd : float, default 0.0
        The plate's reflection fractions (ca = 1 - cs - cd).
    theta_sun0 : float, default 0.0
        The Sun phase (`Sun` ``theta0``, rad).
    phi0 : float, default 0.0
        Every motion's initial angle (rad).
    n_periods : int, optional
        The revolutions after which periodicity is checked: default the orbit's Sun resonance K
        (required for other orbits).
    solve : bool, default True
        Trace the solution branches.
    kinds : sequence of str, default ("periodic",)
        The closures of the gravity-only starts.
    steps : int, default 20
        The continuation's first step is the branch's eps range over ``steps`` (0.1 on the
        README's map, eps from 0 to 2); steps grow while the branch is easy, to four times that
        but at most 0.25, and the branch is corrected exactly at each grid value they pass. Shorter
        steps guard against a step converging onto a neighbouring branch: with 4 (librate
        0.1.4 and before) two branches of the README's map did so.
    progress : callable, optional
        ``progress(done, total)`` after each branch and after the grid's sweep; ``total`` grows
        as the branches to trace are found.

    Returns
    -------
    xarray.Dataset
        ``dwz`` = wz(KT) - wz0, ``dphi`` (wrapped), ``phi_T`` and ``status`` over (eps, wz0); with
        ``solve`` the solutions at the grid's eps values (``sol_*`` along ``solution``), every
        continuation point (``path_*`` along ``path``) and the branches (``branch_*`` along
        ``branch``: ``branch_n``, ``branch_kind``, ``branch_origin``, where and why each stopped,
        ``branch_fold`` when it ends on a fold).

    Raises
    ------
    ValueError
        A bad argument, naming it.
    """
    import xarray as xr

    progress = as_progress(progress, "SRP map", "step")
    counts = {"done": 0, "total": 2}  # the sweep, one per branch (added as found), the assembly

    def advance(done: int = 1, more: int = 0) -> None:
        # every branch runs on this thread (lock step), so the counts need no lock
        if progress is None:
            return
        counts["done"] += done
        counts["total"] += more
        progress(counts["done"], counts["total"])

    orbit = check_orbit(orbit)
    kz = check_kz(kz)
    kinds = check_kinds(kinds)
    if n_periods is None:
        n_periods = sun_resonance(orbit)
        if n_periods is None:
            raise ValueError(f"invalid argument `n_periods`: the orbit (T = {orbit.period_days:.4f} d) is not Sun-resonant "
                             f"(T = Ts/K, Ts = {SUN_SYNODIC_PERIOD * orbit.system.tu_days:.2f} d); give the revolutions K")
    n_periods = as_count(n_periods, "n_periods", 1)
    steps = as_count(steps, "steps", 1)
    es = as_float_array(eps, "eps").ravel()
    if es.size < 2 or not np.all(np.isfinite(es)) or np.any(np.diff(es) <= 0):
        raise ValueError(f"invalid argument `eps`: must be a finite, strictly increasing array of at least 2 values, got {eps!r}")
    wz = as_float_array(wz0, "wz0").ravel()
    if wz.size < 2 or not np.all(np.isfinite(wz)) or np.any(np.diff(wz) <= 0):
        raise ValueError("invalid argument `wz0`: must be a finite, strictly increasing array of at least 2 rates")
    check_map_cells((1, es.size, wz.size), "`eps`, `wz0`")
    phi0 = as_number(phi0, "phi0")
    plate = FlatPlate(0.0, cs, cd, Sun(theta0=as_number(theta_sun0, "theta_sun0")))
    e_grid, w_grid = np.meshgrid(es, wz, indexing="ij")
    forcing = orbit_forcing(orbit)
    shape = (es.size, wz.size)

    def grid_sweep(threads=None) -> dict:
        r = sweep(forcing, n_periods * orbit.period, phi0, w_grid, kz, srp=plate, eps=e_grid, threads=threads)
        return {k: np.asarray(r[k]).reshape(shape) for k in ("dwz", "dphi", "phi_t", "status")}

    sols, path, branches = [], [], []
    if not solve:
        data = grid_sweep()
        advance()
    else:
        # The grid's sweep does not feed the branches: it runs beside them on a thread of its own
        # (its own one-thread engine pool; the engine releases the GIL) and fills the cores the
        # branches' small corrector batches leave idle. Results do not depend on it: each
        # trajectory's result depends only on its group of lanes, never on the threads.
        with ThreadPoolExecutor(max_workers=2) as pool, ThreadPoolExecutor(max_workers=1) as scanner:
            window = (float(wz[0]), float(wz[-1]))
            runs = []  # (jobs, lead, branches, per branch its marks' re-propagations (future, index)), in order

            def run(jobs, lead):
                """Continue each job's ``start`` (at e_start) through the grid ``values`` in order
                (one pseudo-arclength run to the last value, corrected exactly at each grid value
                on the way; only those re-propagated), ending at the grid's end or at a located
                fold. The branches run in lock step (:func:`eps_branches`: each round's corrections
                of every branch in one Rust call); each branch's marked points are queued for
                re-propagation as the branch ends, beside the branches still running, in pieces of
                :data:`VERIFY_PIECE` on the pool (one-thread engine calls, as the grid)."""
                advance(0, len(jobs))
                pieces, queue, slots = [], [], [[] for _ in jobs]  # futures; (job, point) waiting; (piece, index) per mark

                def submit(part):
                    for k, (j, _) in enumerate(part):
                        slots[j].append((len(pieces), k))
                    starts = [jobs[j][0] for j, _ in part]
                    pieces.append(pool.submit(verified, orbit, kz=kz, n_total=[s_.n_total for s_ in starts],
                                              kind=[s_.kind for s_ in starts], phi0=[p.x[1] for _, p in part],
                                              wz0=[p.x[2] for _, p in part], n_periods=n_periods,
                                              plates=[plate.with_eps(float(p.x[0])) for _, p in part],
                                              iterations=[p.iterations for _, p in part], threads=1))

                def ended(j, br):
                    # an item's re-propagation depends on its group of eight in its piece: the pieces
                    # form in the order the branches end, which the lock step fixes (not the pool)
                    advance()
                    queue.extend((j, p) for p in (br.marked if br is not None else ()))
                    while len(queue) >= VERIFY_PIECE:
                        submit(queue[:VERIFY_PIECE])
                        del queue[:VERIFY_PIECE]

                brs = eps_branches([(start, plate.with_eps(float(values[-1])), [float(e) for e in values]) for start, _, values, _ in jobs],
                                   steps=steps, done=ended)
                if queue:
                    submit(queue)
                checked = [[(pieces[a], k) for a, k in slot] for slot in slots]
                runs.append((jobs, lead, brs, checked))

            def found_at(e_end):
                """The motions the runs so far have at eps = e_end (their lead and marked points)."""
                out = [s_ for jobs, lead, _, _ in runs for first in lead for e, s_ in first if e == e_end]
                return out + [Known(start.n_total, start.kind, float(p.x[2]), float(p.x[1]))
                              for jobs, _, brs, _ in runs for (start, _, _, _), br in zip(jobs, brs)
                              for p in br.marked if float(p.x[0]) == e_end]

            def record(jobs, lead, brs, checked):
                """The branches of one run, recorded in order, each after its ``lead`` solutions
                ((eps, solution) recorded at the branch's index first)."""
                for (start, e_start, _, origin), br, first, slot in zip(jobs, brs, lead, checked):
                    pts = [(float(p.x[0]), float(p.x[2]), float(p.x[1]), float(p.data["trace"])) for p in br.points]
                    marked = [(float(p.x[0]), piece.result()[k]) for p, (piece, k) in zip(br.marked, slot)]
                    if br.reached:
                        end = (math.nan, math.nan, False, "reached the end of the eps grid")
                    else:
                        f = branch_fold(br)
                        fold = f is not None and f["located"]
                        last = br.points[-1]
                        end = (float(f["eps"]) if fold else float(last.x[0]), float(last.x[2]), fold, br.end_reason)
                    b = len(branches)
                    sols.extend((b, e, s_) for e, s_ in first)
                    path.extend((b, *pt) for pt in pts)
                    sols.extend((b, e, s_) for e, s_ in marked)
                    branches.append((start.n_total, start.kind, origin, e_start) + end)

            pos, neg = es[es > 0], es[es < 0][::-1]
            jobs, lead = [], []
            for s0 in find_periodic_attitudes(orbit, kz=kz, wz0_range=window, phi0=phi0, kinds=kinds, n_periods=n_periods):
                first = [(0.0, s0)] if 0.0 in es else []
                for side in (pos, neg):
                    if side.size:
                        jobs.append((s0, 0.0, side, "gravity"))
                        lead.append(first)
                        first = []
            # Solutions at the grid's far ends (SRP-dominated ones too), continued back towards eps = 0
            # unless a branch from eps = 0 already reached them. The scans of the ends do not depend
            # on the branches from eps = 0 (only which of their solutions are new does): they run
            # beside those branches, on a thread of their own.
            zero = np.array([0.0] if 0.0 in es else [])
            ends = (([(float(es[-1]), np.concatenate([pos[::-1][1:], zero]))] if es[-1] > 0 else [])
                    + ([(float(es[0]), np.concatenate([neg[::-1][1:], zero]))] if es[0] < 0 else []))
            # phi0 is free: each end scanned from four initial attitudes (one sweep, one corrector call)
            scans = [scanner.submit(find_periodic_attitudes, orbit, kz=kz, wz0_range=window,
                                    phi0=[phi0 + s_ for s_ in (0.0, 0.5 * math.pi, math.pi, -0.5 * math.pi)],
                                    kinds=kinds, n_periods=n_periods, srp=plate.with_eps(e_end)) for e_end, _ in ends]
            # the grid's sweep after the scans, on their thread: the branches from the ends wait
            # for the scans, nothing waits for the sweep until the assembly (started at once, it
            # took a core from the scans and the branches from eps = 0: 45 ms more waiting for
            # the scans in the README's srp_map)
            grid = scanner.submit(grid_sweep, 1)
            run(jobs, lead)
            for (e_end, inward), scan in zip(ends, scans):
                known = found_at(e_end)
                found = scan.result()
                jobs, lead = [], []
                for s1 in sorted(found, key=lambda x: x.wz0):
                    if any(k.n_total == s1.n_total and k.kind == s1.kind and abs(k.wz0 - s1.wz0) < 1e-7
                           and abs(math.remainder(k.phi0 - s1.phi0, 2 * math.pi)) < 1e-7 for k in known):
                        continue
                    known.append(s1)
                    jobs.append((s1, e_end, inward, "end"))
                    lead.append([(e_end, s1)])
                run(jobs, lead)
            for r in runs:
                record(*r)
            path.sort(key=lambda p: (p[0], p[1]))
            data = grid.result()
        advance()
    sol_arr = lambda f, dt=float: np.array([f(b, e, s) for b, e, s in sols], dtype=dt)  # noqa: E731
    ds = xr.Dataset(
        {
            "dwz": (("eps", "wz0"), data["dwz"], {"units": "1/TU", "long_name": "wz(KT) - wz(0)"}),
            "dphi": (("eps", "wz0"), data["dphi"], {"units": "rad", "long_name": "phi(KT) - phi0 wrapped to (-pi, pi]"}),
            "phi_T": (("eps", "wz0"), data["phi_t"], {"units": "rad", "long_name": "phi(KT), unwrapped"}),
            "status": (("eps", "wz0"), data["status"].astype(np.uint8), {"flag_values": "0 ok, 1 max steps, 2 failed"}),
            "sol_eps": ("solution", sol_arr(lambda b, e, s: e)),
            "sol_branch": ("solution", sol_arr(lambda b, e, s: b, np.int64)),
            "sol_wz0": ("solution", sol_arr(lambda b, e, s: s.wz0), {"units": "1/TU"}),
            "sol_phidot0": ("solution", sol_arr(lambda b, e, s: s.phidot0), {"units": "1/TU"}),
            "sol_phi0": ("solution", sol_arr(lambda b, e, s: math.remainder(s.phi0, 2 * math.pi)), {"units": "rad",
                         "long_name": "phi0 wrapped to [-pi, pi]"}),
            "sol_n": ("solution", turns_array(s.n for b, e, s in sols), {"long_name": "net body turns per orbit period"}),
            "sol_n_total": ("solution", sol_arr(lambda b, e, s: s.n_total, np.int64),
                            {"long_name": "net body turns over the n_periods periods"}),
            "sol_kind": ("solution", sol_arr(lambda b, e, s: s.kind, "<U9")),
            "sol_trace": ("solution", sol_arr(lambda b, e, s: s.trace)),
            "sol_stable": ("solution", sol_arr(lambda b, e, s: s.stable, bool)),
            "sol_residual": ("solution", sol_arr(lambda b, e, s: s.residual)),
            "path_branch": ("path", np.array([p[0] for p in path], dtype=np.int64)),
            "path_eps": ("path", np.array([p[1] for p in path], dtype=float)),
            "path_wz0": ("path", np.array([p[2] for p in path], dtype=float), {"units": "1/TU"}),
            "path_phi0": ("path", np.array([math.remainder(p[3], 2 * math.pi) for p in path], dtype=float), {"units": "rad"}),
            "path_trace": ("path", np.array([p[4] for p in path], dtype=float)),
            "branch_n": ("branch", np.array([x[0] / n_periods for x in branches], dtype=float),
                         {"long_name": "net body turns per orbit period"}),
            "branch_n_total": ("branch", np.array([x[0] for x in branches], dtype=np.int64)),
            "branch_kind": ("branch", np.array([x[1] for x in branches], dtype="<U9")),
            "branch_origin": ("branch", np.array([x[2] for x in branches], dtype="<U7")),
            "branch_start_eps": ("branch", np.array([x[3] for x in branches], dtype=float)),
            "branch_end_eps": ("branch", np.array([x[4] for x in branches], dtype=float)),
            "branch_end_wz0": ("branch", np.array([x[5] for x in branches], dtype=float), {"units": "1/TU"}),
            "branch_fold": ("branch", np.array([x[6] for x in branches], dtype=bool)),
            "branch_end_reason": ("branch", np.array([str(x[7]) for x in branches], dtype=str)),
        },
        coords={
            "eps": ("eps", es, {"long_name": "flat-plate SRP amplitude P A d TU^2 / Iz"}),
            "wz0": ("wz0", wz, {"units": "1/TU", "long_name": "initial inertial angular rate"}),
            "phidot0": ("wz0", wz - 1.0, {"units": "1/TU", "long_name": "initial rate relative to the synodic frame"}),
        },
        attrs={
            "title": "librate flat-plate SRP periodicity map over (eps, wz0)",
            "map": "srp-eps",
            "kz": kz,
            "cs": float(plate.cs),
            "cd": float(plate.cd),
            "ca": float(plate.ca),
            "theta_sun0": float(theta_sun0),
            "phi0": phi0,
            "n_periods": n_periods,
            "x0": orbit.x0,
            "period": orbit.period,
            "period_days": orbit.period_days,
            "sun_resonance": sun_resonance(orbit) or 0,
            "system_name": orbit.system.name,
            "mu": orbit.system.mu,
            "tu_s": orbit.system.tu_s,
            "librate_version": __version__,
        },
    )
    if not solve:
        ds = ds.drop_vars([v for v in ds.data_vars if v.startswith(("sol_", "path_", "branch_"))])
    advance()  # the solutions assembled: done == total
    return ds


def sun_pointing_accelerations(system, body_or_plate, t, *, orbit: PeriodicOrbit, offset: float = 0.0, kz: float | None = None,
                               sun=None) -> tuple[np.ndarray, np.ndarray]:
    """The angular accelerations on a body held pointing at the Sun along an orbit (thesis Fig. 39):
    the gravity-gradient and the SRP parts, for phi(t) = theta_s(t) + ``offset``.

    Gravity gradient: 1.5 Kz [S cos 2 phi - C sin 2 phi] with S, C of the orbit's forcing; SRP:
    ``plate.wzdot(t, phi)`` for a `FlatPlate`, or the z torque of a `FacetBody`'s facets over Iz.

    Parameters
    ----------
    system : System or str
        The system.
    body_or_plate : FlatPlate or FacetBody
        A plate (then ``kz`` is required and the Sun is the plate's), or a faceted body (``kz``
        from its inertia; planar: body z along synodic Z, the Sun at the angle -offset in body
        axes).
    t : array_like
        Times (TU).
    orbit : PeriodicOrbit
        The orbit.
    offset : float, default 0.0
        The body x axis's angle from the Sun direction (rad).
    kz : float, optional
        Inertia ratio (with a plate).
    sun : Sun, optional
        With a `FacetBody`: the Sun (default `Sun()`).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        (gravity gradient, SRP) angular accelerations at ``t`` (1/TU^2).

    Raises
    ------
    ValueError
        A bad argument, naming it.
    """
    sys_ = check_system(system)
    if not isinstance(orbit, PeriodicOrbit):
        raise ValueError(f"invalid argument `orbit`: must be a librate.PeriodicOrbit, got {type(orbit).__name__}")
    if orbit.state0[2] != 0.0 or orbit.state0[5] != 0.0:
        raise ValueError("invalid argument `orbit`: the planar attitude model needs a planar orbit (z = zd = 0)")
    offset = as_number(offset, "offset")
    if isinstance(body_or_plate, FlatPlate):
        if sun is not None:
            raise ValueError("invalid argument `sun`: a FlatPlate carries its own Sun (plate.sun)")
        if kz is None:
            raise ValueError("invalid argument `kz`: a number in [-1, 1] is needed with a FlatPlate")
        kz = as_number(kz, "kz")
        if abs(kz) > 1:
            raise ValueError(f"invalid argument `kz`: must be in [-1, 1], got {kz!r}")
        sun_ = body_or_plate.sun
    elif isinstance(body_or_plate, FacetBody):
        if kz is not None:
            raise ValueError("invalid argument `kz`: a FacetBody's inertia sets Kz (leave kz=None)")
        kz = float(body_or_plate.kz)
        sun_ = Sun() if sun is None else sun
        if not isinstance(sun_, Sun):
            raise ValueError(f"invalid argument `sun`: must be a librate.Sun, got {sun!r}")
    else:
        raise ValueError("invalid argument `body_or_plate`: must be a librate.FlatPlate or a librate.FacetBody, got "
                         f"{type(body_or_plate).__name__}")
    t = as_float_array(t, "t")
    if not np.all(np.isfinite(t)):
        raise ValueError("invalid argument `t`: times must be finite")
    phi = sun_angle(sun_.theta0, t) + offset
    s_, c_ = orbit_forcing(orbit).sc(np.ascontiguousarray(t.ravel()))
    s_, c_ = np.asarray(s_).reshape(t.shape), np.asarray(c_).reshape(t.shape)
    gg = _core.planar_gravity_gradient(kz, np.ascontiguousarray(s_.ravel()), np.ascontiguousarray(c_.ravel()),
                                       np.ascontiguousarray(np.broadcast_to(phi, t.shape).ravel())).reshape(t.shape)
    if isinstance(body_or_plate, FlatPlate):
        srp = np.asarray(body_or_plate.wzdot(t, phi), dtype=float)
    else:
        alpha = (sun_angle(sun_.theta0, t) - phi).ravel()
        scale = sun_.pressure / SOLAR_PRESSURE_1AU * sys_.tu_s**2 / body_or_plate.iz
        srp = np.array([force_torque(body_or_plate.facets, (math.cos(v), math.sin(v), 0.0))[1][2] for v in alpha]) * scale
        srp = srp.reshape(t.shape)
    return gg, srp
