//! `mecano.run`, `mecano.run_many`, `mecano.open`: runs of a deck into memory or into an
//! output directory (the CLI's files, byte for byte), and the histories of a run.

use crate::deck::Deck;
use crate::{MecanoError, poll};
use mecano::app::{self, memory};
use mecano::interrupt::Interrupts;
use mecano::model::{Analysis, Model};
use mecano::output::Recorded;
use mecano::output::read::{ReadOptions, read_numeric};
use numpy::{IntoPyArray, PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::path::{Path, PathBuf};

/// Where a run's histories are.
enum Source {
    /// In memory ([`memory::run_in_memory`]).
    Memory {
        nodes: Vec<Recorded>,
        elements: Vec<Recorded>,
        energy: Recorded,
    },
    /// In an output directory (CSV files or `histories.nc`), read when asked for.
    Dir,
}

/// A run's histories and summary (wrapped by the Python class `mecano.Run`).
#[pyclass(module = "mecano._mecano", frozen)]
pub struct RunData {
    source: Source,
    dir: Option<PathBuf>,
    node_ids: Vec<u32>,
    element_ids: Vec<u32>,
    summary: String,
}

/// A history as `(columns, rows × columns array)`: the array takes over the vector (no copy).
fn table<'py>(py: Python<'py>, r: Recorded) -> PyResult<Bound<'py, PyTuple>> {
    let n = r.columns.len();
    let rows = r.data.len() / n.max(1);
    let a = r.data.into_pyarray(py).reshape([rows, n])?;
    PyTuple::new(py, [r.columns.into_pyobject(py)?.into_any(), a.into_any()])
}

fn read_table<'py>(py: Python<'py>, path: &Path) -> PyResult<Bound<'py, PyTuple>> {
    let t = py
        .detach(|| read_numeric(path, ReadOptions::default()))
        .map_err(|e| MecanoError::new_err(format!("{}: {e}", path.display())))?;
    let n = t.header.len();
    let rows = t.rows.len();
    let data: Vec<f64> = t.rows.into_iter().flatten().collect();
    let a: Bound<'py, PyArray2<f64>> = data.into_pyarray(py).reshape([rows, n])?;
    PyTuple::new(py, [t.header.into_pyobject(py)?.into_any(), a.into_any()])
}

#[pymethods]
impl RunData {
    /// Node numbers with a history.
    #[getter]
    fn node_ids(&self) -> Vec<u32> {
        self.node_ids.clone()
    }

    /// Element numbers with a history.
    #[getter]
    fn element_ids(&self) -> Vec<u32> {
        self.element_ids.clone()
    }

    /// `summary.json`'s text.
    #[getter]
    fn summary_json(&self) -> &str {
        &self.summary
    }

    /// The output directory (None for a run into memory).
    #[getter]
    fn dir(&self) -> Option<PathBuf> {
        self.dir.clone()
    }

    /// Node `id`'s history: (columns, array of rows).
    fn node<'py>(&self, py: Python<'py>, id: u32) -> PyResult<Bound<'py, PyTuple>> {
        match &self.source {
            Source::Memory { nodes, .. } => match nodes.iter().find(|r| r.id == id) {
                Some(r) => table(py, r.clone()),
                None => Err(missing("node", id, &self.node_ids)),
            },
            Source::Dir => {
                if !self.node_ids.contains(&id) {
                    return Err(missing("node", id, &self.node_ids));
                }
                read_table(py, &self.path(&format!("node_{id}.csv")))
            }
        }
    }

    /// Element `id`'s history: (columns, array of rows).
    fn element<'py>(&self, py: Python<'py>, id: u32) -> PyResult<Bound<'py, PyTuple>> {
        match &self.source {
            Source::Memory { elements, .. } => match elements.iter().find(|r| r.id == id) {
                Some(r) => table(py, r.clone()),
                None => Err(missing("element", id, &self.element_ids)),
            },
            Source::Dir => {
                if !self.element_ids.contains(&id) {
                    return Err(missing("element", id, &self.element_ids));
                }
                read_table(py, &self.path(&format!("element_{id}.csv")))
            }
        }
    }

    /// The energy balance: (columns, array of rows).
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        match &self.source {
            Source::Memory { energy, .. } => table(py, energy.clone()),
            Source::Dir => read_table(py, &self.path("energy.csv")),
        }
    }
}

impl RunData {
    fn path(&self, name: &str) -> PathBuf {
        self.dir.clone().unwrap_or_default().join(name)
    }

    /// A run's data from in-memory histories and its summary.
    pub fn from_memory(
        nodes: Vec<Recorded>,
        elements: Vec<Recorded>,
        energy: Recorded,
        summary: serde_json::Value,
    ) -> Self {
        RunData {
            node_ids: nodes.iter().map(|r| r.id).collect(),
            element_ids: elements.iter().map(|r| r.id).collect(),
            source: Source::Memory {
                nodes,
                elements,
                energy,
            },
            dir: None,
            summary: serde_json::to_string_pretty(&summary).unwrap_or_default(),
        }
    }

    fn memory(run: memory::MemoryRun) -> Self {
        let h = run.histories;
        RunData {
            node_ids: h.nodes.iter().map(|r| r.id).collect(),
            element_ids: h.elements.iter().map(|r| r.id).collect(),
            source: Source::Memory {
                nodes: h.nodes,
                elements: h.elements,
                energy: h.energy,
            },
            dir: None,
            summary: serde_json::to_string_pretty(&run.summary).unwrap_or_default(),
        }
    }

    /// The run in an output directory (its summary.json read now, histories when asked).
    pub fn from_dir(dir: &Path) -> PyResult<Self> {
        let summary = std::fs::read_to_string(dir.join("summary.json")).map_err(|e| {
            MecanoError::new_err(format!(
                "{}: not the output directory of a run (summary.json: {e})",
                dir.display()
            ))
        })?;
        let mut node_ids = Vec::new();
        let mut element_ids = Vec::new();
        for (kind, id) in mecano::output::columnar::entities(dir) {
            if kind == "node" {
                node_ids.push(id);
            } else {
                element_ids.push(id);
            }
        }
        let entries = std::fs::read_dir(dir)
            .map_err(|e| MecanoError::new_err(format!("{}: {e}", dir.display())))?;
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let num = |prefix: &str| {
                name.strip_prefix(prefix)?
                    .strip_suffix(".csv")?
                    .parse::<u32>()
                    .ok()
            };
            if let Some(n) = num("node_") {
                node_ids.push(n);
            } else if let Some(n) = num("element_") {
                element_ids.push(n);
            }
        }
        node_ids.sort_unstable();
        node_ids.dedup();
        element_ids.sort_unstable();
        element_ids.dedup();
        Ok(RunData {
            source: Source::Dir,
            dir: Some(dir.to_path_buf()),
            node_ids,
            element_ids,
            summary,
        })
    }
}

fn missing(what: &str, id: u32, have: &[u32]) -> PyErr {
    let list: Vec<String> = have.iter().map(u32::to_string).collect();
    PyKeyError::new_err(format!(
        "no history of {what} {id}; this run has {what}s [{}] (the deck's OUTPUT card selects them)",
        list.join(", ")
    ))
}

/// The end time of a model's analysis (1 for a static one: the load factor).
pub fn end_time(model: &Model) -> f64 {
    match model.analysis {
        Analysis::Dynamic { end, .. } => end,
        Analysis::Static { .. } => 1.0,
    }
}

/// One run of `deck` into `out` (None: memory), with the GIL released; what it returns and
/// the Python error that stopped it, if any.
fn execute(deck: &Deck, out: Option<&Path>, interrupts: &Interrupts) -> Outcome {
    if deck.model.modes.is_some() {
        return Err((
            app::EXIT_BAD_INPUT,
            format!(
                "{} asks for a modal analysis (ANALYSIS MODES): use mecano.modes(deck)",
                deck.name
            ),
        ));
    }
    match out {
        None => memory::run_in_memory(&deck.model, &deck.name, deck.refine, interrupts)
            .map(RunData::memory),
        Some(dir) => {
            let id = app::deck_identity(
                deck.path.as_deref().unwrap_or(Path::new(&deck.name)),
                &deck.text,
                &deck.set,
                deck.refine,
            );
            let id = mecano::checkpoint::DeckIdentity {
                path: deck.name.clone(),
                ..id
            };
            app::run_checkpointed(
                &deck.model,
                id,
                dir,
                app::DEFAULT_CHECKPOINT_SECONDS,
                false,
                interrupts.clone(),
            )?;
            RunData::from_dir(dir).map_err(|e| (app::EXIT_FAILED, e.to_string()))
        }
    }
}

/// The Python exception of an error before or around a run.
fn run_error(code: u8, msg: String) -> PyErr {
    if code == app::EXIT_BAD_INPUT {
        PyValueError::new_err(msg)
    } else {
        MecanoError::new_err(msg)
    }
}

/// Runs a deck (see `mecano.run`); returns the run's data, or raises the error that
/// stopped it with the partial run in the exception's `run_data` attribute.
#[pyfunction]
#[pyo3(signature = (deck, out = None, progress = None))]
pub fn run_deck(
    py: Python<'_>,
    deck: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<RunData> {
    let deck = Deck::of(deck)?;
    if let Some(p) = &progress
        && !p.bind(py).is_callable()
    {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "progress must be a callable of (t, end)",
        ));
    }
    let (interrupts, pending) = poll::interrupts(progress, end_time(&deck.model), None);
    let result = py.detach(|| execute(&deck, out.as_deref(), &interrupts));
    let data = result.map_err(|(c, m)| run_error(c, m))?;
    if let Some(err) = poll::take(&pending) {
        let data = Py::new(py, data)?;
        let _ = err.value(py).setattr("run_data", data);
        return Err(err);
    }
    Ok(data)
}

/// What a run returns, or its exit code and message.
type Outcome = Result<RunData, (u8, String)>;

/// Runs several decks on `threads` threads, the GIL released (see `mecano.run_many`).
/// Ctrl-C stops every run at the end of its step; the KeyboardInterrupt then carries the
/// runs (`run_data`, a list) in the order of the decks.
#[pyfunction]
#[pyo3(signature = (decks, threads = None, out = None))]
pub fn run_many(
    py: Python<'_>,
    decks: Vec<Bound<'_, PyAny>>,
    threads: Option<usize>,
    out: Option<Vec<Option<PathBuf>>>,
) -> PyResult<Vec<RunData>> {
    let decks: Vec<Deck> = decks.iter().map(Deck::of).collect::<PyResult<_>>()?;
    let outs = match out {
        Some(o) if o.len() != decks.len() => {
            return Err(PyValueError::new_err(format!(
                "out has {} directories for {} decks",
                o.len(),
                decks.len()
            )));
        }
        Some(o) => o,
        None => vec![None; decks.len()],
    };
    let threads = threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    // One set of flags for all: Ctrl-C (seen by whichever run polls on the main thread
    // first... none does: the main thread waits below and polls itself).
    let (interrupts, pending) = poll::interrupts(None, 0.0, None);
    let quiet = interrupts.flags();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<std::sync::Mutex<Option<Outcome>>> =
        decks.iter().map(|_| std::sync::Mutex::new(None)).collect();
    py.detach(|| {
        std::thread::scope(|s| {
            let workers: Vec<_> = (0..threads.min(decks.len()))
                .map(|_| {
                    s.spawn(|| {
                        loop {
                            let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                            if i >= decks.len() {
                                break;
                            }
                            let r = execute(&decks[i], outs[i].as_deref(), &quiet);
                            *results[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                        }
                    })
                })
                .collect();
            // The calling thread polls Python's signals while the workers run.
            while workers.iter().any(|w| !w.is_finished()) {
                std::thread::sleep(poll::POLL);
                interrupts.stopping_at(0.0);
            }
        });
    });
    let mut out = Vec::with_capacity(decks.len());
    let mut first_error = None;
    for r in results {
        match r.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(Ok(d)) => out.push(d),
            Some(Err((c, m))) => {
                first_error.get_or_insert_with(|| run_error(c, m));
            }
            None => {}
        }
    }
    if let Some(err) = poll::take(&pending) {
        let list: Vec<Py<RunData>> = out
            .into_iter()
            .map(|d| Py::new(py, d))
            .collect::<PyResult<_>>()?;
        let _ = err.value(py).setattr("run_data", list);
        return Err(err);
    }
    if let Some(e) = first_error {
        return Err(e);
    }
    Ok(out)
}

/// The run in an output directory (CSV files or histories.nc).
#[pyfunction]
pub fn open_dir(dir: PathBuf) -> PyResult<RunData> {
    RunData::from_dir(&dir)
}
