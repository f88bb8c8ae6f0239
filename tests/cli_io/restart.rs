//! Interruption, checkpoints and restart (`mecano-rs resume`), on the real binary with
//! `decks/pendulum_short.dat` (the pendulum to 0.6 s, through the impact at 0.534 s).
//!
//! The claim is exact: a run stopped (SIGINT, SIGTERM, SIGKILL, a kill in the middle of a
//! checkpoint's write) and resumed writes every history file byte for byte as a run never
//! stopped, and `summary.json` as its but for the CPU time and the record of restarts.
//! So the comparisons are of bytes, with no tolerance. Runs are stopped at known steps by
//! the test hook `MECANO_FAILPOINT` (the process signals itself through the real
//! handlers) or, for signals from outside, frozen with SIGSTOP first so that the signal
//! lands during the run whatever the machine's speed. Each run costs ~0.3 s of CPU.

use crate::common;

use common::{TempDir, require_failpoints};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

const DECK: &str = "decks/pendulum_short.dat";

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
}

/// A scratch directory removed when the test ends, passed or failed (`common::TempDir`).
fn tmp(name: &str) -> TempDir {
    TempDir::new(&format!("restart_{name}"))
}

fn run(args: &[&str], failpoint: Option<&str>) -> Output {
    if failpoint.is_some() {
        require_failpoints();
    }
    let mut c = bin();
    c.args(args);
    match failpoint {
        Some(f) => c.env("MECANO_FAILPOINT", f),
        None => c.env_remove("MECANO_FAILPOINT"),
    };
    c.output().expect("the binary runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The uninterrupted run (no checkpoints at all), computed once per process. Shared by the
/// tests, so no guard can remove it: it lives in cargo's scratch folder for integration tests
/// (`CARGO_TARGET_TMPDIR`, under `target/`, not the system's temporary folder), under a fixed
/// name that each run of this file overwrites.
fn reference() -> &'static Path {
    static REF: OnceLock<PathBuf> = OnceLock::new();
    REF.get_or_init(|| {
        let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("restart_reference");
        let _ = std::fs::remove_dir_all(&d);
        let o = run(
            &[DECK, "-q", "--checkpoint", "0", "-o", d.to_str().unwrap()],
            None,
        );
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        d
    })
}

fn csv_files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let n = e.ok()?.file_name().to_string_lossy().into_owned();
            n.ends_with(".csv").then_some(n)
        })
        .collect();
    v.sort();
    v
}

/// Every CSV of `dir` is the reference's, byte for byte; so is `summary.json` but for
/// the CPU seconds and the record of restarts.
fn assert_same_as_reference(dir: &Path) {
    let r = reference();
    let files = csv_files(r);
    assert_eq!(files.len(), 7, "node_2, 12, 23, element_1, 12, 23, energy");
    assert_eq!(csv_files(dir), files);
    for f in &files {
        let (a, b) = (
            std::fs::read(r.join(f)).unwrap(),
            std::fs::read(dir.join(f)).unwrap(),
        );
        if a != b {
            let at = a
                .iter()
                .zip(&b)
                .position(|(x, y)| x != y)
                .unwrap_or(a.len().min(b.len()));
            panic!(
                "{f} differs from the uninterrupted run at byte {at} ({} vs {} bytes)",
                b.len(),
                a.len()
            );
        }
    }
    let summary = |d: &Path| -> serde_json::Value {
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap())
                .unwrap();
        v["stats"]["cpu_seconds"] = serde_json::Value::Null;
        v.as_object_mut().unwrap().remove("resumes");
        v
    };
    assert_eq!(summary(dir), summary(r));
    assert!(
        !dir.join("checkpoint.bin").exists(),
        "a complete run keeps no checkpoint"
    );
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// Every file ends with a complete row: a newline, and as many fields on the last line
/// as in the header.
fn assert_whole_rows(dir: &Path) {
    for f in csv_files(dir) {
        let t = std::fs::read_to_string(dir.join(&f)).unwrap();
        assert!(t.ends_with('\n'), "{f} does not end with a newline");
        let lines: Vec<&str> = t.lines().collect();
        let n = lines[0].split(',').count();
        let last = lines[lines.len() - 1];
        assert_eq!(last.split(',').count(), n, "{f}: last row `{last}`");
        assert!(
            last.split(',')
                .all(|x| x.parse::<f64>().is_ok_and(f64::is_finite)),
            "{f}: last row `{last}`"
        );
    }
}

fn resume(dir: &Path) -> Output {
    run(
        &[
            "resume",
            dir.to_str().unwrap(),
            "-q",
            "--checkpoint",
            "0.05",
        ],
        None,
    )
}

/// A run stopped by the failpoint `fp`; returns its output directory and output.
fn stopped_run(name: &str, fp: &str, checkpoint: &str) -> (TempDir, PathBuf, Output) {
    let dir = tmp(name);
    let d = dir.join("out");
    let o = run(
        &[
            DECK,
            "-q",
            "--checkpoint",
            checkpoint,
            "-o",
            d.to_str().unwrap(),
        ],
        Some(fp),
    );
    (dir, d, o)
}

#[test]
fn sigint_ends_at_a_step_with_whole_rows_and_resume_gives_identical_files() {
    // Step 2500 of 6004: before the impact (0.534 s, step ~5340).
    let (_dir, d, o) = stopped_run("sigint", "signal:INT:2500", "60");
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    assert!(text(&o).contains("mecano-rs resume"), "{}", text(&o));
    assert_whole_rows(&d);
    let s = summary(&d);
    assert_eq!(s["complete"], false);
    assert_eq!(s["stop"]["reason"], "interrupted");
    assert_eq!(s["stop"]["at_step_end"], true);
    assert_eq!(s["signal"], "SIGINT");
    // The failpoint waits for the handler's thread to see the signal: the run ends at
    // that very pause.
    let step = s["stop"]["step"].as_u64().unwrap();
    assert_eq!(step, 2500);
    assert_eq!(s["time_reached"], s["stop"]["time"]);
    // The checkpoint is of that very step (the periodic one, 60 s, never came).
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_same_as_reference(&d);
    let r = &summary(&d)["resumes"];
    assert_eq!(r.as_array().unwrap().len(), 1);
    assert_eq!(r[0]["from_checkpoint"]["step"], step);
    assert_eq!(r[0]["bytes_cut"], 0);
    assert_eq!(r[0]["signal"], "SIGINT");
}

#[test]
fn sigterm_during_the_impact_then_again_in_the_restart_then_complete() {
    // Stopped inside the contact phase (steps ~5340-5600), resumed, stopped again by
    // SIGTERM 100 steps further (the failpoint is read again by the restart), resumed.
    let (_dir, d, o) = stopped_run("sigterm", "signal:TERM:5400", "60");
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    assert_eq!(summary(&d)["signal"], "SIGTERM");
    assert_eq!(summary(&d)["stop"]["step"], 5400);
    let o = run(
        &["resume", d.to_str().unwrap(), "-q"],
        Some("signal:TERM:5500"),
    );
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    assert_whole_rows(&d);
    assert_eq!(summary(&d)["stop"]["step"], 5500);
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_same_as_reference(&d);
    let r = summary(&d)["resumes"].clone();
    assert_eq!(r.as_array().unwrap().len(), 2);
    assert_eq!(r[0]["from_checkpoint"]["step"], 5400);
    assert_eq!(r[1]["from_checkpoint"]["step"], 5500);
    assert_eq!(r[1]["stopped"]["reason"], "interrupted");
}

#[test]
fn sigkill_at_several_steps_and_a_torn_row_are_cut_back_by_resume() {
    // Killed at steps before, in and after the impact, with checkpoints every 0.01 s of
    // wall time (several per run, at steps that depend on the machine: the claim must
    // hold whichever). A partial row is appended after the kill, as a write cut by a
    // power failure would leave it.
    for (k, step) in [300u64, 3100, 5450, 5990].into_iter().enumerate() {
        let (_dir, d, o) = stopped_run(&format!("kill{k}"), &format!("signal:KILL:{step}"), "0.01");
        assert_eq!(o.status.code(), None, "killed by a signal: {}", text(&o));
        assert!(d.join("checkpoint.bin").exists());
        let node = d.join("node_23.csv");
        let mut t = std::fs::read(&node).unwrap();
        t.extend_from_slice(b"0.59,1.2345");
        std::fs::write(&node, t).unwrap();
        let o = resume(&d);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        assert_same_as_reference(&d);
        let r = &summary(&d)["resumes"][0];
        assert!(r["bytes_cut"].as_u64().unwrap() >= 11, "{r}");
        assert_eq!(
            r["stopped"]["reason"],
            "unknown (killed, or the machine stopped)"
        );
    }
}

#[test]
fn a_kill_while_writing_a_checkpoint_leaves_the_previous_one() {
    // Killed half-way through the temporary file of the 3rd checkpoint (step 0 is the
    // 1st): checkpoint.bin is still the 2nd, whole, and the restart goes on from it.
    let (_dir, d, o) = stopped_run("torn", "checkpoint:3", "0.01");
    assert_eq!(o.status.code(), None, "{}", text(&o));
    assert!(d.join("checkpoint.bin.tmp").exists());
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_same_as_reference(&d);
    assert!(!d.join("checkpoint.bin.tmp").exists());
}

/// Starts a run and freezes it (SIGSTOP) as soon as its first checkpoint (step 0) is
/// written: a signal sent then lands during the run on any machine.
fn frozen_run(name: &str) -> (TempDir, PathBuf, Child) {
    let dir = tmp(name);
    let d = dir.join("out");
    let child = bin()
        .args([
            DECK,
            "-q",
            "--checkpoint",
            "0.05",
            "-o",
            d.to_str().unwrap(),
        ])
        .env_remove("MECANO_FAILPOINT")
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let t0 = Instant::now();
    while !d.join("checkpoint.bin").exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "no first checkpoint"
        );
        std::thread::sleep(Duration::from_micros(200));
    }
    // SAFETY: signals to our own child.
    unsafe { libc::kill(pid, libc::SIGSTOP) };
    (dir, d, child)
}

fn signal(child: &Child, sig: libc::c_int) {
    // SAFETY: signals to our own child.
    unsafe { libc::kill(child.id() as libc::pid_t, sig) };
}

#[test]
fn ctrl_c_from_outside_stops_cleanly_and_resumes() {
    let (_dir, d, mut child) = frozen_run("outside");
    signal(&child, libc::SIGINT);
    signal(&child, libc::SIGCONT);
    let st = child.wait().unwrap();
    assert_eq!(st.code(), Some(130));
    assert_whole_rows(&d);
    assert_eq!(summary(&d)["stop"]["at_step_end"], true);
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_same_as_reference(&d);
}

#[test]
fn a_second_signal_ends_within_the_step_with_whole_rows_and_the_last_checkpoint_resumes() {
    let (_dir, d, mut child) = frozen_run("twice");
    // Two different signals: a stopped process holds one pending signal of each kind.
    signal(&child, libc::SIGINT);
    signal(&child, libc::SIGTERM);
    signal(&child, libc::SIGCONT);
    let st = child.wait().unwrap();
    assert_eq!(st.code(), Some(130));
    assert_whole_rows(&d);
    let s = summary(&d);
    assert_eq!(s["stop"]["reason"], "interrupted");
    // Depending on when the thread saw the two signals, the run stopped at a pause or
    // within a step; within a step, no checkpoint was written, and the one of step 0 is
    // where the restart goes on.
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_same_as_reference(&d);
}

#[test]
fn resume_refuses_an_edited_deck_another_deck_a_complete_or_failed_run_and_a_missing_checkpoint() {
    let base = tmp("refuse");
    let deck = base.join("deck.dat");
    std::fs::copy(DECK, &deck).unwrap();
    let d = base.join("out");
    let o = run(
        &[deck.to_str().unwrap(), "-q", "-o", d.to_str().unwrap()],
        Some("signal:INT:1000"),
    );
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    // An edit that changes no number (a comment) is still another text: refused.
    let mut t = std::fs::read_to_string(&deck).unwrap();
    t.push_str("! edited\n");
    std::fs::write(&deck, &t).unwrap();
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("its text differs"), "{}", text(&o));
    // Another integrator (issue 26): refused, naming both.
    let t = std::fs::read_to_string(DECK).unwrap().replace(
        "ANALYSIS DYNAMIC ALPHA -0.1",
        "ANALYSIS DYNAMIC GENALPHA RHOINF 0.8",
    );
    assert!(t.contains("GENALPHA"));
    std::fs::write(&deck, &t).unwrap();
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("written by the integrator hht:-0.1")
            && text(&o).contains("now asks for genalpha:0.8"),
        "{}",
        text(&o)
    );
    // Another deck given with --deck: refused.
    let o = run(
        &[
            "resume",
            d.to_str().unwrap(),
            "--deck",
            "decks/pendulum.dat",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("its text differs"), "{}", text(&o));
    // The original text again: accepted, and the result is the reference's.
    std::fs::copy(DECK, &deck).unwrap();
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // A complete run: refused.
    let o = resume(&d);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("complete"), "{}", text(&o));
    // A directory without a checkpoint, and one that does not exist.
    let empty = base.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = resume(&empty);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("no checkpoint"), "{}", text(&o));
    let o = resume(&base.join("nowhere"));
    assert_eq!(o.status.code(), Some(2));
    // A failed run keeps no checkpoint (a restart is bit for bit: it would fail again at
    // the same step) and is refused, saying so.
    let failed = base.join("failed");
    let o = run(
        &[
            "decks/stab_diverge.dat",
            "-q",
            "-o",
            failed.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(!failed.join("checkpoint.bin").exists());
    let o = resume(&failed);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("would fail again"), "{}", text(&o));
    // A damaged checkpoint: refused by its checksum, not decoded.
    let (_dir2, d2, o) = stopped_run("damaged", "signal:INT:100", "60");
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    let ck = d2.join("checkpoint.bin");
    let mut b = std::fs::read(&ck).unwrap();
    let mid = b.len() / 2;
    b[mid] ^= 1;
    std::fs::write(&ck, b).unwrap();
    let o = resume(&d2);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("checksum"), "{}", text(&o));
}

/// All files under `dir` (relative path → bytes), `summary.json` left out.
fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().unwrap() != "summary.json" {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

#[test]
fn a_paraview_series_is_resumed_too() {
    // The deck writing a VTK frame every 100 steps: after a SIGKILL at step 3000 (frames
    // written after the last checkpoint are written again) the series is the same,
    // frame files and model.pvd, byte for byte.
    let base = tmp("vtk");
    let source = std::fs::read_to_string(DECK)
        .unwrap()
        .replace("EVERY 10", "EVERY 100 VTK");
    assert!(source.contains("EVERY 100 VTK"));
    let deck = base.join("vtk.dat");
    std::fs::write(&deck, source).unwrap();
    let (a, b) = (base.join("a"), base.join("b"));
    let o = run(
        &[
            deck.to_str().unwrap(),
            "-q",
            "--checkpoint",
            "0",
            "-o",
            a.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = run(
        &[
            deck.to_str().unwrap(),
            "-q",
            "--checkpoint",
            "0.01",
            "-o",
            b.to_str().unwrap(),
        ],
        Some("signal:KILL:3000"),
    );
    assert_eq!(o.status.code(), None, "{}", text(&o));
    let o = resume(&b);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let (ta, tb) = (tree(&a), tree(&b));
    assert!(ta.keys().any(|k| k.ends_with(".vtu")) && ta.contains_key("model.pvd"));
    assert_eq!(ta.keys().collect::<Vec<_>>(), tb.keys().collect::<Vec<_>>());
    for (k, v) in &ta {
        assert!(tb[k] == *v, "{k} differs");
    }
}

/// A run's `--set` overrides and `--refine` factor are part of its identity: `resume`
/// rebuilds the very model the run had (refined, with the overridden values) and the files
/// come out byte for byte as those of the same run never stopped.
#[test]
fn resume_rebuilds_a_refined_run_with_its_parameter_overrides() {
    let base = tmp("variant");
    let (clean, stopped) = (base.join("clean"), base.join("stopped"));
    let args = |d: &Path| -> Vec<String> {
        [
            "decks/pendulum_sweep.dat",
            "-q",
            "--set",
            "T=0.08",
            "--set",
            "E=2.1e10",
            "--refine",
            "2",
            "-o",
            d.to_str().unwrap(),
        ]
        .map(String::from)
        .to_vec()
    };
    let a = args(&clean);
    let o = run(&a.iter().map(String::as_str).collect::<Vec<_>>(), None);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let a = args(&stopped);
    let o = run(
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        Some("signal:INT:300"),
    );
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    let o = resume(&stopped);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let files = csv_files(&clean);
    assert!(files.len() >= 3, "{files:?}");
    for f in files {
        assert_eq!(
            std::fs::read(clean.join(&f)).unwrap(),
            std::fs::read(stopped.join(&f)).unwrap(),
            "{f} differs"
        );
    }
    assert_eq!(summary(&stopped)["refine"], 2);
}

/// The scratch directories of these tests are removed also when a test fails: a guard
/// dropped while a panic unwinds removes its directory and what it holds.
#[test]
fn a_scratch_directory_is_removed_when_its_test_panics() {
    let path = std::panic::catch_unwind(|| {
        let dir = tmp("panics");
        std::fs::write(dir.join("out.csv"), "t\n0\n").expect("write");
        std::panic::panic_any(dir.path().to_path_buf())
    })
    .expect_err("panicked")
    .downcast::<PathBuf>()
    .expect("the path");
    assert!(!path.exists(), "{} left behind", path.display());
}
