"""A study's problems as the messages ``librate`` prints: pydantic's validation errors of a section
turned into one line per key (``key = value: what is wrong; allowed: ...``), and unknown keys
named with the keys allowed there and the nearest one (:mod:`librate.app.schema` holds the
sections and the rules; :class:`librate.app.study.Study` collects every problem before it
raises)."""

from __future__ import annotations

import difflib
import re
from typing import Any

from pydantic import ValidationError

from .schema import GRID_TAGS, TABLES, TOP_KEYS, Range, SectionProblems, missing, problem, show_value

__all__ = ["dotted_key", "keys_of", "pydantic_problems", "unknown_key"]


def dotted_key(prefix: str, loc: tuple) -> str:
    key = prefix
    for part in loc:
        if isinstance(part, int):
            key += f"[{part}]"
        elif part in GRID_TAGS:
            continue
        else:
            key = f"{key}.{part}" if key else str(part)
    return key


def keys_of(parent: str) -> list[str] | None:
    base = re.sub(r"\[\d+\]", "", parent)
    if base == "":
        return list(TOP_KEYS)
    if base in TABLES:
        return list(TABLES[base].model_fields)
    last = base.rsplit(".", 1)[-1]
    if last in ("x0", "z0", "period_days", "wz0", "phidot0", "wx0", "wy0", "kz"):
        return list(Range.model_fields)
    return None


def unknown_key(key: str, value: Any) -> str:
    parent, _, name = key.rpartition(".")
    keys = keys_of(parent) or []
    where = f"[{parent}]" if parent else "the top level"
    hint = difflib.get_close_matches(name, keys, n=1)
    text = f"{key} = {show_value(value)}: unknown key; allowed keys in {where}: {', '.join(keys)}"
    return text + (f" (did you mean `{(parent + '.') if parent else ''}{hint[0]}`?)" if hint else "")


def pydantic_problems(prefix: str, err: ValidationError, rules: list[str] | None = None) -> list[str]:
    """The problems of a section's validation, one line each naming the key: the type problems
    (returned), and what its rules found (:class:`SectionProblems`; added to ``rules`` when
    given, else returned after the type problems)."""
    out: list[str] = []
    found: list[str] = []
    for e in err.errors():
        key = dotted_key(prefix, e["loc"])
        if isinstance((e.get("ctx") or {}).get("error"), SectionProblems):
            found += e["ctx"]["error"].problems
        elif e["type"] == "attitude_model":  # the discriminator of [attitude]: its model
            value = e["input"].get("model") if isinstance(e["input"], dict) else e["input"]
            out.append(problem(f"{key}.model", value, e["msg"]))
        elif e["type"] == "extra_forbidden":
            out.append(unknown_key(key, e["input"]))
        elif e["type"] == "missing":
            out.append(missing(key, "missing (required)"))
        else:
            msg = e["msg"]
            msg = msg[0].lower() + msg[1:]
            msg = msg.removeprefix("value error, ")
            if e["type"] == "model_type":
                msg = "must be a table"
            out.append(problem(key, e["input"], msg))
    if rules is None:
        return out + found
    rules += found
    return out
