//! Large models and their output (issue 29): a 50,000-beam cantilever runs with its default
//! OUTPUT under the usual limit of 1024 open files; `FORMAT NETCDF` writes the same
//! numbers as the CSVs (bit for bit), `compare` and `plot` read it as they read the CSVs,
//! and a restart gives the same `histories.nc` byte for byte; an output that cannot be
//! opened stops the run before its first step with exit 2.

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_mecano-rs");

/// A scratch directory removed when the test ends, also when it fails ([`common::TempDir`]).
fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(&format!("large_{name}"))
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A 10 m steel cantilever divided into `n` beams, a tip force, `end` s of steps of 1e-5 s.
fn cantilever(n: u32, end: f64, output: &str) -> String {
    format!(
        "TITLE cantilever of {n} beams\nMATERIALS\n  1 E 2.1e11 NU 0.3 RHO 7800\n\
         SECTIONS\n  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8 K 0.8333333333333334\n\
         NODES\n  1 0 0 0 FIX ALL\n  2 10 0 0\nELEMENTS\n  1 BEAM 1 2 MAT 1 SEC 1 AXIS2 0 0 1 DIVIDE {n}\n\
           2 MASS 2 M 0.5\nLOADS\n  FORCE 2 0 -100 0\nANALYSIS DYNAMIC STEP 1e-5 END {end}\n{output}\n"
    )
}

/// The files a run wrote for its user: its bookkeeping (`.mecano-lock`, `.mecano-manifest`,
/// README "What a run does to its output directory") is left out.
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with(".mecano-"))
        .collect();
    v.sort();
    v
}

#[test]
fn fifty_thousand_beams_run_with_the_default_output_under_1024_open_files() {
    let d = tmp("50k");
    let deck = d.join("deck.dat");
    std::fs::write(&deck, cantilever(50_000, 2e-5, "OUTPUT NODES 2")).unwrap();
    let out = d.join("out");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -n 1024 && exec {BIN} -q --checkpoint 0 -o {} {}",
            out.display(),
            deck.display()
        ))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // The default selection of a large model: the deck's numbered element 1 (the first
    // sub-beam keeps its number; the MASS 2 has no history of its own); none of the
    // 49,999 generated beams, none of the 49,999 generated nodes.
    assert_eq!(
        files(&out),
        ["element_1.csv", "energy.csv", "node_2.csv", "summary.json"]
    );
    // t = 0, 1e-5, 2e-5: a header and three rows.
    let node = std::fs::read_to_string(out.join("node_2.csv")).unwrap();
    assert_eq!(node.lines().count(), 4, "{node}");
}

#[test]
fn every_history_of_a_large_selection_opens_at_most_a_few_files_at_once() {
    // 2,000 beams, NODES ALL ELEMENTS ALL: 4,001 history files, written under a limit
    // of 64 open descriptors (one file at a time is ever open, besides the std streams).
    let d = tmp("all");
    let deck = d.join("deck.dat");
    std::fs::write(
        &deck,
        cantilever(2000, 3e-5, "OUTPUT NODES ALL ELEMENTS ALL"),
    )
    .unwrap();
    let out = d.join("out");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -n 64 && exec {BIN} -q --checkpoint 0 -o {} {}",
            out.display(),
            deck.display()
        ))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // 2001 nodes, 2000 beams (the mass writes no history), energy.csv, summary.json.
    assert_eq!(files(&out).len(), 2001 + 2000 + 2);
}

/// Runs `deck` into `out`; with `failpoint` (e.g. `signal:INT:7`) stopped there.
fn run(deck: &Path, out: &Path, failpoint: Option<&str>) -> Output {
    let mut c = Command::new(BIN);
    c.arg(deck).args(["-q", "--checkpoint", "0", "-o"]).arg(out);
    match failpoint {
        Some(f) => c.env("MECANO_FAILPOINT", f),
        None => c.env_remove("MECANO_FAILPOINT"),
    };
    c.output().unwrap()
}

#[test]
fn netcdf_holds_the_csv_numbers_and_compare_plot_and_resume_read_it() {
    let d = tmp("nc");
    let csv_deck = d.join("csv.dat");
    let nc_deck = d.join("nc.dat");
    let sel = "OUTPUT NODES ALL ELEMENTS ALL EVERY 2";
    std::fs::write(&csv_deck, cantilever(20, 4e-4, sel)).unwrap();
    std::fs::write(
        &nc_deck,
        cantilever(20, 4e-4, &format!("{sel} FORMAT NETCDF")),
    )
    .unwrap();
    let (csv, nc) = (d.join("csv"), d.join("nc"));
    let o = run(&csv_deck, &csv, None);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = run(&nc_deck, &nc, None);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(
        files(&nc),
        ["energy.csv", "histories.nc", "summary.json"],
        "one file for every history"
    );

    // Every history: the same header and the same doubles, bit for bit (Ryū's shortest
    // text reads back to the same double, and NetCDF stores the double itself).
    let ents = mecano::output::columnar::entities(&nc);
    assert_eq!(
        ents.len(),
        21 + 20,
        "21 nodes, 20 beams (a mass writes no history)"
    );
    for (kind, n) in &ents {
        let name = format!("{kind}_{n}.csv");
        let from_nc = mecano::output::columnar::from_columnar(&nc.join(&name))
            .expect("held")
            .expect("readable");
        let text = std::fs::read_to_string(csv.join(&name)).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(from_nc.columns, header, "{name}");
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 21, "{name}: t = 0, 2e-5, …, 4e-4");
        assert_eq!(from_nc.rows, rows, "{name}");
    }

    // compare reads it as the CSVs: every file, every difference exactly 0.
    let o = Command::new(BIN)
        .arg("compare")
        .arg(&nc)
        .arg(&csv)
        .args(["--tol", "0"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("0 over tolerance: PASS"), "{}", text(&o));

    // plot reads it as the CSVs.
    let svg = d.join("h.svg");
    let o = Command::new(BIN)
        .args(["plot", "history"])
        .arg(&nc)
        .args(["--node", "2", "--columns", "uy", "-o"])
        .arg(&svg)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));

    // sweep's quantities of interest read a history through plot's Table.
    let from_nc = mecano::plot::Table::read(&nc.join("node_2.csv")).unwrap();
    let from_csv = mecano::plot::Table::read(&csv.join("node_2.csv")).unwrap();
    assert_eq!(
        from_nc.column("uy").unwrap(),
        from_csv.column("uy").unwrap()
    );

    // Stopped by SIGINT at step 13 and resumed: histories.nc byte for byte as the run
    // never stopped (the file is cut back to its checkpoint, its record count with it).
    let stopped = d.join("stopped");
    let o = run(&nc_deck, &stopped, Some("signal:INT:13"));
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    let o = Command::new(BIN)
        .arg("resume")
        .arg(&stopped)
        .args(["-q", "--checkpoint", "0"])
        .env_remove("MECANO_FAILPOINT")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        std::fs::read(stopped.join("histories.nc")).unwrap()
            == std::fs::read(nc.join("histories.nc")).unwrap(),
        "histories.nc differs after the restart"
    );
}

#[test]
fn output_that_cannot_be_opened_stops_before_the_first_step_with_exit_2() {
    let d = tmp("blocked");
    let deck = d.join("deck.dat");
    std::fs::write(&deck, cantilever(4, 1e-4, "OUTPUT NODES 2")).unwrap();
    // The output directory's place is taken by a file: refused before anything is built.
    let out = d.join("out");
    std::fs::write(&out, "not a directory").unwrap();
    let o = run(&deck, &out, None);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("is not a directory"),
        "the cause is named: {}",
        text(&o)
    );
    // The directory is usable but a history file cannot be created (a directory holds its
    // name): refused when the directory is claimed (issue 35 §3: a name the run writes
    // held by anything but a regular file of the previous run), before the first step.
    let out = d.join("out2");
    std::fs::create_dir_all(out.join("node_2.csv")).unwrap();
    let o = run(&deck, &out, None);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("node_2.csv is a directory"),
        "the cause is named: {}",
        text(&o)
    );
}
