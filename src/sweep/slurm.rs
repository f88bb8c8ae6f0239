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

/// The script's text (`exe`: the mecano-rs binary the tasks run).
pub fn script(plan: &Plan, args: &SweepArgs, exe: &Path) -> String {
    let n = plan.cases.len();
    let chunk = args.chunk.max(1);
    let tasks = n.div_ceil(chunk);
    let out = absolute(&plan.out);
    let cwd = std::env::current_dir().unwrap_or_default();
    let stem = plan
        .path
        .file_stem()
        .map_or_else(|| "sweep".into(), |s| s.to_string_lossy().into_owned());
    let mut s = String::from("#!/bin/bash\n");
    let _ = writeln!(
        s,
        "# Written by `mecano-rs sweep {} --emit slurm`: {n} cases, {chunk} per array task.",
        plan.path.display()
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
    let _ = writeln!(s, "#SBATCH --chdir={}", cwd.display());
    let _ = writeln!(s, "#SBATCH --output={}/slurm/%A_%a.out", out.display());
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

/// Writes `<out>/sweep.sbatch` (and creates `<out>/slurm/` for the logs); returns its path.
pub fn emit(plan: &Plan, args: &SweepArgs) -> Result<PathBuf, SweepError> {
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
