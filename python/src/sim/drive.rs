//! How a [`super::Simulation`] steps: the explicit laws called between steps, then the
//! run driven with the GIL released and Ctrl-C polled, and what stopped it turned into
//! Python's exception.

use super::state::{ExplicitLaw, Inner, Running};
use super::{Simulation, busy};
use crate::MecanoError;
use crate::overrides;
use crate::poll;
use crate::run::end_time;
use mecano::app::memory::Recording;
use mecano::solver::{Integrator, RunError, StepOutcome, Stepper};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::atomic::Ordering;

impl Simulation {
    /// Calls the explicit laws with `(t, sim)` and holds their values over the next step.
    pub(super) fn explicit_laws(slf: &Bound<'_, Self>) -> PyResult<()> {
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
    pub(super) fn drive<F>(slf: &Bound<'_, Self>, go: F) -> PyResult<StepOutcome>
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
