//! The step loop: adaptive or fixed steps, output, event location, statistics, errors.

use super::controller::Controller;
use super::events::{brent, Event, EventRecord};
use super::stepper::Rkf78;
use super::tableau::ERROR_ORDER;
use super::{State, Stats, System};
use crate::error::{check_finite, check_positive, invalid, IntegrationError, Result};

/// Integration settings. Defaults: rtol = atol = 1e-12, safety 0.8, step growth in [0.2, 5].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    pub rtol: f64,
    pub atol: f64,
    /// First step (magnitude); `None` picks it automatically.
    pub h0: Option<f64>,
    /// Smallest step magnitude before a [`IntegrationError::StepSizeUnderflow`]; 0 means
    /// "the spacing of floating-point numbers at t" (16 ulp).
    pub h_min: f64,
    pub h_max: f64,
    /// Limit on accepted + rejected steps.
    pub max_steps: usize,
    pub safety: f64,
    pub fac_min: f64,
    pub fac_max: f64,
    /// Fixed-step mode: `Some(h)` takes ceil(|tf - t0| / h) equal steps, no error control.
    pub fixed_step: Option<f64>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-12,
            atol: 1e-12,
            h0: None,
            h_min: 0.0,
            h_max: f64::INFINITY,
            max_steps: 1_000_000,
            safety: Controller::RKF78.safety,
            fac_min: Controller::RKF78.fac_min,
            fac_max: Controller::RKF78.fac_max,
            fixed_step: None,
        }
    }
}

/// The integration tolerances every integrator accepts: atol > 0 and 1e-15 <= rtol (below that
/// the error estimate is double-precision noise).
pub fn check_tolerances(rtol: f64, atol: f64) -> Result<()> {
    check_positive("rtol", rtol)?;
    check_positive("atol", atol)?;
    if rtol < 1e-15 {
        return Err(invalid("rtol", format!("must be >= 1e-15 (below double precision), got {rtol}")));
    }
    Ok(())
}

impl Options {
    pub fn with_tolerances(rtol: f64, atol: f64) -> Self {
        Self { rtol, atol, ..Self::default() }
    }

    /// Check every setting, naming the offending one.
    pub fn validate(&self) -> Result<()> {
        check_tolerances(self.rtol, self.atol)?;
        if let Some(h0) = self.h0 {
            check_positive("h0", h0)?;
        }
        if !(self.h_min >= 0.0 && self.h_min.is_finite()) {
            return Err(invalid("h_min", format!("must be a finite number >= 0, got {}", self.h_min)));
        }
        if !(self.h_max > 0.0) || self.h_max < self.h_min {
            return Err(invalid("h_max", format!("must be > 0 and >= h_min, got {}", self.h_max)));
        }
        if self.max_steps == 0 {
            return Err(invalid("max_steps", "must be >= 1"));
        }
        if !(self.safety > 0.0 && self.safety <= 1.0) {
            return Err(invalid("safety", format!("must be in (0, 1], got {}", self.safety)));
        }
        if !(self.fac_min > 0.0 && self.fac_min < 1.0) {
            return Err(invalid("fac_min", format!("must be in (0, 1), got {}", self.fac_min)));
        }
        if !(self.fac_max > 1.0 && self.fac_max.is_finite()) {
            return Err(invalid("fac_max", format!("must be a finite number > 1, got {}", self.fac_max)));
        }
        if let Some(h) = self.fixed_step {
            check_positive("fixed_step", h)?;
        }
        Ok(())
    }
}

/// Which states the solution records.
#[derive(Debug, Clone, Copy)]
pub enum Output<'a> {
    /// Only the final state.
    Final,
    /// The initial state and every accepted step.
    Steps,
    /// The states at these times (monotonic in the direction of integration, inside the span),
    /// each computed by a fresh RK step from the enclosing accepted step, so the step sequence
    /// is the same as without output.
    At(&'a [f64]),
}

/// Why the integration ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Reached the final time.
    Completed,
    /// A terminal event stopped it; `event` is its index.
    Terminated { event: usize },
}

/// Result of [`solve`].
#[derive(Debug, Clone)]
pub struct Solution<S> {
    /// Output times.
    pub t: Vec<f64>,
    /// Output states, row-major (len = t.len() * dim).
    pub y: Vec<f64>,
    /// Time and state where the integration ended (tf, or the terminal event).
    pub t_final: f64,
    pub y_final: S,
    pub events: Vec<EventRecord<S>>,
    pub status: Status,
    pub stats: Stats,
}

struct Recorder<'a> {
    output: Output<'a>,
    next: usize,
    t: Vec<f64>,
    y: Vec<f64>,
}

impl<'a> Recorder<'a> {
    fn push(&mut self, t: f64, y: &[f64]) {
        self.t.push(t);
        self.y.extend_from_slice(y);
    }
}

/// Integrate y' = f(t, y) from (t0, y0) to tf (forward or backward) with RKF7(8).
pub fn solve<S: State, Sys: System<S>>(
    sys: &Sys,
    t0: f64,
    y0: &S,
    tf: f64,
    opts: &Options,
    output: Output<'_>,
    events: &[Event<'_, S>],
) -> Result<Solution<S>> {
    opts.validate()?;
    if !t0.is_finite() {
        return Err(invalid("t0", format!("must be finite, got {t0}")));
    }
    if !tf.is_finite() {
        return Err(invalid("tf", format!("must be finite, got {tf}")));
    }
    check_finite("y0", y0.as_slice())?;
    let dir = if tf >= t0 { 1.0 } else { -1.0 };
    if let Output::At(times) = output {
        for (i, &te) in times.iter().enumerate() {
            if !te.is_finite() || dir * (te - t0) < 0.0 || dir * (te - tf) > 0.0 {
                return Err(invalid("t_eval", format!("times must lie in the span [{t0}, {tf}]; t_eval[{i}] = {te}")));
            }
            if i > 0 && dir * (te - times[i - 1]) < 0.0 {
                return Err(invalid("t_eval", format!("times must be monotonic in the direction of integration; t_eval[{i}] = {te} follows {}", times[i - 1])));
            }
        }
    }
    for (i, e) in events.iter().enumerate() {
        if !(-1..=1).contains(&e.direction) {
            return Err(invalid("events", format!("event {i}: direction must be -1, 0 or +1, got {}", e.direction)));
        }
    }

    let dim = y0.dim();
    let mut rec = Recorder {
        output,
        next: 0,
        t: Vec::new(),
        y: Vec::new(),
    };
    match output {
        Output::Steps => {
            rec.t.reserve(64);
            rec.y.reserve(64 * dim);
            rec.push(t0, y0.as_slice());
        }
        Output::At(times) => {
            rec.t.reserve(times.len());
            rec.y.reserve(times.len() * dim);
            while rec.next < times.len() && times[rec.next] == t0 {
                rec.push(t0, y0.as_slice());
                rec.next += 1;
            }
        }
        Output::Final => {}
    }

    let mut stepper = Rkf78::new(y0, crate::simd::active()?);
    let mut stats = Stats::default();
    let mut t = t0;
    let mut y = y0.clone();
    let mut y_new = y0.clone();
    let mut y_scratch = y0.clone();
    let mut g_prev: Vec<f64> = events.iter().map(|e| e.func.value(t0, y0)).collect();
    let mut g_new = g_prev.clone();
    let mut hits: Vec<(f64, usize)> = Vec::with_capacity(events.len());
    let mut records: Vec<EventRecord<S>> = Vec::new();
    let controller = Controller::new(opts.safety, opts.fac_min, opts.fac_max, ERROR_ORDER);

    let span = tf - t0;
    let fixed = opts.fixed_step.map(|h| {
        let n = ((span.abs() / h) - 1e-9).ceil().max(1.0);
        (n as usize, span / n)
    });
    if let Some((n, _)) = fixed {
        if n > opts.max_steps {
            return Err(invalid("fixed_step", format!("needs {n} steps, more than max_steps = {}", opts.max_steps)));
        }
    }

    stepper.prime(sys, t, &y);
    stats.rhs_evals += 1;
    if !all_finite(stepper.derivative_at_start().as_slice()) {
        return Err(IntegrationError::NonFinite { t, steps: 0 }.into());
    }
    let mut h = match (fixed, opts.h0) {
        (Some((_, h)), _) => h,
        (None, Some(h0)) => dir * h0.min(opts.h_max),
        (None, None) if span != 0.0 => {
            stats.rhs_evals += 2;
            stepper.initial_step(sys, t, &y, dir, opts.rtol, opts.atol, opts.h_max)
        }
        _ => 0.0,
    };
    let mut status = Status::Completed;
    let mut after_reject = false;
    let mut last_nonfinite = false;
    let mut done = span == 0.0;

    while !done {
        let steps = stats.steps();
        if steps >= opts.max_steps {
            return Err(IntegrationError::MaxStepsExceeded { t, steps, max_steps: opts.max_steps }.into());
        }
        // Last step lands exactly on tf.
        let mut last = false;
        if let Some((n_fixed, _)) = fixed {
            if stats.accepted + 1 == n_fixed {
                h = tf - t;
                last = true;
            }
        } else if dir * (t + h - tf) >= 0.0 || (tf - (t + h)).abs() <= 4.0 * f64::EPSILON * tf.abs().max(1.0) {
            h = tf - t;
            last = true;
        }
        let h_floor = opts.h_min.max(16.0 * f64::EPSILON * t.abs());
        if fixed.is_none() && h.abs() < h_floor && !last {
            return Err(if last_nonfinite {
                IntegrationError::NonFinite { t, steps }
            } else {
                IntegrationError::StepSizeUnderflow { t, steps, h: h.abs(), h_min: h_floor }
            }
            .into());
        }

        let err = stepper.step(sys, t, &y, h, &mut y_new, opts.rtol, opts.atol);
        stats.rhs_evals += 12;
        let (accept, h_next) = if let Some((_, hf)) = fixed {
            if !err.is_finite() || !all_finite(y_new.as_slice()) {
                return Err(IntegrationError::NonFinite { t, steps }.into());
            }
            (true, hf)
        } else {
            let ctl = controller.control(h, err, after_reject);
            let h_next = dir * ctl.h_next.abs().min(opts.h_max);
            (ctl.accept && all_finite(y_new.as_slice()), h_next)
        };
        if !accept {
            stats.rejected += 1;
            after_reject = true;
            last_nonfinite = !err.is_finite() || !all_finite(y_new.as_slice());
            h = if last_nonfinite { h * opts.fac_min } else { h_next };
            continue;
        }
        stats.accepted += 1;
        after_reject = false;
        last_nonfinite = false;
        let t_new = if last { tf } else { t + h };

        // Events in (t, t_new]: locate each counted crossing by re-integrating from (t, y).
        let mut t_end = t_new;
        let mut terminal_at: Option<usize> = None;
        if !events.is_empty() {
            hits.clear();
            for (i, e) in events.iter().enumerate() {
                g_new[i] = e.func.value(t_new, &y_new);
                if e.crosses(g_prev[i], g_new[i]) {
                    let (tau, evals) = brent(
                        |tau| {
                            stepper.step(sys, t, &y, tau, &mut y_scratch, opts.rtol, opts.atol);
                            e.func.value(t + tau, &y_scratch)
                        },
                        0.0,
                        t_new - t,
                        g_prev[i],
                        g_new[i],
                        1e-14 + 4.0 * f64::EPSILON * t.abs(),
                    );
                    stats.rhs_evals += 12 * evals;
                    // A crossing within 1e-12 of the start is the start itself (e.g. a restart
                    // at a located event whose state sits a rounding error before the surface).
                    if stats.accepted == 1 && tau.abs() <= 1e-12 * (1.0 + t0.abs()) {
                        continue;
                    }
                    hits.push((tau, i));
                }
            }
            hits.sort_by(|a, b| (dir * a.0).total_cmp(&(dir * b.0)).then(a.1.cmp(&b.1)));
            for &(tau, i) in hits.iter() {
                let te = if tau == t_new - t { t_new } else { t + tau };
                let ye = if te == t_new {
                    y_new.clone()
                } else {
                    stepper.step(sys, t, &y, tau, &mut y_scratch, opts.rtol, opts.atol);
                    stats.rhs_evals += 12;
                    y_scratch.clone()
                };
                records.push(EventRecord { index: i, t: te, y: ye });
                if events[i].terminal {
                    t_end = te;
                    terminal_at = Some(i);
                    break;
                }
            }
            std::mem::swap(&mut g_prev, &mut g_new);
        }

        // Output up to t_end.
        match rec.output {
            Output::Steps => {
                if terminal_at.is_none() {
                    rec.push(t_new, y_new.as_slice());
                }
            }
            Output::At(times) => {
                while rec.next < times.len() && dir * (times[rec.next] - t_end) <= 0.0 {
                    let te = times[rec.next];
                    if te == t_new {
                        rec.push(te, y_new.as_slice());
                    } else {
                        stepper.step(sys, t, &y, te - t, &mut y_scratch, opts.rtol, opts.atol);
                        stats.rhs_evals += 12;
                        rec.push(te, y_scratch.as_slice());
                    }
                    rec.next += 1;
                }
            }
            Output::Final => {}
        }

        if let Some(i) = terminal_at {
            let rec_e = records.last().expect("terminal event recorded");
            y = rec_e.y.clone();
            t = rec_e.t;
            if let Output::Steps = rec.output {
                rec.push(t, y.as_slice());
            }
            status = Status::Terminated { event: i };
            break;
        }

        std::mem::swap(&mut y, &mut y_new);
        t = t_new;
        h = h_next;
        if last {
            done = true;
        } else {
            stepper.prime(sys, t, &y);
            stats.rhs_evals += 1;
        }
    }

    if let Output::Final = rec.output {
        rec.push(t, y.as_slice());
    }
    Ok(Solution { t: rec.t, y: rec.y, t_final: t, y_final: y, events: records, status, stats })
}

#[inline]
fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Integrate a right-hand side that is smooth except where some `kinks` functions change sign
/// (e.g. a face of the body turning edge-on to the Sun): each kink is located as a terminal
/// event and the integration restarts there, so no step spans a kink and the method keeps its
/// order (a step across a kink makes both embedded solutions, and so the error estimate, wrong
/// at low order). Outputs and statistics are merged; `events` are not supported here.
pub fn solve_piecewise<S: State, Sys: System<S>>(
    sys: &Sys,
    t0: f64,
    y0: &S,
    tf: f64,
    opts: &Options,
    output: Output<'_>,
    kinks: &[&dyn super::EventFn<S>],
) -> Result<Solution<S>> {
    let events: Vec<Event<S>> = kinks.iter().map(|k| Event::new(*k, 0, true)).collect();
    let dir = if tf >= t0 { 1.0 } else { -1.0 };
    let mut t = t0;
    let mut y = y0.clone();
    let mut all_t = Vec::new();
    let mut all_y = Vec::new();
    let mut stats = Stats::default();
    let mut first = true;
    loop {
        // Output times still ahead (strictly after t, except at the very start).
        let part = match output {
            Output::At(times) => {
                let from = times.iter().position(|&te| if first { dir * (te - t) >= 0.0 } else { dir * (te - t) > 0.0 }).unwrap_or(times.len());
                Output::At(&times[from..])
            }
            o => o,
        };
        let sol = solve(sys, t, &y, tf, opts, part, &events)?;
        stats.accepted += sol.stats.accepted;
        stats.rejected += sol.stats.rejected;
        stats.rhs_evals += sol.stats.rhs_evals;
        let skip = if !first && matches!(output, Output::Steps) { 1 } else { 0 };
        let dim = y0.dim();
        match output {
            Output::Final => {}
            _ => {
                all_t.extend_from_slice(&sol.t[skip.min(sol.t.len())..]);
                all_y.extend_from_slice(&sol.y[(skip * dim).min(sol.y.len())..]);
            }
        }
        t = sol.t_final;
        y = sol.y_final;
        first = false;
        if sol.status == Status::Completed {
            if let Output::Final = output {
                all_t.push(t);
                all_y.extend_from_slice(y.as_slice());
            }
            return Ok(Solution { t: all_t, y: all_y, t_final: t, y_final: y, events: Vec::new(), status: Status::Completed, stats });
        }
        if stats.steps() >= opts.max_steps {
            return Err(IntegrationError::MaxStepsExceeded { t, steps: stats.steps(), max_steps: opts.max_steps }.into());
        }
    }
}
