//! One RKF7(8) step with preallocated stage storage.

use super::tableau::{rkf78_stages, A, B8, C, ERR};
use super::{State, System};
use crate::simd::{Isa, Kernel, Level};

/// Stage storage and single-step logic of the RKF7(8) pair. Built once per integration from a
/// template state (its dimension); stepping never allocates. Each step runs at the SIMD level
/// given at construction ([`crate::simd`]): fused multiply-adds in the stage sums on the FMA
/// levels, the level's instructions for the step and what it inlines.
pub struct Rkf78<S: State> {
    k: [S; 13],
    ytmp: S,
    level: Level,
}

/// out_i = y_i + h * sum_m coef_m * ks_m[i]; M is a compile-time constant so the inner sum is
/// unrolled, and the sums use fused multiply-adds on the FMA levels.
#[inline(always)]
fn lincomb<I: Isa, const M: usize>(out: &mut [f64], y: &[f64], h: f64, coef: [f64; M], ks: [&[f64]; M]) {
    let n = out.len();
    let y = &y[..n];
    // written out: `ks.map(..)`'s closure was compiled out of line, outside the dispatched
    // kernel's target features, and called once per stage
    let mut kn: [&[f64]; M] = [&[]; M];
    for m in 0..M {
        kn[m] = &ks[m][..n];
    }
    let ks = kn;
    for i in 0..n {
        let mut acc = 0.0;
        for m in 0..M {
            acc = I::mul_add(coef[m], ks[m][i], acc);
        }
        out[i] = I::mul_add(h, acc, y[i]);
    }
}

macro_rules! stage {
    ($self:ident, $sys:ident, $t:ident, $y:ident, $h:ident, $s:literal; $($j:literal),+) => {{
        lincomb::<I, _>(
            $self.ytmp.as_mut_slice(),
            $y.as_slice(),
            $h,
            [$(A[$s][$j]),+],
            [$($self.k[$j].as_slice()),+],
        );
        $sys.derivative($t + C[$s] * $h, &$self.ytmp, &mut $self.k[$s]);
    }};
}

impl<S: State> Rkf78<S> {
    /// Stage storage shaped like `template`, stepping at the SIMD `level` (one the CPU has:
    /// from [`crate::simd::active`]).
    pub fn new(template: &S, level: Level) -> Self {
        Self { k: std::array::from_fn(|_| template.clone()), ytmp: template.clone(), level }
    }

    /// f(t, y) into the first stage; must be called before [`Self::step`] whenever (t, y) changes.
    #[inline]
    pub fn prime<Sys: System<S>>(&mut self, sys: &Sys, t: f64, y: &S) {
        sys.derivative(t, y, &mut self.k[0]);
    }

    /// The derivative at the primed point.
    pub fn derivative_at_start(&self) -> &S {
        &self.k[0]
    }

    /// One step of size `h` from (t, y), whose derivative must be primed. Writes the 8th-order
    /// solution into `y_out` and returns the scaled max-norm of the error estimate,
    /// max_i |y7_i - y8_i| / (atol + rtol * max(|y_i|, |y8_i|)) (NaN if the step produced one).
    /// 12 right-hand-side evaluations.
    #[inline]
    pub fn step<Sys: System<S>>(&mut self, sys: &Sys, t: f64, y: &S, h: f64, y_out: &mut S, rtol: f64, atol: f64) -> f64 {
        struct Step<'a, S: State, Sys> {
            st: &'a mut Rkf78<S>,
            sys: &'a Sys,
            t: f64,
            y: &'a S,
            h: f64,
            y_out: &'a mut S,
            rtol: f64,
            atol: f64,
        }
        impl<S: State, Sys: System<S>> Kernel for Step<'_, S, Sys> {
            type Output = f64;
            #[inline(always)]
            fn run<I: Isa>(self, _isa: I) -> f64 {
                self.st.step_at::<I, Sys>(self.sys, self.t, self.y, self.h, self.y_out, self.rtol, self.atol)
            }
        }
        // The level was checked when the stepper was built; a NaN error would reject the step.
        crate::simd::run_at(self.level, Step { st: self, sys, t, y, h, y_out, rtol, atol }).unwrap_or(f64::NAN)
    }

    #[inline(always)]
    fn step_at<I: Isa, Sys: System<S>>(&mut self, sys: &Sys, t: f64, y: &S, h: f64, y_out: &mut S, rtol: f64, atol: f64) -> f64 {
        rkf78_stages!(stage!(self, sys, t, y, h));
        let k = &self.k;
        lincomb::<I, _>(
            y_out.as_mut_slice(),
            y.as_slice(),
            h,
            [B8[5], B8[6], B8[7], B8[8], B8[9], B8[11], B8[12]],
            [k[5].as_slice(), k[6].as_slice(), k[7].as_slice(), k[8].as_slice(), k[9].as_slice(), k[11].as_slice(), k[12].as_slice()],
        );
        let (y0, y8) = (y.as_slice(), y_out.as_slice());
        let n = y8.len();
        let (k0, k10, k11, k12) = (&k[0].as_slice()[..n], &k[10].as_slice()[..n], &k[11].as_slice()[..n], &k[12].as_slice()[..n]);
        let hs = h * ERR;
        let mut err = 0.0f64;
        for i in 0..n {
            let e = hs * ((k0[i] + k10[i]) - (k11[i] + k12[i]));
            let sc = I::mul_add(rtol, y0[i].abs().max(y8[i].abs()), atol);
            let r = e.abs() / sc;
            // `max` would drop a NaN: propagate it so the controller rejects the step.
            if !(r <= err) {
                err = r;
            }
        }
        err
    }

    /// Starting step size (Hairer, Norsett & Wanner, Solving ODE I, II.4): two extra
    /// evaluations. Requires the derivative to be primed; `direction` is +1 or -1.
    pub fn initial_step<Sys: System<S>>(&mut self, sys: &Sys, t: f64, y: &S, direction: f64, rtol: f64, atol: f64, h_max: f64) -> f64 {
        let order = super::tableau::ORDER as f64;
        let y0 = y.as_slice();
        let f0 = self.k[0].as_slice();
        let n = y0.len().max(1) as f64;
        let (mut d0, mut d1) = (0.0, 0.0);
        for i in 0..y0.len() {
            let sc = atol + rtol * y0[i].abs();
            d0 += (y0[i] / sc).powi(2);
            d1 += (f0[i] / sc).powi(2);
        }
        let (d0, d1) = ((d0 / n).sqrt(), (d1 / n).sqrt());
        let mut h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
        h0 = h0.min(h_max);
        {
            let (head, tail) = self.k.split_at_mut(1);
            let f0 = head[0].as_slice();
            let y1 = tail[0].as_mut_slice();
            for i in 0..y0.len() {
                y1[i] = y0[i] + direction * h0 * f0[i];
            }
            let (y1s, f1s) = tail.split_at_mut(1);
            sys.derivative(t + direction * h0, &y1s[0], &mut f1s[0]);
        }
        let f1 = self.k[2].as_slice();
        let f0 = self.k[0].as_slice();
        let mut d2 = 0.0;
        for i in 0..y0.len() {
            let sc = atol + rtol * y0[i].abs();
            d2 += ((f1[i] - f0[i]) / sc).powi(2);
        }
        let d2 = (d2 / n).sqrt() / h0;
        let h1 = if d1.max(d2) <= 1e-15 { (h0 * 1e-3).max(1e-6) } else { (0.01 / d1.max(d2)).powf(1.0 / (order + 1.0)) };
        let h = (100.0 * h0).min(h1).min(h_max);
        if h.is_finite() && h > 0.0 { h * direction } else { 1e-6 * direction }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two-body problem y'' = -y / |y|^3 (unit circular orbit: y(t) = (cos t, sin t)).
    struct Kepler;
    impl System<[f64; 4]> for Kepler {
        fn derivative(&self, _t: f64, y: &[f64; 4], dy: &mut [f64; 4]) {
            let r3 = (y[0] * y[0] + y[1] * y[1]).powf(1.5);
            *dy = [y[2], y[3], -y[0] / r3, -y[1] / r3];
        }
    }

    /// 2000 fixed steps of 0.01 around the circular orbit at every SIMD level the CPU has: each
    /// within 1e-12 of the analytic position (RKF7(8) truncation error ~ h^8 per step); the FMA
    /// levels bit-identical, the baseline within 1e-13 of them (rounding only).
    #[test]
    fn steps_at_every_level() {
        let run = |level: Level| {
            let mut y = [1.0, 0.0, 0.0, 1.0];
            let mut st = Rkf78::new(&y, level);
            let mut out = y;
            let h = 0.01;
            for k in 0..2000 {
                st.prime(&Kepler, k as f64 * h, &y);
                let err = st.step(&Kepler, k as f64 * h, &y, h, &mut out, 1e-12, 1e-12);
                assert!(err.is_finite() && err < 1.0, "{level}: step {k} error {err}");
                y = out;
            }
            y
        };
        let levels = crate::simd::available();
        let results: Vec<[f64; 4]> = levels.iter().map(|&l| run(l)).collect();
        let (s, c) = 20.0f64.sin_cos();
        let fma = levels.iter().position(|&l| l != Level::Baseline);
        for (l, y) in levels.iter().zip(&results) {
            assert!((y[0] - c).abs() < 1e-12 && (y[1] - s).abs() < 1e-12, "{l}: {y:?}");
            if let Some(f) = fma {
                let d = (0..4).map(|i| (y[i] - results[f][i]).abs()).fold(0.0, f64::max);
                println!("{l} vs {}: {d:.1e}", levels[f]);
                if *l == Level::Baseline {
                    assert!(d < 1e-13, "{l}: {d:e}");
                } else {
                    assert_eq!(y, &results[f], "{l} vs {}", levels[f]);
                }
            }
        }
    }
}
