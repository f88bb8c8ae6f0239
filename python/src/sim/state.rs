//! The state behind a [`super::Simulation`]'s lock: the deck, the model with the inputs
//! added to it, the run once started and why it failed; the recorder of its histories and
//! the reads of its nodes, elements and sensors.

use crate::deck::Deck;
use crate::overrides::Overrides;
use crate::{MecanoError, SimulationError};
use mecano::app::memory::{self, Recording};
use mecano::elements::NodeState;
use mecano::model::control::{HeldValue, Sensor};
use mecano::model::{ElementId, Model, NodeId};
use mecano::output::Recorder;
use mecano::solver::{self, Integrator, LoopState, Stepper};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// An input added by `add_input`.
pub(super) struct Input {
    pub(super) id: u32,
    /// Its value when held (set between steps, or by an explicit law).
    pub(super) held: Option<Arc<HeldValue>>,
    /// A law called before each step with `(t, sim)` (tangent "explicit").
    pub(super) explicit: Option<Py<PyAny>>,
}

/// An explicit law to call before a step: its input, the callable, the value it sets.
pub(super) type ExplicitLaw = (u32, Py<PyAny>, Arc<HeldValue>);

/// A started run.
pub(super) struct Running {
    pub(super) integ: Integrator,
    pub(super) stepper: Stepper,
    pub(super) rec: Recorder,
}

pub(super) struct Inner {
    pub(super) deck: Deck,
    pub(super) model: Model,
    pub(super) inputs: Vec<Input>,
    pub(super) run: Option<Running>,
    /// Why the simulation cannot go on.
    pub(super) failed: Option<String>,
    /// Values set on the deck's loads and drivers.
    pub(super) overrides: Overrides,
}

impl Inner {
    pub(super) fn usable(&self) -> PyResult<()> {
        match &self.failed {
            Some(why) => Err(SimulationError::new_err(format!(
                "this Simulation failed and cannot go on: {why} (its histories up to the failure: sim.run())"
            ))),
            None => Ok(()),
        }
    }

    /// Starts the run (the inputs are then fixed) unless it is under way.
    pub(super) fn start(&mut self, abort: &Arc<AtomicBool>) -> PyResult<&mut Running> {
        if self.run.is_none() {
            let mut integ = solver::prepare(&self.model)
                .map_err(|e| PyValueError::new_err(format!("{}: {e}", self.deck.name)))?;
            integ.abort = Some(abort.clone());
            self.run = Some(self.running_from(integ, None)?);
        }
        Ok(self.run.as_mut().expect("started"))
    }

    /// The run of `integ` (prepared, or restored from a checkpoint with its step control
    /// `resume`): its recorder, and its stepper at the first state (recorded).
    pub(super) fn running_from(
        &self,
        mut integ: Integrator,
        resume: Option<LoopState>,
    ) -> PyResult<Running> {
        let mut rec = recorder(self, &integ);
        let none = mecano::interrupt::Interrupts::none();
        let stepper = Stepper::start(
            &self.model,
            &mut integ,
            &mut Recording {
                rec: &mut rec,
                interrupts: &none,
            },
            resume,
        )
        .map_err(|e| MecanoError::new_err(e.to_string()))?;
        Ok(Running {
            integ,
            stepper,
            rec,
        })
    }

    pub(super) fn running(&self) -> PyResult<&Running> {
        self.run
            .as_ref()
            .ok_or_else(|| SimulationError::new_err("not started"))
    }

    pub(super) fn node(&self, id: u32) -> PyResult<(usize, NodeState, nalgebra::Vector3<f64>)> {
        let r = self.running()?;
        let i = self.model.nodes.get_index_of(&NodeId(id)).ok_or_else(|| {
            PyKeyError::new_err(format!("node {id} does not exist in {}", self.deck.name))
        })?;
        Ok((i, r.integ.nodes[i], r.integ.sys.x0[i]))
    }

    pub(super) fn element_row(&self, id: u32) -> PyResult<(Vec<String>, Vec<f64>)> {
        let r = self.running()?;
        let e = self
            .model
            .elements
            .get_index_of(&ElementId(id))
            .ok_or_else(|| {
                PyKeyError::new_err(format!("element {id} does not exist in {}", self.deck.name))
            })?;
        let integ = &r.integ;
        let el = &integ.sys.elements[e];
        let reported = integ.reported_multipliers();
        let lam = integ.sys.element_lambda(e, &reported);
        let row = el.output_row(&integ.current_context(), &integ.nodes, lam);
        Ok((el.output_header(), row))
    }
}

/// The recorder of a Simulation's histories. With inputs, the summary's
/// `step_resolution` block (modes about the initial state, `modes::run_summary`) is not
/// computed: its linearisation would call the Python laws with the GIL held. (It also once
/// hung there: on decks/pd_flexible_arm.dat with a PD law faer's blocked real Schur did not
/// return; the run summary now uses the unblocked QR with its iteration limit,
/// `tests/deck/fuzz/pid_flexible_arm_dense_eigen_hang.dat`.)
pub(super) fn recorder(inner: &Inner, integ: &Integrator) -> Recorder {
    if inner.inputs.is_empty() {
        return memory::recorder(&inner.model, &inner.deck.name, inner.deck.refine, integ);
    }
    let mut rec = Recorder::new(&inner.deck.name, &inner.model, &integ.sys);
    rec.refine = inner.deck.refine.max(1);
    rec.notes.insert(
        mecano::modes::run_summary::KEY.into(),
        serde_json::json!({
            "computed": false,
            "reason": "not computed: a Simulation with inputs (use mecano.modes on the deck)",
        }),
    );
    rec
}

pub(super) fn sensor(inner: &Inner, s: Sensor, joint: u32) -> PyResult<f64> {
    let r = inner.running()?;
    if inner.model.hinge_nodes(ElementId(joint)).is_none() {
        return Err(PyKeyError::new_err(format!(
            "element {joint} is not a HINGE"
        )));
    }
    if let Sensor::HingeAngle(_) = s {
        // The joint's own angle, whole turns counted across steps.
        let (h, row) = inner.element_row(joint)?;
        if let Some(i) = h.iter().position(|c| c == "angle") {
            return Ok(row[i]);
        }
    }
    mecano::elements::control::read_sensor(&inner.model, &r.integ.nodes, s)
        .ok_or_else(|| PyValueError::new_err(format!("hinge {joint} has no angle (torn apart)")))
}
