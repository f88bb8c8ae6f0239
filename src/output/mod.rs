//! Output writers: per-node and per-element CSV histories, the energy balance and
//! `summary.json`.
//!
//! Rows are streamed (flushed as they are written), so a run that stops early keeps what
//! it computed. `summary.json` is written at the start with `"complete": false` and
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

pub mod vtk;

use crate::model::{Model, Selection};
use crate::rotation;
use crate::solver::{Failure, Observer, RunReport, Snapshot, Stats, System};
use std::fs::{self, File};
use std::io;
use std::path::{Path, PathBuf};

/// Header of every node history file.
pub const NODE_HEADER: &str = "t,x,y,z,ux,uy,uz,rx,ry,rz,vx,vy,vz,wx,wy,wz,ax,ay,az";

/// Header of `energy.csv`.
pub const ENERGY_HEADER: &str = "t,kinetic,strain,gravity,total,external_work,damping_dissipation,numerical_dissipation,balance_residual";

struct Stream {
    w: csv::Writer<File>,
    /// File name and header, for messages.
    name: String,
    header: String,
    /// Shortest round-trip formatting of a number (Ryū: Adams, PLDI 2018), several
    /// times faster than `{:e}` (Grisu with a Dragon4 fallback), which took 30 % of a
    /// run that wrote every node and element at every step (`OUTPUT`'s default).
    num: ryu::Buffer,
}

impl Stream {
    fn create(path: &Path, header: &str) -> io::Result<Self> {
        // Numbers and column names never need quotes: the writer need not scan for them.
        let mut w = csv::WriterBuilder::new()
            .has_headers(false)
            .quote_style(csv::QuoteStyle::Never)
            .from_path(path)?;
        w.write_record(header.split(','))?;
        Ok(Stream {
            w,
            name: path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
            header: header.to_string(),
            num: ryu::Buffer::new(),
        })
    }

    fn row(&mut self, values: &[f64]) -> io::Result<()> {
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            let col = self.header.split(',').nth(bad).unwrap_or("?");
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "refusing to write a non-finite value to {} (column {}, `{col}`, t = {})",
                    self.name,
                    bad + 1,
                    values[0]
                ),
            ));
        }
        for v in values {
            self.w.write_field(self.num.format_finite(*v))?;
        }
        self.w.write_record(std::iter::empty::<&[u8]>())?;
        Ok(())
    }
}

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
    /// Nodes and elements generated by dividing beams.
    generated: crate::model::Generated,
    /// The `--refine` factor the model was refined by (1: as the deck says), recorded in
    /// `summary.json` so that tools reading the run (`plot animate`) rebuild the same mesh.
    pub refine: u32,
    /// Optional progress callback (e.g. a progress bar): time, end time, counters.
    pub progress: Option<ProgressFn>,
}

impl Writer {
    /// Creates the output directory, the files the model's OUTPUT requests, and a
    /// `summary.json` that says `"complete": false` until [`Writer::finish`] says otherwise.
    pub fn create(dir: &Path, deck: &str, model: &Model, sys: &System) -> io::Result<Self> {
        fs::create_dir_all(dir)?;
        let node_idx: Vec<usize> = match &model.output.nodes {
            Selection::All => (0..model.nodes.len()).collect(),
            Selection::None => Vec::new(),
            Selection::List(l) => l
                .iter()
                .filter_map(|id| model.nodes.get_index_of(id))
                .collect(),
        };
        let mut nodes = Vec::new();
        for i in node_idx {
            let id = sys.node_ids[i].0;
            nodes.push((
                i,
                Stream::create(&dir.join(format!("node_{id}.csv")), NODE_HEADER)?,
            ));
        }
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
            let head = format!("t,{}", header.join(","));
            elements.push((
                e,
                Stream::create(&dir.join(format!("element_{}.csv", el.id().0)), &head)?,
            ));
        }
        let end = match model.analysis {
            crate::model::Analysis::Dynamic { end, .. } => end,
            crate::model::Analysis::Static { .. } => 1.0,
        };
        let w = Writer {
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
            energy: Stream::create(&dir.join("energy.csv"), ENERGY_HEADER)?,
            e0: None,
            energy_scale: 0.0,
            max_balance: 0.0,
            last_row: None,
            row: Vec::new(),
            progress: None,
        };
        w.write_summary(None, None)?;
        Ok(w)
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

    fn flush(&mut self) -> io::Result<()> {
        for (_, s) in self.nodes.iter_mut().chain(self.elements.iter_mut()) {
            s.w.flush()?;
        }
        self.energy.w.flush()
    }

    fn write_summary(
        &self,
        report: Option<&RunReport>,
        extra: Option<serde_json::Value>,
    ) -> io::Result<()> {
        let complete = report.is_some_and(|r| r.failure.is_none());
        let mut v = serde_json::json!({
            "deck": self.deck,
            "title": self.title,
            "effects": self.effects,
            "end_time": self.end,
            "complete": complete,
            "refine": self.refine,
            "generated": self.generated,
        });
        if let Some(r) = report {
            let st = &r.stats;
            v["time_reached"] = serde_json::json!(r.time);
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
        let text = serde_json::to_string_pretty(&v).unwrap_or_else(|_| "{}".into());
        let tmp = self.dir.join("summary.json.tmp");
        fs::write(&tmp, text)?;
        fs::rename(tmp, self.dir.join("summary.json"))
    }

    /// Writes the final state if it was skipped by `EVERY`, flushes, and rewrites
    /// `summary.json` with the counters and the `complete` flag.
    pub fn finish(
        &mut self,
        integ: &crate::solver::Integrator,
        report: &RunReport,
    ) -> io::Result<()> {
        if self.last_row != Some(integ.stats.steps) {
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
