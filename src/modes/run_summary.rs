//! What the step resolves, in every dynamic run's `summary.json` (issue 24 §5): the mesh's
//! highest frequency and, for the lowest elastic modes about the initial state, the
//! samples per period at the deck's step, HHT's numerical damping ratio and its period
//! error (the closed forms of [`super::hht`]; the table `--check` prints).
//!
//! Only when cheap, since a run did not ask for it: the dense solve is O(n³) (963 unknowns,
//! `decks/pendulum_converged_beams.dat`, took 13 s of CPU on the 2-core machine), so above
//! [`RUN_MAX_UNKNOWNS`] unknowns (≈ 0.4 s by that measurement) the block says "not
//! computed" and points to `mecano-rs modes`. The frequencies alone are computed
//! ([`super::Solver::DenseFrequencies`]): a model that moves at its start (the first-order
//! form) skips the eigenvectors, 2/3 of the solve — the flexible slider-crank of
//! `benches/peers/` (69 free unknowns) took 22 ms of a 93 ms run with them, 11 ms without. The block depends on the deck's model alone (no clock, no
//! run state): a resumed run writes the same one, so its summary stays the uninterrupted
//! run's (tests/restart.rs).

use super::about::{deck_step, lowest_about_initial};
use super::output::step_resolution;
use crate::model::Model;

/// Nodal unknowns above which a run's summary does not compute its modes (module docs);
/// `--check`, which the user asks for, goes to [`super::about::CHECK_MAX_UNKNOWNS`].
pub const RUN_MAX_UNKNOWNS: usize = 300;

/// Elastic modes the block reports (with the mesh's highest frequency).
pub const LOWEST_ELASTIC: usize = 5;

/// The `summary.json` key of the block.
pub const KEY: &str = "step_resolution";

/// The block for `model` of `unknowns` nodal unknowns (its system's, known to the run):
/// `None` when its analysis is not dynamic; otherwise the table (`modes`: one row per
/// elastic mode, lowest first, then the mesh's highest frequency), or
/// `{"computed": false, "reason": …}` when it is not cheap or cannot be computed.
pub fn block(model: &Model, unknowns: usize) -> Option<serde_json::Value> {
    let step = deck_step(model)?;
    let not_computed = |reason: String| {
        let reason = format!("not computed: {reason}");
        serde_json::json!({ "computed": false, "reason": reason })
    };
    if unknowns > RUN_MAX_UNKNOWNS {
        return Some(not_computed(format!(
            "{unknowns} unknowns > {RUN_MAX_UNKNOWNS} (a run's limit for the dense solve): use mecano-rs modes --count N"
        )));
    }
    let a = match lowest_about_initial(model, LOWEST_ELASTIC, false) {
        Ok(a) => a,
        Err(f) => return Some(not_computed(f.message)),
    };
    Some(serde_json::json!({
        "computed": true,
        "about": "the initial state (mecano-rs modes)",
        "integrator": step.scheme.name(),
        "alpha": step.scheme.hht_alpha(),
        "high_frequency_radius": step.scheme.rho_inf(),
        "step": step.h,
        "free_unknowns": a.free_unknowns,
        "rigid_modes": a.rigid_modes,
        "highest_frequency_hz": a.highest_hz,
        "modes": step_resolution(&a, step),
        "integrators": integrators(&a, step),
        "note": "one row per elastic mode, lowest first; last row: the mesh's highest frequency; period_error null = not resolved; integrators: the same rows for the deck's scheme, then HHT, generalized-alpha and ESDIRK3 (hht::compared_schemes; issue 26)",
    }))
}

/// The rows of [`step_resolution`] for the deck's scheme and each other one
/// ([`super::hht::compared_schemes`]): what each integrator does to each mode.
fn integrators(a: &super::ModalAnalysis, step: super::output::DeckStep) -> serde_json::Value {
    super::hht::compared_schemes(&step.scheme)
        .iter()
        .map(|s| {
            serde_json::json!({
                "integrator": s.label(),
                "modes": step_resolution(a, super::output::DeckStep { scheme: *s, h: step.h }),
            })
        })
        .collect()
}

/// The lines `mecano-rs study` prints beside its errors: for each step of its ladder, what
/// it resolves of the lowest elastic mode and of the mesh's highest frequency about the
/// initial state (with the deck's scheme), or why it is not computed (above
/// [`RUN_MAX_UNKNOWNS`], as the run's block).
pub fn study_lines(model: &Model, steps: &[f64], out: &mut dyn std::io::Write) {
    let Some(deck) = deck_step(model) else {
        return;
    };
    let Ok(integ) = crate::solver::prepare(model) else {
        return;
    };
    let Some(block) = block(model, integ.sys.n_node_eq) else {
        return;
    };
    if block["computed"] != true {
        let _ = writeln!(
            out,
            "what the steps resolve: {}",
            block["reason"].as_str().unwrap_or("not computed")
        );
        return;
    }
    let Ok(a) = lowest_about_initial(model, 1, false) else {
        return;
    };
    if a.highest_hz <= 0.0 {
        let _ = writeln!(
            out,
            "what the steps resolve: nothing ({} rigid modes, no elastic one, about the initial state)",
            a.rigid_modes
        );
        return;
    }
    let _ = writeln!(
        out,
        "what the steps resolve (modes about the initial state, {}; mecano-rs modes): samples per period, numerical damping ratio, period error",
        deck.scheme
    );
    for &h in steps {
        let rows = step_resolution(
            &a,
            super::output::DeckStep {
                scheme: deck.scheme,
                h,
            },
        );
        let cells: Vec<String> = rows
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let what = if i + 1 == rows.len() {
                    "highest"
                } else {
                    "lowest"
                };
                format!(
                    "{what} {:.4e} Hz: {:.3e}, {:.2e}, {}",
                    r.frequency_hz,
                    r.samples_per_period,
                    r.hht_damping,
                    r.period_error
                        .map_or("unresolved".into(), |e| format!("{e:.2e}"))
                )
            })
            .collect();
        let _ = writeln!(out, "  h = {h:.3e} s  {}", cells.join("; "));
    }
}
