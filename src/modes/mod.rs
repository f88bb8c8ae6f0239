//! Linearised modes of a mechanism at a state (`mecano-rs modes DECK`, `ANALYSIS MODES n`).
//!
//! [`linearise`] assembles the consistent linearisation of the project's residual —
//! tangent stiffness with its geometric, inertial and follower-moment parts, damping and
//! gyroscopic matrix, mass, constraint Jacobian — and eliminates the constraints through
//! an orthonormal basis `N` of the Jacobian's null space (rank-revealing: redundant joints
//! cost nothing). [`dense`] solves the reduced problem: the symmetric generalised problem
//! `NᵀKN φ = ω² NᵀMN φ` when the model is conservative and undamped at the state, else the
//! quadratic problem in first-order form (frequencies and damping ratios); `reduced`
//! drives it and classifies the modes. Rigid motions come out as exact zeros
//! ([`dense::ZERO_FACTOR`]) and are counted. [`hht`] tells what a
//! time step resolves of each mode; [`output`] writes `modes.csv`, `modes_shapes.csv`,
//! `summary.json`; [`cli`] is the `modes` subcommand.

pub mod about;
pub mod dense;
pub mod hht;
pub mod krylov;
pub mod linearise;
pub mod output;
mod reduced;
pub mod rotating;
pub mod run_summary;
pub mod sparse;
pub mod sparse_damped;
pub mod vtk;

use crate::elements::NodeState;
use crate::solver::system::System;
use linearise::ElementMatrices;
use nalgebra::DMatrix;
use std::f64::consts::PI;

/// What a mode is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ModeKind {
    /// A rigid motion (or mechanism motion free of restoring force): zero frequency.
    Rigid,
    /// A vibration.
    Elastic,
    /// A divergent direction (negative stiffness, or an eigenvalue of positive real part).
    Unstable,
}

/// One mode of the linearised model.
#[derive(Debug, Clone)]
pub struct Mode {
    /// Rigid, elastic or unstable.
    pub kind: ModeKind,
    /// Damped frequency `Im s / 2π`, Hz (0 for rigid, unstable or overdamped modes).
    pub frequency_hz: f64,
    /// Undamped natural frequency `|s| / 2π`, Hz.
    pub natural_hz: f64,
    /// Damping ratio `−Re s / |s|` (0 conservative; −1 a pure divergence).
    pub damping_ratio: f64,
    /// Eigenvalue `s`, 1/s (real, imaginary parts).
    pub eigenvalue: (f64, f64),
    /// Shape on the system's nodal equations (mass-normalised for a conservative model).
    pub shape: Vec<f64>,
    /// Share of the mode's kinetic energy `φᵀMφ` per element group ([`ModalAnalysis::groups`]).
    pub kinetic_share: Vec<f64>,
    /// Share of its strain energy `φᵀKφ` per element group (0 when the total is not positive).
    pub strain_share: Vec<f64>,
}

impl Mode {
    /// Period `1/f` of the damped frequency, s (`None` when it does not oscillate).
    pub fn period(&self) -> Option<f64> {
        (self.frequency_hz > 0.0).then(|| 1.0 / self.frequency_hz)
    }
}

/// How the reduced problem was solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Symmetric generalised problem (conservative, undamped).
    Symmetric,
    /// Quadratic problem in first-order form (damped, gyroscopic or non-symmetric).
    StateSpace,
    /// Symmetric problem by sparse shift-invert block Lanczos ([`sparse`]).
    SparseSymmetric,
    /// Quadratic problem by sparse shift-invert block Arnoldi on its first-order form
    /// ([`sparse_damped`]).
    SparseStateSpace,
}

/// The result of a modal analysis.
#[derive(Debug, Clone)]
pub struct ModalAnalysis {
    /// The lowest modes asked for (rigid first, then by frequency).
    pub modes: Vec<Mode>,
    /// Unknowns free of constraints (dimension of the Jacobian's null space).
    pub free_unknowns: usize,
    /// Constraint equations and their rank.
    pub constraints: (usize, usize),
    /// Rigid (zero-frequency) modes in the whole spectrum.
    pub rigid_modes: usize,
    /// Finite modes in the whole spectrum (free unknowns less massless directions).
    pub finite_modes: usize,
    /// Highest finite frequency of the mesh, Hz.
    pub highest_hz: f64,
    /// The solver used.
    pub method: Method,
    /// Relative asymmetry `max|K − Kᵀ| / max|K|` of the reduced stiffness.
    pub asymmetry: f64,
    /// Element groups (deck keywords) the energy shares refer to.
    pub groups: Vec<String>,
}

/// Errors of a modal analysis (bad requests; the CLI exits 2 on them).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModesError {
    /// No free unknown, or no mass on any: nothing to vibrate.
    #[error("nothing to vibrate: {0}")]
    NothingToVibrate(String),
    /// More modes asked for than the model has.
    #[error(
        "{count} modes asked for, but the model has {free} free unknowns ({finite} finite modes)"
    )]
    TooMany {
        /// Modes asked for.
        count: usize,
        /// Free unknowns.
        free: usize,
        /// Finite modes.
        finite: usize,
    },
    /// The dense solve failed.
    #[error(transparent)]
    Dense(#[from] dense::DenseError),
    /// The sparse solve failed.
    #[error(transparent)]
    Sparse(#[from] sparse::SparseError),
    /// The relative equilibrium of a rotating model was not found.
    #[error(transparent)]
    Equilibrium(#[from] rotating::EquilibriumError),
}

/// Nodal unknowns from which [`analyse`] takes the sparse solver ([`sparse`]) for a
/// conservative model. Measured (docs/modes.md, 10 modes of the cantilever, user CPU of
/// the whole command): dense 0.05, 0.27, 3.0, 27 s at 150, 300, 600, 1200 unknowns, sparse
/// 0.02, 0.04, 0.06, 0.22 s: the sparse path is cheaper from the smallest sizes, but below
/// 300 unknowns the dense one costs under 0.3 s and gives the whole spectrum (the
/// highest frequency, every rigid mode counted), so it is kept there.
pub const SPARSE_MIN_UNKNOWNS: usize = 300;
/// Above this many nodal unknowns a model the sparse solver refuses (damped, gyroscopic,
/// redundant constraints) is not solved densely either: `O(n³)` flops and `n²` memory
/// (3000 unknowns: minutes).
pub const DENSE_MAX_UNKNOWNS: usize = 3000;

/// Which solver [`analyse`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// Sparse from [`SPARSE_MIN_UNKNOWNS`] when `count` is at most a quarter of the
    /// unknowns, dense otherwise (and dense when the sparse one refuses the model, up to
    /// [`DENSE_MAX_UNKNOWNS`]).
    Auto,
    /// Always dense.
    Dense,
    /// Dense, the frequencies alone: the modes carry no shape and no energy shares
    /// (a run's summary, `--check`: [`about::lowest_about_initial`]). The damped or
    /// gyroscopic first-order form then skips the eigenvectors, which cost 2/3 of its
    /// solve (the flexible slider-crank's 138 × 138 state matrix: 18 ms of a 93 ms run); a
    /// model where one of them is needed to tell a rigid mode from an elastic one is
    /// solved with them.
    DenseFrequencies,
    /// Always sparse.
    Sparse,
}

/// Relative size of `C` (against `√(‖K‖‖M‖)`) below which the model is undamped and not
/// gyroscopic: round-off of assembled zeros is ~ε; 1e-10 keeps a real dashpot or spin.
pub(crate) const DAMPED_TOL: f64 = 1e-10;
/// Relative asymmetry of `K` above which the symmetric problem is not used.
pub(crate) const ASYMMETRY_TOL: f64 = 1e-8;

fn max_abs(a: &DMatrix<f64>) -> f64 {
    a.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// `max|A| / max|M|`: the scale of `M⁻¹A` (0 without mass).
fn model_scale(a: &DMatrix<f64>, m: &DMatrix<f64>) -> f64 {
    let mn = max_abs(m);
    if mn > 0.0 { max_abs(a) / mn } else { 0.0 }
}

/// The lowest `count` modes of `sys` linearised at the state (`nodes`, scaled multipliers
/// `lambda`, constraint scale `scale`, time `t`); `groups[e]` names element `e`'s group.
/// `solver` chooses dense or sparse ([`Solver`]); the sparse path overwrites `sys`'s
/// iteration matrix.
#[allow(clippy::too_many_arguments)]
pub fn analyse(
    sys: &mut System,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
    groups: &[&str],
    count: usize,
    solver: Solver,
) -> Result<ModalAnalysis, ModesError> {
    let nn = sys.n_node_eq;
    let sparse = match solver {
        Solver::Dense | Solver::DenseFrequencies => false,
        Solver::Sparse => true,
        Solver::Auto => nn >= SPARSE_MIN_UNKNOWNS && 4 * count <= nn,
    };
    if sparse {
        match analyse_sparse(sys, nodes, lambda, scale, t, groups, count) {
            // `auto` falls back to the dense path whenever it can afford it (the whole
            // spectrum, no iteration to fail), also when the iteration did not converge
            // (the damped state-space iteration is tested to 400 unknowns only).
            Err(ModesError::Sparse(_)) if solver == Solver::Auto && nn <= DENSE_MAX_UNKNOWNS => {}
            r => return r,
        }
    }
    let shapes = solver != Solver::DenseFrequencies;
    reduced::analyse_dense(sys, nodes, lambda, scale, t, groups, count, shapes)
}

fn group_index(groups: &[&str]) -> (Vec<String>, Vec<usize>) {
    let mut group_names: Vec<String> = Vec::new();
    let group_of: Vec<usize> = groups
        .iter()
        .map(|g| match group_names.iter().position(|n| n == g) {
            Some(i) => i,
            None => {
                group_names.push(g.to_string());
                group_names.len() - 1
            }
        })
        .collect();
    (group_names, group_of)
}

/// [`analyse`] by the sparse solver. What it cannot know without the whole spectrum is
/// stated, not guessed: `rigid_modes` counts the zeros among the modes found,
/// `finite_modes` is the free unknowns (an upper bound) and `highest_hz` is NaN (null in
/// `summary.json`).
fn analyse_sparse(
    sys: &mut System,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
    groups: &[&str],
    count: usize,
) -> Result<ModalAnalysis, ModesError> {
    let free = sys.n_node_eq.saturating_sub(sys.n_eq() - sys.n_node_eq);
    if free == 0 {
        return Err(ModesError::NothingToVibrate(
            "every degree of freedom is fixed or constrained".into(),
        ));
    }
    if count > free {
        return Err(ModesError::TooMany {
            count,
            free,
            finite: free,
        });
    }
    let found = sparse::lowest(sys, nodes, lambda, scale, t, count)?;
    let (group_names, group_of) = group_index(groups);
    let ng = group_names.len();
    if !found.damped.is_empty() {
        // The dense path's order: rigid first, then by |s| (already so ordered).
        let is_zero = |s: (f64, f64)| s.0 * s.0 + s.1 * s.1 <= found.zero;
        let mut raw: Vec<&sparse_damped::DampedMode> = found.damped.iter().collect();
        raw.sort_by_key(|m| u8::from(!is_zero(m.s)));
        let modes = raw
            .into_iter()
            .map(|m| {
                make_mode_s(
                    m.shape.clone(),
                    m.s,
                    is_zero(m.s),
                    &found.locals,
                    &group_of,
                    ng,
                )
            })
            .collect();
        return Ok(ModalAnalysis {
            modes,
            free_unknowns: found.free_unknowns,
            constraints: (found.constraints, found.constraints),
            rigid_modes: found.damped.iter().filter(|m| is_zero(m.s)).count(),
            finite_modes: found.free_unknowns,
            highest_hz: f64::NAN,
            method: Method::SparseStateSpace,
            asymmetry: found.asymmetry,
            groups: group_names,
        });
    }
    let is_zero = |w2: f64| w2.abs() <= found.zero;
    let mut pairs: Vec<&(f64, Vec<f64>)> = found.pairs.iter().collect();
    pairs.sort_by_key(|p| u8::from(!is_zero(p.0)));
    let modes = pairs
        .into_iter()
        .map(|(w2, phi)| {
            let z = is_zero(*w2);
            make_mode(phi.clone(), *w2, z, &found.locals, &group_of, ng)
        })
        .collect();
    Ok(ModalAnalysis {
        modes,
        free_unknowns: found.free_unknowns,
        constraints: (found.constraints, found.constraints),
        rigid_modes: found.pairs.iter().filter(|p| is_zero(p.0)).count(),
        finite_modes: found.free_unknowns,
        highest_hz: f64::NAN,
        method: Method::SparseSymmetric,
        asymmetry: found.asymmetry,
        groups: group_names,
    })
}

/// The lowest `count` modes of a steadily rotating model seen in its rotating frame
/// ([`rotating`]): `nodes` and `lambda` must hold the relative equilibrium
/// ([`rotating::relative_equilibrium`]); the rotating-frame matrices
/// ([`rotating::to_rotating`]) are solved densely (gyroscopic: the first-order form).
#[allow(clippy::too_many_arguments)]
pub fn analyse_rotating(
    sys: &System,
    frame: &rotating::Frame,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
    groups: &[&str],
    count: usize,
) -> Result<ModalAnalysis, ModesError> {
    let lin = linearise::linearise(sys, nodes, lambda, scale, t);
    let rel = rotating::to_rotating(sys, frame, nodes, &lin);
    reduced::solve_dense(rel, sys.n_node_eq, groups, count, true)
}

/// A conservative mode of `ω² = w2` ([`make_mode_s`] with `s = iω`, or `+√(−ω²)`).
fn make_mode(
    shape: Vec<f64>,
    w2: f64,
    zero: bool,
    locals: &[ElementMatrices],
    group_of: &[usize],
    ngroups: usize,
) -> Mode {
    let s = if w2 >= 0.0 {
        (0.0, w2.sqrt())
    } else {
        ((-w2).sqrt(), 0.0)
    };
    make_mode_s(shape, s, zero, locals, group_of, ngroups)
}

fn make_mode_s(
    shape: Vec<f64>,
    s: (f64, f64),
    zero: bool,
    locals: &[ElementMatrices],
    group_of: &[usize],
    ngroups: usize,
) -> Mode {
    let (mut kin, mut strain) = (vec![0.0; ngroups], vec![0.0; ngroups]);
    for (e, el) in locals.iter().enumerate().filter(|_| !shape.is_empty()) {
        let g = group_of.get(e).copied().unwrap_or(0);
        if g < ngroups {
            kin[g] += el.quadratic(&el.m, &shape);
            strain[g] += el.quadratic(&el.k, &shape);
        }
    }
    let share = |v: &mut Vec<f64>| {
        let tot: f64 = v.iter().sum();
        if tot > 0.0 {
            v.iter_mut().for_each(|x| *x /= tot);
        } else {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
    };
    share(&mut kin);
    share(&mut strain);
    let (re, im) = if zero { (0.0, 0.0) } else { s };
    let w = re.hypot(im);
    let kind = if zero {
        ModeKind::Rigid
    } else if re > 0.0 {
        ModeKind::Unstable
    } else {
        ModeKind::Elastic
    };
    Mode {
        kind,
        frequency_hz: im / (2.0 * PI),
        natural_hz: w / (2.0 * PI),
        // `+ 0.0` turns −0 (from `re = 0`) into +0.
        damping_ratio: if w > 0.0 { -re / w + 0.0 } else { 0.0 },
        eigenvalue: (re, im),
        shape,
        kinetic_share: kin,
        strain_share: strain,
    }
}
