//! Monodromy matrices and stability indices.

use nalgebra::{Complex, Matrix6};

use crate::error::Result;
use crate::integrate::{Options, Output};
use crate::propagation::propagate;

/// Monodromy matrix Phi(T, 0) of the orbit through `state0` with period `period`.
pub fn monodromy(mu: f64, state0: &[f64; 6], period: f64, opts: &Options) -> Result<Matrix6<f64>> {
    let tr = propagate(mu, state0, 0.0, period, opts, true, Output::Final, &[])?;
    let m = tr.stm_final.expect("propagated with the STM");
    Ok(Matrix6::from_fn(|i, j| m[i][j]))
}

/// Stability of a periodic orbit from its monodromy matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct Stability {
    /// Eigenvalues of the monodromy matrix (real Schur decomposition).
    pub eigenvalues: [Complex<f64>; 6],
    /// The two non-trivial stability indices nu = (lambda + 1/lambda)/2 (stable when real and
    /// |nu| <= 1). Planar orbits: [in-plane, out-of-plane], from the decoupled blocks. Spatial
    /// orbits: Broucke's indices from the traces, ordered by decreasing |nu|.
    pub indices: [Complex<f64>; 2],
}

/// Broucke's stability indices of a 6x6 symplectic matrix with one trivial pair of unit
/// eigenvalues: with alpha = 2 - tr M and beta = (alpha^2 - tr M^2)/2 + 1, each non-trivial pair
/// has x = lambda + 1/lambda a root of x^2 + alpha x + (beta - 2) = 0; nu = x / 2.
pub fn broucke_indices(m: &Matrix6<f64>) -> [Complex<f64>; 2] {
    let tr = m.trace();
    let tr2 = (m * m).trace();
    let alpha = 2.0 - tr;
    let beta = 0.5 * (alpha * alpha - tr2) + 1.0;
    let disc = Complex::new(alpha * alpha - 4.0 * (beta - 2.0), 0.0).sqrt();
    let x1 = (Complex::new(-alpha, 0.0) + disc) * 0.5;
    let x2 = (Complex::new(-alpha, 0.0) - disc) * 0.5;
    let (a, b) = (x1 * 0.5, x2 * 0.5);
    if a.norm() >= b.norm() {
        [a, b]
    } else {
        [b, a]
    }
}

impl Stability {
    pub fn new(m: &Matrix6<f64>, planar: bool) -> Self {
        let ev = m.complex_eigenvalues();
        let mut eigenvalues = [Complex::new(0.0, 0.0); 6];
        for i in 0..6 {
            eigenvalues[i] = ev[i];
        }
        let indices = if planar {
            // In-plane block (x, y, xd, yd): eigenvalues 1, 1, lambda, 1/lambda.
            let tr_in = m[(0, 0)] + m[(1, 1)] + m[(3, 3)] + m[(4, 4)];
            let nu_out = 0.5 * (m[(2, 2)] + m[(5, 5)]);
            [Complex::new(0.5 * (tr_in - 2.0), 0.0), Complex::new(nu_out, 0.0)]
        } else {
            broucke_indices(m)
        };
        Self { eigenvalues, indices }
    }

    /// Linearly stable: every index real with |nu| <= 1 + tol.
    pub fn is_stable(&self, tol: f64) -> bool {
        self.indices.iter().all(|nu| nu.im.abs() <= tol && nu.re.abs() <= 1.0 + tol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block-diagonal symplectic matrix with known pairs: rotation by 0.3 rad (nu = cos 0.3),
    /// hyperbolic pair (2, 1/2) (nu = 1.25), and a trivial Jordan block.
    #[test]
    fn broucke_indices_of_known_blocks() {
        let mut m = Matrix6::identity();
        m[(0, 3)] = 0.7; // trivial pair as a shear (eigenvalues 1, 1)
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        m[(1, 1)] = c;
        m[(1, 4)] = s;
        m[(4, 1)] = -s;
        m[(4, 4)] = c;
        m[(2, 2)] = 2.0;
        m[(5, 5)] = 0.5;
        let nu = broucke_indices(&m);
        assert!((nu[0].re - 1.25).abs() < 1e-12 && nu[0].im.abs() < 1e-12);
        assert!((nu[1].re - c).abs() < 1e-12 && nu[1].im.abs() < 1e-12);
        let st = Stability::new(&m, false);
        assert!(!st.is_stable(1e-9));
        let mut found = 0;
        for z in st.eigenvalues {
            if (z - Complex::new(2.0, 0.0)).norm() < 1e-9 || (z - Complex::new(0.5, 0.0)).norm() < 1e-9 {
                found += 1;
            }
        }
        assert_eq!(found, 2);
    }
}
