//! The sweep's Slurm path on a real one-node Slurm (Debian's slurmctld, slurmd, munge),
//! brought up by `scripts/slurm-local.sh up` (which installs the packages when missing:
//! needs root, as CI has) and always taken down, also when the test fails.
//!
//! The 6-case plan `sweeps/bounce.toml` is emitted as a job array (3 tasks of 2 cases),
//! submitted with `sbatch --wait`, collected, and its sweep.csv compared with the same plan
//! run locally: equal in every column but the timing ones (`cpu_s` and the `cpu`
//! quantity, see `mecano::sweep::collect::timing_columns`). Then a task is "killed"
//! (one case's case.json removed, as a time limit leaves it) and the script resubmitted:
//! only that case runs again, and the result is the same.
//!
//! The cluster is brought up on the machine that runs the test (packages, /etc/slurm,
//! a munge key, the spool directories), so the test runs only when asked to with
//! `MECANO_SLURM_TEST=1` (`.ci/run` does, as a step of its own after `cargo test`); without
//! it, it says it is skipped and passes. The script refuses a Slurm configuration it did not
//! write (exit 3), so even opted in it cannot rewrite a cluster node's scheduler.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_mecano-rs");

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sh(cmd: &mut Command) -> (bool, String) {
    let o = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    let t = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), t)
}

/// Takes the cluster down when dropped (the test passed, failed or panicked).
struct Cluster;

impl Cluster {
    fn up() -> Cluster {
        let (ok, t) = sh(Command::new("bash")
            .arg(root().join("scripts/slurm-local.sh"))
            .arg("up"));
        let c = Cluster;
        assert!(
            ok,
            "scripts/slurm-local.sh up failed (needs root and apt):\n{t}"
        );
        c
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = sh(Command::new("bash")
            .arg(root().join("scripts/slurm-local.sh"))
            .arg("down"));
    }
}

fn without_timing(dir: &Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(dir.join("sweep.csv")).expect("sweep.csv");
    let header: Vec<String> = r
        .headers()
        .expect("header")
        .iter()
        .map(String::from)
        .collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&k| header[k] != "cpu_s" && header[k] != "cpu")
        .collect();
    let mut out = vec![keep.iter().map(|&k| header[k].clone()).collect()];
    for rec in r.records() {
        let rec = rec.expect("row");
        out.push(keep.iter().map(|&k| rec[k].to_string()).collect());
    }
    out
}

fn sweep(args: &[&str]) -> (bool, String) {
    sh(Command::new(BIN)
        .arg("sweep")
        .arg("sweeps/bounce.toml")
        .args(args)
        .current_dir(root()))
}

/// The opt-in: `MECANO_SLURM_TEST=1`.
const OPT_IN: &str = "MECANO_SLURM_TEST";

#[test]
fn a_slurm_job_array_gives_the_local_sweep_csv() {
    if std::env::var(OPT_IN).as_deref() != Ok("1") {
        eprintln!(
            "skipped: this test installs and starts Slurm on this machine \
             (scripts/slurm-local.sh); set {OPT_IN}=1 to run it (.ci/run does)"
        );
        return;
    }
    let base =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("slurm_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    let (local, remote) = (base.join("local"), base.join("slurm"));
    let (l, s) = (
        local.to_str().expect("utf-8"),
        remote.to_str().expect("utf-8"),
    );
    let (ok, t) = sweep(&["-o", l, "-q"]);
    assert!(ok, "{t}");

    let _cluster = Cluster::up();
    let (ok, t) = sweep(&[
        "-o", s, "--emit", "slurm", "--chunk", "2", "--mem", "200M", "--time", "00:05:00",
    ]);
    assert!(ok, "{t}");
    let script = remote.join("sweep.sbatch");
    let submit = |what: &str| {
        let (ok, t) = sh(Command::new("timeout")
            .arg("300")
            .arg("sbatch")
            .arg("--wait")
            .arg(&script));
        assert!(ok, "{what}: sbatch --wait failed:\n{t}");
    };
    submit("first submission");
    let (ok, t) = sweep(&["-o", s, "--collect", "-q"]);
    assert!(ok, "collect: {t}");
    assert_eq!(without_timing(&remote), without_timing(&local));
    assert_eq!(
        std::fs::read_dir(remote.join("slurm"))
            .map(|d| d.count())
            .unwrap_or(0),
        3,
        "one log per array task"
    );

    // A case left unfinished (as a task killed by its time limit leaves it) runs again
    // when the script is resubmitted; the finished ones are skipped.
    let case = remote.join("cases/0004");
    std::fs::remove_file(case.join("case.json")).expect("rm");
    let before = std::fs::metadata(remote.join("cases/0005/case.json"))
        .and_then(|m| m.modified())
        .expect("mtime");
    submit("resubmission");
    assert!(case.join("case.json").is_file());
    let after = std::fs::metadata(remote.join("cases/0005/case.json"))
        .and_then(|m| m.modified())
        .expect("mtime");
    assert_eq!(before, after, "a finished case was run again");
    let (ok, t) = sweep(&["-o", s, "--collect", "-q"]);
    assert!(ok, "{t}");
    assert_eq!(without_timing(&remote), without_timing(&local));
    let _ = std::fs::remove_dir_all(&base);
}
