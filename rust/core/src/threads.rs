//! The global worker pool and where its threads run.
//!
//! Every parallel loop of the core (map sweeps, batch propagation, the correctors' rounds) runs
//! on rayon's global pool. [`start_global_pool`] builds it (with the first parallel work: never
//! at import, so that a process forked after importing librate starts its own) with one worker
//! per CPU the process may use and, on Linux, each worker bound to its own CPU when the pool
//! covers all of them. Unbound, a short call (a 2-ms map on two cores) can
//! run at one core's speed: the kernel wakes an idle worker on the CPU of the thread that woke
//! it, and the pair shares that CPU until the load balancer moves one, a few milliseconds later
//! (measured on a 2-core Intel Xeon VM: the standard map in 1.9-3.4 ms unbound against 1.8-2.0
//! ms bound, its one-thread time 3.1 ms; docs/benchmarks.md).
//!
//! `LIBRATE_BIND_THREADS` chooses: `auto` (the default) binds worker i to the i-th allowed CPU
//! when the pool has as many workers as the process has allowed CPUs (at least two), so that a
//! pool narrowed by `RAYON_NUM_THREADS`, or a process given fewer CPUs, is left to the kernel;
//! `on` binds worker i to allowed CPU i mod n in any case; `off` never binds. Binding is
//! Linux-only (elsewhere the pool is always unbound), and a worker whose binding the kernel
//! refuses (a CPU set changed since) runs unbound: [`PoolInfo::bound`] counts the bound ones.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use crate::error::{invalid, Result};

/// The environment variable that chooses the binding.
pub const BIND_VAR: &str = "LIBRATE_BIND_THREADS";

/// Whether the pool's workers are bound to CPUs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// Bound when the pool covers every allowed CPU (at least two).
    Auto,
    /// Worker i on allowed CPU i mod n.
    On,
    /// Left to the kernel.
    Off,
}

impl Binding {
    pub fn name(self) -> &'static str {
        match self {
            Binding::Auto => "auto",
            Binding::On => "on",
            Binding::Off => "off",
        }
    }
}

/// A `LIBRATE_BIND_THREADS` value (None or empty: auto).
pub fn parse_binding(value: Option<&str>) -> Result<Binding> {
    match value.map(|v| v.trim().to_ascii_lowercase()).as_deref() {
        None | Some("") | Some("auto") => Ok(Binding::Auto),
        Some("on") | Some("1") | Some("true") => Ok(Binding::On),
        Some("off") | Some("0") | Some("false") => Ok(Binding::Off),
        Some(other) => Err(invalid(BIND_VAR, format!("must be auto, on or off, got {other:?}"))),
    }
}

/// The CPUs a binding gives the pool's workers, worker i on `cpus[i]` (empty: unbound).
/// `allowed` are the process's allowed CPUs, in ascending order.
pub fn plan(binding: Binding, workers: usize, allowed: &[usize]) -> Vec<usize> {
    let n = allowed.len();
    let bind = match binding {
        Binding::Off => false,
        Binding::On => n > 0,
        Binding::Auto => n >= 2 && workers == n,
    };
    if bind {
        (0..workers).map(|i| allowed[i % n]).collect()
    } else {
        Vec::new()
    }
}

/// The global pool as [`start_global_pool`] left it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PoolInfo {
    /// Its workers.
    pub threads: usize,
    /// The binding asked for.
    pub binding: Binding,
    /// The CPU of each worker, when bound (empty: unbound).
    pub cpus: Vec<usize>,
    /// Whether the pool runs (else this is its plan: [`pool_info`] before the first parallel work).
    pub started: bool,
    /// False when the pool was already running (built by someone else: left as it is).
    pub started_here: bool,
}

impl PoolInfo {
    /// How many workers the kernel accepted on their CPU (their binding is set as they start).
    pub fn bound(&self) -> usize {
        BOUND.load(Ordering::Relaxed)
    }
}

static BOUND: AtomicUsize = AtomicUsize::new(0);
static STARTED: OnceLock<PoolInfo> = OnceLock::new();

/// The binding `LIBRATE_BIND_THREADS` asks for (an error naming it when invalid).
pub fn binding_from_env() -> Result<Binding> {
    parse_binding(std::env::var(BIND_VAR).ok().as_deref())
}

/// The pool [`start_global_pool`] builds (or built): before it starts, its plan
/// (`started` false, no worker bound yet).
pub fn pool_info() -> Result<PoolInfo> {
    if let Some(info) = STARTED.get() {
        return Ok(info.clone());
    }
    let binding = binding_from_env()?;
    // rayon's own default size: RAYON_NUM_THREADS, else the available parallelism
    let workers = match std::env::var("RAYON_NUM_THREADS").ok().and_then(|v| v.parse::<usize>().ok()) {
        Some(n) if n > 0 => n,
        _ => std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
    };
    let cpus = plan(binding, workers, &allowed_cpus());
    Ok(PoolInfo { threads: workers, binding, cpus, started: false, started_here: false })
}

/// Build rayon's global pool with `LIBRATE_BIND_THREADS`'s binding (module docs), once per
/// process; later calls return the first one's outcome. The core's parallel entry points call
/// it ([`crate::propagation::with_threads`], [`run_polled`]), so the pool starts with the first
/// parallel work, not before: a process forked before that starts its own pool. An invalid value
/// is an error naming the variable, and leaves the pool unstarted. If the pool already runs
/// (another library in the process started it), it is left as it is (`started_here` false,
/// unbound).
pub fn start_global_pool() -> Result<PoolInfo> {
    if let Some(info) = STARTED.get() {
        return Ok(info.clone());
    }
    let planned = pool_info()?;
    let to_bind = planned.cpus.clone();
    let built = rayon::ThreadPoolBuilder::new()
        .num_threads(planned.threads)
        .start_handler(move |i| {
            if let Some(&cpu) = to_bind.get(i) {
                if bind_current_thread(cpu) {
                    BOUND.fetch_add(1, Ordering::Relaxed);
                }
            }
        })
        .build_global();
    let info = match built {
        Ok(()) => PoolInfo { started: true, started_here: true, ..planned },
        Err(_) => PoolInfo { threads: rayon::current_num_threads(), cpus: Vec::new(), started: true, started_here: false, ..planned },
    };
    Ok(STARTED.get_or_init(|| info).clone())
}

/// Idle pools of a given size for calls asked to run on `n` threads, with the process id that
/// built them (a child forked after they started cannot use their threads, and builds its own).
static IDLE: std::sync::Mutex<Vec<(u32, usize, rayon::ThreadPool)>> = std::sync::Mutex::new(Vec::new());

/// A pool of `n` workers lent to one call ([`pool_of_size`]); dropped, it waits idle for the
/// next call asking for `n`.
pub struct SizedPool {
    n: usize,
    pool: Option<rayon::ThreadPool>,
}

impl SizedPool {
    /// Run `f` on this pool's workers.
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool.as_ref().expect("a lent pool until dropped").install(f)
    }

    /// Its workers.
    pub fn threads(&self) -> usize {
        self.n
    }
}

impl Drop for SizedPool {
    fn drop(&mut self) {
        if let Some(pool) = self.pool.take() {
            IDLE.lock().unwrap_or_else(|e| e.into_inner()).push((std::process::id(), self.n, pool));
        }
    }
}

/// The pool a call asked to run on `n` threads runs on: None for the global pool (started here)
/// when it has (or will have) `n` workers, else a pool of `n` workers of its own, an idle one
/// kept from an earlier call or, when none is idle (the first call, or calls running at the
/// same time: each has its own pool, as if it had built it), a new one, its workers bound by
/// [`plan`] as the global pool's are. A pool built per call cost its threads' start and,
/// unbound, ran a 2-ms map on two threads at one thread's speed (the standard map: 3.99 ms with
/// `threads=2` against 2.38 ms on the global pool, 2-core Intel Xeon). `n` is at least 1 (the
/// callers check it).
pub fn pool_of_size(n: usize) -> Result<Option<SizedPool>> {
    // the global pool's size, without starting it (a process that only asks for other sizes
    // never starts it, and a child it forks can run its own pools)
    if pool_info()?.threads == n {
        start_global_pool()?;
        return Ok(None);
    }
    let pid = std::process::id();
    {
        let mut idle = IDLE.lock().unwrap_or_else(|e| e.into_inner());
        // pools inherited through fork have no threads in this process: never dropped (their
        // registry would wait for workers that do not exist), never used
        let (here, inherited): (Vec<_>, Vec<_>) = std::mem::take(&mut *idle).into_iter().partition(|p| p.0 == pid);
        inherited.into_iter().for_each(std::mem::forget);
        *idle = here;
        if let Some(i) = idle.iter().position(|p| p.1 == n) {
            let (_, _, pool) = idle.swap_remove(i);
            return Ok(Some(SizedPool { n, pool: Some(pool) }));
        }
    }
    let to_bind = plan(binding_from_env()?, n, &allowed_cpus());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .thread_name(move |i| format!("librate-{n}-{i}"))
        .start_handler(move |i| {
            if let Some(&cpu) = to_bind.get(i) {
                bind_current_thread(cpu);
            }
        })
        .build()
        .map_err(|e| invalid("threads", format!("could not start {n} threads: {e}")))?;
    Ok(Some(SizedPool { n, pool: Some(pool) }))
}

/// Calls of [`run_polled`] and [`spawn`]ed work in flight.
static CALLS: AtomicUsize = AtomicUsize::new(0);

/// One call in flight (counted in [`CALLS`] by its maker), until dropped.
struct InFlight;

impl Drop for InFlight {
    fn drop(&mut self) {
        CALLS.fetch_sub(1, Ordering::AcqRel);
    }
}

/// The value from `rx`, running `poll` every `every` while it is not there; None when the
/// sender was dropped unsent.
fn receive_polled<T>(rx: &std::sync::mpsc::Receiver<T>, every: std::time::Duration, poll: &mut dyn FnMut()) -> Option<T> {
    use std::sync::mpsc::RecvTimeoutError;
    loop {
        match rx.recv_timeout(every) {
            Ok(out) => return Some(out),
            Err(RecvTimeoutError::Timeout) => poll(),
            Err(RecvTimeoutError::Disconnected) => return None,
        }
    }
}

/// Work started on the global pool by [`spawn`], to be waited for later; dropped unwaited, the
/// work still runs to its end and its result is discarded.
pub struct Pending<T> {
    rx: std::sync::mpsc::Receiver<std::thread::Result<T>>,
}

/// Start `f` as a job on the global pool and return at once: the caller goes on with other work
/// (the Python facade builds a result's containers while a map's solutions are refined) and
/// waits with [`Pending::wait_polled`]. The job counts as a call in flight for [`run_polled`]
/// until it has returned, so calls made meanwhile run on threads of their own.
pub fn spawn<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> Result<Pending<T>> {
    start_global_pool()?;
    CALLS.fetch_add(1, Ordering::AcqRel);
    let (tx, rx) = std::sync::mpsc::channel();
    rayon::spawn(move || {
        let in_flight = InFlight;
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        drop(in_flight);
        let _ = tx.send(out);
    });
    Ok(Pending { rx })
}

impl<T> Pending<T> {
    /// Wait for the work while running `poll` every `every` (as [`run_polled`]); a panic in the
    /// work resumes here.
    pub fn wait_polled(self, every: std::time::Duration, mut poll: impl FnMut()) -> T {
        match receive_polled(&self.rx, every, &mut poll) {
            Some(Ok(out)) => out,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => unreachable!("a spawned job sends its outcome, value or panic"),
        }
    }
}

/// Run `f` while the calling thread runs `poll` every `every` until `f` has returned (the Python
/// binding polls its signal handlers so); a panic in `f` resumes on the calling thread.
///
/// A call alone runs `f` as a job on a worker of the global pool: its parallel loops then split
/// from inside the pool, and no thread is started (a thread started per call cost 30-70 us).
/// A call made while another is in flight runs `f` on a thread of its own instead, as every call
/// did before: a worker waiting inside one call's parallel loop takes up whatever job is queued,
/// and a whole second call queued as one job could run to its end inside the first one, holding
/// it back; started on its own thread, a call queues only its loops' pieces.
pub fn run_polled<T: Send>(f: impl FnOnce() -> T + Send, every: std::time::Duration, mut poll: impl FnMut()) -> Result<T> {
    start_global_pool()?;
    let alone = CALLS.fetch_add(1, Ordering::AcqRel) == 0;
    let _in_flight = InFlight;
    let (tx, rx) = std::sync::mpsc::channel();
    // f panicked (tx dropped unsent, None): the scope's end resumes that panic
    let wait = |rx: std::sync::mpsc::Receiver<T>, poll: &mut dyn FnMut()| receive_polled(&rx, every, poll);
    let out = if alone {
        rayon::in_place_scope(|s| {
            s.spawn(move |_| {
                let _ = tx.send(f());
            });
            wait(rx, &mut poll)
        })
    } else {
        std::thread::scope(|s| {
            let job = s.spawn(move || {
                let _ = tx.send(f());
            });
            let out = wait(rx, &mut poll);
            if let Err(panic) = job.join() {
                std::panic::resume_unwind(panic);
            }
            out
        })
    };
    Ok(out.expect("a job that neither returned nor panicked"))
}

/// The CPUs this process may run on, ascending (empty where unknown: not Linux).
pub fn allowed_cpus() -> Vec<usize> {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: cpu_set_t is plain data; sched_getaffinity fills at most its size.
        unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
                return Vec::new();
            }
            (0..libc::CPU_SETSIZE as usize).filter(|&c| libc::CPU_ISSET(c, &set)).collect()
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        Vec::new()
    }
}

/// Bind the calling thread to `cpu`; whether the kernel accepted it.
fn bind_current_thread(cpu: usize) -> bool {
    #[cfg(target_os = "linux")]
    {
        if cpu >= libc::CPU_SETSIZE as usize {
            return false;
        }
        // SAFETY: as in allowed_cpus; pid 0 is the calling thread.
        unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_SET(cpu, &mut set);
            libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = cpu;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Held by the tests whose calls count in [`CALLS`] (run_polled decides from it where a call
    /// runs, and one test asserts that): cargo runs a module's tests on parallel threads.
    static CALLS_TESTS: std::sync::Mutex<()> = std::sync::Mutex::new(());

    #[test]
    fn spawned_work_returns_its_value_or_resumes_its_panic_on_wait() {
        use rayon::prelude::*;
        let _calls = CALLS_TESTS.lock().unwrap_or_else(|e| e.into_inner());
        let every = std::time::Duration::from_millis(1);
        let pending = spawn(|| (0..1000u64).sum::<u64>()).unwrap();
        let mut polls = 0;
        assert_eq!(pending.wait_polled(every, || polls += 1), 499_500);
        let pending = spawn(|| -> u64 { panic!("boom") }).unwrap();
        let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| pending.wait_polled(every, || {})));
        let msg = caught.unwrap_err().downcast_ref::<&str>().copied();
        assert_eq!(msg, Some("boom"));
        // dropped unwaited: the work still runs (and its parallel loops too)
        let (tx, rx) = std::sync::mpsc::channel();
        drop(spawn(move || tx.send((0..100u64).into_par_iter().sum::<u64>()).unwrap()).unwrap());
        assert_eq!(rx.recv().unwrap(), 4950);
    }

    #[test]
    fn binding_values_parse_and_bad_ones_name_the_variable() {
        assert_eq!(parse_binding(None).unwrap(), Binding::Auto);
        assert_eq!(parse_binding(Some(" AUTO ")).unwrap(), Binding::Auto);
        assert_eq!(parse_binding(Some("on")).unwrap(), Binding::On);
        assert_eq!(parse_binding(Some("0")).unwrap(), Binding::Off);
        let e = parse_binding(Some("cores")).unwrap_err().to_string();
        assert!(e.contains(BIND_VAR) && e.contains("auto, on or off") && e.contains("cores"), "{e}");
    }

    #[test]
    fn auto_binds_only_a_pool_that_covers_every_allowed_cpu() {
        // a full pool: worker i on the i-th allowed CPU (which need not be CPU i)
        assert_eq!(plan(Binding::Auto, 2, &[2, 5]), vec![2, 5]);
        // narrowed pools, and a single CPU, are left to the kernel
        assert!(plan(Binding::Auto, 1, &[0, 1]).is_empty());
        assert!(plan(Binding::Auto, 3, &[0, 1]).is_empty());
        assert!(plan(Binding::Auto, 1, &[3]).is_empty());
        // on: round robin in any case; off: never; unknown CPUs: never
        assert_eq!(plan(Binding::On, 3, &[0, 1]), vec![0, 1, 0]);
        assert!(plan(Binding::Off, 2, &[0, 1]).is_empty());
        assert!(plan(Binding::On, 2, &[]).is_empty());
    }

    /// One test for every property of run_polled: the calls of concurrent tests would change
    /// which path each takes.
    #[test]
    fn run_polled_returns_polls_resumes_a_panic_and_runs_a_concurrent_call_on_its_own_thread() {
        let _calls = CALLS_TESTS.lock().unwrap_or_else(|e| e.into_inner());
        let every = std::time::Duration::from_millis(5);
        let v = vec![1.0f64; 1000];
        let mut polls = 0;
        let sum = run_polled(
            || {
                std::thread::sleep(std::time::Duration::from_millis(30));
                rayon::current_thread_index().map(|_| v.iter().sum::<f64>())
            },
            every,
            || polls += 1,
        )
        .unwrap();
        // alone: ran on a worker of the global pool, borrowing v; polled meanwhile
        assert_eq!(sum, Some(1000.0));
        assert!(polls >= 2, "{polls}");
        for alone in [true, false] {
            let r = std::thread::scope(|s| {
                let (hold, held) = std::sync::mpsc::channel::<()>();
                let (started, has_started) = std::sync::mpsc::channel::<()>();
                let first = (!alone).then(|| {
                    s.spawn(move || {
                        run_polled(
                            move || {
                                started.send(()).unwrap();
                                let _ = held.recv(); // until `hold` is dropped
                            },
                            every,
                            || (),
                        )
                    })
                });
                if first.is_some() {
                    has_started.recv().unwrap();
                }
                let r = std::panic::catch_unwind(|| run_polled(|| -> u8 { panic!("boom") }, every, || ()).unwrap());
                // a second call while the first is in flight: on a thread of its own
                let on_worker = run_polled(|| rayon::current_thread_index().is_some(), every, || ()).unwrap();
                assert_eq!(on_worker, alone);
                drop(hold);
                if let Some(h) = first {
                    h.join().unwrap().unwrap();
                }
                r
            });
            let msg = r.unwrap_err();
            assert_eq!(msg.downcast_ref::<&str>(), Some(&"boom"));
        }
    }

    /// pool_of_size: the global pool for its own size; any other size a pool of its own per
    /// call, kept idle between calls (the same workers on the next call), and two calls at the
    /// same time have two pools (neither waits for the other's workers).
    #[test]
    fn a_sized_pool_is_kept_between_calls_and_concurrent_calls_have_their_own() {
        let global = pool_info().unwrap();
        assert!(pool_of_size(global.threads).unwrap().is_none());
        // a size no other test asks for
        let n = global.threads + 3;
        let ids = |p: &SizedPool| {
            let mut v = p.install(|| rayon::broadcast(|_| std::thread::current().id()));
            v.sort_by_key(|id| format!("{id:?}"));
            v
        };
        let a = pool_of_size(n).unwrap().unwrap();
        assert_eq!(a.threads(), n);
        assert_eq!(a.install(rayon::current_num_threads), n);
        let first = ids(&a);
        let name = a.install(|| std::thread::current().name().map(str::to_owned));
        assert!(name.as_deref().is_some_and(|s| s.starts_with(&format!("librate-{n}-"))), "{name:?}");
        // while a is lent, another call gets another pool
        let b = pool_of_size(n).unwrap().unwrap();
        let second = ids(&b);
        assert!(first.iter().all(|id| !second.contains(id)));
        drop(b);
        drop(a);
        // both idle now: the next two calls reuse them, no new threads
        let c = pool_of_size(n).unwrap().unwrap();
        let d = pool_of_size(n).unwrap().unwrap();
        let mut seen = ids(&c);
        seen.extend(ids(&d));
        assert!(first.iter().chain(&second).all(|id| seen.contains(id)));
        // two calls at once run at once: each waits until both have started
        let barrier = std::sync::Barrier::new(2);
        std::thread::scope(|s| {
            for p in [&c, &d] {
                let barrier = &barrier;
                s.spawn(move || p.install(|| barrier.wait()));
            }
        });
    }

    #[test]
    fn the_global_pool_starts_once_and_binds_what_it_planned() {
        let a = start_global_pool().unwrap();
        let b = start_global_pool().unwrap();
        assert_eq!(a, b);
        assert!(a.started && pool_info().unwrap() == a);
        // the workers bind as they start: wait for every worker to have run a job
        rayon::broadcast(|_| ());
        if a.started_here {
            assert_eq!(a.threads, rayon::current_num_threads());
            assert_eq!(a.bound(), a.cpus.len(), "planned {:?}", a.cpus);
        }
    }
}
