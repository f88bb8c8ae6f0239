//! The command-line application behind the thin `main.rs`: check a deck, run it, report.
//!
//! Exit codes: 0 done, 1 the run failed (diagnosis printed, outputs kept and marked
//! incomplete), 2 bad input (deck errors, unsupported elements; nothing written).

use crate::deck;
use crate::model::Model;
use crate::output::Writer;
use crate::output::vtk::{Fanout, VtkWriter};
use crate::solver::{self, RunReport};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

/// Exit code: the run completed.
pub const EXIT_OK: u8 = 0;
/// Exit code: the run failed (no convergence, non-finite state, output error).
pub const EXIT_FAILED: u8 = 1;
/// Exit code: bad input (the deck has errors or uses unsupported elements).
pub const EXIT_BAD_INPUT: u8 = 2;

/// Options of a run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Output directory (default `out/<deck name>/`, or the deck's OUTPUT DIR).
    pub out_dir: Option<PathBuf>,
    /// No progress bar, no summary on standard output.
    pub quiet: bool,
    /// Parameter overrides (`--set name=value`), in command-line order (the last wins).
    pub set: Vec<(String, f64)>,
}

/// Reads `name=value` (`--set`): a parameter name and a number or an expression of numbers
/// (`E=2.1e11`, `h=1e-4/2`).
pub fn parse_set(arg: &str) -> Result<(String, f64), String> {
    let (name, value) = arg
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found `{arg}`"))?;
    let name = name.trim().trim_start_matches('$');
    let valid = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid {
        return Err(format!("`{name}` is not a parameter name"));
    }
    let v = deck::eval_constant(value.trim())
        .ok_or_else(|| format!("`{value}` is not a finite number or expression of numbers"))?;
    Ok((name.to_string(), v))
}

/// Parses a deck, printing diagnostics on error.
pub fn load(path: &Path) -> Result<Model, u8> {
    load_with(path, &[])
}

/// Parses a deck with parameter overrides, printing diagnostics on error.
pub fn load_with(path: &Path, set: &[(String, f64)]) -> Result<Model, u8> {
    deck::load_deck_with(path, set).map_err(|errs| {
        eprintln!("{:?}", miette::Report::new(errs));
        EXIT_BAD_INPUT
    })
}

/// `mecano-rs --check DECK`: parse, validate, build the system, print the summary and the
/// parameters with their values (`--set` overrides marked).
pub fn check(path: &Path, set: &[(String, f64)]) -> u8 {
    let model = match load_with(path, set) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let mut out = std::io::stdout().lock();
    // A closed pipe (`mecano-rs --check deck | head`) is not an error of ours: ignore it.
    let _ = write!(out, "{}", model.summary());
    if !model.parameters.is_empty() {
        let _ = writeln!(out, "parameters:  {}", model.parameters.len());
        for (name, v) in &model.parameters {
            let mark = if set.iter().any(|(n, _)| n == name) {
                "   (--set)"
            } else {
                ""
            };
            let _ = writeln!(out, "  {name} = {v:?}{mark}");
        }
    }
    match solver::prepare(&model) {
        Ok(integ) => {
            let _ = writeln!(
                out,
                "equations:   {} ({} nodal, {} multipliers; {} non-zeros in the iteration matrix)",
                integ.sys.n_eq(),
                integ.sys.n_node_eq,
                integ.sys.n_eq() - integ.sys.n_node_eq,
                integ.sys.matrix.nnz()
            );
            EXIT_OK
        }
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            EXIT_BAD_INPUT
        }
    }
}

/// The default output directory of a deck: the deck's `OUTPUT DIR` or `out/<deck stem>`.
pub fn default_out_dir(path: &Path, model: &Model) -> PathBuf {
    if let Some(d) = &model.output.dir {
        return PathBuf::from(d);
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "deck".into());
    PathBuf::from("out").join(stem)
}

/// Runs a parsed model, writing into `dir`. Returns the report (with a failure if the run
/// stopped early) or an exit code for errors before the run.
pub fn run_model(
    model: &Model,
    deck_name: &str,
    dir: &Path,
    quiet: bool,
) -> Result<RunReport, (u8, String)> {
    let mut integ = solver::prepare(model).map_err(|e| (EXIT_BAD_INPUT, e.to_string()))?;
    let mut writer = Writer::create(dir, deck_name, model, &integ.sys)
        .map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?;
    let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
        let pb = indicatif::ProgressBar::new(1000);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {msg} [{elapsed} elapsed, ~{eta} left]",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        pb
    });
    if let Some(pb) = bar.clone() {
        writer.progress = Some(Box::new(move |t, end, st| {
            pb.set_position(((t / end) * 1000.0) as u64);
            pb.set_message(format!(
                "t = {t:.4} s, {} steps, {} Newton iterations",
                st.steps, st.newton_iterations
            ));
        }));
    }
    let mut vtk = if model.output.vtk {
        Some(
            VtkWriter::create(dir, model, &integ.sys)
                .map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?,
        )
    } else {
        None
    };
    let result = match vtk.as_mut() {
        Some(v) => solver::run_prepared(model, &mut integ, &mut Fanout(vec![&mut writer, v])),
        None => solver::run_prepared(model, &mut integ, &mut writer),
    };
    if let Some(pb) = bar {
        pb.finish_and_clear();
    }
    let mut report = match result {
        Ok(r) => r,
        Err(solver::RunError::Output(e)) => {
            // The writer refused a row (non-finite value) or the disk failed: the run
            // stops here, its files marked incomplete.
            RunReport {
                stats: integ.stats,
                time: integ.t,
                failure: Some(solver::Failure {
                    time: integ.t,
                    step: 0.0,
                    reason: solver::FailureReason::NotFinite,
                    residual_history: vec![],
                    worst: format!("output: {e}"),
                    worst_value: 0.0,
                    reference_force: 0.0,
                    diagnoses: Box::default(),
                }),
            }
        }
        Err(e) => return Err((EXIT_BAD_INPUT, e.to_string())),
    };
    report.stats = integ.stats;
    writer
        .finish(&integ, &report)
        .map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?;
    if let Some(v) = vtk.as_mut() {
        v.finish(&integ)
            .map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?;
    }
    Ok(report)
}

/// `mecano-rs DECK`: parse, run, write; returns the exit code.
pub fn run(path: &Path, opts: &RunOptions) -> u8 {
    let model = match load_with(path, &opts.set) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| default_out_dir(path, &model));
    match run_model(&model, &path.display().to_string(), &dir, opts.quiet) {
        Ok(report) => {
            let st = &report.stats;
            let per = if st.steps > 0 {
                st.newton_iterations as f64 / st.steps as f64
            } else {
                0.0
            };
            match &report.failure {
                None => {
                    if !opts.quiet {
                        let _ = writeln!(
                            std::io::stdout(),
                            "{}: done, t = {:.6} s, {} steps ({} rejected), {:.2} Newton iterations/step, {:.3} s CPU; output in {}",
                            path.display(),
                            report.time,
                            st.steps,
                            st.rejected_steps,
                            per,
                            st.cpu_seconds,
                            dir.display()
                        );
                    }
                    EXIT_OK
                }
                Some(f) => {
                    eprintln!("error: {}: the run stopped.\n{f}", path.display());
                    eprintln!(
                        "  histories up to t = {:.6e} s are kept in {} and marked incomplete (summary.json: \"complete\": false)",
                        report.time,
                        dir.display()
                    );
                    EXIT_FAILED
                }
            }
        }
        Err((code, msg)) => {
            eprintln!("error: {}: {msg}", path.display());
            code
        }
    }
}
