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
    /// `--refine k`: divide every beam into k times its elements (0 or 1: as written).
    pub refine: u32,
}

/// Parses a deck, printing diagnostics on error.
pub fn load(path: &Path) -> Result<Model, u8> {
    deck::load_deck(path).map_err(|errs| {
        eprintln!("{:?}", miette::Report::new(errs));
        EXIT_BAD_INPUT
    })
}

/// Parses a deck and refines its mesh by `refine` ([`Model::refine`]; 0 or 1: as
/// written), printing diagnostics on error.
pub fn load_refined(path: &Path, refine: u32) -> Result<Model, u8> {
    let mut model = load(path)?;
    if refine > 1 {
        model.refine(refine).map_err(|e| {
            eprintln!("error: {}: --refine {refine}: {e}", path.display());
            EXIT_BAD_INPUT
        })?;
    }
    Ok(model)
}

/// `mecano-rs --check DECK [--refine k]`: parse, validate, refine, build the system, print
/// the summary (with the nodes and elements generated).
pub fn check(path: &Path, refine: u32) -> u8 {
    let model = match load_refined(path, refine) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let mut out = std::io::stdout().lock();
    // A closed pipe (`mecano-rs --check deck | head`) is not an error of ours: ignore it.
    let _ = write!(out, "{}", model.summary());
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
    run_model_refined(model, deck_name, dir, quiet, 1)
}

/// [`run_model`] for a model refined by `refine` (recorded in `summary.json`).
pub fn run_model_refined(
    model: &Model,
    deck_name: &str,
    dir: &Path,
    quiet: bool,
    refine: u32,
) -> Result<RunReport, (u8, String)> {
    let mut integ = solver::prepare(model).map_err(|e| (EXIT_BAD_INPUT, e.to_string()))?;
    let mut writer = Writer::create(dir, deck_name, model, &integ.sys)
        .map_err(|e| (EXIT_FAILED, format!("{}: {e}", dir.display())))?;
    writer.refine = refine;
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
    let model = match load_refined(path, opts.refine) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| default_out_dir(path, &model));
    match run_model_refined(
        &model,
        &path.display().to_string(),
        &dir,
        opts.quiet,
        opts.refine.max(1),
    ) {
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
