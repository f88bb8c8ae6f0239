//! The solve's paths agree: the frequencies alone (a run's summary, `--check`) equal those
//! of the solve with shapes.

use super::*;

/// The frequencies alone (a run's summary, `--check`: `lowest_about_initial`) skip the
/// first-order form's eigenvectors; they must be the frequencies, rigid-mode count and
/// highest frequency of the solve with shapes (`mecano-rs modes`), on models that move or
/// are damped at their initial state (the first-order form) and on conservative ones.
#[test]
fn frequencies_alone_equal_the_solve_with_shapes() {
    use mecano::modes::Method;
    let (mut first_order, mut skipped, mut fell_back) = (0, 0, 0);
    for name in [
        "heavy_top.dat",
        "spinning_beam.dat",
        "flywheel.dat",
        "pd_flexible_arm.dat",
        "benchmarks/slider_crank_clearance.dat",
        "tumbling_beam.dat",
        "flying_beam.dat",
        "rotating_cantilever.dat",
        "pendulum_launched.dat",
        "cantilever_modes.dat",
        "spherical_pendulum_modes.dat",
    ] {
        let model = model_from(&std::fs::read_to_string(deck(name)).unwrap());
        let alone = mecano::modes::about::lowest_about_initial(&model, 5, false)
            .unwrap_or_else(|f| panic!("{name}: {}", f.message));
        let n = alone.modes.len();
        let full = modes(&model, About::Initial, n);
        if full.method == Method::StateSpace {
            first_order += 1;
        }
        assert_eq!(alone.method, full.method, "{name}");
        assert_eq!(alone.rigid_modes, full.rigid_modes, "{name}");
        assert_eq!(alone.highest_hz, full.highest_hz, "{name}");
        for (a, f) in alone.modes.iter().zip(&full.modes) {
            // The same Francis QR steps on the same Hessenberg matrix: the same numbers.
            assert_eq!(a.eigenvalue, f.eigenvalue, "{name}");
            assert_eq!(a.kind, f.kind, "{name}");
        }
        // The eigenvectors skipped (no mode needed its own to be classified), or computed
        // because one did (a light direction's round-off: the tumbling beam's rigid modes).
        if alone.method == Method::StateSpace {
            if alone.modes.iter().all(|m| m.shape.is_empty()) {
                skipped += 1;
            } else {
                fell_back += 1;
            }
        }
    }
    assert!(
        first_order >= 3,
        "{first_order} decks in the first-order form"
    );
    assert!(skipped >= 2, "{skipped} decks solved without eigenvectors");
    assert!(fell_back >= 1, "{fell_back} decks solved again with them");
}
