//! The scalar types equations are written over, so that each equation is written once:
//!
//! - [`Real`]: f64 and forward-mode dual numbers [`Dual`] carrying N partial derivatives, so one
//!   generic right-hand side gives both the values (f64) and the exact Jacobian (`Dual<N>`) used
//!   by the variational equations (the CR3BP acceleration, the 3-D attitude model);
//! - [`Lane`]: f64 and the SIMD vector `wide::f64x8`, so the scalar planar model and the map
//!   engine's lanes evaluate the same torque laws (gravity gradient, flat-plate SRP).
//!
//! This module depends on nothing else in the crate (cr3bp and attitude both build on it).

use std::ops::{Add, Div, Mul, Neg, Sub};

use wide::f64x8;

/// Scalar arithmetic needed by the dynamics.
pub trait Real:
    Copy + Send + Sync + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    fn cst(x: f64) -> Self;
    fn sqrt(self) -> Self;
    /// The value part.
    fn re(self) -> f64;
    fn scale(self, k: f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn cst(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self
    }
    #[inline(always)]
    fn scale(self, k: f64) -> Self {
        self * k
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

impl<const N: usize> Real for Dual<N> {
    #[inline(always)]
    fn cst(x: f64) -> Self {
        Self { re: x, eps: [0.0; N] }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        let d = 0.5 / s;
        Self { re: s, eps: self.eps.map(|e| e * d) }
    }
    #[inline(always)]
    fn re(self) -> f64 {
        self.re
    }
    #[inline(always)]
    fn scale(self, k: f64) -> Self {
        Self { re: self.re * k, eps: self.eps.map(|e| e * k) }
    }
}

/// Fused multiply-add `a * b + c` where the target has a hardware FMA (one rounding, faster),
/// otherwise the plain expression (a software `fma` call would be far slower).
#[inline(always)]
pub(crate) fn fmadd(a: f64, b: f64, c: f64) -> f64 {
    #[cfg(target_feature = "fma")]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(target_feature = "fma"))]
    {
        a * b + c
    }
}

/// Lane-wise arithmetic shared by f64 and `wide::f64x8`.
pub trait Lane: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self> {
    /// The value in every lane.
    fn splat(x: f64) -> Self;
    /// self * a + b, fused where the target has FMA (as `wide` does for f64x8, so that the
    /// scalar and lane evaluations round alike).
    fn mul_add(self, a: Self, b: Self) -> Self;
    fn abs(self) -> Self;
}

impl Lane for f64 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        fmadd(self, a, b)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
}

impl Lane for f64x8 {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        f64x8::splat(x)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64x8::mul_add(self, a, b)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64x8::abs(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
