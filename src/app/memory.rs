//! A run into memory: what `mecano-rs DECK` computes, its histories kept by an
//! [`output::Recorder`] instead of written to files (the Python package's
//! `mecano.run(deck, out=None)`). Nothing is written anywhere.

use super::EXIT_BAD_INPUT;
use crate::interrupt::Interrupts;
use crate::model::Model;
use crate::output::Recorder;
use crate::solver::{self, Integrator, LoopState, Observer, Pause, RunReport, Snapshot, Stats};
use std::io;

/// A finished (or stopped) run in memory: the report, the histories, `summary.json`'s
/// content.
#[derive(Debug, Clone)]
pub struct MemoryRun {
    /// Counters, time reached, failure, interruption.
    pub report: RunReport,
    /// The histories the deck's OUTPUT selects, as the files would hold them.
    pub histories: Recorder,
    /// What `summary.json` would say.
    pub summary: serde_json::Value,
}

/// The recorder with the interruption check of [`Interrupts::stopping_at`] at each pause.
pub struct Recording<'a> {
    /// Where the histories go.
    pub rec: &'a mut Recorder,
    /// Read at each pause between steps: a stop ends the run there.
    pub interrupts: &'a Interrupts,
}

impl Observer for Recording<'_> {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        self.rec.state(snap)
    }

    fn progress(&mut self, t: f64, end: f64, stats: &Stats) {
        self.rec.progress(t, end, stats);
    }

    fn pause(&mut self, integ: &Integrator, _ctl: &LoopState) -> io::Result<Pause> {
        Ok(if self.interrupts.stopping_at(integ.t) {
            Pause::Stop
        } else {
            Pause::Continue
        })
    }
}

/// A recorder for `model`'s run, with the notes a run's `summary.json` carries
/// (`step_resolution`) and its refinement factor.
pub fn recorder(model: &Model, deck_name: &str, refine: u32, integ: &Integrator) -> Recorder {
    let mut rec = Recorder::new(deck_name, model, &integ.sys);
    rec.refine = refine.max(1);
    if let Some(v) = crate::modes::run_summary::block(model, integ.sys.n_node_eq) {
        rec.notes.insert(crate::modes::run_summary::KEY.into(), v);
    }
    rec
}

/// Runs `model` (named `deck_name`, refined by `refine`) into memory. `interrupts` stops
/// it at the end of a step ([`Interrupts::stopping_at`] at each pause) or within one
/// (`abort`). A run that fails or stops keeps its histories, its summary saying
/// `"complete": false`. Errors before the run (the system cannot be built) are bad input.
pub fn run_in_memory(
    model: &Model,
    deck_name: &str,
    refine: u32,
    interrupts: &Interrupts,
) -> Result<MemoryRun, (u8, String)> {
    let mut integ = solver::prepare(model).map_err(|e| (EXIT_BAD_INPUT, e.to_string()))?;
    integ.abort = Some(interrupts.abort.clone());
    let mut rec = recorder(model, deck_name, refine, &integ);
    let result = {
        let mut obs = Recording {
            rec: &mut rec,
            interrupts,
        };
        solver::run_from(model, &mut integ, &mut obs, None)
    };
    let mut report = match result {
        Ok(r) => r,
        // The recorder refused a non-finite value: the run stops there, as a writer's.
        Err(solver::RunError::Output(e)) => RunReport {
            stats: integ.stats,
            time: integ.t,
            failure: Some(solver::Failure::output(&integ, &e)),
            interrupted: None,
        },
        Err(e) => return Err((EXIT_BAD_INPUT, e.to_string())),
    };
    report.stats = integ.stats;
    if report.interrupted.is_some()
        && let Some(signal) = interrupts.signal_name()
    {
        rec.notes.insert("signal".into(), serde_json::json!(signal));
    }
    let summary = rec.finish(&integ, &report);
    Ok(MemoryRun {
        report,
        histories: rec,
        summary,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The in-memory histories hold the very numbers a run writes to its files: the CSVs of
    /// `decks/driven_arm.dat` read back (ryu's shortest round-trip form) equal the
    /// recorded rows bit for bit, and the summaries agree but for the CPU seconds.
    #[test]
    fn memory_run_equals_the_files() {
        let path = std::path::Path::new("decks/driven_arm.dat");
        let mut model = crate::deck::load_deck(path).expect("deck");
        model.set_fixed_step(1e-3, 0.2, None);
        let mem =
            run_in_memory(&model, "decks/driven_arm.dat", 1, &Interrupts::none()).expect("runs");
        assert!(mem.report.failure.is_none());
        let dir = std::env::temp_dir().join(format!("mecano-memory-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        super::super::run_model(&model, "decks/driven_arm.dat", &dir, true).expect("runs");
        let read = |name: &str| -> Vec<f64> {
            let text = std::fs::read_to_string(dir.join(name)).expect("file");
            text.lines()
                .skip(1)
                .flat_map(|l| l.split(',').map(|v| v.parse::<f64>().expect("number")))
                .collect()
        };
        let h = &mem.histories;
        assert_eq!(h.nodes.len(), 1);
        assert_eq!(read("node_2.csv"), h.nodes[0].data);
        assert_eq!(read("element_1.csv"), h.elements[0].data);
        assert_eq!(read("energy.csv"), h.energy.data);
        assert_eq!(h.nodes[0].rows(), 201);
        let file: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        let strip = |mut v: serde_json::Value| {
            v["stats"]["cpu_seconds"] = serde_json::json!(0);
            v
        };
        assert_eq!(strip(file), strip(mem.summary.clone()));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
