//! mecano-rs: a flexible multibody dynamics code in the line of MECANO (Géradin & Cardona).
//!
//! Data flows one way: [`deck`] (text → cards → [`model::Model`]) → [`elements`]
//! (residual, tangent and mass of each element) → [`solver`] (HHT time integration,
//! Newton, sparse linear algebra) → [`output`] (per-node CSV histories, `summary.json`).
#![warn(missing_docs)]
// Numeric kernels index several arrays with one loop index; iterator zips would hide it.
#![allow(clippy::needless_range_loop)]

pub mod app;
pub mod checkpoint;
pub mod compare;
pub mod deck;
pub mod dual;
pub mod elements;
pub mod failpoint;
pub mod figure;
pub mod framed;
pub mod interrupt;
pub mod interval;
mod kinds;
pub mod lagrange;
pub mod lanczos;
pub mod model;
pub mod modes;
pub mod output;
pub mod plot;
pub mod rotation;
pub mod safe_file;
pub mod scenes;
pub mod solver;
pub mod study;
pub mod sweep;
