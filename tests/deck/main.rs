//! Integration tests of the deck parser and writer, in one test binary (one link instead of
//! eight): each module is a former `tests/<name>.rs`; `cargo test --test deck <name>::` runs
//! one of them.

#[path = "../common/mod.rs"]
mod common;

mod deck_errors;
mod deck_props;
mod deck_roundtrip;
mod functions;
mod fuzz_regressions;
mod grammar_doc;
mod hostile;
mod hostile_corpus;
mod kinds_registry;
mod model_props;
