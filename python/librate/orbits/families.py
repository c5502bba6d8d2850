"""Families of symmetric periodic orbits built by continuation: DROs, planar Lyapunov orbits,
halos and NRHOs.

A family is computed by continuation (``librate.orbits.orbit_continuation``), every member's
stability from its monodromy matrix (batch-propagated on all cores), and bifurcations located
where a stability index crosses +1 or -1. The result is an :class:`OrbitFamily`
(:mod:`librate.orbits.orbit_family`: its members, lookup and files); :func:`dro`,
:func:`lyapunov` and :func:`halo` return one member of a family computed once per system and
cached.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from .._checks import as_between, as_count, as_float_array, as_real, as_tolerance
from .._errors import ConvergenceError, LibrateError
from .._progress import as_progress
from .orbit_continuation import continue_arclength, continue_natural, geometry
from .orbit_family import OrbitFamily, check_branch
from .periodic import SHOOT_ATOL, SHOOT_RTOL, PeriodicOrbit, check_outside_primaries, collision_mode, correct_symmetric
from .system import System, resolve_system

__all__ = ["OrbitFamily", "correct_dro", "dro", "dro_family", "lyapunov", "lyapunov_family", "halo", "halo_family"]


# --- DROs ------------------------------------------------------------------------------------
def _collision_stop(system: System, radii_km: tuple[float, float]):
    """Stop reason when the orbit passes within a primary's radius (point-mass model: only
    radii > 0 count, and only if the first member was outside)."""
    radii = [r / system.lu_km for r in radii_km]
    state = {"inside": None}

    def stop(orbit, g):
        if g is None:
            return None
        inside = [r > 0 and d < r for d, r in zip(g.min_distance, radii)]
        if state["inside"] is None:
            state["inside"] = inside
            return None
        for k, name in ((0, "larger primary (Earth)"), (1, "smaller primary (Moon)")):
            if inside[k] and not state["inside"][k]:
                return f"collision: the orbit passes within the {name}'s radius ({radii_km[k]} km)"
        return None

    return stop


#: Winding numbers (turns about the Earth, about the Moon; negative = clockwise in the synodic
#: frame) shared by every DRO: once clockwise about the Moon, not about the Earth.
DRO_WINDING = (0, -1)


def correct_dro(
    system: System | str,
    x0: float,
    ydot0: float | None = None,
    *,
    tol: float = 1e-12,
    max_iter: int = 30,
    rtol: float = SHOOT_RTOL,
    atol: float = SHOOT_ATOL,
    collision: str | None = "radius",
) -> PeriodicOrbit:
    """Correct the distant retrograde orbit (DRO) through (x0, 0, 0) with ydot0 > 0.

    The method is single shooting on the half period (thesis eq. 19; docs/physics.md, periodic
    orbits). The trajectory is integrated with its STM to the next y = 0 crossing, located in
    time, and ydot0 is corrected (x0 held fixed) until xdot vanishes there. Without ``ydot0``
    the guess is the retrograde circle about the Moon as it appears in the rotating frame,
    ydot0 = sqrt(mu/d) + d with d = 1 - mu - x0. That guess is good close to the Moon
    (d <= 0.2); farther out, the family is instead continued (guarded natural continuation)
    from x0 = 0.95 to ``x0``.

    The orbit returned is always a DRO: it winds once clockwise about the Moon and not about
    the Earth (winding numbers (0, -1)). A correction that lands on some other orbit (e.g. one
    about the Earth, from a poor ``ydot0``) raises :class:`librate.ConvergenceError` naming
    what it found.

    Parameters
    ----------
    system : System or str
        The system, or a preset name ("earth-moon", "earth-moon-jpl").
    x0 : float
        The x-axis crossing, between the primaries: -mu < x0 < 1 - mu (finite, not a bool).
    ydot0 : float, optional
        The guess of the velocity at x0 (LU/TU), a finite number > 0. By default the circle
        guess near the Moon (d <= 0.2), the family continued from x0 = 0.95 farther out.
    tol : float, default 1e-12
        Newton tolerance, in [1e-15, 1e-3].
    max_iter : int, default 30
        Newton iterations at most, in [1, 10,000].
    rtol, atol : float, default 1e-13
        Integration tolerances, rtol in [1e-15, 1e-3] and atol in [1e-18, 1e-3].
    collision : {"radius", "point", None}, default "radius"
        As in :func:`librate.correct_symmetric`. With "radius", a DRO that passes within a
        primary's radius raises :class:`librate.CollisionError`: in the Earth-Moon system the
        Moon's for x0 near 0.985, the Earth's for x0 near 0. "point" counts only the singular
        points; ``None`` returns the point-mass orbit anyway. (When the family is continued
        from x0 = 0.95, ``tol``, ``max_iter``, ``rtol`` and ``atol`` apply to that first
        member; the continuation's own corrections keep their defaults.)

    Returns
    -------
    PeriodicOrbit
        The corrected DRO (family "dro").

    Raises
    ------
    ValueError
        An argument out of range (``x0`` outside the primaries, ``ydot0`` not > 0, a tolerance
        or count outside its range, an unknown system or collision mode), naming it.
    ConvergenceError
        Newton did not converge; the family continued from x0 = 0.95 did not reach ``x0``; or
        the correction converged to an orbit that is not a DRO (its ydot0, period and winding
        numbers named).
    CollisionError
        The DRO passes within a primary's radius (with ``collision`` "radius" or "point"),
        naming the primary, the closest approach and the radius.

    Examples
    --------
    >>> import librate
    >>> orbit = librate.correct_dro("earth-moon", 0.9)
    >>> orbit.family, round(orbit.period_days, 3)
    ('dro', 5.545)
    >>> librate.correct_dro("earth-moon", 0.985)
    Traceback (most recent call last):
        ...
    librate.CollisionError: the corrected dro orbit (x0 = 0.985, ...) passes within the Moon's radius (primary 2): ...
    >>> librate.correct_dro("earth-moon", 0.985, collision=None).family
    'dro'
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    collision_mode(collision)
    if not (isinstance(x0, (int, float, np.integer, np.floating)) and not isinstance(x0, (bool, np.bool_))
            and math.isfinite(x0) and -mu < x0 < 1.0 - mu):
        raise ValueError(f"invalid argument `x0`: a DRO starts between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}), got {x0!r}")
    x0 = float(x0)
    if ydot0 is not None:
        ydot0 = as_real(ydot0, "ydot0", positive=True)
    as_count(max_iter, "max_iter", 1)
    as_tolerance(tol, "tol")
    as_tolerance(rtol, "rtol")
    as_tolerance(atol, "atol")
    d = 1.0 - mu - x0
    if ydot0 is None and d > 0.2:
        start = _correct_dro_at(sys_, 0.95, None, tol, max_iter, rtol, atol)
        res = continue_natural(sys_, start, "x0", [x0], family="dro")
        if not res.members:
            raise ConvergenceError(f"DRO at x0 = {x0}: the family continued from x0 = 0.95 did not reach it ({res.end_reason})")
        orbit = res.members[-1]
    else:
        orbit = _correct_dro_at(sys_, x0, ydot0, tol, max_iter, rtol, atol)
    g = geometry(orbit)
    if g.winding != DRO_WINDING:
        raise ConvergenceError(
            f"DRO correction at x0 = {x0} converged to an orbit that is not a DRO: ydot0 = {orbit.vy0:.6g}, period {orbit.period:.6g} TU, "
            f"winding numbers about (Earth, Moon) {g.winding} instead of {DRO_WINDING}; omit ydot0 (the family is then continued) "
            "or use librate.dro(system, x0=...)")
    return check_outside_primaries(orbit, collision)


def _correct_dro_at(sys_, x0, ydot0, tol, max_iter, rtol, atol) -> PeriodicOrbit:
    if ydot0 is None:
        d = 1.0 - sys_.mu - x0
        ydot0 = math.sqrt(sys_.mu / d) + d
    return correct_symmetric(sys_, (x0, 0.0, ydot0), fix="x0", family="dro", tol=tol, max_iter=max_iter, rtol=rtol,
                             atol=atol, collision=None)


#: The default DRO family's members: x0 from 0.985 near the Moon to 0.005 near the Earth, every 0.005.
DRO_DEFAULT_X0 = np.round(np.arange(0.985, 0.0049, -0.005), 10)


def dro_family(system: System | str = "earth-moon", x0=None, *, check_geometry: bool = True, allow_partial: bool = False,
               progress=None) -> OrbitFamily:
    """The planar DRO family, by natural-parameter continuation in x0 (thesis eq. 20-22).

    Every continuation step is guarded against silent jumps (continuity of the Jacobi constant
    and of the period, the winding numbers about both primaries) and is halved when a guard
    trips. The run ends cleanly, with its ``end_reason``, when an orbit reaches the Earth's
    surface or the step reaches its floor, and every member found up to there is kept.
    Members that pass within a primary's radius (in the Earth-Moon system, near the Moon at
    x0 = 0.985) are kept too, flagged in :attr:`OrbitFamily.inside_primary`.

    Requested members are reached the way the default family is. The continuation starts at
    x0 = 0.985 (or at the largest requested x0, if above that) and walks down the default
    members to the smallest requested x0; each requested x0 is inserted among the targets and
    corrected exactly there. The family then holds only the requested members, in the
    requested order. Any member the default family reaches can thus be requested.

    Parameters
    ----------
    system : System or str, default "earth-moon"
        The system, or a preset name.
    x0 : float or array_like, optional
        The members wanted, in any order along the family, each finite and between the
        primaries (-mu < x0 < 1 - mu); at least one. By default the whole family, from 0.985
        near the Moon to 0.005 near the Earth every 0.005 (:data:`DRO_DEFAULT_X0`).
    check_geometry : bool, default True
        Guard the steps with the winding numbers about both primaries too (False: the Jacobi
        constant and period continuity only).
    allow_partial : bool, default False
        With ``x0`` given, return the members found when some were not reached
        (``parameters["missing_x0"]`` lists the others) instead of raising.
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)``, called as the requested members
        are reached (total: their number).

    Returns
    -------
    OrbitFamily
        The family (kind "dro", planar), with ``end_reason``, the bifurcations between its
        members and ``parameters["rejected_jumps"]`` (the steps the guards refused).

    Raises
    ------
    ValueError
        An argument out of range (an ``x0`` empty, not finite or outside the primaries, a bad
        ``progress``), naming it.
    LibrateError
        With ``x0`` given and ``allow_partial`` False, some requested member was not reached:
        the message lists the missing x0 values and why the continuation ended (attributes
        ``missing``, ``found`` and ``end_reason``).
    ConvergenceError
        The first member (at the largest x0) could not be corrected.

    Examples
    --------
    >>> import librate
    >>> fam = librate.dro_family("earth-moon", x0=[0.95, 0.9, 0.85])
    >>> len(fam), fam.period_days.round(3).tolist()
    (3, [1.724, 5.545, 9.977])
    >>> fam.end_reason
    'completed: reached the last requested value'
    """
    sys_ = resolve_system(system)
    mu = sys_.mu
    xs = DRO_DEFAULT_X0.copy() if x0 is None else np.atleast_1d(as_float_array(x0, "x0")).ravel()
    if xs.size == 0 or not np.all(np.isfinite(xs)) or np.any(xs <= -mu) or np.any(xs >= 1 - mu):
        raise ValueError(f"invalid argument `x0`: DROs start between the primaries, -mu < x0 < 1 - mu = ({-mu}, {1 - mu}); got {x0!r}")
    progress = as_progress(progress, "dro family", "member")
    top = max(float(xs.max()), float(DRO_DEFAULT_X0[0]))
    ds_min = 1e-6  # the natural continuation's step floor: default members closer to a request are left out
    grid = [g for g in DRO_DEFAULT_X0 if float(xs.min()) < g <= top and np.min(np.abs(xs - g)) > ds_min]
    path = np.array(sorted(set(float(v) for v in xs) | set(float(g) for g in grid), reverse=True))
    wanted = np.isin(path, xs)
    n_wanted = int(np.unique(xs).size)
    counted = np.concatenate([[0], np.cumsum(wanted)])

    def along(done, total):  # the run's progress over the path, as requested members reached
        if progress is not None:
            progress(int(counted[min(int(done), path.size)]), n_wanted)

    first = correct_dro(sys_, float(path[0]), collision=None)
    stop = _collision_stop(sys_, (sys_.r1_km, 0.0))
    res = continue_natural(sys_, first, "x0", path, family="dro", check_geometry=check_geometry, stop=stop,
                           progress=along if progress is not None else None)
    params: dict = {"rejected_jumps": res.rejected_jumps}
    members, bifurcations = res.members, res.bifurcations
    if x0 is not None:
        got = np.array([m.x0 for m in res.members])
        pick = [int(np.flatnonzero(got == x)[0]) for x in xs if np.any(got == x)]
        missing = [float(x) for x in xs if not np.any(got == x)]
        if missing:
            if not allow_partial:
                err = LibrateError(f"dro_family: {len(missing)} of the {xs.size} requested members were not reached, x0 = {missing} "
                                   f"(the continuation ended: {res.end_reason}); {len(pick)} found; pass allow_partial=True to keep them")
                err.missing, err.found, err.end_reason = missing, [float(got[i]) for i in pick], res.end_reason
                raise err
            params["missing_x0"] = missing
        members = [res.members[i] for i in pick]
        bifurcations = _kept_bifurcations(res.bifurcations, pick)
    return OrbitFamily.from_members(sys_, "dro", False, members, res.end_reason, params, bifurcations=bifurcations)


def _kept_bifurcations(bifurcations, pick: list[int]):
    """The driver's bifurcations for a family of the members ``pick`` (indices into the run's
    members): those between two kept members, their ``after`` renumbered, when the kept members
    are in the run's order; otherwise None (the family then detects them between its members)."""
    if any(b <= a for a, b in zip(pick, pick[1:])):
        return None
    out = []
    for b in bifurcations:
        j = int(np.searchsorted(pick, b.after, side="right")) - 1  # the last kept member at or before b.after
        if 0 <= j < len(pick) - 1:
            out.append(dataclasses.replace(b, after=j))
    return out


@functools.lru_cache(maxsize=8)
def _default_dro_family(system: System) -> OrbitFamily:
    return dro_family(system)


def _one_target(kw: dict) -> tuple[str, float]:
    given = {k: v for k, v in kw.items() if v is not None}
    if len(given) != 1:
        raise ValueError(f"invalid arguments {', '.join(f'`{k}`' for k in kw)}: give exactly one of them, got {', '.join(given) or 'none'}")
    return next(iter(given.items()))


def dro(system: System | str = "earth-moon", *, x0: float | None = None, period: float | None = None,
        period_days: float | None = None, jacobi: float | None = None, which: int | None = None) -> PeriodicOrbit:
    """One corrected DRO, chosen by its x0, period (TU or days) or Jacobi constant.

    Near the Moon (x0 >= 0.8) an ``x0`` is corrected directly (:func:`correct_dro`). Any other
    value is looked up on the whole default family (:func:`dro_family`, computed once per
    system and cached) by :meth:`OrbitFamily.member`. Exactly one of ``x0``, ``period``,
    ``period_days`` and ``jacobi`` is given.

    Parameters
    ----------
    system : System or str, default "earth-moon"
        The system, or a preset name.
    x0 : float, optional
        The x-axis crossing, finite and between the primaries (-mu < x0 < 1 - mu); below 0.8,
        within the default family's range (0.985 to 0.005).
    period : float, optional
        The period (TU), within the default family's range.
    period_days : float, optional
        The period in days, within the default family's range.
    jacobi : float, optional
        The Jacobi constant, within the default family's range.
    which : int, optional
        As in :meth:`OrbitFamily.member`: for a value that several members have, the index of
        the one wanted among them (ordered by period). Not used for an ``x0`` >= 0.8.

    Returns
    -------
    PeriodicOrbit
        The corrected DRO (family "dro").

    Raises
    ------
    ValueError
        Not exactly one of the four given, a value not a finite number or outside the family's
        range, an ambiguous value without ``which`` (the candidates listed with their periods)
        or a ``which`` out of range.
    ConvergenceError
        The correction did not converge.
    CollisionError
        The DRO passes within a primary's radius (e.g. the Moon's at x0 near 0.985).

    Examples
    --------
    >>> import librate
    >>> orbit = librate.dro(period_days=12.66)
    >>> round(orbit.x0, 5)
    0.82017
    >>> round(librate.dro(x0=0.9).period_days, 3)
    5.545
    """
    sys_ = resolve_system(system)
    name, value = _one_target(dict(x0=x0, period=period, period_days=period_days, jacobi=jacobi))
    value = as_real(value, name)
    if name == "x0":
        if not (math.isfinite(value) and -sys_.mu < value < 1 - sys_.mu):
            raise ValueError(f"invalid argument `x0`: DROs start between the primaries, -mu < x0 < 1 - mu; got {value!r}")
        if value >= 0.8:
            return correct_dro(sys_, value)
    return _default_dro_family(sys_).member(**{name: value}, which=which)


# --- Lyapunov and halo orbits -----------------------------------------------------------------
def _check_point(point) -> int:
    if isinstance(point, (bool, np.bool_)) or point not in (1, 2):
        raise ValueError(f"invalid argument `point`: must be 1 (L1) or 2 (L2), got {point!r}")
    return int(point)


def _lyapunov_start(sys_: System, point: int, amplitude: float) -> PeriodicOrbit:
    """Small planar Lyapunov orbit from the linearisation at L1/L2: x = L - A cos(w t),
    ydot0 = (w^2 + Uxx) A / 2, with w the in-plane centre frequency."""
    mu = sys_.mu
    xl = float(sys_.lagrange_points()[point - 1, 0])
    c2 = (1 - mu) / abs(xl + mu) ** 3 + mu / abs(xl - 1 + mu) ** 3
    uxx, uyy = 1 + 2 * c2, 1 - c2
    b = 4 - uxx - uyy
    w2 = 0.5 * (b + math.sqrt(b * b - 4 * uxx * uyy))
    a = -amplitude
    vy0 = -(w2 + uxx) * a / 2
    return correct_symmetric(sys_, (xl + a, 0.0, vy0), fix="x0", family=f"lyapunov-L{point}", collision=None)


def lyapunov_family(system: System | str = "earth-moon", point: int = 1, *, max_members: int = 150,
                    ds_max: float = 0.02, check_geometry: bool = True, progress=None) -> OrbitFamily:
    """The planar Lyapunov family at L1 or L2, by pseudo-arclength continuation.

    The family starts from a small orbit, x0 = L - 0.002 (on the side of the libration point L
    toward the larger primary), corrected from the linearisation at L, and grows in amplitude.
    The run ends when an orbit passes within a primary's radius (a collision with the Moon's
    or the Earth's surface), when the step reaches its floor, or at ``max_members``.

    Parameters
    ----------
    system : System or str, default "earth-moon"
        The system, or a preset name.
    point : {1, 2}, default 1
        The libration point, L1 or L2.
    max_members : int, default 150
        Members at most, in [2, 100,000].
    ds_max : float, default 0.02
        The largest continuation step in (x0, z0, vy0) (LU, LU/TU), in [1e-5, 0.5].
    check_geometry : bool, default True
        Guard the steps with the winding numbers about both primaries too (False: the Jacobi
        constant and period continuity only).
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)`` after each member (total:
        ``max_members`` until the end, then the number found).

    Returns
    -------
    OrbitFamily
        The family (kind "lyapunov-L1" or "lyapunov-L2", planar; ``parameters["point"]``),
        with its ``end_reason`` and bifurcations.

    Raises
    ------
    ValueError
        An argument out of range, naming it.
    ConvergenceError
        The small starting orbit could not be corrected.

    Examples
    --------
    >>> import librate
    >>> fam = librate.lyapunov_family("earth-moon", 1, max_members=10)
    >>> len(fam), fam.kind, fam.end_reason
    (10, 'lyapunov-L1', 'completed: max_points = 10 reached')
    >>> l1 = fam.system.lagrange_points()[0, 0]
    >>> round(float(fam.x0[0] - l1), 6)
    -0.002
    """
    sys_ = resolve_system(system)
    point = _check_point(point)
    max_members, ds_max = as_count(max_members, "max_members", 2), as_between(ds_max, "ds_max", 1e-5, 0.5)
    first = _lyapunov_start(sys_, point, 2e-3)
    res = continue_arclength(
        sys_, first, spatial=False, orient=np.array([-1.0, 0.0, 0.0]), ds=2e-3, ds_max=ds_max, max_members=max_members,
        family=f"lyapunov-L{point}", check_geometry=check_geometry, stop=_collision_stop(sys_, (sys_.r1_km, sys_.r2_km)), progress=progress,
    )
    return OrbitFamily.from_members(sys_, f"lyapunov-L{point}", False, res.members, res.end_reason, {"point": point},
                                    bifurcations=res.bifurcations)


@functools.lru_cache(maxsize=8)
def _cached_lyapunov(system: System, point: int) -> OrbitFamily:
    return lyapunov_family(system, point)


def lyapunov(system: System | str = "earth-moon", point: int = 1, *, x0: float | None = None,
             period: float | None = None, period_days: float | None = None, jacobi: float | None = None,
             which: int | None = None) -> PeriodicOrbit:
    """One planar Lyapunov orbit at L1 or L2, chosen by its x0, period (TU or days) or Jacobi constant.

    The orbit is looked up on the family (:func:`lyapunov_family` with its defaults, computed
    once per system and point and cached) by :meth:`OrbitFamily.member`. Exactly one of
    ``x0``, ``period``, ``period_days`` and ``jacobi`` is given.

    Parameters
    ----------
    system : System or str, default "earth-moon"
        The system, or a preset name.
    point : {1, 2}, default 1
        The libration point, L1 or L2.
    x0 : float, optional
        The x-axis crossing, within the family's range.
    period : float, optional
        The period (TU), within the family's range.
    period_days : float, optional
        The period in days, within the family's range.
    jacobi : float, optional
        The Jacobi constant, within the family's range.
    which : int, optional
        As in :meth:`OrbitFamily.member`: for a value that several members have, the index of
        the one wanted among them (ordered by period).

    Returns
    -------
    PeriodicOrbit
        The corrected orbit (family "lyapunov-L1" or "lyapunov-L2").

    Raises
    ------
    ValueError
        Not exactly one of the four given, a bad ``point``, a value not a finite number or
        outside the family's range, an ambiguous value without ``which`` (the candidates listed
        with their periods) or a ``which`` out of range.
    ConvergenceError
        The correction did not converge.
    CollisionError
        The orbit passes within a primary's radius.

    Examples
    --------
    >>> import librate
    >>> orbit = librate.lyapunov("earth-moon", 1, x0=0.8)
    >>> orbit.family, round(orbit.period_days, 3)
    ('lyapunov-L1', 14.431)
    """
    sys_ = resolve_system(system)
    name, value = _one_target(dict(x0=x0, period=period, period_days=period_days, jacobi=jacobi))
    return _cached_lyapunov(sys_, _check_point(point)).member(**{name: value}, which=which)


def halo_family(system: System | str = "earth-moon", point: int = 2, branch: str = "south", *, max_members: int = 400,
                ds_max: float = 0.02, check_geometry: bool = True, progress=None) -> OrbitFamily:
    """The halo family at L1 or L2, from its bifurcation off the planar Lyapunov family into the NRHOs.

    The family starts where it branches off the planar Lyapunov family (:func:`lyapunov`'s
    cached family), at the bifurcation where the out-of-plane stability index crosses +1: the
    planar orbit there is corrected, lifted to z0 = 0.002 and corrected in 3-D. It is then
    continued by pseudo-arclength in (x0, z0, vy0) into the near-rectilinear halo orbits
    (NRHOs), until an orbit reaches a primary's surface (the Moon's), the step reaches its
    floor, or at ``max_members``.

    The branches follow the usual convention, the JPL catalog's too: a southern halo has its
    largest excursion from the x-y plane (apolune, for L2) below it, z < 0; a northern one
    above it. The two are mirror images of each other under z -> -z, so one is computed and
    mirrored. Each member's ``state0`` is its x-z-plane crossing in the branch's hemisphere
    (the one of smaller z for south, larger z for north), as the JPL catalog lists them;
    ``state_half`` is the other crossing. Neither x0 nor z0 is monotonic along the family; the
    period is, for L2.

    Parameters
    ----------
    system : System or str, default "earth-moon"
        The system, or a preset name.
    point : {1, 2}, default 2
        The libration point, L1 or L2.
    branch : {"south", "north"}, default "south"
        The branch.
    max_members : int, default 400
        Members at most, in [2, 100,000].
    ds_max : float, default 0.02
        The largest continuation step in (x0, z0, vy0) (LU, LU/TU), in [1e-5, 0.5].
    check_geometry : bool, default True
        Guard the steps with the winding numbers of planar members too (False: the Jacobi
        constant and period continuity only).
    progress : bool or callable, optional
        True for a bar on stderr, or ``progress(done, total)`` after each member (total:
        ``max_members`` until the end, then the number found).

    Returns
    -------
    OrbitFamily
        The family (kind "halo-L1-south", "halo-L2-north", ..., spatial), with its
        ``end_reason``, its bifurcations and ``parameters`` "point", "branch" and
        "bifurcation_x0" (the Lyapunov orbit it starts from).

    Raises
    ------
    ValueError
        An argument out of range (``point``, ``branch``, a count or step), naming it.
    LibrateError
        No halo bifurcation (out-of-plane index through +1) on the Lyapunov family.
    ConvergenceError
        The orbit at the bifurcation, or the first halo, could not be corrected.

    Examples
    --------
    >>> import librate
    >>> fam = librate.halo_family("earth-moon", 2, "south", max_members=10)
    >>> len(fam), fam.kind, bool((fam.z0 < 0).all())
    (10, 'halo-L2-south', True)
    >>> round(fam.parameters["bifurcation_x0"], 4)
    1.1204
    """
    sys_ = resolve_system(system)
    point = _check_point(point)
    sign = check_branch(branch)
    max_members, ds_max = as_count(max_members, "max_members", 2), as_between(ds_max, "ds_max", 1e-5, 0.5)
    lyap = _cached_lyapunov(sys_, point)
    cands = [b for b in lyap.bifurcations if b["index"] == "out-of-plane" and b["level"] == 1.0]
    if not cands:
        raise LibrateError(f"no halo bifurcation found on the L{point} Lyapunov family ({len(lyap)} members, end: {lyap.end_reason})")
    bif = cands[0]
    i = bif["member"]
    w = (bif["x0"] - lyap.x0[i]) / (lyap.x0[i + 1] - lyap.x0[i])
    p = lyap.state0[i] + w * (lyap.state0[i + 1] - lyap.state0[i])
    planar = correct_symmetric(sys_, p, fix="x0", family=f"lyapunov-L{point}", collision=None)
    name = f"halo-L{point}-{branch}"
    first = correct_symmetric(sys_, (planar.x0, 2e-3, planar.vy0), spatial=True, fix="z0", family=name, collision=None)
    res = continue_arclength(
        sys_, first, spatial=True, orient=np.array([0.0, 1.0, 0.0]), ds=2e-3, ds_max=ds_max, max_members=max_members,
        family=name, check_geometry=check_geometry, stop=_collision_stop(sys_, (sys_.r1_km, sys_.r2_km)), progress=progress,
    )
    fam = OrbitFamily.from_members(sys_, name, True, res.members, res.end_reason,
                                   {"point": point, "branch": branch, "bifurcation_x0": bif["x0"]}, bifurcations=res.bifurcations)
    # Name the branch by the sign of z where |z| is largest along the family (apolune).
    both = np.concatenate([fam.state0[:, 2], fam.state_half[:, 2]])
    if np.sign(both[np.argmax(np.abs(both))]) != sign:
        flip = np.array([1.0, 1.0, -1.0, 1.0, 1.0, -1.0])
        fam.state0 = fam.state0 * flip
        fam.state_half = fam.state_half * flip
        for b in fam.bifurcations:
            b["z0"], b["z0_half"] = -b["z0"], -b["z0_half"]
    fam._hemisphere_first(sign)
    return fam


@functools.lru_cache(maxsize=8)
def _cached_halo(system: System, point: int, branch: str) -> OrbitFamily:
    return halo_family(system, point, branch)


def halo(system: System | str = "earth-moon", point: int = 2, branch: str = "south", *, x0: float | None = None,
         z0: float | None = None, period: float | None = None, period_days: float | None = None,
         jacobi: float | None = None, which: int | None = None) -> PeriodicOrbit:
    """One halo orbit at L1 or L2, north or south, chosen by its x0, z0, period (TU or days) or Jacobi constant.

    The orbit is looked up on the family (:func:`halo_family` with its defaults, computed once
    per system, point and branch and cached) by :meth:`OrbitFamily.member`. ``x0`` and ``z0``
    are those of ``state0``, the x-z-plane crossing in the branch's hemisphere (the JPL
    catalog's). Exactly one of ``x0``, ``z0``, ``period``, ``period_days`` and ``jacobi`` is
    given. Several members can have the value (x0, z0 and the Jacobi constant are not
    monotonic along the family): then ``ValueError`` lists them with their periods, and
    ``which`` picks one.

    Parameters
    ----------
    system : System or str, default "earth-moon"
        The system, or a preset name.
    point : {1, 2}, default 2
        The libration point, L1 or L2.
    branch : {"south", "north"}, default "south"
        The branch.
    x0, z0 : float, optional
        The components of ``state0``, within the family's range.
    period : float, optional
        The period (TU), within the family's range.
    period_days : float, optional
        The period in days, within the family's range.
    jacobi : float, optional
        The Jacobi constant, within the family's range.
    which : int, optional
        For a value that several members have, the index of the one wanted among them (ordered
        by period); with one candidate, omitted or 0.

    Returns
    -------
    PeriodicOrbit
        The corrected halo (family "halo-L2-south", ...).

    Raises
    ------
    ValueError
        Not exactly one of the five given, a bad ``point`` or ``branch``, a value not a finite
        number or outside the family's range, an ambiguous value without ``which`` or a
        ``which`` out of range.
    ConvergenceError
        The correction did not converge.
    CollisionError
        The orbit passes within a primary's radius.
    LibrateError
        The family could not be started (no halo bifurcation on the Lyapunov family).

    Examples
    --------
    >>> import librate
    >>> orbit = librate.halo("earth-moon", 2, "south", period_days=8.0)
    >>> round(orbit.z0, 4)
    -0.195
    >>> librate.halo(jacobi=3.05)
    Traceback (most recent call last):
        ...
    ValueError: ambiguous `jacobi` = 3.05: 2 members of the halo-L2-south family have it ...
    >>> round(librate.halo(jacobi=3.05, which=1).period_days, 3)
    13.317
    """
    sys_ = resolve_system(system)
    point = _check_point(point)
    check_branch(branch)
    name, value = _one_target(dict(x0=x0, z0=z0, period=period, period_days=period_days, jacobi=jacobi))
    return _cached_halo(sys_, point, branch).member(**{name: value}, which=which)
