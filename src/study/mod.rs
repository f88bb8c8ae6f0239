//! Work–precision study: what accuracy costs in time (`mecano-rs study DECK`).
//!
//! Runs a deck at a ladder of fixed time steps (and optionally with adaptive tolerances and
//! other HHT α), takes the finest fixed-step run as the reference, and reports for each run
//! the CPU seconds, steps, Newton iterations, factorisations and the error of chosen node
//! histories, **per time window**: positions (m), rotations (rad, `|log(R_refᵀR)|`) and
//! velocities (m/s), max over the window's sample instants and the chosen nodes. A window
//! counts as converged when the reference itself is: the difference between the two finest
//! runs there is at most half the difference between the second and third finest (the
//! sequence contracts at least like a first-order method) or below a floor (`--floor`,
//! default 1e-6 m: where the finest runs agree to a micrometre their difference is the
//! noise of the Newton tolerance, and its ratio to the next pair says nothing). This is
//! judged for each quantity on its own — positions, rotations (the same floor in rad),
//! velocities (in m/s) — because they converge differently: on the pendulum the tip
//! rotations, driven by the bars' torsion, converge at order 1.1–1.5 before the impact
//! where the positions converge at 1.5–1.9 (`docs/accuracy.md`). Each quantity's error is
//! the largest over the windows where its reference is converged. The observed order is
//! measured on positions (on rotations if the chosen nodes do not move). The
//! work–precision figure (position error against CPU time) uses the position-converged
//! windows only, as the IFToMM benchmark protocol compares codes at given precision bands.
//!
//! Samples are taken on the grid of the coarsest fixed step (which every fixed run hits);
//! adaptive runs are interpolated there with cubic Hermite polynomials in position and
//! velocity (error O(h⁴)) and geodesically in rotation.
//!
//! Files: `run.rs` (the runs and their errors per window), `report.rs` (CSV files and the
//! printed table), `figure.rs` (the work–precision diagram), `tolerance.rs` (the adaptive
//! runs' error against the tolerance: slope and diagram), `space/` (the space–time
//! study: a ladder of meshes as well as of steps), `cli.rs` (`mecano-rs study`).

mod cli;
mod figure;
/// What each integrator needs for 1e-2, 1e-3 and 1e-4 (issue 26 §3).
pub mod needs;
mod report;
mod run;
/// The space–time study: a ladder of meshes as well as of steps.
pub mod space;
/// Tolerance proportionality: the adaptive runs' error against the tolerance asked.
pub mod tolerance;

pub use cli::{StudyArgs, run};
pub use figure::draw_work_precision;
pub use report::{print_table, write_results};
pub use run::run_study;

use crate::solver;
use std::io;
use std::path::PathBuf;

/// What to study.
#[derive(Debug, Clone)]
pub struct StudyOptions {
    /// Fixed time steps, s (at least 3; the smallest is the reference).
    pub steps: Vec<f64>,
    /// Adaptive position tolerances, m (rotation tolerance = position tolerance / m).
    pub adaptive: Vec<f64>,
    /// Time integration schemes of the fixed-step runs, one ladder each (default: the
    /// deck's); the first one's finest run is the reference, its scheme the adaptive runs'.
    pub schemes: Vec<crate::model::Scheme>,
    /// User node numbers whose histories are compared (default: the deck's output nodes).
    pub nodes: Vec<u32>,
    /// Window length, s.
    pub window: f64,
    /// Difference (m for positions, rad for rotations) below which the two finest runs
    /// count as converged whatever their ratio to the next pair (there they differ by
    /// solver-tolerance noise).
    pub floor: f64,
    /// Only study up to this time (default: the deck's end).
    pub t_max: Option<f64>,
    /// Where to write study.csv, study_windows.csv and the diagram.
    pub out_dir: PathBuf,
    /// Mesh refinement factor applied to every beam before the runs (`--refine k`; 0 or 1:
    /// the deck's mesh). A time study is converged in time only, on this mesh.
    pub refine: u32,
}

/// One run of the study.
#[derive(Debug, Clone)]
pub struct StudyRun {
    /// Label, e.g. `h=1.000e-4 hht:-0.1` or `adaptive tol=1.0e-5 hht:-0.1`.
    pub label: String,
    /// Fixed step (or the initial step of an adaptive run), s.
    pub h: f64,
    /// Time integration scheme.
    pub scheme: crate::model::Scheme,
    /// Adaptive position tolerance, m.
    pub tol: Option<f64>,
    /// Counters.
    pub stats: solver::Stats,
    /// The run reached its end.
    pub complete: bool,
    /// Where and why the run stopped, if it did not reach its end.
    pub stopped: Option<String>,
    /// Errors per window: (position, rotation, velocity).
    pub window_errors: Vec<[f64; 3]>,
    /// Errors over the converged windows of each quantity: (position, rotation, velocity).
    pub error: [f64; 3],
    /// Observed order against the next finer fixed run (fixed runs only).
    pub order: Option<f64>,
    /// Adaptive runs: what fixed steps (of the first α) cost for the same position error.
    pub fixed_equivalent: Option<FixedEquivalent>,
}

/// The CPU time fixed steps take to reach an adaptive run's position error (the measure of
/// issue 7's target: adaptive CPU over "the best fixed step that reaches the same
/// accuracy").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedEquivalent {
    /// CPU seconds interpolated on the fixed runs' work–precision line, linear in
    /// `(ln error, ln CPU)` between the two successive ladder runs whose errors bracket the
    /// adaptive run's; `None` when no pair brackets it.
    pub interpolated: Option<f64>,
    /// The cheapest fixed run whose error is at most the adaptive run's: (CPU s, h).
    pub cheapest: Option<(f64, f64)>,
}

/// The error the diagram and the adaptive comparison use: 0 (positions), or 1 (rotations)
/// when no run has a position error (the chosen nodes do not translate).
fn compared_quantity(runs: &[StudyRun]) -> usize {
    usize::from(
        runs.iter()
            .all(|x| x.error[0] == 0.0 || !x.error[0].is_finite()),
    )
}

/// [`FixedEquivalent`] of an error `e` among fixed runs `(h, error, CPU s)`, coarsest first
/// (runs with a zero, NaN or infinite error — the reference, stopped runs — are ignored).
pub fn fixed_equivalent(fixed: &[(f64, f64, f64)], e: f64) -> FixedEquivalent {
    let runs: Vec<(f64, f64, f64)> = fixed
        .iter()
        .copied()
        .filter(|r| r.1 > 0.0 && r.1.is_finite() && r.2 > 0.0)
        .collect();
    let interpolated = runs.windows(2).find_map(|w| {
        let ((_, e0, c0), (_, e1, c1)) = (w[0], w[1]);
        (e0 >= e && e >= e1 && e0 > e1).then(|| {
            let theta = (e0.ln() - e.ln()) / (e0.ln() - e1.ln());
            (c0.ln() + theta * (c1.ln() - c0.ln())).exp()
        })
    });
    let cheapest = runs
        .iter()
        .filter(|r| r.1 <= e)
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|r| (r.2, r.0));
    FixedEquivalent {
        interpolated,
        cheapest,
    }
}

/// The study's result.
#[derive(Debug, Clone)]
pub struct StudyReport {
    /// Runs, coarsest fixed first, then adaptive.
    pub runs: Vec<StudyRun>,
    /// Window start times, s.
    pub windows: Vec<f64>,
    /// Whether each window's reference is converged: (position, rotation, velocity).
    pub converged: Vec<[bool; 3]>,
    /// Difference between the two finest runs per window: (position m, rotation rad,
    /// velocity m/s).
    pub reference_uncertainty: Vec<[f64; 3]>,
}

/// Errors of study runs.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The deck could not be read.
    #[error("{0}")]
    Deck(String),
    /// The study cannot be set up as asked.
    #[error("{0}")]
    Setup(String),
    /// Writing results failed.
    #[error(transparent)]
    Io(#[from] io::Error),
}
