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
//! of the drivers (`P = τ·a ḟ` of each prescribed motion, [`crate::elements::Element::input_power`]) and
//! `D_c = ∫ P_damp dt` the energy dissipated by dampers (contact dashpots, trapezoidal
//! rule over each step), the balance reads `E(t) − E(0) = W_ext − D_c − D_num`, where
//! `D_num`, the remainder, is the energy removed by the integrator's numerical damping.
//! The *balance residual* is `−D_num`: positive values are energy the scheme created,
//! which a stable HHT with `α ≤ 0` should not do beyond round-off and time-discretisation
//! error. `summary.json` reports its largest positive value relative to
//! `max(|E(0)|, W_ext, the largest of T, U over the run)`.

pub mod columnar;
mod history;
pub mod netcdf;
mod plan;
pub mod read;
mod record;
mod stream;
pub mod vtk;

use crate::model::Model;
use crate::rotation;
use crate::solver::{Failure, Interruption, Observer, RunReport, Snapshot, Stats, System};
pub use history::History;
use netcdf::Columnar;
pub use plan::{CSV_NUMBER_BYTES, Volume, volume};
use plan::{groups, plan};
pub use record::{Recorded, Recorder};
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
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sampling {
    every: u64,
    /// `n h` for fixed steps.
    period: Option<f64>,
    /// `OUTPUT … SUBSTEPS`: also the states of steps shorter than `step` (fixed steps), or
    /// every accepted state (adaptive).
    #[serde(default)]
    substeps: bool,
    /// The deck's STEP, s (fixed steps; 0 otherwise).
    #[serde(default)]
    step: f64,
    /// The end time, s: an instant less than r before it, or after it, is the end's row.
    #[serde(default = "no_end")]
    end: f64,
}

/// A checkpoint's sampling that predates `end`: no limit.
fn no_end() -> f64 {
    f64::INFINITY
}

impl Sampling {
    /// The sampling a model asks for.
    pub fn of(model: &crate::model::Model) -> Self {
        let every = u64::from(model.output.every.max(1));
        let (period, step, end) = match &model.analysis {
            crate::model::Analysis::Dynamic {
                step,
                adaptive,
                end,
                ..
            } if adaptive.is_none() => (Some(*step * every as f64), *step, *end),
            _ => (None, 0.0, f64::INFINITY),
        };
        Sampling {
            every,
            period,
            substeps: model.output.substeps,
            step,
            end,
        }
    }

    /// Every accepted state.
    pub fn every_step() -> Self {
        Sampling {
            every: 1,
            period: None,
            substeps: false,
            step: 0.0,
            end: f64::INFINITY,
        }
    }

    /// Whether the state at `t`, reached by a step `h`, is the first to reach an instant
    /// `k p` (k ≥ 1) of the output grid: the step `(t − h, t]` crosses `k p − r`, r the
    /// stepper's reach [`crate::solver::GRID_REACH`]·STEP. The stepper lands on every
    /// instant or, when an event landed it less than r before one, steps over it (no
    /// sliver step is taken): that state is then the instant's row. The steps' intervals
    /// are disjoint, so each instant has exactly one row (issue 34 §7: a touch landed
    /// 1e-4 STEP before an instant, with MINSTEP 3e-4 STEP, lost that instant's row when a
    /// row had to be within 1e-6 of it).
    fn first_at_instant(&self, t: f64, h: f64, p: f64) -> bool {
        // STEP = p / every (a checkpoint of an older version has no `step`).
        let r = crate::solver::GRID_REACH * p / self.every as f64;
        let k = ((t + r) / p).floor();
        // An instant less than r before the end (or after it) has the end's state, which
        // is always written.
        let at_end = t >= self.end - 1e-9 * p / self.every as f64;
        k >= 1.0 && t - h < k * p - r && (k * p <= self.end - r || at_end)
    }

    /// Whether the state of a snapshot is written.
    pub fn takes(&self, snap: &Snapshot) -> bool {
        match self.period {
            Some(p) => {
                snap.step == 0
                    || self.first_at_instant(snap.integ.t, snap.h, p)
                    || (self.substeps && snap.h < self.step * (1.0 - 1e-9))
            }
            None => self.substeps || snap.step.is_multiple_of(self.every),
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
    /// `histories.nc` (`OUTPUT FORMAT NETCDF`), with its nodes and elements (dense
    /// indices, elements in the order of its groups) in place of the CSVs.
    columnar: Option<(Columnar, Vec<usize>, Vec<usize>)>,
    balance: Balance,
    last_row: Option<u64>,
    /// The energy guard's largest accepted rise of the balance residual and its bound, J
    /// (`solver::energy_guard::Balance`), for `summary.json`.
    guard: (f64, f64),
    /// An element's row, reused (no allocation per row).
    row: Vec<f64>,
    /// Nodes and elements generated by dividing beams.
    generated: crate::model::Generated,
    /// The `--refine` factor the model was refined by (1: as the deck says), recorded in
    /// `summary.json` so that tools reading the run (`plot animate`) rebuild the same mesh.
    pub refine: u32,
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
    /// Which states the run writes (a sweep's case writes every accepted step).
    sampling: Option<Sampling>,
}

/// The names of the history files a model's OUTPUT asks for (node and element files, or
/// `histories.nc` with `FORMAT NETCDF`, and `energy.csv`), relative to the output
/// directory: what a run's manifest lists.
pub fn history_files(model: &Model, sys: &System) -> Vec<String> {
    let mut names = Vec::new();
    if model.output.netcdf {
        names.push(netcdf::FILE_NAME.to_string());
    } else {
        let (nodes, elements) = plan(Path::new(""), model, sys);
        names.extend(nodes.iter().map(|(_, p)| stream::file_name(p)));
        names.extend(elements.iter().map(|(_, p, _)| stream::file_name(p)));
    }
    names.push("energy.csv".to_string());
    names
}

impl Writer {
    /// Creates the output directory, the files the model's OUTPUT requests, and a
    /// `summary.json` that says `"complete": false` until [`Writer::finish`] says otherwise.
    pub fn create(dir: &Path, deck: &str, model: &Model, sys: &System) -> io::Result<Self> {
        fs::create_dir_all(dir)?;
        let mut p = plan(dir, model, sys);
        let columnar = if model.output.netcdf {
            let (g, n, e) = groups(&p, sys);
            p = (Vec::new(), Vec::new());
            Some((Columnar::create(dir, &model.title, &g)?, n, e))
        } else {
            None
        };
        let (node_files, elem_files) = p;
        let block = stream::block_size(node_files.len() + elem_files.len() + 1);
        let mut nodes = Vec::new();
        for (i, path) in node_files {
            nodes.push((i, Stream::create(&path, NODE_HEADER, block)?));
        }
        let mut elements = Vec::new();
        for (e, path, head) in elem_files {
            elements.push((e, Stream::create(&path, &head, block)?));
        }
        let energy = Stream::create(&dir.join("energy.csv"), ENERGY_HEADER, block)?;
        let mut w = Self::with_streams(dir, deck, model, nodes, elements, energy);
        w.columnar = columnar;
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
        let mut p = plan(dir, model, sys);
        let mut columnar = None;
        if model.output.netcdf {
            let (g, n, e) = groups(&p, sys);
            p = (Vec::new(), Vec::new());
            let len = match state.files.last() {
                Some((name, len)) if name == netcdf::FILE_NAME => *len,
                _ => {
                    return Err(io::Error::new(
                        io::ErrorKind::InvalidData,
                        format!("the checkpoint has no {}", netcdf::FILE_NAME),
                    ));
                }
            };
            columnar = Some((Columnar::reopen(dir, &model.title, &g, len)?, n, e));
        }
        let files = &state.files[..state.files.len() - usize::from(columnar.is_some())];
        let (node_files, elem_files) = p;
        let mut names: Vec<(PathBuf, String)> = node_files
            .iter()
            .map(|(_, p)| (p.clone(), NODE_HEADER.to_string()))
            .collect();
        names.extend(elem_files.iter().map(|(_, p, h)| (p.clone(), h.clone())));
        names.push((dir.join("energy.csv"), ENERGY_HEADER.to_string()));
        let expected: Vec<String> = names.iter().map(|(p, _)| stream::file_name(p)).collect();
        let saved: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
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
        let block = stream::block_size(names.len());
        for ((path, header), (_, len)) in names.iter().zip(files) {
            streams.push(Stream::reopen(path, header, *len, block)?);
        }
        let energy = streams.pop().expect("energy.csv is always written");
        let elements: Vec<(usize, Stream)> = elem_files
            .iter()
            .map(|(e, _, _)| *e)
            .zip(streams.drain(node_files.len()..))
            .collect();
        let nodes: Vec<(usize, Stream)> = node_files.iter().map(|(i, _)| *i).zip(streams).collect();
        let mut w = Self::with_streams(dir, deck, model, nodes, elements, energy);
        w.columnar = columnar;
        w.balance = Balance {
            e0: state.e0,
            scale: state.energy_scale,
            max: state.max_balance,
        };
        w.last_row = state.last_row;
        if let Some(sampling) = state.sampling {
            w.sampling = sampling;
        }
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
            generated: model.summary().generated,
            refine: 1,
            end,
            sampling: Sampling::of(model),
            nodes,
            elements,
            energy,
            columnar: None,
            balance: Balance::default(),
            last_row: None,
            guard: (0.0, 0.0),
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
        if let Some((c, _, _)) = &mut self.columnar {
            c.sync()?;
            files.push((netcdf::FILE_NAME.to_string(), c.len()));
        }
        Ok(WriterState {
            files,
            e0: self.balance.e0,
            energy_scale: self.balance.scale,
            max_balance: self.balance.max,
            last_row: self.last_row,
            sampling: Some(self.sampling),
        })
    }

    /// Rewrites `summary.json` (e.g. after [`Writer::notes`] changed), still incomplete.
    pub fn write_notes(&self) -> io::Result<()> {
        self.write_summary(None, None)
    }

    /// Writes every accepted state (also the extra steps a contact event adds between the
    /// instants k·h), as `OUTPUT EVERY 1` with adaptive steps does: for the sweeps, whose
    /// quantities of interest must see the impacts (`crate::sweep::runner`).
    pub fn every_accepted_step(&mut self) {
        self.sampling = Sampling::every_step();
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn write_state(&mut self, snap: &Snapshot) -> io::Result<()> {
        let integ = snap.integ;
        let t = integ.t;
        for (i, st) in &mut self.nodes {
            st.row(&node_row(integ, *i))?;
        }
        let ctx = integ.current_context();
        // Where redundant equations were removed the reactions are not unique: the
        // minimum-norm ones are written (solver::redundancy).
        let reported = integ.reported_multipliers();
        let element_row = |e: usize, row: &mut Vec<f64>| {
            let el = &integ.sys.elements[e];
            let lam = integ.sys.element_lambda(e, &reported);
            row.clear();
            row.push(t);
            el.write_output_row(&ctx, &integ.nodes, lam, row);
        };
        for (e, st) in &mut self.elements {
            element_row(*e, &mut self.row);
            st.row(&self.row)?;
        }
        if let Some((c, nodes, elements)) = &mut self.columnar {
            c.begin(t);
            for i in nodes.iter() {
                let row = node_row(integ, *i);
                finite(&row, "histories.nc (node)")?;
                c.put(&row[1..]);
            }
            for e in elements.iter() {
                element_row(*e, &mut self.row);
                finite(&self.row, "histories.nc (element)")?;
                c.put(&self.row[1..]);
            }
        }
        let row = self.balance.row(integ);
        self.energy.row(&row)?;
        if let Some((c, _, _)) = &mut self.columnar {
            c.put(&row[1..]);
            c.end()?;
        }
        self.last_row = Some(snap.step);
        Ok(())
    }

    /// Writes every buffered row to its file (rows are only ever written whole).
    pub fn flush(&mut self) -> io::Result<()> {
        for (_, s) in self.nodes.iter_mut().chain(self.elements.iter_mut()) {
            s.flush()?;
        }
        if let Some((c, _, _)) = &mut self.columnar {
            c.flush()?;
        }
        self.energy.flush()
    }

    fn write_summary(
        &self,
        report: Option<&RunReport>,
        extra: Option<serde_json::Value>,
    ) -> io::Result<()> {
        let v = summary_value(
            &SummaryHead {
                deck: &self.deck,
                title: &self.title,
                effects: &self.effects,
                end: self.end,
                refine: self.refine,
                generated: &self.generated,
            },
            report,
            self.balance.max,
            self.guard,
            extra,
            &self.notes,
        );
        let text = serde_json::to_string_pretty(&v).unwrap_or_else(|_| "{}".into());
        let tmp = self.dir.join("summary.json.tmp");
        crate::safe_file::write_atomic(&tmp, &self.dir.join("summary.json"), text.as_bytes())
    }

    /// Writes the final state if it was skipped by `EVERY` (not for an interrupted run:
    /// its files end where a restart goes on), flushes, and rewrites `summary.json` with
    /// the counters and the `complete` flag.
    pub fn finish(
        &mut self,
        integ: &crate::solver::Integrator,
        report: &RunReport,
    ) -> io::Result<()> {
        // (No state was accepted when the initial one could not be computed: no row.)
        // Whatever happens to that row or the flush, the summary is written: every
        // failure leaves its record (issue 28).
        let last = if self.last_row.is_some()
            && self.last_row != Some(integ.stats.steps)
            && report.interrupted.is_none()
        {
            self.write_state(&Snapshot {
                integ,
                step: integ.stats.steps,
                h: 0.0,
            })
        } else {
            Ok(())
        };
        let flushed = self.flush();
        self.guard = (integ.balance.largest_rise, integ.balance.its_bound);
        let extra = element_facts(integ);
        self.write_summary(Some(report), extra)?;
        last.and(flushed)
    }

    /// Largest relative energy-balance error so far.
    pub fn max_balance_error(&self) -> f64 {
        self.balance.max
    }
}

/// What `summary.json` says of a run besides its report: the deck, its title, its
/// effects, the end time, the refinement and the generated nodes and elements.
pub struct SummaryHead<'a> {
    /// The deck's name (its path as given).
    pub deck: &'a str,
    /// The deck's title.
    pub title: &'a str,
    /// Active effects ([`crate::model::Effects::names`]).
    pub effects: &'a [&'static str],
    /// End time, s.
    pub end: f64,
    /// The `--refine` factor.
    pub refine: u32,
    /// Nodes and elements generated by dividing beams.
    pub generated: &'a crate::model::Generated,
}

/// The content of `summary.json` (before the run ends: `report = None`, `"complete":
/// false`), shared by the [`Writer`] and the in-memory [`Recorder`] so that both say the
/// same: `max_balance` the largest relative energy-balance error, `extra` the elements'
/// facts, `notes` the application's entries.
pub fn summary_value(
    head: &SummaryHead,
    report: Option<&RunReport>,
    max_balance: f64,
    guard: (f64, f64),
    extra: Option<serde_json::Value>,
    notes: &serde_json::Map<String, serde_json::Value>,
) -> serde_json::Value {
    let complete = report.is_some_and(|r| r.failure.is_none() && r.interrupted.is_none());
    let mut v = serde_json::json!({
        "deck": head.deck,
        "title": head.title,
        "effects": head.effects,
        "end_time": head.end,
        "complete": complete,
        "refine": head.refine,
        "generated": head.generated,
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
        v["energy"] = serde_json::json!({
            "max_balance_error": max_balance,
            "largest_created_j": guard.0,
            "its_bound_j": guard.1,
        });
        v["failure"] = match &r.failure {
            Some(f) => failure_json(f),
            None => serde_json::Value::Null,
        };
    }
    if let Some(x) = extra {
        v["elements"] = x;
    }
    for (k, x) in notes {
        v[k] = x.clone();
    }
    v
}

/// The elements' facts for `summary.json` ([`crate::elements::Element::summary`]), by
/// element number; `None` when no element has any.
pub fn element_facts(integ: &crate::solver::Integrator) -> Option<serde_json::Value> {
    let mut per_elem = serde_json::Map::new();
    for el in &integ.sys.elements {
        if let Some(s) = el.summary() {
            per_elem.insert(el.id().0.to_string(), s);
        }
    }
    (!per_elem.is_empty()).then_some(serde_json::Value::Object(per_elem))
}

/// The energy balance's accumulators (module docs): the initial energy, the scale the
/// balance error is relative to, and its largest value so far.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Balance {
    e0: Option<f64>,
    scale: f64,
    max: f64,
}

impl Balance {
    /// The row of `energy.csv` ([`ENERGY_HEADER`]) at the integrator's state, the
    /// accumulators updated: `D_num = W_ext − D_c − (E − E(0))`, residual `−D_num`.
    pub fn row(&mut self, integ: &crate::solver::Integrator) -> [f64; 9] {
        let e = integ.energies();
        let total = e.kinetic + e.strain + e.gravity;
        let e0 = *self.e0.get_or_insert(total);
        let numerical = integ.external_work - integ.damping_work - (total - e0);
        let residual = -numerical;
        self.scale = self
            .scale
            .max(e0.abs())
            .max(integ.external_work.abs())
            .max(e.kinetic)
            .max(e.strain.abs());
        if integ.dynamic && self.scale > 0.0 {
            self.max = self.max.max(residual / self.scale);
        }
        [
            integ.t,
            e.kinetic,
            e.strain,
            e.gravity,
            total,
            integ.external_work,
            integ.damping_work,
            numerical,
            residual,
        ]
    }

    /// Largest relative energy-balance error so far.
    pub fn max_error(&self) -> f64 {
        self.max
    }
}

/// A node's row of `node_<N>.csv` ([`NODE_HEADER`]).
pub fn node_row(integ: &crate::solver::Integrator, i: usize) -> [f64; 19] {
    let s = &integ.nodes[i];
    let u = s.x - integ.sys.x0[i];
    let phi = rotation::log(&s.r);
    let w = s.r * s.w;
    [
        integ.t, s.x.x, s.x.y, s.x.z, u.x, u.y, u.z, phi.x, phi.y, phi.z, s.v.x, s.v.y, s.v.z, w.x,
        w.y, w.z, s.a.x, s.a.y, s.a.z,
    ]
}

/// Refuses a row with a non-finite value (no NaN reaches a file).
fn finite(row: &[f64], file: &str) -> io::Result<()> {
    match row.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(bad) => Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "refusing to write a non-finite value to {file} (column {}, t = {})",
                bad + 1,
                row[0]
            ),
        )),
    }
}

fn failure_json(f: &Failure) -> serde_json::Value {
    serde_json::json!({
        "message": f.to_string(),
        "time": f.time,
        "step": f.step,
        "residual_history": f.residual_history.iter().map(|r| if r.is_finite() { *r } else { f64::MAX }).collect::<Vec<_>>(),
        "worst": &*f.worst,
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

    /// The rows written (node accelerations, element reactions): the sampled states.
    fn reads_reactions(&self, snap: &Snapshot) -> bool {
        self.sampling.takes(snap)
    }

    fn progress(&mut self, t: f64, end: f64, stats: &Stats) {
        if let Some(p) = &mut self.progress {
            p(t, end, stats);
        }
    }
}
