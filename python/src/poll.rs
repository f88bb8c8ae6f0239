//! Ctrl-C and progress while Rust runs with the GIL released: at each pause between steps
//! the run calls [`mecano::interrupt::Interrupts::stopping_at`], whose hook here takes the
//! GIL at most every [`POLL`] of wall time, runs Python's signal handlers
//! (`PyErr_CheckSignals`: a KeyboardInterrupt is kept and the run asked to stop at the
//! end of this step) and calls the progress callback with `(t, end)`.

use mecano::interrupt::Interrupts;
use pyo3::prelude::*;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How often the GIL is taken between steps (signals, progress).
pub const POLL: Duration = Duration::from_millis(50);

/// The Python error that stopped a run (a KeyboardInterrupt, a progress callback's or a
/// law's exception), kept until the run returns.
pub type Pending = Arc<Mutex<Option<PyErr>>>;

/// Flags the run reads, with the hook that polls Python (see the module docs), and the
/// slot of the error that stopped it. `kept`: where a law keeps a KeyboardInterrupt it
/// caught inside the step (`law::PyLaw`); the hook moves it into that slot and asks the
/// run to stop at every pause, without the [`POLL`] delay.
pub fn interrupts(
    progress: Option<Py<PyAny>>,
    end: f64,
    kept: Option<Pending>,
) -> (Interrupts, Pending) {
    let pending: Pending = Arc::new(Mutex::new(None));
    let last = Mutex::new(Instant::now());
    let slot = pending.clone();
    let stop_flags: Arc<Mutex<Option<Interrupts>>> = Arc::new(Mutex::new(None));
    let flags = stop_flags.clone();
    let stop = move |e: PyErr, flags: &Mutex<Option<Interrupts>>| {
        let mut s = slot.lock().unwrap_or_else(|e| e.into_inner());
        if s.is_none() {
            *s = Some(e);
        }
        if let Some(i) = flags.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
            i.request_stop(libc_sigint());
        }
    };
    let hook = move |t: f64| {
        if let Some(e) = kept.as_ref().and_then(take) {
            stop(e, &flags);
            return;
        }
        {
            let mut l = last.lock().unwrap_or_else(|e| e.into_inner());
            if l.elapsed() < POLL {
                return;
            }
            *l = Instant::now();
        }
        let err = Python::attach(|py| -> Option<PyErr> {
            if let Err(e) = py.check_signals() {
                return Some(e);
            }
            if let Some(p) = &progress
                && let Err(e) = p.call1(py, (t, end))
            {
                return Some(e);
            }
            None
        });
        if let Some(e) = err {
            stop(e, &flags);
        }
    };
    let interrupts = Interrupts::polled(Arc::new(hook));
    *stop_flags.lock().unwrap_or_else(|e| e.into_inner()) = Some(interrupts.flags());
    (interrupts, pending)
}

/// SIGINT's number (2 on every POSIX system).
fn libc_sigint() -> i32 {
    2
}

/// The error kept in `pending`, if any (taken out).
pub fn take(pending: &Pending) -> Option<PyErr> {
    pending.lock().unwrap_or_else(|e| e.into_inner()).take()
}
