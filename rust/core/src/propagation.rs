//! CR3BP propagation with optional STM, events and output; batches on all cores.

use rayon::prelude::*;

use crate::cr3bp::{check_mu, Cr3bp, Cr3bpStm, STM_DIM};
use crate::error::{check_finite, invalid, Error, IntegrationError, Result};
use crate::integrate::{solve, Event, EventFn, Options, Output, State, Stats, Status};

/// Scalar event functions on a CR3BP state (the first six components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EventKind {
    /// g = state[index] - value (index 0..6: x, y, z, xd, yd, zd).
    Crossing { index: usize, value: f64 },
    /// g = |r - center| - radius: reaching a sphere about a point (e.g. a primary's surface).
    Distance { center: [f64; 3], radius: f64 },
}

impl<S: State> EventFn<S> for EventKind {
    #[inline]
    fn value(&self, _t: f64, y: &S) -> f64 {
        let s = y.as_slice();
        match *self {
            EventKind::Crossing { index, value } => s[index] - value,
            EventKind::Distance { center, radius } => {
                ((s[0] - center[0]).powi(2) + (s[1] - center[1]).powi(2) + (s[2] - center[2]).powi(2)).sqrt() - radius
            }
        }
    }
}

/// An event to locate during a CR3BP propagation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventSpec {
    pub kind: EventKind,
    /// +1 increasing, -1 decreasing, 0 both.
    pub direction: i8,
    pub terminal: bool,
}

impl EventSpec {
    fn validate(&self, i: usize) -> Result<()> {
        match self.kind {
            EventKind::Crossing { index, value } => {
                if index >= 6 {
                    return Err(invalid("events", format!("event {i}: component index must be in 0..6, got {index}")));
                }
                check_finite("events", &[value])?;
            }
            EventKind::Distance { center, radius } => {
                check_finite("events", &center)?;
                if !(radius.is_finite() && radius >= 0.0) {
                    return Err(invalid("events", format!("event {i}: radius must be finite and >= 0, got {radius}")));
                }
            }
        }
        if !(-1..=1).contains(&self.direction) {
            return Err(invalid("events", format!("event {i}: direction must be -1, 0 or +1, got {}", self.direction)));
        }
        Ok(())
    }
}

/// A located event: which one, when, the state and (when propagated) the STM.
#[derive(Debug, Clone, PartialEq)]
pub struct EventHit {
    pub index: usize,
    pub t: f64,
    pub state: [f64; 6],
    pub stm: Option<[[f64; 6]; 6]>,
}

/// Result of [`propagate`].
#[derive(Debug, Clone)]
pub struct Trajectory {
    pub t: Vec<f64>,
    /// Row-major n x 6.
    pub states: Vec<f64>,
    pub t_final: f64,
    pub state_final: [f64; 6],
    /// STM from t0 to t_final, when asked for.
    pub stm_final: Option<[[f64; 6]; 6]>,
    pub events: Vec<EventHit>,
    pub status: Status,
    pub stats: Stats,
    /// Set when [`propagate_checked`] stopped at a collision with a primary (then `t_final`
    /// and `state_final` are the state on the collision sphere and `status` is `Terminated`).
    pub collision: Option<CollisionHit>,
}

/// Collision radius (LU) of a primary without a physical radius: the distance below which the
/// point-mass field is treated as singular.
pub const POINT_COLLISION_RADIUS: f64 = 1e-8;

/// Collision spheres about the two primaries (nondimensional radii, > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    pub radii: [f64; 2],
}

/// Where a propagation met a primary: `primary` 1 (at x = -mu) or 2 (at x = 1 - mu).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionHit {
    pub primary: u8,
    pub t: f64,
    pub distance: f64,
    pub radius: f64,
}

impl Collision {
    /// The spheres of the given radii; a radius of 0 means [`POINT_COLLISION_RADIUS`].
    pub fn new(radii: [f64; 2]) -> Result<Self> {
        for (k, r) in radii.iter().enumerate() {
            if !(r.is_finite() && *r >= 0.0) {
                return Err(invalid("collision", format!("radius of primary {} must be finite and >= 0, got {r}", k + 1)));
            }
        }
        Ok(Self { radii: radii.map(|r| if r > 0.0 { r } else { POINT_COLLISION_RADIUS }) })
    }

    fn center(mu: f64, k: usize) -> [f64; 3] {
        [if k == 0 { -mu } else { 1.0 - mu }, 0.0, 0.0]
    }

    fn distance(mu: f64, k: usize, s: &[f64]) -> f64 {
        let c = Self::center(mu, k);
        ((s[0] - c[0]).powi(2) + (s[1] - c[1]).powi(2) + (s[2] - c[2]).powi(2)).sqrt()
    }

    /// The first primary whose sphere holds `state` (distance <= radius).
    pub fn inside(&self, mu: f64, state: &[f64]) -> Option<CollisionHit> {
        (0..2).find_map(|k| {
            let d = Self::distance(mu, k, state);
            (d <= self.radii[k]).then_some(CollisionHit { primary: k as u8 + 1, t: f64::NAN, distance: d, radius: self.radii[k] })
        })
    }
}

impl CollisionHit {
    /// The typed error of this collision.
    pub fn error(&self, steps: usize) -> Error {
        IntegrationError::Collision { t: self.t, steps, primary: self.primary, distance: self.distance, radius: self.radius }.into()
    }
}

/// [`propagate`] with collisions: reaching the sphere of `collision` about either primary is a
/// terminal event. The trajectory then ends on that sphere with `collision` set (its `events`
/// hold only the caller's events). A state that starts inside a sphere collides at t0.
pub fn propagate_checked(
    mu: f64,
    state: &[f64; 6],
    t0: f64,
    tf: f64,
    opts: &Options,
    with_stm: bool,
    output: Output<'_>,
    events: &[EventSpec],
    collision: &Collision,
) -> Result<Trajectory> {
    check_mu(mu)?;
    check_finite("state", state)?;
    if let Some(mut hit) = collision.inside(mu, state) {
        hit.t = t0;
        let stm = with_stm.then(|| std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 })));
        return Ok(Trajectory {
            t: vec![t0],
            states: state.to_vec(),
            t_final: t0,
            state_final: *state,
            stm_final: stm,
            events: Vec::new(),
            status: Status::Terminated { event: events.len() + hit.primary as usize - 1 },
            stats: Stats::default(),
            collision: Some(hit),
        });
    }
    let n = events.len();
    let mut all = events.to_vec();
    for k in 0..2 {
        all.push(EventSpec { kind: EventKind::Distance { center: Collision::center(mu, k), radius: collision.radii[k] }, direction: -1, terminal: true });
    }
    let mut tr = propagate(mu, state, t0, tf, opts, with_stm, output, &all)?;
    if let Status::Terminated { event } = tr.status {
        if event >= n {
            let k = event - n;
            tr.collision = Some(CollisionHit {
                primary: k as u8 + 1,
                t: tr.t_final,
                distance: Collision::distance(mu, k, &tr.state_final),
                radius: collision.radii[k],
            });
        }
    }
    tr.events.retain(|e| e.index < n);
    Ok(tr)
}

/// Propagate one CR3BP state from t0 to tf (either direction).
pub fn propagate(
    mu: f64,
    state: &[f64; 6],
    t0: f64,
    tf: f64,
    opts: &Options,
    with_stm: bool,
    output: Output<'_>,
    events: &[EventSpec],
) -> Result<Trajectory> {
    check_mu(mu)?;
    check_finite("state", state)?;
    for (i, e) in events.iter().enumerate() {
        e.validate(i)?;
    }
    if with_stm {
        let sys = Cr3bpStm { mu };
        let evs: Vec<Event<[f64; STM_DIM]>> = events.iter().map(|e| Event::new(&e.kind, e.direction, e.terminal)).collect();
        let sol = solve(&sys, t0, &Cr3bpStm::initial(state), tf, opts, output, &evs)?;
        let (state_final, stm) = Cr3bpStm::split(&sol.y_final);
        let mut states = Vec::with_capacity(sol.t.len() * 6);
        for row in sol.y.chunks_exact(STM_DIM) {
            states.extend_from_slice(&row[..6]);
        }
        let events = sol
            .events
            .iter()
            .map(|r| {
                let (s, m) = Cr3bpStm::split(&r.y);
                EventHit { index: r.index, t: r.t, state: s, stm: Some(m) }
            })
            .collect();
        Ok(Trajectory { t: sol.t, states, t_final: sol.t_final, state_final, stm_final: Some(stm), events, status: sol.status, stats: sol.stats, collision: None })
    } else {
        let sys = Cr3bp { mu };
        let evs: Vec<Event<[f64; 6]>> = events.iter().map(|e| Event::new(&e.kind, e.direction, e.terminal)).collect();
        let sol = solve(&sys, t0, state, tf, opts, output, &evs)?;
        let events = sol.events.iter().map(|r| EventHit { index: r.index, t: r.t, state: r.y, stm: None }).collect();
        Ok(Trajectory { t: sol.t, states: sol.y, t_final: sol.t_final, state_final: sol.y_final, stm_final: None, events, status: sol.status, stats: sol.stats, collision: None })
    }
}

/// Final state of one member of a batch.
#[derive(Debug, Clone, PartialEq)]
pub struct FinalState {
    pub state: [f64; 6],
    pub stm: Option<[[f64; 6]; 6]>,
    pub stats: Stats,
}

/// The pool a call asked to run on `threads` workers runs on: None for the global pool (started
/// here), else a pool of that size lent to this call ([`crate::threads::pool_of_size`]).
fn pool_for(threads: Option<usize>) -> Result<Option<crate::threads::SizedPool>> {
    match threads {
        Some(0) => Err(invalid("threads", "must be >= 1 (or None for all cores)")),
        Some(n) => crate::threads::pool_of_size(n),
        None => crate::threads::start_global_pool().map(|_| None),
    }
}

/// Run `f` on a rayon pool of `threads` workers (`None`: the global pool, all cores; see
/// [`pool_for`]).
pub fn with_threads<R: Send>(threads: Option<usize>, f: impl FnOnce() -> R + Send) -> Result<R> {
    Ok(match pool_for(threads)? {
        Some(pool) => pool.install(f),
        None => f(),
    })
}

/// [`with_threads`] for a loop of many parallel rounds (a Newton driver integrating its
/// candidates' pending points once per iteration): with `None`, `f` runs on a worker of the
/// global pool, so that each round is split among the workers from inside the pool. Started
/// from any other thread, each round would be injected into the pool and its caller woken at
/// its end, two thread switches per round: the standard map's 13 crossings (9 rounds) took
/// 0.43 ms in the corrector against 0.40 ms on a worker, and `srp_map` 0.50 s against 0.45 s
/// (Intel Xeon, 2 cores). A single parallel sweep gains nothing from it (measured: slightly
/// slower), so [`with_threads`] is unchanged.
pub fn with_threads_rounds<R: Send>(threads: Option<usize>, f: impl FnOnce() -> R + Send) -> Result<R> {
    Ok(match pool_for(threads)? {
        Some(pool) => pool.install(f),
        // on a worker already, rayon::scope runs f in place
        None => rayon::scope(|_| f()),
    })
}

/// Propagate many states from t0 to their final times (one shared, or one per state) on all
/// cores. Each member is integrated exactly as [`propagate`] would, independently of the
/// others, so the results are bit-identical to one-at-a-time calls whatever the thread count.
/// One member failing does not lose the others: each carries its own `Result`. With
/// `collision`, a member that reaches a primary's sphere is an
/// [`IntegrationError::Collision`] (see [`propagate_checked`]).
pub fn propagate_many(
    mu: f64,
    states: &[[f64; 6]],
    t0: f64,
    t_final: &[f64],
    opts: &Options,
    with_stm: bool,
    threads: Option<usize>,
    collision: Option<&Collision>,
) -> Result<Vec<Result<FinalState>>> {
    check_mu(mu)?;
    opts.validate()?;
    if t_final.len() != 1 && t_final.len() != states.len() {
        return Err(invalid("t_final", format!("must be one time or one per state ({}), got {}", states.len(), t_final.len())));
    }
    check_finite("t_final", t_final)?;
    let run = |i: usize| -> Result<FinalState> {
        crate::interrupt::check()?;
        let tf = if t_final.len() == 1 { t_final[0] } else { t_final[i] };
        let tr = match collision {
            Some(c) => propagate_checked(mu, &states[i], t0, tf, opts, with_stm, Output::Final, &[], c)?,
            None => propagate(mu, &states[i], t0, tf, opts, with_stm, Output::Final, &[])?,
        };
        if let Some(hit) = tr.collision {
            return Err(hit.error(tr.stats.steps()));
        }
        Ok(FinalState { state: tr.state_final, stm: tr.stm_final, stats: tr.stats })
    };
    let out: Vec<Result<FinalState>> = with_threads(threads, || (0..states.len()).into_par_iter().map(run).collect())?;
    // an interrupted batch is an error of the call, not of its members
    crate::interrupt::check()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// with_threads_rounds: `None` (or the global pool's size) runs the loop on a worker of the
    /// global pool (from outside it), another `Some(n)` on a pool of n workers, and the loop's
    /// parallel rounds give the same results as [`with_threads`].
    #[test]
    fn with_threads_rounds_runs_on_a_pool_worker() {
        let rounds = || -> (bool, Vec<u64>) {
            let on_worker = rayon::current_thread_index().is_some();
            let v = (0..5u64).flat_map(|r| (0..100u64).into_par_iter().map(move |i| i * i + r).collect::<Vec<_>>()).collect();
            (on_worker, v)
        };
        let (outside, v0) = with_threads(None, rounds).unwrap();
        let (inside, v1) = with_threads_rounds(None, rounds).unwrap();
        let (inside2, v2) = with_threads_rounds(Some(2), rounds).unwrap();
        let other = crate::threads::start_global_pool().unwrap().threads + 1;
        let (inside3, v3) = with_threads_rounds(Some(other), rounds).unwrap();
        assert!(!outside, "the test thread is not a worker");
        assert!(inside && inside2 && inside3);
        assert_eq!(v0, v1);
        assert_eq!(v0, v2);
        assert_eq!(v0, v3);
        assert!(with_threads_rounds(Some(0), rounds).is_err());
    }
}
