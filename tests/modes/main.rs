//! Linearised modes (issue 24): against closed forms and an independent
//! minimal-coordinate model. See docs/modes.md. One module a concept (beams, pendulums,
//! rotating structures, integrators, the command line, the solve's paths), one test binary:
//! `cargo test --test modes rotating::` runs one of them.

#[path = "../common/mod.rs"]
mod common;

mod beams;
mod cli;
mod integrators;
mod paths;
mod pendulums;
mod rotating;

use mecano::app::modes::{About, analyse_model, load};
use mecano::model::Model;
use mecano::modes::{ModalAnalysis, ModeKind};
use std::f64::consts::PI;
use std::path::Path;

fn deck(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("decks")
        .join(name)
}

fn model_from(text: &str) -> Model {
    mecano::deck::parse_deck(text, "test.dat").expect("valid deck")
}

fn modes(model: &Model, about: About, count: usize) -> ModalAnalysis {
    analyse_model(model, about, count)
        .map_err(|f| f.message)
        .expect("modal analysis")
        .1
}

fn mecano(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .args(args)
        .output()
        .expect("binary runs")
}

/// The Timoshenko frequencies of the cantilever with a 1 kg tip mass (issue 24; the
/// frequency equation of `src/elements/beam_p_cases.rs`), Hz, given to 1e-5 Hz.
const TIMOSHENKO_HZ: [f64; 3] = [22.19447, 148.11007, 426.61513];
