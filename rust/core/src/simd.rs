//! Runtime CPU dispatch of the hot kernels (the map engine's lanes, `map::lanes`; each step of the
//! scalar RKF7(8) stepper, `integrate::Rkf78`): one portable build runs on every x86-64 CPU and
//! uses the widest instruction set the running CPU has.
//!
//! Levels: on x86-64, `baseline` (SSE2, no fused multiply-add: every x86-64 CPU), `avx2`
//! (x86-64-v3: AVX2 + FMA) and `avx512` (x86-64-v4: AVX-512 F/BW/CD/DQ/VL + FMA); on aarch64,
//! `neon` (part of the architecture's baseline, with FMA; compile time). The level is chosen once,
//! at first use, from the running CPU (the highest it supports), or forced by the environment
//! variable `LIBRATE_SIMD=auto|baseline|avx2|avx512` (an unknown or unavailable value is an
//! [`crate::error::Error::InvalidArgument`] naming the variable and the allowed values, at every
//! use); [`set_active`] switches levels within a process (tests, benchmarks).
//!
//! How: a kernel is written once, generic over an [`Isa`] token ([`Kernel::run`]; the AVX2 and
//! AVX-512 tokens exist only once the CPU's support is detected), with everything it calls in its
//! hot loop `#[inline(always)]`. [`run`] calls it inside a function
//! compiled with the level's target features (`pulp`'s `V3` / `V4` `vectorize`, which also
//! detect and cache the CPU's features), so LLVM generates the same generic code once per level.
//! The marker's [`Isa::FMA`] decides `a * b + c` (two roundings) or a fused multiply-add (one):
//! this, and nothing else, is why results may differ in the last bits between `baseline` and the
//! FMA levels; `avx2` and `avx512` compute the same operations in the same order (eight lanes,
//! as 4 x 128, 2 x 256 or 1 x 512 bits) and agree bit for bit. On one level, results are
//! bit-identical for any thread count and chunking (each kernel's own guarantee).

use std::fmt;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::OnceLock;

use crate::error::{invalid, Result};

/// The environment variable that forces a level.
pub const ENV_VAR: &str = "LIBRATE_SIMD";

/// An instruction-set level of the dispatched kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    /// x86-64 baseline: SSE2, no FMA.
    Baseline,
    /// x86-64-v3: AVX2 and FMA.
    Avx2,
    /// x86-64-v4: AVX-512 (F, BW, CD, DQ, VL) and FMA.
    Avx512,
    /// aarch64: NEON with FMA (the architecture's baseline).
    Neon,
}

impl Level {
    /// The level's name as `LIBRATE_SIMD` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Level::Baseline => "baseline",
            Level::Avx2 => "avx2",
            Level::Avx512 => "avx512",
            Level::Neon => "neon",
        }
    }

    /// Whether the running CPU can execute this level.
    pub fn is_available(self) -> bool {
        match self {
            #[cfg(target_arch = "x86_64")]
            Level::Baseline => true,
            #[cfg(target_arch = "x86_64")]
            Level::Avx2 => pulp::x86::V3::is_available(),
            #[cfg(target_arch = "x86_64")]
            Level::Avx512 => pulp::x86::V4::is_available(),
            #[cfg(target_arch = "aarch64")]
            Level::Neon => true,
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }
}

impl fmt::Display for Level {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The levels this build knows on this architecture, lowest first.
pub fn known() -> &'static [Level] {
    if cfg!(target_arch = "x86_64") {
        &[Level::Baseline, Level::Avx2, Level::Avx512]
    } else if cfg!(target_arch = "aarch64") {
        &[Level::Neon]
    } else {
        &[]
    }
}

/// The levels the running CPU supports, lowest first.
pub fn available() -> Vec<Level> {
    known().iter().copied().filter(|l| l.is_available()).collect()
}

/// The values `LIBRATE_SIMD` accepts on this architecture.
pub fn allowed_values() -> String {
    let mut v = vec!["auto"];
    if cfg!(target_arch = "aarch64") {
        v.push("baseline (= neon)");
    }
    v.extend(known().iter().map(|l| l.name()));
    v.join(", ")
}

/// The level a `LIBRATE_SIMD` value asks for (None or empty: `auto`, the highest available).
pub fn parse(request: Option<&str>) -> Result<Level> {
    let req = request.map(|s| s.trim().to_ascii_lowercase()).unwrap_or_default();
    let best = || *available().last().expect("every supported architecture has a baseline level");
    let level = match req.as_str() {
        "" | "auto" => return Ok(best()),
        "baseline" if cfg!(target_arch = "aarch64") => Level::Neon,
        name => match known().iter().find(|l| l.name() == name) {
            Some(&l) => l,
            None => return Err(invalid(ENV_VAR, format!("unknown SIMD level {name:?}; allowed: {}", allowed_values()))),
        },
    };
    if !level.is_available() {
        let have: Vec<&str> = available().iter().map(|l| l.name()).collect();
        return Err(invalid(
            ENV_VAR,
            format!("SIMD level {:?} is not supported by this CPU (it supports {}); allowed: {}", level.name(), have.join(", "), allowed_values()),
        ));
    }
    Ok(level)
}

/// The level [`set_active`] chose (0: none, else 1 + index in [`known`]).
static OVERRIDE: AtomicU8 = AtomicU8::new(0);

/// The active level: chosen once, at first use, from `LIBRATE_SIMD` (unset: `auto`), unless
/// [`set_active`] chose one since.
pub fn active() -> Result<Level> {
    static FROM_ENV: OnceLock<Result<Level>> = OnceLock::new();
    match OVERRIDE.load(Ordering::Relaxed) {
        0 => FROM_ENV.get_or_init(|| parse(std::env::var(ENV_VAR).ok().as_deref())).clone(),
        k => Ok(known()[k as usize - 1]),
    }
}

/// Make `request` (a `LIBRATE_SIMD` value) the active level of this process from now on, for
/// comparing levels in one process (tests, benchmarks); an error if the CPU lacks it.
pub fn set_active(request: &str) -> Result<Level> {
    let level = parse(Some(request))?;
    let k = known().iter().position(|&l| l == level).expect("parse returns a known level");
    OVERRIDE.store(k as u8 + 1, Ordering::Relaxed);
    Ok(level)
}

type A8 = [f64; 8];

/// An instruction-set token: the level a kernel is compiled for, and its eight-lane primitives
/// (the operations of [`crate::scalar::F8`]). The AVX2 and AVX-512 tokens hold `pulp`'s proof
/// that the CPU has the features (they cannot be made otherwise); the default methods are the
/// portable element-wise loops (used on aarch64, where NEON is the baseline).
pub trait Isa: Copy + Send + Sync + 'static {
    const LEVEL: Level;
    /// Whether `mul_add` fuses (one rounding).
    const FMA: bool;

    /// a * b + c, fused on FMA levels.
    #[inline(always)]
    fn mul_add(a: f64, b: f64, c: f64) -> f64 {
        if Self::FMA {
            a.mul_add(b, c)
        } else {
            a * b + c
        }
    }

    #[inline(always)]
    fn add8(self, a: A8, b: A8) -> A8 {
        std::array::from_fn(|l| a[l] + b[l])
    }
    #[inline(always)]
    fn sub8(self, a: A8, b: A8) -> A8 {
        std::array::from_fn(|l| a[l] - b[l])
    }
    #[inline(always)]
    fn mul8(self, a: A8, b: A8) -> A8 {
        std::array::from_fn(|l| a[l] * b[l])
    }
    #[inline(always)]
    fn div8(self, a: A8, b: A8) -> A8 {
        std::array::from_fn(|l| a[l] / b[l])
    }
    /// The correctly rounded square root per lane (IEEE 754: the same bits as f64::sqrt).
    #[inline(always)]
    fn sqrt8(self, a: A8) -> A8 {
        a.map(f64::sqrt)
    }
    #[inline(always)]
    fn neg8(self, a: A8) -> A8 {
        a.map(|x| -x)
    }
    #[inline(always)]
    fn abs8(self, a: A8) -> A8 {
        a.map(f64::abs)
    }
    /// `if a > b { a } else { b }` per lane.
    #[inline(always)]
    fn max8(self, a: A8, b: A8) -> A8 {
        std::array::from_fn(|l| if a[l] > b[l] { a[l] } else { b[l] })
    }
    /// `if a <= b { x } else { y }` per lane.
    #[inline(always)]
    fn le_select8(self, a: A8, b: A8, x: A8, y: A8) -> A8 {
        std::array::from_fn(|l| if a[l] <= b[l] { x[l] } else { y[l] })
    }
    /// a * b + c per lane, fused on FMA levels.
    #[inline(always)]
    fn mul_add8(self, a: A8, b: A8, c: A8) -> A8 {
        std::array::from_fn(|l| Self::mul_add(a[l], b[l], c[l]))
    }
    /// The largest integer <= a per lane (exact; vectorised in the level's dispatched code).
    #[inline(always)]
    fn floor8(self, a: A8) -> A8 {
        a.map(f64::floor)
    }
}

/// x86-64 baseline (SSE2, no FMA).
#[derive(Debug, Clone, Copy, Default)]
pub struct Baseline;
/// x86-64-v3 (AVX2, FMA): holds the detected features.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy)]
pub struct Avx2(pulp::x86::V3);
/// x86-64-v4 (AVX-512, FMA): holds the detected features.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy)]
pub struct Avx512(pulp::x86::V4);
/// aarch64 NEON (FMA).
#[derive(Debug, Clone, Copy, Default)]
pub struct Neon;

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Avx2, Avx512, Baseline, Isa, Level, A8};
    use std::arch::x86_64::*;

    // SAFETY (every transmute below): [f64; 8] and 4 x __m128d, 2 x __m256d or 1 x __m512d have
    // the same size and every bit pattern is valid for both.
    #[inline(always)]
    fn q(a: A8) -> [__m128d; 4] {
        unsafe { std::mem::transmute::<A8, [__m128d; 4]>(a) }
    }
    #[inline(always)]
    fn uq(a: [__m128d; 4]) -> A8 {
        unsafe { std::mem::transmute::<[__m128d; 4], A8>(a) }
    }
    #[inline(always)]
    fn h(a: A8) -> [__m256d; 2] {
        unsafe { std::mem::transmute::<A8, [__m256d; 2]>(a) }
    }
    #[inline(always)]
    fn uh(a: [__m256d; 2]) -> A8 {
        unsafe { std::mem::transmute::<[__m256d; 2], A8>(a) }
    }
    #[inline(always)]
    fn z(a: A8) -> __m512d {
        unsafe { std::mem::transmute::<A8, __m512d>(a) }
    }
    #[inline(always)]
    fn uz(a: __m512d) -> A8 {
        unsafe { std::mem::transmute::<__m512d, A8>(a) }
    }
    const SIGN: A8 = [-0.0; 8];

    macro_rules! sse2 {
        ($a:expr, $b:expr, $f:ident) => {{
            let (a, b) = (q($a), q($b));
            // SAFETY: SSE2 is part of the x86-64 baseline, present on every CPU of the arch.
            uq(unsafe { [$f(a[0], b[0]), $f(a[1], b[1]), $f(a[2], b[2]), $f(a[3], b[3])] })
        }};
    }

    impl Isa for Baseline {
        const LEVEL: Level = Level::Baseline;
        const FMA: bool = false;
        #[inline(always)]
        fn add8(self, a: A8, b: A8) -> A8 {
            sse2!(a, b, _mm_add_pd)
        }
        #[inline(always)]
        fn sub8(self, a: A8, b: A8) -> A8 {
            sse2!(a, b, _mm_sub_pd)
        }
        #[inline(always)]
        fn mul8(self, a: A8, b: A8) -> A8 {
            sse2!(a, b, _mm_mul_pd)
        }
        #[inline(always)]
        fn div8(self, a: A8, b: A8) -> A8 {
            sse2!(a, b, _mm_div_pd)
        }
        #[inline(always)]
        fn sqrt8(self, a: A8) -> A8 {
            let a = q(a);
            // SAFETY: as in `sse2!`.
            uq(unsafe { [_mm_sqrt_pd(a[0]), _mm_sqrt_pd(a[1]), _mm_sqrt_pd(a[2]), _mm_sqrt_pd(a[3])] })
        }
        #[inline(always)]
        fn neg8(self, a: A8) -> A8 {
            sse2!(SIGN, a, _mm_xor_pd)
        }
        #[inline(always)]
        fn abs8(self, a: A8) -> A8 {
            sse2!(SIGN, a, _mm_andnot_pd)
        }
        #[inline(always)]
        fn max8(self, a: A8, b: A8) -> A8 {
            sse2!(a, b, _mm_max_pd)
        }
        #[inline(always)]
        fn le_select8(self, a: A8, b: A8, x: A8, y: A8) -> A8 {
            let m = sse2!(a, b, _mm_cmple_pd);
            let (m, x, y) = (q(m), q(x), q(y));
            // SAFETY: as in `sse2!`.
            uq(std::array::from_fn(|k| unsafe { _mm_or_pd(_mm_and_pd(m[k], x[k]), _mm_andnot_pd(m[k], y[k])) }))
        }
        #[inline(always)]
        fn mul_add8(self, a: A8, b: A8, c: A8) -> A8 {
            self.add8(self.mul8(a, b), c)
        }
    }

    macro_rules! avx {
        ($s:ident, $a:expr, $b:expr, $f:ident) => {{
            let (a, b) = (h($a), h($b));
            uh([$s.0.avx.$f(a[0], b[0]), $s.0.avx.$f(a[1], b[1])])
        }};
    }

    impl Isa for Avx2 {
        const LEVEL: Level = Level::Avx2;
        const FMA: bool = true;
        #[inline(always)]
        fn add8(self, a: A8, b: A8) -> A8 {
            avx!(self, a, b, _mm256_add_pd)
        }
        #[inline(always)]
        fn sub8(self, a: A8, b: A8) -> A8 {
            avx!(self, a, b, _mm256_sub_pd)
        }
        #[inline(always)]
        fn mul8(self, a: A8, b: A8) -> A8 {
            avx!(self, a, b, _mm256_mul_pd)
        }
        #[inline(always)]
        fn div8(self, a: A8, b: A8) -> A8 {
            avx!(self, a, b, _mm256_div_pd)
        }
        #[inline(always)]
        fn sqrt8(self, a: A8) -> A8 {
            let a = h(a);
            uh([self.0.avx._mm256_sqrt_pd(a[0]), self.0.avx._mm256_sqrt_pd(a[1])])
        }
        #[inline(always)]
        fn neg8(self, a: A8) -> A8 {
            avx!(self, SIGN, a, _mm256_xor_pd)
        }
        #[inline(always)]
        fn abs8(self, a: A8) -> A8 {
            avx!(self, SIGN, a, _mm256_andnot_pd)
        }
        #[inline(always)]
        fn max8(self, a: A8, b: A8) -> A8 {
            avx!(self, a, b, _mm256_max_pd)
        }
        #[inline(always)]
        fn le_select8(self, a: A8, b: A8, x: A8, y: A8) -> A8 {
            let (a, b, x, y) = (h(a), h(b), h(x), h(y));
            let avx = self.0.avx;
            // both halves written out: a closure (array::from_fn's) is compiled outside the
            // kernel's target features, and the intrinsics in it become calls
            let m = [avx._mm256_cmp_pd::<_CMP_LE_OQ>(a[0], b[0]), avx._mm256_cmp_pd::<_CMP_LE_OQ>(a[1], b[1])];
            uh([avx._mm256_blendv_pd(y[0], x[0], m[0]), avx._mm256_blendv_pd(y[1], x[1], m[1])])
        }
        #[inline(always)]
        fn mul_add8(self, a: A8, b: A8, c: A8) -> A8 {
            let (a, b, c) = (h(a), h(b), h(c));
            uh([self.0.fma._mm256_fmadd_pd(a[0], b[0], c[0]), self.0.fma._mm256_fmadd_pd(a[1], b[1], c[1])])
        }
        #[inline(always)]
        fn floor8(self, a: A8) -> A8 {
            let a = h(a);
            uh([self.0.avx._mm256_floor_pd(a[0]), self.0.avx._mm256_floor_pd(a[1])])
        }
    }

    impl Isa for Avx512 {
        const LEVEL: Level = Level::Avx512;
        const FMA: bool = true;
        #[inline(always)]
        fn add8(self, a: A8, b: A8) -> A8 {
            uz(self.0.avx512f._mm512_add_pd(z(a), z(b)))
        }
        #[inline(always)]
        fn sub8(self, a: A8, b: A8) -> A8 {
            uz(self.0.avx512f._mm512_sub_pd(z(a), z(b)))
        }
        #[inline(always)]
        fn mul8(self, a: A8, b: A8) -> A8 {
            uz(self.0.avx512f._mm512_mul_pd(z(a), z(b)))
        }
        #[inline(always)]
        fn div8(self, a: A8, b: A8) -> A8 {
            uz(self.0.avx512f._mm512_div_pd(z(a), z(b)))
        }
        #[inline(always)]
        fn sqrt8(self, a: A8) -> A8 {
            uz(self.0.avx512f._mm512_sqrt_pd(z(a)))
        }
        #[inline(always)]
        fn neg8(self, a: A8) -> A8 {
            uz(self.0.avx512dq._mm512_xor_pd(z(SIGN), z(a)))
        }
        #[inline(always)]
        fn abs8(self, a: A8) -> A8 {
            uz(self.0.avx512f._mm512_abs_pd(z(a)))
        }
        #[inline(always)]
        fn max8(self, a: A8, b: A8) -> A8 {
            uz(self.0.avx512f._mm512_max_pd(z(a), z(b)))
        }
        #[inline(always)]
        fn le_select8(self, a: A8, b: A8, x: A8, y: A8) -> A8 {
            let f = self.0.avx512f;
            uz(f._mm512_mask_blend_pd(f._mm512_cmp_pd_mask::<_CMP_LE_OQ>(z(a), z(b)), z(y), z(x)))
        }
        #[inline(always)]
        fn mul_add8(self, a: A8, b: A8, c: A8) -> A8 {
            uz(self.0.avx512f._mm512_fmadd_pd(z(a), z(b), z(c)))
        }
        #[inline(always)]
        fn floor8(self, a: A8) -> A8 {
            // rounding toward -infinity (1), precision exception suppressed (8), scale 0
            uz(self.0.avx512f._mm512_roundscale_pd::<0x09>(z(a)))
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl Isa for Baseline {
    const LEVEL: Level = Level::Baseline;
    const FMA: bool = false;
}
impl Isa for Neon {
    const LEVEL: Level = Level::Neon;
    const FMA: bool = true;
}

/// A computation written once for every level. `run` and everything its hot loop calls must be
/// `#[inline(always)]`, so that it is compiled inside the level's target-feature function.
pub trait Kernel {
    type Output;
    fn run<I: Isa>(self, isa: I) -> Self::Output;
}

#[cfg(target_arch = "x86_64")]
struct At<K, I>(K, I);

#[cfg(target_arch = "x86_64")]
impl<K: Kernel, I: Isa> pulp::NullaryFnOnce for At<K, I> {
    type Output = K::Output;
    #[inline(always)]
    fn call(self) -> K::Output {
        self.0.run(self.1)
    }
}

/// Run `kernel` at `level` (an error naming `LIBRATE_SIMD` if the CPU lacks it).
#[inline]
pub fn run_at<K: Kernel>(level: Level, kernel: K) -> Result<K::Output> {
    let unavailable = || parse(Some(level.name())).err().unwrap_or_else(|| invalid(ENV_VAR, format!("level {level} is not available")));
    match level {
        #[cfg(target_arch = "x86_64")]
        Level::Baseline => Ok(kernel.run(Baseline)),
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => {
            let simd = pulp::x86::V3::try_new().ok_or_else(unavailable)?;
            Ok(simd.vectorize(At(kernel, Avx2(simd))))
        }
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => {
            let simd = pulp::x86::V4::try_new().ok_or_else(unavailable)?;
            Ok(simd.vectorize(At(kernel, Avx512(simd))))
        }
        #[cfg(target_arch = "aarch64")]
        Level::Neon => Ok(kernel.run(Neon)),
        #[allow(unreachable_patterns)]
        _ => Err(unavailable()),
    }
}

/// Run `kernel` at the active level ([`active`]).
#[inline]
pub fn run<K: Kernel>(kernel: K) -> Result<K::Output> {
    run_at(active()?, kernel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_parsed_and_checked() {
        let best = *available().last().unwrap();
        assert_eq!(parse(None).unwrap(), best);
        assert_eq!(parse(Some("AUTO")).unwrap(), best);
        let e = parse(Some("sse9")).unwrap_err().to_string();
        assert!(e.contains("LIBRATE_SIMD") && e.contains("auto") && e.contains("sse9"), "{e}");
        for &l in known() {
            assert_eq!(parse(Some(l.name())).is_ok(), l.is_available(), "{l}");
        }
    }

    /// The FMA marker decides the rounding: 0.1 * 10 - 1 is 0 in two roundings and the
    /// representation error of 0.1 (5.55e-17) fused.
    #[test]
    fn fused_and_unfused_multiply_add() {
        let (a, b, c) = (std::hint::black_box(0.1), 10.0, -1.0);
        assert_eq!(Baseline::mul_add(a, b, c), 0.0);
        assert_eq!(Neon::mul_add(a, b, c), 5.551115123125783e-17);
        for &l in &available() {
            struct Probe(f64);
            impl Kernel for Probe {
                type Output = f64;
                #[inline(always)]
                fn run<I: Isa>(self, isa: I) -> f64 {
                    let v = isa.mul_add8([self.0; 8], [10.0; 8], [-1.0; 8]);
                    assert!(v.iter().all(|&x| x == v[0]));
                    assert_eq!(I::mul_add(self.0, 10.0, -1.0), v[0]);
                    v[0]
                }
            }
            let r = run_at(l, Probe(a)).unwrap();
            assert_eq!(r, if l == Level::Baseline { 0.0 } else { 5.551115123125783e-17 }, "{l}");
        }
    }
}
