//! Output writers: per-node and per-element CSV histories, the energy balance and
//! `summary.json`.
//!
//! Rows are streamed, and reach the files only whole ([`stream`]), so a run that stops
//! early keeps what it computed, and every file ends with a complete row. `summary.json` is written at the start with `"complete": false` and
//! rewritten at the end; only a run that reached its end time says `"complete": true`.
//!
//! **Invariant:** no NaN or infinity is ever written: a non-finite value makes the writer
//! refuse the row with an error, which stops the run with a diagnosis.
//!
//! # The energy balance (`energy.csv`)
//! `E = T + U + V_g` (kinetic, strain and contact-spring, gravity potential relative to
//! the initial configuration). With `W_ext = ∫ P_ext dt` the work of the applied loads and
//! `D_c = ∫ P_damp dt` the energy dissipated by dampers (contact dashpots, trapezoidal
//! rule over each step), the balance reads `E(t) − E(0) = W_ext − D_c − D_num`, where
//! `D_num`, the remainder, is the energy removed by the integrator's numerical damping.
//! The *balance residual* is `−D_num`: positive values are energy the scheme created,
//! which a stable HHT with `α ≤ 0` should not do beyond round-off and time-discretisation
//! error. `summary.json` reports its largest positive value relative to
//! `max(|E(0)|, W_ext, the largest of T, U over the run)`.

mod stream;
pub mod vtk;

use crate::model::{Model, Selection};
use crate::rotation;
use crate::solver::{Failure, Interruption, Observer, RunReport, Snapshot, Stats, System};
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use stream::Stream;

/// Header of every node history file.
pub const NODE_HEADER: &str = "t,x,y,z,ux,uy,uz,rx,ry,rz,vx,vy,vz,wx,wy,wz,ax,ay,az";

/// Header of `energy.csv`.
pub const ENERGY_HEADER: &str = "t,kinetic,strain,gravity,total,external_work,damping_dissipation,numerical_dissipation,balance_residual";

/// A progress callback: time reached, end time, counters.
pub type ProgressFn = Box<dyn FnMut(f64, f64, &Stats)>;

/// Which accepted states `OUTPUT … EVERY n` writes: with fixed steps, the states at the
/// instants `k n h` (steps land back on that grid after contact events, which add steps of
/// their own, so a history keeps regular instants); with adaptive steps, every n-th state.
#[derive(Debug, Clone, Copy)]
pub struct Sampling {
    every: u64,
    /// `n h` for fixed steps.
    period: Option<f64>,
}

impl Sampling {
    /// The sampling a model asks for.
    pub fn of(model: &crate::model::Model) -> Self {
        let every = u64::from(model.output.every.max(1));
        let period = match &model.analysis {
            crate::model::Analysis::Dynamic { step, adaptive, .. } if adaptive.is_none() => {
                Some(*step * every as f64)
            }
            _ => None,
        };
        Sampling { every, period }
    }

    /// Whether the state of a snapshot is written.
    pub fn takes(&self, snap: &Snapshot) -> bool {
        match self.period {
            Some(p) => {
                let t = snap.integ.t;
                snap.step == 0 || (t / p - (t / p).round()).abs() <= 1e-6
            }
            None => snap.step.is_multiple_of(self.every),
        }
    }
}

/// Streams a run's histories to a directory.
pub struct Writer {
    dir: PathBuf,
    deck: String,
    title: String,
    effects: Vec<&'static str>,
    end: f64,
    sampling: Sampling,
    nodes: Vec<(usize, Stream)>,
    elements: Vec<(usize, Stream)>,
    energy: Stream,
    e0: Option<f64>,
    energy_scale: f64,
    max_balance: f64,
    last_row: Option<u64>,
    /// An element's row, reused (no allocation per row).
    row: Vec<f64>,
    /// Optional progress callback (e.g. a progress bar): time, end time, counters.
    pub progress: Option<ProgressFn>,
    /// Entries added to `summary.json` by the application (e.g. the record of a run's
    /// interruptions and restarts).
    pub notes: serde_json::Map<String, serde_json::Value>,
}

/// What a [`Writer`] needs to go on after a restart: the length of each file at the
/// checkpoint (what follows was written later, and is cut) and the energy balance's
/// accumulators.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WriterState {
    /// (file name, length in bytes) of each history file, in the writer's order.
    pub files: Vec<(String, u64)>,
    e0: Option<f64>,
    energy_scale: f64,
    max_balance: f64,
    last_row: Option<u64>,
}

/// The files a model's OUTPUT asks for: (dense node, file, header), (dense element,
/// file, header).
type Plan = (Vec<(usize, PathBuf)>, Vec<(usize, PathBuf, String)>);

fn plan(dir: &Path, model: &Model, sys: &System) -> Plan {
    let node_idx: Vec<usize> = match &model.output.nodes {
        Selection::All => (0..model.nodes.len()).collect(),
        Selection::None => Vec::new(),
        Selection::List(l) => l
            .iter()
            .filter_map(|id| model.nodes.get_index_of(id))
            .collect(),
    };
    let nodes = node_idx
        .into_iter()
        .map(|i| (i, dir.join(format!("node_{}.csv", sys.node_ids[i].0))))
        .collect();
    let elem_idx: Vec<usize> = match &model.output.elements {
        Selection::All => (0..model.elements.len()).collect(),
        Selection::None => Vec::new(),
        Selection::List(l) => l
            .iter()
            .filter_map(|id| model.elements.get_index_of(id))
            .collect(),
    };
    let mut elements = Vec::new();
    for e in elem_idx {
        let el = &sys.elements[e];
        let header = el.output_header();
        if header.is_empty() {
            continue;
        }
        elements.push((
            e,
            dir.join(format!("element_{}.csv", el.id().0)),
            format!("t,{}", header.join(",")),
        ));
    }
    (nodes, elements)
}

impl Writer {
    /// Creates the output directory, the files the model's OUTPUT requests, and a
    /// `summary.json` that says `"complete": false` until [`Writer::finish`] says otherwise.
    pub fn create(dir: &Path, deck: &str, model: &Model, sys: &System) -> io::Result<Self> {
        fs::create_dir_all(dir)?;
        let (node_files, elem_files) = plan(dir, model, sys);
        let mut nodes = Vec::new();
        for (i, path) in node_files {
            nodes.push((i, Stream::create(&path, NODE_HEADER)?));
        }
        let mut elements = Vec::new();
        for (e, path, head) in elem_files {
            elements.push((e, Stream::create(&path, &head)?));
        }
        let energy = Stream::create(&dir.join("energy.csv"), ENERGY_HEADER)?;
        let w = Self::with_streams(dir, deck, model, nodes, elements, energy);
        w.write_summary(None, None)?;
        Ok(w)
    }

    /// Reopens the files of a stopped run in `dir` to go on from a checkpoint: each is cut
    /// back to the length `state` recorded, and the energy balance goes on from its
    /// accumulators. The files must be those the model's OUTPUT asks for.
    pub fn resume(
        dir: &Path,
        deck: &str,
        model: &Model,
        sys: &System,
        state: &WriterState,
    ) -> io::Result<Self> {
        let (node_files, elem_files) = plan(dir, model, sys);
        let mut names: Vec<(PathBuf, String)> = node_files
            .iter()
            .map(|(_, p)| (p.clone(), NODE_HEADER.to_string()))
            .collect();
        names.extend(elem_files.iter().map(|(_, p, h)| (p.clone(), h.clone())));
        names.push((dir.join("energy.csv"), ENERGY_HEADER.to_string()));
        let expected: Vec<String> = names.iter().map(|(p, _)| stream::file_name(p)).collect();
        let saved: Vec<String> = state.files.iter().map(|(n, _)| n.clone()).collect();
        if expected != saved {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "the checkpoint's files [{}] are not the deck's outputs [{}]",
                    saved.join(", "),
                    expected.join(", ")
                ),
            ));
        }
        let mut streams = Vec::with_capacity(names.len());
        for ((path, header), (_, len)) in names.iter().zip(&state.files) {
            streams.push(Stream::reopen(path, header, *len)?);
        }
        let energy = streams.pop().expect("energy.csv is always written");
        let elements: Vec<(usize, Stream)> = elem_files
            .iter()
            .map(|(e, _, _)| *e)
            .zip(streams.drain(node_files.len()..))
            .collect();
        let nodes: Vec<(usize, Stream)> = node_files.iter().map(|(i, _)| *i).zip(streams).collect();
        let mut w = Self::with_streams(dir, deck, model, nodes, elements, energy);
        w.e0 = state.e0;
        w.energy_scale = state.energy_scale;
        w.max_balance = state.max_balance;
        w.last_row = state.last_row;
        Ok(w)
    }

    fn with_streams(
        dir: &Path,
        deck: &str,
        model: &Model,
        nodes: Vec<(usize, Stream)>,
        elements: Vec<(usize, Stream)>,
        energy: Stream,
    ) -> Self {
        let end = match model.analysis {
            crate::model::Analysis::Dynamic { end, .. } => end,
            crate::model::Analysis::Static { .. } => 1.0,
        };
        Writer {
            dir: dir.to_path_buf(),
            deck: deck.to_string(),
            title: model.title.clone(),
            effects: model.effects().names(),
            end,
            sampling: Sampling::of(model),
            nodes,
            elements,
            energy,
            e0: None,
            energy_scale: 0.0,
            max_balance: 0.0,
            last_row: None,
            row: Vec::new(),
            progress: None,
            notes: serde_json::Map::new(),
        }
    }

    /// Writes every buffered row, waits until the files are on the disk, and returns the
    /// state a restart from this point needs ([`WriterState`]). What the files hold is not
    /// changed: only when it reaches the disk.
    pub fn save_state(&mut self) -> io::Result<WriterState> {
        let mut files = Vec::with_capacity(self.nodes.len() + self.elements.len() + 1);
        for (_, s) in self.nodes.iter_mut().chain(self.elements.iter_mut()) {
            s.sync()?;
            files.push((s.name.clone(), s.len()));
        }
        self.energy.sync()?;
        files.push((self.energy.name.clone(), self.energy.len()));
        Ok(WriterState {
            files,
            e0: self.e0,
            energy_scale: self.energy_scale,
            max_balance: self.max_balance,
            last_row: self.last_row,
        })
    }

    /// Rewrites `summary.json` (e.g. after [`Writer::notes`] changed), still incomplete.
    pub fn write_notes(&self) -> io::Result<()> {
        self.write_summary(None, None)
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn write_state(&mut self, snap: &Snapshot) -> io::Result<()> {
        let integ = snap.integ;
        let t = integ.t;
        for (i, st) in &mut self.nodes {
            let s = &integ.nodes[*i];
            let x0 = integ.sys.x0[*i];
            let u = s.x - x0;
            let phi = rotation::log(&s.r);
            let w = s.r * s.w;
            let row = [
                t, s.x.x, s.x.y, s.x.z, u.x, u.y, u.z, phi.x, phi.y, phi.z, s.v.x, s.v.y, s.v.z,
                w.x, w.y, w.z, s.a.x, s.a.y, s.a.z,
            ];
            st.row(&row)?;
        }
        let ctx = integ.current_context();
        for (e, st) in &mut self.elements {
            let el = &integ.sys.elements[*e];
            let lam = integ.sys.element_lambda(*e, &integ.lambda);
            let row = &mut self.row;
            row.clear();
            row.push(t);
            el.write_output_row(&ctx, &integ.nodes, lam, row);
            st.row(row)?;
        }
        let e = integ.energies();
        let total = e.kinetic + e.strain + e.gravity;
        let e0 = *self.e0.get_or_insert(total);
        let numerical = integ.external_work - integ.damping_work - (total - e0);
        let residual = -numerical;
        self.energy_scale = self
            .energy_scale
            .max(e0.abs())
            .max(integ.external_work.abs())
            .max(e.kinetic)
            .max(e.strain.abs());
        if integ.dynamic && self.energy_scale > 0.0 {
            self.max_balance = self.max_balance.max(residual / self.energy_scale);
        }
        self.energy.row(&[
            t,
            e.kinetic,
            e.strain,
            e.gravity,
            total,
            integ.external_work,
            integ.damping_work,
            numerical,
            residual,
        ])?;
        self.last_row = Some(snap.step);
        Ok(())
    }

    /// Writes every buffered row to its file (rows are only ever written whole).
    pub fn flush(&mut self) -> io::Result<()> {
        for (_, s) in self.nodes.iter_mut().chain(self.elements.iter_mut()) {
            s.flush()?;
        }
        self.energy.flush()
    }

    fn write_summary(
        &self,
        report: Option<&RunReport>,
        extra: Option<serde_json::Value>,
    ) -> io::Result<()> {
        let complete = report.is_some_and(|r| r.failure.is_none() && r.interrupted.is_none());
        let mut v = serde_json::json!({
            "deck": self.deck,
            "title": self.title,
            "effects": self.effects,
            "end_time": self.end,
            "complete": complete,
        });
        if let Some(r) = report {
            let st = &r.stats;
            v["time_reached"] = serde_json::json!(r.time);
            v["stop"] = if let Some(how) = r.interrupted {
                serde_json::json!({
                    "reason": "interrupted",
                    "time": r.time,
                    "step": st.steps,
                    "at_step_end": how == Interruption::AtStep,
                })
            } else if let Some(f) = &r.failure {
                serde_json::json!({ "reason": "failed", "time": f.time, "step": st.steps })
            } else {
                serde_json::Value::Null
            };
            v["stats"] = serde_json::to_value(st).unwrap_or_default();
            v["newton_iterations_per_step"] = serde_json::json!(if st.steps > 0 {
                st.newton_iterations as f64 / st.steps as f64
            } else {
                0.0
            });
            v["energy"] = serde_json::json!({ "max_balance_error": self.max_balance });
            v["failure"] = match &r.failure {
                Some(f) => failure_json(f),
                None => serde_json::Value::Null,
            };
        }
        if let Some(x) = extra {
            v["elements"] = x;
        }
        for (k, x) in &self.notes {
            v[k] = x.clone();
        }
        let text = serde_json::to_string_pretty(&v).unwrap_or_else(|_| "{}".into());
        let tmp = self.dir.join("summary.json.tmp");
        fs::write(&tmp, text)?;
        fs::rename(tmp, self.dir.join("summary.json"))
    }

    /// Writes the final state if it was skipped by `EVERY` (not for an interrupted run:
    /// its files end where a restart goes on), flushes, and rewrites `summary.json` with
    /// the counters and the `complete` flag.
    pub fn finish(
        &mut self,
        integ: &crate::solver::Integrator,
        report: &RunReport,
    ) -> io::Result<()> {
        if self.last_row != Some(integ.stats.steps) && report.interrupted.is_none() {
            self.write_state(&Snapshot {
                integ,
                step: integ.stats.steps,
                h: 0.0,
            })?;
        }
        self.flush()?;
        let mut per_elem = serde_json::Map::new();
        for el in &integ.sys.elements {
            if let Some(s) = el.summary() {
                per_elem.insert(el.id().0.to_string(), s);
            }
        }
        let extra = (!per_elem.is_empty()).then_some(serde_json::Value::Object(per_elem));
        self.write_summary(Some(report), extra)
    }

    /// Largest relative energy-balance error so far.
    pub fn max_balance_error(&self) -> f64 {
        self.max_balance
    }
}

fn failure_json(f: &Failure) -> serde_json::Value {
    serde_json::json!({
        "message": f.to_string(),
        "time": f.time,
        "step": f.step,
        "residual_history": f.residual_history.iter().map(|r| if r.is_finite() { *r } else { f64::MAX }).collect::<Vec<_>>(),
        "worst": f.worst,
        "worst_value": if f.worst_value.is_finite() { f.worst_value } else { f64::MAX },
    })
}

impl Observer for Writer {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        if self.sampling.takes(snap) {
            self.write_state(snap)?;
        }
        Ok(())
    }

    fn progress(&mut self, t: f64, end: f64, stats: &Stats) {
        if let Some(p) = &mut self.progress {
            p(t, end, stats);
        }
    }
}

/// An in-memory observer: keeps the time, node states and energies of every
/// `every`-th accepted state (for tests and programs that use the library directly).
#[derive(Debug, Clone, Default)]
pub struct History {
    /// Record every this many steps (0 or 1 = every step).
    pub every: u64,
    /// Times, s.
    pub t: Vec<f64>,
    /// Node states at each recorded time (dense node order).
    pub nodes: Vec<Vec<crate::elements::NodeState>>,
    /// Kinetic + strain + gravity energy at each recorded time, J.
    pub energy: Vec<f64>,
    /// Work of the applied loads since t = 0, J.
    pub external_work: Vec<f64>,
    /// Energy dissipated by element dampers since t = 0, J.
    pub damping_work: Vec<f64>,
    /// Largest constraint violation at each recorded time.
    pub violation: Vec<f64>,
}

impl History {
    /// Records every `every`-th step.
    pub fn new(every: u64) -> Self {
        History {
            every,
            ..Default::default()
        }
    }

    /// Position history of dense node `i`.
    pub fn positions(&self, i: usize) -> Vec<nalgebra::Vector3<f64>> {
        self.nodes.iter().map(|n| n[i].x).collect()
    }
}

impl Observer for History {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        if snap.step.is_multiple_of(self.every.max(1)) {
            let integ = snap.integ;
            let e = integ.energies();
            self.t.push(integ.t);
            self.nodes.push(integ.nodes.clone());
            self.energy.push(e.kinetic + e.strain + e.gravity);
            self.external_work.push(integ.external_work);
            self.damping_work.push(integ.damping_work);
            self.violation.push(integ.constraint_violation());
        }
        Ok(())
    }
}
