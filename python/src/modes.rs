//! `mecano.modes`: the linearised modes of a deck, the numbers `mecano-rs modes` prints
//! and writes (the same library call, [`mecano::modes::about::analyse_model`]).

use crate::MecanoError;
use crate::deck::{Deck, finite};
use mecano::modes::about::{self, About};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Modes of `deck` about its initial state (`at=None`), its static equilibrium
/// (`at="static"`), the state reached at time `at` (s), or the rotating hub's relative
/// equilibrium (`rotating=True`): a dict of arrays (see `mecano.modes`).
#[pyfunction]
#[pyo3(signature = (deck, at = None, count = 20, rotating = false))]
pub fn modes<'py>(
    py: Python<'py>,
    deck: &Bound<'py, PyAny>,
    at: Option<&Bound<'py, PyAny>>,
    count: usize,
    rotating: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let deck = Deck::of(deck)?;
    if count == 0 {
        return Err(PyValueError::new_err("count must be at least 1"));
    }
    let about = match at {
        _ if rotating || deck.model.modes_rotating => About::Rotating,
        None => About::Initial,
        Some(a) if a.extract::<String>().is_ok_and(|s| s == "static") => About::Static,
        Some(a) => match a.extract::<f64>() {
            Ok(t) => About::At(finite("at", t)?),
            Err(_) => {
                return Err(pyo3::exceptions::PyTypeError::new_err(
                    "at is None (initial state), 'static' or a time in s",
                ));
            }
        },
    };
    let model = deck.model.clone();
    let (integ, a) = py
        .detach(|| about::analyse_model(&model, about, count))
        .map_err(|f| {
            let msg = format!("{}: {}", deck.name, f.message);
            if f.bad_input {
                PyValueError::new_err(msg)
            } else {
                MecanoError::new_err(msg)
            }
        })?;
    let n = a.modes.len();
    let nodes = &integ.sys.node_dofs;
    let mut shapes = vec![0.0; n * nodes.len() * 6];
    for (m, mode) in a.modes.iter().enumerate() {
        for (i, dofs) in nodes.iter().enumerate() {
            for (c, &d) in dofs.iter().enumerate() {
                if d != mecano::solver::system::FIXED {
                    shapes[(m * nodes.len() + i) * 6 + c] = mode.shape[d];
                }
            }
        }
    }
    let out = PyDict::new(py);
    let col =
        |f: &dyn Fn(&mecano::modes::Mode) -> f64| -> Vec<f64> { a.modes.iter().map(f).collect() };
    out.set_item("frequency_hz", col(&|m| m.frequency_hz).into_pyarray(py))?;
    out.set_item("natural_hz", col(&|m| m.natural_hz).into_pyarray(py))?;
    out.set_item("damping_ratio", col(&|m| m.damping_ratio).into_pyarray(py))?;
    out.set_item("eigenvalue_real", col(&|m| m.eigenvalue.0).into_pyarray(py))?;
    out.set_item("eigenvalue_imag", col(&|m| m.eigenvalue.1).into_pyarray(py))?;
    let kinds: Vec<&str> = a
        .modes
        .iter()
        .map(|m| match m.kind {
            mecano::modes::ModeKind::Rigid => "rigid",
            mecano::modes::ModeKind::Elastic => "elastic",
            mecano::modes::ModeKind::Unstable => "unstable",
        })
        .collect();
    out.set_item("kind", kinds)?;
    out.set_item(
        "shapes",
        shapes.into_pyarray(py).reshape([n, nodes.len(), 6])?,
    )?;
    out.set_item(
        "nodes",
        integ.sys.node_ids.iter().map(|n| n.0).collect::<Vec<_>>(),
    )?;
    out.set_item("groups", a.groups.clone())?;
    out.set_item("highest_hz", a.highest_hz)?;
    out.set_item("time", integ.t)?;
    Ok(out)
}
