//! A [`super::Simulation`]'s checkpoints: the state written in mecano-rs's checkpoint
//! format with the values set from Python beside it, and a simulation restored from them.

use super::Simulation;
use super::state::{Inner, Input};
use crate::deck::Deck;
use crate::overrides;
use crate::{MecanoError, SimulationError};
use mecano::checkpoint::{self, Checkpoint};
use mecano::solver;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

impl Simulation {
    /// `Simulation.save`.
    pub(super) fn save_to(slf: &Bound<'_, Self>, dir: PathBuf) -> PyResult<()> {
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

    /// `Simulation.load`.
    pub(super) fn load_from<'py>(
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

    pub(super) fn restore_from(&self, c: Checkpoint, dir: &std::path::Path) -> PyResult<()> {
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
        let mut run = inner.running_from(integ, Some(c.control))?;
        if let Some(saved) = saved {
            let inner: &mut Inner = &mut inner;
            inner
                .overrides
                .restore(&inner.model, &mut run.integ, &saved)?;
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
        inner.run = Some(run);
        Ok(())
    }
}
