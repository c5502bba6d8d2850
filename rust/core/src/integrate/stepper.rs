//! One RKF7(8) step with preallocated stage storage.

use super::tableau::{A, B8, C, ERR};
use super::{fmadd, State, System};

/// Stage storage and single-step logic of the RKF7(8) pair. Built once per integration from a
/// template state (its dimension); stepping never allocates.
pub struct Rkf78<S: State> {
    k: [S; 13],
    ytmp: S,
}

/// out_i = y_i + h * sum_m coef_m * ks_m[i]; M is a compile-time constant so the inner sum is
/// unrolled, and the sums use fused multiply-adds where the target has them.
#[inline(always)]
fn lincomb<const M: usize>(out: &mut [f64], y: &[f64], h: f64, coef: [f64; M], ks: [&[f64]; M]) {
    let n = out.len();
    let y = &y[..n];
    let ks = ks.map(|k| &k[..n]);
    for i in 0..n {
        let mut acc = 0.0;
        for m in 0..M {
            acc = fmadd(coef[m], ks[m][i], acc);
        }
        out[i] = fmadd(h, acc, y[i]);
    }
}

macro_rules! stage {
    ($self:ident, $sys:ident, $t:ident, $y:ident, $h:ident, $s:literal; $($j:literal),+) => {{
        lincomb(
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
    pub fn new(template: &S) -> Self {
        Self { k: std::array::from_fn(|_| template.clone()), ytmp: template.clone() }
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
        stage!(self, sys, t, y, h, 1; 0);
        stage!(self, sys, t, y, h, 2; 0, 1);
        stage!(self, sys, t, y, h, 3; 0, 2);
        stage!(self, sys, t, y, h, 4; 0, 2, 3);
        stage!(self, sys, t, y, h, 5; 0, 3, 4);
        stage!(self, sys, t, y, h, 6; 0, 3, 4, 5);
        stage!(self, sys, t, y, h, 7; 0, 4, 5, 6);
        stage!(self, sys, t, y, h, 8; 0, 3, 4, 5, 6, 7);
        stage!(self, sys, t, y, h, 9; 0, 3, 4, 5, 6, 7, 8);
        stage!(self, sys, t, y, h, 10; 0, 3, 4, 5, 6, 7, 8, 9);
        stage!(self, sys, t, y, h, 11; 0, 5, 6, 7, 8, 9);
        stage!(self, sys, t, y, h, 12; 0, 3, 4, 5, 6, 7, 8, 9, 11);
        let k = &self.k;
        lincomb(
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
            let sc = fmadd(rtol, y0[i].abs().max(y8[i].abs()), atol);
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
