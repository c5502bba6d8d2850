//! Event functions: a scalar g(t, y) whose zero crossings are located during integration.

use super::State;

/// A scalar function of (t, y) whose sign changes are events.
pub trait EventFn<S>: Sync {
    fn value(&self, t: f64, y: &S) -> f64;
}

impl<S, F: Fn(f64, &S) -> f64 + Sync> EventFn<S> for F {
    fn value(&self, t: f64, y: &S) -> f64 {
        self(t, y)
    }
}

/// g = y[index] - value: crossing of a coordinate plane (e.g. y = 0 for symmetric orbits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComponentCrossing {
    pub index: usize,
    pub value: f64,
}

impl<S: State> EventFn<S> for ComponentCrossing {
    #[inline]
    fn value(&self, _t: f64, y: &S) -> f64 {
        y.as_slice()[self.index] - self.value
    }
}

/// An event to locate: which crossings count and whether the first one stops the integration.
pub struct Event<'a, S> {
    pub func: &'a dyn EventFn<S>,
    /// +1: only increasing crossings (g from < 0 to >= 0); -1: only decreasing; 0: both.
    pub direction: i8,
    /// Stop the integration at the first counted crossing.
    pub terminal: bool,
}

impl<'a, S> Event<'a, S> {
    pub fn new(func: &'a dyn EventFn<S>, direction: i8, terminal: bool) -> Self {
        Self { func, direction, terminal }
    }

    /// Whether going from g0 to g1 is a counted crossing. A start exactly on the surface
    /// (g0 = 0) is not a crossing, so an orbit started on its symmetry plane does not trigger.
    #[inline]
    pub(crate) fn crosses(&self, g0: f64, g1: f64) -> bool {
        let up = g0 < 0.0 && g1 >= 0.0;
        let down = g0 > 0.0 && g1 <= 0.0;
        match self.direction {
            1 => up,
            -1 => down,
            _ => up || down,
        }
    }
}

/// A located event.
#[derive(Debug, Clone, PartialEq)]
pub struct EventRecord<S> {
    /// Index of the event in the list given to the driver.
    pub index: usize,
    pub t: f64,
    pub y: S,
}

/// Brent's root finder on [a, b] with f(a), f(b) of opposite signs (or one zero), to an
/// absolute tolerance `xtol` on the abscissa. Returns the root and the evaluations used.
pub(crate) fn brent(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64, mut fa: f64, mut fb: f64, xtol: f64) -> (f64, usize) {
    if fa == 0.0 {
        return (a, 0);
    }
    if fb == 0.0 {
        return (b, 0);
    }
    let mut evals = 0;
    let (mut c, mut fc) = (b, fb);
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..200 {
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol1 = 2.0 * f64::EPSILON * b.abs() + 0.5 * xtol;
        let xm = 0.5 * (c - b);
        if xm.abs() <= tol1 || fb == 0.0 {
            return (b, evals);
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * xm * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * xm * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            }
            p = p.abs();
            let min1 = 3.0 * xm * q - (tol1 * q).abs();
            let min2 = (e * q).abs();
            if 2.0 * p < min1.min(min2) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol1 { d } else { tol1.copysign(xm) };
        fb = f(b);
        evals += 1;
    }
    (b, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_cos_root() {
        let (x, n) = brent(f64::cos, 1.0, 2.0, 1f64.cos(), 2f64.cos(), 1e-15);
        assert!((x - std::f64::consts::FRAC_PI_2).abs() < 1e-14, "{x}");
        assert!(n < 15);
    }

    #[test]
    fn crossing_rules() {
        let g = ComponentCrossing { index: 0, value: 0.0 };
        let up: Event<[f64; 1]> = Event::new(&g, 1, false);
        assert!(up.crosses(-1.0, 1.0) && !up.crosses(1.0, -1.0) && !up.crosses(0.0, 1.0));
        let both: Event<[f64; 1]> = Event::new(&g, 0, false);
        assert!(both.crosses(-1.0, 0.0) && both.crosses(1.0, -1.0));
    }
}
