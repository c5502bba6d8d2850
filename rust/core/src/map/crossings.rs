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

/// The crossings of one row in grid order (each interval's in increasing k): `phi_t` the
/// unwrapped final angles over the increasing rates `wz`; an interval with a non-finite end,
/// equal ends, or (`max_crossings`) more than that many levels crossed is left out (the grid does
/// not resolve it there). The arithmetic is that of librate's Python `candidates` (numpy
/// elementwise, then Python floats), so its values are those, bit for bit.
pub fn crossings(phi_t: &[f64], phi0: f64, wz: &[f64], level: f64, max_crossings: Option<usize>) -> Vec<Crossing> {
    let mut out = Vec::new();
    let n = phi_t.len().min(wz.len());
    for i in 0..n.saturating_sub(1) {
        let (a, b) = ((phi_t[i] - phi0) / level, (phi_t[i + 1] - phi0) / level);
        if !(a.is_finite() && b.is_finite()) || a == b {
            continue;
        }
        let (lo, hi) = (a.min(b).ceil(), a.max(b).floor());
        if max_crossings.is_some_and(|m| hi - lo + 1.0 > m as f64) || hi < lo {
            continue;
        }
        let (w0, w1) = (wz[i], wz[i + 1]);
        let mut k = lo + 0.0; // -0.0 (the ceiling of a small negative) as Python's int 0
        while k <= hi {
            out.push(Crossing { k: k as i64, wz0: w0 + (k - a) / (b - a) * (w1 - w0), interval: i });
            k += 1.0;
        }
    }
    out
}

/// The intervals of a row that cross more than `max_crossings` levels (those [`crossings`]
/// leaves out; an interval with a non-finite end is not counted).
pub fn unresolved(phi_t: &[f64], phi0: f64, level: f64, max_crossings: usize) -> usize {
    phi_t
        .windows(2)
        .filter(|p| {
            let (a, b) = ((p[0] - phi0) / level, (p[1] - phi0) / level);
            let crossed = a.max(b).floor() - a.min(b).ceil() + 1.0;
            crossed.is_finite() && crossed > max_crossings as f64
        })
        .count()
}

/// The search window (lo, hi) of wz0 of each crossing: its rate interval widened by `quick`
/// intervals on each side (clipped to the grid) where phi(KT) changes by at most `resolved`
/// levels per interval over that whole neighbourhood (a non-finite change is not resolved); else
/// (-inf, inf). As librate's Python `crossing_windows`: the interval is the one holding the
/// crossing's interpolated rate (the last rate at or below it).
pub fn windows(phi_t: &[f64], phi0: f64, wz: &[f64], level: f64, cross: &[Crossing], quick: usize, resolved: f64) -> Vec<(f64, f64)> {
    let n = wz.len();
    if n < 2 {
        return vec![(f64::NEG_INFINITY, f64::INFINITY); cross.len()];
    }
    let change = |j: usize| ((phi_t[j + 1] - phi0) / level - (phi_t[j] - phi0) / level).abs();
    cross
        .iter()
        .map(|c| {
            let at = wz.partition_point(|&w| w <= c.wz0).saturating_sub(1).min(n - 2);
            let (first, last) = (at.saturating_sub(quick), (at + quick).min(n - 2));
            // the 2 quick + 1 intervals from `first`, each clipped to `last` (as the Python form)
            let ok = (0..=2 * quick).all(|d| change((first + d).min(last)) <= resolved);
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
        let c = crossings(&phi, 0.0, &wz, PI, None);
        let got: Vec<(i64, usize)> = c.iter().map(|c| (c.k, c.interval)).collect();
        assert_eq!(got, vec![(1, 0), (0, 2), (1, 2)]);
        assert!((c[0].wz0 - 0.5).abs() < 1e-15 && (c[1].wz0 - 2.75).abs() < 1e-15 && (c[2].wz0 - 2.25).abs() < 1e-15);
        // two levels in one interval: left out by max_crossings = 1, and counted as unresolved
        assert_eq!(crossings(&phi, 0.0, &wz, PI, Some(1)).len(), 1);
        assert_eq!(unresolved(&phi, 0.0, PI, 1), 1);
        assert_eq!(unresolved(&phi, 0.0, PI, 2), 0);
    }

    #[test]
    fn windows_widen_resolved_crossings_only() {
        let wz: Vec<f64> = (0..20).map(|i| i as f64 * 0.1).collect();
        // slow everywhere (0.05 levels per interval) except a jump of 0.5 between rates 15 and 16
        let mut phi: Vec<f64> = (0..20).map(|i| (0.81 + 0.05 * i as f64) * PI).collect();
        for p in phi.iter_mut().skip(16) {
            *p += 0.5 * PI;
        }
        let c = crossings(&phi, 0.0, &wz, PI, None);
        assert_eq!(c.len(), 2);
        let w = windows(&phi, 0.0, &wz, PI, &c, 4, 0.25);
        // the crossing of 1 in interval 3: intervals 0..=7 (clipped at the grid's start), resolved
        assert_eq!(c[0].interval, 3);
        assert_eq!(w[0], (wz[0], wz[8]));
        assert_eq!(c[1].interval, 15);
        // crossing of 2 within the jump's neighbourhood: not resolved
        assert_eq!(w[1], (f64::NEG_INFINITY, f64::INFINITY));
    }
}
