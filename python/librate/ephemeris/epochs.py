"""Epochs: ISO strings with a time scale (TDB, TT, UTC) or TDB seconds past J2000.

UTC goes to TT through pyerfa (the IAU SOFA library: its leap-second table), TT to TDB by
``erfa.dtdb`` (Fairhead & Bretagnon series, geocentre). A UTC epoch past the table's reach
(leap seconds are announced six months ahead) takes the table's last offset TAI - UTC: the
only value there is, so pyerfa's "dubious year" warning for such epochs is not passed on.
"""

from __future__ import annotations

import math
import re
import warnings

__all__ = ["tdb_seconds", "iso_tdb"]

_S_PER_DAY = 86400.0
_J2000_JD = 2451545.0
_FORMS = "an ISO string with a scale, 'YYYY-MM-DDTHH:MM:SS[.fff] TDB' (or UTC, TT), or a float of TDB seconds past J2000"
_ISO = re.compile(r"^\s*(\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)\s+(TDB|TT|UTC)\s*$")


def _tt_to_tdb(d1: float, d2: float) -> float:
    """TDB - TT in seconds at the TT two-part Julian date (d1, d2)."""
    import erfa

    return float(erfa.dtdb(d1, d2, 0.0, 0.0, 0.0, 0.0))


def tdb_seconds(epoch: str | float) -> float:
    """TDB seconds past J2000 (2000-01-01T12:00:00 TDB) of ``epoch``."""
    if isinstance(epoch, bool):
        raise ValueError(f"epoch: got {epoch!r}; expected {_FORMS}")
    if isinstance(epoch, (int, float)):
        t = float(epoch)
        if not math.isfinite(t):
            raise ValueError(f"epoch: got {epoch!r}, not finite; expected {_FORMS}")
        return t
    if not isinstance(epoch, str):
        raise ValueError(f"epoch: got {type(epoch).__name__} {epoch!r}; expected {_FORMS}")
    m = _ISO.match(epoch)
    if m is None:
        raise ValueError(f"epoch: cannot read {epoch!r}; expected {_FORMS}")
    import erfa

    y, mo, d, h, mi = (int(m.group(i)) for i in range(1, 6))
    sec, scale = float(m.group(6)), m.group(7)
    with warnings.catch_warnings():
        # a UTC epoch beyond the leap-second table: the last offset applies (module docstring)
        warnings.filterwarnings("ignore", message=r".*dubious year", category=erfa.ErfaWarning)
        try:
            d1, d2 = erfa.dtf2d("UTC" if scale == "UTC" else scale, y, mo, d, h, mi, sec)
        except Exception as exc:  # erfa raises on an impossible date or time of day
            raise ValueError(f"epoch: {epoch!r} is not a valid date and time: {exc}") from exc
        d1, d2 = float(d1), float(d2)
        if scale == "UTC":
            d1, d2 = (float(x) for x in erfa.utctai(d1, d2))
            d1, d2 = (float(x) for x in erfa.taitt(d1, d2))
    if scale in ("UTC", "TT"):
        # TDB = TT + dtdb; the TT Julian date serves as the argument (the difference is < 2 ms)
        return ((d1 - _J2000_JD) + d2) * _S_PER_DAY + _tt_to_tdb(d1, d2)
    return ((d1 - _J2000_JD) + d2) * _S_PER_DAY


def iso_tdb(t: float) -> str:
    """The ISO string 'YYYY-MM-DDTHH:MM:SS.ffffff TDB' of TDB seconds past J2000."""
    import erfa

    t = tdb_seconds(t)
    days = t / _S_PER_DAY
    whole = math.floor(days)
    iy, im, iid, ihmsf = erfa.d2dtf("TDB", 6, _J2000_JD + whole, days - whole)
    h, mi, s, f = (int(x) for x in ihmsf)
    return f"{int(iy):04d}-{int(im):02d}-{int(iid):02d}T{h:02d}:{mi:02d}:{s:02d}.{f:06d} TDB"
