//! Step-size control: an elementary (integral) controller on the scaled error norm.

/// Decision on a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    pub accept: bool,
    /// Proposed size of the next step (or of the retry, on rejection), same sign as `h`.
    pub h_next: f64,
}

/// h_next = h * clamp(safety / err^(1/(q+1)), fac_min, fac_max), with q the order of the
/// error estimate (7 for RKF7(8)). A safety factor near 0.8 cut rejected steps about four-fold
/// against 0.9 on CR3BP orbits; growth is capped at 1 right after a rejection. The scalar
/// driver and the map engine's lanes both step with this controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    pub safety: f64,
    pub fac_min: f64,
    pub fac_max: f64,
    /// 1 / (q + 1).
    inv_order: f64,
    /// log2(q + 1) when q + 1 is a power of two: the root is then that many square roots
    /// (three for RKF7(8): cheaper than powf and within an ulp or two of it).
    sqrts: Option<u32>,
}

impl Controller {
    /// The RKF7(8) defaults (those of [`super::Options`], and the map lanes'): safety 0.8,
    /// growth in [0.2, 5].
    pub const RKF78: Controller = Controller::new(0.8, 0.2, 5.0, super::tableau::ERROR_ORDER);

    pub const fn new(safety: f64, fac_min: f64, fac_max: f64, error_order: u32) -> Self {
        let p = error_order + 1;
        let sqrts = if p.is_power_of_two() { Some(p.trailing_zeros()) } else { None };
        Self { safety, fac_min, fac_max, inv_order: 1.0 / p as f64, sqrts }
    }

    /// err^(1/(q+1)).
    #[inline(always)]
    fn root(&self, err: f64) -> f64 {
        match self.sqrts {
            Some(n) => {
                let mut r = err;
                for _ in 0..n {
                    r = r.sqrt();
                }
                r
            }
            None => err.powf(self.inv_order),
        }
    }

    /// Step-size factor after a rejected step (err > 1, or a non-finite step): shrink, never
    /// grow; fac_min for a non-finite error.
    #[inline(always)]
    pub fn factor_rejected(&self, err: f64) -> f64 {
        if err.is_finite() {
            (self.safety / self.root(err)).clamp(self.fac_min, 1.0)
        } else {
            self.fac_min
        }
    }

    /// Step-size factor after an accepted step (err <= 1); growth capped at 1 right after a
    /// rejection.
    #[inline(always)]
    pub fn factor_accepted(&self, err: f64, after_reject: bool) -> f64 {
        let fac_max = if after_reject { 1.0 } else { self.fac_max };
        if err == 0.0 {
            fac_max
        } else {
            (self.safety / self.root(err)).clamp(self.fac_min, fac_max)
        }
    }

    /// `err` is the scaled error norm (accept when <= 1); NaN counts as a failed step.
    #[inline]
    pub fn control(&self, h: f64, err: f64, after_reject: bool) -> StepControl {
        if !(err <= 1.0) {
            return StepControl { accept: false, h_next: h * self.factor_rejected(err) };
        }
        StepControl { accept: true, h_next: h * self.factor_accepted(err, after_reject) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_small_errors_and_rejects_large_ones() {
        let c = Controller::new(0.8, 0.2, 5.0, 7);
        let ok = c.control(0.1, 0.5, false);
        assert!(ok.accept);
        // 0.8 * 0.5^(-1/8) = 0.8724
        assert!((ok.h_next - 0.1 * 0.8 * 0.5f64.powf(-0.125)).abs() < 1e-15);
        let bad = c.control(0.1, 300.0, false);
        assert!(!bad.accept && bad.h_next < 0.1 && bad.h_next >= 0.02 - 1e-15);
        let nan = c.control(-0.1, f64::NAN, false);
        assert!(!nan.accept && (nan.h_next + 0.02).abs() < 1e-15);
        // no growth right after a rejection
        assert_eq!(c.control(0.1, 1e-30, true).h_next, 0.1);
        assert_eq!(c.control(0.1, 0.0, false).h_next, 0.5);
    }

    /// The square-root chain of RKF7(8) against powf: factors agree to 4 ulp (relative 1e-15)
    /// over errors from 1e-300 to 1e300; a non-power-of-two order uses powf.
    #[test]
    fn square_root_chain_matches_powf() {
        let c = Controller::RKF78;
        assert_eq!(c.sqrts, Some(3));
        for k in -300..=300 {
            let err = 1.37f64 * 10f64.powi(k);
            let want = 0.8 * err.powf(-0.125);
            let got = 0.8 / c.root(err);
            assert!((got - want).abs() <= 1e-15 * want, "err {err:e}: {got} vs {want}");
        }
        let c5 = Controller::new(0.9, 0.2, 5.0, 4);
        assert_eq!(c5.sqrts, None);
        assert_eq!(c5.root(3.0), 3f64.powf(0.2));
    }
}
