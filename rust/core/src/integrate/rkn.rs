//! The Runge-Kutta-Nyström pair RKN8(6) of Dormand, El-Mikkawy and Prince ("High-order
//! embedded Runge-Kutta-Nyström formulae", IMA J. Numer. Anal. 7, 1987, 423-430; see
//! Hairer, Nørsett & Wanner, *Solving ODEs I*, sec. II.14) for special second-order equations
//! y'' = f(t, y):
//!
//!   k_i = f(t + c_i h, y + c_i h y' + h^2 sum_j A_ij k_j),
//!   y_1 = y + h y' + h^2 sum_i B_i k_i,    y'_1 = y' + h sum_i BP_i k_i,
//!
//! eighth order; the embedded sixth-order solution differs by h^2 sum_i BT_i k_i (position) and
//! h sum_i BPT_i k_i (velocity), the error estimate (the step advances with the eighth-order
//! solution: local extrapolation). Nine stages, the last one at the new position (first same as
//! last: it is the next step's first).

/// Number of stages.
pub const STAGES: usize = 9;

/// Nodes c_i.
pub const C: [f64; STAGES] = [0.0, 1.0 / 20.0, 1.0 / 10.0, 3.0 / 10.0, 1.0 / 2.0, 7.0 / 10.0, 9.0 / 10.0, 1.0, 1.0];

/// Coupling coefficients A_ij (row i, j < i), zero-padded.
pub const A: [[f64; STAGES]; STAGES] = [
    [0.0; STAGES],
    [1.0 / 800.0, 0., 0., 0., 0., 0., 0., 0., 0.],
    [1.0 / 600.0, 1.0 / 300.0, 0., 0., 0., 0., 0., 0., 0.],
    [9.0 / 200.0, -9.0 / 100.0, 9.0 / 100.0, 0., 0., 0., 0., 0., 0.],
    [-66701.0 / 197352.0, 28325.0 / 32892.0, -2665.0 / 5482.0, 2170.0 / 24669.0, 0., 0., 0., 0., 0.],
    [227015747.0 / 304251000.0, -54897451.0 / 30425100.0, 12942349.0 / 10141700.0, -9499.0 / 304251.0, 539.0 / 9250.0, 0., 0., 0., 0.],
    [
        -1131891597.0 / 901789000.0, 41964921.0 / 12882700.0, -6663147.0 / 3220675.0, 270954.0 / 644135.0, -108.0 / 5875.0, 114.0 / 1645.0, 0.,
        0., 0.,
    ],
    [
        13836959.0 / 3667458.0, -17731450.0 / 1833729.0, 1063919505.0 / 156478208.0, -33213845.0 / 39119552.0, 13335.0 / 28544.0,
        -705.0 / 14272.0, 1645.0 / 57088.0, 0., 0.,
    ],
    [223.0 / 7938.0, 0.0, 1175.0 / 8064.0, 925.0 / 6048.0, 41.0 / 448.0, 925.0 / 14112.0, 1175.0 / 72576.0, 0.0, 0.],
];

/// Position weights of the eighth-order solution (equal to the last row of A: FSAL).
pub const B: [f64; STAGES] = [223.0 / 7938.0, 0.0, 1175.0 / 8064.0, 925.0 / 6048.0, 41.0 / 448.0, 925.0 / 14112.0, 1175.0 / 72576.0, 0.0, 0.0];

/// Velocity weights of the eighth-order solution.
pub const BP: [f64; STAGES] =
    [223.0 / 7938.0, 0.0, 5875.0 / 36288.0, 4625.0 / 21168.0, 41.0 / 224.0, 4625.0 / 21168.0, 5875.0 / 36288.0, 223.0 / 7938.0, 0.0];

/// Position weights of the eighth-order solution minus those of the sixth-order one.
pub const BT: [f64; STAGES] = [
    223.0 / 7938.0 - 7987313.0 / 109941300.0,
    0.0,
    1175.0 / 8064.0 - 1610737.0 / 44674560.0,
    925.0 / 6048.0 - 10023263.0 / 33505920.0,
    41.0 / 448.0 + 497221.0 / 12409600.0,
    925.0 / 14112.0 - 10023263.0 / 78180480.0,
    1175.0 / 72576.0 - 1610737.0 / 402071040.0,
    0.0,
    0.0,
];

/// Velocity weights of the eighth-order solution minus those of the sixth-order one.
pub const BPT: [f64; STAGES] = [
    223.0 / 7938.0 - 7987313.0 / 109941300.0,
    0.0,
    5875.0 / 36288.0 - 1610737.0 / 40207104.0,
    4625.0 / 21168.0 - 10023263.0 / 23454144.0,
    41.0 / 224.0 + 497221.0 / 6204800.0,
    4625.0 / 21168.0 - 10023263.0 / 23454144.0,
    5875.0 / 36288.0 - 1610737.0 / 40207104.0,
    223.0 / 7938.0 + 4251941.0 / 54970650.0,
    -3.0 / 20.0,
];

/// Order of the propagated solution and of the embedded one.
pub const ORDER: u32 = 8;
pub const ERROR_ORDER: u32 = 6;

#[cfg(test)]
mod tests {
    use super::*;

    fn powi(c: f64, k: usize) -> f64 {
        c.powi(k as i32)
    }

    /// The Nyström order conditions that involve each weight vector alone (quadrature
    /// conditions): sum BP_i c_i^k = 1/(k+1) for k <= 7 and sum B_i c_i^k = 1/((k+1)(k+2)) for
    /// k <= 6 (eighth order), the embedded weights to sixth order (k <= 5 and k <= 4), and the
    /// row sums sum_j A_ij = c_i^2 / 2: a mistyped coefficient breaks one of them (1e-14).
    #[test]
    fn val_rkn86_order_conditions() {
        for i in 0..STAGES {
            let s: f64 = A[i].iter().sum();
            assert!((s - C[i] * C[i] / 2.0).abs() < 1e-14, "row {i}: {s}");
        }
        let dot = |w: &[f64; STAGES], k: usize| (0..STAGES).map(|i| w[i] * powi(C[i], k)).sum::<f64>();
        let hat = |w: &[f64; STAGES], t: &[f64; STAGES]| -> [f64; STAGES] { std::array::from_fn(|i| w[i] - t[i]) };
        for k in 0..=7 {
            assert!((dot(&BP, k) - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "BP, k = {k}");
        }
        for k in 0..=6 {
            assert!((dot(&B, k) - 1.0 / ((k as f64 + 1.0) * (k as f64 + 2.0))).abs() < 1e-14, "B, k = {k}");
        }
        let (bh, bph) = (hat(&B, &BT), hat(&BP, &BPT));
        for k in 0..=5 {
            assert!((dot(&bph, k) - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "BP hat, k = {k}");
        }
        for k in 0..=4 {
            assert!((dot(&bh, k) - 1.0 / ((k as f64 + 1.0) * (k as f64 + 2.0))).abs() < 1e-14, "B hat, k = {k}");
        }
        // two conditions of the coupling (trees with f_y): sum BP_i A_ij c_j = 1/24 and
        // sum B_i A_ij = 1/24, with their higher-moment companions sum BP_i c_i A_ij c_j = 1/30
        let ac = |i: usize, k: usize| (0..STAGES).map(|j| A[i][j] * powi(C[j], k)).sum::<f64>();
        let tree = |w: &[f64; STAGES], m: usize, k: usize| (0..STAGES).map(|i| w[i] * powi(C[i], m) * ac(i, k)).sum::<f64>();
        assert!((tree(&BP, 0, 1) - 1.0 / 24.0).abs() < 1e-14);
        assert!((tree(&B, 0, 0) - 1.0 / 24.0).abs() < 1e-14);
        assert!((tree(&BP, 1, 1) - 1.0 / 30.0).abs() < 1e-14);
        // the embedded pair is really of lower order: the eighth-order velocity condition fails
        assert!((dot(&bph, 7) - 1.0 / 8.0).abs() > 1e-6);
        // first same as last: the last stage sits at the new position
        assert_eq!(A[STAGES - 1], B);
        assert_eq!(C[STAGES - 1], 1.0);
    }
}
