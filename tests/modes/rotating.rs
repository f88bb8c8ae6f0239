//! Rotating structures: the rotating cantilever against the Euler–Bernoulli table, the
//! rotating frame's bad input and command line, the gyroscopic heavy top.

use super::*;

/// The rotating Euler–Bernoulli cantilever clamped on the axis (hub radius 0): flapwise
/// frequencies `ω·√(mL⁴/EI)` at `ν = Ω·√(mL⁴/EI) = 0, 1, …, 12` (issue 24; the
/// rotating-beam literature, e.g. Wright et al., J. Appl. Mech. 49 (1982); confirmed to
/// 1e-6 by /work/shared/design/benchmarks.md at ν = 1 and 4), given to four decimals.
const ROTATING_FLAP: [[f64; 13]; 2] = [
    [
        3.5160, 3.6816, 4.1373, 4.7973, 5.5850, 6.4495, 7.3604, 8.2996, 9.2568, 10.2257, 11.2023,
        12.1843, 13.1702,
    ],
    [
        22.0345, 22.1810, 22.6149, 23.3203, 24.2733, 25.4461, 26.8091, 28.3341, 29.9954, 31.7705,
        33.6404, 35.5890, 37.6031,
    ],
];

/// The modes of `decks/rotating_cantilever.dat` at hub speed `nu` (dimensionless: L = EI =
/// ρA = 1), seen in the rotating frame: the angular frequencies (Im s) of the flapwise
/// (out-of-plane, Z) and lead-lag (in-plane) modes, each sorted.
fn rotating_cantilever(nu: f64) -> (Vec<f64>, Vec<f64>) {
    let model = load(
        &deck("rotating_cantilever.dat"),
        &[("OMEGA".to_string(), nu)],
        1,
        None,
    )
    .unwrap();
    let (integ, a) = analyse_model(&model, About::Rotating, 10)
        .map_err(|f| f.message)
        .expect("modal analysis");
    let (mut flap, mut lag) = (Vec::new(), Vec::new());
    for m in &a.modes {
        assert_eq!(m.kind, ModeKind::Elastic, "ν = {nu}: {m:?}");
        // Conservative gyroscopic system: purely imaginary eigenvalues.
        assert!(
            m.damping_ratio.abs() < 1e-8,
            "ν = {nu}: ζ = {}",
            m.damping_ratio
        );
        let (mut z, mut inplane) = (0.0, 0.0);
        for d in &integ.sys.node_dofs {
            let v = |k: usize| {
                if d[k] == mecano::solver::system::FIXED {
                    0.0
                } else {
                    m.shape[d[k]].powi(2)
                }
            };
            z += v(2);
            inplane += v(0) + v(1);
        }
        let w = m.eigenvalue.1;
        if z > inplane {
            flap.push(w)
        } else {
            lag.push(w)
        }
    }
    flap.sort_by(f64::total_cmp);
    lag.sort_by(f64::total_cmp);
    (flap, lag)
}

/// Centrifugal stiffening (issue 24 target): the geometrically exact beam of
/// `decks/rotating_cantilever.dat`, linearised about its relative equilibrium in the frame
/// of the hub (`About::Rotating`), against the Euler–Bernoulli table: 1e-3 relative on all
/// 26 values (the requirement). What separates the two models, each bound far below
/// it (docs/modes.md, "Rotating structures"):
/// - the table's four decimals: 0.5e-4/3.5160 = 1.4e-5 relative at most;
/// - shear and rotary inertia (EI/(GA L²) = 1e-5, ρI/(ρA L²) = 1e-6): the Timoshenko
///   softening ½(βL)²(EI/(GA L²) + ρI/(ρA L²)) ≈ 2e-5 (mode 1), 1.2e-4 (mode 2) —
///   measured at ν = 0 (symmetric path): −2.6e-5, −1.8e-4;
/// - axial stretch ρAΩ²L²/EA ≤ 1.4e-5 at ν = 12;
/// - the mesh, one beam of order 10, and the eigen-solve's round-off: at ν = 0 orders 10,
///   12 and 14 agree to ≤ 5e-11, at ν = 12 to 3e-8 (flapwise), 7e-7 (lead-lag).
///
/// Their sum, < 3e-4, leaves the 1e-3 a margin of three. Second check, independent of the
/// table: with EI2 = EI3 the lead-lag (in-plane) frequencies of the inextensible
/// Euler–Bernoulli beam are `ω_lag² = ω_flap² − Ω²` (the in-plane equation is the
/// flapwise one plus the centrifugal softening −mΩ²v of the rotating frame). The exact
/// beam departs from it by the Coriolis coupling of the lag motion to the axial one,
/// ≈ (2Ωω)²/ω²_axial in ω² (ω_axial = (π/2)√(EA/ρA)/L ≈ 5e3): ≤ 2.5e-5 relative in ω at
/// ν = 12; the shear and rotary-inertia errors are common to both and cancel to first
/// order. Held to 1e-4.
#[test]
fn rotating_cantilever_flapwise_frequencies_match_the_euler_bernoulli_table() {
    let (mut worst, mut worst_lag): (f64, f64) = (0.0, 0.0);
    for (i, nu) in (0..13).map(|i| (i, i as f64)) {
        let (flap, lag) = rotating_cantilever(nu);
        assert!(
            flap.len() >= 2 && lag.len() >= 2,
            "ν = {nu}: {flap:?} {lag:?}"
        );
        for k in 0..2 {
            let e = (flap[k] - ROTATING_FLAP[k][i]) / ROTATING_FLAP[k][i];
            let pred = (flap[k] * flap[k] - nu * nu).sqrt();
            let el = (lag[k] - pred) / pred;
            eprintln!(
                "nu {nu:2} flap {} {:9.6} table {:7.4} rel {e:+.2e}   lag {:9.6} sqrt(flap^2-nu^2) {pred:9.6} rel {el:+.2e}",
                k + 1,
                flap[k],
                ROTATING_FLAP[k][i],
                lag[k]
            );
            worst = worst.max(e.abs());
            worst_lag = worst_lag.max(el.abs());
        }
    }
    eprintln!("worst relative error: flapwise {worst:.2e}, lead-lag relation {worst_lag:.2e}");
    assert!(worst <= 1e-3, "{worst}");
    assert!(worst_lag <= 1e-4, "{worst_lag}");
}

/// `--rotating` needs one grounded driven hinge at constant speed: otherwise a located
/// error, exit 2, nothing written.
#[test]
fn rotating_without_a_steady_driven_hinge_is_bad_input() {
    let base = common::TempDir::new("modes_rotating_bad");
    let _ = std::fs::remove_dir_all(&base);
    let o = base.join("out");
    // No driven hinge.
    let cant = deck("cantilever_modes.dat");
    let out = mecano(&[
        "modes",
        cant.to_str().unwrap(),
        "--rotating",
        "-o",
        o.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no driven HINGE"), "{err}");
    assert!(!o.exists());
    // A driver accelerating at t = 0 (θ = t²/2): the error names the DRIVE's line.
    let text = std::fs::read_to_string(deck("rotating_cantilever.dat"))
        .unwrap()
        .replace("$OMEGA*t", "0.5*t^2");
    let line = 1 + text.lines().position(|l| l.contains("DRIVE 1")).unwrap();
    std::fs::create_dir_all(&base).unwrap();
    let p = base.join("accelerating.dat");
    std::fs::write(&p, &text).unwrap();
    let out = mecano(&["modes", p.to_str().unwrap(), "-o", o.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("accelerating.dat:{line}:")) && err.contains("not constant"),
        "{err}"
    );
    assert!(!o.exists());
    let _ = std::fs::remove_dir_all(&base);
}

/// The rotating deck through the command line: `mecano-rs modes --set OMEGA=4` states the
/// frame in summary.json, and running the deck itself (`ANALYSIS MODES 10 ROTATING`) writes
/// the same modes.csv, byte for byte.
#[test]
fn rotating_deck_through_the_cli_states_its_frame() {
    let base = common::TempDir::new("modes_rotating_cli");
    let _ = std::fs::remove_dir_all(&base);
    let d = deck("rotating_cantilever.dat");
    let (a, b) = (base.join("modes"), base.join("run"));
    let d = d.to_str().unwrap();
    let out = mecano(&[
        "modes",
        d,
        "--set",
        "OMEGA=4",
        "-q",
        "-o",
        a.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = mecano(&[d, "--set", "OMEGA=4", "-o", b.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(a.join("modes.csv")).unwrap();
    assert_eq!(csv, std::fs::read_to_string(b.join("modes.csv")).unwrap());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["frame"]["kind"], "rotating");
    assert_eq!(summary["frame"]["speed_rad_s"], 4.0);
    assert_eq!(summary["frame"]["axis"], serde_json::json!([0.0, 0.0, 1.0]));
    // Mode 2 (the first flapwise; mode 1 is lead-lag) against the table at ν = 4, with
    // the library test's 1e-3.
    let f2: f64 = csv
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .nth(3)
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (2.0 * PI * f2 - ROTATING_FLAP[0][4]).abs() <= 1e-3 * ROTATING_FLAP[0][4],
        "{f2}"
    );
    let _ = std::fs::remove_dir_all(&base);
}

/// Review of the modes command (round-off signs): the heavy top spinning about its
/// initial state is gyroscopic (state-space solve); its precession-like mode's computed
/// `Re s` was −9e-15 1/s (ζ = −1.9e-15), far below the solver's round-off
/// `10 ε ‖A‖ (1 + |s|²)/(2|s|)` ≈ 8e-13 1/s (src/modes/mod.rs): it is neither damped nor
/// unstable, and its damping ratio is +0 (not −0).
#[test]
fn heavy_top_has_no_round_off_unstable_mode() {
    let model = load(&deck("heavy_top.dat"), &[], 1, None).unwrap();
    let a = modes(&model, About::Initial, 3);
    let z: Vec<(ModeKind, f64, f64)> = a
        .modes
        .iter()
        .map(|m| (m.kind, m.natural_hz, m.damping_ratio))
        .collect();
    eprintln!("heavy top: {z:?}");
    assert!(
        a.modes.iter().all(|m| m.kind != ModeKind::Unstable),
        "{z:?}"
    );
    assert!(a.modes.iter().any(|m| m.kind == ModeKind::Elastic), "{z:?}");
    for m in &a.modes {
        assert!(
            m.damping_ratio == 0.0 && m.damping_ratio.is_sign_positive(),
            "{z:?}"
        );
    }
}
