//! The scalar types equations are written over, so that each equation is written once:
//!
//! - [`Real`]: f64 and forward-mode dual numbers [`Dual`] carrying N partial derivatives, so one
//!   generic right-hand side gives both the values (f64) and the exact Jacobian (`Dual<N>`) used
//!   by the variational equations (the CR3BP acceleration, the 3-D attitude model);
//! - [`Lane`]: f64 and the eight-lane vector [`F8`], so the scalar planar model and the map
//!   engine's lanes evaluate the same torque laws (gravity gradient, flat-plate SRP);
//! - [`Arith`]: the field operations common to all three (f64, [`Dual`], [`F8`]; no constants,
//!   which an [`F8`] cannot make without its instruction-set token), so the 3-D attitude laws
//!   (kinematics, gravity-gradient torque from the tidal tensor, Euler's equations) are written
//!   once for the scalar model, its STM and the 3-D map lanes;
//! - [`Field`]: [`Arith`] with square roots and constants made like a value, so the CR3BP's
//!   acceleration is written once for the scalar model, its Jacobians and the orbit tables'
//!   eight samples at a time.
//!
//! This module depends on nothing else in the crate but [`crate::simd`]'s instruction-set
//! markers (cr3bp and attitude both build on it).

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

use crate::simd::Isa;

/// Field arithmetic and scaling by an f64 (f64, [`Dual`], [`F8`]).
pub trait Arith: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self> {
    fn scale(self, k: f64) -> Self;
    /// self * a + b: two roundings for f64 and [`Dual`] (so an equation written with it has the
    /// bits of `self * a + b`, or of `b + self * a`: addition commutes), one on the lanes of a
    /// fused level ([`crate::simd::Isa::FMA`]).
    #[inline(always)]
    fn madd(self, a: Self, b: Self) -> Self {
        self * a + b
    }
}

/// Multiplication by a coefficient of type K: an f64 for f64 and [`Dual`] (a scaling), a per-lane
/// value for [`F8`]. A trait rather than a closure argument: closures are not
/// `#[inline(always)]`, and a lane operation left in an out-of-line closure is compiled without
/// the dispatched level's target features (a call per operation).
pub trait MulBy<K>: Copy {
    fn mul_by(self, k: K) -> Self;
}

impl MulBy<f64> for f64 {
    #[inline(always)]
    fn mul_by(self, k: f64) -> Self {
        self * k
    }
}

impl<const N: usize> MulBy<f64> for Dual<N> {
    #[inline(always)]
    fn mul_by(self, k: f64) -> Self {
        self.scale(k)
    }
}

impl<I: Isa> MulBy<F8<I>> for F8<I> {
    #[inline(always)]
    fn mul_by(self, k: F8<I>) -> Self {
        self * k
    }
}

/// [`Arith`] with square roots and constants made alongside a value (f64, [`Dual`], [`F8`]: an
/// [`F8`] takes its instruction-set token from the value), so that an equation written over it
/// (the CR3BP's acceleration) runs on the scalar model, its dual-number Jacobians and the lanes.
pub trait Field: Arith {
    fn sqrt(self) -> Self;
    /// The constant x, made like `self` (for a [`Dual`], no partials).
    fn cst_like(self, x: f64) -> Self;
}

/// Scalar arithmetic needed by the dynamics.
pub trait Real: Field + MulBy<f64> + Send + Sync {
    fn cst(x: f64) -> Self;
    /// The value part.
    fn re(self) -> f64;
}

impl Arith for f64 {
    #[inline(always)]
    fn scale(self, k: f64) -> Self {
        self * k
    }
}

impl Field for f64 {
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn cst_like(self, x: f64) -> Self {
        x
    }
}

impl Real for f64 {
    #[inline(always)]
    fn cst(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self
    }
}

/// a + sum_k eps_k e_k with e_k e_j = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<const N: usize> {
    pub re: f64,
    pub eps: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// The k-th independent variable with value x.
    pub fn var(x: f64, k: usize) -> Self {
        let mut eps = [0.0; N];
        eps[k] = 1.0;
        Self { re: x, eps }
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self { re: self.re + o.re, eps: std::array::from_fn(|k| self.eps[k] + o.eps[k]) }
    }
}
impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self { re: self.re - o.re, eps: std::array::from_fn(|k| self.eps[k] - o.eps[k]) }
    }
}
impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self { re: self.re * o.re, eps: std::array::from_fn(|k| self.eps[k] * o.re + self.re * o.eps[k]) }
    }
}
impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.re;
        let v = self.re * inv;
        Self { re: v, eps: std::array::from_fn(|k| (self.eps[k] - v * o.eps[k]) * inv) }
    }
}
impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self { re: -self.re, eps: self.eps.map(|e| -e) }
    }
}

impl<const N: usize> Arith for Dual<N> {
    #[inline(always)]
    fn scale(self, k: f64) -> Self {
        Self { re: self.re * k, eps: self.eps.map(|e| e * k) }
    }
}

impl<const N: usize> Field for Dual<N> {
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        let d = 0.5 / s;
        Self { re: s, eps: self.eps.map(|e| e * d) }
    }
    #[inline(always)]
    fn cst_like(self, x: f64) -> Self {
        Self::cst(x)
    }
}

impl<const N: usize> Real for Dual<N> {
    #[inline(always)]
    fn cst(x: f64) -> Self {
        Self { re: x, eps: [0.0; N] }
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self.re
    }
}

/// Fused multiply-add `a * b + c` where the build's baseline target has a hardware FMA (aarch64;
/// x86-64 built for a CPU with FMA), otherwise the plain expression (a software `fma` call would
/// be far slower). The portable x86-64 build does not fuse here: the dispatched kernels
/// ([`crate::simd`]) fuse on their FMA levels through [`Isa::mul_add`].
#[inline(always)]
pub(crate) fn fmadd(a: f64, b: f64, c: f64) -> f64 {
    #[cfg(any(target_feature = "fma", target_arch = "aarch64"))]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(any(target_feature = "fma", target_arch = "aarch64")))]
    {
        a * b + c
    }
}

/// Lane-wise arithmetic shared by f64 and [`F8`].
pub trait Lane: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self> {
    /// self * a + b: fused where the level (F8) or the build (f64, `fmadd`) has FMA.
    fn mul_add(self, a: Self, b: Self) -> Self;
    fn abs(self) -> Self;
}

impl Lane for f64 {
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        fmadd(self, a, b)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
}

/// Eight f64 lanes computed with the instruction set `I` ([`crate::simd`]): each operation is
/// one call of the level's eight-lane primitive ([`Isa`]: 4 x SSE2, 2 x AVX or 1 x AVX-512
/// instructions); `mul_add` fuses on FMA levels. A vector carries its level's token (zero-sized;
/// for AVX2 and AVX-512 it exists only once the CPU's support is detected), so the only way to
/// compute with one is inside that level's dispatched code.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct F8<I> {
    v: [f64; 8],
    isa: I,
}

impl<I: Isa> F8<I> {
    #[inline(always)]
    pub fn new(isa: I, v: [f64; 8]) -> Self {
        Self { v, isa }
    }
    #[inline(always)]
    pub fn splat(isa: I, x: f64) -> Self {
        Self { v: [x; 8], isa }
    }
    /// The instruction-set token.
    #[inline(always)]
    pub fn isa(self) -> I {
        self.isa
    }
    #[inline(always)]
    pub fn to_array(self) -> [f64; 8] {
        self.v
    }
    #[inline(always)]
    fn with(self, v: [f64; 8]) -> Self {
        Self { v, isa: self.isa }
    }
    /// Lane-wise `if self > o { self } else { o }` (x86 `maxpd`: o where either is NaN).
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        self.with(self.isa.max8(self.v, o.v))
    }
    /// Lane-wise `if self <= o { if_le } else { if_not }` (NaN compares false).
    #[inline(always)]
    pub fn le_select(self, o: Self, if_le: Self, if_not: Self) -> Self {
        self.with(self.isa.le_select8(self.v, o.v, if_le.v, if_not.v))
    }
    #[inline(always)]
    pub fn abs(self) -> Self {
        self.with(self.isa.abs8(self.v))
    }
    /// self * a + b, fused on FMA levels.
    #[inline(always)]
    pub fn mul_add(self, a: Self, b: Self) -> Self {
        self.with(self.isa.mul_add8(self.v, a.v, b.v))
    }
    /// Lane-wise floor.
    #[inline(always)]
    pub fn floor(self) -> Self {
        self.with(self.isa.floor8(self.v))
    }

    /// Lane-wise (sin, cos), to about an ulp for |x| < 1e5 (no table, no branch: Cody-Waite
    /// reduction by pi/2 in three parts and the minimax polynomials of Cephes' sin/cos on
    /// [-pi/4, pi/4], as in `wide`'s vector sin_cos; NaN for non-finite input).
    #[inline(always)]
    #[allow(clippy::excessive_precision)] // Cephes' coefficients as published
    pub fn sin_cos(self) -> (Self, Self) {
        const PS: [f64; 6] = [
            -1.66666666666666307295E-1,
            8.33333333332211858878E-3,
            -1.98412698295895385996E-4,
            2.75573136213857245213E-6,
            -2.50507477628578072866E-8,
            1.58962301576546568060E-10,
        ];
        const PC: [f64; 6] = [
            4.16666666666665929218E-2,
            -1.38888888888730564116E-3,
            2.48015872888517045348E-5,
            -2.75573141792967388112E-7,
            2.08757008419747316778E-9,
            -1.13585365213876817300E-11,
        ];
        const DP: [f64; 3] = [7.853981554508209228515625E-1 * 2.0, 7.94662735614792836714E-9 * 2.0, 3.06161699786838294307E-17 * 2.0];
        let isa = self.isa;
        let k = |v: f64| Self::splat(isa, v);
        let xa = self.abs();
        // quadrant q = round(|x| 2/pi), and r = |x| - q pi/2 in three exact-product parts
        let q = (xa * k(std::f64::consts::FRAC_2_PI) + k(0.5)).floor();
        let r = (-q).mul_add(k(DP[2]), (-q).mul_add(k(DP[1]), (-q).mul_add(k(DP[0]), xa)));
        let r2 = r * r;
        // Horner by index loops, no closure: a closure (or an iterator's rfold) may be compiled
        // outside the kernel's target features, with its intrinsics called out of line
        let (mut ps, mut pc) = (k(PS[5]), k(PC[5]));
        for j in (0..5).rev() {
            ps = ps.mul_add(r2, k(PS[j]));
            pc = pc.mul_add(r2, k(PC[j]));
        }
        let s = (r * r2).mul_add(ps, r);
        let c = (r2 * r2).mul_add(pc, r2.mul_add(k(-0.5), k(1.0)));
        // q mod 4 selects and signs: sin = (s, c, -s, -c)[q], cos = (c, -s, -c, s)[q]
        let m = q - (q * k(0.25)).floor() * k(4.0);
        let odd = m - (m * k(0.5)).floor() * k(2.0);
        let (sin1, cos1) = (odd.le_select(k(0.5), s, c), odd.le_select(k(0.5), c, s));
        let sin_sign = m.le_select(k(1.5), k(1.0), k(-1.0)) * k(0.0).le_select(self, k(1.0), k(-1.0));
        let d = m - k(1.5);
        let cos_sign = (d * d).le_select(k(0.5), k(-1.0), k(1.0));
        (sin1 * sin_sign, cos1 * cos_sign)
    }
}

macro_rules! f8_binop {
    ($tr:ident, $f:ident, $op:ident) => {
        impl<I: Isa> $tr for F8<I> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                self.with(self.isa.$op(self.v, o.v))
            }
        }
    };
}
f8_binop!(Add, add, add8);
f8_binop!(Sub, sub, sub8);
f8_binop!(Mul, mul, mul8);
f8_binop!(Div, div, div8);

impl<I: Isa> Neg for F8<I> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.with(self.isa.neg8(self.v))
    }
}

impl<I: Isa> AddAssign for F8<I> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<I: Isa> Arith for F8<I> {
    #[inline(always)]
    fn scale(self, k: f64) -> Self {
        self * Self::splat(self.isa, k)
    }
    #[inline(always)]
    fn madd(self, a: Self, b: Self) -> Self {
        self.mul_add(a, b)
    }
}

impl<I: Isa> Field for F8<I> {
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.with(self.isa.sqrt8(self.v))
    }
    #[inline(always)]
    fn cst_like(self, x: f64) -> Self {
        Self::splat(self.isa, x)
    }
}

impl<I: Isa> Lane for F8<I> {
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        F8::mul_add(self, a, b)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F8::abs(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes' vector sin_cos against libm's f64 sin_cos: 20000 arguments in [-1e3, 1e3]
    /// plus multiples of pi/4 and signed zeros, within 2e-16 absolute plus 2 ulp relative.
    #[test]
    fn vector_sin_cos_matches_libm() {
        use crate::simd::Baseline;
        let mut xs: Vec<f64> = (0..20000).map(|i| -1e3 + 2e3 * ((i as f64 * 0.6180339887498949) % 1.0)).collect();
        xs.extend((-40..=40).map(|k| k as f64 * std::f64::consts::FRAC_PI_4));
        xs.extend([0.0, -0.0, 1e-300, -1e-300, 3.0e4, -7.7e4]);
        for chunk in xs.chunks(8) {
            let mut v = [0.0; 8];
            v[..chunk.len()].copy_from_slice(chunk);
            let (s, c) = F8::new(Baseline, v).sin_cos();
            for (l, &x) in chunk.iter().enumerate() {
                let (sr, cr) = x.sin_cos();
                let tol = |r: f64| 2e-16 + 4.0 * f64::EPSILON * r.abs();
                assert!((s.to_array()[l] - sr).abs() <= tol(sr), "sin({x}) = {} vs {sr}", s.to_array()[l]);
                assert!((c.to_array()[l] - cr).abs() <= tol(cr), "cos({x}) = {} vs {cr}", c.to_array()[l]);
            }
        }
    }

    #[test]
    fn derivatives_of_a_rational_expression() {
        // f(x, y) = sqrt(x^2 + y) / (x - y): partials against the closed forms.
        let (x, y) = (1.3, 0.4);
        let (dx, dy) = (Dual::<2>::var(x, 0), Dual::<2>::var(y, 1));
        let f = (dx * dx + dy).sqrt() / (dx - dy);
        let s = (x * x + y).sqrt();
        assert!((f.re - s / (x - y)).abs() < 1e-15);
        let fx = (x / s) / (x - y) - s / (x - y).powi(2);
        let fy = (0.5 / s) / (x - y) + s / (x - y).powi(2);
        assert!((f.eps[0] - fx).abs() < 1e-14 && (f.eps[1] - fy).abs() < 1e-14);
    }
}
