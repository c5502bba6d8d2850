"""Notebook display: the short ``repr`` and the HTML summary (``_repr_html_``) of librate's objects.

One place builds both, in the way xarray summarises a Dataset: a title line, the key numbers in a
table, and collapsed ``<details>`` sections for the rest. The classes (``System``,
``PeriodicOrbit``, ``OrbitFamily``, ``AttitudeSolution``, ``AttitudeSolution3D``, ``Map3DGrid``)
pass their rows; nothing here knows their fields. Arrays are shown by shape and range, never in
full, and nested objects (an orbit's system, a solution's orbit) by their one-line repr.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Mapping, Sequence

import numpy as np

#: a row: (name, value, unit or "")
Row = tuple[str, object, str]

_STYLE = (
    "<style>.librate-repr{font-family:var(--jp-code-font-family,monospace);font-size:12px;line-height:1.4}"
    ".librate-repr .lr-title{font-weight:bold;margin-bottom:4px}"
    ".librate-repr table{border-collapse:collapse;margin:2px 0}"
    ".librate-repr td{padding:1px 10px 1px 0;text-align:left;vertical-align:top}"
    ".librate-repr td.lr-name{font-weight:bold}.librate-repr td.lr-unit{opacity:.7}"
    ".librate-repr summary{cursor:pointer}</style>"
)


def fmt(value: object, digits: int = 6) -> str:
    """A value in a few characters: floats to ``digits`` significant digits, arrays by shape and
    range, anything else by its ``str`` (cut at 200 characters)."""
    if isinstance(value, bool | np.bool_):
        return str(bool(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        return f"{float(value):.{digits}g}"
    if isinstance(value, complex | np.complexfloating):
        return f"{complex(value):.{digits}g}"
    if isinstance(value, np.ndarray):
        return array_summary(value, digits)
    text = str(value)
    return text if len(text) <= 200 else text[:197] + "..."


def array_summary(a: np.ndarray, digits: int = 4) -> str:
    """``shape dtype [min .. max]`` for a numeric array (the finite values), or its first values
    when it is small: never the whole array."""
    a = np.asarray(a)
    if a.size <= 6 and a.ndim <= 1:
        return "[" + ", ".join(fmt(x, digits) for x in a.ravel()) + "]"
    head = f"{a.shape} {a.dtype}"
    if a.dtype.kind in "fiu":
        finite = a[np.isfinite(a)] if a.dtype.kind == "f" else a
        if finite.size:
            return f"{head} [{fmt(finite.min(), digits)} .. {fmt(finite.max(), digits)}]"
    return head


def short_repr(title: str, rows: Iterable[Row], digits: int = 6) -> str:
    """``Title(name=value unit, ...)`` on one line."""
    parts = []
    for name, value, unit in rows:
        parts.append(f"{name}={fmt(value, digits)}{' ' + unit if unit else ''}")
    return f"{title}({', '.join(parts)})"


def _table(rows: Iterable[Row]) -> str:
    out = ["<table>"]
    for name, value, unit in rows:
        out.append(
            f'<tr><td class="lr-name">{html.escape(name)}</td><td>{html.escape(fmt(value))}</td>'
            f'<td class="lr-unit">{html.escape(unit)}</td></tr>'
        )
    out.append("</table>")
    return "".join(out)


def html_summary(title: str, rows: Sequence[Row], details: Mapping[str, Sequence[Row]] | None = None) -> str:
    """The HTML summary: ``title`` (bold), the table of ``rows`` and, for each entry of
    ``details``, a collapsed ``<details>`` section holding its table (empty sections left out)."""
    out = [_STYLE, '<div class="librate-repr">', f'<div class="lr-title">{html.escape(title)}</div>', _table(rows)]
    for name, section in (details or {}).items():
        if section:
            out.append(f"<details><summary>{html.escape(name)} ({len(section)})</summary>{_table(section)}</details>")
    out.append("</div>")
    return "".join(out)
