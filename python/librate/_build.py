"""What this build of librate is and which SIMD level its Rust kernels run at (base layer).

The numerical kernels are compiled for several CPU instruction-set levels and one is chosen
once per process, from the running CPU (the highest it supports) or from the environment
variable ``LIBRATE_SIMD`` (``auto``, ``baseline``, ``avx2``, ``avx512``; ``neon`` on aarch64). An
unknown value, or a level this CPU lacks, raises ValueError naming the variable at
``import librate``. Results on one level are bit-identical for any thread count; between
levels they may differ in the last bits (fused multiply-add on ``avx2``/``avx512``/``neon``,
separate multiply and add on ``baseline``).
"""

from __future__ import annotations

from typing import Any

from . import _core

__all__ = ["build_info"]


def build_info() -> dict[str, Any]:
    """The build and its SIMD levels, as a dict:

    - ``simd_available``: the levels this CPU supports, lowest first (e.g. ``["baseline",
      "avx2", "avx512"]``); ``simd_known``: the levels of this architecture;
    - ``simd_active``: the level the kernels run at;
    - ``version``: the package version; ``profile``: the cargo profile the extension was built
      with (``"dev"``, ``"release"`` or ``"dist"``, the published wheels'); ``debug_assertions``:
      whether Rust's debug assertions are on (dev builds); ``target_arch``: the CPU architecture;
    - ``threads``: the workers of the pool every parallel call runs on (``RAYON_NUM_THREADS``, else
      one per CPU); ``threads_started``: whether it runs yet (it starts with the first parallel
      work, not at import; before, the other entries are its plan); ``threads_binding``:
      ``LIBRATE_BIND_THREADS`` (``"auto"``, the default, ``"on"`` or ``"off"``); ``threads_cpus``:
      the CPU each worker is bound to (empty: left to the kernel; ``auto`` binds only a pool with
      one worker per allowed CPU, on Linux);
      ``threads_bound``: how many workers the kernel accepted on their CPU.

    Raises ValueError naming ``LIBRATE_SIMD`` when it asks for an unknown or unavailable level
    (``LIBRATE_BIND_THREADS`` is read when the extension is imported: an invalid value fails the
    import with a ValueError naming it).
    """
    return dict(_core.build_info())


build_info()  # an invalid LIBRATE_SIMD fails here, at import, with its message
