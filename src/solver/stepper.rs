//! The run loop as an object advanced one accepted step at a time: [`Stepper`].
//!
//! [`super::run_from`] drives it to the end time; a library user (the Python package's
//! `Simulation`) calls [`Stepper::step`] or [`Stepper::advance_to`] and reads or changes
//! the state between two steps. The loop's state lives here, the computation's state in
//! the [`Integrator`], so that the two are borrowed separately and a step sees exactly
//! what the run loop would have: a run driven step by step computes bit for bit what
//! [`super::run`] computes (`tests::stepping_is_the_run_loop`).
//!
//! What a step does (unchanged from the run loop it was taken from): breakpoints of load
//! and driver functions are landed on, fixed steps come back to the grid `k h₀` after an
//! event cut them, a refused attempt is cut in half (or retried at the step an element asks
//! for) down to the smallest step, and the adaptive step follows the ladder
//! `h₀·2^(k/4)` ([`super::ladder_step`]).

use super::{
    Failure, FailureReason, Integrator, Interruption, LoopState, Observer, Pause, RunError,
    RunReport, ladder_step,
};
use crate::model::{Analysis, Model, Scheme};
use std::time::Instant;

/// What one call of [`Stepper::step`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepOutcome {
    /// A step was accepted (the observers have seen its state).
    Accepted,
    /// The end time was already reached: nothing was done.
    Finished,
    /// The run failed (the diagnosis is in [`Stepper::failure`]); the state is that of
    /// the last accepted step.
    Failed,
    /// An observer's pause asked to stop, or the step was aborted
    /// ([`Stepper::interrupted`]).
    Interrupted,
}

/// The run loop's state between two steps (see the module docs).
#[derive(Debug, Clone)]
pub struct Stepper {
    /// End time (or load factor 1 in statics), s. [`Stepper::advance_to`] may move it
    /// later.
    pub end: f64,
    h0: f64,
    hmin: f64,
    hmax: f64,
    adaptive: bool,
    /// Breakpoints of the load and driver functions (and of [`Stepper::advance_to`]).
    breaks: Vec<f64>,
    drive_breaks: Vec<f64>,
    h: f64,
    good: u32,
    retry: Option<f64>,
    /// The α schemes' steps grow back by doubling after an event's landing
    /// ([`super::regrowth`]): whether they do, and the longest next step.
    regrows: bool,
    regrow: Option<f64>,
    /// Consecutive refused attempts (reset at each accepted step), bounded by
    /// [`super::MAX_REFUSALS`].
    refusals: u32,
    pause_due: bool,
    cpu0: f64,
    start: Instant,
    failure: Option<Failure>,
    interrupted: Option<Interruption>,
}

impl Stepper {
    /// Starts a run of `model` on a prepared integrator: from its initial state
    /// (`resume = None`: the initial accelerations are computed and the initial state
    /// observed), or from a restored state with the step controller's state saved with it.
    pub fn start(
        model: &Model,
        integ: &mut Integrator,
        obs: &mut dyn Observer,
        resume: Option<LoopState>,
    ) -> Result<Self, RunError> {
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
        integ.error_horizon = end;
        integ.event_floor = hmin;
        let mut failure = None;
        if resume.is_none() {
            integ.stats.min_step = f64::INFINITY;
            failure = integ.initialize().err();
            if failure.is_none() {
                super::observe(integ, obs, 0, 0.0)?;
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
            regrow: None,
        });
        let regrows = !adaptive
            && matches!(
                model.analysis,
                Analysis::Dynamic {
                    scheme: Scheme::Hht { .. } | Scheme::GeneralizedAlpha { .. },
                    ..
                }
            );
        Ok(Stepper {
            end,
            h0,
            hmin,
            hmax,
            adaptive,
            breaks,
            drive_breaks,
            h: ctl.h,
            good: ctl.good,
            // A step an element asked for after refusing one (an event's time): tried once,
            // the nominal step `h` stays as it was.
            retry: ctl.retry,
            // Pauses come after the initial state and after each accepted step (not after a
            // refused attempt, nor at once after a restart: that state was the last pause's).
            regrows,
            regrow: ctl.regrow,
            refusals: 0,
            pause_due: resume.is_none(),
            cpu0,
            start,
            failure,
            interrupted: None,
        })
    }

    /// The step controller's state now ([`LoopState`], what a checkpoint saves).
    pub fn control(&self) -> LoopState {
        LoopState {
            h: self.h,
            good: self.good,
            retry: self.retry,
            regrow: self.regrow,
        }
    }

    /// The diagnosis of the failure that stopped the run, if any.
    pub fn failure(&self) -> Option<&Failure> {
        self.failure.as_ref()
    }

    /// Whether (and how) the run was interrupted.
    pub fn interrupted(&self) -> Option<Interruption> {
        self.interrupted
    }

    /// Whether the run can take another step before `self.end`.
    pub fn running(&self, integ: &Integrator) -> bool {
        self.failure.is_none() && self.interrupted.is_none() && integ.t < self.end - 1e-9 * self.h0
    }

    /// Takes one accepted step (cutting and retrying refused attempts as the run loop
    /// does), after the pause between steps that is due. Errors are the observers'.
    pub fn step(
        &mut self,
        integ: &mut Integrator,
        obs: &mut dyn Observer,
    ) -> Result<StepOutcome, RunError> {
        let eps = 1e-9 * self.h0;
        let end = self.end;
        loop {
            if self.failure.is_some() {
                return Ok(StepOutcome::Failed);
            }
            if self.interrupted.is_some() {
                return Ok(StepOutcome::Interrupted);
            }
            if integ.t >= end - eps {
                return Ok(StepOutcome::Finished);
            }
            if self.pause_due {
                self.pause_due = false;
                if obs.pause(integ, &self.control())? == Pause::Stop {
                    self.interrupted = Some(Interruption::AtStep);
                    return Ok(StepOutcome::Interrupted);
                }
            }
            if self.attempt(integ, obs, end)? {
                return Ok(StepOutcome::Accepted);
            }
        }
    }

    /// Steps until the time `t` is reached, landing on it (a breakpoint for the steps, as a
    /// load function's kink is; the end time moves to `t` if it was earlier). Returns the
    /// outcome of the last step (`Finished` when `t` was already reached).
    pub fn advance_to(
        &mut self,
        t: f64,
        integ: &mut Integrator,
        obs: &mut dyn Observer,
    ) -> Result<StepOutcome, RunError> {
        let eps = 1e-9 * self.h0;
        if t <= integ.t + eps {
            return Ok(StepOutcome::Finished);
        }
        self.land_on(t);
        let mut last = StepOutcome::Finished;
        while integ.t < t - eps {
            last = self.step(integ, obs)?;
            if last != StepOutcome::Accepted {
                break;
            }
        }
        Ok(last)
    }

    /// One step toward the time `t`, landing on it (see [`Stepper::advance_to`]): for a
    /// program that does something between any two steps (e.g. sets an input).
    pub fn step_toward(
        &mut self,
        t: f64,
        integ: &mut Integrator,
        obs: &mut dyn Observer,
    ) -> Result<StepOutcome, RunError> {
        let eps = 1e-9 * self.h0;
        if t <= integ.t + eps {
            return Ok(StepOutcome::Finished);
        }
        self.land_on(t);
        self.step(integ, obs)
    }

    /// Makes `t` a time steps land on (the end time if it is later than it).
    fn land_on(&mut self, t: f64) {
        let eps = 1e-9 * self.h0;
        if t > self.end {
            self.end = t;
        } else if !self.breaks.iter().any(|b| (b - t).abs() <= eps) {
            self.breaks.push(t);
            self.breaks.sort_by(f64::total_cmp);
        }
    }

    /// Forgets a stop at a pause ([`Interruption::AtStep`]): the state is a step's end, and
    /// the run may go on from it (a program that handled its Ctrl-C).
    pub fn clear_stop(&mut self) {
        if self.interrupted == Some(Interruption::AtStep) {
            self.interrupted = None;
        }
    }

    /// One attempt at a step from `integ.t`; `true` when it was accepted.
    fn attempt(
        &mut self,
        integ: &mut Integrator,
        obs: &mut dyn Observer,
        end: f64,
    ) -> Result<bool, RunError> {
        let (h0, hmin, hmax) = (self.h0, self.hmin, self.hmax);
        let t = integ.t;
        let asked = self.retry.take();
        let mut h_try = asked
            .unwrap_or(self.h)
            .min(end - t)
            .min(integ.step_cap.max(hmin));
        if let Some(r) = self.regrow.filter(|_| asked.is_none()) {
            h_try = h_try.min(r);
        }
        if !self.adaptive {
            // Fixed steps come back to the grid t = k h₀ after an event moved them off it,
            // so that histories keep their sampling times: in equal steps
            // ([`super::grid_step`]); a step an element asked for (an event's time) is
            // taken as asked, or to the grid instant before it.
            h_try = match asked {
                Some(_) => h_try.min(super::grid_distance(t, h0)),
                // The stage schemes keep no acceleration history, which a sliver's
                // accelerations would feed (`super::grid_step`'s reason): the longest steps
                // back to the grid, then the remainder, which the restitution through a
                // landed contact needs for its order (ESDIRK3's error stalled at 2.5e-6 with
                // equal steps: tests/esdirk.rs, restitution_is_third_order…).
                None if !self.regrows => h_try.min(super::grid_distance(t, h0)),
                None => {
                    // The next instant to land on before the grid's: a breakpoint or the end.
                    let until = self
                        .breaks
                        .iter()
                        .find(|b| **b > t + 1e-3 * h_try)
                        .map_or(end, |b| b.min(end));
                    super::grid_step(t, h_try, h0, h_try >= self.h, until)
                }
            };
        }
        // A breakpoint closer than 1e-3 h_try ahead counts as reached (round-off: t, a sum
        // of steps, is 2.4e-15 s short of 0.02 s after 10,240 steps of 1.953125e-6 s), and
        // a step ending that close to one ends on it: never a sliver of a step, whose
        // 1/(βh²) would swamp the iteration matrix and whose accelerations would be
        // position round-off over βh². Straddling a kink by 1e-3 h errs by O(1e-3 h²)
        // of the slope's jump, as the same rule at the end of the run.
        let near = 1e-3 * h_try;
        if let Some(b) = self.breaks.iter().find(|b| **b > t + near)
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
                self.refusals = 0;
                integ.stats.min_step = integ.stats.min_step.min(h_try);
                integ.stats.max_step = integ.stats.max_step.max(h_try);
                let v = integ.constraint_violation();
                integ.stats.max_constraint_violation = integ.stats.max_constraint_violation.max(v);
                // Equations removed as redundant must keep following from the others.
                if let Err(f) = integ.check_removed_equations() {
                    self.failure = Some(f);
                }
                integ.stats.cpu_seconds = self.cpu0 + self.start.elapsed().as_secs_f64();
                integ.stats.pivot_searches = integ.sys.matrix.pivoting_factorizations();
                self.pause_due = true;
                let step = integ.stats.steps;
                super::observe(integ, obs, step, h_try)?;
                obs.progress(integ.t, end, &integ.stats);
                if integ.dynamic
                    && self
                        .drive_breaks
                        .iter()
                        .any(|b| (integ.t - b).abs() <= near)
                    && integ.consistent_accelerations().is_ok()
                {
                    integ.stats.restarts += 1;
                }
                self.good += 1;
                if self.regrows {
                    self.regrow = super::regrowth(h_try, self.h);
                }
                if self.adaptive {
                    // The local error estimate proposes the next step; it is taken from
                    // a ladder h₀·2^(k/4), and grows only by two rungs or more, so that
                    // runs of equal steps keep the factored matrix (modified Newton).
                    self.h = ladder_step(self.h, integ.error_next, h0).clamp(hmin, hmax);
                } else if self.h < h0 && self.good >= 4 {
                    self.h = (2.0 * self.h).min(h0);
                    self.good = 0;
                }
                Ok(true)
            }
            Err(Failure {
                reason: FailureReason::Aborted,
                ..
            }) => {
                self.interrupted = Some(Interruption::WithinStep);
                Ok(false)
            }
            Err(
                f @ Failure {
                    reason: FailureReason::StepRefused(_),
                    ..
                },
            ) => {
                // An element (e.g. a contact at an impact) or the error control asks for a
                // shorter step.
                let FailureReason::StepRefused(h_ok) = f.reason else {
                    unreachable!("matched above")
                };
                integ.stats.rejected_steps += 1;
                self.refusals += 1;
                if self.refusals > super::MAX_REFUSALS {
                    self.failure = Some(f);
                } else {
                    integ.recycle_history(f.residual_history);
                    self.retry = Some(h_ok.max(hmin).min(h_try));
                }
                Ok(false)
            }
            Err(f) => {
                integ.stats.rejected_steps += 1;
                self.good = 0;
                self.h = h_try / 2.0;
                if self.h < hmin * (1.0 - 1e-12) {
                    let mut f = f;
                    integ.diagnose_constraints(&mut f);
                    self.failure = Some(f);
                } else {
                    integ.recycle_history(f.residual_history);
                }
                Ok(false)
            }
        }
    }

    /// Closes the run: the counters' smallest step (0 when no step was taken), CPU
    /// seconds and pivot searches written into `integ.stats`, and the report.
    pub fn finish(&self, integ: &mut Integrator) -> RunReport {
        integ.stats = self.report(integ).stats;
        self.report(integ)
    }

    /// The report of the run so far, the integrator left as it is (a run driven step by
    /// step goes on after it). CPU seconds are wall seconds since the start.
    pub fn report(&self, integ: &Integrator) -> RunReport {
        let mut stats = integ.stats;
        if stats.min_step == f64::INFINITY {
            stats.min_step = 0.0;
        }
        stats.cpu_seconds = self.cpu0 + self.start.elapsed().as_secs_f64();
        stats.pivot_searches = integ.sys.matrix.pivoting_factorizations();
        RunReport {
            stats,
            time: integ.t,
            failure: self.failure.clone(),
            interrupted: self.interrupted,
        }
    }
}
