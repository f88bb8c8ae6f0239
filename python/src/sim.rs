//! `mecano.Simulation`: a run you drive step by step ([`mecano::solver::Stepper`]), read
//! between steps, with inputs whose value you set or a Python law gives, and checkpoints.
//!
//! The state is behind a mutex taken with `try_lock`: a second thread using the same
//! Simulation while a step runs gets a `SimulationError`, never a data race.

mod drive;
mod inputs;
mod saved;
mod state;

use crate::deck::{Deck, finite};
use crate::overrides::{self, Overrides};
use crate::poll::Pending;
use crate::run::{RunData, end_time};
use crate::{MecanoError, SimulationError};
use inputs::{InputRequest, check_axis};
use mecano::checkpoint;
use mecano::model::ElementId;
use mecano::model::control::Sensor;
use mecano::solver::StepOutcome;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use state::{Inner, Input, sensor};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// A 3-vector handed to Python.
type Vector<'py> = Bound<'py, PyArray1<f64>>;

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

fn v3<'py>(py: Python<'py>, v: &nalgebra::Vector3<f64>) -> Bound<'py, PyArray1<f64>> {
    vec![v.x, v.y, v.z].into_pyarray(py)
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
        let request = InputRequest {
            hinge,
            node,
            axis,
            value,
            law,
            sensors,
            tangent,
        };
        self.add_input_to(request)
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
        Self::save_to(slf, dir)
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
        Self::load_from(cls, dir, deck)
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

/// The simulation's state, started.
fn started<'a>(slf: &'a Bound<'_, Simulation>) -> PyResult<MutexGuard<'a, Inner>> {
    let this = slf.get();
    let mut inner = this.lock()?;
    inner.start(&this.abort)?;
    Ok(inner)
}
