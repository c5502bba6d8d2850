#!/usr/bin/env bash
# The SIMD kernels call no intrinsic out of line. A closure that the compiler keeps outside a
# dispatched kernel (array::from_fn's, array::map's, an iterator's fold) is compiled without the
# kernel's target features, so each AVX2 / AVX-512 intrinsic in it becomes a function call
# through memory (with vzeroupper): the standard map ran 1.38x slower on AVX2 with a few of
# them. Usage: bash .ci/check_inlined.sh EXTENSION.so
set -euo pipefail
so="$1"
if ! command -v objdump >/dev/null; then
    echo "objdump not found (binutils): the check of out-of-line intrinsics is skipped" >&2
    exit 0
fi
# the functions that call an intrinsic, except the run-time CPU detection of std and
# compiler_builtins (which call cpuid helpers by design)
calls="$(objdump -d --no-show-raw-insn -C "$so" | awk '/^[0-9a-f]+ <.*>:$/ {fn = $0} /call.*<core::core_arch::/ {print fn}' \
    | grep -v -e std_detect -e compiler_builtins | sort | uniq -c || true)"
if [ -n "$calls" ]; then
    echo "intrinsics called out of line in $(basename "$so") (count, calling function):" >&2
    echo "$calls" | cut -c1-240 >&2
    exit 1
fi
echo "no intrinsic called out of line in $(basename "$so")"
