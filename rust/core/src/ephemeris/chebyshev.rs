//! JPL SPK type-2 segments (Chebyshev position coefficients per fixed-length record, as in DE440
//! and DE421) and their chaining into the state of one body relative to another.
//!
//! Evaluation follows the SPK type-2 definition (NAIF SPK Required Reading): for an epoch t the
//! record is k = floor((t - init) / intlen) (the last record also covers the segment's end), the
//! normalised time is s = 2 (t - t_k) / intlen - 1 in [-1, 1], the position is
//! sum_n c_n T_n(s), the velocity the exact derivative of that series, sum_n c_n T'_n(s) 2 /
//! intlen, and the acceleration its second derivative.

use std::sync::Arc;

use crate::error::{invalid, Result};

/// NAIF ids.
pub const SSB: i32 = 0;
pub const EMB: i32 = 3;
pub const SUN: i32 = 10;
pub const MOON: i32 = 301;
pub const EARTH: i32 = 399;

/// One type-2 segment: `target` relative to `center`.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    pub target: i32,
    pub center: i32,
    /// Coverage, TDB s past J2000.
    pub start: f64,
    pub end: f64,
    /// First record's start epoch and the record length (s).
    pub init: f64,
    pub intlen: f64,
    pub n_records: usize,
    pub n_coef: usize,
    /// (n_records, 3, n_coef) row-major, km.
    pub coef: Vec<f64>,
}

impl Segment {
    /// Check the shape and values of a segment.
    pub fn new(target: i32, center: i32, start: f64, end: f64, init: f64, intlen: f64, n_records: usize, n_coef: usize, coef: Vec<f64>) -> Result<Self> {
        if !(start.is_finite() && end.is_finite() && start < end) {
            return Err(invalid("segments", format!("segment {target} rel. {center}: coverage [{start}, {end}] must be finite with start < end")));
        }
        if !(intlen.is_finite() && intlen > 0.0 && init.is_finite()) {
            return Err(invalid("segments", format!("segment {target} rel. {center}: record length must be finite > 0, got {intlen}")));
        }
        if n_records == 0 || n_coef == 0 || coef.len() != n_records * 3 * n_coef {
            return Err(invalid("segments", format!("segment {target} rel. {center}: coefficients must have shape (n_records >= 1, 3, n_coef >= 1), got {} values for ({n_records}, 3, {n_coef})", coef.len())));
        }
        let last = init + intlen * (n_records as f64);
        if init > start + 1e-6 * intlen || last < end - 1e-6 * intlen {
            return Err(invalid("segments", format!("segment {target} rel. {center}: records [{init}, {last}] do not cover [{start}, {end}]")));
        }
        if let Some(i) = coef.iter().position(|c| !c.is_finite()) {
            return Err(invalid("segments", format!("segment {target} rel. {center}: coefficient {i} is not finite")));
        }
        Ok(Self { target, center, start, end, init, intlen, n_records, n_coef, coef })
    }

    /// Whether t lies in the coverage.
    #[inline]
    pub fn covers(&self, t: f64) -> bool {
        t >= self.start && t <= self.end
    }

    /// The record covering t and the scaled time s in [-1, 1] within it.
    #[inline]
    fn record(&self, t: f64) -> (&[f64], f64) {
        let off = t - self.init;
        let k = (off / self.intlen).floor().clamp(0.0, (self.n_records - 1) as f64);
        let ki = k as usize;
        let s = 2.0 * (off - k * self.intlen) / self.intlen - 1.0;
        (&self.coef[ki * 3 * self.n_coef..(ki + 1) * 3 * self.n_coef], s)
    }

    /// Position (km) at t only (Clenshaw's recurrence; the right-hand side needs no more).
    #[inline]
    pub fn position(&self, t: f64) -> [f64; 3] {
        let (rec, s) = self.record(t);
        let n = self.n_coef;
        std::array::from_fn(|c| {
            let a = &rec[c * n..(c + 1) * n];
            let (mut b1, mut b2) = (0.0, 0.0);
            for k in (1..n).rev() {
                let b0 = 2.0 * s * b1 - b2 + a[k];
                b2 = b1;
                b1 = b0;
            }
            s * b1 - b2 + a[0]
        })
    }

    /// Position (km), velocity (km/s) and acceleration (km/s^2) at t (inside the coverage;
    /// the caller checks).
    #[inline]
    pub fn evaluate(&self, t: f64) -> [[f64; 3]; 3] {
        let (rec, s) = self.record(t);
        let scale = 2.0 / self.intlen;
        let mut out = [[0.0; 3]; 3];
        // T_n, T'_n, T''_n by their recurrences.
        let (mut t0, mut t1) = (1.0, s);
        let (mut d0, mut d1) = (0.0, 1.0);
        let (mut e0, mut e1) = (0.0, 0.0);
        for n in 0..self.n_coef {
            let (tn, dn, en) = match n {
                0 => (1.0, 0.0, 0.0),
                1 => (s, 1.0, 0.0),
                _ => {
                    let t2 = 2.0 * s * t1 - t0;
                    let d2 = 2.0 * t1 + 2.0 * s * d1 - d0;
                    let e2 = 4.0 * d1 + 2.0 * s * e1 - e0;
                    (t0, t1) = (t1, t2);
                    (d0, d1) = (d1, d2);
                    (e0, e1) = (e1, e2);
                    (t2, d2, e2)
                }
            };
            for (c, o) in out[0].iter_mut().enumerate() {
                *o += rec[c * self.n_coef + n] * tn;
            }
            for c in 0..3 {
                let a = rec[c * self.n_coef + n];
                out[1][c] += a * dn;
                out[2][c] += a * en;
            }
        }
        for v in out[1].iter_mut() {
            *v *= scale;
        }
        for v in out[2].iter_mut() {
            *v *= scale * scale;
        }
        out
    }
}

/// A set of segments and the chains between bodies.
#[derive(Debug, Clone)]
pub struct Ephemeris {
    /// Shared: cloning an ephemeris is cheap.
    segments: Arc<Vec<Segment>>,
    span: (f64, f64),
}

impl Ephemeris {
    /// Build from segments; every body's chain must lead to the SSB (0) without a loop. The span is
    /// the common coverage of the segments of Sun, EMB, Moon and Earth (those present).
    pub fn new(segments: Vec<Segment>) -> Result<Self> {
        if segments.is_empty() {
            return Err(invalid("segments", "at least one segment is needed"));
        }
        let mut span = (f64::NEG_INFINITY, f64::INFINITY);
        for s in &segments {
            span.0 = span.0.max(s.start);
            span.1 = span.1.min(s.end);
        }
        if span.0 >= span.1 {
            return Err(invalid("segments", "the segments have no common coverage"));
        }
        Ok(Self { segments: Arc::new(segments), span })
    }

    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The common coverage, TDB s past J2000.
    pub fn span(&self) -> (f64, f64) {
        self.span
    }

    /// Ok when t lies in the span; an error naming the span otherwise.
    pub fn check_epoch(&self, name: &'static str, t: f64) -> Result<()> {
        let (a, b) = self.span;
        if t.is_finite() && t >= a && t <= b {
            Ok(())
        } else {
            let year = |x: f64| 2000.0 + (x - 43200.0) / (365.25 * 86400.0);
            Err(invalid(name, format!("epoch {t} TDB s past J2000 lies outside the ephemeris span [{a}, {b}] TDB s (about {:.2} to {:.2})", year(a), year(b))))
        }
    }

    fn segment_of(&self, target: i32, t: f64) -> Option<&Segment> {
        self.segments.iter().find(|s| s.target == target && s.covers(t))
    }

    /// The chain body -> ... -> SSB at t.
    fn chain(&self, body: i32, t: f64) -> Result<Vec<&Segment>> {
        let mut out = Vec::with_capacity(3);
        let mut b = body;
        while b != SSB {
            let s = self.segment_of(b, t).ok_or_else(|| invalid("target", format!("no segment for body {b} (in the chain of {body}) at t = {t}")))?;
            out.push(s);
            b = s.center;
            if out.len() > 8 {
                return Err(invalid("segments", format!("the chain of body {body} has a loop")));
            }
        }
        Ok(out)
    }

    /// Position, velocity, acceleration of `target` relative to `center` at t (km, km/s,
    /// km/s^2): only the segments below the common ancestor are summed (Earth relative to the
    /// Moon uses 399 rel. 3 and 301 rel. 3 only).
    pub fn pva(&self, target: i32, center: i32, t: f64) -> Result<[[f64; 3]; 3]> {
        self.check_epoch("epoch", t)?;
        let ct = self.chain(target, t)?;
        let cc = self.chain(center, t)?;
        // Drop the common tail.
        let (mut nt, mut nc) = (ct.len(), cc.len());
        while nt > 0 && nc > 0 && std::ptr::eq(ct[nt - 1], cc[nc - 1]) {
            nt -= 1;
            nc -= 1;
        }
        let mut out = [[0.0; 3]; 3];
        for s in &ct[..nt] {
            let e = s.evaluate(t);
            for i in 0..3 {
                for c in 0..3 {
                    out[i][c] += e[i][c];
                }
            }
        }
        for s in &cc[..nc] {
            let e = s.evaluate(t);
            for i in 0..3 {
                for c in 0..3 {
                    out[i][c] -= e[i][c];
                }
            }
        }
        Ok(out)
    }

    /// State (x, y, z, vx, vy, vz) of `target` relative to `center` at t (km, km/s).
    pub fn state(&self, target: i32, center: i32, t: f64) -> Result<[f64; 6]> {
        let p = self.pva(target, center, t)?;
        Ok([p[0][0], p[0][1], p[0][2], p[1][0], p[1][1], p[1][2]])
    }
}

/// Earth and Sun relative to the Moon at t, for the right-hand side: their positions. Precomputed chains keep it allocation-free.
#[derive(Debug, Clone)]
pub(crate) struct MoonCentred {
    eph: Ephemeris,
}

impl MoonCentred {
    pub fn new(eph: Ephemeris) -> Result<Self> {
        let t = 0.5 * (eph.span.0 + eph.span.1);
        for (b, c) in [(EARTH, EMB), (MOON, EMB), (EMB, SSB), (SUN, SSB)] {
            let s = eph.segment_of(b, t).ok_or_else(|| invalid("segments", format!("a segment of body {b} relative to {c} is needed")))?;
            if s.center != c {
                return Err(invalid("segments", format!("body {b} must be given relative to {c}, got relative to {}", s.center)));
            }
        }
        Ok(Self { eph })
    }

    pub fn ephemeris(&self) -> &Ephemeris {
        &self.eph
    }

    #[inline]
    fn position(&self, b: i32, t: f64) -> [f64; 3] {
        match self.eph.segment_of(b, t) {
            Some(s) => s.position(t),
            None => [f64::NAN; 3],
        }
    }

    /// (Earth rel. Moon, Sun rel. Moon) positions (km); NaN outside the span.
    #[inline]
    pub fn positions(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        let e = self.position(EARTH, t);
        let m = self.position(MOON, t);
        let b = self.position(EMB, t);
        let s = self.position(SUN, t);
        (std::array::from_fn(|c| e[c] - m[c]), std::array::from_fn(|c| (s[c] - b[c]) - m[c]))
    }
}
