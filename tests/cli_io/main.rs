//! Integration tests of the binary and its files, in one test binary (one link instead of
//! eleven): each module is a former `tests/<name>.rs`; `cargo test --test cli_io <name>::`
//! runs one of them.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod compare;
mod energy_guard_run;
mod every_row;
mod large;
mod modes_output;
mod outdir;
mod outdir_hostile;
mod plot;
mod refusals;
mod resources;
mod restart;
mod silent_wrong;
mod sweep;
mod vtk;
