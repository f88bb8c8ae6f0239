//! Integration tests of the mechanics (dynamics, springs, drivers, contact, clearance, control,
//! rotations, sparse modes), in one test binary (one link instead of seven): each module is
//! a former `tests/<name>.rs`; `cargo test --test mechanics <name>::` runs one of them.
//!
//! proptest keeps its failure seeds beside the crate root's directory once that holds a
//! `main.rs`: `rotation_props`' seeds are in `tests/proptest-regressions/rotation_props.txt`
//! (they were `tests/rotation_props.proptest-regressions` while the test was a file of its own).

#[path = "../common/mod.rs"]
mod common;

mod clearance;
mod contact;
mod control;
mod drivers;
mod dynamics;
mod modes_sparse;
mod planar_loops;
mod rotation_props;
mod springs;
