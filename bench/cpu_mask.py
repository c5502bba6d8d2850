"""Run a benchmark as on a CPU without AVX-512: hide AVX-512 from this process's CPUID.

Why: librate chooses its SIMD level at run time (``LIBRATE_SIMD=avx2`` forces its AVX2 path), but
heyoka compiles its integrators with LLVM for the CPU that CPUID describes. On an AVX-512 CPU a
``LIBRATE_SIMD=avx2`` run therefore pits librate's AVX2 code (16 registers of 256 bits) against
heyoka's AVX-512 code (32 registers of 512 bits): not what either program does on an AVX2
machine. With AVX-512 hidden from CPUID, both sides see an AVX2 CPU: librate's dispatch picks
its AVX2 level by itself, and heyoka's JIT emits AVX2 code (checked: no zmm register and no
ymm16-31 in its object code), as on an AVX2 machine of the same microarchitecture.

How (Linux, x86-64): CPUID faulting. ``arch_prctl(ARCH_SET_CPUID, 0)`` makes the CPUID
instruction trap in this thread and in every thread it starts afterwards (the setting is
inherited by fork and clone); a SIGSEGV handler (a few lines of C, compiled here with the system's
C compiler) executes the real CPUID with faulting briefly off, clears the AVX-512 feature bits
of leaf 7 (EBX, ECX, EDX of subleaf 0; AVX512_BF16 of subleaf 1) and resumes after the
instruction. Any other SIGSEGV goes to the handler that was installed before. This is how
record-and-replay debuggers (rr) present a different CPU to a process. It needs the CPU and
kernel to support CPUID faulting (the ``cpuid_fault`` flag of /proc/cpuinfo); the mask must be
set before anything reads the CPU's features (numpy, librate and heyoka read them when first
imported or used) and before other threads start.

    python bench/cpu_mask.py bench/bench_map3d.py [args]   # any benchmark, AVX-512 hidden
    python bench/bench_goals.py --no-avx512                 # the goals (the flag calls mask_avx512 first)
"""

import ctypes
import os
import platform
import runpy
import shutil
import subprocess
import sys
import tempfile

#: bench_goals.py's flag that hides AVX-512 before anything else is imported.
FLAG = "--no-avx512"

_SOURCE = r"""
#define _GNU_SOURCE
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <ucontext.h>
#include <unistd.h>
#include <sys/syscall.h>
#include <asm/prctl.h>

static struct sigaction previous;

static long set_cpuid(int enabled) { return syscall(SYS_arch_prctl, ARCH_SET_CPUID, enabled); }

static void on_segv(int sig, siginfo_t *si, void *ctx) {
    greg_t *g = ((ucontext_t *)ctx)->uc_mcontext.gregs;
    const unsigned char *ip = (const unsigned char *)g[REG_RIP];
    /* a faulting CPUID is a general-protection fault (SI_KERNEL); anything else is not ours */
    if (si->si_code != SI_KERNEL || ip[0] != 0x0f || ip[1] != 0xa2) {
        sigaction(SIGSEGV, &previous, 0);
        return; /* the instruction faults again, under the previous handler */
    }
    uint32_t leaf = (uint32_t)g[REG_RAX], sub = (uint32_t)g[REG_RCX];
    uint32_t a = leaf, b, c = sub, d;
    set_cpuid(1);
    __asm__ volatile("cpuid" : "+a"(a), "=b"(b), "+c"(c), "=d"(d));
    set_cpuid(0);
    if (leaf == 7 && sub == 0) {
        /* AVX512 F, DQ, IFMA, PF, ER, CD, BW, VL */
        b &= ~((1u << 16) | (1u << 17) | (1u << 21) | (1u << 26) | (1u << 27) | (1u << 28) | (1u << 30) | (1u << 31));
        /* AVX512 VBMI, VBMI2, VNNI, BITALG, VPOPCNTDQ */
        c &= ~((1u << 1) | (1u << 6) | (1u << 11) | (1u << 12) | (1u << 14));
        /* AVX512 4VNNIW, 4FMAPS, VP2INTERSECT, FP16 */
        d &= ~((1u << 2) | (1u << 3) | (1u << 8) | (1u << 23));
    } else if (leaf == 7 && sub == 1) {
        a &= ~(1u << 5); /* AVX512 BF16 */
    }
    g[REG_RAX] = a;
    g[REG_RBX] = b;
    g[REG_RCX] = c;
    g[REG_RDX] = d;
    g[REG_RIP] += 2;
}

int librate_mask_avx512(void) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = on_segv;
    sa.sa_flags = SA_SIGINFO;
    sigemptyset(&sa.sa_mask);
    if (sigaction(SIGSEGV, &sa, &previous) != 0) return -1;
    if (set_cpuid(0) != 0) { sigaction(SIGSEGV, &previous, 0); return -2; }
    return 0;
}

uint32_t librate_leaf7_ebx(void) {
    uint32_t a = 7, b, c = 0, d;
    __asm__ volatile("cpuid" : "+a"(a), "=b"(b), "+c"(c), "=d"(d));
    return b;
}
"""

_lib = None


def unavailable() -> str | None:
    """Why AVX-512 cannot be hidden here (None: it can)."""
    if platform.system() != "Linux" or platform.machine() not in ("x86_64", "AMD64"):
        return f"CPUID faulting is a Linux x86-64 feature (this is {platform.system()} {platform.machine()})"
    try:
        with open("/proc/cpuinfo") as f:
            flags = next((line.split(":", 1)[1].split() for line in f if line.startswith("flags")), [])
    except OSError as e:
        return f"/proc/cpuinfo cannot be read: {e}"
    if "cpuid_fault" not in flags:
        return "this CPU or kernel does not support CPUID faulting (no cpuid_fault flag in /proc/cpuinfo)"
    if not (shutil.which("cc") or shutil.which("gcc")):
        return "no C compiler (cc or gcc) to build the CPUID handler"
    return None


def mask_avx512() -> None:
    """Hide AVX-512 from CPUID in this thread and every thread it starts afterwards (see the
    module's doc); a RuntimeError naming the reason when that cannot be done, or when CPUID
    still reports AVX-512F afterwards. Idempotent."""
    global _lib
    if _lib is not None:
        return
    why = unavailable()
    if why:
        raise RuntimeError(f"cannot hide AVX-512: {why}")
    work = tempfile.mkdtemp(prefix="librate-cpu-mask-")
    src, so = os.path.join(work, "mask.c"), os.path.join(work, "libmask.so")
    with open(src, "w") as f:
        f.write(_SOURCE)
    cc = shutil.which("cc") or shutil.which("gcc")
    res = subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", so, src], capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"cannot hide AVX-512: the CPUID handler did not compile:\n{res.stderr}")
    lib = ctypes.CDLL(so)
    lib.librate_leaf7_ebx.restype = ctypes.c_uint32
    rc = lib.librate_mask_avx512()
    if rc != 0:
        raise RuntimeError(f"cannot hide AVX-512: {'sigaction' if rc == -1 else 'arch_prctl(ARCH_SET_CPUID, 0)'} failed")
    if lib.librate_leaf7_ebx() & (1 << 16):
        raise RuntimeError("cannot hide AVX-512: CPUID leaf 7 still reports AVX512F after masking")
    _lib = lib


def masked() -> bool:
    """Whether this process hides AVX-512 (mask_avx512 was called)."""
    return _lib is not None


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__)
        return 2
    mask_avx512()
    sys.argv = list(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(argv[0])))
    runpy.run_path(argv[0], run_name="__main__")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
