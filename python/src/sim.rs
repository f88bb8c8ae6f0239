//! `mecano.Simulation`: a run you drive step by step ([`mecano::solver::Stepper`]), read
//! between steps, with inputs whose value you set or a Python law gives, and checkpoints.
//!
//! The state is behind a mutex taken with `try_lock`: a second thread using the same
//! Simulation while a step runs gets a `SimulationError`, never a data race.

use crate::deck::{Deck, finite};
use crate::law::PyLaw;
use crate::overrides::{self, Overrides};
use crate::poll::{self, Pending};
use crate::run::{RunData, end_time};
use crate::{MecanoError, SimulationError};
use mecano::app::memory::{self, Recording};
use mecano::checkpoint::{self, Checkpoint};
use mecano::elements::NodeState;
use mecano::model::control::{Actuator, ControlData, ControlLaw, HeldValue, Sensor};
use mecano::model::{ElementId, Model, NodeId};
use mecano::output::Recorder;
use mecano::solver::{self, Integrator, RunError, StepOutcome, Stepper};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// An input added by `add_input`.
struct Input {
    id: u32,
    /// Its value when held (set between steps, or by an explicit law).
    held: Option<Arc<HeldValue>>,
    /// A law called before each step with `(t, sim)` (tangent "explicit").
    explicit: Option<Py<PyAny>>,
}

/// An explicit law to call before a step: its input, the callable, the value it sets.
type ExplicitLaw = (u32, Py<PyAny>, Arc<HeldValue>);

/// A 3-vector handed to Python.
type Vector<'py> = Bound<'py, PyArray1<f64>>;

/// A started run.
struct Running {
    integ: Integrator,
    stepper: Stepper,
    rec: Recorder,
}

struct Inner {
    deck: Deck,
    model: Model,
    inputs: Vec<Input>,
    run: Option<Running>,
    /// Why the simulation cannot go on.
    failed: Option<String>,
    /// Values set on the deck's loads and drivers.
    overrides: Overrides,
}

/// A simulation of a deck you advance yourself (see the Python docstrings in mecano/).
#[pyclass(module = "mecano", frozen, subclass)]
pub struct Simulation {
    inner: Mutex<Inner>,
    /// The error a Python law raised inside a step.
    pending: Pending,
    /// A KeyboardInterrupt a law caught inside a step: the run stops at the step's end.
    ctrl_c: Pending,
    /// Set by a failing law: the step under way is given up.
    abort: Arc<AtomicBool>,
    /// Whether an explicit law is being called (it may read the simulation, not step it).
    in_law: AtomicBool,
}

fn busy() -> PyErr {
    SimulationError::new_err(
        "this Simulation is in use by another thread (or by a law called from its step): one thread at a time",
    )
}

/// A sensor from its Python form: `("angle" | "rate", hinge)` or
/// `("x" | "y" | "z" | "vx" | "vy" | "vz", node)`.
fn sensor_of(obj: &Bound<'_, PyAny>) -> PyResult<Sensor> {
    let bad = || {
        PyTypeError::new_err(format!(
            "a sensor is ('angle'|'rate', hinge) or ('x'|'y'|'z'|'vx'|'vy'|'vz', node), not {}",
            obj.repr().map(|r| r.to_string()).unwrap_or_default()
        ))
    };
    let (kind, id): (String, u32) = obj.extract().map_err(|_| bad())?;
    Ok(match kind.as_str() {
        "angle" => Sensor::HingeAngle(ElementId(id)),
        "rate" => Sensor::HingeRate(ElementId(id)),
        "x" | "y" | "z" => Sensor::Coordinate(NodeId(id), axis_of(&kind)),
        "vx" | "vy" | "vz" => Sensor::Velocity(NodeId(id), axis_of(&kind[1..])),
        _ => return Err(bad()),
    })
}

fn axis_of(s: &str) -> usize {
    match s {
        "x" => 0,
        "y" => 1,
        _ => 2,
    }
}

fn check_axis(a: usize) -> PyResult<usize> {
    if a < 3 {
        Ok(a)
    } else {
        Err(PyValueError::new_err(format!("axis {a} is not 0, 1 or 2")))
    }
}

fn v3<'py>(py: Python<'py>, v: &nalgebra::Vector3<f64>) -> Bound<'py, PyArray1<f64>> {
    vec![v.x, v.y, v.z].into_pyarray(py)
}

impl Inner {
    fn usable(&self) -> PyResult<()> {
        match &self.failed {
            Some(why) => Err(SimulationError::new_err(format!(
                "this Simulation failed and cannot go on: {why} (its histories up to the failure: sim.run())"
            ))),
            None => Ok(()),
        }
    }

    /// Starts the run (the inputs are then fixed) unless it is under way.
    fn start(&mut self, abort: &Arc<AtomicBool>) -> PyResult<&mut Running> {
        if self.run.is_none() {
            let mut integ = solver::prepare(&self.model)
                .map_err(|e| PyValueError::new_err(format!("{}: {e}", self.deck.name)))?;
            integ.abort = Some(abort.clone());
            let mut rec = recorder(self, &integ);
            let none = mecano::interrupt::Interrupts::none();
            let stepper = Stepper::start(
                &self.model,
                &mut integ,
                &mut Recording {
                    rec: &mut rec,
                    interrupts: &none,
                },
                None,
            )
            .map_err(|e| MecanoError::new_err(e.to_string()))?;
            self.run = Some(Running {
                integ,
                stepper,
                rec,
            });
        }
        Ok(self.run.as_mut().expect("started"))
    }

    fn running(&self) -> PyResult<&Running> {
        self.run
            .as_ref()
            .ok_or_else(|| SimulationError::new_err("not started"))
    }

    fn node(&self, id: u32) -> PyResult<(usize, NodeState, nalgebra::Vector3<f64>)> {
        let r = self.running()?;
        let i = self.model.nodes.get_index_of(&NodeId(id)).ok_or_else(|| {
            PyKeyError::new_err(format!("node {id} does not exist in {}", self.deck.name))
        })?;
        Ok((i, r.integ.nodes[i], r.integ.sys.x0[i]))
    }

    fn element_row(&self, id: u32) -> PyResult<(Vec<String>, Vec<f64>)> {
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

impl Simulation {
    fn lock(&self) -> PyResult<MutexGuard<'_, Inner>> {
        match self.inner.try_lock() {
            Ok(g) => Ok(g),
            Err(std::sync::TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(std::sync::TryLockError::WouldBlock) => Err(busy()),
        }
    }

    fn new_from(deck: Deck) -> Self {
        Simulation {
            inner: Mutex::new(Inner {
                model: deck.model.clone(),
                deck,
                inputs: Vec::new(),
                run: None,
                failed: None,
                overrides: Overrides::default(),
            }),
            pending: Arc::new(Mutex::new(None)),
            ctrl_c: Arc::new(Mutex::new(None)),
            abort: Arc::new(AtomicBool::new(false)),
            in_law: AtomicBool::new(false),
        }
    }

    /// Calls the explicit laws with `(t, sim)` and holds their values over the next step.
    fn explicit_laws(slf: &Bound<'_, Self>) -> PyResult<()> {
        let this = slf.get();
        let (laws, t): (Vec<ExplicitLaw>, f64) = {
            let inner = this.lock()?;
            // A failed simulation says so before any law is called again.
            inner.usable()?;
            let laws = inner
                .inputs
                .iter()
                .filter_map(|i| {
                    Some((
                        i.id,
                        i.explicit.as_ref()?.clone_ref(slf.py()),
                        i.held.clone()?,
                    ))
                })
                .collect();
            (laws, inner.run.as_ref().map_or(0.0, |r| r.integ.t))
        };
        let mut changed = false;
        for (id, f, held) in laws {
            this.in_law.store(true, Ordering::SeqCst);
            let r = f.call1(slf.py(), (t, slf));
            this.in_law.store(false, Ordering::SeqCst);
            let fail = |e: PyErr| -> PyErr {
                // Ctrl-C in the law, between steps: the simulation stops there, usable.
                if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(slf.py()) {
                    return e;
                }
                if let Ok(mut inner) = this.lock() {
                    inner.failed = Some(format!("the law of input {id} raised at t = {t} s"));
                }
                e
            };
            let r = r.map_err(fail)?;
            let v: f64 = r.extract(slf.py()).map_err(|_| {
                fail(PyTypeError::new_err(format!(
                    "the law of input {id} returned {}, not a number",
                    r.bind(slf.py())
                        .repr()
                        .map(|x| x.to_string())
                        .unwrap_or_default()
                )))
            })?;
            if !v.is_finite() {
                return Err(fail(PyValueError::new_err(format!(
                    "the law of input {id} returned {v} at t = {t} s"
                ))));
            }
            changed |= held.get() != v;
            held.set(v);
        }
        // Before the first step the initial accelerations were computed with the inputs'
        // `value`: recomputed with the laws' values at t = 0, so the first step starts
        // from the equations of motion it integrates (the arm held at rest by its law
        // stays at rest), and the t = 0 row is recorded again with them.
        if changed {
            let mut inner = this.lock()?;
            if let Some(r) = inner.run.as_mut()
                && r.integ.stats.steps == 0
                && r.integ.t == 0.0
            {
                overrides::restart(&mut r.integ, &mut r.rec)?;
            }
        }
        Ok(())
    }

    /// Runs `go` on the started run with the GIL released and Ctrl-C polled; turns what
    /// stopped it into Python's exception.
    fn drive<F>(slf: &Bound<'_, Self>, go: F) -> PyResult<StepOutcome>
    where
        F: FnOnce(&mut Stepper, &mut Integrator, &mut Recording) -> Result<StepOutcome, RunError>
            + Send,
    {
        let py = slf.py();
        let this = slf.get();
        if this.in_law.load(Ordering::SeqCst) {
            return Err(busy());
        }
        let mut inner = this.lock()?;
        inner.usable()?;
        let end = inner
            .run
            .as_ref()
            .map_or(end_time(&inner.model), |r| r.stepper.end);
        let (interrupts, stop) = poll::interrupts(None, end, Some(this.ctrl_c.clone()));
        let inner_ref: &mut Inner = &mut inner;
        inner_ref.start(&this.abort)?;
        let run = inner_ref.run.as_mut().expect("started");
        let result = py.detach(|| {
            let Running {
                integ,
                stepper,
                rec,
            } = run;
            let mut obs = Recording {
                rec,
                interrupts: &interrupts,
            };
            go(stepper, integ, &mut obs)
        });
        let law_error = poll::take(&this.pending);
        // Ctrl-C caught by a law in the last step (if the pauses did not see it).
        let ctrl_c = poll::take(&this.ctrl_c);
        let t = run.integ.t;
        if let Some(e) = law_error {
            inner.failed = Some(format!("a law raised at t = {t} s: {e}"));
            return Err(e);
        }
        let outcome = match result {
            Ok(o) => o,
            Err(e) => {
                inner.failed = Some(e.to_string());
                return Err(MecanoError::new_err(e.to_string()));
            }
        };
        // A step that failed is a failure, whatever Ctrl-C a law caught in it.
        let ctrl_c = ctrl_c.filter(|_| outcome != StepOutcome::Failed);
        if let Some(e) = poll::take(&stop).or(ctrl_c) {
            // Ctrl-C: stopped at the end of a step; the simulation can go on.
            if let Some(r) = inner.run.as_mut() {
                r.stepper.clear_stop();
            }
            return Err(e);
        }
        if outcome == StepOutcome::Failed {
            let msg = inner
                .run
                .as_ref()
                .and_then(|r| r.stepper.failure().map(|f| f.to_string()))
                .unwrap_or_default();
            inner.failed = Some(msg.clone());
            return Err(MecanoError::new_err(format!(
                "the step failed: {msg}\n(histories up to t = {t} s are kept: sim.run())"
            )));
        }
        Ok(outcome)
    }
}

#[pymethods]
impl Simulation {
    /// A simulation of `deck` (a Deck or a path), at its initial state once started.
    #[new]
    fn py_new(deck: &Bound<'_, PyAny>) -> PyResult<Self> {
        let deck = Deck::of(deck)?;
        if deck.model.modes.is_some() {
            return Err(PyValueError::new_err(format!(
                "{} asks for a modal analysis (ANALYSIS MODES): use mecano.modes(deck)",
                deck.name
            )));
        }
        Ok(Self::new_from(deck))
    }

    /// Adds an input before the first step; returns its element number.
    #[pyo3(signature = (*, hinge = None, node = None, axis = None, value = 0.0, law = None, sensors = None, tangent = "differentiated"))]
    #[allow(clippy::too_many_arguments)]
    fn add_input(
        &self,
        hinge: Option<u32>,
        node: Option<u32>,
        axis: Option<usize>,
        value: f64,
        law: Option<Py<PyAny>>,
        sensors: Option<Vec<Bound<'_, PyAny>>>,
        tangent: &str,
    ) -> PyResult<u32> {
        let mut inner = self.lock()?;
        if inner.run.is_some() {
            return Err(SimulationError::new_err(
                "inputs are added before the simulation starts (its first step or state query)",
            ));
        }
        finite("value", value)?;
        let actuator = match (hinge, node, axis) {
            (Some(h), None, None) => Actuator::HingeTorque(ElementId(h)),
            (None, Some(n), Some(a)) => Actuator::NodeForce(NodeId(n), check_axis(a)?),
            (None, Some(_), None) => {
                return Err(PyValueError::new_err(
                    "a force on a node needs its axis (0, 1, 2)",
                ));
            }
            _ => {
                return Err(PyValueError::new_err(
                    "an input acts on a hinge (hinge=) or on a node along an axis (node=, axis=)",
                ));
            }
        };
        let sensors: Vec<Sensor> = sensors
            .unwrap_or_default()
            .iter()
            .map(sensor_of)
            .collect::<PyResult<_>>()?;
        let id = inner.model.elements.keys().map(|k| k.0).max().unwrap_or(0) + 1;
        let mut input = Input {
            id,
            held: None,
            explicit: None,
        };
        let law_kind = match law {
            None => {
                let h = HeldValue::new(value);
                input.held = Some(h.clone());
                ControlLaw::Held(h)
            }
            Some(f) => {
                Python::attach(|py| {
                    if f.bind(py).is_callable() {
                        Ok(())
                    } else {
                        Err(PyTypeError::new_err("law must be a callable of (t, sim)"))
                    }
                })?;
                match tangent {
                    "explicit" => {
                        let h = HeldValue::new(value);
                        input.held = Some(h.clone());
                        input.explicit = Some(f);
                        ControlLaw::Held(h)
                    }
                    "differentiated" => {
                        if sensors.is_empty() {
                            return Err(PyValueError::new_err(
                                "a differentiated law names the sensors it reads: sensors=[('angle', 3), ('rate', 3)]",
                            ));
                        }
                        ControlLaw::External(Arc::new(PyLaw {
                            f,
                            sensors: Arc::new(sensors.clone()),
                            input: id,
                            pending: self.pending.clone(),
                            abort: self.abort.clone(),
                            interrupt: self.ctrl_c.clone(),
                        }))
                    }
                    other => {
                        return Err(PyValueError::new_err(format!(
                            "tangent is 'differentiated' or 'explicit', not {other:?}"
                        )));
                    }
                }
            }
        };
        inner
            .model
            .add_control(
                ElementId(id),
                ControlData {
                    actuator,
                    sensors,
                    law: law_kind,
                },
            )
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        inner.inputs.push(input);
        Ok(id)
    }

    /// Sets a held input's value (N·m or N), used from the next step on; in a started
    /// dynamic run the accelerations restart from it (see set_load).
    fn set_input(&self, input: u32, value: f64) -> PyResult<()> {
        finite("value", value)?;
        let mut inner = self.lock()?;
        let inner: &mut Inner = &mut inner;
        match inner.inputs.iter().find(|i| i.id == input) {
            Some(Input {
                held: Some(h),
                explicit: None,
                ..
            }) => {
                let changed = h.get() != value;
                h.set(value);
                if changed
                    && inner.failed.is_none()
                    && let Some(r) = inner.run.as_mut()
                {
                    overrides::restart(&mut r.integ, &mut r.rec)?;
                }
                Ok(())
            }
            Some(_) => Err(PyValueError::new_err(format!(
                "input {input} follows its law: its value is not set by hand"
            ))),
            None => Err(PyKeyError::new_err(format!("no input {input}"))),
        }
    }

    /// Holds load `load`'s time function at `value` from now on (the load is then
    /// `value` times the components its card gives, N or N·m), or gives it its deck
    /// function back (`None`). Loads are numbered from 1 in the order of the FORCE and
    /// MOMENT cards of LOADS. A dynamic run restarts its accelerations from the new load.
    /// Starts the simulation.
    #[pyo3(signature = (load, value))]
    fn set_load(slf: &Bound<'_, Self>, load: u32, value: Option<f64>) -> PyResult<()> {
        let this = slf.get();
        if this.in_law.load(Ordering::SeqCst) {
            return Err(busy());
        }
        let mut inner = this.lock()?;
        inner.usable()?;
        let inner: &mut Inner = &mut inner;
        inner.start(&this.abort)?;
        let r = inner.run.as_mut().expect("started");
        if inner.overrides.set_load(&mut r.integ, load, value)? {
            overrides::restart(&mut r.integ, &mut r.rec)?;
        }
        Ok(())
    }

    /// Sets driver `element`'s prescribed value (rad or m; a HINGE/PRISMATIC with DRIVE,
    /// or a PRESCRIBED): reached `over` seconds from now along the C² quintic from the
    /// law's present value, rate and acceleration, then held at rest. `over = 0` only
    /// where that is no jump. Starts the simulation.
    #[pyo3(signature = (element, value, over = 0.0))]
    fn set_drive(slf: &Bound<'_, Self>, element: u32, value: f64, over: f64) -> PyResult<()> {
        let this = slf.get();
        if this.in_law.load(Ordering::SeqCst) {
            return Err(busy());
        }
        finite("value", value)?;
        finite("over", over)?;
        let mut inner = this.lock()?;
        inner.usable()?;
        let inner: &mut Inner = &mut inner;
        inner.start(&this.abort)?;
        let r = inner.run.as_mut().expect("started");
        inner
            .overrides
            .set_drive(&inner.model, &mut r.integ, element, value, over)
    }

    /// Time reached, s.
    #[getter]
    fn t(slf: &Bound<'_, Self>) -> PyResult<f64> {
        let this = slf.get();
        let mut inner = this.lock()?;
        Ok(inner.start(&this.abort)?.integ.t)
    }

    /// End time of the deck's analysis (moved by advance(t) beyond it), s.
    #[getter]
    fn end(&self) -> PyResult<f64> {
        let inner = self.lock()?;
        Ok(inner
            .run
            .as_ref()
            .map_or(end_time(&inner.model), |r| r.stepper.end))
    }

    /// Takes one accepted step; returns the time reached (s).
    fn step(slf: &Bound<'_, Self>) -> PyResult<f64> {
        Self::explicit_laws(slf)?;
        Self::drive(slf, |stepper, integ, obs| {
            if !stepper.running(integ) {
                // Past the deck's end time: a driven simulation goes on.
                stepper.end = f64::INFINITY;
            }
            stepper.step(integ, obs)
        })?;
        Self::t(slf)
    }

    /// Steps until time `t` (s), landing on it; returns the time reached.
    fn advance(slf: &Bound<'_, Self>, t: f64) -> PyResult<f64> {
        finite("t", t)?;
        let explicit = slf
            .get()
            .lock()?
            .inputs
            .iter()
            .any(|i| i.explicit.is_some());
        if explicit {
            // A law called between steps: one step at a time, with the GIL in between.
            loop {
                let now = Self::t(slf)?;
                if now >= t - 1e-12 * t.abs().max(1.0) {
                    return Ok(now);
                }
                Self::explicit_laws(slf)?;
                let o = Self::drive(slf, |stepper, integ, obs| {
                    stepper.step_toward(t, integ, obs)
                })?;
                if o != StepOutcome::Accepted {
                    return Self::t(slf);
                }
            }
        }
        Self::drive(slf, |stepper, integ, obs| stepper.advance_to(t, integ, obs))?;
        Self::t(slf)
    }

    /// Node `node`'s position (global, m).
    fn position<'py>(slf: &Bound<'py, Self>, node: u32) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, s, _) = started(slf)?.node(node)?;
        Ok(v3(slf.py(), &s.x))
    }

    /// Node `node`'s displacement from its reference position (global, m).
    fn displacement<'py>(slf: &Bound<'py, Self>, node: u32) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, s, x0) = started(slf)?.node(node)?;
        Ok(v3(slf.py(), &(s.x - x0)))
    }

    /// Node `node`'s rotation matrix (material frame to global).
    fn rotation<'py>(slf: &Bound<'py, Self>, node: u32) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (_, s, _) = started(slf)?.node(node)?;
        let r = s.r;
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|i| (0..3).map(|j| r[(i, j)]).collect())
            .collect();
        PyArray2::from_vec2(slf.py(), &rows).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Node `node`'s velocity (global, m/s), or its component along `axis`.
    #[pyo3(signature = (node, axis = None))]
    fn velocity<'py>(
        slf: &Bound<'py, Self>,
        node: u32,
        axis: Option<usize>,
    ) -> PyResult<Py<PyAny>> {
        let (_, s, _) = started(slf)?.node(node)?;
        let py = slf.py();
        Ok(match axis {
            Some(a) => s.v[check_axis(a)?].into_pyobject(py)?.into_any().unbind(),
            None => v3(py, &s.v).into_any().unbind(),
        })
    }

    /// Node `node`'s global coordinate along `axis` (0, 1, 2), m.
    fn coordinate(slf: &Bound<'_, Self>, node: u32, axis: usize) -> PyResult<f64> {
        let (_, s, _) = started(slf)?.node(node)?;
        Ok(s.x[check_axis(axis)?])
    }

    /// Node `node`'s angular velocity (global, rad/s).
    fn angular_velocity<'py>(
        slf: &Bound<'py, Self>,
        node: u32,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, s, _) = started(slf)?.node(node)?;
        Ok(v3(slf.py(), &(s.r * s.w)))
    }

    /// Node `node`'s acceleration (global, m/s²).
    fn acceleration<'py>(slf: &Bound<'py, Self>, node: u32) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, s, _) = started(slf)?.node(node)?;
        Ok(v3(slf.py(), &s.a))
    }

    /// HINGE `joint`'s relative angle, rad (whole turns counted).
    fn joint_angle(slf: &Bound<'_, Self>, joint: u32) -> PyResult<f64> {
        let inner = started(slf)?;
        sensor(&inner, Sensor::HingeAngle(ElementId(joint)), joint)
    }

    /// HINGE `joint`'s relative rate, rad/s.
    fn joint_rate(slf: &Bound<'_, Self>, joint: u32) -> PyResult<f64> {
        let inner = started(slf)?;
        sensor(&inner, Sensor::HingeRate(ElementId(joint)), joint)
    }

    /// Element `element`'s outputs now, as its history's columns name them (a joint's
    /// reaction force fx, fy, fz in N and moment mx, my, mz in N·m, global; a beam's
    /// resultants; an input's value; ...).
    fn element<'py>(slf: &Bound<'py, Self>, element: u32) -> PyResult<Bound<'py, PyDict>> {
        let (h, row) = started(slf)?.element_row(element)?;
        let d = PyDict::new(slf.py());
        for (k, v) in h.iter().zip(row) {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// A joint's reaction now: (force N, moment N·m), global, on its second node.
    fn reaction<'py>(slf: &Bound<'py, Self>, element: u32) -> PyResult<(Vector<'py>, Vector<'py>)> {
        let (h, row) = started(slf)?.element_row(element)?;
        let col = |name: &str| h.iter().position(|c| c == name).map(|i| row[i]);
        match (
            col("fx"),
            col("fy"),
            col("fz"),
            col("mx"),
            col("my"),
            col("mz"),
        ) {
            (Some(a), Some(b), Some(c), Some(d), Some(e), Some(f)) => Ok((
                vec![a, b, c].into_pyarray(slf.py()),
                vec![d, e, f].into_pyarray(slf.py()),
            )),
            _ => Err(PyValueError::new_err(format!(
                "element {element} has no reaction (its outputs: {})",
                h.join(", ")
            ))),
        }
    }

    /// Whether the simulation failed (and cannot go on).
    #[getter]
    fn failed(&self) -> PyResult<Option<String>> {
        Ok(self.lock()?.failed.clone())
    }

    /// The histories so far (the deck's OUTPUT selection) and the summary: `complete`
    /// only once the deck's end time is reached without failure; a law's error (which
    /// the solver did not see) is the summary's `failure`, a simulation short of its end
    /// is `stop: {"reason": "paused"}`.
    fn run_data(slf: &Bound<'_, Self>) -> PyResult<RunData> {
        let this = slf.get();
        let mut inner = this.lock()?;
        let deck_end = end_time(&inner.model);
        let failed = inner.failed.clone();
        let r = inner.start(&this.abort)?;
        let report = r.stepper.report(&r.integ);
        let mut summary = r.rec.summary(&r.integ, Some(&report));
        let (t, steps) = (r.integ.t, r.integ.stats.steps);
        let reached = t >= deck_end - 1e-9 * deck_end.abs().max(1.0);
        if failed.is_some() || !reached {
            summary["complete"] = false.into();
        }
        if let Some(why) = failed
            && summary["failure"].is_null()
        {
            summary["failure"] = serde_json::json!({ "message": why, "time": t, "step": steps });
            summary["stop"] = serde_json::json!({ "reason": "failed", "time": t, "step": steps });
        } else if !reached && summary["stop"].is_null() {
            summary["stop"] = serde_json::json!({ "reason": "paused", "time": t, "step": steps });
        }
        Ok(RunData::from_memory(
            r.rec.nodes.clone(),
            r.rec.elements.clone(),
            r.rec.energy.clone(),
            summary,
        ))
    }

    /// Writes the state to `dir`/checkpoint.bin (the checkpoint format of mecano-rs).
    fn save(slf: &Bound<'_, Self>, dir: PathBuf) -> PyResult<()> {
        let this = slf.get();
        let mut inner = this.lock()?;
        inner.usable()?;
        let deck = inner.deck.clone();
        let r = inner.start(&this.abort)?;
        let integrator = r
            .integ
            .save_state()
            .map_err(|e| MecanoError::new_err(e.to_string()))?;
        let id = mecano::app::deck_identity(
            deck.path
                .as_deref()
                .unwrap_or(std::path::Path::new(&deck.name)),
            &deck.text,
            &deck.set,
            deck.refine,
        );
        let c = Checkpoint {
            program: format!("mecano (Python) {}", env!("CARGO_PKG_VERSION")),
            deck: mecano::checkpoint::DeckIdentity {
                path: deck.name.clone(),
                ..id
            },
            time: r.integ.t,
            step: r.integ.stats.steps,
            control: r.stepper.control(),
            integrator,
            writer: Default::default(),
            vtk: None,
        };
        let held: Vec<(u32, f64)> = inner
            .inputs
            .iter()
            .filter(|i| i.explicit.is_none())
            .filter_map(|i| Some((i.id, i.held.as_ref()?.get())))
            .collect();
        let record = inner.overrides.record(c.time, c.step, &held);
        std::fs::create_dir_all(&dir)
            .map_err(|e| MecanoError::new_err(format!("{}: {e}", dir.display())))?;
        // The values set from Python first: a checkpoint left without its record would be
        // refused at load by the record's time, never restored without them.
        overrides::write(&dir, &record)?;
        checkpoint::write(&dir, &c, 1)
            .map_err(|e| MecanoError::new_err(format!("{}: {e}", dir.display())))
    }

    /// A simulation restored from `dir`/checkpoint.bin (its deck read again from where it
    /// was, or `deck`; a deck whose text differs is refused).
    #[classmethod]
    #[pyo3(signature = (dir, deck = None))]
    fn load<'py>(
        cls: &Bound<'py, pyo3::types::PyType>,
        dir: PathBuf,
        deck: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = cls.py();
        let c = checkpoint::read(&dir).map_err(|e| MecanoError::new_err(e.to_string()))?;
        let deck = match deck {
            Some(d) => Deck::of(d)?,
            None => {
                let path = c
                    .deck
                    .absolute
                    .clone()
                    .unwrap_or_else(|| c.deck.path.clone());
                Deck::of(&pyo3::types::PyString::new(py, &path).into_any())?
            }
        };
        let deck = if deck.set != c.deck.set || deck.refine != c.deck.refine.max(1) {
            Deck::parse(
                py,
                deck.text,
                deck.name,
                deck.path,
                c.deck.set.clone(),
                c.deck.refine,
            )?
        } else {
            deck
        };
        let sim = cls.call1((Py::new(py, deck)?,))?;
        sim.cast::<Simulation>()?.get().restore_from(c, &dir)?;
        Ok(sim)
    }

    /// Restores this (not yet started) simulation from `dir`/checkpoint.bin: for a
    /// simulation with inputs, add the same inputs first.
    fn restore(&self, dir: PathBuf) -> PyResult<()> {
        let c = checkpoint::read(&dir).map_err(|e| MecanoError::new_err(e.to_string()))?;
        self.restore_from(c, &dir)
    }

    fn __repr__(&self) -> String {
        match self.inner.try_lock() {
            Ok(i) => format!(
                "Simulation({:?}, t={}, inputs={})",
                i.deck.name,
                i.run.as_ref().map_or(0.0, |r| r.integ.t),
                i.inputs.len()
            ),
            Err(_) => "Simulation(<in use>)".into(),
        }
    }
}

impl Simulation {
    fn restore_from(&self, c: Checkpoint, dir: &std::path::Path) -> PyResult<()> {
        let saved = overrides::read(dir, c.time, c.step)?;
        let mut inner = self.lock()?;
        if inner.run.is_some() {
            return Err(SimulationError::new_err(
                "restore() is for a simulation not yet started",
            ));
        }
        let sha = mecano::checkpoint::sha256_hex(inner.deck.text.as_bytes());
        if sha != c.deck.sha256 {
            return Err(MecanoError::new_err(format!(
                "the checkpoint belongs to another deck text than {} (SHA-256 {} vs {})",
                inner.deck.name, c.deck.sha256, sha
            )));
        }
        let mut integ =
            solver::prepare(&inner.model).map_err(|e| PyValueError::new_err(e.to_string()))?;
        integ.abort = Some(self.abort.clone());
        integ.restore_state(c.integrator).map_err(|e| {
            MecanoError::new_err(format!(
                "{e} (a simulation saved with inputs is restored by one with the same inputs: add them, then sim.restore(dir))"
            ))
        })?;
        let mut rec = recorder(&inner, &integ);
        let none = mecano::interrupt::Interrupts::none();
        let stepper = Stepper::start(
            &inner.model,
            &mut integ,
            &mut Recording {
                rec: &mut rec,
                interrupts: &none,
            },
            Some(c.control),
        )
        .map_err(|e| MecanoError::new_err(e.to_string()))?;
        if let Some(saved) = saved {
            let inner: &mut Inner = &mut inner;
            inner.overrides.restore(&inner.model, &mut integ, &saved)?;
            for (id, v) in saved.inputs {
                match inner.inputs.iter().find(|i| i.id == id) {
                    Some(Input {
                        held: Some(h),
                        explicit: None,
                        ..
                    }) => h.set(v),
                    _ => {
                        return Err(SimulationError::new_err(format!(
                            "the checkpoint was saved with input {id} held at {v}: add the same inputs (add_input), then sim.restore(dir)"
                        )));
                    }
                }
            }
        }
        inner.run = Some(Running {
            integ,
            stepper,
            rec,
        });
        Ok(())
    }
}

/// The recorder of a Simulation's histories. With inputs, the summary's
/// `step_resolution` block (modes about the initial state, `modes::run_summary`) is not
/// computed: it would call the Python laws with the GIL held, and on
/// decks/pd_flexible_arm.dat with a PD law the dense eigensolver of that block does not
/// return (faer's real Schur; the CLI hangs the same way with a deck PID on that arm).
fn recorder(inner: &Inner, integ: &Integrator) -> Recorder {
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

/// The simulation's state, started.
fn started<'a>(slf: &'a Bound<'_, Simulation>) -> PyResult<MutexGuard<'a, Inner>> {
    let this = slf.get();
    let mut inner = this.lock()?;
    inner.start(&this.abort)?;
    Ok(inner)
}

fn sensor(inner: &Inner, s: Sensor, joint: u32) -> PyResult<f64> {
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
