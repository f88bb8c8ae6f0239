//! Located and bounded refusals (issue 35 §5): the modal analysis's refusals point at the
//! deck's `ANALYSIS MODES` card (or name the option that asked), a request the deck's
//! analysis cannot honour is refused rather than ignored, no message echoes an unbounded
//! part of its input, the expression nesting grammar.md states is accepted, messages name
//! a node or an element once, and `sweep` refuses what a run refuses, with exit code 2.

use crate::common;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_mecano-rs"));
    c.env_remove("MECANO_FAILPOINT");
    c
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn run(args: &[&str], paths: &[&Path]) -> Output {
    bin()
        .args(args)
        .args(paths)
        .output()
        .expect("the binary runs")
}

fn rotating(dir: &Path, name: &str, from: &str, to: &str) -> PathBuf {
    let src = fs::read_to_string(common::deck_path("rotating_cantilever.dat")).unwrap();
    assert!(src.contains(from), "{from}");
    let p = dir.join(name);
    fs::write(&p, src.replacen(from, to, 1)).unwrap();
    p
}

/// The line of `needle` in the file `p`, 1-based.
fn line_of(p: &Path, needle: &str) -> usize {
    fs::read_to_string(p)
        .unwrap()
        .lines()
        .position(|l| l.contains(needle))
        .expect("needle")
        + 1
}

#[test]
fn modal_refusals_point_at_the_deck_card_or_the_option() {
    let d = common::TempDir::new("refusals_modes");
    // A mode count of 2³² − 1 in the deck: at its ANALYSIS card, by a run and by modes.
    let big = rotating(
        &d,
        "big.dat",
        "ANALYSIS MODES 10 ROTATING",
        "ANALYSIS MODES 4294967295 ROTATING",
    );
    let line = line_of(&big, "ANALYSIS MODES 4294967295");
    for args in [vec!["-q", "-o"], vec!["modes", "-q", "-o"]] {
        let o = run(&args, &[&d.join("o1"), &big]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        assert!(
            text(&o).contains(&format!("big.dat:{line}:1: ANALYSIS MODES 4294967295")),
            "{}",
            text(&o)
        );
    }
    // The same count on the command line names --count.
    let o = run(
        &["modes", "-q", "--count", "4294967295", "-o"],
        &[&d.join("o2"), &common::deck_path("rotating_cantilever.dat")],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--count 4294967295"), "{}", text(&o));
    // No driven hinge on a deck asking for ROTATING: at its ANALYSIS card.
    let undriven = rotating(&d, "undriven.dat", "AXIS 0 0 1  DRIVE 1", "AXIS 0 0 1");
    let o = run(&["-q", "-o"], &[&d.join("o3"), &undriven]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let line = line_of(&undriven, "ANALYSIS MODES 10");
    assert!(
        text(&o).contains(&format!(
            "undriven.dat:{line}:1: ANALYSIS MODES … ROTATING: no driven HINGE"
        )),
        "{}",
        text(&o)
    );
    // A hub not grounded: at the hinge's card, naming the element once.
    let loose = rotating(&d, "loose.dat", "1  0 0 0  FIX ALL", "1  0 0 0");
    let o = run(&["-q", "-o"], &[&d.join("o4"), &loose]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let line = line_of(&loose, "HINGE 1 2");
    assert!(
        text(&o).contains(&format!("loose.dat:{line}:"))
            && text(&o).contains(": element 1: the driven hinge"),
        "{}",
        text(&o)
    );
    assert!(!text(&o).contains("element element"), "{}", text(&o));
    // --at (or --static) on a deck of ANALYSIS MODES … ROTATING: refused, not ignored.
    for opt in [vec!["--at", "0.1"], vec!["--static"]] {
        let mut args = vec!["modes", "-q"];
        args.extend(&opt);
        args.push("-o");
        let o = run(
            &args,
            &[&d.join("o5"), &common::deck_path("rotating_cantilever.dat")],
        );
        assert_eq!(o.status.code(), Some(2), "{opt:?}: {}", text(&o));
        assert!(
            text(&o).contains(opt[0]) && text(&o).contains("ROTATING"),
            "{}",
            text(&o)
        );
        assert!(!d.join("o5").exists(), "nothing written");
    }
    // A node held in the inertial frame besides the ground: named once.
    let held = rotating(&d, "held.dat", "3  1 0 0", "3  1 0 0  FIX X");
    let o = run(&["-q", "-o"], &[&d.join("o6"), &held]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("node 3 has fixed degrees"),
        "{}",
        text(&o)
    );
    assert!(!text(&o).contains("node node"), "{}", text(&o));
}

#[test]
fn echoes_of_the_command_line_are_bounded_and_100_levels_are_accepted() {
    let deck = common::deck_path("pendulum_sweep.dat");
    let nest = |k: usize| format!("E={}2.1e11{}", "(".repeat(k), ")".repeat(k));
    // 60,000 levels: refused, the message a few hundred bytes (it was 120 kB).
    let o = bin()
        .arg("--check")
        .arg(&deck)
        .arg("--set")
        .arg(nest(60_000))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).len() < 1000,
        "{} bytes: {}",
        text(&o).len(),
        text(&o)
    );
    assert!(text(&o).contains("nested too deeply"), "{}", text(&o));
    // grammar.md: 100 levels of parentheses; 101 refused.
    let o = bin()
        .arg("--check")
        .arg(&deck)
        .arg("--set")
        .arg(nest(100))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("E = 210000000000.0   (--set)"),
        "{}",
        text(&o)
    );
    let o = bin()
        .arg("--check")
        .arg(&deck)
        .arg("--set")
        .arg(nest(101))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    // Any other argument clap refuses: its echo is cut per line.
    let huge = "9".repeat(100_000);
    let o = bin()
        .args(["--check", "--refine", &huge])
        .arg(&deck)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).len() < 1000, "{} bytes", text(&o).len());
}

#[test]
fn sweep_refuses_an_unusable_output_path_and_zero_jobs_with_exit_2() {
    let d = common::TempDir::new("refusals_sweep");
    let plan = common::root().join("sweeps/pendulum_E.toml");
    let file = d.join("a_file");
    fs::write(&file, "x").unwrap();
    for out in [file.clone(), file.join("sub"), PathBuf::from("/dev/null")] {
        let o = bin()
            .arg("sweep")
            .arg(&plan)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{}: {}", out.display(), text(&o));
        assert!(text(&o).contains("not a directory"), "{}", text(&o));
    }
    assert_eq!(fs::read_to_string(&file).unwrap(), "x");
    let o = bin()
        .arg("sweep")
        .arg(&plan)
        .args(["--jobs", "0", "-o"])
        .arg(d.join("s"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!d.join("s").exists());
}
