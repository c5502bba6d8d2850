//! Equations of motion and variational equations.

use crate::integrate::System;
use crate::scalar::Field;

/// Dimension of the state augmented with the row-major 6x6 state transition matrix.
pub const STM_DIM: usize = 42;

/// The potential U(x, y, z).
pub fn potential(mu: f64, r: &[f64]) -> f64 {
    let (x, y, z) = (r[0], r[1], r[2]);
    let r1 = ((x + mu).powi(2) + y * y + z * z).sqrt();
    let r2 = ((x - 1.0 + mu).powi(2) + y * y + z * z).sqrt();
    0.5 * (x * x + y * y) + (1.0 - mu) / r1 + mu / r2
}

/// Gradient of U, over any [`Field`] scalar (f64, dual numbers for exact Jacobians, or eight
/// lanes).
#[inline(always)]
pub fn potential_gradient<R: Field>(mu: f64, r: &[R]) -> [R; 3] {
    let (x, y, z) = (r[0], r[1], r[2]);
    let (dx1, dx2) = (x + x.cst_like(mu), x - x.cst_like(1.0) + x.cst_like(mu));
    let yz = y * y + z * z;
    let r1sq = dx1 * dx1 + yz;
    let r2sq = dx2 * dx2 + yz;
    let c1 = x.cst_like(1.0 - mu) / (r1sq * r1sq.sqrt());
    let c2 = x.cst_like(mu) / (r2sq * r2sq.sqrt());
    [x - c1 * dx1 - c2 * dx2, y - (c1 + c2) * y, -(c1 + c2) * z]
}

/// The CR3BP acceleration (xdd, ydd, zdd) = grad U + (2 yd, -2 xd, 0) at position `p` and
/// velocity `v`, over any [`Field`] scalar: the one definition of the equations of motion,
/// used by [`Cr3bp`], by the coupled attitude model and by the orbit tables' lanes.
#[inline(always)]
pub fn acceleration<R: Field>(mu: f64, p: &[R], v: &[R]) -> [R; 3] {
    let g = potential_gradient(mu, p);
    [v[1].scale(2.0) + g[0], v[0].scale(-2.0) + g[1], g[2]]
}

/// Hessian of U (symmetric), row-major 3x3.
#[inline(always)]
pub fn potential_hessian(mu: f64, r: &[f64]) -> [[f64; 3]; 3] {
    let (x, y, z) = (r[0], r[1], r[2]);
    let (dx1, dx2) = (x + mu, x - 1.0 + mu);
    let yz = y * y + z * z;
    let r1sq = dx1 * dx1 + yz;
    let r2sq = dx2 * dx2 + yz;
    let r1 = r1sq.sqrt();
    let r2 = r2sq.sqrt();
    let a1 = (1.0 - mu) / (r1sq * r1);
    let a2 = mu / (r2sq * r2);
    let b1 = 3.0 * a1 / r1sq;
    let b2 = 3.0 * a2 / r2sq;
    let s = a1 + a2;
    let uxx = 1.0 - s + b1 * dx1 * dx1 + b2 * dx2 * dx2;
    let uyy = 1.0 - s + (b1 + b2) * y * y;
    let uzz = -s + (b1 + b2) * z * z;
    let uxy = (b1 * dx1 + b2 * dx2) * y;
    let uxz = (b1 * dx1 + b2 * dx2) * z;
    let uyz = (b1 + b2) * y * z;
    [[uxx, uxy, uxz], [uxy, uyy, uyz], [uxz, uyz, uzz]]
}

/// Jacobi constant C = 2U - |v|^2 of a state (x, y, z, xd, yd, zd).
pub fn jacobi(mu: f64, s: &[f64]) -> f64 {
    2.0 * potential(mu, &s[..3]) - (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])
}

/// CR3BP equations of motion, state (x, y, z, xd, yd, zd).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cr3bp {
    pub mu: f64,
}

impl Cr3bp {
    /// The derivative of the state (x, y, z, xd, yd, zd) over any [`Field`] scalar (the orbit
    /// tables sample eight states at a time with it).
    #[inline(always)]
    pub fn derivative_of<R: Field>(&self, y: &[R; 6]) -> [R; 6] {
        let a = acceleration(self.mu, &y[..3], &y[3..]);
        [y[3], y[4], y[5], a[0], a[1], a[2]]
    }
}

impl System<[f64; 6]> for Cr3bp {
    #[inline(always)]
    fn derivative(&self, _t: f64, y: &[f64; 6], dy: &mut [f64; 6]) {
        *dy = self.derivative_of(y);
    }
}

/// CR3BP with the variational equations: state (6) followed by the 6x6 STM row-major (36),
/// dPhi/dt = A Phi with A = [[0, I], [U_rr, Omega]], Omega = [[0, 2, 0], [-2, 0, 0], [0, 0, 0]].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cr3bpStm {
    pub mu: f64,
}

impl Cr3bpStm {
    /// The state followed by the identity matrix.
    pub fn initial(state: &[f64; 6]) -> [f64; STM_DIM] {
        let mut y = [0.0; STM_DIM];
        y[..6].copy_from_slice(state);
        for i in 0..6 {
            y[6 + 7 * i] = 1.0;
        }
        y
    }

    /// Split an augmented state into the state and the STM (row-major 6x6).
    pub fn split(y: &[f64; STM_DIM]) -> ([f64; 6], [[f64; 6]; 6]) {
        let mut s = [0.0; 6];
        s.copy_from_slice(&y[..6]);
        let m = std::array::from_fn(|i| std::array::from_fn(|j| y[6 + 6 * i + j]));
        (s, m)
    }
}

impl System<[f64; STM_DIM]> for Cr3bpStm {
    #[inline(always)]
    fn derivative(&self, t: f64, y: &[f64; STM_DIM], dy: &mut [f64; STM_DIM]) {
        let mut s = [0.0; 6];
        s.copy_from_slice(&y[..6]);
        let mut ds = [0.0; 6];
        Cr3bp { mu: self.mu }.derivative(t, &s, &mut ds);
        dy[..6].copy_from_slice(&ds);
        let h = potential_hessian(self.mu, &s);
        let phi = &y[6..];
        let dphi = &mut dy[6..];
        for j in 0..6 {
            let (p0, p1, p2) = (phi[j], phi[6 + j], phi[12 + j]);
            let (v0, v1) = (phi[18 + j], phi[24 + j]);
            dphi[j] = v0;
            dphi[6 + j] = v1;
            dphi[12 + j] = phi[30 + j];
            dphi[18 + j] = h[0][0] * p0 + h[0][1] * p1 + h[0][2] * p2 + 2.0 * v1;
            dphi[24 + j] = h[1][0] * p0 + h[1][1] * p1 + h[1][2] * p2 - 2.0 * v0;
            dphi[30 + j] = h[2][0] * p0 + h[2][1] * p1 + h[2][2] * p2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generic acceleration over dual numbers: its Jacobian in position equals the
    /// closed-form Hessian of U (to 1e-14 relative to max |U_ij|), in velocity the Coriolis
    /// matrix [[0, 2, 0], [-2, 0, 0], [0, 0, 0]] (exactly); its value equals the f64 evaluation
    /// bit for bit.
    #[test]
    fn dual_acceleration_jacobian_is_the_hessian() {
        use crate::scalar::Dual;
        let mu = 0.01215;
        let s = [0.7, 0.2, -0.1, 0.05, -0.3, 0.02];
        let y: [Dual<6>; 6] = std::array::from_fn(|k| Dual::var(s[k], k));
        let a = acceleration(mu, &y[..3], &y[3..]);
        let af = acceleration(mu, &s[..3], &s[3..]);
        let h = potential_hessian(mu, &s);
        let hmax = h.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let coriolis = [[0.0, 2.0, 0.0], [-2.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        for i in 0..3 {
            assert_eq!(a[i].re.to_bits(), af[i].to_bits());
            for j in 0..3 {
                assert!((a[i].eps[j] - h[i][j]).abs() < 1e-14 * hmax, "d a_{i} / d r_{j}");
                assert_eq!(a[i].eps[3 + j], coriolis[i][j]);
            }
        }
    }

    /// Gradient and Hessian against central differences of U (independent of the closed forms).
    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let mu = 0.01215;
        let r = [0.7, 0.2, -0.1];
        let g = potential_gradient(mu, &r);
        let hs = potential_hessian(mu, &r);
        let d = 1e-5;
        for i in 0..3 {
            let (mut rp, mut rm) = (r, r);
            rp[i] += d;
            rm[i] -= d;
            let fd = (potential(mu, &rp) - potential(mu, &rm)) / (2.0 * d);
            assert!((fd - g[i]).abs() < 1e-9, "U_{i}: {fd} vs {}", g[i]);
            let (gp, gm) = (potential_gradient(mu, &rp), potential_gradient(mu, &rm));
            for j in 0..3 {
                let fd = (gp[j] - gm[j]) / (2.0 * d);
                assert!((fd - hs[j][i]).abs() < 1e-8, "U_{j}{i}: {fd} vs {}", hs[j][i]);
            }
        }
    }
}
