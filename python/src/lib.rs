//! The extension module `mecano._mecano` of the Python package `mecano` (python/mecano/):
//! a thin layer that converts Python values and delegates to the library crate `mecano`
//! (no physics here). Long calls release the GIL and poll Python's signals, so Ctrl-C
//! raises KeyboardInterrupt at the end of a step; errors map onto the exception hierarchy
//! below, whose attributes carry the data (file, line, column; time; the partial run).

use pyo3::prelude::*;

mod deck;
mod law;
mod modes;
mod overrides;
mod poll;
mod run;
mod sim;

pyo3::create_exception!(
    _mecano,
    MecanoError,
    pyo3::exceptions::PyException,
    "Base class of the errors of mecano."
);
pyo3::create_exception!(
    _mecano,
    DeckError,
    MecanoError,
    "A deck with errors: `errors` lists each as (file, line, column, message); str() is the diagnostic the CLI prints."
);
pyo3::create_exception!(
    _mecano,
    SimulationError,
    MecanoError,
    "A Simulation that cannot go on (it failed, or it is in use by another thread)."
);

#[pymodule]
fn _mecano(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("MecanoError", py.get_type::<MecanoError>())?;
    m.add("DeckError", py.get_type::<DeckError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add_class::<deck::Deck>()?;
    m.add_class::<run::RunData>()?;
    m.add_class::<sim::Simulation>()?;
    m.add_class::<law::Sensors>()?;
    m.add_function(wrap_pyfunction!(run::run_deck, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_many, m)?)?;
    m.add_function(wrap_pyfunction!(run::open_dir, m)?)?;
    m.add_function(wrap_pyfunction!(modes::modes, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
