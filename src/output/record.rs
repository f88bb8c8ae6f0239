//! `Recorder`: a run's histories in memory, the very rows the [`super::Writer`] writes to
//! its files (same selection, same sampling, same numbers), for library users that want
//! no files (the Python package's `mecano.run(deck, out=None)`).

use super::plan::plan;
use super::{Balance, ENERGY_HEADER, NODE_HEADER, Sampling, SummaryHead, node_row};
use crate::model::Model;
use crate::solver::{Integrator, Observer, RunReport, Snapshot, System};
use std::io;
use std::path::Path;

/// One history: the columns of a file and its rows, row-major.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Recorded {
    /// The user's number of the node or element (0 for the energy balance).
    pub id: u32,
    /// Dense index of the node or element in the system.
    pub index: usize,
    /// Column names, `t` first (the file's header).
    pub columns: Vec<String>,
    /// The rows, one after the other (`rows() × columns.len()` values).
    pub data: Vec<f64>,
}

impl Recorded {
    fn new(id: u32, index: usize, header: &str) -> Self {
        Recorded {
            id,
            index,
            columns: header.split(',').map(str::to_string).collect(),
            data: Vec::new(),
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.data.len() / self.columns.len().max(1)
    }

    /// Column `name`, copied out; `None` if there is no such column.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        let n = self.columns.len();
        Some(self.data.iter().skip(k).step_by(n).copied().collect())
    }
}

/// An observer that keeps in memory what a [`super::Writer`] would write: the node and
/// element histories the model's `OUTPUT` selects (the same rows, `EVERY n` included),
/// the energy balance, and the content of `summary.json` at the end ([`Recorder::summary`]).
#[derive(Debug, Clone)]
pub struct Recorder {
    sampling: Sampling,
    /// Node histories (`node_<N>.csv`), in the Writer's order.
    pub nodes: Vec<Recorded>,
    /// Element histories (`element_<N>.csv`), in the Writer's order.
    pub elements: Vec<Recorded>,
    /// The energy balance (`energy.csv`).
    pub energy: Recorded,
    balance: Balance,
    last_row: Option<u64>,
    row: Vec<f64>,
    deck: String,
    title: String,
    effects: Vec<&'static str>,
    end: f64,
    generated: crate::model::Generated,
    /// The refinement factor the model was refined by (recorded in the summary).
    pub refine: u32,
    /// Entries added to the summary (as [`super::Writer::notes`]).
    pub notes: serde_json::Map<String, serde_json::Value>,
}

impl Recorder {
    /// A recorder of `model`'s outputs (`deck` names it in the summary).
    pub fn new(deck: &str, model: &Model, sys: &System) -> Self {
        let (nodes, elements) = plan(Path::new(""), model, sys);
        let end = match model.analysis {
            crate::model::Analysis::Dynamic { end, .. } => end,
            crate::model::Analysis::Static { .. } => 1.0,
        };
        Recorder {
            sampling: Sampling::of(model),
            nodes: nodes
                .iter()
                .map(|(i, _)| Recorded::new(sys.node_ids[*i].0, *i, NODE_HEADER))
                .collect(),
            elements: elements
                .iter()
                .map(|(e, _, h)| Recorded::new(sys.elements[*e].id().0, *e, h))
                .collect(),
            energy: Recorded::new(0, 0, ENERGY_HEADER),
            balance: Balance::default(),
            last_row: None,
            row: Vec::new(),
            deck: deck.to_string(),
            title: model.title.clone(),
            effects: model.effects().names(),
            end,
            generated: model.summary().generated,
            refine: 1,
            notes: serde_json::Map::new(),
        }
    }

    /// Records every accepted state (as [`super::Writer::every_accepted_step`]).
    pub fn every_accepted_step(&mut self) {
        self.sampling = Sampling::every_step();
    }

    fn record(&mut self, integ: &Integrator) {
        for n in &mut self.nodes {
            n.data.extend_from_slice(&node_row(integ, n.index));
        }
        let ctx = integ.current_context();
        // The reactions the files hold: minimum-norm where equations were removed.
        let reported = integ.reported_multipliers();
        for e in &mut self.elements {
            let el = &integ.sys.elements[e.index];
            let lam = integ.sys.element_lambda(e.index, &reported);
            self.row.clear();
            self.row.push(integ.t);
            el.write_output_row(&ctx, &integ.nodes, lam, &mut self.row);
            e.data.extend_from_slice(&self.row);
        }
        let row = self.balance.row(integ);
        self.energy.data.extend_from_slice(&row);
    }

    /// Records the initial state again in place of the row written at `t = 0`, when no
    /// step was taken since: a program that set an input's value (or a load's) before the
    /// first step recomputed the initial accelerations with it, and the first row shows
    /// the state the run starts from. Returns whether it did.
    pub fn record_start_again(&mut self, integ: &Integrator) -> bool {
        if integ.stats.steps != 0 || self.last_row != Some(0) {
            return false;
        }
        for r in self
            .nodes
            .iter_mut()
            .chain(&mut self.elements)
            .chain(std::iter::once(&mut self.energy))
        {
            r.data.clear();
        }
        self.balance = Balance::default();
        self.record(integ);
        true
    }

    /// Closes the histories as [`super::Writer::finish`] closes the files (the final state
    /// recorded if `EVERY` skipped it and the run was not interrupted) and returns the
    /// content of `summary.json`.
    pub fn finish(&mut self, integ: &Integrator, report: &RunReport) -> serde_json::Value {
        if self.last_row.is_some()
            && self.last_row != Some(integ.stats.steps)
            && report.interrupted.is_none()
        {
            self.record(integ);
            self.last_row = Some(integ.stats.steps);
        }
        self.summary(integ, Some(report))
    }

    /// The summary (`summary.json`'s content) at this point: `report = None` says the run
    /// is under way (`"complete": false`).
    pub fn summary(&self, integ: &Integrator, report: Option<&RunReport>) -> serde_json::Value {
        super::summary_value(
            &SummaryHead {
                deck: &self.deck,
                title: &self.title,
                effects: &self.effects,
                end: self.end,
                refine: self.refine,
                generated: &self.generated,
            },
            report,
            self.balance.max_error(),
            integ.balance.summary(),
            report.and_then(|_| super::element_facts(integ)),
            &self.notes,
        )
    }

    /// Whether any value recorded is not finite (the [`super::Writer`] refuses those).
    fn finite(&self) -> io::Result<()> {
        let bad = self
            .nodes
            .iter()
            .chain(&self.elements)
            .chain(std::iter::once(&self.energy))
            .find(|r| {
                let n = r.columns.len();
                r.data.len() >= n && r.data[r.data.len() - n..].iter().any(|v| !v.is_finite())
            });
        match bad {
            None => Ok(()),
            Some(r) => Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "refusing to record a non-finite value (a history of {} columns, {} {})",
                    r.columns.len(),
                    if r.columns.len() == 9 {
                        "energy"
                    } else {
                        "number"
                    },
                    r.id
                ),
            )),
        }
    }
}

impl Observer for Recorder {
    /// The rows recorded (node accelerations, element reactions): the sampled states.
    fn reads_reactions(&self, snap: &Snapshot) -> bool {
        self.sampling.takes(snap)
    }

    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        if self.sampling.takes(snap) {
            self.record(snap.integ);
            self.last_row = Some(snap.step);
            // As the Writer: a non-finite row stops the run; it is taken back, so that
            // the histories hold finite values only.
            if let Err(e) = self.finite() {
                for r in self
                    .nodes
                    .iter_mut()
                    .chain(self.elements.iter_mut())
                    .chain(std::iter::once(&mut self.energy))
                {
                    let n = r.columns.len();
                    r.data.truncate(r.data.len().saturating_sub(n));
                }
                return Err(e);
            }
        }
        Ok(())
    }
}
