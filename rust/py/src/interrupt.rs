//! Ctrl-C during long core calls: the call runs with the GIL released on a worker of the pool
//! (on a thread of its own while another call is in flight: `librate_core::threads::run_polled`)
//! while the calling thread runs Python's signal handlers every 50 ms. When one raises (SIGINT:
//! KeyboardInterrupt), the core's interrupt flag stops the call's loops at their next poll
//! (a map chunk, a Newton iteration, a batch member) and that exception is returned; work the
//! Python caller finished in earlier calls is kept by its own chunking. Work started to be
//! joined later (`librate_core::threads::spawn`) is waited for the same way ([`join`]).

use std::time::Duration;

use librate_core::interrupt;
use librate_core::threads::Pending;
use pyo3::prelude::*;

use crate::to_py;

/// How often the signal handlers run during a call.
const POLL: Duration = Duration::from_millis(50);

/// Run `f` with the GIL released, interruptible by Ctrl-C (see the module docs).
pub(crate) fn interruptible<T: Send>(py: Python<'_>, f: impl FnOnce() -> librate_core::Result<T> + Send) -> PyResult<T> {
    interrupt::clear();
    polled(py, |poll| librate_core::threads::run_polled(f, POLL, poll).and_then(|r| r))
}

/// Start `f` on the pool and return at once; [`join`] waits for it (see the module docs).
pub(crate) fn start<T: Send + 'static>(f: impl FnOnce() -> librate_core::Result<T> + Send + 'static) -> PyResult<Pending<librate_core::Result<T>>> {
    interrupt::clear();
    librate_core::threads::spawn(f).map_err(to_py)
}

/// Wait for work [`start`]ed, with the GIL released, interruptible by Ctrl-C: the work is asked
/// to stop and waited for, and the handler's exception returned.
pub(crate) fn join<T: Send>(py: Python<'_>, pending: Pending<librate_core::Result<T>>) -> PyResult<T> {
    polled(py, |poll| pending.wait_polled(POLL, poll))
}

/// `wait(poll)` with the GIL released, `poll` running the signal handlers; a handler's exception
/// requests the core's interrupt and wins over the outcome.
fn polled<T: Send>(py: Python<'_>, wait: impl FnOnce(&mut dyn FnMut()) -> librate_core::Result<T> + Send) -> PyResult<T> {
    let (out, signal) = py.detach(|| {
        let mut signal: Option<PyErr> = None;
        let out = wait(&mut || {
            if signal.is_none() {
                if let Err(e) = Python::attach(|py| py.check_signals()) {
                    interrupt::request();
                    signal = Some(e);
                }
            }
        });
        (out, signal)
    });
    interrupt::clear();
    match signal {
        // the handler's exception wins over the call's outcome (finished or stopped)
        Some(e) => Err(e),
        None => out.map_err(to_py),
    }
}
