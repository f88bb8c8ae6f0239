//! `--emit slurm`: a Slurm job-array script for a plan (`<out>/sweep.sbatch`).
//!
//! Array task `t` runs cases `t·K … min((t+1)·K, N) − 1` (K = `--chunk`) with
//! `mecano-rs sweep PLAN -o OUT --case FIRST-LAST`, one case after the other on one CPU;
//! resources from the options (`--time`, `--mem`, `--partition`, `--max-running`). Paths
//! (binary, plan, output, working directory) are absolute: the nodes must see the same
//! file system (as on any cluster with a shared home). A task killed by the time limit
//! leaves its case unfinished; resubmitting the script runs the unfinished cases again
//! (finished ones are skipped), so a sweep completes by resubmission. Logs go to
//! `<out>/slurm/<job>_<task>.out`.
//!
//! Nothing reaches the script unchecked (issue 28 §3): [`validate`] holds every scheduler
//! option to Slurm's own syntax (sbatch(1): `--time` in minutes, `MM:SS`, `HH:MM:SS`,
//! `D-HH`, `D-HH:MM`, `D-HH:MM:SS`; `--mem` an integer with an optional K, M, G or T
//! suffix; `--partition` a comma-separated list of names of letters, digits, `_`, `-`,
//! `.`), refuses `--chunk 0` and `--max-running 0`, and refuses paths that a `#SBATCH`
//! line cannot hold (control characters, `"`, `\`, `%`); paths in directives are
//! double-quoted, paths in the command single-quoted, the job name keeps only safe
//! characters.

use super::plan::Plan;
use super::{SweepArgs, SweepError};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Single-quotes `s` for the shell.
fn quote(s: &Path) -> String {
    format!("'{}'", s.display().to_string().replace('\'', "'\\''"))
}

/// A scheduler option (or path) that does not follow Slurm's syntax.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{option} `{value}` refused: expected {expected}")]
pub struct OptionError {
    /// The option (`--time`, ...) or the path's role.
    pub option: &'static str,
    /// The value, shortened and with control characters escaped.
    pub value: String,
    /// What Slurm accepts there.
    pub expected: &'static str,
}

fn refuse(option: &'static str, value: &str, expected: &'static str) -> OptionError {
    let value: String = value.escape_debug().collect();
    OptionError {
        option,
        value: crate::deck::short(&value),
        expected,
    }
}

fn digits(s: &str) -> bool {
    !s.is_empty() && s.len() <= 9 && s.bytes().all(|b| b.is_ascii_digit())
}

/// Slurm's time formats: `MM`, `MM:SS`, `HH:MM:SS`, `D-HH`, `D-HH:MM`, `D-HH:MM:SS`.
pub fn valid_time(t: &str) -> bool {
    let (days, rest) = match t.split_once('-') {
        Some((d, r)) => (Some(d), r),
        None => (None, t),
    };
    let parts: Vec<&str> = rest.split(':').collect();
    let ok_parts = parts.iter().all(|p| digits(p));
    match days {
        Some(d) => digits(d) && ok_parts && (1..=3).contains(&parts.len()),
        None => ok_parts && (1..=3).contains(&parts.len()),
    }
}

/// Slurm's memory: an integer with an optional K, M, G or T suffix (megabytes without).
pub fn valid_mem(m: &str) -> bool {
    let n = m
        .strip_suffix(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't'])
        .unwrap_or(m);
    digits(n)
}

/// Slurm's partition names: a comma-separated list of names of letters, digits, `_`,
/// `-`, `.`.
pub fn valid_partition(p: &str) -> bool {
    p.len() <= 256
        && p.split(',').all(|n| {
            !n.is_empty()
                && n.bytes()
                    .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.'))
        })
}

/// A path a `#SBATCH` line can hold between double quotes.
fn valid_path(p: &Path) -> bool {
    let s = p.to_string_lossy();
    !s.chars()
        .any(|c| c.is_control() || matches!(c, '"' | '\\' | '%' | '\u{FFFD}'))
}

/// Checks every value the script would hold; nothing is written when one is refused.
pub fn validate(plan: &Plan, args: &SweepArgs) -> Result<(), OptionError> {
    if !valid_time(&args.time) {
        return Err(refuse(
            "--time",
            &args.time,
            "a Slurm time: MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS (digits)",
        ));
    }
    if !valid_mem(&args.mem) {
        return Err(refuse(
            "--mem",
            &args.mem,
            "a Slurm memory size: an integer with an optional K, M, G or T suffix",
        ));
    }
    if let Some(p) = &args.partition
        && !valid_partition(p)
    {
        return Err(refuse(
            "--partition",
            p,
            "Slurm partition names (letters, digits, _ - .), separated by commas",
        ));
    }
    if args.chunk == 0 {
        return Err(refuse("--chunk", "0", "at least 1 case per array task"));
    }
    if args.max_running == Some(0) {
        return Err(refuse("--max-running", "0", "at least 1 task at once"));
    }
    let cwd = std::env::current_dir().unwrap_or_default();
    for (what, p) in [
        ("the output directory", absolute(&plan.out)),
        ("the working directory", cwd),
    ] {
        if !valid_path(&p) {
            return Err(refuse(
                what,
                &p.to_string_lossy(),
                "a path without control characters, `\"`, `\\` or `%` (a #SBATCH line holds it)",
            ));
        }
    }
    Ok(())
}

/// The script's text (`exe`: the mecano-rs binary the tasks run). Call [`validate`]
/// first: the values are written as they are.
pub fn script(plan: &Plan, args: &SweepArgs, exe: &Path) -> String {
    let n = plan.cases.len();
    let chunk = args.chunk.max(1);
    let tasks = n.div_ceil(chunk);
    let out = absolute(&plan.out);
    let cwd = std::env::current_dir().unwrap_or_default();
    let stem: String = plan
        .path
        .file_stem()
        .map_or_else(|| "sweep".into(), |s| s.to_string_lossy().into_owned())
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let mut s = String::from("#!/bin/bash\n");
    let _ = writeln!(
        s,
        "# Written by `mecano-rs sweep {:?} --emit slurm`: {n} cases, {chunk} per array task.",
        plan.path.display().to_string()
    );
    let _ = writeln!(s, "#SBATCH --job-name=sweep-{stem}");
    let array = match args.max_running {
        Some(m) => format!("0-{}%{m}", tasks - 1),
        None => format!("0-{}", tasks - 1),
    };
    let _ = writeln!(s, "#SBATCH --array={array}");
    let _ = writeln!(s, "#SBATCH --ntasks=1");
    let _ = writeln!(s, "#SBATCH --cpus-per-task=1");
    let _ = writeln!(s, "#SBATCH --time={}", args.time);
    let _ = writeln!(s, "#SBATCH --mem={}", args.mem);
    if let Some(p) = &args.partition {
        let _ = writeln!(s, "#SBATCH --partition={p}");
    }
    let _ = writeln!(s, "#SBATCH --chdir=\"{}\"", cwd.display());
    let _ = writeln!(s, "#SBATCH --output=\"{}/slurm/%A_%a.out\"", out.display());
    s.push_str("set -euo pipefail\n");
    let _ = writeln!(s, "N={n}\nCHUNK={chunk}");
    s.push_str("FIRST=$(( SLURM_ARRAY_TASK_ID * CHUNK ))\nLAST=$(( FIRST + CHUNK - 1 ))\n");
    s.push_str("if (( LAST >= N )); then LAST=$(( N - 1 )); fi\n");
    let _ = writeln!(
        s,
        "exec {} sweep {} -o {} --case \"$FIRST-$LAST\" --jobs 1 --quiet",
        quote(exe),
        quote(&absolute(&plan.path)),
        quote(&out)
    );
    s
}

/// Writes `<out>/sweep.sbatch` (and creates `<out>/slurm/` for the logs) once
/// [`validate`] accepts every value; returns its path.
pub fn emit(plan: &Plan, args: &SweepArgs) -> Result<PathBuf, SweepError> {
    validate(plan, args).map_err(SweepError::Slurm)?;
    let io = |p: &Path, e: std::io::Error| SweepError::Io {
        path: p.to_path_buf(),
        reason: e.to_string(),
    };
    let logs = plan.out.join("slurm");
    std::fs::create_dir_all(&logs).map_err(|e| io(&logs, e))?;
    let exe = std::env::current_exe().map_err(|e| io(Path::new("mecano-rs"), e))?;
    let file = plan.out.join("sweep.sbatch");
    std::fs::write(&file, script(plan, args, &exe)).map_err(|e| io(&file, e))?;
    Ok(file)
}
