//! Robust input beyond the parser: whatever a mutated deck parses to, building the solver's
//! system from it (`solver::prepare`: elements, dof numbering, sparsity pattern, symbolic
//! LU) and computing the initial accelerations never panics — it succeeds or returns an
//! error (issue: hard cases stay numerically stable, item 3).

use crate::common;

use mecano::deck::parse_deck;
use mecano::solver;
use proptest::prelude::*;

const NUMBERS: &[&str] = &[
    "0", "-1", "1e-12", "1e12", "2", "0.5", "-0.5", "1e300", "13", "24", "7",
];

/// The decks mutated; a missing one fails the test (it was silently dropped).
fn decks() -> Vec<String> {
    [
        "pendulum.dat",
        "double_pendulum_rigid.dat",
        "cam_follower.dat",
        "heavy_top.dat",
    ]
    .iter()
    .map(|d| std::fs::read_to_string(common::deck_path(d)).expect("read"))
    .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Replace one to three numeric tokens of a real deck by extreme or off-by-one values.
    #[test]
    fn building_the_system_never_panics(
        which in 0usize..4,
        edits in proptest::collection::vec((0usize..10_000, 0usize..11), 1..4),
    ) {
        let all = decks();
        let text = &all[which % all.len()];
        let mut tokens: Vec<String> = text.split(' ').map(str::to_string).collect();
        let numeric: Vec<usize> = tokens
            .iter()
            .enumerate()
            .filter(|(_, t)| t.trim().parse::<f64>().is_ok())
            .map(|(i, _)| i)
            .collect();
        for (pos, val) in edits {
            let i = numeric[pos % numeric.len()];
            tokens[i] = NUMBERS[val].to_string();
        }
        let deck = tokens.join(" ");
        if let Ok(mut model) = parse_deck(&deck, "mutated") {
            // Keep the run short; only the building and the initial state are exercised.
            if let mecano::model::Analysis::Dynamic { end, step, .. } = &mut model.analysis {
                *end = *step;
            }
            if let Ok(mut integ) = solver::prepare(&model) {
                let _ = integ.initialize();
            }
        }
    }
}
