"""One progress style for every long step, from Python and from the command line: a tqdm bar on
stderr with a description, the count, the rate and the time left.

Every long call takes ``progress=``: None or False (silent), True (a bar on stderr, drawn
whatever stderr is) or a callable ``progress(done, total)``. :func:`as_progress` turns that into
a callback or None, so each call site has one line. tqdm is imported only when a bar is drawn,
so that ``import librate`` stays light.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

__all__ = ["as_progress", "bar", "reporter", "shown"]

Progress = Callable[[int, int], None]


def shown(show: bool | None = None) -> bool:
    """Whether bars are drawn: ``show`` when given (False for ``--quiet``), else whether stderr
    is a terminal."""
    if show is not None:
        return bool(show)
    isatty = getattr(sys.stderr, "isatty", None)
    return bool(isatty and isatty())


def bar(total: int, desc: str, unit: str, show: bool | None = None, initial: int = 0) -> Any:
    """A tqdm progress bar over ``total`` units on stderr (disabled, hence silent, unless
    :func:`shown`)."""
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc=desc, unit=unit, disable=not shown(show), file=sys.stderr, dynamic_ncols=True)


def reporter(desc: str, unit: str, show: bool | None = None) -> Progress | None:
    """A ``progress(done, total)`` callback that draws :func:`bar` (opened at the first call,
    closed when ``done >= total``); None when bars are not shown."""
    if not shown(show):
        return None
    state: dict[str, Any] = {}

    def report(done: int, total: int) -> None:
        b = state.get("bar")
        if b is None:
            b = state["bar"] = bar(total, desc, unit, True)
        if total != b.total:  # work found along the way (srp_map's branches)
            b.total = total
        b.update(done - b.n)
        if done >= total:
            b.close()
            state.pop("bar")

    return report


def as_progress(progress: Any, desc: str, unit: str) -> Progress | None:
    """The callback behind a long call's ``progress`` argument: None or False -> None, True ->
    a bar (:func:`reporter`, ``desc`` and ``unit`` label it), a callable -> itself."""
    if progress is None or progress is False:
        return None
    if progress is True:
        return reporter(desc, unit, True)
    if callable(progress):
        return progress
    raise ValueError(f"invalid argument `progress`: must be True, False, None or a callable progress(done, total), got {progress!r}")
