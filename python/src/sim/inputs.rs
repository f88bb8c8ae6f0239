//! The inputs a Python program adds to a [`super::Simulation`] before it starts: a torque
//! on a hinge or a force on a node, held at a value, or following a law of `(t, sim)` —
//! called between steps ("explicit") or at every Newton iterate with its derivatives
//! ("differentiated", of the sensors it names).

use super::Simulation;
use super::state::Input;
use crate::SimulationError;
use crate::deck::finite;
use crate::law::PyLaw;
use mecano::model::control::{Actuator, ControlData, ControlLaw, HeldValue, Sensor};
use mecano::model::{ElementId, NodeId};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::Arc;

/// A sensor from its Python form: `("angle" | "rate", hinge)` or
/// `("x" | "y" | "z" | "vx" | "vy" | "vz", node)`.
pub(super) fn sensor_of(obj: &Bound<'_, PyAny>) -> PyResult<Sensor> {
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

pub(super) fn check_axis(a: usize) -> PyResult<usize> {
    if a < 3 {
        Ok(a)
    } else {
        Err(PyValueError::new_err(format!("axis {a} is not 0, 1 or 2")))
    }
}

/// `Simulation.add_input`'s keyword arguments, as Python gave them (its docstring: mecano/).
pub(super) struct InputRequest<'a, 'py> {
    pub(super) hinge: Option<u32>,
    pub(super) node: Option<u32>,
    pub(super) axis: Option<usize>,
    pub(super) value: f64,
    pub(super) law: Option<Py<PyAny>>,
    pub(super) sensors: Option<Vec<Bound<'py, PyAny>>>,
    pub(super) tangent: &'a str,
}

impl Simulation {
    /// `Simulation.add_input`: the input's element number.
    pub(super) fn add_input_to(&self, r: InputRequest<'_, '_>) -> PyResult<u32> {
        let value = r.value;
        let mut inner = self.lock()?;
        if inner.run.is_some() {
            return Err(SimulationError::new_err(
                "inputs are added before the simulation starts (its first step or state query)",
            ));
        }
        finite("value", value)?;
        let actuator = match (r.hinge, r.node, r.axis) {
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
        let sensors: Vec<Sensor> = r
            .sensors
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
        let law_kind = match r.law {
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
                match r.tangent {
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
}
