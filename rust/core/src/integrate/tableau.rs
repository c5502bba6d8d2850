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

/// Prince and Dormand's RK8(7)13M (P. J. Prince and J. R. Dormand, "High order embedded
/// Runge-Kutta formulae", J. Comput. Appl. Math. 7 (1981) 67-75, Table 2, the rational
/// approximations of the coefficients given there): 13 stages, the 8th-order solution `B8`
/// propagated, the 7th-order `B7` for the error estimate (`E` = B8 - B7). The same number of
/// evaluations per step as RKF7(8), with an error estimate of the propagated solution's own
/// accuracy class (Fehlberg's vanishes for quadratures and is pessimistic elsewhere).
pub mod dp87 {
    /// Nodes c_i.
    pub const C: [f64; 13] = [
        0.0, 1.0 / 18.0, 1.0 / 12.0, 1.0 / 8.0, 5.0 / 16.0, 3.0 / 8.0, 59.0 / 400.0, 93.0 / 200.0, 5490023248.0 / 9719169821.0, 13.0 / 20.0,
        1201146811.0 / 1299019798.0, 1.0, 1.0,
    ];

    /// Coupling coefficients a_ij (row i, j < i), zero-padded.
    #[rustfmt::skip]
    pub const A: [[f64; 12]; 13] = [
        [0.0; 12],
        [1.0 / 18.0, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
        [1.0 / 48.0, 1.0 / 16.0, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
        [1.0 / 32.0, 0.0, 3.0 / 32.0, 0., 0., 0., 0., 0., 0., 0., 0., 0.],
        [5.0 / 16.0, 0.0, -75.0 / 64.0, 75.0 / 64.0, 0., 0., 0., 0., 0., 0., 0., 0.],
        [3.0 / 80.0, 0.0, 0.0, 3.0 / 16.0, 3.0 / 20.0, 0., 0., 0., 0., 0., 0., 0.],
        [29443841.0 / 614563906.0, 0.0, 0.0, 77736538.0 / 692538347.0, -28693883.0 / 1125000000.0, 23124283.0 / 1800000000.0, 0., 0., 0., 0., 0., 0.],
        [16016141.0 / 946692911.0, 0.0, 0.0, 61564180.0 / 158732637.0, 22789713.0 / 633445777.0, 545815736.0 / 2771057229.0, -180193667.0 / 1043307555.0, 0., 0., 0., 0., 0.],
        [39632708.0 / 573591083.0, 0.0, 0.0, -433636366.0 / 683701615.0, -421739975.0 / 2616292301.0, 100302831.0 / 723423059.0, 790204164.0 / 839813087.0, 800635310.0 / 3783071287.0, 0., 0., 0., 0.],
        [246121993.0 / 1340847787.0, 0.0, 0.0, -37695042795.0 / 15268766246.0, -309121744.0 / 1061227803.0, -12992083.0 / 490766935.0, 6005943493.0 / 2108947869.0, 393006217.0 / 1396673457.0, 123872331.0 / 1001029789.0, 0., 0., 0.],
        [-1028468189.0 / 846180014.0, 0.0, 0.0, 8478235783.0 / 508512852.0, 1311729495.0 / 1432422823.0, -10304129995.0 / 1701304382.0, -48777925059.0 / 3047939560.0, 15336726248.0 / 1032824649.0, -45442868181.0 / 3398467696.0, 3065993473.0 / 597172653.0, 0., 0.],
        [185892177.0 / 718116043.0, 0.0, 0.0, -3185094517.0 / 667107341.0, -477755414.0 / 1098053517.0, -703635378.0 / 230739211.0, 5731566787.0 / 1027545527.0, 5232866602.0 / 850066563.0, -4093664535.0 / 808688257.0, 3962137247.0 / 1805957418.0, 65686358.0 / 487910083.0, 0.],
        [403863854.0 / 491063109.0, 0.0, 0.0, -5068492393.0 / 434740067.0, -411421997.0 / 543043805.0, 652783627.0 / 914296604.0, 11173962825.0 / 925320556.0, -13158990841.0 / 6184727034.0, 3936647629.0 / 1978049680.0, -160528059.0 / 685178525.0, 248638103.0 / 1413531060.0, 0.0],
    ];

    /// Weights of the 8th-order solution (the one propagated).
    #[rustfmt::skip]
    pub const B8: [f64; 13] = [
        14005451.0 / 335480064.0, 0., 0., 0., 0., -59238493.0 / 1068277825.0, 181606767.0 / 758867731.0, 561292985.0 / 797845732.0,
        -1041891430.0 / 1371343529.0, 760417239.0 / 1151165299.0, 118820643.0 / 751138087.0, -528747749.0 / 2220607170.0, 1.0 / 4.0,
    ];

    /// Weights of the embedded 7th-order solution.
    #[rustfmt::skip]
    pub const B7: [f64; 13] = [
        13451932.0 / 455176623.0, 0., 0., 0., 0., -808719846.0 / 976000145.0, 1757004468.0 / 5645159321.0, 656045339.0 / 265891186.0,
        -3867574721.0 / 1518517206.0, 465885868.0 / 322736535.0, 53011238.0 / 667516719.0, 2.0 / 45.0, 0.0,
    ];

    /// Error weights: y8 - y7 = h sum_i E_i k_i.
    pub const E: [f64; 13] = {
        let mut e = [0.0; 13];
        let mut i = 0;
        while i < 13 {
            e[i] = B8[i] - B7[i];
            i += 1;
        }
        e
    };

    /// Order of the propagated solution and of the embedded one.
    pub const ORDER: u32 = 8;
    pub const ERROR_ORDER: u32 = 7;

    /// The stages 1..=12 of an RK8(7)13M step with the non-zero columns of their rows (as
    /// [`super::rkf78_stages`]).
    macro_rules! dp87_stages {
        ($stage:ident!($($a:tt)*)) => {
            $stage!($($a)*, 1; 0);
            $stage!($($a)*, 2; 0, 1);
            $stage!($($a)*, 3; 0, 2);
            $stage!($($a)*, 4; 0, 2, 3);
            $stage!($($a)*, 5; 0, 3, 4);
            $stage!($($a)*, 6; 0, 3, 4, 5);
            $stage!($($a)*, 7; 0, 3, 4, 5, 6);
            $stage!($($a)*, 8; 0, 3, 4, 5, 6, 7);
            $stage!($($a)*, 9; 0, 3, 4, 5, 6, 7, 8);
            $stage!($($a)*, 10; 0, 3, 4, 5, 6, 7, 8, 9);
            $stage!($($a)*, 11; 0, 3, 4, 5, 6, 7, 8, 9, 10);
            $stage!($($a)*, 12; 0, 3, 4, 5, 6, 7, 8, 9, 10);
        };
    }
    pub(crate) use dp87_stages;
}

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

    /// RK8(7)13M: `dp87_stages!` lists exactly A's non-zero entries.
    #[test]
    fn dp87_stage_columns_are_the_nonzero_entries_of_a() {
        let mut got = vec![Vec::new(); 13];
        macro_rules! record {
            ($v:ident, $s:literal; $($j:literal),+) => {
                $v[$s] = vec![$($j),+];
            };
        }
        dp87::dp87_stages!(record!(got));
        for (s, cols) in got.iter().enumerate().skip(1) {
            let nonzero: Vec<usize> = (0..12).filter(|&j| dp87::A[s][j] != 0.0).collect();
            assert_eq!(cols, &nonzero, "stage {s}");
        }
    }

    /// RK8(7)13M order conditions (Prince & Dormand 1981; Butcher's conditions for order 8 and
    /// 7), at the accuracy of the paper's rational coefficients (about 1e-18 each, so 1e-14 on the
    /// sums): row sums are the nodes (a_ij sum to c_i); sum b = 1 and b.c^k = 1/(k+1) for
    /// k = 0..=7 with the 8th-order weights (k = 0..=6 with the 7th-order ones, which fail k = 7:
    /// a genuinely lower-order pair), and the simplifying conditions the pair is built on:
    /// sum_j a_ij c_j = c_i^2 / 2 for i >= 2 (stage order 2), and b8.(A c^k) = 1/((k+1)(k+2))
    /// for k = 0..=6.
    #[test]
    fn dp87_order_conditions() {
        use dp87::*;
        for i in 0..13 {
            let s: f64 = A[i].iter().sum();
            assert!((s - C[i]).abs() < 1e-14, "row {i}: sum {s} vs c {}", C[i]);
        }
        for k in 0..=7 {
            let s8: f64 = (0..13).map(|i| B8[i] * C[i].powi(k)).sum();
            assert!((s8 - 1.0 / (k + 1) as f64).abs() < 1e-14, "B8, k = {k}: {s8}");
            let s7: f64 = (0..13).map(|i| B7[i] * C[i].powi(k)).sum();
            if k <= 6 {
                assert!((s7 - 1.0 / (k + 1) as f64).abs() < 1e-14, "B7, k = {k}: {s7}");
            } else {
                assert!((s7 - 1.0 / 8.0).abs() > 1e-8, "B7 must not be of order 8: {s7}");
            }
        }
        for i in 2..13 {
            let s: f64 = (0..i).map(|j| A[i][j] * C[j]).sum();
            assert!((s - C[i] * C[i] / 2.0).abs() < 1e-13, "stage {i}: {s}");
        }
        for k in 0..=6 {
            let s: f64 = (0..13).map(|i| B8[i] * (0..i).map(|j| A[i][j] * C[j].powi(k)).sum::<f64>()).sum();
            assert!((s - 1.0 / ((k + 1) * (k + 2)) as f64).abs() < 1e-14, "b.A c^{k}: {s}");
        }
        for i in 0..13 {
            assert!((E[i] - (B8[i] - B7[i])).abs() == 0.0);
        }
    }

    /// One RK8(7)13M step is exact (to rounding) on y' = p(t) for a polynomial p of degree 7 (the
    /// solution of degree 8) and on the linear system y' = J y to the Taylor terms up to h^8; its
    /// local error scales as h^9 (halving h divides it by more than 400, 2^9 = 512 nominal; a
    /// mistyped coupling coefficient drops the order and the ratio).
    #[test]
    fn dp87_steps_have_order_8() {
        use dp87::*;
        let step = |f: &dyn Fn(f64, f64) -> f64, y0: f64, h: f64| {
            let mut k = [0.0; 13];
            for s in 0..13 {
                let y = y0 + h * (0..s).map(|j| A[s][j] * k[j]).sum::<f64>();
                k[s] = f(C[s] * h, y);
            }
            y0 + h * (0..13).map(|i| B8[i] * k[i]).sum::<f64>()
        };
        // y' = sum_k (k+1) t^k, k = 0..=7: y(h) = sum h^(k+1)
        let p = |t: f64, _y: f64| (0..=7).map(|k| (k + 1) as f64 * t.powi(k)).sum::<f64>();
        for h in [0.3f64, 0.7, 1.0] {
            let want: f64 = (1..=8).map(|k| h.powi(k)).sum();
            assert!((step(&p, 0.0, h) - want).abs() < 1e-14 * want.max(1.0), "h {h}");
        }
        // y' = cos(t) y, y(0) = 1: y = exp(sin t) (non-autonomous, so more than the stability
        // polynomial is tested); local errors 3.2e-7, 4.4e-10, 5.4e-13 at h = 0.8, 0.4, 0.2
        let f = |t: f64, y: f64| t.cos() * y;
        let err = |h: f64| (step(&f, 1.0, h) - h.sin().exp()).abs();
        for h in [0.8f64, 0.4] {
            let ratio = err(h) / err(h / 2.0);
            assert!(ratio > 400.0, "h {h}: error ratio {ratio} (order 8: local error ~ h^9, ratio ~ 512 or more)");
        }
    }
}
