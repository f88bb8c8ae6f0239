//! SIGINT and SIGTERM: the first ends a run at the end of the step under way, the second
//! at once (within one Newton iteration).
//!
//! A thread of `signal-hook` receives the signals (no work in a signal handler) and sets
//! two flags the run reads: [`Interrupts::stop`], read between steps, where the run writes
//! a checkpoint and ends; [`Interrupts::abort`], read at each Newton iteration, where the
//! step is given up (no checkpoint then: the last one stays the restart point). Either
//! way the histories keep only whole rows and `summary.json` says why the run stopped.

use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

/// A hook a run calls at each pause between steps with the time reached, before it reads
/// [`Interrupts::stop`]: an embedding program (the Python package) polls its own signals
/// there (Python's SIGINT handler runs only when the interpreter is asked) and sets `stop`.
pub type PollHook = Arc<dyn Fn(f64) + Send + Sync>;

/// The flags the signals set.
#[derive(Clone, Default)]
pub struct Interrupts {
    /// Set by the first signal: end at the end of the step under way.
    pub stop: Arc<AtomicBool>,
    /// Set by the second: end at once.
    pub abort: Arc<AtomicBool>,
    /// The last signal received (0 = none).
    signal: Arc<AtomicI32>,
    /// Called at each pause between steps ([`Interrupts::stopping_at`]); `None` = nothing.
    pub poll: Option<PollHook>,
}

impl std::fmt::Debug for Interrupts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Interrupts")
            .field("stop", &self.stop)
            .field("abort", &self.abort)
            .field("signal", &self.signal)
            .field("poll", &self.poll.is_some())
            .finish()
    }
}

impl Interrupts {
    /// Flags no signal sets (library use, tests).
    pub fn none() -> Self {
        Self::default()
    }

    /// Gives SIGINT and SIGTERM their default action (end the process) where the process
    /// inherited them ignored — a command started in the background by a non-interactive
    /// shell (`cmd &` in a script, a batch job's wrapper) has SIGINT ignored — so that every
    /// phase hears them: a run installs its handlers over this ([`Interrupts::install`]);
    /// `--check`, `modes` and `export`, whose dense phases (an eigen-solver's QR sweeps) do
    /// not poll a flag, end at once on them, having written nothing that needs a clean
    /// stop. (The fuzzer's case 17:6222: `--check` of a 1,368-state model, 10 s of QR, sat
    /// through SIGINT for 15 s.)
    pub fn default_dispositions() {
        for sig in [libc::SIGINT, libc::SIGTERM] {
            // SAFETY: `signal` with `SIG_DFL` installs no handler (no code runs in the
            // signal's context); called first thing in `main`, before any thread exists.
            unsafe {
                libc::signal(sig, libc::SIG_DFL);
            }
        }
    }

    /// Installs the handlers of SIGINT and SIGTERM for the rest of the process.
    pub fn install() -> std::io::Result<Self> {
        let me = Self::default();
        let mut signals = Signals::new([SIGINT, SIGTERM])?;
        let (stop, abort, signal) = (me.stop.clone(), me.abort.clone(), me.signal.clone());
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                for sig in signals.forever() {
                    signal.store(sig, Ordering::SeqCst);
                    if stop.swap(true, Ordering::SeqCst) {
                        abort.store(true, Ordering::SeqCst);
                    }
                }
            })?;
        Ok(me)
    }

    /// Flags no signal sets, with a [`PollHook`] that may set [`Interrupts::stop`].
    pub fn polled(poll: PollHook) -> Self {
        Interrupts {
            poll: Some(poll),
            ..Self::default()
        }
    }

    /// The same flags without the [`PollHook`] (for the hook itself to hold: no cycle).
    pub fn flags(&self) -> Self {
        Interrupts {
            poll: None,
            ..self.clone()
        }
    }

    /// At a pause between steps at time `t`: calls the [`PollHook`], then says whether a
    /// stop was asked for.
    pub fn stopping_at(&self, t: f64) -> bool {
        if let Some(p) = &self.poll {
            p(t);
        }
        self.stopping()
    }

    /// Whether a stop was asked for.
    pub fn stopping(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    /// Records that a stop was asked for by `signal` (e.g. `libc::SIGINT` seen by an
    /// embedding program's own handler, [`Interrupts::poll`]).
    pub fn request_stop(&self, signal: i32) {
        self.signal.store(signal, Ordering::SeqCst);
        self.stop.store(true, Ordering::SeqCst);
    }

    /// The name of the last signal received (`SIGINT`, `SIGTERM`), if any.
    pub fn signal_name(&self) -> Option<&'static str> {
        match self.signal.load(Ordering::SeqCst) {
            SIGINT => Some("SIGINT"),
            SIGTERM => Some("SIGTERM"),
            _ => None,
        }
    }
}
