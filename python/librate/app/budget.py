"""The size of a study before it runs (issue 24 #7): how many trajectories a ``solve`` or a
``map`` integrates, over how many orbit periods, and how much memory the map takes.
:func:`refusal` names the keys of a study past the stated limits; ``--force`` on the command
line (``Study.check(purpose, force=True)``) lifts it. Nothing here allocates: the counts come
from the grids' sizes (``num``, list lengths), and a whole family counts as its largest size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._checks import MAX_ARRAY_BYTES

__all__ = ["MAX_MAP_BYTES", "MAX_WORK", "Estimate", "estimate", "refusal"]

#: The most trajectory-periods (trajectories x orbit periods each) a study may integrate without
#: --force: about a day of the map engine on 2 cores (~2e3 trajectory-periods per second).
MAX_WORK = 2e8
#: The most memory a map may take without --force (bytes): the API's limit on the arrays one
#: call sizes (``librate._checks.MAX_ARRAY_BYTES``, 2 GiB), so that a study that passes its
#: budget is never refused by the engine it runs.
MAX_MAP_BYTES = MAX_ARRAY_BYTES
#: The members of a whole family (no selection in [orbits]): the DRO family's default x0 grid,
#: else the continuation's ``max_members`` default.
_WHOLE_FAMILY = {"dro": 197, "lyapunov": 150, "halo": 400}


@dataclass(frozen=True)
class Estimate:
    """``factors``: (key, count) along each dimension; ``trajectories`` their product;
    ``periods`` orbit periods per trajectory; ``bytes`` the map's memory (its result arrays and
    the row in flight: ``librate._checks.map_bytes``)."""

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
        return f"{dims} = {self.trajectories:,} trajectories{per}, {self.work:.3g} trajectory-periods, about {_size(self.bytes)} of memory"


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} TB"  # pragma: no cover


def estimate(study, purpose: str) -> Estimate:
    """The size of ``study`` run as ``purpose`` ("solve" or "map")."""
    from .rules import member_count

    o = study.orbits
    sel = member_count(o)
    orbits = ("orbits." + sel[0], sel[2]) if sel else ("orbits.max_members" if o.max_members else "orbits.kind",
                                                       o.max_members or _WHOLE_FAMILY[o.kind])
    factors = [orbits, *study.grid_factors(purpose)]  # the model's grids (PlanarStudy, Study3D)
    nbytes = study.map_bytes(orbits[1], math.prod(n for _, n in factors[1:])) if purpose == "map" else 0
    return Estimate(tuple(factors), study.n_periods(), nbytes)


def refusal(est: Estimate, purpose: str) -> str | None:
    """The problem of a study past the limits, naming its keys; None within them."""
    over = []
    if est.work > MAX_WORK:
        over.append(f"{est.work:.3g} trajectory-periods exceed the limit of {MAX_WORK:.3g}")
    if est.bytes > MAX_MAP_BYTES:
        over.append(f"the map's memory ({_size(est.bytes)}) exceeds the limit of {_size(MAX_MAP_BYTES)}")
    if not over:
        return None
    keys = ", ".join(k for k, n in est.factors if n > 1) or "the study's grids"
    return (f"{', '.join(f'{k} = {n:,} values' for k, n in est.factors)}: this {purpose} is too large: {est.text()}; "
            f"{' and '.join(over)}; allowed: fewer values in {keys}, or --force (Study.check(\"{purpose}\", force=True)) to run it anyway")
