//! `mecano-rs compare` on real runs: identical runs pass, a planted difference is found
//! where it was planted, with the exit codes of the README (0 pass, 1 over tolerance,
//! 2 bad input).

use crate::common;

use common::TempDir;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn compare(run: &Path, reference: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("compare")
        .arg(run)
        .arg(reference)
        .args(extra)
        .output()
        .unwrap()
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// `decks/pendulum_short.dat` run into `base/ref`.
fn short_run(base: &TempDir) -> PathBuf {
    let reference = base.join("ref");
    let o = bin()
        .args(["decks/pendulum_short.dat", "-q", "--checkpoint", "0", "-o"])
        .arg(&reference)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    reference
}

/// Rewrites the columns `cols` of `dir/file` row by row with `f(t, values)`.
fn rewrite(dir: &Path, file: &str, cols: &[usize], f: impl Fn(f64, &mut [f64])) {
    let path = dir.join(file);
    let t = std::fs::read_to_string(&path).unwrap();
    let mut lines = t.lines();
    let mut out = vec![lines.next().unwrap().to_string()];
    for l in lines {
        let mut v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let mut picked: Vec<f64> = cols.iter().map(|&c| v[c]).collect();
        f(v[0], &mut picked);
        for (&c, x) in cols.iter().zip(picked) {
            v[c] = x;
        }
        out.push(
            v.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(","),
        );
    }
    std::fs::write(&path, out.join("\n") + "\n").unwrap();
}

/// Rotations are compared as rotations (issue 27 §3): node 23's rotation vector rewritten
/// in every row as the same attitude, `Φ − 2π Φ/|Φ|` (2π away as numbers), is no difference
/// (the angle of `R_runᵀ R_ref` is the rounding of exp and log, ~1e-15 rad; judged at 1e-12);
/// a planted 1e-3 rad turn about x at t = 0.3 s is found as 1e-3 rad, where it was planted.
/// `energy.csv` is compared too: a planted 1 J on its `kinetic` column is found.
#[test]
fn compare_judges_rotations_as_rotations_and_compares_the_energies() {
    use mecano::rotation::{exp, log};
    use nalgebra::Vector3;
    let base = TempDir::new("compare_rot");
    let reference = short_run(&base);
    let run = base.join("run");
    copy_dir(&reference, &run);
    // node_<N>.csv: t,x,y,z,ux,uy,uz,rx,ry,rz,...
    let rot = [7, 8, 9];
    rewrite(&run, "node_23.csv", &rot, |_, r| {
        let phi = Vector3::new(r[0], r[1], r[2]);
        if phi.norm() > 0.0 {
            let other = phi - phi.normalize() * (2.0 * std::f64::consts::PI);
            r.copy_from_slice(other.as_slice());
        }
    });
    let o = compare(
        &run,
        &reference,
        &["--nodes", "23", "--tol", "rotation=1e-12", "--json"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let cols = v["files"][0]["columns"].as_array().unwrap();
    assert!(cols.iter().any(|c| c["column"] == "rotation"), "{v}");
    assert!(
        !cols.iter().any(|c| c["column"] == "rx"),
        "rx is not compared as a number"
    );

    rewrite(&run, "node_23.csv", &rot, |t, r| {
        if (t - 0.3).abs() < 1e-9 {
            let turned = exp(&Vector3::new(r[0], r[1], r[2])) * exp(&Vector3::new(1e-3, 0.0, 0.0));
            r.copy_from_slice(log(&turned).as_slice());
        }
    });
    let o = compare(
        &run,
        &reference,
        &["--nodes", "23", "--tol", "rotation=1e-12", "--json"],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let cols = v["files"][0]["columns"].as_array().unwrap();
    let m = &cols.iter().find(|c| c["column"] == "rotation").unwrap()["max"];
    assert!((m["at_time"].as_f64().unwrap() - 0.3).abs() < 1e-9, "{m}");
    // The planted turn composed with the rewritten vector: 1e-3 rad to a few ulps of π.
    assert!(
        (m["max_abs_diff"].as_f64().unwrap() - 1e-3).abs() < 1e-12,
        "{m}"
    );

    // energy.csv: t,kinetic,...
    rewrite(&run, "energy.csv", &[1], |t, e| {
        if (t - 0.3).abs() < 1e-9 {
            e[0] += 1.0;
        }
    });
    let o = compare(
        &run,
        &reference,
        &["--tol", "kinetic=1e-6,rotation=1", "--json"],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let energy = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "energy.csv")
        .expect("energy.csv compared");
    let k = &energy["columns"].as_array().unwrap()[0];
    assert_eq!(k["column"], "kinetic");
    assert!(
        (k["max"]["max_abs_diff"].as_f64().unwrap() - 1.0).abs() < 1e-9,
        "{k}"
    );
}

#[test]
fn compare_passes_identical_runs_and_finds_a_planted_difference() {
    let base = TempDir::new("compare");
    let reference = short_run(&base);

    // Identical: every difference is exactly 0, within any tolerance, even 0.
    let o = compare(&reference, &reference, &["--tol", "0"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("0 over tolerance: PASS"), "{}", text(&o));

    // Plant +1e-3 m on y of node 23 in the row of t = 0.3 s.
    let run = base.join("run");
    copy_dir(&reference, &run);
    let f = run.join("node_23.csv");
    let t = std::fs::read_to_string(&f).unwrap();
    let mut planted = None;
    let lines: Vec<String> = t
        .lines()
        .map(|l| {
            let mut v: Vec<String> = l.split(',').map(str::to_string).collect();
            if v[0].parse::<f64>().is_ok_and(|t| (t - 0.3).abs() < 1e-9) {
                let y: f64 = v[2].parse().unwrap();
                v[2] = (y + 1e-3).to_string();
                planted = Some((v[0].parse::<f64>().unwrap(), y));
            }
            v.join(",")
        })
        .collect();
    let (t_planted, y) = planted.expect("a row at t = 0.3 s");
    std::fs::write(&f, lines.join("\n") + "\n").unwrap();

    let o = compare(&run, &reference, &["--tol", "1e-6", "--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["pass"], false);
    assert_eq!(v["exceeded"], 1, "only node 23's y");
    let node = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "node_23.csv")
        .unwrap();
    let col = node["columns"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["column"] == "y")
        .unwrap();
    let m = &col["max"];
    // serde_json's default number parser may be one ulp off the double written (ryu's
    // shortest form): compare to a relative 1e-15 (≈ 4.5 ulp).
    let near = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() <= 1e-15 * b.abs());
    assert!(near(m["at_time"].as_f64(), t_planted), "{m}");
    assert!(near(m["ref_value"].as_f64(), y), "{m}");
    // y + 1e-3 rounded to a double and back: within a few ulps of 1e-3.
    let d = m["max_abs_diff"].as_f64().unwrap();
    assert!((d - 1e-3).abs() < 1e-15, "{d}");
    // The window [0.25, 0.5) holds it; the others are clean.
    let w = col["windows"].as_array().unwrap();
    assert!(near(w[1]["max_abs_diff"].as_f64(), d));
    assert_eq!(w[0]["max_abs_diff"].as_f64(), Some(0.0));

    // Tolerances per quantity: position 1e-2 passes; y alone at 1e-4 fails; columns
    // not chosen are not looked at.
    let o = compare(
        &run,
        &reference,
        &["--nodes", "12,23", "--tol", "position=1e-2"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = compare(&run, &reference, &["--nodes", "23", "--tol", "y=1e-4"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("FAIL"), "{}", text(&o));
    let o = compare(
        &run,
        &reference,
        &["--nodes", "23", "--columns", "x,z", "--tol", "0"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));

    // A reference sampled at other times is interpolated: the run against itself
    // thinned to every other row (h = 2e-3 s between rows) differs by the error of
    // linear interpolation, at most h²/8 max|ẍ| per coordinate (max over the sampled
    // accelerations, doubled for peaks between samples): passes at that tolerance, and
    // does not at a tenth of it (the error is not zero).
    let thin = base.join("thin");
    copy_dir(&reference, &thin);
    let f = thin.join("node_23.csv");
    let t = std::fs::read_to_string(&f).unwrap();
    let kept: Vec<&str> = t
        .lines()
        .enumerate()
        .filter(|(i, _)| *i == 0 || i % 2 == 1)
        .map(|(_, l)| l)
        .collect();
    std::fs::write(&f, kept.join("\n") + "\n").unwrap();
    let mut amax = [0.0f64; 3];
    for l in t.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        for c in 0..3 {
            amax[c] = amax[c].max(v[16 + c].abs());
        }
    }
    let h = 2e-3;
    let bound = |k: f64| {
        format!(
            "x={:e},y={:e},z={:e}",
            k * h * h / 8.0 * 2.0 * amax[0],
            k * h * h / 8.0 * 2.0 * amax[1],
            k * h * h / 8.0 * 2.0 * amax[2]
        )
    };
    let args = |tol: &str| -> Vec<String> {
        [
            "--nodes",
            "23",
            "--columns",
            "x,y,z",
            "--json",
            "--tol",
            tol,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let a = args(&bound(1.0));
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    let o = compare(&reference, &thin, &a);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["files"][0]["interpolated"], true);
    let a = args(&bound(0.1));
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    let o = compare(&reference, &thin, &a);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));

    // Bad input: exit 2, naming what is available.
    let o = compare(&run, &reference, &["--nodes", "7"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("nodes 2, 12, 23"), "{}", text(&o));
    let o = compare(&run, &reference, &["--columns", "nope"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("vy"), "{}", text(&o));
    let o = compare(&run, &base.join("missing"), &[]);
    assert_eq!(o.status.code(), Some(2));
    let o = compare(&run, &reference, &["--tol", "x=-1"]);
    assert_eq!(o.status.code(), Some(2));
}
