//! Time integration (HHT), static load stepping, Newton–Raphson and sparse linear algebra.
//!
//! [`run`] drives an analysis of a [`Model`] and reports every accepted state to an
//! [`Observer`] (the output writers), so a run that stops early has already delivered
//! what it computed.

pub mod energy_guard;
pub mod integrator;
pub mod linear;
pub mod redundancy;
pub mod state;
pub mod system;

pub use integrator::{AlphaParams, Integrator, StepInfo};
pub use system::{BuildError, System};

use crate::model::{Analysis, Model, Scheme};
use std::time::Instant;

/// Counters of a run (written to `summary.json`).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Newton iterations of accepted steps.
    pub newton_iterations: u64,
    /// Numeric LU factorisations (accepted and rejected attempts).
    pub factorizations: u64,
    /// Of those, the ones that searched for pivots; the others were refactorisations on
    /// the pivots of an earlier one ([`linear`]).
    pub pivot_searches: u64,
    /// Rejected (cut) step attempts.
    pub rejected_steps: u64,
    /// Restarts of the accelerations at events (e.g. contact touches).
    pub restarts: u64,
    /// Smallest step used, s.
    pub min_step: f64,
    /// Largest step used, s.
    pub max_step: f64,
    /// CPU (wall) seconds of the integration.
    pub cpu_seconds: f64,
    /// Largest constraint violation seen at an accepted step.
    pub max_constraint_violation: f64,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq)]
pub enum FailureReason {
    /// Newton did not converge within the iteration limit.
    NoConvergence(u32),
    /// A residual or an increment became NaN or infinite.
    NotFinite,
    /// The iteration matrix could not be factored.
    Singular(String),
    /// Newton converged but an element refused the step as too long (e.g. an impact
    /// resolved by too few steps): retry with this step, s.
    StepRefused(f64),
    /// Newton converged to a state holding far more energy than the step's start state
    /// and work can pay for ([`energy_guard`]): a spurious root, refused like a divergence.
    /// (Boxed: `Failure` travels in `Result`s.)
    EnergyJump(Box<energy_guard::EnergyJump>),
    /// An element refused a step already at the run's smallest step (`MINSTEP`): its
    /// event (e.g. an impact) would be resolved by fewer steps than it needs, and
    /// accepting the step anyway can create energy (76 J of 12.5 J in a steel clearance
    /// impact with `MINSTEP = STEP`, docs/stability.md). Not retried: the run stops.
    EventUnresolved {
        /// The element that refused.
        element: crate::model::ElementId,
        /// The step it asks for, s.
        asks: f64,
    },
    /// The run was asked to stop at once ([`Integrator::abort`], e.g. a second Ctrl-C):
    /// not a failure of the step, which was given up.
    Aborted,
}

/// The diagnosis of a failed run: where, when and how badly.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// Time of the last accepted state, s.
    pub time: f64,
    /// Step size of the failed attempt, s.
    pub step: f64,
    /// What went wrong.
    pub reason: FailureReason,
    /// Relative residual at each Newton iteration of the last attempt.
    pub residual_history: Vec<f64>,
    /// The equation with the largest residual, e.g. `node 23 uy`.
    pub worst: String,
    /// Its residual, N or N·m.
    pub worst_value: f64,
    /// Reference force used to scale the residual.
    pub reference_force: f64,
    /// What the elements diagnose at the failed state ([`crate::elements::Element::diagnose`]),
    /// e.g. a universal joint at its singular configuration. (A boxed slice keeps
    /// `Failure` small: it travels in `Result`s.)
    pub diagnoses: Box<[String]>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let why = match &self.reason {
            FailureReason::NoConvergence(n) => format!("Newton did not converge in {n} iterations"),
            FailureReason::NotFinite => {
                "the solution became non-finite (NaN or infinity)".to_string()
            }
            FailureReason::Singular(s) => s.clone(),
            FailureReason::StepRefused(h) => {
                format!("an element refused the step (asks for h <= {h:.3e} s)")
            }
            FailureReason::Aborted => "the run was aborted".to_string(),
            FailureReason::EventUnresolved { element, asks } => format!(
                "element {} needs steps of at most {asks:.3e} s to resolve its event (an impact), but the step may not be cut below MINSTEP = {:.3e} s; lower MINSTEP on the ANALYSIS card",
                element.0, self.step
            ),
            FailureReason::EnergyJump(j) => format!(
                "the step created {:.3e} J of energy that no work paid for (energy in play {:.3e} J before the step, {:.3e} J after, work of the step {:.3e} J): a spurious solution, refused",
                j.created, j.before, j.after, j.work
            ),
        };
        writeln!(
            f,
            "{why} at t = {:.6e} s with step h = {:.3e} s",
            self.time, self.step
        )?;
        let hist: Vec<String> = self
            .residual_history
            .iter()
            .map(|r| format!("{r:.2e}"))
            .collect();
        writeln!(f, "  relative residual by iteration: [{}]", hist.join(", "))?;
        write!(
            f,
            "  largest residual: {} = {:.3e} (reference force {:.3e})",
            self.worst, self.worst_value, self.reference_force
        )?;
        for d in &self.diagnoses {
            write!(f, "\n  diagnosis: {d}")?;
        }
        Ok(())
    }
}

/// A snapshot of an accepted state, handed to observers.
pub struct Snapshot<'a> {
    /// The integrator (state, system, counters).
    pub integ: &'a Integrator,
    /// Step index (0 = initial state).
    pub step: u64,
    /// Step size that led here (0 at the start).
    pub h: f64,
}

/// Receives the states of a run as they are accepted.
pub trait Observer {
    /// Called with the initial state and each accepted state. An error stops the run.
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()>;
    /// Whether [`Observer::state`] reads this state's multipliers or accelerations (a
    /// joint's reaction, a driver's torque, node accelerations). For a stage scheme (ESDIRK)
    /// the run then hands it the values of the index-1 equations at the state's `(q, v)`
    /// instead of the last stage's, which are a stage order less accurate
    /// ([`Integrator::exact_reactions`]); this costs a factorisation, so an observer that
    /// writes only some states (`OUTPUT … EVERY n`) or reads only positions says no for the
    /// others. Default: yes.
    fn reads_reactions(&self, _snap: &Snapshot) -> bool {
        true
    }
    /// Progress: time reached and end time.
    fn progress(&mut self, _t: f64, _end: f64, _stats: &Stats) {}
    /// A pause between two steps: after the initial state and after each accepted step,
    /// once the step controller has chosen the next step. The state is complete here
    /// ([`Integrator::save_state`] and `ctl`): a checkpoint taken now restarts bit for
    /// bit. [`Pause::Stop`] ends the run here, as interrupted. An error stops the run.
    fn pause(&mut self, _integ: &Integrator, _ctl: &LoopState) -> std::io::Result<Pause> {
        Ok(Pause::Continue)
    }
}

/// An observer's decision at a pause between two steps ([`Observer::pause`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pause {
    /// Go on.
    Continue,
    /// End the run here (an interruption): the state is that of the last accepted step.
    Stop,
}

/// The step controller's state between two steps (the rest of the run loop's state is
/// the integrator's or derived from the model): the nominal step, the count of good
/// steps since a cut, and the step an element asked for after refusing one.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LoopState {
    /// Nominal next step, s.
    pub h: f64,
    /// Accepted steps since the step was last cut (fixed steps double back after 4).
    pub good: u32,
    /// The step an element asked for, tried once before `h`.
    pub retry: Option<f64>,
}

/// How a run ended before its end time without failing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interruption {
    /// Stopped at a pause between two steps ([`Pause::Stop`]): the state is that of the
    /// last accepted step, and a checkpoint of it restarts the run.
    AtStep,
    /// Aborted within a step ([`Integrator::abort`]): the integrator's state is not that
    /// of a step's end (the LU may have been refactored); only an earlier checkpoint
    /// restarts the run.
    WithinStep,
}

/// Result of a run.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// Counters.
    pub stats: Stats,
    /// Time (or load factor) reached.
    pub time: f64,
    /// The diagnosis if the run stopped before its end.
    pub failure: Option<Failure>,
    /// Whether (and how) the run was interrupted before its end (not a failure).
    pub interrupted: Option<Interruption>,
}

/// Errors that prevent a run from starting or continuing.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The system could not be built.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// An observer failed (e.g. disk full).
    #[error("writing output failed: {0}")]
    Output(#[from] std::io::Error),
}

/// Builds the integrator for a model (initial velocities applied, not yet initialised).
pub fn prepare(model: &Model) -> Result<Integrator, BuildError> {
    let sys = System::new(model)?;
    let mut integ = match &model.analysis {
        Analysis::Dynamic { scheme, newton, .. } => {
            Integrator::new(sys, newton.clone(), *scheme, true)
        }
        Analysis::Static { newton, .. } => {
            Integrator::new(sys, newton.clone(), Scheme::Hht { alpha: 0.0 }, false)
        }
    };
    if integ.dynamic {
        for iv in &model.initial {
            if let Some(i) = model.nodes.get_index_of(&iv.node) {
                integ.set_velocity(i, iv.velocity, iv.angular);
            }
        }
    }
    Ok(integ)
}

/// Hands an accepted state to the observer. For a stage scheme, with the multipliers and
/// accelerations of the index-1 equations at the state's `(q, v)` when the observer reads
/// them ([`Observer::reads_reactions`], [`Integrator::exact_reactions`]); the stage values
/// come back after it, so the integration does not depend on what is observed.
fn observe(
    integ: &mut Integrator,
    obs: &mut dyn Observer,
    step: u64,
    h: f64,
) -> std::io::Result<()> {
    let exact = integ.is_esdirk()
        && obs.reads_reactions(&Snapshot { integ, step, h })
        && integ.exact_reactions();
    let seen = obs.state(&Snapshot { integ, step, h });
    if exact {
        integ.restore_stage_values();
    }
    seen
}

/// The adaptive step after `h` when the error estimate proposes `proposal`: the largest
/// rung `h₀·2^(k/4)` not above the proposal; a larger step only if that is at least two
/// rungs (×1.41) above `h`, else `h` is kept.
pub fn ladder_step(h: f64, proposal: f64, h0: f64) -> f64 {
    let rung = |x: f64| h0 * 2f64.powf((4.0 * (x / h0).log2() + 1e-9).floor() / 4.0);
    let q = rung(proposal);
    if proposal < h || q >= h * 2f64.sqrt() * (1.0 - 1e-9) {
        q
    } else {
        h
    }
}

/// Runs the model's analysis, reporting every accepted state to `obs`.
pub fn run(model: &Model, obs: &mut dyn Observer) -> Result<RunReport, RunError> {
    let mut integ = prepare(model)?;
    run_prepared(model, &mut integ, obs)
}

/// Runs an already prepared integrator (lets callers set initial conditions first).
pub fn run_prepared(
    model: &Model,
    integ: &mut Integrator,
    obs: &mut dyn Observer,
) -> Result<RunReport, RunError> {
    run_from(model, integ, obs, None)
}

/// Runs an already prepared integrator from its initial state (`resume = None`), or goes
/// on from a restored state ([`Integrator::restore_state`]) with the step controller's
/// state saved with it: the initial state is then neither recomputed nor observed, and
/// the CPU seconds add to those of the restored counters.
pub fn run_from(
    model: &Model,
    integ: &mut Integrator,
    obs: &mut dyn Observer,
    resume: Option<LoopState>,
) -> Result<RunReport, RunError> {
    let start = Instant::now();
    let cpu0 = if resume.is_some() {
        integ.stats.cpu_seconds
    } else {
        0.0
    };
    let (end, h0, hmin, hmax) = match &model.analysis {
        Analysis::Dynamic {
            step,
            end,
            min_step,
            max_step,
            ..
        } => (*end, *step, *min_step, *max_step),
        Analysis::Static { steps, .. } => {
            let h = 1.0 / f64::from((*steps).max(1));
            (1.0, h, h / 1024.0, h)
        }
    };
    if let Analysis::Dynamic { adaptive, .. } = &model.analysis {
        integ.adaptive = adaptive.clone();
    }
    let adaptive = integ.adaptive.is_some();
    integ.event_floor = hmin;
    let mut failure = None;
    if resume.is_none() {
        integ.stats.min_step = f64::INFINITY;
        failure = integ.initialize().err();
        if failure.is_none() {
            observe(integ, obs, 0, 0.0)?;
        }
    }
    // Breakpoints of load functions: steps land on them rather than straddle a kink.
    let mut breaks: Vec<f64> = integ
        .sys
        .loads
        .iter()
        .filter_map(|l| l.function.as_ref())
        .flat_map(|f| f.breakpoints())
        .filter(|t| *t > 0.0 && *t < end)
        .collect();
    // Drivers' breakpoints too: there a prescribed acceleration may jump (the haversine's
    // ends), and the accelerations restart from the law's new value once a step lands on
    // one (as after a contact's touch: no step straddles the jump).
    let mut drive_breaks: Vec<f64> = model
        .driver_functions()
        .iter()
        .flat_map(|f| f.breakpoints())
        .filter(|t| *t > 0.0 && *t < end)
        .collect();
    drive_breaks.sort_by(f64::total_cmp);
    breaks.extend_from_slice(&drive_breaks);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let ctl = resume.unwrap_or(LoopState {
        h: h0,
        good: 0,
        retry: None,
    });
    let mut h = ctl.h;
    let mut good = ctl.good;
    let eps = 1e-9 * h0;
    // A step an element asked for after refusing one (an event's time): tried once, the
    // nominal step `h` stays as it was.
    let mut retry: Option<f64> = ctl.retry;
    // Pauses come after the initial state and after each accepted step (not after a
    // refused attempt, nor at once after a restart: that state was the last pause's).
    let mut pause_due = resume.is_none();
    let mut interrupted = None;
    while failure.is_none() && integ.t < end - eps {
        if pause_due {
            pause_due = false;
            let ctl = LoopState { h, good, retry };
            if obs.pause(integ, &ctl)? == Pause::Stop {
                interrupted = Some(Interruption::AtStep);
                break;
            }
        }
        let t = integ.t;
        let mut h_try = retry
            .take()
            .unwrap_or(h)
            .min(end - t)
            .min(integ.step_cap.max(hmin));
        if !adaptive {
            // Fixed steps come back to the grid t = k h₀ after an event moved them off it,
            // so that histories keep their sampling times.
            // (t is a sum of steps: "on the grid" within round-off, and never a sliver.)
            let k = (t / h0).round();
            let next_grid = if (t - k * h0).abs() <= 1e-6 * h0 {
                (k + 1.0) * h0
            } else {
                (t / h0).ceil() * h0
            };
            let mut to_grid = next_grid - t;
            if to_grid < 1e-3 * h0 {
                to_grid += h0;
            }
            h_try = h_try.min(to_grid);
        }
        // A breakpoint closer than 1e-3 h_try ahead counts as reached (round-off: t, a sum
        // of steps, is 2.4e-15 s short of 0.02 s after 10,240 steps of 1.953125e-6 s), and
        // a step ending that close to one ends on it: never a sliver of a step, whose
        // 1/(βh²) would swamp the iteration matrix and whose accelerations would be
        // position round-off over βh². Straddling a kink by 1e-3 h errs by O(1e-3 h²)
        // of the slope's jump, as the same rule at the end of the run.
        let near = 1e-3 * h_try;
        if let Some(b) = breaks.iter().find(|b| **b > t + near)
            && t + h_try > *b - near
        {
            h_try = *b - t;
        }
        // Never leave a sliver of a step before the end (round-off in t would otherwise
        // ask Newton for a step of 1e-11 s).
        if end - (t + h_try) < 1e-3 * h_try {
            h_try = end - t;
        }
        match integ.try_step(h_try) {
            Ok(_) => {
                integ.stats.min_step = integ.stats.min_step.min(h_try);
                integ.stats.max_step = integ.stats.max_step.max(h_try);
                let v = integ.constraint_violation();
                integ.stats.max_constraint_violation = integ.stats.max_constraint_violation.max(v);
                integ.stats.cpu_seconds = cpu0 + start.elapsed().as_secs_f64();
                integ.stats.pivot_searches = integ.sys.matrix.pivoting_factorizations();
                pause_due = true;
                observe(integ, obs, integ.stats.steps, h_try)?;
                obs.progress(integ.t, end, &integ.stats);
                if integ.dynamic
                    && drive_breaks.iter().any(|b| (integ.t - b).abs() <= near)
                    && integ.consistent_accelerations().is_ok()
                {
                    integ.stats.restarts += 1;
                }
                good += 1;
                if adaptive {
                    // The local error estimate proposes the next step; it is taken from
                    // a ladder h₀·2^(k/4), and grows only by two rungs or more, so that
                    // runs of equal steps keep the factored matrix (modified Newton).
                    h = ladder_step(h, integ.error_next, h0).clamp(hmin, hmax);
                } else if h < h0 && good >= 4 {
                    h = (2.0 * h).min(h0);
                    good = 0;
                }
            }
            Err(Failure {
                reason: FailureReason::Aborted,
                ..
            }) => {
                interrupted = Some(Interruption::WithinStep);
                break;
            }
            Err(Failure {
                reason: FailureReason::StepRefused(h_ok),
                residual_history,
                ..
            }) => {
                // An element (e.g. a contact at an impact) asks for a shorter step.
                integ.recycle_history(residual_history);
                integ.stats.rejected_steps += 1;
                retry = Some(h_ok.max(hmin).min(h_try));
            }
            Err(f) => {
                integ.stats.rejected_steps += 1;
                good = 0;
                h = h_try / 2.0;
                if h < hmin * (1.0 - 1e-12) {
                    failure = Some(f);
                } else {
                    integ.recycle_history(f.residual_history);
                }
            }
        }
    }
    if integ.stats.min_step == f64::INFINITY {
        integ.stats.min_step = 0.0;
    }
    integ.stats.cpu_seconds = cpu0 + start.elapsed().as_secs_f64();
    integ.stats.pivot_searches = integ.sys.matrix.pivoting_factorizations();
    Ok(RunReport {
        stats: integ.stats,
        time: integ.t,
        failure,
        interrupted,
    })
}

#[cfg(test)]
mod tests {
    use super::ladder_step;

    /// Whether `h` is a rung `h0 2^(k/4)` (to round-off).
    fn is_rung(h: f64, h0: f64) -> bool {
        let k = 4.0 * (h / h0).log2();
        (k - k.round()).abs() < 1e-6
    }

    /// The adaptive ladder: a shrinking proposal gives the largest rung not above it; a
    /// growing one is taken (as its rung) only from two rungs (×√2) above the current step,
    /// else the step is kept, so that runs of equal steps keep the factored matrix.
    #[test]
    fn ladder_steps_are_rungs_below_the_proposal_and_grow_by_two_rungs() {
        let h0 = 1e-4;
        let r = 2f64.powf(0.25);
        // Shrinking: the largest rung ≤ proposal.
        for p in [0.99e-4, 0.5e-4, 0.3e-4, 1.234e-6] {
            let q = ladder_step(h0, p, h0);
            assert!(
                is_rung(q, h0) && q <= p * (1.0 + 1e-12) && q * r > p,
                "{p:e} -> {q:e}"
            );
        }
        // A rung proposal maps to itself (no round-off drift to the rung below).
        for k in -8..=8 {
            let rung = h0 * 2f64.powf(f64::from(k) / 4.0);
            assert_eq!(ladder_step(rung, rung, h0), rung);
        }
        // Growing by less than two rungs: kept.
        assert_eq!(ladder_step(h0, h0 * r * 1.1, h0), h0);
        // By two rungs or more: the largest rung ≤ proposal.
        let q = ladder_step(h0, h0 * r * r * 1.01, h0);
        assert!(is_rung(q, h0) && (q / (h0 * r * r) - 1.0).abs() < 1e-12);
        let q = ladder_step(h0, 10.0 * h0, h0);
        assert!(is_rung(q, h0) && q <= 10.0 * h0 && q * r > 10.0 * h0);
    }
}
