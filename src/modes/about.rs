//! The state a modal analysis linearises about (the initial state, the static equilibrium,
//! the state a run reaches at a time), and the analyses about it that `--check`, a run's
//! summary and `mecano-rs modes` share.

use super::output::DeckStep;
use super::rotating::{Frame, relative_equilibrium};
use super::{ModalAnalysis, ModesError, Solver};
use crate::model::{Analysis, Model};
use crate::solver::{self, Integrator, Observer, Snapshot};

/// Where the linearisation is taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum About {
    /// The initial state (consistent accelerations and multipliers at t = 0).
    Initial,
    /// The static equilibrium under the deck's loads.
    Static,
    /// The state a dynamic run reaches at this time.
    At(f64),
    /// The relative equilibrium of a hub driven at constant speed, at t = 0; the modes
    /// are those seen in the rotating frame ([`super::rotating`]).
    Rotating,
}

/// Where an `ANALYSIS MODES` deck asks its modes to be taken: `ROTATING`, `STATIC`, or
/// the initial state.
pub fn deck_about(model: &Model) -> About {
    if model.modes_rotating {
        About::Rotating
    } else if model.modes_static {
        About::Static
    } else {
        About::Initial
    }
}

/// A failure to reach the state or to solve: bad input (the command exits 2) or a failed
/// solve or run (1).
#[derive(Debug)]
pub struct Failed {
    /// The deck or the request is at fault (not the solver).
    pub bad_input: bool,
    /// More modes asked for than the model has (the request's count is at fault: the
    /// command points at it).
    pub too_many: bool,
    /// Message.
    pub message: String,
}

fn bad(message: String) -> Failed {
    Failed {
        bad_input: true,
        too_many: false,
        message,
    }
}

fn failed(message: String) -> Failed {
    Failed {
        bad_input: false,
        too_many: false,
        message,
    }
}

struct Quiet;
impl Observer for Quiet {
    fn state(&mut self, _snap: &Snapshot) -> std::io::Result<()> {
        Ok(())
    }
}

/// The integrator at the state the analysis linearises about.
pub fn reach_state(model: &Model, about: About) -> Result<Integrator, Failed> {
    reach_state_with(model, about, true)
}

/// [`reach_state`], saying on standard error when the initial multipliers are set to zero
/// only if `warn` (a run's summary block says it in its own words).
fn reach_state_with(model: &Model, about: About, warn: bool) -> Result<Integrator, Failed> {
    let newton = match &model.analysis {
        Analysis::Dynamic { newton, .. } | Analysis::Static { newton, .. } => newton.clone(),
    };
    let mut m = model.clone();
    match about {
        About::Initial => {}
        About::Rotating => {
            // The deck's own analysis is not run: the state is the relative equilibrium.
            let frame = Frame::from_model(model, 0.0).map_err(|e| bad(e.to_string()))?;
            let mut integ = solver::prepare(&m).map_err(|e| bad(e.to_string()))?;
            let (t, scale) = (integ.t, integ.scale);
            relative_equilibrium(
                &mut integ.sys,
                &frame,
                &mut integ.nodes,
                &mut integ.lambda,
                scale,
                t,
            )
            .map_err(|e| failed(format!("the rotating state: {e}")))?;
            return Ok(integ);
        }
        // The deck's own load steps when it is a static analysis (`ANALYSIS STATIC STEPS
        // k`, `ANALYSIS MODES n STATIC STEPS k`), else one, cut automatically.
        About::Static => {
            if !matches!(m.analysis, Analysis::Static { .. }) {
                m.analysis = Analysis::Static {
                    steps: 1,
                    newton,
                    proportional: false,
                }
            }
        }
        About::At(t) => match &mut m.analysis {
            Analysis::Dynamic { end, .. } => {
                if !(t >= 0.0 && t <= *end) {
                    return Err(bad(format!(
                        "--at {t}: outside the deck's time span [0, {}] s",
                        *end
                    )));
                }
                *end = t;
            }
            Analysis::Static { .. } => {
                return Err(bad("--at needs a deck with ANALYSIS DYNAMIC".into()));
            }
        },
    }
    let mut integ = solver::prepare(&m).map_err(|e| bad(e.to_string()))?;
    if about == About::Initial {
        // The initial state is the dynamic one whatever the deck runs (an `ANALYSIS
        // MODES` deck is static): consistent accelerations and multipliers, so that the
        // constraints' forces (a pendulum's tension under gravity) give their geometric
        // stiffness, as `mecano-rs modes` of the same model in a dynamic deck does.
        integ.dynamic = true;
        if let Err(f) = integ.initialize() {
            // An over-constrained mechanism (the four-bar of hinges) has no unique
            // multipliers, and runs refuse it; its modes are still defined: linearise
            // with zero multipliers (exact when the constraints carry no force) and say so.
            let crate::solver::FailureReason::Singular(why) = &f.reason else {
                return Err(failed(format!("the initial state: {f}")));
            };
            if warn {
                eprintln!(
                    "warning: the initial multipliers could not be computed ({why}); linearised with zero constraint forces"
                );
            }
            integ = solver::prepare(&m).map_err(|e| bad(e.to_string()))?;
        }
        return Ok(integ);
    }
    let report = solver::run_prepared(&m, &mut integ, &mut Quiet)
        .map_err(|e| failed(format!("reaching the state: {e}")))?;
    if let Some(f) = report.failure {
        return Err(failed(format!("reaching the state: {f}")));
    }
    Ok(integ)
}

/// Modal analysis of a model at a state, `count` modes (the library's entry point).
pub fn analyse_model(
    model: &Model,
    about: About,
    count: usize,
) -> Result<(Integrator, ModalAnalysis), Failed> {
    analyse_model_using(model, about, count, Solver::Auto)
}

/// [`analyse_model`] with the solver chosen.
pub fn analyse_model_using(
    model: &Model,
    about: About,
    count: usize,
    solver: Solver,
) -> Result<(Integrator, ModalAnalysis), Failed> {
    analyse_model_with(model, about, count, true, solver)
}

fn analyse_model_with(
    model: &Model,
    about: About,
    count: usize,
    warn: bool,
    solver: Solver,
) -> Result<(Integrator, ModalAnalysis), Failed> {
    let mut integ = reach_state_with(model, about, warn)?;
    let groups: Vec<&str> = model.elements.values().map(|e| e.kind.keyword()).collect();
    let a = if about == About::Rotating {
        let frame = Frame::from_model(model, integ.t).map_err(|e| bad(e.to_string()))?;
        crate::modes::analyse_rotating(
            &integ.sys,
            &frame,
            &integ.nodes,
            &integ.lambda,
            integ.scale,
            integ.t,
            &groups,
            count,
        )
    } else {
        crate::modes::analyse(
            &mut integ.sys,
            &integ.nodes,
            &integ.lambda,
            integ.scale,
            integ.t,
            &groups,
            count,
            solver,
        )
    }
    .map_err(|e| match e {
        ModesError::Dense(d) => failed(d.to_string()),
        ModesError::Sparse(d) => failed(d.to_string()),
        ModesError::Equilibrium(d) => failed(d.to_string()),
        e @ ModesError::TooMany { .. } => Failed {
            too_many: true,
            ..bad(e.to_string())
        },
        other => bad(other.to_string()),
    })?;
    Ok((integ, a))
}

/// The deck's step and integration scheme when it is dynamic.
pub fn deck_step(model: &Model) -> Option<DeckStep> {
    match &model.analysis {
        Analysis::Dynamic { scheme, step, .. } => Some(DeckStep {
            scheme: *scheme,
            h: *step,
        }),
        Analysis::Static { .. } => None,
    }
}

/// Dense solves are O(n³): `--check` reports modes only up to this many free unknowns.
pub const CHECK_MAX_UNKNOWNS: usize = 1500;

/// The rigid modes and the lowest `elastic` others about the initial state (fewer when the
/// model has fewer). One dense solve in the usual case (room for six rigid motions); a
/// model with fewer free unknowns or more rigid motions takes a second one, sized by the
/// first. `warn`: as [`reach_state`]'s. The frequencies alone: the modes carry no shapes
/// ([`Solver::DenseFrequencies`]).
pub fn lowest_about_initial(
    model: &Model,
    elastic: usize,
    warn: bool,
) -> Result<ModalAnalysis, Failed> {
    // Its callers (a run's summary, `--check`, `study`) print frequencies: no shapes.
    const SOLVER: Solver = Solver::DenseFrequencies;
    let guess = elastic + 6;
    let probe = match analyse_model_with(model, About::Initial, guess, warn, SOLVER) {
        Ok((_, mut a)) if a.rigid_modes + elastic <= guess => {
            // Rigid modes come first, then the others by frequency.
            a.modes.truncate(a.rigid_modes + elastic);
            return Ok(a);
        }
        Ok((_, a)) => a,
        Err(_) => analyse_model_with(model, About::Initial, 1, warn, SOLVER)?.1,
    };
    // A state-space solve (gyroscopic, damped) finds up to twice the free unknowns'
    // eigenvalues; at most `free_unknowns` modes may be asked for.
    let n = (probe.rigid_modes + elastic)
        .min(probe.finite_modes)
        .min(probe.free_unknowns);
    Ok(analyse_model_with(model, About::Initial, n, warn, SOLVER)?.1)
}

/// How far the state a modal analysis linearises about is from a static equilibrium:
/// the largest nodal acceleration (`|ẍ|`, and `|ω̇| L` for rotations, `L` the model's
/// reference length), m/s², and whether the state moves (kinetic energy). Modes about a
/// state that accelerates or moves are those of the linearised equations there, not free
/// vibrations about an equilibrium.
pub fn equilibrium_gap(integ: &Integrator) -> (f64, bool) {
    let l = integ.sys.ref_length;
    let acc = integ
        .nodes
        .iter()
        .fold(0.0f64, |m, s| m.max(s.a.norm()).max(s.wd.norm() * l));
    let moving = integ.energies().kinetic > 0.0;
    (acc, moving)
}

/// The warning [`equilibrium_gap`] calls for, if any: accelerations above `1e-6` of the
/// reference acceleration (gravity's, or 1 m/s² without gravity), or a moving state.
pub fn equilibrium_warning(integ: &Integrator) -> Option<String> {
    let (acc, moving) = equilibrium_gap(integ);
    let g = integ.sys.gravity.norm();
    let a_ref = if g > 0.0 { g } else { 1.0 };
    let mut why = Vec::new();
    if acc > 1e-6 * a_ref {
        why.push(format!("accelerates (up to {acc:.3e} m/s²)"));
    }
    if moving {
        why.push("moves (its kinetic energy is not zero)".to_string());
    }
    (!why.is_empty()).then(|| {
        format!(
            "the state linearised about is not a static equilibrium: it {}; the modes are those of the equations linearised there, not free vibrations (for those, take the modes about the static equilibrium: --static)",
            why.join(" and ")
        )
    })
}
