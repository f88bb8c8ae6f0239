//! `mecano-rs resume OUTDIR`: go on from the last checkpoint of a stopped run.
//!
//! The deck is read again (from where the run found it, or `--deck`) and must have the
//! text the checkpoint names (SHA-256); a complete run is refused. The history files are
//! cut back to their lengths at the checkpoint (rows written after it, before a SIGKILL or
//! a power cut, go) and the run goes on from the checkpoint's state, appending to them: the
//! files come out byte for byte as those of a run that was never stopped, and
//! `summary.json` as its, but for the CPU time and a record of the restarts (`resumes`).

use super::session::{CheckpointPlan, Session};
use super::{
    DEFAULT_CHECKPOINT_SECONDS, EXIT_BAD_INPUT, EXIT_FAILED, checkpoint_seconds, interrupts,
    load_identified, report_outcome,
};
use crate::checkpoint;
use crate::interrupt::Interrupts;
use crate::model::Analysis;
use crate::output::Writer;
use crate::output::vtk::VtkWriter;
use crate::solver::{self, RunReport};
use std::path::{Path, PathBuf};

/// `mecano-rs resume …`
#[derive(clap::Args, Debug, Clone)]
pub struct ResumeArgs {
    /// Output directory of the stopped run (it holds checkpoint.bin and summary.json).
    pub dir: PathBuf,
    /// The deck, if it is no longer where the run read it (its text must be the same).
    #[arg(long, value_name = "DECK")]
    pub deck: Option<PathBuf>,
    /// Wall time between two checkpoints, s (0: only at an interruption).
    #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_CHECKPOINT_SECONDS)]
    pub checkpoint: f64,
    /// No progress bar and no closing summary line.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Why a restart is refused (exit code 2).
fn refuse(msg: impl std::fmt::Display) -> (u8, String) {
    (EXIT_BAD_INPUT, msg.to_string())
}

/// `mecano-rs resume OUTDIR`; returns the exit code.
pub fn resume(args: &ResumeArgs) -> u8 {
    let every = match checkpoint_seconds(args.checkpoint) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let what = format!("resume {}", args.dir.display());
    match resume_run(
        &args.dir,
        args.deck.as_deref(),
        every,
        args.quiet,
        interrupts(),
    ) {
        Ok(report) => report_outcome(&what, &args.dir, args.quiet, &report),
        Err((code, msg)) => {
            eprintln!("error: {what}: {msg}");
            code
        }
    }
}

/// Goes on from the last checkpoint in `dir` (the deck read from where the run found it,
/// or `deck`), writing checkpoints every `every` seconds of wall time (0: only at an
/// interruption), until the end, a failure or a stop that `interrupts` asks for. The
/// library's entry point of `mecano-rs resume` (a sweep's interrupted case goes on here).
/// A refusal is exit code 2 with its reason.
pub fn resume_run(
    dir: &Path,
    deck: Option<&Path>,
    every: f64,
    quiet: bool,
    interrupts: Interrupts,
) -> Result<RunReport, (u8, String)> {
    if !dir.is_dir() {
        return Err(refuse("no such output directory"));
    }
    // The same lock as a fresh run's: a restart never writes beside another run.
    let claim = super::outdir::OutDir::lock_existing(dir).map_err(refuse)?;
    let summary: Option<serde_json::Value> = match crate::safe_file::read_text(
        &dir.join("summary.json"),
        crate::safe_file::MAX_TEXT_BYTES,
    ) {
        Ok(t) => match serde_json::from_str(&t) {
            Ok(v) => Some(v),
            Err(e) => return Err(refuse(format!("summary.json is not valid JSON ({e})"))),
        },
        Err(_) => None,
    };
    if summary
        .as_ref()
        .is_some_and(|s| s["complete"] == serde_json::Value::Bool(true))
    {
        return Err(refuse(
            "the run is complete (summary.json: \"complete\": true): nothing to resume",
        ));
    }
    if let Some(f) = summary
        .as_ref()
        .map(|s| &s["failure"])
        .filter(|f| f.is_object())
        && !dir.join(checkpoint::FILE_NAME).exists()
    {
        return Err(refuse(format!(
            "the run failed ({}); a restart would fail again at the same step: change the deck and run it again",
            f["message"]
                .as_str()
                .unwrap_or("see summary.json")
                .lines()
                .next()
                .unwrap_or("")
        )));
    }
    let ck = match checkpoint::read(dir) {
        Ok(c) => c,
        Err(e) => return Err(refuse(e)),
    };
    let deck_path = deck.map(Path::to_path_buf).unwrap_or_else(|| {
        ck.deck
            .absolute
            .as_ref()
            .map(PathBuf::from)
            .filter(|p| p.exists())
            .unwrap_or_else(|| PathBuf::from(&ck.deck.path))
    });
    let (model, id) = match load_identified(&deck_path, &ck.deck.set, ck.deck.refine) {
        Ok(m) => m,
        Err(code) => {
            return Err((
                code,
                format!(
                    "the run's deck {} cannot be read (see above); give its place with --deck",
                    deck_path.display()
                ),
            ));
        }
    };
    // Named before the deck's hash (which differs too): the clearer reason.
    if let Analysis::Dynamic { scheme, .. } = &model.analysis
        && ck.integrator.scheme() != scheme.label()
    {
        return Err(refuse(format!(
            "the checkpoint was written by the integrator {}, the deck {} now asks for {}: a run resumes only with the integrator that wrote it; a changed deck is a new run",
            ck.integrator.scheme(),
            deck_path.display(),
            scheme.label()
        )));
    }
    if id.sha256 != ck.deck.sha256 {
        return Err(refuse(format!(
            "the deck {} is not the one this run's checkpoint belongs to: its text differs (SHA-256 {} now, {} at the run); a changed deck is a new run",
            deck_path.display(),
            &id.sha256[..16],
            &ck.deck.sha256[..16.min(ck.deck.sha256.len())]
        )));
    }
    let mut integ = match solver::prepare(&model) {
        Ok(i) => i,
        Err(e) => return Err(refuse(e)),
    };
    let (time, step) = (ck.time, ck.step);
    if let Err(e) = integ.restore_state(ck.integrator) {
        return Err(refuse(format!("the checkpoint does not fit the deck: {e}")));
    }
    if integ.t.to_bits() != time.to_bits() || integ.stats.steps != step {
        return Err(refuse("the checkpoint is inconsistent (time or step)"));
    }
    // What the restart cuts: rows written after the checkpoint.
    let cut: u64 = ck
        .writer
        .files
        .iter()
        .filter_map(|(name, len)| {
            let now = std::fs::metadata(dir.join(name)).ok()?.len();
            Some(now.saturating_sub(*len))
        })
        .sum();
    let mut writer = match Writer::resume(dir, &ck.deck.path, &model, &integ.sys, &ck.writer) {
        Ok(w) => w,
        Err(e) => {
            return Err(refuse(format!(
                "the history files do not fit the checkpoint: {e}"
            )));
        }
    };
    writer.refine = ck.deck.refine;
    // The same block as the fresh run's (it depends on the model alone).
    if let Some(v) = crate::modes::run_summary::block(&model, integ.sys.n_node_eq) {
        writer
            .notes
            .insert(crate::modes::run_summary::KEY.into(), v);
    }
    let vtk = match (model.output.vtk, &ck.vtk) {
        (false, _) => None,
        (true, Some(state)) => match VtkWriter::resume(dir, &model, &integ.sys, state) {
            Ok(v) => Some(v),
            Err(e) => return Err((EXIT_FAILED, e.to_string())),
        },
        (true, None) => {
            return Err(refuse(
                "the checkpoint has no VTK series, the deck asks for one",
            ));
        }
    };
    // The record of the stops and restarts, carried from one restart to the next.
    let mut resumes = summary
        .as_ref()
        .and_then(|s| s["resumes"].as_array().cloned())
        .unwrap_or_default();
    let stop = summary
        .as_ref()
        .map(|s| s["stop"].clone())
        .filter(|s| !s.is_null());
    resumes.push(serde_json::json!({
        "stopped": stop.unwrap_or_else(|| serde_json::json!({
            "reason": "unknown (killed, or the machine stopped)",
        })),
        "signal": summary.as_ref().map(|s| s["signal"].clone()).unwrap_or_default(),
        "from_checkpoint": { "time": time, "step": step },
        "bytes_cut": cut,
    }));
    writer
        .notes
        .insert("resumes".into(), serde_json::Value::Array(resumes));
    if let Err(e) = writer.write_notes() {
        return Err((EXIT_FAILED, e.to_string()));
    }
    let what = format!("resume {}", dir.display());
    if !quiet {
        eprintln!(
            "{what}: going on from t = {time:.6e} s (step {step}) of {}; {cut} bytes written after the checkpoint cut",
            ck.deck.path
        );
    }
    let session = Session {
        model: &model,
        dir,
        quiet,
        integ,
        writer,
        vtk,
        plan: Some(CheckpointPlan::new(every, ck.deck)),
        interrupts,
        resume: Some(ck.control),
        claim,
    };
    session.execute()
}
