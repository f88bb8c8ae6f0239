//! `mecano-rs sweep PLAN`: parameter studies — a plan (TOML, `sweeps/`) names a deck, the
//! deck parameters to vary and the quantities of interest; each case runs in its own
//! directory; the sweep assembles `sweep.csv`, `statistics.csv` and figures.
//!
//! * locally (default): the pending cases run in parallel on `--jobs` threads (all cores by
//!   default), each in-process, with a progress bar over cases; then the sweep is collected;
//! * on Slurm: `--emit slurm` writes a job-array script (one array task per chunk of
//!   `--chunk` cases) that runs `mecano-rs sweep PLAN --case FIRST-LAST` on the nodes, and
//!   `--collect` assembles the same files from the case directories afterwards.
//!
//! Running a plan again skips its finished cases (`runner.rs`). Modules: `plan` (the plan
//! and its cases), `quantity` (quantities of interest), `runner` (cases), `collect`
//! (sweep.csv, statistics), `figures`, `slurm` (the job-array script).

pub mod collect;
pub mod figures;
pub mod plan;
pub mod quantity;
pub mod runner;
pub mod slurm;

use crate::app::{EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK};
use plan::Plan;
use std::io::Write;
use std::path::PathBuf;

/// Collects a sweep (sweep.csv, statistics.csv) and draws its figures: the data flows
/// plan → runner → collect → figures, and only this top level calls the last two.
pub fn collect_and_draw(plan: &Plan) -> Result<collect::Collected, SweepError> {
    let mut c = collect::collect(plan)?;
    c.files.extend(figures::draw(plan, &c.records)?);
    Ok(c)
}

/// What can go wrong in a sweep (the cases' own failures are recorded, not errors).
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The plan file is not a valid plan.
    #[error("plan {path}: {msg}")]
    Plan {
        /// The plan file.
        path: PathBuf,
        /// What is wrong.
        msg: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The operating system's reason.
        reason: String,
    },
    /// SIGINT or SIGTERM stopped the sweep: the cases under way wrote a checkpoint and
    /// go on from it when the plan runs again.
    #[error(
        "interrupted: the cases under way were checkpointed; run the same command again to go on"
    )]
    Interrupted,
    /// A scheduler option (or path) the script cannot hold (bad input: exit 2).
    #[error("{0}")]
    Slurm(slurm::OptionError),
    /// `--case` names cases the plan does not have, or is malformed.
    #[error("--case {spec}: {msg}")]
    CaseSpec {
        /// The argument.
        spec: String,
        /// What is wrong.
        msg: String,
    },
}

/// The scheduler `--emit` writes a script for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Emit {
    /// A Slurm job array (`sbatch`).
    Slurm,
}

/// Arguments of `mecano-rs sweep`.
#[derive(Debug, Clone, clap::Args)]
pub struct SweepArgs {
    /// The plan (TOML; see docs/sweeps.md).
    pub plan: PathBuf,
    /// The sweep's output directory (default: the plan's `out`, else out/sweeps/<plan name>).
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Cases run at once, at least 1 (default: all cores).
    #[arg(short = 'j', long, value_name = "N", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    pub jobs: Option<usize>,
    /// Print the cases (index and parameter values), run nothing.
    #[arg(long)]
    pub list: bool,
    /// Run only these cases in this process, without collecting: `7`, `0-9`, `1,4,10-12`
    /// (what a Slurm array task runs).
    #[arg(long, value_name = "CASES")]
    pub case: Option<String>,
    /// Assemble sweep.csv, statistics.csv and the figures from the case directories; run
    /// nothing.
    #[arg(long)]
    pub collect: bool,
    /// Write a job script for a scheduler instead of running.
    #[arg(long, value_enum)]
    pub emit: Option<Emit>,
    /// Slurm: cases per array task.
    #[arg(long, default_value_t = 1, value_name = "K")]
    pub chunk: usize,
    /// Slurm: time limit of one array task (sbatch --time).
    #[arg(long, default_value = "01:00:00", value_name = "TIME")]
    pub time: String,
    /// Slurm: memory of one array task (sbatch --mem).
    #[arg(long, default_value = "1G", value_name = "MEM")]
    pub mem: String,
    /// Slurm: partition (sbatch --partition; default: the cluster's default).
    #[arg(long, value_name = "NAME")]
    pub partition: Option<String>,
    /// Slurm: most array tasks running at once (`--array=0-N%M`).
    #[arg(long, value_name = "M")]
    pub max_running: Option<usize>,
    /// No progress bar and no closing summary.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Parses `7`, `0-9`, `1,4,10-12` into case indices (each below `n`).
pub fn parse_cases(spec: &str, n: usize) -> Result<Vec<usize>, SweepError> {
    let err = |msg: String| SweepError::CaseSpec {
        spec: spec.to_string(),
        msg,
    };
    let mut out = Vec::new();
    for part in spec.split(',') {
        let num = |s: &str| {
            s.trim()
                .parse::<usize>()
                .map_err(|_| err(format!("`{s}` is not a case number")))
        };
        let (a, b) = match part.split_once('-') {
            Some((a, b)) => (num(a)?, num(b)?),
            None => (num(part)?, num(part)?),
        };
        if a > b || b >= n {
            return Err(err(format!(
                "`{part}`: the plan has cases 0 to {}",
                n.saturating_sub(1)
            )));
        }
        out.extend(a..=b);
    }
    Ok(out)
}

/// Why the sweep's output directory `dir` cannot be used (a file, `/dev/null`, a path
/// below a file), as a run says it; `None` when it is a directory or can be created.
fn unusable_out(dir: &std::path::Path) -> Option<String> {
    if dir.exists() && !dir.is_dir() {
        return Some(format!(
            "the output path {} exists and is not a directory",
            dir.display()
        ));
    }
    // The nearest existing ancestor must be a directory (`out/file/sub`: below a file).
    let mut p = dir.parent();
    while let Some(a) = p.filter(|a| !a.as_os_str().is_empty()) {
        if a.exists() {
            return (!a.is_dir()).then(|| {
                format!(
                    "the output directory {} cannot be used: {} is not a directory",
                    dir.display(),
                    a.display()
                )
            });
        }
        p = a.parent();
    }
    None
}

fn fmt_values(plan: &Plan, i: usize) -> String {
    let mut b = ryu::Buffer::new();
    plan.params
        .iter()
        .zip(&plan.cases[i])
        .map(|(p, v)| format!("{}={}", p.name, b.format(*v)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `mecano-rs sweep`: returns the exit code (0 every case ran and is `ok`, or the script
/// was written; 1 a case is not `ok` — failed, bad input, a quantity error or missing —
/// or cases could not be run or files not written; 2 bad plan, deck or scheduler option;
/// 130 interrupted by SIGINT/SIGTERM, the cases under way checkpointed).
pub fn run(args: &SweepArgs) -> u8 {
    let plan = match Plan::load(&args.plan, args.out.as_deref()) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    // The deck and the plan's parameter names, checked once with case 0's values.
    if let Err(code) = crate::app::load_with(&plan.deck, &plan.overrides(0)) {
        eprintln!(
            "error: plan {}: the deck does not accept the plan's parameters (above)",
            plan.path.display()
        );
        return code;
    }
    // An output path that cannot be a directory is bad input, as for a run (exit 2, before
    // anything is run or written).
    if !args.list
        && let Some(why) = unusable_out(&plan.out)
    {
        eprintln!("error: plan {}: {why}", plan.path.display());
        return EXIT_BAD_INPUT;
    }
    let mut out = std::io::stdout().lock();
    if args.list {
        for i in 0..plan.cases.len() {
            if writeln!(out, "{i} {}", fmt_values(&plan, i)).is_err() {
                break; // a closed pipe (`| head`)
            }
        }
        return EXIT_OK;
    }
    if let Some(Emit::Slurm) = args.emit {
        return match slurm::emit(&plan, args) {
            Ok(script) => {
                let _ = writeln!(
                    out,
                    "{}: {} cases in {} array tasks\nsubmit:  sbatch {}\nthen:    mecano-rs sweep {} -o {} --collect",
                    script.display(),
                    plan.cases.len(),
                    plan.cases.len().div_ceil(args.chunk.max(1)),
                    script.display(),
                    args.plan.display(),
                    plan.out.display()
                );
                EXIT_OK
            }
            Err(e @ SweepError::Slurm(_)) => {
                eprintln!("error: {e}");
                EXIT_BAD_INPUT
            }
            Err(e) => {
                eprintln!("error: {e}");
                EXIT_FAILED
            }
        };
    }
    if !args.collect {
        let which: Vec<usize> = match &args.case {
            Some(spec) => match parse_cases(spec, plan.cases.len()) {
                Ok(w) => w,
                Err(e) => {
                    eprintln!("error: {e}");
                    return EXIT_BAD_INPUT;
                }
            },
            None => (0..plan.cases.len()).collect(),
        };
        let default_jobs = if args.case.is_some() {
            1
        } else {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        };
        let jobs = args.jobs.unwrap_or(default_jobs).max(1);
        let start = std::time::Instant::now();
        let any_not_ok = match runner::run_local(
            &plan,
            &which,
            jobs,
            args.quiet,
            &crate::app::interrupts(),
        ) {
            Ok((ran, not_ok)) => {
                if !args.quiet {
                    let _ = writeln!(
                        out,
                        "{ran} of {} cases run ({} already finished), {not_ok} not ok, {:.1} s on {jobs} jobs",
                        which.len(),
                        which.len() - ran,
                        start.elapsed().as_secs_f64()
                    );
                }
                not_ok > 0
            }
            Err(SweepError::Interrupted) => {
                eprintln!("{}: {}", args.plan.display(), SweepError::Interrupted);
                return crate::app::EXIT_INTERRUPTED;
            }
            Err(e) => {
                eprintln!("error: {e}");
                return EXIT_FAILED;
            }
        };
        if args.case.is_some() {
            return if any_not_ok { EXIT_FAILED } else { EXIT_OK };
        }
    }
    match collect_and_draw(&plan) {
        Ok(c) => {
            let count = |s: runner::Status| c.records.iter().filter(|r| r.status == s).count();
            let missing = count(runner::Status::Missing);
            if !args.quiet {
                let _ = writeln!(
                    out,
                    "{}: {} cases: {} ok, {} failed, {} bad input, {} quantity errors, {} missing",
                    plan.out.join("sweep.csv").display(),
                    c.records.len(),
                    count(runner::Status::Ok),
                    count(runner::Status::Failed),
                    count(runner::Status::BadInput),
                    count(runner::Status::QuantityError),
                    missing
                );
                let _ = write!(
                    out,
                    "{}",
                    crate::safe_file::read_text(
                        &plan.out.join("statistics.csv"),
                        crate::safe_file::MAX_TEXT_BYTES
                    )
                    .unwrap_or_default()
                );
            }
            // Issue 28 §5: a sweep whose cases failed (or whose quantities are missing)
            // does not report success.
            let ok = count(runner::Status::Ok);
            if ok < c.records.len() {
                EXIT_FAILED
            } else {
                EXIT_OK
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            EXIT_FAILED
        }
    }
}

#[cfg(test)]
mod tests {
    use super::parse_cases;

    #[test]
    fn case_specs() {
        assert_eq!(parse_cases("3", 5).expect("ok"), [3]);
        assert_eq!(parse_cases("0-2,4", 5).expect("ok"), [0, 1, 2, 4]);
        assert!(parse_cases("5", 5).is_err());
        assert!(parse_cases("3-1", 5).is_err());
        assert!(parse_cases("a", 5).is_err());
    }
}
