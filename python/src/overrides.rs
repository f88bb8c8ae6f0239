//! Values a program sets between steps on the deck's own loads and drivers (issue 36 §5:
//! `Simulation.set_load`, `Simulation.set_drive`), and their record beside a checkpoint.
//!
//! - **A load** (the k-th `FORCE`/`MOMENT` card of `LOADS`, from 1; `GRAVITY` is not
//!   counted): its time function `f(t)` is replaced by a value `s` held from the current
//!   time on, so the load is `s · (fx, fy, fz)` as the card writes the components (a
//!   zero-order hold; `None` gives the card its `f(t)` back). A load that changes is a
//!   force that jumps: in a dynamic run the accelerations restart at the current state
//!   from the equations of motion with the new load (`Integrator::consistent_accelerations`,
//!   as after a contact's touch), so no step straddles the jump and the scheme keeps its
//!   order after it.
//! - **A driver** (a `HINGE`/`PRISMATIC` with `DRIVE`, a `PRESCRIBED`): its law `a f(t)` is
//!   replaced by a value reached over a duration along the C² quintic of
//!   [`mecano::elements::drive::Transition`] (value, rate and acceleration continuous, so
//!   the rheonomic velocity and acceleration terms are those of the quintic, exact, and no
//!   impulse is needed); a change at once that would make the value or its rate jump is
//!   refused.
//!
//! Checkpoints: `checkpoint.bin` is the CLI's format, which has no room for these; `save`
//! writes them to [`SIDECAR`] beside it (with the time and step of the checkpoint), and
//! `load`/`restore` put them back, refusing a record of another time or step. Held input
//! values (`add_input(value=...)`, `set_input`) are recorded there too.

use crate::{MecanoError, SimulationError};
use mecano::elements::drive::Transition;
use mecano::model::{ElementId, Function, Model};
use mecano::solver::Integrator;
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// The file beside `checkpoint.bin` that holds the values set from Python.
pub const SIDECAR: &str = "simulation.json";

/// What identifies the record's format.
const FORMAT: &str = "mecano.Simulation set values 1";

/// The values set on a simulation's loads and drivers.
#[derive(Debug, Default, Clone)]
pub struct Overrides {
    /// Load number → its held scale.
    pub loads: BTreeMap<u32, f64>,
    /// Each overridden load's own law, to give back: `(function, ramp)`.
    deck_laws: BTreeMap<u32, (Option<Function>, bool)>,
    /// Driver element → its transition.
    pub drives: BTreeMap<u32, Transition>,
}

/// After a load or input changed at the current state: the accelerations restart from
/// the equations of motion with it (dynamic runs) and, before the first step, the row of
/// `t = 0` is recorded again.
pub fn restart(integ: &mut Integrator, rec: &mut mecano::output::Recorder) -> PyResult<()> {
    if integ.dynamic {
        integ
            .consistent_accelerations()
            .map_err(|f| MecanoError::new_err(f.to_string()))?;
        if integ.stats.steps > 0 {
            integ.stats.restarts += 1;
        }
    }
    rec.record_start_again(integ);
    Ok(())
}

impl Overrides {
    /// Holds load `load`'s scale at `value` from now on, or gives it its deck law back
    /// (`None`). Returns whether the load changed.
    pub fn set_load(
        &mut self,
        integ: &mut Integrator,
        load: u32,
        value: Option<f64>,
    ) -> PyResult<bool> {
        let n = integ.sys.loads.len();
        let k = (load as usize)
            .checked_sub(1)
            .filter(|k| *k < n)
            .ok_or_else(|| {
                PyKeyError::new_err(format!(
                    "no load {load}: the deck has {n} (the FORCE and MOMENT cards of LOADS, numbered from 1 in deck order; GRAVITY is not one)"
                ))
            })?;
        let l = &mut integ.sys.loads[k];
        let before = (l.function.clone(), l.ramp);
        match value {
            Some(v) => {
                crate::deck::finite("value", v)?;
                self.deck_laws.entry(load).or_insert_with(|| before.clone());
                l.function = Some(Function::Constant(v));
                l.ramp = false;
                self.loads.insert(load, v);
            }
            None => {
                if let Some((f, ramp)) = self.deck_laws.remove(&load) {
                    l.function = f;
                    l.ramp = ramp;
                }
                self.loads.remove(&load);
            }
        }
        Ok((l.function.clone(), l.ramp) != before)
    }

    /// Sets driver `element`'s value: `value` reached `over` seconds from now.
    pub fn set_drive(
        &mut self,
        model: &Model,
        integ: &mut Integrator,
        element: u32,
        value: f64,
        over: f64,
    ) -> PyResult<()> {
        let t = integ.t;
        let law = driver(model, integ, element)?;
        law.set_value(t, value, over)
            .map_err(|e| PyValueError::new_err(format!("element {element}: {e}")))?;
        let set = law.transition().expect("just set");
        self.drives.insert(element, set);
        Ok(())
    }

    /// The record written beside a checkpoint of `time`, `step`; `inputs` the held
    /// inputs' values.
    pub fn record(&self, time: f64, step: u64, inputs: &[(u32, f64)]) -> serde_json::Value {
        let map = |it: &mut dyn Iterator<Item = (String, serde_json::Value)>| {
            serde_json::Value::Object(it.collect())
        };
        serde_json::json!({
            "format": FORMAT,
            "time": time,
            "step": step,
            "loads": map(&mut self.loads.iter().map(|(k, v)| (k.to_string(), (*v).into()))),
            "drives": map(&mut self.drives.iter().map(|(k, v)| {
                (k.to_string(), serde_json::to_value(v).unwrap_or_default())
            })),
            "inputs": map(&mut inputs.iter().map(|(k, v)| (k.to_string(), (*v).into()))),
        })
    }
}

/// Driver `element`'s time law in the system.
fn driver<'a>(
    model: &Model,
    integ: &'a mut Integrator,
    element: u32,
) -> PyResult<&'a mut mecano::elements::drive::TimeLaw> {
    let e = model
        .elements
        .get_full(&ElementId(element))
        .ok_or_else(|| PyKeyError::new_err(format!("element {element} does not exist")))?;
    let (i, kind) = (e.0, e.2.kind.keyword());
    integ.sys.elements[i].drive_law_mut().ok_or_else(|| {
        PyValueError::new_err(format!(
            "element {element} is a {kind} without a driver: set_drive is for a HINGE or PRISMATIC with DRIVE, or a PRESCRIBED"
        ))
    })
}

/// Writes `record` to `dir`/[`SIDECAR`] (through a temporary file and a rename).
pub fn write(dir: &Path, record: &serde_json::Value) -> PyResult<()> {
    let tmp = dir.join(format!("{SIDECAR}.tmp"));
    let text = serde_json::to_string_pretty(record).unwrap_or_default();
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, dir.join(SIDECAR)))
        .map_err(|e| MecanoError::new_err(format!("{}: {e}", dir.join(SIDECAR).display())))
}

/// What a record holds, read back.
pub struct Saved {
    pub loads: Vec<(u32, f64)>,
    pub drives: Vec<(u32, Transition)>,
    pub inputs: Vec<(u32, f64)>,
}

/// Reads `dir`/[`SIDECAR`] (`None` when there is none: a checkpoint of the CLI), checking
/// that it belongs to the checkpoint of `time` and `step`.
pub fn read(dir: &Path, time: f64, step: u64) -> PyResult<Option<Saved>> {
    let path = dir.join(SIDECAR);
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(MecanoError::new_err(format!("{}: {e}", path.display()))),
    };
    let bad = |why: &str| MecanoError::new_err(format!("{}: {why}", path.display()));
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(&e.to_string()))?;
    if v["format"] != FORMAT {
        return Err(bad(&format!("not a record of the format {FORMAT:?}")));
    }
    if v["time"].as_f64() != Some(time) || v["step"].as_u64() != Some(step) {
        return Err(SimulationError::new_err(format!(
            "{} records the values set at t = {} s (step {}), the checkpoint is of t = {time} s (step {step}): they were not saved together (a save that failed half-way?); refusing to restore a run whose loads and drivers may differ",
            path.display(),
            v["time"],
            v["step"]
        )));
    }
    let pairs = |key: &str| -> PyResult<Vec<(u32, serde_json::Value)>> {
        let Some(m) = v[key].as_object() else {
            return Ok(Vec::new());
        };
        m.iter()
            .map(|(k, x)| {
                k.parse::<u32>()
                    .map(|k| (k, x.clone()))
                    .map_err(|_| bad(&format!("{key}: {k:?} is not a number")))
            })
            .collect()
    };
    let num = |(k, x): (u32, serde_json::Value)| -> PyResult<(u32, f64)> {
        x.as_f64()
            .map(|x| (k, x))
            .ok_or_else(|| bad(&format!("{k}: {x} is not a number")))
    };
    Ok(Some(Saved {
        loads: pairs("loads")?
            .into_iter()
            .map(num)
            .collect::<PyResult<_>>()?,
        inputs: pairs("inputs")?
            .into_iter()
            .map(num)
            .collect::<PyResult<_>>()?,
        drives: pairs("drives")?
            .into_iter()
            .map(|(k, x)| {
                serde_json::from_value(x)
                    .map(|t| (k, t))
                    .map_err(|e| bad(&format!("drive {k}: {e}")))
            })
            .collect::<PyResult<_>>()?,
    }))
}

impl Overrides {
    /// Puts back what `saved` holds on a restored integrator (no restart: the state
    /// restored was computed with them).
    pub fn restore(
        &mut self,
        model: &Model,
        integ: &mut Integrator,
        saved: &Saved,
    ) -> PyResult<()> {
        for &(k, v) in &saved.loads {
            self.set_load(integ, k, Some(v))?;
        }
        for &(e, set) in &saved.drives {
            driver(model, integ, e)?.restore_transition(Some(set));
            self.drives.insert(e, set);
        }
        Ok(())
    }
}
