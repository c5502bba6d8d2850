"""The size of a study before it runs (issue 24 #7): how many trajectories a ``solve`` or a
``map`` integrates, over how many orbit periods, and how much memory the map's arrays take.
:func:`refusal` names the keys of a study past the stated limits; ``--force`` on the command
line (``Study.check(purpose, force=True)``) lifts it. Nothing here allocates: the counts come
from the grids' sizes (``num``, list lengths), and a whole family counts as its largest size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["MAX_MAP_BYTES", "MAX_WORK", "Estimate", "estimate", "refusal"]

#: The most trajectory-periods (trajectories x orbit periods each) a study may integrate without
#: --force: about a day of the map engine on 2 cores (~2e3 trajectory-periods per second).
MAX_WORK = 2e8
#: The most memory the map's result arrays may take without --force (bytes).
MAX_MAP_BYTES = 2 * 1024**3
#: Bytes per map cell: dwz, dphi, phi_T (float64) and status (uint8); 3-D: six residuals, their
#: norm (float64) and status.
_CELL_BYTES = {"planar": 3 * 8 + 1, "3d": 7 * 8 + 1}
#: The members of a whole family (no selection in [orbits]): the DRO family's default x0 grid,
#: else the continuation's ``max_members`` default.
_WHOLE_FAMILY = {"dro": 197, "lyapunov": 150, "halo": 400}


@dataclass(frozen=True)
class Estimate:
    """``factors``: (key, count) along each dimension; ``trajectories`` their product;
    ``periods`` orbit periods per trajectory; ``bytes`` the map's result arrays."""

    factors: tuple[tuple[str, int], ...]
    periods: int
    bytes: int

    @property
    def trajectories(self) -> int:
        return math.prod(n for _, n in self.factors)

    @property
    def work(self) -> int:
        return self.trajectories * self.periods

    def text(self) -> str:
        dims = " x ".join(f"{n:,} ({k})" for k, n in self.factors)
        per = f" of {self.periods} orbit period{'s' if self.periods != 1 else ''}"
        return f"{dims} = {self.trajectories:,} trajectories{per}, {self.work:.3g} trajectory-periods, about {_size(self.bytes)} of results"


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} TB"  # pragma: no cover


def _count(g) -> int:
    """The number of values of a grid (a number: 1; a list; a table {start, stop, num})."""
    if g is None:
        return 1
    if isinstance(g, (int, float)):
        return 1
    num = getattr(g, "num", None)
    return int(num) if num is not None else len(g)


def estimate(study, purpose: str) -> Estimate:
    """The size of ``study`` run as ``purpose`` ("solve" or "map")."""
    from .rules import member_count

    o = study.orbits
    sel = member_count(o)
    orbits = ("orbits." + sel[0], sel[2]) if sel else ("orbits.max_members" if o.max_members else "orbits.kind",
                                                       o.max_members or _WHOLE_FAMILY[o.kind])
    r = study.rates
    factors = [orbits]
    if study.attitude.model == "3d":
        if r is not None:
            for k in ("wx0", "wy0", "wz0", "phidot0"):
                if getattr(r, k) is not None and _count(getattr(r, k)) > 1:
                    factors.append((f"rates.{k}", _count(getattr(r, k))))
        if purpose == "solve":
            factors = [orbits]  # one continuation along the members
    else:
        b = study.body
        if b is not None and b.kz is not None:
            factors.append(("body.kz", _count(b.kz)))
        if r is not None:
            k = "wz0" if r.wz0 is not None else "phidot0"
            factors.append((f"rates.{k}", _count(getattr(r, k))))
    cells = math.prod(n for _, n in factors)
    nbytes = cells * _CELL_BYTES[study.attitude.model] if purpose == "map" else 0
    return Estimate(tuple(factors), study.n_periods(), nbytes)


def refusal(est: Estimate, purpose: str) -> str | None:
    """The problem of a study past the limits, naming its keys; None within them."""
    over = []
    if est.work > MAX_WORK:
        over.append(f"{est.work:.3g} trajectory-periods exceed the limit of {MAX_WORK:.3g}")
    if est.bytes > MAX_MAP_BYTES:
        over.append(f"the map's arrays ({_size(est.bytes)}) exceed the limit of {_size(MAX_MAP_BYTES)}")
    if not over:
        return None
    keys = ", ".join(k for k, n in est.factors if n > 1) or "the study's grids"
    return (f"{', '.join(f'{k} = {n:,} values' for k, n in est.factors)}: this {purpose} is too large: {est.text()}; "
            f"{' and '.join(over)}; allowed: fewer values in {keys}, or --force (Study.check(\"{purpose}\", force=True)) to run it anyway")
