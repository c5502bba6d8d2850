//! Truncated Fourier series of a periodic orbit (thesis eq. 44-45, docs/physics.md, periodic orbits).
//!
//! For a periodic orbit of period T and fundamental frequency w = 2 pi / T, each coordinate
//! q in (x, y, z) is
//!
//! ```text
//! q(t)   = a0_q + sum_{n=1..N} [ a_{n,q} cos(n w t) + c_{n,q} sin(n w t) ]
//! q'(t)  =        sum_{n=1..N} n w   [ -a_{n,q} sin(n w t) + c_{n,q} cos(n w t) ]
//! q''(t) =       -sum_{n=1..N} (n w)^2 [ a_{n,q} cos(n w t) + c_{n,q} sin(n w t) ]
//! ```
//!
//! (the general form; an x-axis-symmetric planar orbit started on the x axis, such as a DRO,
//! has only cosines in x and only sines in y). The derivatives are the exact derivatives of the
//! series. Evaluation at one time allocates nothing: cos(n w t), sin(n w t) come from the
//! angle-addition recurrence seeded by one `sin_cos`, on the phase reduced to [0, T) so that
//! large times do not lose accuracy.
//!
//! The coefficients come from a fit elsewhere (the Python `librate.fit_fourier` does a
//! least-squares fit on dense samples of the integrated orbit).

use rayon::prelude::*;

use crate::error::{check_finite, invalid, Result};

/// What to evaluate at each time; the number of output columns is [`Quantity::width`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// (x, y, z): 3 columns.
    Position,
    /// (xd, yd, zd): 3 columns.
    Velocity,
    /// (xdd, ydd, zdd): 3 columns.
    Acceleration,
    /// (x, y, z, xd, yd, zd): 6 columns.
    State,
    /// position, velocity, acceleration: 9 columns.
    All,
}

impl Quantity {
    /// Number of values per time.
    pub fn width(self) -> usize {
        match self {
            Quantity::Position | Quantity::Velocity | Quantity::Acceleration => 3,
            Quantity::State => 6,
            Quantity::All => 9,
        }
    }

    /// Parse "position", "velocity", "acceleration", "state" or "all".
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "position" => Ok(Quantity::Position),
            "velocity" => Ok(Quantity::Velocity),
            "acceleration" => Ok(Quantity::Acceleration),
            "state" => Ok(Quantity::State),
            "all" => Ok(Quantity::All),
            _ => Err(invalid("quantity", format!("must be one of position, velocity, acceleration, state, all; got {name:?}"))),
        }
    }
}

/// Position, velocity and acceleration from the series at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    pub position: [f64; 3],
    pub velocity: [f64; 3],
    pub acceleration: [f64; 3],
}

/// A periodic orbit as a truncated Fourier series in time (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct FourierOrbit {
    period: f64,
    omega: f64,
    a0: [f64; 3],
    /// a_n for n = 1..=N, each (x, y, z).
    cos: Vec<[f64; 3]>,
    /// c_n for n = 1..=N, each (x, y, z).
    sin: Vec<[f64; 3]>,
}

impl FourierOrbit {
    /// A series of period `period` (> 0) with mean `a0`, cosine coefficients `cos[n - 1]` and
    /// sine coefficients `sin[n - 1]` of harmonic n = 1..=N (both of length N, N >= 0).
    pub fn new(period: f64, a0: [f64; 3], cos: Vec<[f64; 3]>, sin: Vec<[f64; 3]>) -> Result<Self> {
        if !(period.is_finite() && period > 0.0) {
            return Err(invalid("period", format!("must be a finite number > 0, got {period}")));
        }
        if cos.len() != sin.len() {
            return Err(invalid("sin", format!("must have as many harmonics as `cos` ({}), got {}", cos.len(), sin.len())));
        }
        check_finite("a0", &a0)?;
        check_finite("cos", cos.as_flattened())?;
        check_finite("sin", sin.as_flattened())?;
        Ok(Self { period, omega: std::f64::consts::TAU / period, a0, cos, sin })
    }

    /// Build from row-major (N, 3) coefficient slices.
    pub fn from_flat(period: f64, a0: [f64; 3], cos: &[f64], sin: &[f64]) -> Result<Self> {
        for (name, c) in [("cos", cos), ("sin", sin)] {
            if c.len() % 3 != 0 {
                return Err(invalid(name, format!("must hold N rows of (x, y, z), got {} values", c.len())));
            }
        }
        let rows = |c: &[f64]| c.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect::<Vec<_>>();
        Self::new(period, a0, rows(cos), rows(sin))
    }

    pub fn period(&self) -> f64 {
        self.period
    }
    /// Number of harmonics N.
    pub fn n_harmonics(&self) -> usize {
        self.cos.len()
    }
    pub fn a0(&self) -> [f64; 3] {
        self.a0
    }
    /// Cosine coefficients a_n, n = 1..=N.
    pub fn cos_coefficients(&self) -> &[[f64; 3]] {
        &self.cos
    }
    /// Sine coefficients c_n, n = 1..=N.
    pub fn sin_coefficients(&self) -> &[[f64; 3]] {
        &self.sin
    }

    /// Phase w * (t mod T) in [0, 2 pi).
    #[inline(always)]
    fn phase(&self, t: f64) -> f64 {
        self.omega * t.rem_euclid(self.period)
    }

    /// Sum over harmonics with weights: out_k = sum_n f(n, cos(n w t), sin(n w t)) per coordinate.
    /// `deriv` 0, 1, 2 selects the series, its first or its second derivative.
    #[inline(always)]
    fn sum(&self, t: f64, deriv: u8) -> [f64; 3] {
        let (s1, c1) = self.phase(t).sin_cos();
        let (mut cn, mut sn) = (c1, s1);
        let mut out = if deriv == 0 { self.a0 } else { [0.0; 3] };
        for (n, (a, c)) in self.cos.iter().zip(&self.sin).enumerate() {
            let k = (n + 1) as f64 * self.omega;
            for q in 0..3 {
                out[q] += match deriv {
                    0 => a[q] * cn + c[q] * sn,
                    1 => k * (c[q] * cn - a[q] * sn),
                    _ => -k * k * (a[q] * cn + c[q] * sn),
                };
            }
            // cos((n+1)x), sin((n+1)x) by angle addition.
            (cn, sn) = (cn * c1 - sn * s1, sn * c1 + cn * s1);
        }
        out
    }

    /// Position (x, y, z) at time t.
    pub fn position(&self, t: f64) -> [f64; 3] {
        self.sum(t, 0)
    }

    /// Velocity: the exact time derivative of the series.
    pub fn velocity(&self, t: f64) -> [f64; 3] {
        self.sum(t, 1)
    }

    /// Acceleration: the exact second time derivative of the series.
    pub fn acceleration(&self, t: f64) -> [f64; 3] {
        self.sum(t, 2)
    }

    /// State (x, y, z, xd, yd, zd) at time t.
    pub fn state(&self, t: f64) -> [f64; 6] {
        let e = self.evaluate(t);
        [e.position[0], e.position[1], e.position[2], e.velocity[0], e.velocity[1], e.velocity[2]]
    }

    /// Position, velocity and acceleration in one sweep over the harmonics.
    pub fn evaluate(&self, t: f64) -> Evaluation {
        let (s1, c1) = self.phase(t).sin_cos();
        let (mut cn, mut sn) = (c1, s1);
        let mut p = self.a0;
        let mut v = [0.0; 3];
        let mut acc = [0.0; 3];
        for (n, (a, c)) in self.cos.iter().zip(&self.sin).enumerate() {
            let k = (n + 1) as f64 * self.omega;
            for q in 0..3 {
                let even = a[q] * cn + c[q] * sn;
                p[q] += even;
                v[q] += k * (c[q] * cn - a[q] * sn);
                acc[q] -= k * k * even;
            }
            (cn, sn) = (cn * c1 - sn * s1, sn * c1 + cn * s1);
        }
        Evaluation { position: p, velocity: v, acceleration: acc }
    }

    /// Write `quantity` at one time into `out` (length `quantity.width()`).
    #[inline]
    fn write(&self, t: f64, quantity: Quantity, out: &mut [f64]) {
        match quantity {
            Quantity::Position => out.copy_from_slice(&self.position(t)),
            Quantity::Velocity => out.copy_from_slice(&self.velocity(t)),
            Quantity::Acceleration => out.copy_from_slice(&self.acceleration(t)),
            Quantity::State => out.copy_from_slice(&self.state(t)),
            Quantity::All => {
                let e = self.evaluate(t);
                out[..3].copy_from_slice(&e.position);
                out[3..6].copy_from_slice(&e.velocity);
                out[6..].copy_from_slice(&e.acceleration);
            }
        }
    }

    /// Evaluate at many times into a row-major (len(ts), width) buffer, in parallel for long
    /// inputs. Each row is computed independently, so the result does not depend on the
    /// number of threads.
    pub fn evaluate_many_into(&self, ts: &[f64], quantity: Quantity, out: &mut [f64]) -> Result<()> {
        let w = quantity.width();
        if out.len() != ts.len() * w {
            return Err(invalid("out", format!("must have {} x {} = {} values, got {}", ts.len(), w, ts.len() * w, out.len())));
        }
        check_finite("t", ts)?;
        const PARALLEL_FROM: usize = 4096;
        if ts.len() >= PARALLEL_FROM {
            out.par_chunks_exact_mut(w).zip(ts.par_iter()).for_each(|(row, &t)| self.write(t, quantity, row));
        } else {
            out.chunks_exact_mut(w).zip(ts).for_each(|(row, &t)| self.write(t, quantity, row));
        }
        Ok(())
    }

    /// Evaluate at many times: a row-major (len(ts), width) vector.
    pub fn evaluate_many(&self, ts: &[f64], quantity: Quantity) -> Result<Vec<f64>> {
        let mut out = vec![0.0; ts.len() * quantity.width()];
        self.evaluate_many_into(ts, quantity, &mut out)?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A three-harmonic test series with every kind of term.
    fn sample() -> FourierOrbit {
        FourierOrbit::new(
            3.7,
            [0.3, -0.1, 0.05],
            vec![[0.8, 0.0, 0.01], [0.0, 0.02, -0.03], [-0.004, 0.001, 0.0]],
            vec![[0.0, -0.6, 0.02], [0.05, 0.0, 0.0], [0.002, -0.003, 0.007]],
        )
        .unwrap()
    }

    /// The series written out term by term with direct cos/sin calls and hand derivatives.
    fn direct(f: &FourierOrbit, t: f64) -> [[f64; 3]; 3] {
        let w = TAU / f.period();
        let mut out = [f.a0(), [0.0; 3], [0.0; 3]];
        for n in 1..=f.n_harmonics() {
            let (a, c) = (f.cos_coefficients()[n - 1], f.sin_coefficients()[n - 1]);
            let k = n as f64 * w;
            let (s, co) = (k * t).sin_cos();
            for q in 0..3 {
                out[0][q] += a[q] * co + c[q] * s;
                out[1][q] += -k * a[q] * s + k * c[q] * co;
                out[2][q] += -k * k * (a[q] * co + c[q] * s);
            }
        }
        out
    }

    /// Reference: the same series evaluated term by term (direct sin/cos of n w t, no
    /// recurrence, no phase reduction); tolerance 1e-13 absolute for |t| up to 20 periods.
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn matches_term_by_term_evaluation() {
        let f = sample();
        for i in -40..=200 {
            let t = 0.37 * i as f64;
            let e = f.evaluate(t);
            let d = direct(&f, t);
            for q in 0..3 {
                assert!((e.position[q] - d[0][q]).abs() < 1e-13, "x t={t}");
                assert!((e.velocity[q] - d[1][q]).abs() < 1e-13, "v t={t}");
                assert!((e.acceleration[q] - d[2][q]).abs() < 1e-12, "a t={t}");
            }
            assert_eq!(f.position(t), e.position);
            assert!((0..3).all(|q| (f.velocity(t)[q] - e.velocity[q]).abs() < 1e-15));
            assert!((0..3).all(|q| (f.acceleration(t)[q] - e.acceleration[q]).abs() < 1e-14));
        }
    }

    /// Velocity and acceleration against 4th-order central differences of the position and of
    /// the velocity, h = 1e-3 (truncation ~ h^4 |x^(5)| ~ 1e-10): tolerance 1e-8.
    #[test]
    fn derivatives_match_finite_differences() {
        let f = sample();
        let h = 1e-3;
        let cd = |g: &dyn Fn(f64) -> [f64; 3], t: f64, q: usize| {
            (-g(t + 2.0 * h)[q] + 8.0 * g(t + h)[q] - 8.0 * g(t - h)[q] + g(t - 2.0 * h)[q]) / (12.0 * h)
        };
        for i in 0..50 {
            let t = -2.0 + 0.31 * i as f64;
            for q in 0..3 {
                let v = cd(&|s| f.position(s), t, q);
                let a = cd(&|s| f.velocity(s), t, q);
                assert!((v - f.velocity(t)[q]).abs() < 1e-8, "v t={t} q={q}: {v} vs {}", f.velocity(t)[q]);
                assert!((a - f.acceleration(t)[q]).abs() < 1e-8, "a t={t} q={q}: {a} vs {}", f.acceleration(t)[q]);
            }
        }
    }

    /// Analytic: a circle of radius r at rate w = 2 pi / T, x = r cos wt, y = r sin wt, has speed
    /// r w and centripetal acceleration -w^2 (x, y), and z = 0. Tolerance 1e-14 relative.
    #[test]
    fn circle_has_centripetal_acceleration() {
        let (r, period) = (2.5, 5.0);
        let w = TAU / period;
        let f = FourierOrbit::new(period, [0.0; 3], vec![[r, 0.0, 0.0]], vec![[0.0, r, 0.0]]).unwrap();
        for i in 0..100 {
            let t = 0.173 * i as f64;
            let e = f.evaluate(t);
            let (x, y) = (r * (w * t).cos(), r * (w * t).sin());
            assert!((e.position[0] - x).abs() < 1e-14 * r && (e.position[1] - y).abs() < 1e-14 * r);
            let speed = (e.velocity[0].powi(2) + e.velocity[1].powi(2)).sqrt();
            assert!((speed - r * w).abs() < 1e-14 * r * w);
            assert!((e.acceleration[0] + w * w * e.position[0]).abs() < 1e-14 * r * w * w);
            assert!((e.acceleration[1] + w * w * e.position[1]).abs() < 1e-14 * r * w * w);
            assert_eq!([e.position[2], e.velocity[2], e.acceleration[2]], [0.0; 3]);
        }
    }

    /// The series is T-periodic (phase reduced modulo T): values at t and t + 7T agree to
    /// rounding of the reduced phase (1e-12).
    #[test]
    fn periodic_in_time() {
        let f = sample();
        for i in 0..30 {
            let t = 0.123 * i as f64;
            let (a, b) = (f.state(t), f.state(t + 7.0 * f.period()));
            assert!((0..6).all(|k| (a[k] - b[k]).abs() < 1e-12));
        }
    }

    /// Vectorised evaluation equals the single-time calls exactly, in serial and parallel
    /// (>= 4096 times) paths, for every quantity.
    #[test]
    fn evaluate_many_matches_single_calls() {
        let f = sample();
        for n in [7usize, 5000] {
            let ts: Vec<f64> = (0..n).map(|i| -1.0 + 0.0031 * i as f64).collect();
            for q in [Quantity::Position, Quantity::Velocity, Quantity::Acceleration, Quantity::State, Quantity::All] {
                let out = f.evaluate_many(&ts, q).unwrap();
                assert_eq!(out.len(), n * q.width());
                for (i, &t) in ts.iter().enumerate() {
                    let row = &out[i * q.width()..(i + 1) * q.width()];
                    let e = f.evaluate(t);
                    let expect: Vec<f64> = match q {
                        Quantity::Position => f.position(t).to_vec(),
                        Quantity::Velocity => f.velocity(t).to_vec(),
                        Quantity::Acceleration => f.acceleration(t).to_vec(),
                        Quantity::State => f.state(t).to_vec(),
                        Quantity::All => [e.position, e.velocity, e.acceleration].concat(),
                    };
                    assert_eq!(row, expect.as_slice());
                }
            }
        }
    }

    #[test]
    fn bad_arguments_name_the_parameter() {
        let msg = |r: Result<FourierOrbit>| r.unwrap_err().to_string();
        assert!(msg(FourierOrbit::new(0.0, [0.0; 3], vec![], vec![])).contains("`period`"));
        assert!(msg(FourierOrbit::new(f64::NAN, [0.0; 3], vec![], vec![])).contains("`period`"));
        assert!(msg(FourierOrbit::new(1.0, [0.0; 3], vec![[0.0; 3]], vec![])).contains("`sin`"));
        assert!(msg(FourierOrbit::new(1.0, [f64::INFINITY, 0.0, 0.0], vec![], vec![])).contains("`a0`"));
        assert!(msg(FourierOrbit::new(1.0, [0.0; 3], vec![[0.0, f64::NAN, 0.0]], vec![[0.0; 3]])).contains("`cos`"));
        assert!(msg(FourierOrbit::from_flat(1.0, [0.0; 3], &[0.0; 4], &[0.0; 3])).contains("`cos`"));
        let f = sample();
        assert!(f.evaluate_many(&[0.0, f64::NAN], Quantity::State).unwrap_err().to_string().contains("`t`"));
        let mut out = vec![0.0; 5];
        assert!(f.evaluate_many_into(&[0.0, 1.0], Quantity::Position, &mut out).unwrap_err().to_string().contains("`out`"));
        assert!(Quantity::parse("jerk").unwrap_err().to_string().contains("`quantity`"));
        // Zero harmonics: the constant a0.
        let c = FourierOrbit::new(2.0, [1.0, 2.0, 3.0], vec![], vec![]).unwrap();
        assert_eq!(c.evaluate(0.7), Evaluation { position: [1.0, 2.0, 3.0], velocity: [0.0; 3], acceleration: [0.0; 3] });
    }
}
