//! The 13-stage Runge-Kutta-Fehlberg 7(8) pair (E. Fehlberg, "Classical fifth-, sixth-, seventh-,
//! and eighth-order Runge-Kutta formulas with stepsize control", NASA TR R-287, 1968, Table X).
//!
//! `B8` gives the 8th-order solution used to advance (local extrapolation); the 7th-order
//! solution differs from it by `ERR * (k0 + k10 - k11 - k12)`, which is the error estimate.

/// Nodes c_i.
pub const C: [f64; 13] = [
    0.0, 2.0 / 27.0, 1.0 / 9.0, 1.0 / 6.0, 5.0 / 12.0, 0.5, 5.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0, 1.0 / 3.0, 1.0, 0.0, 1.0,
];

/// Coupling coefficients a_ij (row i, j < i), zero-padded.
pub const A: [[f64; 12]; 13] = [
    [0.0; 12],
    [2.0 / 27.0, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
    [1.0 / 36.0, 1.0 / 12.0, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
    [1.0 / 24.0, 0.0, 1.0 / 8.0, 0., 0., 0., 0., 0., 0., 0., 0., 0.],
    [5.0 / 12.0, 0.0, -25.0 / 16.0, 25.0 / 16.0, 0., 0., 0., 0., 0., 0., 0., 0.],
    [1.0 / 20.0, 0.0, 0.0, 1.0 / 4.0, 1.0 / 5.0, 0., 0., 0., 0., 0., 0., 0.],
    [-25.0 / 108.0, 0.0, 0.0, 125.0 / 108.0, -65.0 / 27.0, 125.0 / 54.0, 0., 0., 0., 0., 0., 0.],
    [31.0 / 300.0, 0.0, 0.0, 0.0, 61.0 / 225.0, -2.0 / 9.0, 13.0 / 900.0, 0., 0., 0., 0., 0.],
    [2.0, 0.0, 0.0, -53.0 / 6.0, 704.0 / 45.0, -107.0 / 9.0, 67.0 / 90.0, 3.0, 0., 0., 0., 0.],
    [-91.0 / 108.0, 0.0, 0.0, 23.0 / 108.0, -976.0 / 135.0, 311.0 / 54.0, -19.0 / 60.0, 17.0 / 6.0, -1.0 / 12.0, 0., 0., 0.],
    [
        2383.0 / 4100.0, 0.0, 0.0, -341.0 / 164.0, 4496.0 / 1025.0, -301.0 / 82.0, 2133.0 / 4100.0, 45.0 / 82.0,
        45.0 / 164.0, 18.0 / 41.0, 0., 0.,
    ],
    [3.0 / 205.0, 0.0, 0.0, 0.0, 0.0, -6.0 / 41.0, -3.0 / 205.0, -3.0 / 41.0, 3.0 / 41.0, 6.0 / 41.0, 0.0, 0.],
    [
        -1777.0 / 4100.0, 0.0, 0.0, -341.0 / 164.0, 4496.0 / 1025.0, -289.0 / 82.0, 2193.0 / 4100.0, 51.0 / 82.0,
        33.0 / 164.0, 12.0 / 41.0, 0.0, 1.0,
    ],
];

/// Weights of the 7th-order solution.
pub const B7: [f64; 13] = [
    41.0 / 840.0, 0., 0., 0., 0., 34.0 / 105.0, 9.0 / 35.0, 9.0 / 35.0, 9.0 / 280.0, 9.0 / 280.0, 41.0 / 840.0, 0., 0.,
];

/// Weights of the 8th-order solution (the one propagated).
pub const B8: [f64; 13] = [
    0., 0., 0., 0., 0., 34.0 / 105.0, 9.0 / 35.0, 9.0 / 35.0, 9.0 / 280.0, 9.0 / 280.0, 0., 41.0 / 840.0, 41.0 / 840.0,
];

/// y7 - y8 = h * ERR * (k0 + k10 - k11 - k12).
pub const ERR: f64 = 41.0 / 840.0;

/// Order of the propagated solution and of the embedded one.
pub const ORDER: u32 = 8;
pub const ERROR_ORDER: u32 = 7;

/// The stages 1..=12 of an RKF7(8) step, each with the columns j of its row where A[s][j] is
/// not zero (the one place of the tableau's sparsity, used by the scalar stepper and the SIMD
/// lanes): `rkf78_stages!(stage!(args))` expands to `stage!(args, s; j, ...)` for every stage,
/// unrolled.
macro_rules! rkf78_stages {
    ($stage:ident!($($a:tt)*)) => {
        $stage!($($a)*, 1; 0);
        $stage!($($a)*, 2; 0, 1);
        $stage!($($a)*, 3; 0, 2);
        $stage!($($a)*, 4; 0, 2, 3);
        $stage!($($a)*, 5; 0, 3, 4);
        $stage!($($a)*, 6; 0, 3, 4, 5);
        $stage!($($a)*, 7; 0, 4, 5, 6);
        $stage!($($a)*, 8; 0, 3, 4, 5, 6, 7);
        $stage!($($a)*, 9; 0, 3, 4, 5, 6, 7, 8);
        $stage!($($a)*, 10; 0, 3, 4, 5, 6, 7, 8, 9);
        $stage!($($a)*, 11; 0, 5, 6, 7, 8, 9);
        $stage!($($a)*, 12; 0, 3, 4, 5, 6, 7, 8, 9, 11);
    };
}
pub(crate) use rkf78_stages;

#[cfg(test)]
mod tests {
    use super::*;

    /// The stages' column lists of `rkf78_stages!` are exactly the non-zero entries of A.
    #[test]
    fn stage_columns_are_the_nonzero_entries_of_a() {
        let mut got = vec![Vec::new(); 13];
        macro_rules! record {
            ($v:ident, $s:literal; $($j:literal),+) => {
                $v[$s] = vec![$($j),+];
            };
        }
        rkf78_stages!(record!(got));
        for (s, cols) in got.iter().enumerate().skip(1) {
            let nonzero: Vec<usize> = (0..12).filter(|&j| A[s][j] != 0.0).collect();
            assert_eq!(cols, &nonzero, "stage {s}");
        }
    }

    /// Consistency of the tableau (row sums equal the nodes; weights sum to one; the error
    /// weights are B7 - B8): guards against a mistyped coefficient.
    #[test]
    fn tableau_is_consistent() {
        for i in 0..13 {
            let s: f64 = A[i].iter().sum();
            assert!((s - C[i]).abs() < 1e-14, "row {i}: sum {s} vs c {}", C[i]);
        }
        assert!((B7.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!((B8.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let d: Vec<f64> = (0..13).map(|i| B7[i] - B8[i]).collect();
        let expect = [ERR, 0., 0., 0., 0., 0., 0., 0., 0., 0., ERR, -ERR, -ERR];
        for i in 0..13 {
            assert!((d[i] - expect[i]).abs() < 1e-16);
        }
    }

    /// Quadrature order conditions sum b_i c_i^(k-1) = 1/k, k = 1..=8 for B8 and 1..=7 for B7
    /// (necessary conditions of the pair's orders; the full order is measured in the driver tests).
    #[test]
    fn quadrature_conditions() {
        for k in 1..=8 {
            let s8: f64 = (0..13).map(|i| B8[i] * C[i].powi(k - 1)).sum();
            assert!((s8 - 1.0 / k as f64).abs() < 1e-14, "B8, k = {k}");
            if k <= 7 {
                let s7: f64 = (0..13).map(|i| B7[i] * C[i].powi(k - 1)).sum();
                assert!((s7 - 1.0 / k as f64).abs() < 1e-14, "B7, k = {k}");
            }
        }
    }
}
