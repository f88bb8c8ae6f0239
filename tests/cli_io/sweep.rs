//! `mecano-rs sweep` and deck parameters through the real binary: a 6-case plan of a
//! bouncing mass (a few ms of CPU per case) against the Kelvin–Voigt closed form, reruns
//! that skip finished cases and restart interrupted ones, failed cases recorded, random
//! plans, a 10,000-case plan listed and emitted without running, and bad input (exit 2).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_mecano-rs");

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("sweep_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("tmp dir");
    d
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .current_dir(root())
        .output()
        .expect("binary runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// sweep.csv as rows of cells (header first).
fn rows(dir: &Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(dir.join("sweep.csv")).expect("sweep.csv");
    let mut out = vec![
        r.headers()
            .expect("header")
            .iter()
            .map(String::from)
            .collect(),
    ];
    for rec in r.records() {
        out.push(rec.expect("row").iter().map(String::from).collect());
    }
    out
}

fn col(rows: &[Vec<String>], name: &str) -> usize {
    rows[0]
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

fn num(rows: &[Vec<String>], i: usize, name: &str) -> f64 {
    rows[i + 1][col(rows, name)].parse().expect("a number")
}

/// Kelvin–Voigt impact of a mass m at speed v (no gravity): restitution
/// e = exp(−ζπ/√(1−ζ²)) and largest penetration (v/ω) exp(−ζ/√(1−ζ²) atan(√(1−ζ²)/ζ)).
fn closed_form(k: f64, zeta: f64, v: f64) -> (f64, f64) {
    let w = k.sqrt();
    let s = (1.0 - zeta * zeta).sqrt();
    let e = (-zeta * std::f64::consts::PI / s).exp();
    let xmax = v / w * (-zeta / s * (s / zeta).atan()).exp();
    (e * v, xmax)
}

#[test]
fn a_local_sweep_matches_the_closed_form_and_reruns_skip_finished_cases() {
    let out = tmp("local");
    let o = out.to_str().expect("utf-8");
    let r = run(&["sweep", "sweeps/bounce.toml", "-o", o, "--jobs", "2"]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let t = rows(&out);
    assert_eq!(t.len(), 7, "6 cases");
    assert_eq!(
        t[0],
        [
            "case",
            "k",
            "zeta",
            "status",
            "steps",
            "rebound_speed",
            "max_penetration",
            "t_contact",
            "impacts",
            "cpu",
            "cpu_s",
            "diagnosis"
        ]
    );
    for i in 0..6 {
        assert_eq!(t[i + 1][col(&t, "status")], "ok");
        assert_eq!(num(&t, i, "impacts"), 1.0);
        // The gap is 1 mm at 1 m/s: first contact at 1 ms (landed on the event).
        assert!(
            (num(&t, i, "t_contact") - 1e-3).abs() < 1e-9,
            "{}",
            num(&t, i, "t_contact")
        );
    }
    // k = 1e7 (cases 4, 5): the contact (≈1 ms) ends well before 8 ms. With 20 steps per
    // impact at α = 0, the trapezoidal rule's period error (ωh)²/12 ≈ 2e-3 bounds the
    // error of the rebound speed and penetration: tolerance 5e-3 relative.
    for (i, zeta) in [(4, 0.05), (5, 0.2)] {
        let (v, x) = closed_form(1e7, zeta, 1.0);
        let got_v = num(&t, i, "rebound_speed");
        let got_x = num(&t, i, "max_penetration");
        assert!(
            (got_v - v).abs() < 5e-3 * v,
            "zeta {zeta}: rebound {got_v} vs {v}"
        );
        assert!(
            (got_x - x).abs() < 5e-3 * x,
            "zeta {zeta}: penetration {got_x} vs {x}"
        );
    }
    // More damping, slower rebound; softer floor, deeper penetration.
    assert!(num(&t, 1, "rebound_speed") < num(&t, 0, "rebound_speed"));
    assert!(num(&t, 0, "max_penetration") > num(&t, 4, "max_penetration"));
    let stats = std::fs::read_to_string(out.join("statistics.csv")).expect("statistics.csv");
    assert!(
        stats
            .lines()
            .any(|l| l.starts_with("impacts,6,0,1.0,0.0,0.0,")),
        "{stats}"
    );

    // Again: every case is finished, nothing runs, the same file (timings included).
    let before = std::fs::read(out.join("sweep.csv")).expect("read");
    let r = run(&["sweep", "sweeps/bounce.toml", "-o", o]);
    assert!(
        text(&r).contains("0 of 6 cases run (6 already finished)"),
        "{}",
        text(&r)
    );
    assert_eq!(std::fs::read(out.join("sweep.csv")).expect("read"), before);

    // An interrupted case (no case.json; a half-written history) runs again from scratch
    // and gives the same row.
    let case3 = out.join("cases/0003");
    std::fs::remove_file(case3.join("case.json")).expect("rm");
    std::fs::write(case3.join("node_2.csv"), "t,x\n0,").expect("write");
    let r = run(&["sweep", "sweeps/bounce.toml", "-o", o]);
    assert!(
        text(&r).contains("1 of 6 cases run (5 already finished)"),
        "{}",
        text(&r)
    );
    let again = rows(&out);
    let timing = [col(&t, "cpu"), col(&t, "cpu_s")];
    let strip = |r: &Vec<String>| -> Vec<String> {
        r.iter()
            .enumerate()
            .filter(|(k, _)| !timing.contains(k))
            .map(|(_, c)| c.clone())
            .collect()
    };
    assert_eq!(
        again.iter().map(strip).collect::<Vec<_>>(),
        t.iter().map(strip).collect::<Vec<_>>()
    );

    // --case runs only the cases named, in a fresh directory, and does not collect.
    let out2 = tmp("case");
    let r = run(&[
        "sweep",
        "sweeps/bounce.toml",
        "-o",
        out2.to_str().expect("utf-8"),
        "--case",
        "1-2",
    ]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    assert!(
        out2.join("cases/0001/case.json").is_file() && out2.join("cases/0002/case.json").is_file()
    );
    assert!(!out2.join("cases/0000").exists() && !out2.join("sweep.csv").exists());
    // Collecting a partial sweep: the others are `missing`, exit 1.
    let r = run(&[
        "sweep",
        "sweeps/bounce.toml",
        "-o",
        out2.to_str().expect("utf-8"),
        "--collect",
    ]);
    assert_eq!(r.status.code(), Some(1), "{}", text(&r));
    let p = rows(&out2);
    assert_eq!(p[1][col(&p, "status")], "missing");
    assert_eq!(strip(&p[2]), strip(&t[2]));
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&out2);
}

#[test]
fn failed_cases_are_recorded_and_the_others_go_on() {
    let dir = tmp("failed");
    let plan = dir.join("p.toml");
    let deck = root().join("decks/bounce_sweep.dat");
    // zeta = -1 gives a negative damping C: the deck rejects the case's values.
    std::fs::write(
        &plan,
        format!(
            "deck = {:?}\nout = {:?}\n[[parameter]]\nname = \"zeta\"\nvalues = [0.1, -1, 0.2]\n[[quantity]]\nname = \"v\"\nnode = 2\ncolumn = \"vy\"\nstat = \"last\"\n[[quantity]]\nname = \"nope\"\nnode = 99\ncolumn = \"vy\"\nstat = \"last\"\n",
            deck.display().to_string(),
            dir.join("out").display().to_string()
        ),
    )
    .expect("write");
    let r = run(&["sweep", plan.to_str().expect("utf-8"), "-q"]);
    // Issue 28 §5: cases not ok make the sweep exit 1 (it still ran and collected all).
    assert_eq!(r.status.code(), Some(1), "{}", text(&r));
    let t = rows(&dir.join("out"));
    let st = col(&t, "status");
    let diag = col(&t, "diagnosis");
    // Case 1: bad input, located in the deck (line 20, the CAME card's C field).
    assert_eq!(t[2][st], "bad_input");
    assert!(
        t[2][diag].contains("bounce_sweep.dat:20:") && t[2][diag].contains("C"),
        "{}",
        t[2][diag]
    );
    // Cases 0 and 2 ran, but node 99 is not written: a quantity error, named.
    assert_eq!(t[1][st], "quantity_error");
    assert!(t[1][diag].contains("node_99.csv"), "{}", t[1][diag]);
    assert!(num(&t, 0, "v") > 0.0 && t[1][col(&t, "nope")].is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn random_plans_give_statistics_and_figures() {
    let dir = tmp("random");
    let plan = dir.join("mc.toml");
    std::fs::write(
        &plan,
        format!(
            "deck = {:?}\nsamples = 8\nseed = 3\nsampling = \"latin-hypercube\"\n\
             [[parameter]]\nname = \"k\"\ndistribution = \"lognormal\"\nmedian = 1e7\nsigma = 0.05\n\
             [[parameter]]\nname = \"zeta\"\ndistribution = \"uniform\"\nlow = 0.08\nhigh = 0.12\n\
             [[quantity]]\nname = \"v\"\nnode = 2\ncolumn = \"vy\"\nstat = \"last\"\n",
            root().join("decks/bounce_sweep.dat").display().to_string()
        ),
    )
    .expect("write");
    let out = dir.join("out");
    let r = run(&[
        "sweep",
        plan.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
        "-q",
    ]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let t = rows(&out);
    assert_eq!(t.len(), 9);
    // Every rebound speed lies between the closed forms at the ends of zeta's range.
    let (hi, _) = closed_form(1e7, 0.08, 1.0);
    let (lo, _) = closed_form(1e7, 0.12, 1.0);
    for i in 0..8 {
        let v = num(&t, i, "v");
        assert!(v > lo * 0.995 && v < hi * 1.005, "{v} not in [{lo}, {hi}]");
    }
    for f in ["v_hist.svg", "v_vs_k.svg", "v_vs_zeta.svg"] {
        assert!(out.join("figures").join(f).is_file(), "{f}");
    }
    // The same plan lists the same cases.
    let a = run(&["sweep", plan.to_str().expect("utf-8"), "--list"]);
    let b = run(&["sweep", plan.to_str().expect("utf-8"), "--list"]);
    assert_eq!(a.stdout, b.stdout);
    assert_eq!(String::from_utf8_lossy(&a.stdout).lines().count(), 8);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ten_thousand_cases_are_listed_and_emitted_without_running() {
    let dir = tmp("big");
    let plan = dir.join("big.toml");
    std::fs::write(
        &plan,
        format!(
            "deck = {:?}\n[[parameter]]\nname = \"k\"\nfrom = 1e6\nto = 1e7\nn = 100\nscale = \"log\"\n\
             [[parameter]]\nname = \"zeta\"\nfrom = 0.01\nto = 0.5\nn = 100\n",
            root().join("decks/bounce_sweep.dat").display().to_string()
        ),
    )
    .expect("write");
    let p = plan.to_str().expect("utf-8");
    let out = dir.join("out");
    let o = out.to_str().expect("utf-8");
    let r = run(&["sweep", p, "-o", o, "--list"]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let list = String::from_utf8_lossy(&r.stdout).to_string();
    assert_eq!(list.lines().count(), 10_000);
    assert_eq!(list.lines().next(), Some("0 k=1000000.0 zeta=0.01"));
    assert_eq!(list.lines().last(), Some("9999 k=10000000.0 zeta=0.5"));
    let r = run(&[
        "sweep", p, "-o", o, "--emit", "slurm", "--chunk", "50", "--time", "00:10:00",
    ]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let script = std::fs::read_to_string(out.join("sweep.sbatch")).expect("script");
    assert!(script.contains("#SBATCH --array=0-199\n"), "{script}");
    assert!(script.contains("#SBATCH --time=00:10:00\n") && script.contains("CHUNK=50\n"));
    assert!(!out.join("cases").exists(), "nothing ran");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_plans_and_parameters_exit_2_with_a_message() {
    let dir = tmp("bad");
    let deck = root().join("decks/bounce_sweep.dat").display().to_string();
    for (body, needle) in [
        (
            "[[parameter]]\nname = \"kk\"\nvalues = [1]\n",
            "cannot set parameter `kk`",
        ),
        ("[[parameter]]\nname = \"k\"\nvalues = []\n", "non-empty"),
        (
            "[[parameter]]\nname = \"k\"\nvalues = [1]\n[[quantity]]\nname = \"q\"\nnode = 2\n",
            "column",
        ),
        ("[[parameter]\n", "TOML"),
    ] {
        let plan = dir.join("p.toml");
        std::fs::write(&plan, format!("deck = {deck:?}\n{body}")).expect("write");
        let r = run(&["sweep", plan.to_str().expect("utf-8"), "--list"]);
        assert_eq!(r.status.code(), Some(2), "{body}: {}", text(&r));
        assert!(
            text(&r).contains(needle) || needle == "TOML",
            "{body}: {}",
            text(&r)
        );
    }
    // --set and --check through the binary.
    let r = run(&[
        "--check",
        "decks/bounce_sweep.dat",
        "--set",
        "zeta=0.3",
        "--set",
        "k=2e6/2",
    ]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let t = text(&r);
    assert!(
        t.contains("  zeta = 0.3   (--set)")
            && t.contains("  k = 1000000.0   (--set)")
            && t.contains("  v = 1.0\n"),
        "{t}"
    );
    let r = run(&["--check", "decks/bounce_sweep.dat", "--set", "zetta=0.3"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(
        text(&r).contains("cannot set parameter `zetta`"),
        "{}",
        text(&r)
    );
    let r = run(&["--check", "decks/bounce_sweep.dat", "--set", "zeta"]);
    assert_eq!(r.status.code(), Some(2), "clap rejects a malformed --set");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_diverging_case_is_recorded_with_its_diagnosis() {
    let dir = tmp("diverge");
    // decks/stab_diverge.dat (an absurd tip load on a cantilever: Newton fails) with the
    // load as a parameter: 1 N runs, 1e12 N fails.
    let deck = std::fs::read_to_string(root().join("decks/stab_diverge.dat")).expect("deck");
    let deck = deck
        .replace("FORCE 5  0 1e12 0", "FORCE 5  0 $F 0")
        .replace("END 1 MAXIT 10", "END 0.05 MAXIT 10")
        .replace("MATERIALS\n", "PARAMETERS\n  F 1e12\nMATERIALS\n");
    assert!(
        deck.contains("$F") && deck.contains("PARAMETERS"),
        "the deck changed: {deck}"
    );
    std::fs::write(dir.join("d.dat"), deck).expect("write");
    std::fs::write(
        dir.join("p.toml"),
        "deck = \"d.dat\"\n[[parameter]]\nname = \"F\"\nvalues = [1, 1e12]\n\
         [[quantity]]\nname = \"y5\"\nnode = 5\ncolumn = \"y\"\nstat = \"max\"\n",
    )
    .expect("write");
    let out = dir.join("out");
    let r = run(&[
        "sweep",
        dir.join("p.toml").to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
        "-q",
    ]);
    // Issue 28 §5: a failed case makes the sweep exit 1.
    assert_eq!(r.status.code(), Some(1), "case 1 fails: {}", text(&r));
    let t = rows(&out);
    let (st, diag) = (col(&t, "status"), col(&t, "diagnosis"));
    assert_eq!(t[1][st], "ok");
    assert!(t[1][diag].is_empty());
    assert_eq!(t[2][st], "failed");
    assert!(
        t[2][diag].to_lowercase().contains("newton"),
        "{}",
        t[2][diag]
    );
    // The histories up to the failure are kept and the quantity computed on them.
    assert!(!t[2][col(&t, "y5")].is_empty());
    // Another deck text (even a comment) means other cases: all run again.
    let d = dir.join("d.dat");
    let old = std::fs::read_to_string(&d).expect("read");
    std::fs::write(&d, format!("! changed\n{old}")).expect("write");
    let r = run(&[
        "sweep",
        dir.join("p.toml").to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert!(
        text(&r).contains("2 of 2 cases run (0 already finished)"),
        "{}",
        text(&r)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sweep stopped by SIGINT (through the run's test hook `MECANO_FAILPOINT`, which raises
/// the real signal at a known step) exits 130 leaving the case under way with a checkpoint
/// and no `case.json`; running the plan again goes on from that checkpoint, and every
/// history file of every case is byte for byte that of a sweep never stopped.
#[test]
fn an_interrupted_sweep_goes_on_from_its_checkpoints() {
    common::require_failpoints();
    let clean = tmp("clean");
    let stopped = tmp("stopped");
    let (c, s) = (
        clean.to_str().expect("utf-8"),
        stopped.to_str().expect("utf-8"),
    );
    let r = run(&["sweep", "sweeps/bounce.toml", "-o", c, "-q"]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let r = Command::new(BIN)
        .args(["sweep", "sweeps/bounce.toml", "-o", s, "-q", "--jobs", "1"])
        .env("MECANO_FAILPOINT", "signal:INT:20")
        .current_dir(root())
        .output()
        .expect("binary runs");
    assert_eq!(r.status.code(), Some(130), "{}", text(&r));
    let case0 = stopped.join("cases/0000");
    assert!(case0.join("checkpoint.bin").is_file() && !case0.join("case.json").exists());
    assert!(
        !stopped.join("cases/0001").exists(),
        "no case starts after the stop"
    );
    let r = run(&["sweep", "sweeps/bounce.toml", "-o", s, "-q"]);
    assert_eq!(r.status.code(), Some(0), "{}", text(&r));
    let summary = std::fs::read_to_string(case0.join("summary.json")).expect("summary");
    assert!(
        summary.contains("\"resumes\""),
        "case 0 was resumed: {summary}"
    );
    for case in 0..6 {
        let name = format!("cases/{case:04}");
        for entry in std::fs::read_dir(clean.join(&name)).expect("case dir") {
            let path = entry.expect("entry").path();
            if path.extension().is_some_and(|e| e == "csv") {
                let other = stopped.join(&name).join(path.file_name().expect("name"));
                assert_eq!(
                    std::fs::read(&path).expect("read"),
                    std::fs::read(&other).expect("read"),
                    "{} differs",
                    other.display()
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&clean);
    let _ = std::fs::remove_dir_all(&stopped);
}
