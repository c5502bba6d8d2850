//! A process-wide interrupt request (Ctrl-C): set by the caller (the Python binding, when a
//! signal handler raises during a long call), polled by the batch loops (the map sweeps' chunks,
//! batch propagation's members) and the Newton drivers (each iteration), which stop with
//! [`Error::Interrupted`]. Work already finished by the caller's own chunking is unaffected.
//! (No unit test sets the flag: it is process-wide, and would stop the tests running beside it;
//! tests/test_interrupt.py sends SIGINT to a subprocess.)

use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::{Error, Result};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Ask every running loop to stop at its next poll.
pub fn request() {
    REQUESTED.store(true, Ordering::Relaxed);
}

/// Withdraw the request (before a new call starts, and after an interrupted one returned).
pub fn clear() {
    REQUESTED.store(false, Ordering::Relaxed);
}

/// Whether a stop was requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// `Err(Error::Interrupted)` when a stop was requested: the poll of the loops.
#[inline]
pub fn check() -> Result<()> {
    if requested() {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

