//! The force law of a contact state (eq. [17]): closed or open, the applied (clipped) normal
//! force, the active set's anti-chatter memory, and the dissipated power.

use super::{Came, ContactState, MAX_FLIPS};
use crate::elements::EvalContext;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};

/// The active set's anti-chatter memory of one step attempt (shared by the contact
/// elements, CAME and CLEARANCE): within one attempt (same `t`, `h`), after [`MAX_FLIPS`]
/// changes of the active flag the flag is frozen at its last value. Interior-mutable,
/// since `evaluate` takes `&self`.
#[derive(Debug)]
pub(crate) struct ActiveSetMemory {
    attempt: AtomicU64,
    flips: AtomicU32,
    last_flag: AtomicBool,
}

impl ActiveSetMemory {
    /// No attempt seen yet.
    pub(crate) fn new() -> Self {
        ActiveSetMemory {
            attempt: AtomicU64::new(u64::MAX),
            flips: AtomicU32::new(0),
            last_flag: AtomicBool::new(false),
        }
    }

    /// The active flag to use for the raw flag `raw` at an evaluation in `ctx`.
    pub(crate) fn flag(&self, ctx: &EvalContext, raw: bool) -> bool {
        if !ctx.dynamic || ctx.h <= 0.0 {
            return raw;
        }
        let key = ctx.t.to_bits() ^ ctx.h.to_bits().rotate_left(17);
        if self.attempt.swap(key, Ordering::Relaxed) != key {
            self.flips.store(0, Ordering::Relaxed);
            self.last_flag.store(raw, Ordering::Relaxed);
            return raw;
        }
        let last = self.last_flag.load(Ordering::Relaxed);
        if raw == last {
            return raw;
        }
        if self.flips.fetch_add(1, Ordering::Relaxed) + 1 > MAX_FLIPS {
            return last;
        }
        self.last_flag.store(raw, Ordering::Relaxed);
        raw
    }

    /// The memory, for a checkpoint: `(attempt, flips, last_flag)`.
    pub(crate) fn save(&self) -> (u64, u32, bool) {
        (
            self.attempt.load(Ordering::Relaxed),
            self.flips.load(Ordering::Relaxed),
            self.last_flag.load(Ordering::Relaxed),
        )
    }

    /// Restores what [`ActiveSetMemory::save`] returned.
    pub(crate) fn restore(&self, (attempt, flips, last_flag): (u64, u32, bool)) {
        self.attempt.store(attempt, Ordering::Relaxed);
        self.flips.store(flips, Ordering::Relaxed);
        self.last_flag.store(last_flag, Ordering::Relaxed);
    }
}

impl Came {
    /// Whether the contact is closed at a state: penetrating, or within the landing
    /// tolerance of a touch event the committed state sits on.
    pub(super) fn closed(&self, st: &ContactState<f64>) -> bool {
        st.gap < 0.0 || (self.touching && st.gap <= self.touch_tol)
    }

    /// The normal force actually applied (compressive, N) for a contact state.
    pub(super) fn applied(&self, st: &ContactState<f64>) -> f64 {
        if !self.closed(st) {
            0.0
        } else if self.clip {
            st.force.max(0.0)
        } else {
            st.force
        }
    }

    /// Active flag with the per-attempt anti-chatter memory.
    pub(super) fn active_flag(&self, ctx: &EvalContext, raw: bool) -> bool {
        self.memory.flag(ctx, raw)
    }

    /// Dissipated power (dashpot, clipped spring energy, friction) at a contact state.
    pub(super) fn power(&self, st: &ContactState<f64>) -> f64 {
        if !self.closed(st) {
            return 0.0;
        }
        let p = self.applied(st);
        // −(power of the contact force on the bodies) − d/dt(½ k q_n²).
        let normal = -(p + self.k * st.gap) * st.gap_rate;
        let fric = if self.mu > 0.0 {
            self.mu * p.abs() * st.slip.norm_squared()
                / (st.slip.norm_squared() + self.vreg * self.vreg).sqrt()
        } else {
            0.0
        };
        normal + fric
    }
}
