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
//! every 0.1 s) stopped by SIGINT at t = 20.62 s, with its checkpoint; the test resumes it
//! through the contacts of node 23 to 20.8 s (about a second of CPU). Since issue 35 the
//! steps' return to their grid changed the chaotic path: the floor is met at 20.628 s
//! rather than grazed at 20.73 s; the test's claim is unchanged. How the data was made,
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

/// A run the guard cannot check says so (issue 35 §0, never silent): the fuzz case
/// `benches/fuzz/open/7_2002.dat` (HHT α = 0, `TOLINC 4.6e-5` on beams of EA 4e8 N) passes
/// its first step only by the allowance for Newton's tolerance, 79 J (`c_v τ (…) +
/// τ L n f_ref`), with 63 J in play; its strain energy then grows from 12.7 J to 4.13e4 J
/// with no work. The run still completes (the guard's bound is not met by a tighter one
/// yet: benches/fuzz/open/README.md), but it prints the warning and lists the notice in
/// `summary.json` with the step's time, the allowance and the energy in play, so that the
/// number is not read as checked. Without the notice the test fails on both asserts.
#[test]
fn a_run_whose_newton_tolerance_voids_the_guard_says_so() {
    let tmp = TempDir::new("energy_unchecked");
    let out = tmp.join("out");
    let deck = common::root().join("benches/fuzz/open/7_2002.dat");
    let o = Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&deck)
        .args(["-q", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("the energy guard could not check the run"),
        "{stderr}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let notice = s["notices"]
        .as_array()
        .and_then(|a| a.iter().find(|n| n["kind"] == "energy_unchecked"))
        .unwrap_or_else(|| panic!("no energy_unchecked notice: {s}"));
    let (allowance, play) = (
        notice["allowance"].as_f64().unwrap(),
        notice["play"].as_f64().unwrap(),
    );
    assert!(allowance > play && play > 0.0, "{notice}");
}
