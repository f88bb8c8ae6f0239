//! A Python callable as an input's law inside the step ([`mecano::model::control::Law`]):
//! called as `law(t, s)` at every Newton iterate with `s` a [`Sensors`] view of the
//! declared sensors' values there; its derivatives by forward differences of further
//! calls (one per sensor, only when the iteration matrix is rebuilt). An exception, a
//! non-number or a non-finite value stops the run: the error is kept for Python and the
//! integrator's abort flag set, so that the step is given up at its next iteration.
//! A KeyboardInterrupt (Ctrl-C while the law's Python code runs) is not the law's
//! failure: it is kept in [`PyLaw::interrupt`], the law called again for the value the
//! step needs, and the Simulation stops at the end of that step (issue 36 §7); a second
//! Ctrl-C during that call gives the step up as a failure would.

use crate::poll::Pending;
use mecano::model::control::{Law, Sensor};
use pyo3::exceptions::{PyKeyboardInterrupt, PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The sensors a law declared, as the view and the error messages name them.
pub fn sensor_name(s: &Sensor) -> String {
    match *s {
        Sensor::HingeAngle(h) => format!("('angle', {})", h.0),
        Sensor::HingeRate(h) => format!("('rate', {})", h.0),
        Sensor::Coordinate(n, a) => format!("('{}', {})", ["x", "y", "z"][a], n.0),
        Sensor::Velocity(n, a) => format!("('{}', {})", ["vx", "vy", "vz"][a], n.0),
    }
}

/// The values of a law's sensors at an iterate, read as a Simulation is:
/// `s.joint_angle(3)`, `s.joint_rate(3)`, `s.coordinate(12, 1)`, `s.velocity(12, 1)`, or
/// `s[i]` in the order the sensors were declared. Reading a sensor that was not declared
/// is an error (its derivative would be missing from the iteration matrix).
#[pyclass(module = "mecano", frozen)]
pub struct Sensors {
    t: f64,
    sensors: Arc<Vec<Sensor>>,
    values: Vec<f64>,
}

impl Sensors {
    fn find(&self, want: Sensor) -> PyResult<f64> {
        match self.sensors.iter().position(|s| *s == want) {
            Some(i) => Ok(self.values[i]),
            None => {
                let have: Vec<String> = self.sensors.iter().map(sensor_name).collect();
                Err(PyValueError::new_err(format!(
                    "the law read {}, which is not among its sensors [{}]: declare it in sensors=",
                    sensor_name(&want),
                    have.join(", ")
                )))
            }
        }
    }
}

fn check_axis(a: usize) -> PyResult<usize> {
    if a < 3 {
        Ok(a)
    } else {
        Err(PyValueError::new_err(format!("axis {a} is not 0, 1 or 2")))
    }
}

#[pymethods]
impl Sensors {
    /// Time of the iterate, s.
    #[getter]
    fn t(&self) -> f64 {
        self.t
    }

    /// HINGE `joint`'s relative angle, rad (whole turns counted).
    fn joint_angle(&self, joint: u32) -> PyResult<f64> {
        self.find(Sensor::HingeAngle(mecano::model::ElementId(joint)))
    }

    /// HINGE `joint`'s relative rate, rad/s.
    fn joint_rate(&self, joint: u32) -> PyResult<f64> {
        self.find(Sensor::HingeRate(mecano::model::ElementId(joint)))
    }

    /// Node `node`'s global coordinate along `axis` (0, 1, 2), m.
    fn coordinate(&self, node: u32, axis: usize) -> PyResult<f64> {
        self.find(Sensor::Coordinate(
            mecano::model::NodeId(node),
            check_axis(axis)?,
        ))
    }

    /// Node `node`'s global velocity component along `axis` (0, 1, 2), m/s.
    fn velocity(&self, node: u32, axis: usize) -> PyResult<f64> {
        self.find(Sensor::Velocity(
            mecano::model::NodeId(node),
            check_axis(axis)?,
        ))
    }

    fn __len__(&self) -> usize {
        self.values.len()
    }

    fn __getitem__(&self, i: isize) -> PyResult<f64> {
        let n = self.values.len() as isize;
        let k = if i < 0 { i + n } else { i };
        if (0..n).contains(&k) {
            Ok(self.values[k as usize])
        } else {
            Err(pyo3::exceptions::PyIndexError::new_err(format!(
                "sensor index {i} out of range ({n} sensors)"
            )))
        }
    }

    fn __repr__(&self) -> String {
        let parts: Vec<String> = self
            .sensors
            .iter()
            .zip(&self.values)
            .map(|(s, v)| format!("{}: {v}", sensor_name(s)))
            .collect();
        format!("Sensors(t={}, {{{}}})", self.t, parts.join(", "))
    }
}

/// A Python law (see the module docs).
pub struct PyLaw {
    /// The callable.
    pub f: Py<PyAny>,
    /// Its sensors, in order.
    pub sensors: Arc<Vec<Sensor>>,
    /// The input's element number (for messages).
    pub input: u32,
    /// Where its error goes.
    pub pending: Pending,
    /// Set when it fails: the step under way is given up.
    pub abort: Arc<AtomicBool>,
    /// Where a KeyboardInterrupt raised in the law goes (the run stops at the end of
    /// the step: [`crate::poll::interrupts`] reads it between steps).
    pub interrupt: Pending,
}

impl PyLaw {
    fn call(&self, py: Python<'_>, t: f64, s: &[f64]) -> PyResult<f64> {
        let view = Sensors {
            t,
            sensors: self.sensors.clone(),
            values: s.to_vec(),
        };
        let r = self.f.call1(py, (t, view))?;
        let v: f64 = r.extract(py).map_err(|_| {
            PyTypeError::new_err(format!(
                "the law of input {} returned {}, not a number",
                self.input,
                r.bind(py)
                    .repr()
                    .map(|x| x.to_string())
                    .unwrap_or_else(|_| "?".into())
            ))
        })?;
        if !v.is_finite() {
            return Err(PyValueError::new_err(format!(
                "the law of input {} returned {v} at t = {t} s (sensors {s:?})",
                self.input
            )));
        }
        Ok(v)
    }

    /// [`PyLaw::call`], a KeyboardInterrupt kept aside and the call made once more.
    fn call_through_ctrl_c(&self, py: Python<'_>, t: f64, s: &[f64]) -> PyResult<f64> {
        match self.call(py, t, s) {
            Err(e) if e.is_instance_of::<PyKeyboardInterrupt>(py) => {
                let mut slot = self.interrupt.lock().unwrap_or_else(|e| e.into_inner());
                if slot.is_none() {
                    *slot = Some(e);
                    drop(slot);
                    return self.call(py, t, s);
                }
                Err(e)
            }
            r => r,
        }
    }

    fn fail(&self, e: PyErr) -> f64 {
        let mut slot = self.pending.lock().unwrap_or_else(|e| e.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
        self.abort.store(true, Ordering::SeqCst);
        f64::NAN
    }
}

impl Law for PyLaw {
    fn eval(&self, t: f64, s: &[f64], grad: Option<&mut [f64]>) -> f64 {
        if self.abort.load(Ordering::Relaxed) {
            return f64::NAN;
        }
        Python::attach(|py| {
            let u = match self.call_through_ctrl_c(py, t, s) {
                Ok(u) => u,
                Err(e) => return self.fail(e),
            };
            if let Some(g) = grad {
                // Forward differences: δ = 1e-7 max(1, |sᵢ|) balances truncation and
                // round-off (~1e-7 relative). Only Newton's rate depends on them.
                let mut p = s.to_vec();
                for i in 0..s.len() {
                    let d = 1e-7 * s[i].abs().max(1.0);
                    p[i] = s[i] + d;
                    match self.call_through_ctrl_c(py, t, &p) {
                        Ok(v) => g[i] = (v - u) / d,
                        Err(e) => return self.fail(e),
                    }
                    p[i] = s[i];
                }
            }
            u
        })
    }
}
