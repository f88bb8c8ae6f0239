//! A run owns its output directory (issue 28): a path that cannot be a directory is bad
//! input (exit 2); two runs never write into one directory at once (a lock the kernel
//! releases when its holder dies); a new run removes the files of the previous run there
//! (its manifest) and refuses files of anyone else unless `--force`.

use crate::common;

use std::fs::{self, File, OpenOptions};
use std::os::fd::AsRawFd;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_mecano-rs"));
    c.env_remove("MECANO_FAILPOINT");
    c
}

/// A scratch directory removed when the test ends, also when it fails ([`common::TempDir`]).
fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(&format!("outdir_{name}"))
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `decks/pendulum.dat` cut to `end` seconds, with the OUTPUT line `output`, in `dir`.
fn deck(dir: &Path, name: &str, end: &str, output: &str) -> PathBuf {
    let src =
        fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/decks/pendulum.dat")).unwrap();
    let text: String = src
        .lines()
        .map(|l| {
            if l.starts_with("ANALYSIS") {
                l.replace("END 2.0", &format!("END {end}"))
            } else if l.starts_with("OUTPUT") {
                output.to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let p = dir.join(name);
    fs::write(&p, text + "\n").unwrap();
    p
}

fn run(deck: &Path, out: &Path, extra: &[&str]) -> Output {
    bin()
        .arg(deck)
        .arg("-q")
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .expect("the binary runs")
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn an_output_path_that_cannot_be_a_directory_is_bad_input() {
    let d = tmp("paths");
    let dk = deck(&d, "p.dat", "0.001", "OUTPUT NODES 12");
    let file = d.join("a_file");
    fs::write(&file, "x").unwrap();
    for (out, says) in [
        (file.clone(), "exists and is not a directory"),
        (PathBuf::from("/dev/null"), "exists and is not a directory"),
        (file.join("sub"), "cannot be used"),
    ] {
        let o = run(&dk, &out, &[]);
        assert_eq!(
            o.status.code(),
            Some(2),
            "-o {}: {}",
            out.display(),
            text(&o)
        );
        assert!(
            text(&o).contains(says),
            "-o {}: {}",
            out.display(),
            text(&o)
        );
    }
    assert_eq!(
        fs::read_to_string(&file).unwrap(),
        "x",
        "the file is untouched"
    );
    let _ = fs::remove_dir_all(&d);
}

/// Takes the directory's lock as a run does (flock, exclusive, non-blocking).
fn hold_lock(dir: &Path) -> File {
    fs::create_dir_all(dir).unwrap();
    let f = OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(dir.join(".mecano-lock"))
        .unwrap();
    // SAFETY: flock(2) on a descriptor we own.
    let rc = unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    assert_eq!(rc, 0, "the test takes the lock");
    f
}

#[test]
fn a_second_run_into_a_directory_in_use_is_refused_and_a_dead_holder_leaves_no_lock() {
    let d = tmp("lock");
    let dk = deck(&d, "p.dat", "0.003", "OUTPUT NODES 12 EVERY 1");
    let out = d.join("out");
    // A run completes; then someone (this test, as a run would) holds the lock.
    let o = run(&dk, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let before = fs::read(out.join("node_12.csv")).unwrap();
    let lock = hold_lock(&out);
    let o = run(&dk, &out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("in use by another mecano-rs run"),
        "{}",
        text(&o)
    );
    assert_eq!(
        fs::read(out.join("node_12.csv")).unwrap(),
        before,
        "the refused run wrote nothing"
    );
    // resume takes the same lock.
    let o = bin().arg("resume").arg(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("in use"), "{}", text(&o));
    drop(lock);
    // A run killed (SIGKILL, no clean-up of ours) at its 5th step: the kernel released
    // its lock, and the next run goes on into the directory.
    let o = bin()
        .arg(&dk)
        .args(["-q", "-o"])
        .arg(&out)
        .env("MECANO_FAILPOINT", "signal:KILL:5")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), None, "killed by a signal: {}", text(&o));
    let o = run(&dk, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let _ = fs::remove_dir_all(&d);
}

#[test]
fn two_runs_started_together_one_runs_and_the_other_is_refused() {
    let d = tmp("race");
    let dk = deck(&d, "p.dat", "0.02", "OUTPUT NODES 12 23 EVERY 1");
    let out = d.join("out");
    let spawn = || {
        bin()
            .arg(&dk)
            .args(["-q", "--checkpoint", "0", "-o"])
            .arg(&out)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn(), spawn());
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    let mut codes = [a.status.code(), b.status.code()];
    codes.sort();
    // Either the second found the first's lock (2), or the first had ended before the
    // second started (both 0): never two writers, so the files are one run's.
    assert!(
        codes == [Some(0), Some(2)] || codes == [Some(0), Some(0)],
        "{codes:?}: {} / {}",
        text(&a),
        text(&b)
    );
    // The loser is told the directory is in use, never that it holds foreign files
    // (the winner's, written under its manifest while the loser looked).
    for o in [&a, &b] {
        if o.status.code() == Some(2) {
            assert!(text(o).contains("in use"), "{}", text(o));
        }
    }
    let rows = fs::read_to_string(out.join("node_12.csv")).unwrap();
    let times: Vec<f64> = rows
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(
        times.windows(2).all(|w| w[1] > w[0]),
        "time goes forward in one run's file"
    );
    let s: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["complete"], true);
    let _ = fs::remove_dir_all(&d);
}

#[test]
fn a_new_run_removes_the_previous_runs_files_and_refuses_foreign_ones_without_force() {
    let d = tmp("stale");
    let all = deck(&d, "all.dat", "0.001", "OUTPUT NODES ALL ELEMENTS ALL");
    let three = deck(&d, "three.dat", "0.001", "OUTPUT NODES 2 12 23 ELEMENTS 12");
    let out = d.join("out");
    let o = run(&all, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let first = names(&out);
    assert!(first.iter().filter(|n| n.starts_with("node_")).count() > 20);
    // The second run writes three node files: nothing of the first run stays.
    let o = run(&three, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let expected: Vec<String> = [
        ".mecano-lock",
        ".mecano-manifest",
        "element_12.csv",
        "energy.csv",
        "node_12.csv",
        "node_2.csv",
        "node_23.csv",
        "summary.json",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    assert_eq!(names(&out), expected);
    // The same after a run that fails (an unresolvable section: its stiffness swamps the
    // mass in the iteration matrix): its files only.
    let bad = fs::read_to_string(&three)
        .unwrap()
        .replace("I2 8.3e-8", "I2 1e60");
    let bad_deck = d.join("bad.dat");
    fs::write(&bad_deck, bad).unwrap();
    let o = run(&bad_deck, &out, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let o = run(&three, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(names(&out), expected);
    // A file no run wrote: refused, nothing touched; --force runs and leaves it.
    fs::write(out.join("notes.txt"), "mine").unwrap();
    let before = fs::read(out.join("node_12.csv")).unwrap();
    let o = run(&three, &out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("notes.txt") && text(&o).contains("--force"),
        "{}",
        text(&o)
    );
    assert_eq!(fs::read(out.join("node_12.csv")).unwrap(), before);
    // A directory of someone else's files only: refused, and nothing written into it.
    let theirs = d.join("theirs");
    fs::create_dir_all(&theirs).unwrap();
    fs::write(theirs.join("node_12.csv"), "old").unwrap();
    let o = run(&three, &theirs, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert_eq!(names(&theirs), ["node_12.csv"]);
    let o = run(&three, &out, &["--force"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    // A subdirectory (e.g. a study's) is neither counted nor touched.
    fs::remove_file(out.join("notes.txt")).unwrap();
    fs::create_dir_all(out.join("study")).unwrap();
    fs::write(out.join("study/study.csv"), "x").unwrap();
    let o = run(&three, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(out.join("study/study.csv").exists());
    let _ = fs::remove_dir_all(&d);
}
