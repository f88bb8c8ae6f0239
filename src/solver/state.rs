//! The complete state of a run between two steps, for checkpoints and restarts.
//!
//! A restart must reproduce the uninterrupted run bit for bit, so the state holds
//! everything a later step reads, not only the physics: the nodal states and HHT's
//! pseudo-accelerations, the multipliers and their scale, the step controller, the
//! counters, the trial buffers modified Newton starts from, the iteration matrix with
//! its LU factors and pivots (kept across steps of one size), and each element's history
//! (contact flags and attempt memory). Saving only reads: a run that writes checkpoints
//! computes exactly what a run that writes none does.

use super::Stats;
use super::integrator::Integrator;
use super::linear::{LinearError, LuState};
use crate::elements::{ElementState, NodeState, StateMismatch};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// A node's kinematic state in plain arrays (column-major rotation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct NodeRec {
    x: [f64; 3],
    r: [f64; 9],
    v: [f64; 3],
    w: [f64; 3],
    a: [f64; 3],
    wd: [f64; 3],
}

fn arr3(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn arr9(m: &Matrix3<f64>) -> [f64; 9] {
    let mut a = [0.0; 9];
    a.copy_from_slice(m.as_slice());
    a
}

impl From<&NodeState> for NodeRec {
    fn from(s: &NodeState) -> Self {
        NodeRec {
            x: arr3(&s.x),
            r: arr9(&s.r),
            v: arr3(&s.v),
            w: arr3(&s.w),
            a: arr3(&s.a),
            wd: arr3(&s.wd),
        }
    }
}

impl From<&NodeRec> for NodeState {
    fn from(s: &NodeRec) -> Self {
        NodeState {
            x: Vector3::from(s.x),
            r: Matrix3::from_column_slice(&s.r),
            v: Vector3::from(s.v),
            w: Vector3::from(s.w),
            a: Vector3::from(s.a),
            wd: Vector3::from(s.wd),
        }
    }
}

type Pair = [[f64; 3]; 2];

fn pairs(v: &[[Vector3<f64>; 2]]) -> Vec<Pair> {
    v.iter().map(|[a, b]| [arr3(a), arr3(b)]).collect()
}

fn restore_pairs(dst: &mut [[Vector3<f64>; 2]], src: &[Pair]) {
    for (d, [a, b]) in dst.iter_mut().zip(src) {
        *d = [Vector3::from(*a), Vector3::from(*b)];
    }
}

/// Everything of an [`Integrator`] a later step reads (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntegratorState {
    /// The time integration scheme that wrote the state ([`crate::model::Scheme::label`]):
    /// a state resumes only with the same one (another's pseudo-accelerations and history
    /// mean something else).
    scheme: String,
    t: f64,
    stats: Stats,
    nodes: Vec<NodeRec>,
    pseudo: Vec<Pair>,
    lambda: Vec<f64>,
    scale: f64,
    mass_ref: f64,
    stiff_ref: f64,
    rot_mass_ref: f64,
    residual_floor: f64,
    external_work: f64,
    damping_work: f64,
    step_cap: f64,
    error_next: f64,
    event_floor: f64,
    lu_step: f64,
    /// The nodes' orientations the kept LU was computed at (`Integrator::lu_frames`).
    lu_frames: Vec<[f64; 9]>,
    trial: Vec<NodeRec>,
    trial_pseudo: Vec<Pair>,
    trial_lambda: Vec<f64>,
    delta: Vec<f64>,
    u: Vec<Pair>,
    tmap: Vec<[f64; 9]>,
    rhs: Vec<f64>,
    lu: LuState,
    /// The stage schemes' index-1 solve of the reactions (its kept pivots).
    lu_index1: Option<LuState>,
    /// The adaptive steps' drift filter (`CARRY MODES`), once built.
    drift: Option<super::integrator::DriftState>,
    elements: Vec<ElementState>,
    /// The energy guard's record along the run ([`crate::solver::energy_guard::Balance`]).
    balance: crate::solver::energy_guard::Balance,
}

/// Why a saved state cannot be restored into an integrator.
#[derive(Debug, thiserror::Error)]
pub enum StateError {
    /// The state was saved from a model of another size.
    #[error("the saved state has {what} {saved}, the model {model}")]
    Size {
        /// What differs.
        what: &'static str,
        /// Size in the state.
        saved: usize,
        /// Size in the model.
        model: usize,
    },
    /// The state was written by another time integration scheme.
    #[error(
        "the saved state was written by the integrator {saved}, the model asks for {model}: a run resumes only with the integrator that wrote it"
    )]
    Scheme {
        /// The scheme of the state ([`crate::model::Scheme::label`]).
        saved: String,
        /// The model's.
        model: String,
    },
    /// An element's state is of another kind of element.
    #[error(transparent)]
    Element(#[from] StateMismatch),
    /// The LU state does not fit the matrix.
    #[error(transparent)]
    Linear(#[from] LinearError),
    /// The model's start (what a run does before its first step: redundant equations
    /// removed, assembly) failed, so no state of a run of it can exist.
    #[error("the model's start failed: {0}")]
    Start(String),
}

impl IntegratorState {
    /// The time integration scheme that wrote the state ([`crate::model::Scheme::label`]).
    pub fn scheme(&self) -> &str {
        &self.scheme
    }
}

impl Integrator {
    /// The state a restart needs (module docs). Only reads.
    pub fn save_state(&self) -> Result<IntegratorState, StateError> {
        Ok(IntegratorState {
            scheme: self.scheme.label(),
            t: self.t,
            stats: self.stats,
            nodes: self.nodes.iter().map(NodeRec::from).collect(),
            pseudo: pairs(&self.pseudo),
            lambda: self.lambda.clone(),
            scale: self.scale,
            mass_ref: self.mass_ref,
            stiff_ref: self.stiff_ref,
            rot_mass_ref: self.rot_mass_ref,
            residual_floor: self.residual_floor,
            external_work: self.external_work,
            damping_work: self.damping_work,
            step_cap: self.step_cap,
            error_next: self.error_next,
            event_floor: self.event_floor,
            lu_step: self.lu_step,
            lu_frames: self.lu_frames.iter().map(arr9).collect(),
            trial: self.trial.iter().map(NodeRec::from).collect(),
            trial_pseudo: pairs(&self.trial_pseudo),
            trial_lambda: self.trial_lambda.clone(),
            delta: self.delta.clone(),
            u: pairs(&self.u),
            tmap: self.tmap.iter().map(arr9).collect(),
            rhs: self.sys.rhs.clone(),
            lu: self.sys.matrix.save_state(),
            lu_index1: self.index1_lu(),
            drift: self.drift_state(),
            elements: self.sys.elements.iter().map(|e| e.save_state()).collect(),
            balance: self.balance,
        })
    }

    /// Restores a [`Integrator::save_state`] into an integrator prepared from the same
    /// model ([`super::prepare`]). The integrator is first started as the run was
    /// ([`Integrator::initialize`], if not yet: the constraint equations removed as
    /// redundant, the notices), which the state then overwrites. Sizes are checked first:
    /// on error the integrator is left as it was or partly restored, and must not be run.
    pub fn restore_state(&mut self, s: IntegratorState) -> Result<(), StateError> {
        if !self.started {
            self.initialize()
                .map_err(|f| StateError::Start(f.to_string()))?;
        }
        let nn = self.nodes.len();
        let n = self.sys.n_eq();
        let ne = self.sys.elements.len();
        let checks = [
            ("nodes", s.nodes.len(), nn),
            ("trial nodes", s.trial.len(), nn),
            ("pseudo-accelerations", s.pseudo.len(), nn),
            ("trial pseudo-accelerations", s.trial_pseudo.len(), nn),
            ("increments", s.u.len(), nn),
            ("tangent maps", s.tmap.len(), nn),
            ("factorisation frames", s.lu_frames.len(), nn),
            ("equations", s.lambda.len(), n),
            ("trial multipliers", s.trial_lambda.len(), n),
            ("Newton corrections", s.delta.len(), n),
            ("residuals", s.rhs.len(), n),
            ("elements", s.elements.len(), ne),
        ];
        if s.scheme != self.scheme.label() {
            return Err(StateError::Scheme {
                saved: s.scheme,
                model: self.scheme.label(),
            });
        }
        if let Some((what, saved, model)) = checks.into_iter().find(|c| c.1 != c.2) {
            return Err(StateError::Size { what, saved, model });
        }
        for (el, st) in self.sys.elements.iter_mut().zip(&s.elements) {
            el.restore_state(st)?;
        }
        self.sys.matrix.restore_state(s.lu)?;
        self.restore_index1_lu(s.lu_index1)?;
        self.restore_drift(s.drift)?;
        self.t = s.t;
        self.stats = s.stats;
        for (d, r) in self.nodes.iter_mut().zip(&s.nodes) {
            *d = NodeState::from(r);
        }
        for (d, r) in self.trial.iter_mut().zip(&s.trial) {
            *d = NodeState::from(r);
        }
        restore_pairs(&mut self.pseudo, &s.pseudo);
        restore_pairs(&mut self.trial_pseudo, &s.trial_pseudo);
        restore_pairs(&mut self.u, &s.u);
        for (d, m) in self.tmap.iter_mut().zip(&s.tmap) {
            *d = Matrix3::from_column_slice(m);
        }
        for (d, m) in self.lu_frames.iter_mut().zip(&s.lu_frames) {
            *d = Matrix3::from_column_slice(m);
        }
        self.lambda = s.lambda;
        self.trial_lambda = s.trial_lambda;
        self.delta = s.delta;
        self.sys.rhs = s.rhs;
        self.scale = s.scale;
        self.mass_ref = s.mass_ref;
        self.stiff_ref = s.stiff_ref;
        self.rot_mass_ref = s.rot_mass_ref;
        self.residual_floor = s.residual_floor;
        self.external_work = s.external_work;
        self.damping_work = s.damping_work;
        self.step_cap = s.step_cap;
        self.error_next = s.error_next;
        self.event_floor = s.event_floor;
        self.lu_step = s.lu_step;
        self.balance = s.balance;
        self.guard_cache = None;
        Ok(())
    }
}
