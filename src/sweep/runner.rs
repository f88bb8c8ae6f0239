//! Running cases: one case in this process ([`run_case`], what a Slurm task runs), or all
//! pending cases of a plan on the local cores ([`run_local`]).
//!
//! A case runs the plan's deck with the case's parameter values (`--set`) into its own
//! directory, computes the quantities of interest from what the run wrote, and records it
//! all in `case.json`, written last (atomically): a case directory with a `case.json` of
//! the same parameter values and deck text (hash) is *finished* — completed or failed with its diagnosis — and
//! is skipped when the plan runs again; a directory without one was interrupted and is run
//! again ([`restart_incomplete_case`]). A failed case (Newton divergence, non-finite
//! values, values the deck rejects) is recorded and the others go on.

use super::SweepError;
use super::plan::Plan;
use crate::app;
use crate::interrupt::Interrupts;
use serde::{Deserialize, Serialize};
use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How a case ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The run reached its end.
    Ok,
    /// The run stopped (no convergence, non-finite state): its diagnosis is recorded.
    Failed,
    /// The deck rejected the case's values (e.g. a parameter out of a field's range).
    BadInput,
    /// A quantity could not be computed (the deck does not write the file or column).
    QuantityError,
    /// Not run yet (only in sweep.csv).
    Missing,
}

impl Status {
    /// The word written in sweep.csv.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
            Status::BadInput => "bad_input",
            Status::QuantityError => "quantity_error",
            Status::Missing => "missing",
        }
    }
}

/// What `case.json` records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseRecord {
    /// The case's index in the plan.
    pub case: usize,
    /// Parameter values, in plan order.
    pub values: Vec<f64>,
    /// How it ended.
    pub status: Status,
    /// Why it failed (empty when ok).
    pub diagnosis: String,
    /// Accepted steps.
    pub steps: u64,
    /// Time reached, s.
    pub time: f64,
    /// CPU (wall) seconds of the run (a timing).
    pub cpu_s: f64,
    /// Quantities of interest, in plan order (`None`: does not exist for this case).
    pub quantities: Vec<Option<f64>>,
    /// Their names (a plan whose quantities changed recomputes them from the case's files).
    #[serde(default)]
    pub quantity_names: Vec<String>,
    /// The hash of the deck's text it ran with (SHA-256, as a checkpoint names its deck).
    #[serde(default)]
    pub deck_hash: String,
}

/// The record of finished case `i`, if its directory holds one for its parameter values.
/// When the plan's quantities differ from those recorded, they are computed again from
/// the case's files (no rerun) and the record rewritten.
pub fn finished(plan: &Plan, i: usize) -> Option<CaseRecord> {
    let dir = plan.case_dir(i);
    let text =
        crate::safe_file::read_text(&dir.join("case.json"), crate::safe_file::MAX_TEXT_BYTES)
            .ok()?;
    let mut rec: CaseRecord = serde_json::from_str(&text).ok()?;
    if rec.values != plan.cases[i] || rec.deck_hash != plan.deck_hash {
        return None;
    }
    if rec.quantity_names != names(plan) {
        quantify(plan, &dir, &mut rec);
        write_record(&dir, &rec).ok()?;
    }
    Some(rec)
}

fn names(plan: &Plan) -> Vec<String> {
    plan.quantities.iter().map(|q| q.name.clone()).collect()
}

/// Computes the plan's quantities from the case's files (runs that ended ok or failed).
fn quantify(plan: &Plan, dir: &Path, rec: &mut CaseRecord) {
    rec.quantity_names = names(plan);
    rec.quantities = vec![None; plan.quantities.len()];
    if rec.status == Status::QuantityError {
        rec.status = Status::Ok;
        rec.diagnosis.clear();
    }
    if !matches!(rec.status, Status::Ok | Status::Failed) {
        return;
    }
    let summary: serde_json::Value =
        crate::safe_file::read_text(&dir.join("summary.json"), crate::safe_file::MAX_TEXT_BYTES)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default();
    for (k, q) in plan.quantities.iter().enumerate() {
        match q.eval(dir, &summary) {
            Ok(v) => rec.quantities[k] = v,
            Err(msg) => {
                if rec.status == Status::Ok {
                    rec.status = Status::QuantityError;
                    rec.diagnosis = one_line(&msg);
                }
            }
        }
    }
}

fn write_record(dir: &Path, rec: &CaseRecord) -> std::io::Result<()> {
    let text = serde_json::to_string_pretty(rec).unwrap_or_default();
    let tmp = dir.join("case.json.tmp");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, dir.join("case.json"))
}

/// Runs case `i` unless it is finished; returns its record, or
/// [`SweepError::Interrupted`] when `interrupts` stopped it (it then has a checkpoint and
/// no `case.json`: the next run of the plan goes on from there).
pub fn run_case(plan: &Plan, i: usize, interrupts: &Interrupts) -> Result<CaseRecord, SweepError> {
    let dir = plan.case_dir(i);
    if let Some(rec) = finished(plan, i) {
        return Ok(rec);
    }
    if dir.exists() {
        return restart_incomplete_case(plan, i, &dir, interrupts);
    }
    run_fresh(plan, i, &dir, interrupts)
}

/// A case directory without a finished `case.json` was stopped (Ctrl-C, Slurm's time
/// limit, a killed node) or belongs to an edited plan or deck. It goes on from its
/// checkpoint ([`app::resume_run`]: the files come out as those of a case never stopped)
/// when the checkpoint is of this case's deck text and values; otherwise (no checkpoint,
/// a refused one) the case is run again from scratch, its old files removed.
pub fn restart_incomplete_case(
    plan: &Plan,
    i: usize,
    dir: &Path,
    interrupts: &Interrupts,
) -> Result<CaseRecord, SweepError> {
    if dir.join(crate::checkpoint::FILE_NAME).exists()
        && let Ok(ck) = crate::checkpoint::read(dir)
        && ck.deck.sha256 == plan.deck_hash
        && same_values(&ck.deck.set, &plan.overrides(i))
    {
        let result = app::resume_run(
            dir,
            Some(&plan.deck),
            app::DEFAULT_CHECKPOINT_SECONDS,
            true,
            interrupts.clone(),
        );
        if let Ok(report) = result {
            return record(plan, i, dir, Ok(report));
        }
    }
    std::fs::remove_dir_all(dir).map_err(|e| SweepError::Io {
        path: dir.to_path_buf(),
        reason: e.to_string(),
    })?;
    run_fresh(plan, i, dir, interrupts)
}

/// The values of two override lists agree bit for bit.
fn same_values(a: &[(String, f64)], b: &[(String, f64)]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.0 == y.0 && x.1.to_bits() == y.1.to_bits())
}

fn run_fresh(
    plan: &Plan,
    i: usize,
    dir: &Path,
    interrupts: &Interrupts,
) -> Result<CaseRecord, SweepError> {
    std::fs::create_dir_all(dir).map_err(|e| SweepError::Io {
        path: dir.to_path_buf(),
        reason: e.to_string(),
    })?;
    let overrides = plan.overrides(i);
    // Read once (bounded: a regular file or a pipe): the text parsed is the text named.
    let read = crate::deck::read_source(&plan.deck);
    let text = read.as_deref().unwrap_or_default().to_string();
    let parsed = read.and_then(|t| {
        crate::deck::parse_deck_with(&t, &plan.deck.display().to_string(), &overrides).map(
            |mut m| {
                // A SUPERELEMENT's FILES are relative to the deck's directory.
                let base = plan.deck.parent().unwrap_or(std::path::Path::new("."));
                m.resolve_superelement_dirs(base);
                m
            },
        )
    });
    let result = match parsed {
        Err(errs) => Err((app::EXIT_BAD_INPUT, deck_errors_text(&errs))),
        // `ANALYSIS MODES n`: the case is a modal analysis (its summary.json holds the
        // modes the `mode` quantities read), as `mecano-rs DECK` makes it.
        Ok(model) if model.modes.is_some() => {
            let n = model.modes.unwrap_or(1) as usize;
            let about = crate::modes::about::deck_about(&model);
            match app::modes::run_loaded(&plan.deck, &text, &model, about, n, dir, true, false) {
                app::EXIT_OK => Ok(crate::solver::RunReport {
                    stats: Default::default(),
                    time: 0.0,
                    failure: None,
                    interrupted: None,
                }),
                code => Err((code, "the modal analysis failed (see its message)".into())),
            }
        }
        Ok(model) => {
            // A case writes every accepted step (EVERY 1, the default) so that its
            // quantities see the impacts, which a plain run's grid rows can step over
            // (with h = 5e-5 s on the pendulum the whole first contact falls between two
            // grid instants); with EVERY n > 1 the deck's sampling is kept.
            let every_step = model.output.every <= 1;
            let id = app::deck_identity(&plan.deck, &text, &overrides, 1);
            app::run_checkpointed(
                &model,
                id,
                dir,
                app::DEFAULT_CHECKPOINT_SECONDS,
                every_step,
                interrupts.clone(),
            )
        }
    };
    record(plan, i, dir, result)
}

/// The record of case `i` from the outcome of its run, written as `case.json` — unless
/// the run was interrupted: then the case is not finished ([`SweepError::Interrupted`]).
fn record(
    plan: &Plan,
    i: usize,
    dir: &Path,
    result: Result<crate::solver::RunReport, (u8, String)>,
) -> Result<CaseRecord, SweepError> {
    let mut rec = CaseRecord {
        case: i,
        values: plan.cases[i].clone(),
        status: Status::Ok,
        diagnosis: String::new(),
        steps: 0,
        time: 0.0,
        cpu_s: 0.0,
        quantities: vec![None; plan.quantities.len()],
        quantity_names: names(plan),
        deck_hash: plan.deck_hash.clone(),
    };
    match result {
        Err((_, msg)) => {
            rec.status = Status::BadInput;
            rec.diagnosis = one_line(&msg);
        }
        Ok(report) => {
            if report.interrupted.is_some() {
                return Err(SweepError::Interrupted);
            }
            rec.steps = report.stats.steps;
            rec.time = report.time;
            rec.cpu_s = report.stats.cpu_seconds;
            if let Some(f) = &report.failure {
                rec.status = Status::Failed;
                rec.diagnosis = one_line(&f.to_string());
            }
            quantify(plan, dir, &mut rec);
        }
    }
    write_record(dir, &rec).map_err(|e| SweepError::Io {
        path: dir.to_path_buf(),
        reason: e.to_string(),
    })?;
    Ok(rec)
}

fn deck_errors_text(errs: &crate::deck::DeckErrors) -> String {
    let mut parts = Vec::new();
    for (k, e) in errs.errors().iter().enumerate() {
        match errs.line_col(k) {
            Some((l, c)) => parts.push(format!("{}:{l}:{c}: {e}", errs.file_name())),
            None => parts.push(format!("{}: {e}", errs.file_name())),
        }
    }
    parts.join("; ")
}

/// The first line of a message, without the separators of sweep.csv's cells.
fn one_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_string()
}

/// Runs the cases `which` (indices) of the plan on `jobs` threads, each case in-process,
/// with a progress bar over cases (on a terminal, unless `quiet`). Returns how many were
/// run and how many of those did not end `ok`.
pub fn run_local(
    plan: &Plan,
    which: &[usize],
    jobs: usize,
    quiet: bool,
    interrupts: &Interrupts,
) -> Result<(usize, usize), SweepError> {
    let pending: Vec<usize> = which
        .iter()
        .copied()
        .filter(|&i| finished(plan, i).is_none())
        .collect();
    let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
        let pb = indicatif::ProgressBar::new(pending.len() as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} cases, {msg} [{elapsed}, ~{eta} left]",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        pb
    });
    let next = AtomicUsize::new(0);
    let not_ok = AtomicUsize::new(0);
    let first_error: std::sync::Mutex<Option<SweepError>> = std::sync::Mutex::new(None);
    let jobs = jobs.clamp(1, pending.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&i) = pending.get(k) else { break };
                    if interrupts.stopping() {
                        break; // a stop was asked for: no new case starts
                    }
                    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        run_case(plan, i, interrupts)
                    }));
                    match r {
                        Ok(Ok(rec)) => {
                            if rec.status != Status::Ok {
                                not_ok.fetch_add(1, Ordering::Relaxed);
                            }
                        }
                        Ok(Err(SweepError::Interrupted)) => {
                            if let Ok(mut g) = first_error.lock() {
                                g.get_or_insert(SweepError::Interrupted);
                            }
                        }
                        Ok(Err(e)) => {
                            not_ok.fetch_add(1, Ordering::Relaxed);
                            if let Ok(mut g) = first_error.lock() {
                                g.get_or_insert(e);
                            }
                        }
                        Err(_) => {
                            not_ok.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                    if let Some(pb) = &bar {
                        pb.inc(1);
                        pb.set_message(format!("{} not ok", not_ok.load(Ordering::Relaxed)));
                    }
                }
            });
        }
    });
    if let Some(pb) = bar {
        pb.finish_and_clear();
    }
    if let Some(e) = first_error.into_inner().ok().flatten() {
        return Err(e);
    }
    Ok((pending.len(), not_ok.into_inner()))
}
