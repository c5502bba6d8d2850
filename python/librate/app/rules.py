"""The rules between sections of a study (and what each command needs from it), on the section
models that passed type validation; the rules within one section are its model's validator
(:mod:`librate.app.schema`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .schema import Range, Table, grid_raw, grid_values, missing, problem, show_value


def _check_increasing(key: str, g, problems: list[str]) -> None:
    if isinstance(g, Range):
        if g.num < 2:
            problems.append(problem(f"{key}.num", g.num, "a rate grid needs at least 2 values", "an integer in [2, 1000000]"))
        if not g.start < g.stop:
            problems.append(problem(f"{key}.stop", g.stop, f"must be greater than {key}.start = {show_value(g.start)} (rates increase)",
                                     f"a number > {key}.start"))
    else:
        v = np.asarray(g, dtype=float)
        if v.size < 2:
            problems.append(problem(key, g, "a rate grid needs at least 2 values"))
        elif np.any(np.diff(v) <= 0):
            problems.append(problem(key, g, "must be strictly increasing"))


def common_rules(s: dict[str, Table], given: dict, purpose: str | None) -> list[str]:
    """The rules between sections that hold for every attitude model, on the sections that
    passed type validation (``s``); ``given`` is the raw study as written (to tell a missing
    section from a defaulted one). The rules within one section are its model's validator; each
    attitude model's own rules between sections are :func:`planar_rules` and :func:`rules_3d`
    (the study's class, :class:`librate.app.study.PlanarStudy` or ``Study3D``, picks one)."""
    problems: list[str] = []
    body, tq, rates = s.get("body"), s.get("torques"), s.get("rates")
    if tq is not None:
        srp = tq.srp  # one rule between [torques.srp] and [body]:
        if srp is not None and srp.eps is None and srp.area_m2 is not None and srp.offset_m is not None \
                and body is not None and body.iz is None and body.kz is not None:
            problems.append(problem("torques.srp.area_m2", srp.area_m2,
                                     "the plate's geometry needs the body's Iz in kg m^2 (body.ix, body.iy, body.iz); with body.kz alone "
                                     "give torques.srp.eps",
                                     "torques.srp.eps with body.kz, or the geometry with body.ix/iy/iz"))
    if rates is not None and rates.wz0 is not None and rates.phidot0 is not None:
        problems.append(problem("rates.phidot0", grid_raw(rates.phidot0), "cannot be combined with rates.wz0 (phidot0 = wz0 - 1)",
                                "either rates.wz0 or rates.phidot0"))
    if purpose == "transition":
        problems += _needs_transition(s, given)
    return problems


def planar_rules(s: dict[str, Table], given: dict, purpose: str | None) -> list[str]:
    """The planar model's rules between sections (a study whose [attitude] failed type
    validation is checked as planar, the default), and what ``purpose`` needs from it."""
    problems: list[str] = []
    orb, body, tq, rates = s.get("orbits"), s.get("body"), s.get("torques"), s.get("rates")
    if rates is not None:
        if rates.wz0 is None and rates.phidot0 is None:
            problems.append(missing("rates.wz0", "missing: give rates.wz0 (inertial) or rates.phidot0 (relative to the synodic frame)"))
        for k in ("wx0", "wy0"):
            if getattr(rates, k) is not None:
                problems.append(problem(f"rates.{k}", grid_raw(getattr(rates, k)),
                                         "applies only to attitude.model = \"3d\" (the planar model has the one rate wz)",
                                         "rates.wz0 or rates.phidot0 with the planar model; rates.wx0 and rates.wy0 with "
                                         "[attitude] model = '3d'"))
        for k in ("wz0", "phidot0"):
            if getattr(rates, k) is not None:
                _check_increasing(f"rates.{k}", getattr(rates, k), problems)
    if purpose not in ("solve", "map"):
        return problems
    what, need = ("periodic solutions", "need") if purpose == "solve" else ("a periodicity map", "needs")
    if "body" not in given:
        problems.append(missing("body", f"missing section [body]: {what} {need} the body (body.kz, or body.ix/iy/iz)"))
    if "rates" not in given:
        problems.append(missing("rates", f"missing section [rates]: {what} {need} the initial rates (rates.wz0 or rates.phidot0)"))
    if orb is not None and orb.kind == "halo":
        problems.append(problem("orbits.kind", orb.kind,
                                 f"{what} use{'s' if need == 'needs' else ''} the planar attitude model, which needs a planar family",
                                 "'dro' or 'lyapunov' with the planar model, or any family with [attitude] model = '3d'"))
    if purpose == "map" and body is not None and body.flexible is not None:
        problems.append(problem("body.flexible", body.flexible, "the periodicity-map engine integrates rigid bodies; "
                                 "`librate solve` reports how flexibility moves each periodic solution",
                                 "body.kz or body.ix/iy/iz for a map"))
    if body is not None and body.flexible is not None and tq is not None and tq.srp is not None:
        problems.append(problem("torques.srp", "[torques.srp]", "the flexible model has no solar radiation pressure yet",
                                "no [torques.srp] with body.flexible"))
    if tq is not None and sorted(tq.gravity_gradient) != ["earth", "moon"]:
        problems.append(problem("torques.gravity_gradient", tq.gravity_gradient,
                                 f"the planar engine behind {what} models the gravity gradient of both primaries", "[\"earth\", \"moon\"]"))
    if tq is not None and tq.srp is not None and orb is not None:
        why = "with torques.srp the forcing is periodic only on a Sun-resonant orbit (T = Ts / k): select exactly one"
        if orb.sun_resonance is None:
            problems.append(missing("orbits.sun_resonance", f"missing: {why}, e.g. orbits.sun_resonance = [2]"))
        elif len(orb.sun_resonance) != 1:
            problems.append(problem("orbits.sun_resonance", orb.sun_resonance, why, "a list of one integer k >= 1, e.g. [2]"))
        else:
            k = orb.sun_resonance[0]
            sol = s.get("solver")
            if sol is not None and sol.n_periods is not None and sol.n_periods % k:
                problems.append(problem("solver.n_periods", sol.n_periods,
                                         f"with torques.srp on the 1:{k} Sun-resonant orbit the attitude period must "
                                         "cover whole Sun periods",
                                         f"a multiple of {k}"))
    return problems


def rules_3d(s: dict[str, Table], given: dict, purpose: str | None) -> list[str]:
    """The 3-D model's rules between sections (``s["attitude"]`` an
    :class:`~librate.app.schema.Attitude3D`), and what ``purpose`` needs from it."""
    problems: list[str] = []
    att, rates = s["attitude"], s.get("rates")
    start = start_of(att, s.get("orbits"))
    if rates is not None:
        for k in ("wz0", "phidot0", "wx0", "wy0"):
            g = getattr(rates, k)
            if g is not None and not isinstance(g, (int, float)):  # a number is a fixed rate of a 3-D map; every grid increases
                _check_increasing(f"rates.{k}", g, problems)
    problems += _check_3d(att, start, s, given)
    eph = s.get("ephemeris")
    if start in ("planar", "spin") and att.n is None and (purpose == "solve" or eph is None or eph.attitude_n is None):
        # a transition's 3-D motions take their n from ephemeris.attitude_n (as the planar model needs no n at all)
        problems.append(missing("attitude.n", f"missing: attitude.start = \"{start}\" needs the net turns n per attitude period"))
    if purpose in ("solve", "map"):
        problems += _needs_3d(purpose, start, s, given)
    return problems


_NOT_3D = "not modelled in 3-D yet (the 3-D model has the gravity gradient of both primaries on a rigid body)"


def start_of(att, orb) -> str:
    """How a 3-D solve starts (:meth:`librate.app.schema.Attitude3D.start_on` for the orbits' family)."""
    return att.start_on(orb.kind if orb is not None else None)


def _check_3d(att, start: str, s: dict, given: dict) -> list[str]:
    """The rules between ``[attitude] model = "3d"`` and the other sections that passed type
    validation (the rules within [attitude] are its model's validator)."""
    problems: list[str] = []
    orb, body, tq, sol = s.get("orbits"), s.get("body"), s.get("torques"), s.get("solver")
    if start == "planar" and orb is not None and orb.kind == "halo":
        problems.append(problem("attitude.start", start,
                                 "the planar start takes a planar solution, which needs a planar family "
                                 "(orbits.kind = 'dro' or 'lyapunov')",
                                 "'spin' or 'given' on a halo family"))
    if att.q0 is not None and sol is not None and "phi0" in (given.get("solver") or {}):
        problems.append(problem("solver.phi0", sol.phi0, "cannot be combined with attitude.q0 (q0 is the whole initial attitude)",
                                 "solver.phi0 (a rotation about Z) or attitude.q0, not both"))
    if body is not None:
        if body.flexible is not None:
            problems.append(problem("body.flexible", body.flexible, f"flexible bodies are {_NOT_3D}",
                                    "body.ix, body.iy and body.iz (kg m^2) with attitude.model = '3d'"))
        elif body.kz is not None and body.ix is None and body.iy is None and body.iz is None:
            problems.append(problem("body.kz", grid_raw(body.kz),
                                     "the 3-D attitude model needs the full inertia, not Kz alone (Kz fixes only (Iy - Ix) / Iz)",
                                     "body.ix, body.iy and body.iz in kg m^2 (principal moments, each <= the sum of the other two)"))
    if tq is not None:
        if tq.srp is not None:
            problems.append(problem("torques.srp", "[torques.srp]", f"solar radiation pressure is {_NOT_3D}",
                                    "no [torques.srp] with attitude.model = '3d'"))
        if sorted(tq.gravity_gradient) != ["earth", "moon"]:
            problems.append(problem("torques.gravity_gradient", tq.gravity_gradient,
                                     "the 3-D attitude model has the gravity gradient of both primaries",
                                     "[\"earth\", \"moon\"]"))
    return problems


def member_count(orb) -> tuple[str, Any, int] | None:
    """(key, value, count) of the members [orbits] selects, None for the whole family."""
    for k in ("x0", "z0", "period_days"):
        g = getattr(orb, k)
        if g is not None:
            return k, grid_raw(g), int(grid_values(g).size)
    for k in ("resonance", "sun_resonance"):
        if getattr(orb, k) is not None:
            return k, getattr(orb, k), len(getattr(orb, k))
    if orb.members is not None:
        return "members", orb.members, orb.members
    return None


def _needs_3d(purpose: str, start: str, s: dict, given: dict) -> list[str]:
    """What ``librate solve`` or ``librate map`` needs from a 3-D study."""
    problems: list[str] = []
    rates = s.get("rates")
    what = "a 3-D solve" if purpose == "solve" else "a 3-D map"
    if "body" not in given:
        problems.append(missing("body", f"missing section [body]: {what} needs the body's principal moments (body.ix, body.iy, body.iz)"))
    if purpose == "solve":
        if start == "planar":
            if "rates" not in given:
                problems.append(missing("rates",
                                        "missing section [rates]: the planar start scans rates.wz0 (or rates.phidot0) "
                                        "for the planar solution"))
            elif rates is not None:
                if rates.wz0 is None and rates.phidot0 is None:
                    problems.append(missing("rates.wz0",
                                            "missing: the planar start scans rates.wz0 (or rates.phidot0) for the planar solution"))
                for k in ("wz0", "phidot0"):
                    g = getattr(rates, k)
                    if isinstance(g, (int, float)):
                        problems.append(problem(f"rates.{k}", g,
                                                "the planar start scans a grid of rates for the planar solution, not one value"))
        return problems
    if "rates" not in given:
        problems.append(missing("rates",
                                "missing section [rates]: a 3-D map needs rates.wx0, rates.wy0 and rates.wz0 (or rates.phidot0): two grids "
                                "and one fixed number"))
        return problems
    if rates is None:
        return problems
    comp = {"wx0": rates.wx0, "wy0": rates.wy0, "wz0": rates.wz0 if rates.wz0 is not None else rates.phidot0}
    for k, v in comp.items():
        if v is None:
            problems.append(missing(f"rates.{k}",
                                    "missing: a 3-D map needs rates.wx0, rates.wy0 and rates.wz0 (or rates.phidot0): two grids "
                                    "and one fixed number"))
    fixed = [k for k, v in comp.items() if isinstance(v, (int, float))]
    if all(v is not None for v in comp.values()) and len(fixed) != 1:
        key = fixed[-1] if fixed else "wz0"
        name = key if key != "wz0" or rates.wz0 is not None else "phidot0"
        problems.append(problem(f"rates.{name}", grid_raw(getattr(rates, name)),
                                 f"a 3-D map has grids over two rate components and one fixed number; "
                                 f"given {len(fixed)} fixed ({', '.join('rates.' + f for f in fixed) or 'none'})",
                                 "exactly one of rates.wx0, rates.wy0, rates.wz0 (or rates.phidot0) a number, the other two grids"))
    return problems


def _needs_transition(s: dict, given: dict) -> list[str]:
    """What ``librate transition`` needs: [ephemeris], and one orbit selected by [orbits]."""
    problems: list[str] = []
    if "ephemeris" not in given:
        problems.append(missing("ephemeris", "missing section [ephemeris]: a transition needs the epoch(s) (ephemeris.epoch)"))
    orb = s.get("orbits")
    if orb is not None:
        sel = member_count(orb)
        if sel is None:
            problems.append(missing("orbits.x0", "missing: a transition carries one orbit into the ephemeris model: select it "
                                                 "(e.g. orbits.x0 = [0.8], orbits.period_days = [6.56], orbits.members = 1)"))
        elif sel[2] != 1:
            problems.append(problem(f"orbits.{sel[0]}", sel[1],
                                    f"selects {sel[2]} orbits; a transition carries one orbit into the ephemeris model "
                                    "(its epochs are ephemeris.epoch)", "exactly one value"))
    eph = s.get("ephemeris")
    if eph is not None and eph.attitude_n is not None:
        problems += _needs_transition_attitude(s, given)
    return problems


def _needs_transition_attitude(s: dict, given: dict) -> list[str]:
    """What ``ephemeris.attitude_n`` needs: the CR3BP solutions found as ``librate solve`` finds
    them (the body, the rate scan), in a model the ephemeris attitude has (gravity gradient of a
    rigid body; no flat-plate SRP, no flexible body)."""
    from .schema import Attitude3D

    problems: list[str] = []
    n = s["ephemeris"].attitude_n
    body, rates, tq, orb, att = s.get("body"), s.get("rates"), s.get("torques"), s.get("orbits"), s.get("attitude")
    is_3d = isinstance(att, Attitude3D)
    start = start_of(att, orb) if is_3d else "planar"
    why = "ephemeris.attitude_n carries the CR3BP periodic attitude solutions that `librate solve` finds"
    if "body" not in given:
        problems.append(missing("body", f"missing section [body]: {why} for the body (body.kz, or body.ix/iy/iz)"))
    elif body is not None and not is_3d:
        if body.flexible is not None:
            problems.append(problem("body.flexible", body.flexible, "the ephemeris attitude model is a rigid body",
                                    "body.kz or body.ix/iy/iz"))
        elif body.kz is not None and grid_values(body.kz).size != 1:
            problems.append(problem("body.kz", grid_raw(body.kz), f"{why} for one body: one Kz", "one number in [-1, 1]"))
    if start == "planar" and "rates" not in given:
        problems.append(missing("rates", f"missing section [rates]: {why} by scanning rates.wz0 (or rates.phidot0)"))
    elif start == "planar" and rates is not None and rates.wz0 is None and rates.phidot0 is None:
        problems.append(missing("rates.wz0", f"missing: {why} by scanning rates.wz0 (or rates.phidot0)"))
    if is_3d and start == "given":
        problems.append(problem("ephemeris.attitude_n", n, "with attitude.start = \"given\" the 3-D motion has no N",
                                "ephemeris.attitude_n with attitude.start = 'planar' or 'spin' (each N the start's n)"))
    if not is_3d and orb is not None and orb.kind == "halo":
        problems.append(problem("orbits.kind", orb.kind, "the planar attitude solutions need a planar family",
                                "'dro' or 'lyapunov' with the planar model, or any family with [attitude] model = '3d'"))
    if tq is not None and tq.srp is not None:
        problems.append(problem("torques.srp", "[torques.srp]", "the ephemeris attitude model has no flat-plate SRP (its SRP acts on the "
                                "facets of a librate.FacetBody, in the Python API)", "no [torques.srp] with ephemeris.attitude_n"))
    if tq is not None and sorted(tq.gravity_gradient) != ["earth", "moon"]:
        problems.append(problem("torques.gravity_gradient", tq.gravity_gradient, "the CR3BP solutions have the gravity gradient of both "
                                "primaries (the ephemeris model adds the Sun's)", "[\"earth\", \"moon\"]"))
    return problems
