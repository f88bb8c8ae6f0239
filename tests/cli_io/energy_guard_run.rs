//! The energy guard inside a run (issue 28, "the same hole on the seed's own scene"): the
//! pendulum of `decks/pendulum.dat`, run long, grazes the floor with node 23 near
//! t = 20.73 s (the contact switching on and off within each millisecond). Newton, started
//! from a poor guess there, met its tolerance on a wrong root holding ~1e5 J where the step
//! started with 179 J and the loads did no work; the run accepted it, wrote the row (2.0e11 J
//! of kinetic energy a few steps later) and failed at 20.7315 s. With the guard
//! (`src/solver/energy_guard.rs`) such a root is refused, the step is cut, and the run goes
//! on (`docs/stability.md`, "An energy jump in a grazing contact").
//!
//! To keep the test cheap it does not run the 20.6 s: `tests/data/grazing/` holds the
//! output directory of `decks/pendulum_grazing.dat` (the pendulum deck to 20.8 s, node 23
//! every 0.1 s) stopped by SIGINT, with its checkpoint; the test resumes it through the
//! contacts of node 23 to 20.8 s (a few seconds of CPU). Since issue 35 the
//! steps' return to their grid changed the chaotic path: the floor is met at 20.628 s
//! rather than grazed at 20.73 s; since issue 37's co-rotated kept matrix the last contacts
//! are before 20.4 s and the data stops at 20.03 s, so that the resumed 0.77 s hold two
//! contact events and two refused steps. The test's claim is unchanged. How the data was made,
//! and how to make it again after a change of the checkpoint format or of the solver:
//! `tests/data/grazing/README.md`.
//!
//! What fails without the guard: the resumed run exits 1 at 20.7315 s (measured with the
//! code before the guard, `docs/stability.md`), so `complete` is never reached.

use crate::common;

use common::TempDir;
use std::path::Path;
use std::process::Command;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let name = e.file_name();
        if name == "README.md" {
            continue;
        }
        std::fs::copy(e.path(), to.join(&name)).unwrap();
    }
}

/// The largest of the columns `kinetic`, `strain` over the rows of `energy.csv`, J.
fn largest_energy(dir: &Path) -> f64 {
    let text = std::fs::read_to_string(dir.join("energy.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let cols: Vec<usize> = ["kinetic", "strain"]
        .iter()
        .map(|c| {
            header
                .iter()
                .position(|h| h == c)
                .unwrap_or_else(|| panic!("energy.csv has no column {c}: {header:?}"))
        })
        .collect();
    let mut worst = 0.0f64;
    for l in lines {
        let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        for &c in &cols {
            assert!(f[c].is_finite(), "a non-finite energy in {l}");
            worst = worst.max(f[c].abs());
        }
    }
    worst
}

#[test]
fn the_grazing_contact_at_20_73_s_is_crossed_without_an_energy_jump() {
    let root = common::root();
    let data = root.join("tests/data/grazing");
    let d = TempDir::new("energy_guard_run");
    let out = d.join("out");
    copy_dir(&data, &out);
    let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .args(["resume", out.to_str().unwrap(), "-q", "--checkpoint", "0"])
        .arg("--deck")
        .arg(root.join("decks/pendulum_grazing.dat"))
        .env_remove("MECANO_FAILPOINT")
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(o.status.code(), Some(0), "{text}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        summary["complete"],
        serde_json::Value::Bool(true),
        "{summary}"
    );
    // The resumed window must cross contact events (restarts), or the data no longer
    // tests what it is kept for: remake it (`tests/data/grazing/README.md`).
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data.join("summary.json")).unwrap()).unwrap();
    let restarts = |s: &serde_json::Value| s["stats"]["restarts"].as_u64().unwrap();
    assert!(
        restarts(&summary) > restarts(&stored),
        "no contact event in the resumed window: {summary}"
    );
    // The scene holds ~180 J after the first second (docs/stability.md: 179 J at the
    // start of the refused step); a bound of 1e4 J is far above any state the pendulum
    // reaches with the loads it has (the torque pulse of t < 0.2 s puts in ~200 J), and
    // five orders of magnitude below the accepted wrong roots (1e5 J, then 2e11 J).
    let worst = largest_energy(&out);
    assert!(
        worst < 1e4,
        "an energy of {worst:e} J was written: the guard let a jump through"
    );
}

/// The fuzzer's energy cases (issue 35 §0, `tests/deck/energy/README.md`): each
/// either completes without a burst or stops with the guard's diagnosis, its histories kept
/// and marked incomplete. "Without a burst" is the guard's ceiling, at most
/// `(g + ROTATION_RESOLVED² + QUADRATURE_SHARE) max E_osc` plus this step's Newton term and
/// the round-off: `g` ≤ 0.222 for the schemes of these decks (HHT α = −0.1, the largest of
/// the α family's `g`, `energy_guard::bound`), ¼ from the rotation term's cap, 1/12 the
/// trapezoid's over a run of steps; a complete run whose largest rise exceeds that share of
/// the largest `T + |U|` it wrote has let a burst through. Before the fixes the first five
/// completed with rises of 4.1e4 … 1.5e17 J, as large as the energies they wrote (the
/// bounds had grown with the bursts), and the ten of 2026-11-28 with rises up to 1.2e6 J
/// under bounds summed from brackets of 1e6 W powers or 1.5e5 steps' Newton terms. A
/// complete run whose balance closes to worse than a tenth says so (`coarse_balance`), as
/// does one that kept steps at the smallest step above the ceiling (within the summed
/// bound: `energy_guard`, "At the smallest step"); the rise is then the summed bound's,
/// and the share above is not asserted of it.
#[test]
fn the_fuzzers_energy_cases_end_clean_or_stop() {
    let dir = common::root().join("tests/deck/energy");
    let mut decks: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dat"))
        .collect();
    decks.sort();
    assert_eq!(decks.len(), 18, "{decks:?}");
    for deck in decks {
        let tmp = TempDir::new("energy_cases");
        let out = tmp.join("out");
        let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
            .arg(&deck)
            .args(["-q", "--checkpoint", "0", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let name = deck.file_name().unwrap().to_string_lossy();
        match o.status.code() {
            Some(0) => {
                assert_eq!(s["complete"], true, "{name}: {s}");
                // The guard's ceiling: g E_osc(s) (g ≤ 0.222 for the decks' schemes), the
                // rotation's ¼ T and the trapezoid's 1/12 of the largest E_osc, each of the
                // largest kinetic + |strain| energy at most (plus Newton's and round-off's
                // terms, orders below).
                let share = 0.222 + 0.25 + 1.0 / 12.0;
                let created = s["energy"]["largest_created_j"].as_f64().unwrap();
                let kept = s["energy"]["unverified_steps"].as_u64().unwrap() > 0;
                // The largest T + |U| of the run's steps (the rows of energy.csv may miss
                // a driven pulse between them: 11_4398's 169 J fall between its rows).
                let play = s["energy"]["largest_oscillation_j"].as_f64().unwrap();
                assert!(play >= largest_oscillation(&out), "{name}: {s}");
                assert!(
                    kept || created <= share * play,
                    "{name}: {created:e} J created with at most {play:e} J in play"
                );
                // The same bound read by summary.json's figure, relative to the run's scale
                // (11_2201 read 1.49 when each row's residual was made relative to the scale
                // reached at that row: the round-off of a start from 1e-26 J).
                let relative = s["energy"]["max_balance_error"].as_f64().unwrap();
                assert!(
                    kept || relative <= share,
                    "{name}: max_balance_error {relative}"
                );
                // A balance that closes to worse than a tenth is said (11_5355: 0.33), and
                // so are steps kept at the smallest step above the ceiling (11_3276: one).
                let unverified = s["energy"]["unverified_steps"].as_u64().unwrap();
                let warned = stderr.contains("energy balance closes to")
                    && s["notices"]
                        .as_array()
                        .is_some_and(|n| n.iter().any(|n| n["kind"] == "coarse_balance"));
                let expected = relative > 0.1 || unverified > 0;
                assert_eq!(warned, expected, "{name}: {relative}: {stderr}");
                assert_eq!(
                    stderr.contains("at the smallest step (MINSTEP)"),
                    unverified > 0,
                    "{name}: {stderr}"
                );
            }
            Some(1) => {
                assert_eq!(s["complete"], false, "{name}: {s}");
                assert!(stderr.contains("that no work paid for"), "{name}: {stderr}");
            }
            c => panic!("{name}: exit {c:?}: {stderr}"),
        }
    }
}

/// The largest `kinetic + |strain|` over the rows of `energy.csv`, J.
fn largest_oscillation(dir: &Path) -> f64 {
    let text = std::fs::read_to_string(dir.join("energy.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |c: &str| header.iter().position(|h| *h == c).unwrap();
    let (k, u) = (col("kinetic"), col("strain"));
    lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            f[k] + f[u].abs()
        })
        .fold(0.0, f64::max)
}

/// A fixed component has no velocity (the fuzz case 7_2002 gave `INITIAL V` to a node
/// `FIX TRANS`: the fixed components kept it in the energies, never in the positions, and
/// the first step created 0.178 J at every step size). A mass of 2 kg on a spring along y,
/// fixed along x and z, given V = (3, 4, 0): the start zeroes vx with the projection's
/// warning, so the kinetic energy written at t = 0 is ½·2·4² = 16 J (25 J before), and the
/// trapezoidal rule (α = 0) keeps the total energy of this linear oscillator to round-off.
#[test]
fn a_velocity_along_a_fixed_component_is_zeroed_with_a_warning() {
    let tmp = TempDir::new("fixed_velocity");
    let deck = tmp.join("fixed_velocity.dat");
    std::fs::write(
        &deck,
        "TITLE a node fixed along x given a velocity along x\n\
         NODES\n  1 0 0 0 FIX ALL\n  2 0 1 0 FIX X Z RX RY RZ\n\
         ELEMENTS\n  1 SPRING 1 2 K 200 L0 1\n  2 MASS 2 M 2\n\
         INITIAL\n  2 V 3 4 0\n\
         ANALYSIS DYNAMIC ALPHA 0 STEP 1e-3 END 0.5\n",
    )
    .unwrap();
    let out = tmp.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .args(["--checkpoint", "0", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("constraints and fixities"), "{stderr}");
    let text = std::fs::read_to_string(out.join("energy.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |c: &str| header.iter().position(|h| *h == c).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let (k, total) = (col("kinetic"), col("total"));
    assert!((rows[0][k] - 16.0).abs() < 1e-12, "{:?}", rows[0]);
    for r in &rows {
        assert!((r[total] - 16.0).abs() < 1e-9 * 16.0, "{r:?}");
    }
}
