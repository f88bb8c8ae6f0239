//! `mecano-rs plot`: the three figures from a short real run, and clear errors (exit 2).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_mecano-rs");

/// A two-bar pendulum of beams, 0.05 s, every node written.
const DECK: &str = "TITLE plot test pendulum
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8
NODES
  1 0 0 0 FIX ALL
  2 TO 4 LINE 0 0 0  1 0 0
ELEMENTS
  1 HINGE 1 2 AXIS 0 0 1
  2 TO 3 BEAM 2 3 MAT 1 SEC 1
  4 MASS 4 M 1
LOADS
  GRAVITY 0 -9.81 0
ANALYSIS DYNAMIC ALPHA -0.1 STEP 1e-3 END 0.05
OUTPUT NODES ALL ELEMENTS NONE
END
";

/// A scratch directory removed when the test ends, also when it fails.
fn scratch(name: &str) -> common::TempDir {
    common::TempDir::new(&format!("plot-{name}"))
}

fn run_deck(dir: &Path) -> PathBuf {
    let deck = dir.join("deck.dat");
    std::fs::write(&deck, DECK).unwrap();
    let out = dir.join("out");
    let st = Command::new(BIN)
        .arg(&deck)
        .arg("-o")
        .arg(&out)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(st.success(), "the run failed");
    out
}

fn plot(args: &[&str]) -> (i32, String) {
    let o = Command::new(BIN).arg("plot").args(args).output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn figures_are_written_and_errors_are_clear() {
    let dir = scratch("figs");
    let out = run_deck(&dir);
    let o = out.to_str().unwrap();
    let f = |n: &str| dir.join(n).to_str().unwrap().to_string();

    let (code, err) = plot(&[
        "trajectory",
        o,
        o,
        "--nodes",
        "3",
        "4",
        "--labels",
        "a,b",
        "-o",
        &f("t.svg"),
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(f("t.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("X (m)") && svg.contains("a, node 4"));

    let (code, err) = plot(&[
        "history",
        o,
        "--node",
        "4",
        "--columns",
        "rz,vy,ay",
        "-o",
        &f("h.png"),
    ]);
    assert_eq!(code, 0, "{err}");
    let png = std::fs::read(f("h.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");

    let (code, err) = plot(&[
        "history",
        o,
        "--node",
        "4",
        "--columns",
        "vy",
        "-o",
        &f("h.svg"),
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(f("h.svg")).unwrap();
    assert!(svg.contains("velocity Y (m/s)") && svg.contains("t: time (s)"));

    // The deck is found through summary.json (an absolute path here).
    let (code, err) = plot(&["animate", o, "--frames", "5", "-o", &f("a.gif")]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(&std::fs::read(f("a.gif")).unwrap()[..3], b"GIF");

    // Errors: exit code 2, a message naming what is missing, no panic.
    let (code, err) = plot(&[
        "history",
        &f("nope"),
        "--node",
        "4",
        "--columns",
        "vy",
        "-o",
        &f("x.svg"),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("no such output directory"), "{err}");
    let (code, err) = plot(&[
        "history",
        o,
        "--node",
        "4",
        "--columns",
        "vq",
        "-o",
        &f("x.svg"),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("no column \"vq\""), "{err}");
    let (code, err) = plot(&["trajectory", o, "--nodes", "9", "-o", &f("x.svg")]);
    assert_eq!(code, 2);
    assert!(
        err.contains("node_9.csv") && !err.contains("panicked"),
        "{err}"
    );
    let (code, _) = plot(&[
        "history",
        o,
        "--node",
        "4",
        "--columns",
        "vy",
        "-o",
        &f("x.pdf"),
    ]);
    assert_eq!(code, 2);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn running_a_deck_still_works_without_subcommand() {
    let o = Command::new(BIN)
        .args(["--check", "decks/simple_pendulum.dat"])
        .output()
        .unwrap();
    assert!(o.status.success());
}

/// The points of each `<polyline>` of an SVG, as (x, y) pixels.
fn polylines(svg: &str) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|p| {
            let i = p.find("points=\"")? + 8;
            let j = p[i..].find('"')?;
            Some(
                p[i..i + j]
                    .split_whitespace()
                    .filter_map(|xy| {
                        let (x, y) = xy.split_once(',')?;
                        Some((x.parse().ok()?, y.parse().ok()?))
                    })
                    .collect(),
            )
        })
        .collect()
}

/// `plot history --element` (issue 34 §8): an element's columns drawn against time — the
/// clearance joint's normal force in decks/clearance_impact.dat, beside the journal's
/// velocity (node 2): two panels, each holding one series of as many points as the file
/// has rows, the force's not flat (the impact); an element not written and a column the
/// element does not have are located errors (exit 2).
#[test]
fn history_draws_an_elements_columns() {
    let dir = scratch("element");
    let out = dir.join("out");
    let st = Command::new(BIN)
        .arg(common::deck_path("clearance_impact.dat"))
        .arg("-o")
        .arg(&out)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(st.success());
    let o = out.to_str().unwrap();
    let rows = std::fs::read_to_string(out.join("element_1.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    let svg_path = dir.join("h.svg");
    let (code, err) = plot(&[
        "history",
        o,
        "--node",
        "2",
        "--columns",
        "vx",
        "--element",
        "1",
        "--element-columns",
        "normal_force",
        "-o",
        svg_path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.contains("element 1") && svg.contains("normal_force") && svg.contains("node 2"));
    let series: Vec<_> = polylines(&svg)
        .into_iter()
        .filter(|p| p.len() == rows)
        .collect();
    assert_eq!(
        series.len(),
        2,
        "{rows} rows: no two series of that many points"
    );
    let (lo, hi) = series[1]
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    assert!(hi - lo > 10.0, "the force's series is flat: {lo}..{hi} px");
    // The element's columns alone (--columns serves when --element-columns is not given).
    let png = dir.join("f.png");
    let (code, err) = plot(&[
        "history",
        o,
        "--element",
        "1",
        "--columns",
        "normal_force,penetration",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    // Errors.
    let x = dir.join("x.svg");
    let x = x.to_str().unwrap();
    let (code, err) = plot(&[
        "history",
        o,
        "--element",
        "7",
        "--columns",
        "normal_force",
        "-o",
        x,
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("element_7.csv") && err.contains("OUTPUT ELEMENTS"),
        "{err}"
    );
    let (code, err) = plot(&[
        "history",
        o,
        "--element",
        "1",
        "--columns",
        "torque",
        "-o",
        x,
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("no column \"torque\"") && err.contains("normal_force"),
        "{err}"
    );
}
