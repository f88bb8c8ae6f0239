//! Integration tests against closed forms and published benchmarks, in one test binary (one
//! link instead of nine): each module is a former `tests/<name>.rs` (`benchmarks` with its
//! submodules in `benchmarks/`); `cargo test --test validation <name>::` runs one of them.

#[path = "../common/mod.rs"]
mod common;

mod benchmarks;
mod bend_shooting;
mod converged;
mod damping;
mod high_order;
mod pendulum;
mod refine;
mod section_properties;
mod slider_crank_clearance;
mod slider_crank_driven;
mod spinup;
