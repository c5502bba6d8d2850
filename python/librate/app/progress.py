"""One progress style for every long step of the command line and the app layer (maps, their
solutions, solution tables, figures): a tqdm bar on stderr with a description, the count, the
rate and the time left. It is drawn only when stderr is a terminal, and never with ``--quiet``.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from tqdm import tqdm

__all__ = ["bar", "reporter", "shown"]


def shown(show: bool | None = None) -> bool:
    """Whether bars are drawn: ``show`` when given (False for ``--quiet``), else whether stderr
    is a terminal."""
    if show is not None:
        return bool(show)
    isatty = getattr(sys.stderr, "isatty", None)
    return bool(isatty and isatty())


def bar(total: int, desc: str, unit: str, show: bool | None = None, initial: int = 0) -> tqdm:
    """A progress bar over ``total`` units (disabled, hence silent, unless :func:`shown`)."""
    return tqdm(total=total, initial=initial, desc=desc, unit=unit, disable=not shown(show), file=sys.stderr, dynamic_ncols=True)


def reporter(desc: str, unit: str, show: bool | None = None) -> Callable[[int, int], None] | None:
    """A ``progress(done, total)`` callback that draws :func:`bar`, for the functions that take
    one (``periodicity_map``, ``Study.run_solve``); None when bars are not shown."""
    if not shown(show):
        return None
    state: dict[str, tqdm] = {}

    def report(done: int, total: int) -> None:
        b = state.get("bar")
        if b is None:
            b = state["bar"] = bar(total, desc, unit, True)
        if total != b.total:  # work found along the way (srp_map's branches)
            b.total = total
        b.update(done - b.n)
        if done >= total:
            b.close()

    return report
