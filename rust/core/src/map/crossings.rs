//! A map row's crossings: where the unwrapped final angle phi(KT) - phi0 passes a multiple of a
//! level (pi for a map: every periodic or half-turn motion has phi(KT) = phi0 + k pi), located
//! by linear interpolation between neighbouring rates; and the search window each crossing is
//! refined in.

/// One crossing of a row: phi(KT) - phi0 = `k` levels between the rates `interval` and
/// `interval + 1`, at `wz0` by linear interpolation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    pub k: i64,
    pub wz0: f64,
    pub interval: usize,
}

/// floor(x), exactly, without a libm call (the baseline x86-64 has no rounding instruction, and
/// `f64::floor` there is a call: 8 us of a 2000-rate row's 13).
#[inline]
fn floor(x: f64) -> f64 {
    if x.abs() < 4.5e15 {
        let t = x as i64 as f64; // truncated toward zero, exact below 2^52
        if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x.floor() // large, infinite or NaN
    }
}

/// ceil(x), exactly (but +0.0 for -1 < x < 0), without a libm call ([`floor`]).
#[inline]
fn ceil(x: f64) -> f64 {
    -floor(-x) + 0.0
}

/// A row in levels: u = (phi_t - phi0) / level, the input of [`crossings`], [`unresolved`] and
/// [`windows`].
pub fn levels(phi_t: &[f64], phi0: f64, level: f64) -> Vec<f64> {
    phi_t.iter().map(|p| (p - phi0) / level).collect()
}

/// The crossings of one row in grid order (each interval's in increasing k): `u` the row in
/// levels ([`levels`]) over the increasing rates `wz`; an interval with a non-finite end,
/// equal ends, or (`max_crossings`) more than that many levels crossed is left out (the grid does
/// not resolve it there). The arithmetic is that of librate's former Python `candidates` (numpy
/// elementwise, then Python floats), so its values are those, bit for bit.
pub fn crossings(u: &[f64], wz: &[f64], max_crossings: Option<usize>) -> Vec<Crossing> {
    let mut out = Vec::new();
    let n = u.len().min(wz.len());
    for i in 0..n.saturating_sub(1) {
        let (a, b) = (u[i], u[i + 1]);
        if !(a.is_finite() && b.is_finite()) || a == b {
            continue;
        }
        let (lo, hi) = (ceil(a.min(b)), floor(a.max(b)));
        if max_crossings.is_some_and(|m| hi - lo + 1.0 > m as f64) || hi < lo {
            continue;
        }
        let (w0, w1) = (wz[i], wz[i + 1]);
        let mut k = lo;
        while k <= hi {
            out.push(Crossing { k: k as i64, wz0: w0 + (k - a) / (b - a) * (w1 - w0), interval: i });
            k += 1.0;
        }
    }
    out
}

/// The intervals of a row in levels that cross more than `max_crossings` levels (those
/// [`crossings`] leaves out; an interval with a non-finite end is not counted).
pub fn unresolved(u: &[f64], max_crossings: usize) -> usize {
    u.windows(2)
        .filter(|p| {
            let crossed = floor(p[0].max(p[1])) - ceil(p[0].min(p[1])) + 1.0;
            crossed.is_finite() && crossed > max_crossings as f64
        })
        .count()
}

/// The search window (lo, hi) of wz0 of each crossing of the row in levels `u`: its rate
/// interval widened by `quick` intervals on each side (clipped to the grid) where u changes by at
/// most `resolved` per interval over that whole neighbourhood (a non-finite change is not
/// resolved); else (-inf, inf). As librate's former Python `crossing_windows`: the interval is
/// the one holding the crossing's interpolated rate (the last rate at or below it).
pub fn windows(u: &[f64], wz: &[f64], cross: &[Crossing], quick: usize, resolved: f64) -> Vec<(f64, f64)> {
    let n = wz.len().min(u.len());
    if n < 2 {
        return vec![(f64::NEG_INFINITY, f64::INFINITY); cross.len()];
    }
    cross
        .iter()
        .map(|c| {
            let at = wz[..n].partition_point(|&w| w <= c.wz0).saturating_sub(1).min(n - 2);
            let (first, last) = (at.saturating_sub(quick), (at + quick).min(n - 2));
            // the 2 quick + 1 intervals from `first`, each clipped to `last` (as the Python form)
            let ok = (0..=2 * quick).all(|d| {
                let j = (first + d).min(last);
                (u[j + 1] - u[j]).abs() <= resolved
            });
            if ok {
                (wz[first], wz[last + 1])
            } else {
                (f64::NEG_INFINITY, f64::INFINITY)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn crossings_interpolate_and_skip_what_the_grid_does_not_resolve() {
        // phi/pi: 0.5 -> 1.5 crosses 1 at the middle; 1.5 -> 1.5 nothing; 1.5 -> -0.5 crosses 1, 0
        let wz = [0.0, 1.0, 2.0, 3.0, 4.0];
        let phi = [0.5 * PI, 1.5 * PI, 1.5 * PI, -0.5 * PI, f64::NAN];
        let u = levels(&phi, 0.0, PI);
        let c = crossings(&u, &wz, None);
        let got: Vec<(i64, usize)> = c.iter().map(|c| (c.k, c.interval)).collect();
        assert_eq!(got, vec![(1, 0), (0, 2), (1, 2)]);
        assert!((c[0].wz0 - 0.5).abs() < 1e-15 && (c[1].wz0 - 2.75).abs() < 1e-15 && (c[2].wz0 - 2.25).abs() < 1e-15);
        // two levels in one interval: left out by max_crossings = 1, and counted as unresolved
        assert_eq!(crossings(&u, &wz, Some(1)).len(), 1);
        assert_eq!(unresolved(&u, 1), 1);
        assert_eq!(unresolved(&u, 2), 0);
    }

    #[test]
    fn floor_and_ceil_are_exact() {
        let xs = [0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.5, -2.5, 1e15 + 0.5, -1e15 - 0.5, 4.4e15, -4.4e15, 1e300, -1e300, f64::EPSILON, -f64::EPSILON, 3.0 - 1e-15];
        for x in xs.into_iter().chain((0..2000).map(|i| (i as f64 - 1000.0) * 0.37)) {
            assert_eq!(floor(x), x.floor(), "floor({x})");
            assert_eq!(ceil(x), x.ceil(), "ceil({x})"); // == also holds for -0.0 against +0.0
        }
        assert!(floor(f64::NAN).is_nan() && ceil(f64::NAN).is_nan());
        assert_eq!(floor(f64::INFINITY), f64::INFINITY);
        assert_eq!(ceil(f64::NEG_INFINITY), f64::NEG_INFINITY);
    }

    #[test]
    fn windows_widen_resolved_crossings_only() {
        let wz: Vec<f64> = (0..20).map(|i| i as f64 * 0.1).collect();
        // slow everywhere (0.05 levels per interval) except a jump of 0.5 between rates 15 and 16
        let mut phi: Vec<f64> = (0..20).map(|i| (0.81 + 0.05 * i as f64) * PI).collect();
        for p in phi.iter_mut().skip(16) {
            *p += 0.5 * PI;
        }
        let u = levels(&phi, 0.0, PI);
        let c = crossings(&u, &wz, None);
        assert_eq!(c.len(), 2);
        let w = windows(&u, &wz, &c, 4, 0.25);
        // the crossing of 1 in interval 3: intervals 0..=7 (clipped at the grid's start), resolved
        assert_eq!(c[0].interval, 3);
        assert_eq!(w[0], (wz[0], wz[8]));
        assert_eq!(c[1].interval, 15);
        // crossing of 2 within the jump's neighbourhood: not resolved
        assert_eq!(w[1], (f64::NEG_INFINITY, f64::INFINITY));
    }
}
