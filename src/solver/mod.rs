//! Time integration (HHT), static load stepping, Newton–Raphson and sparse linear algebra.
//!
//! [`run`] drives an analysis of a [`Model`] and reports every accepted state to an
//! [`Observer`] (the output writers), so a run that stops early has already delivered
//! what it computed.

pub mod assembly;
pub mod energy_guard;
pub mod idle;
pub mod integrator;
pub mod linear;
pub mod notice;
pub mod redundancy;
pub mod state;
pub mod stepper;
pub mod system;

pub use integrator::{AlphaParams, Integrator, StepInfo};
pub use stepper::{StepOutcome, Stepper};
pub use system::{BuildError, System};

use crate::model::{Analysis, Model, Scheme};

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
    /// The step, or the run of steps it ends, created more energy than no work paid for and
    /// than the scheme's error allows ([`energy_guard`]): a spurious root, or a burst;
    /// refused like a divergence. (Boxed: `Failure` travels in `Result`s.)
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
    /// The constraints cannot be met: the initial positions cannot be assembled onto
    /// them ([`assembly`]), or equations removed as redundant contradict the others or
    /// stopped following from them ([`redundancy`]).
    Constraints(Box<str>),
    /// A static load step found no equilibrium: the loads are not carried.
    NoEquilibrium(Box<str>),
}

/// The diagnosis of a failed run: where, when and how badly.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// Time of the last accepted state, s (statics: the load factor).
    pub time: f64,
    /// Step size of the failed attempt, s (statics: the load step).
    pub step: f64,
    /// A static analysis: `time` and `step` are a load factor and a load step.
    pub load_steps: bool,
    /// What went wrong.
    pub reason: FailureReason,
    /// Relative residual at each Newton iteration of the last attempt.
    pub residual_history: Vec<f64>,
    /// The equation with the largest residual, e.g. `node 23 uy`.
    pub worst: Box<str>,
    /// Its residual, N or N·m.
    pub worst_value: f64,
    /// Reference force used to scale the residual.
    pub reference_force: f64,
    /// What the elements diagnose at the failed state ([`crate::elements::Element::diagnose`]),
    /// e.g. a universal joint at its singular configuration. (A boxed slice keeps
    /// `Failure` small: it travels in `Result`s.)
    pub diagnoses: Box<[String]>,
}

impl Failure {
    /// The diagnosis of a run stopped by its output (a writer refused a non-finite value,
    /// or the disk failed) at the integrator's last accepted state.
    pub fn output(integ: &Integrator, e: &std::io::Error) -> Self {
        Failure {
            time: integ.t,
            step: 0.0,
            load_steps: !integ.dynamic,
            reason: FailureReason::NotFinite,
            residual_history: vec![],
            worst: format!("output: {e}").into(),
            worst_value: 0.0,
            reference_force: 0.0,
            diagnoses: Box::default(),
        }
    }
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
            FailureReason::Constraints(s) | FailureReason::NoEquilibrium(s) => s.to_string(),
            FailureReason::EventUnresolved { element, asks } => format!(
                "element {} needs steps of at most {asks:.3e} s to resolve its event (an impact), but the step may not be cut below MINSTEP = {:.3e} s; lower MINSTEP on the ANALYSIS card",
                element.0, self.step
            ),
            FailureReason::EnergyJump(j) => format!(
                "the integration created {:.3e} J of energy that no work paid for since t = {:.6e} s ({:.3e} J in this step; energy in play {:.3e} J before the step, {:.3e} J after, work of the step {:.3e} J), more than the scheme's error allows ({:.3e} J: docs/stability.md, \"The energy guard's bound\"); steps down to the smallest allowed did not avoid it",
                j.created, j.since, j.by_step, j.before, j.after, j.work, j.bound
            ),
        };
        if self.load_steps {
            writeln!(
                f,
                "{why} at load factor {:.6e} with load step {:.3e}",
                self.time, self.step
            )?;
        } else {
            writeln!(
                f,
                "{why} at t = {:.6e} s with step h = {:.3e} s",
                self.time, self.step
            )?;
        }
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
    /// After a step shorter than half the nominal one (an event's landing), the longest
    /// next step: steps grow back by doubling, not at once ([`regrowth`]).
    pub regrow: Option<f64>,
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
/// Free translations nothing acts on are refused ([`BuildError::Undetermined`]); nodes
/// whose rotations nothing acts on have them held ([`idle`]), which the integrator's
/// [`Integrator::notices`] say.
pub fn prepare(model: &Model) -> Result<Integrator, BuildError> {
    let sys = System::new(model)?;
    let idle = idle::scan(&sys, model);
    if !idle.undetermined.is_empty() {
        return Err(BuildError::Undetermined(idle.undetermined));
    }
    let mut notices = Vec::new();
    let sys = if idle.rotations.is_empty() {
        sys
    } else {
        notices.push(notice::Notice::HeldRotations {
            nodes: idle.rotations.iter().map(|&i| sys.node_ids[i]).collect(),
        });
        System::new(&idle::with_held_rotations(model, &idle.rotations))?
    };
    let mut integ = match &model.analysis {
        Analysis::Dynamic { scheme, newton, .. } => {
            Integrator::new(sys, newton.clone(), *scheme, true)
        }
        Analysis::Static { newton, .. } => {
            Integrator::new(sys, newton.clone(), Scheme::Hht { alpha: 0.0 }, false)
        }
    };
    integ.notices = notices;
    if integ.dynamic {
        for iv in &model.initial {
            if let Some(i) = model.nodes.get_index_of(&iv.node) {
                integ.set_velocity(i, iv.velocity, iv.angular);
            }
        }
    }
    Ok(integ)
}

/// How far above the smallest step (`MINSTEP`) a step still counts as the smallest, for
/// the refusals of the error and event controls: the run loop stretches a step by up to
/// 1e-3 of itself to land on a breakpoint or the end (never a sliver of a step after it),
/// so a retry at the smallest step may come back that much longer. With a tolerance of
/// 1e-9 such a step was refused again, retried at the smallest step, stretched again — for
/// ever (the fuzzer's case 35:8517: an adaptive run 1e-8 s short of its end, deaf to
/// Ctrl-C since no step was ever accepted).
pub(crate) const FLOOR_SLACK: f64 = 1e-3;

/// Most consecutive refused attempts of one step. Each refusal shortens the step by at
/// least 0.1 % (an event's retry is at most 0.999 h, the error control's at most 0.9 h)
/// down to `MINSTEP`, where no refusal is made, and `END/MINSTEP ≤ 1e12` (grammar.md), so
/// ln(1e12)/ln(1/0.999) ≈ 27,600 refusals is the most a step can take: this bound is a
/// guard that a broken control cannot turn into a loop without end.
pub(crate) const MAX_REFUSALS: u32 = 100_000;

/// Hands an accepted state to the observer. For a stage scheme, with the multipliers and
/// accelerations of the index-1 equations at the state's `(q, v)` when the observer reads
/// them ([`Observer::reads_reactions`], [`Integrator::exact_reactions`]); the stage values
/// come back after it, so the integration does not depend on what is observed.
pub(crate) fn observe(
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

/// How close before an instant `k h₀` of a fixed-step run's grid a state counts as having
/// reached it, in units of h₀: no step shorter than this is taken to land on the grid (a
/// sliver's 1/(βh²) would swamp the iteration matrix, issue 35), so a state an event landed
/// that close before the instant stands for it — in the steps ([`grid_distance`]) and in the
/// histories (`output::Sampling`, which writes it as that instant's row: issue 34 §7).
pub const GRID_REACH: f64 = 1e-3;

/// The distance from `t` to the next instant `k h₀` of a fixed-step run's grid (one closer
/// than [`GRID_REACH`] h₀ counts as reached: t is a sum of steps, on the grid within
/// round-off, or an event landed it there).
pub(crate) fn grid_distance(t: f64, h0: f64) -> f64 {
    let k = (t / h0).round();
    let next = if (t - k * h0).abs() <= 1e-6 * h0 {
        (k + 1.0) * h0
    } else {
        (t / h0).ceil() * h0
    };
    let d = next - t;
    if d < GRID_REACH * h0 { d + h0 } else { d }
}

/// The step from `t` toward the grid `k h₀` of a fixed-step run, given the step `h` the
/// controller would take: the distance `d` to the next grid instant split into `n` equal
/// steps no longer than `h`. A step is then never shorter than half the one tried unless
/// `d` itself is (an event landed the run just before a grid instant, which the histories'
/// sampling needs), and steps of a cut size keep fitting the grid (halving them halves
/// `d/n`).
///
/// Why not the longest steps and then what is left: that remainder, a sliver (3.5e-7 s
/// after steps of 1.25e-5–5e-5 s on the seed's scene, and again every 1e-4 s as the cut
/// steps never divided the grid), gives the α schemes' acceleration history the unresolved
/// modes' true accelerations, which the next, 36–140 times longer steps turn into energy:
/// 66 J created in 2 ms at t = 23.18 s of `decks/pendulum.dat` run to 30 s (issue 35,
/// `docs/stability.md`).
/// A step not limited by anything but the controller (`free`) may be up to 1e-3 longer
/// than `h` to land on the grid, as a breakpoint that close counts as reached: after a
/// landing 1e-9 s before a grid instant the next one is 1.00001 h away, one step, not two.
///
/// `until` is the next instant the run must land on before the grid's (the end, a load's
/// or a driver's breakpoint; infinity when none): the distance to it is split the same
/// way. Taking the longest steps toward it and then the grid's split of what is left gave
/// steps that halved for ever toward the end: 5e-3, 1.25e-3, 1.2e-4, 3.4e-6 s before
/// `decks/spinning_beam.dat`'s end 4π s with STEP 0.01 s.
pub fn grid_step(t: f64, h: f64, h0: f64, free: bool, until: f64) -> f64 {
    let d = grid_distance(t, h0).min(until - t);
    // A grid instant farther than `h` by round-off only (t is a sum of steps): the step
    // `h` itself, not one stretched by an ulp at every step (which turned the spinning
    // beam's exact steady spin, `decks/spinning_beam.dat`, 1e-10 off in 558 steps).
    if d > h && d - h <= 1e-9 * h {
        return h;
    }
    let slack = if free { 1e-3 } else { 1e-9 };
    // n steps of d/n ≤ h (1 + slack).
    let n = (d / h - slack).ceil().max(1.0);
    d / n
}

/// The longest step after an accepted step `taken` of an α scheme whose nominal step is
/// `h`: `2 taken` while that is below `h`, else no limit. Why: a step much shorter than
/// the ones around it (a contact's landing at MINSTEP) resolves the mesh's unresolved
/// modes and gives the acceleration history their true accelerations; a next step
/// hundreds of times longer turns them into energy (11 J per step, 40 J in 0.7 ms at
/// t = 28.518 s of the seed's scene run to 30 s: issue 35, `docs/stability.md`). Doubling
/// keeps every step-size change within the factor 2 of the controller's own halving.
pub fn regrowth(taken: f64, h: f64) -> Option<f64> {
    (2.0 * taken < h * (1.0 - 1e-9)).then_some(2.0 * taken)
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
    let mut stepper = Stepper::start(model, integ, obs, resume)?;
    while stepper.step(integ, obs)? == StepOutcome::Accepted {}
    Ok(stepper.finish(integ))
}

#[cfg(test)]
mod tests {
    use super::{grid_step, ladder_step};

    /// Steps back to the grid: never shorter than half the step tried (when the grid
    /// instant is at least that far), never longer, and they land on the grid; a step of
    /// the grid's size stays on it. The seed's sliver: from t = 23.1840 s with steps of
    /// 4.983e-5 s, three steps of 3.33e-5 s, not two and 3.5e-7 s.
    #[test]
    fn grid_steps_land_without_slivers() {
        let h0 = 1e-4;
        for (t0, h) in [
            (0.0, 1e-4),
            (23.18390035, 9.965e-5),
            (0.5 * h0 + 3.7e-7, 1e-4),
            (7.0 * h0 - 3.0e-5, 1e-4),
            (7.0 * h0 - 3.0e-5, 2.491e-5),
            (12.0 * h0 + 9.8e-8, 1.246e-5),
            (23.184, 4.983e-5),
            (3.0 * h0 + 0.3 * h0, 0.25 * h0),
        ] {
            let mut t = t0;
            let mut landed = false;
            for _ in 0..200 {
                let s = grid_step(t, h, h0, false, f64::INFINITY);
                let d = super::grid_distance(t, h0);
                assert!(
                    s <= h * (1.0 + 1e-9) && s >= (0.5 * h).min(d) * (1.0 - 1e-9),
                    "t = {t:e}, h = {h:e}: step {s:e}"
                );
                t += s;
                if ((t / h0).round() * h0 - t).abs() <= 1e-6 * h0 {
                    landed = true;
                    break;
                }
            }
            assert!(landed, "t0 = {t0:e}, h = {h:e} never reached the grid");
        }
        // On the grid with the grid's step: exactly h0.
        assert!((grid_step(5.0 * h0, h0, h0, true, f64::INFINITY) / h0 - 1.0).abs() < 1e-12);
        // 1e-9 s short of a grid instant: one step of 1.00001 h0 when the step is free.
        let t = 5.0 * h0 - 1e-9;
        assert!((grid_step(t, h0, h0, true, f64::INFINITY) - (h0 + 1e-9)).abs() < 1e-15);
        assert!((grid_step(t, h0, h0, false, f64::INFINITY) - 0.5 * (h0 + 1e-9)).abs() < 1e-15);
        let s = grid_step(23.184, 4.983e-5, h0, true, f64::INFINITY);
        assert!((s - h0 / 3.0).abs() < 1e-12, "{s:e}");
        // The end (or a breakpoint) before the next grid instant: equal steps to it, no
        // halving toward it (the spinning beam's end 4π s with STEP 0.01 s).
        let (mut t, end) = (12.56, 4.0 * std::f64::consts::PI);
        let mut steps = 0;
        while t < end - 1e-12 {
            let s = grid_step(t, (end - t).min(0.01), 0.01, false, end);
            assert!(s >= 0.5 * (end - t).min(0.01), "step {s:e} at {t}");
            t += s;
            steps += 1;
        }
        assert_eq!(steps, 1);
    }

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
