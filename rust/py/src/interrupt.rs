//! Ctrl-C during long core calls: the call runs with the GIL released on a worker of the pool
//! (on a thread of its own while another call is in flight: `librate_core::threads::run_polled`)
//! while the calling thread runs Python's signal handlers every 50 ms. When one raises (SIGINT:
//! KeyboardInterrupt), the core's interrupt flag stops the call's loops at their next poll
//! (a map chunk, a Newton iteration, a batch member) and that exception is returned; work the
//! Python caller finished in earlier calls is kept by its own chunking.

use std::time::Duration;

use librate_core::interrupt;
use pyo3::prelude::*;

use crate::to_py;

/// How often the signal handlers run during a call.
const POLL: Duration = Duration::from_millis(50);

/// Run `f` with the GIL released, interruptible by Ctrl-C (see the module docs).
pub(crate) fn interruptible<T: Send>(py: Python<'_>, f: impl FnOnce() -> librate_core::Result<T> + Send) -> PyResult<T> {
    interrupt::clear();
    let (out, signal) = py.detach(|| {
        let mut signal: Option<PyErr> = None;
        let out = librate_core::threads::run_polled(f, POLL, || {
            if signal.is_none() {
                if let Err(e) = Python::attach(|py| py.check_signals()) {
                    interrupt::request();
                    signal = Some(e);
                }
            }
        });
        (out.and_then(|r| r), signal)
    });
    interrupt::clear();
    match signal {
        // the handler's exception wins over the call's outcome (finished or stopped)
        Some(e) => Err(e),
        None => out.map_err(to_py),
    }
}
