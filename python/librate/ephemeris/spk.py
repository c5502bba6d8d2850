"""Reading JPL SPK files (type-2 Chebyshev segments, as in DE440 and DE421) with jplephem.

The records are handed to the Rust core unchanged; no Python runs inside an integration.
"""

from __future__ import annotations

import pathlib
from dataclasses import dataclass
from importlib.resources import files

import numpy as np

__all__ = ["SpkSegment", "read_spk", "embedded_spk_path"]

_EMBEDDED = "de440_2020_2070.bsp"
_S_PER_DAY = 86400.0
_J2000_JD = 2451545.0


@dataclass(frozen=True)
class SpkSegment:
    """One type-2 SPK segment: Chebyshev position records of ``target`` relative to ``center``.

    NAIF ids: 10 Sun, 0 solar-system barycentre, 3 Earth-Moon barycentre, 301 Moon, 399 Earth.
    Epochs are TDB seconds past J2000; ``coefficients`` is float64 ``(n_records, 3, n_coef)``,
    C-contiguous, in km (the x, y, z Chebyshev coefficients of each record, record ``k`` covering
    ``[init_s + k intlen_s, init_s + (k + 1) intlen_s]``).
    """

    target: int
    center: int
    start_s: float
    end_s: float
    init_s: float
    intlen_s: float
    coefficients: np.ndarray


def read_spk(path: str | pathlib.Path) -> list[SpkSegment]:
    """Read every segment of the SPK file at ``path``; ValueError if one is not of type 2."""
    from jplephem.spk import SPK

    p = pathlib.Path(path)
    if not p.is_file():
        raise ValueError(f"path: no SPK file at {str(p)!r}")
    try:
        spk = SPK.open(str(p))
    except Exception as exc:  # jplephem raises bare ValueError/struct errors on a non-DAF file
        raise ValueError(f"path: {str(p)!r} is not a readable SPK (DAF) file: {exc}") from exc
    try:
        out = []
        for seg in spk.segments:
            if seg.data_type != 2:
                raise ValueError(
                    f"path: segment {seg.center}->{seg.target} of {str(p)!r} is of SPK type {seg.data_type}; "
                    "only type 2 (Chebyshev position) is supported"
                )
            # jplephem's layout: (n_coef, 3, n_records), highest degree first
            init, intlen, coef = seg._data
            out.append(
                SpkSegment(
                    target=int(seg.target),
                    center=int(seg.center),
                    start_s=float((seg.start_jd - _J2000_JD) * _S_PER_DAY),
                    end_s=float((seg.end_jd - _J2000_JD) * _S_PER_DAY),
                    init_s=float(init),
                    intlen_s=float(intlen),
                    coefficients=np.ascontiguousarray(np.transpose(coef[::-1], (2, 1, 0)), dtype=np.float64),
                )
            )
        return out
    finally:
        spk.close()


def embedded_spk_path() -> pathlib.Path:
    """The shipped excerpt of DE440 (2020-2070; Sun and EMB about the SSB, Moon and Earth about the EMB)."""
    return pathlib.Path(str(files("librate.ephemeris").joinpath("data", _EMBEDDED)))
