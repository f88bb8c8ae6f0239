//! `mecano.Deck`: a deck's text parsed into a model, with its parameters and refinement.

use crate::DeckError;
use mecano::deck as mdeck;
use mecano::model::Model;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use std::path::PathBuf;

/// A deck (its text), parsed and validated: `Deck(text)` or `Deck.read(path)`.
#[pyclass(module = "mecano", frozen)]
#[derive(Clone)]
pub struct Deck {
    /// The deck's text as read.
    pub text: String,
    /// Its name in diagnostics and summaries (the path as given, or `<deck>`).
    pub name: String,
    /// The path it was read from, if any.
    pub path: Option<PathBuf>,
    /// Parameter overrides, in order.
    pub set: Vec<(String, f64)>,
    /// `refined(k)`'s factor (1: as written).
    pub refine: u32,
    /// The model.
    pub model: Model,
}

/// The `DeckError` of a deck's errors: message as the CLI prints it, `errors` the list of
/// `(file, line, column, message)`.
pub fn deck_error(py: Python<'_>, errs: mdeck::DeckErrors) -> PyErr {
    let items: Vec<(String, Option<usize>, Option<usize>, String)> = errs
        .errors()
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let lc = errs.line_col(i);
            (
                errs.file_name().to_string(),
                lc.map(|x| x.0),
                lc.map(|x| x.1),
                e.kind.to_string(),
            )
        })
        .collect();
    let text = format!("{:?}", miette::Report::new(errs));
    let err = DeckError::new_err(text);
    if let Ok(list) = PyList::new(py, items) {
        let _ = err.value(py).setattr("errors", list);
    }
    err
}

impl Deck {
    /// Parses `text` named `name` with overrides `set`, refined by `refine`.
    pub fn parse(
        py: Python<'_>,
        text: String,
        name: String,
        path: Option<PathBuf>,
        set: Vec<(String, f64)>,
        refine: u32,
    ) -> PyResult<Self> {
        let mut model = py
            .detach(|| mdeck::parse_deck_with(&text, &name, &set))
            .map_err(|e| deck_error(py, e))?;
        // A deck read from a file names its superelements' FILES relative to its own
        // directory, as the command line's `load_deck` reads them.
        if let Some(dir) = path.as_deref().and_then(std::path::Path::parent) {
            model.resolve_superelement_dirs(dir);
        }
        if refine > 1 {
            model
                .refine(refine)
                .map_err(|e| DeckError::new_err(format!("{name}: refined({refine}): {e}")))?;
        }
        Ok(Deck {
            text,
            name,
            path,
            set,
            refine,
            model,
        })
    }

    /// The deck of a Python argument: a `Deck`, or a path (str or os.PathLike) to read.
    pub fn of(obj: &Bound<'_, PyAny>) -> PyResult<Deck> {
        if let Ok(d) = obj.cast::<Deck>() {
            return Ok(d.get().clone());
        }
        if obj.is_instance_of::<pyo3::types::PyString>() || obj.hasattr("__fspath__")? {
            let p: PathBuf = obj.extract()?;
            return Self::read_path(obj.py(), p);
        }
        Err(PyTypeError::new_err(format!(
            "expected a mecano.Deck or a path to a deck, not {}",
            obj.get_type().name()?
        )))
    }

    fn read_path(py: Python<'_>, path: PathBuf) -> PyResult<Deck> {
        let name = path.display().to_string();
        let too_large =
            std::fs::metadata(&path).is_ok_and(|m| m.len() > mdeck::limits::MAX_DECK_BYTES as u64);
        match (!too_large).then(|| std::fs::read(&path).map(String::from_utf8)) {
            Some(Ok(Ok(text))) => Self::parse(py, text, name, Some(path), Vec::new(), 1),
            // Missing, unreadable, too large or not UTF-8: the loader's own diagnostics.
            _ => match mdeck::load_deck(&path) {
                Err(e) => Err(deck_error(py, e)),
                Ok(_) => Err(DeckError::new_err(format!("{name}: cannot be read"))),
            },
        }
    }
}

/// A number that must be finite.
pub fn finite(what: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!(
            "{what} must be a finite number, not {v}"
        )))
    }
}

#[pymethods]
impl Deck {
    /// A deck from its text; `name` names it in diagnostics and summaries.
    #[new]
    #[pyo3(signature = (text, name = "<deck>".to_string()))]
    fn new(py: Python<'_>, text: String, name: String) -> PyResult<Self> {
        Self::parse(py, text, name, None, Vec::new(), 1)
    }

    /// Reads and parses the deck file `path` (str or os.PathLike).
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        Self::read_path(py, path)
    }

    /// The deck's name (its path as given, or the name given to `Deck(text, name)`).
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// The deck's text as read (`str(deck)` is the canonical text of the model).
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// The deck's title.
    #[getter]
    fn title(&self) -> &str {
        &self.model.title
    }

    /// The refinement factor (`refined(k)`; 1 as written).
    #[getter]
    fn refine(&self) -> u32 {
        self.refine
    }

    /// The PARAMETERS and their values in force (overrides applied), in deck order.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.model.parameters {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The same deck with parameter overrides, e.g. `deck.with_parameters(E=2.1e10)`
    /// (names the deck's PARAMETERS; a name it does not define is a DeckError).
    #[pyo3(signature = (**values))]
    fn with_parameters(
        &self,
        py: Python<'_>,
        values: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Deck> {
        let mut set = self.set.clone();
        if let Some(values) = values {
            for (k, v) in values.iter() {
                let name: String = k.extract()?;
                let v: f64 = v.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "parameter {name}: expected a number, not {}",
                        v.get_type()
                            .name()
                            .map(|n| n.to_string())
                            .unwrap_or_default()
                    ))
                })?;
                finite(&format!("parameter {name}"), v)?;
                set.retain(|(n, _)| n != &name);
                set.push((name, v));
            }
        }
        Self::parse(
            py,
            self.text.clone(),
            self.name.clone(),
            self.path.clone(),
            set,
            self.refine,
        )
    }

    /// The same deck with every beam divided into `k` times its elements (`--refine k`).
    fn refined(&self, py: Python<'_>, k: u32) -> PyResult<Deck> {
        if k == 0 {
            return Err(PyValueError::new_err("refined(k) takes k >= 1"));
        }
        Self::parse(
            py,
            self.text.clone(),
            self.name.clone(),
            self.path.clone(),
            self.set.clone(),
            self.refine.max(1) * k,
        )
    }

    /// The canonical text of the model (parse ∘ write = identity).
    fn __str__(&self) -> String {
        mdeck::write_deck(&self.model)
    }

    fn __repr__(&self) -> String {
        let mut s = format!("Deck({:?}, title={:?}", self.name, self.model.title);
        if !self.set.is_empty() {
            let kv: Vec<String> = self.set.iter().map(|(k, v)| format!("{k}={v}")).collect();
            s += &format!(", parameters={{{}}}", kv.join(", "));
        }
        if self.refine > 1 {
            s += &format!(", refine={}", self.refine);
        }
        s + ")"
    }

    /// Node numbers, in deck order (generated nodes included).
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        PyTuple::new(py, self.model.nodes.keys().map(|n| n.0))
    }

    /// Element numbers with their kind (deck keyword), in deck order.
    #[getter]
    fn elements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, e) in &self.model.elements {
            d.set_item(k.0, e.kind.keyword())?;
        }
        Ok(d)
    }
}
