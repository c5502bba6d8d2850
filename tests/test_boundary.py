"""The Rust-Python boundary is typed and narrow (issue 20 item 4): no callable of
``librate._core`` (function, class constructor or method) takes more than 8 parameters, read
from the ``__text_signature__`` that PyO3 generates from each binding's signature (``self`` and
``py`` do not count). Options, models and per-case containers are classes, variants are enums."""

import librate._core as core
import pytest

MAX_PARAMETERS = 8


def _split(params: str) -> list[str]:
    """Top-level comma split of a signature's parameter list (defaults may hold [..] and (..))."""
    out, depth, cur = [], 0, ""
    for ch in params:
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        if ch == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if cur.strip():
        out.append(cur.strip())
    return out


def parameter_count(text_signature: str) -> int:
    """Named parameters of a text signature such as "($self, a, b=1, *, c=(1, 2))"."""
    assert text_signature.startswith("(") and text_signature.endswith(")"), text_signature
    names = [p for p in _split(text_signature[1:-1]) if p not in ("/", "*") and not p.startswith("$")]
    return len(names)


def _callables():
    """(qualified name, text signature) of every function, class constructor and method."""
    for name in sorted(dir(core)):
        obj = getattr(core, name)
        if isinstance(obj, type) and issubclass(obj, BaseException):
            continue
        if isinstance(obj, type):
            if getattr(obj, "__text_signature__", None):
                yield name, obj.__text_signature__
            for attr, member in vars(obj).items():
                sig = getattr(member, "__text_signature__", None)
                if callable(member) and sig:
                    yield f"{name}.{attr}", sig
        elif callable(obj):
            yield name, obj.__text_signature__


def test_parameter_count_reads_signatures():
    # the counter itself, on signatures of the shapes PyO3 writes
    assert parameter_count("()") == 0
    assert parameter_count("($self, t)") == 1
    assert parameter_count("(mu, state, t_span, *, options, stm, t_eval, events, collision=None)") == 8
    assert parameter_count("(q, w, *, primaries=[True, True], sun=(0.0, 1.0, 2.0))") == 4


def test_every_function_has_a_signature():
    missing = [name for name, sig in _callables() if not sig]
    assert not missing, f"callables of librate._core without __text_signature__: {missing}"


def test_no_binding_takes_more_than_eight_parameters():
    counts = {name: parameter_count(sig) for name, sig in _callables() if sig}
    assert len(counts) > 40  # the functions, constructors and methods of the module
    offenders = {name: n for name, n in counts.items() if n > MAX_PARAMETERS}
    assert not offenders, f"bindings of librate._core with more than {MAX_PARAMETERS} parameters: {offenders}"


@pytest.mark.parametrize("enum, members", [
    ("Closure", ("HALF", "FULL")),
    ("Free", ("PHI0", "SUN_PHASE")),
    ("BorderedParameter", ("KZ", "EPS", "ORBIT_X0")),
    ("LaneMethod", ("RKF78", "RKN86", "DP87")),
    ("OrbitMode", ("INTEGRATE", "HELD", "COUPLED")),
])
def test_variants_cross_as_enums(enum, members):
    cls = getattr(core, enum)
    for m in members:
        v = getattr(cls, m)
        assert v == getattr(cls, m) and isinstance(v, cls)
    assert len({int(getattr(cls, m)) for m in members}) == len(members)
