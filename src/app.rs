//! The command-line application behind the thin `main.rs`: check a deck, run it, report.
//!
//! Exit codes: 0 done, 1 the run failed (diagnosis printed, outputs kept and marked
//! incomplete), 2 bad input (deck errors, unsupported elements; nothing written), 130
//! interrupted (SIGINT or SIGTERM: whole rows kept, a checkpoint to go on from with
//! `mecano-rs resume`).

pub use locate::{locate, located_build_error, located_model_error};
pub mod export;
mod locate;
pub mod memory;
pub mod modes;
pub mod outdir;
mod resume;
mod session;

pub use resume::{ResumeArgs, resume, resume_run};
pub use session::CheckpointPlan;

use crate::checkpoint::{self, DeckIdentity};
use crate::deck;
use crate::interrupt::Interrupts;
use crate::model::Model;
use crate::output::Writer;
use crate::output::vtk::VtkWriter;
use crate::solver::{self, RunReport};
use session::Session;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Exit code: the run completed.
pub const EXIT_OK: u8 = 0;
/// Exit code: the run failed (no convergence, non-finite state, output error).
pub const EXIT_FAILED: u8 = 1;
/// Exit code: bad input (the deck has errors or uses unsupported elements).
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit code: the run was interrupted (SIGINT or SIGTERM; 128 + 2, the shell's code of a
/// process ended by SIGINT). Its files end with whole rows, and a checkpoint lets
/// `mecano-rs resume` go on.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Default wall time between two checkpoints, s.
pub const DEFAULT_CHECKPOINT_SECONDS: f64 = 60.0;

/// Options of a run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Output directory (default `out/<deck name>/`, or the deck's OUTPUT DIR).
    pub out_dir: Option<PathBuf>,
    /// No progress bar, no summary on standard output.
    pub quiet: bool,
    /// Wall time between two checkpoints, s (0: only at an interruption;
    /// [`DEFAULT_CHECKPOINT_SECONDS`] by default).
    pub checkpoint: f64,
    /// `--refine k`: divide every beam into k times its elements (0 or 1: as written).
    pub refine: u32,
    /// Parameter overrides (`--set name=value`), in command-line order (the last wins).
    pub set: Vec<(String, f64)>,
    /// `--force`: run into a directory holding files no run of this program wrote there
    /// (they are left as they are; [`outdir`]).
    pub force: bool,
}

impl RunOptions {
    /// Options of a run into `dir` with checkpoints every `checkpoint` seconds, the deck's
    /// mesh as written.
    pub fn new(out_dir: Option<PathBuf>, quiet: bool, checkpoint: f64) -> Self {
        RunOptions {
            out_dir,
            quiet,
            checkpoint,
            refine: 1,
            set: Vec::new(),
            force: false,
        }
    }
}

/// The longest line a message of the command line echoes, characters.
pub const ECHO_LINE_CHARS: usize = 200;

/// `text` with every line longer than [`ECHO_LINE_CHARS`] cut there (with `…` and its
/// length): no message grows with the input it quotes.
pub fn cap_lines(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(64 << 10));
    for line in text.split_inclusive('\n') {
        match line.char_indices().nth(ECHO_LINE_CHARS) {
            Some((i, _)) => {
                out.push_str(&line[..i]);
                out.push_str(&format!("… ({} characters)", line.chars().count()));
                if line.ends_with('\n') {
                    out.push('\n');
                }
            }
            None => out.push_str(line),
        }
    }
    out
}

/// clap's parser of `--set` ([`parse_set`]): its refusal says what is wrong, at which
/// character, quoting at most a short prefix — not the whole argument, as clap's own
/// message of an invalid value does.
#[derive(Clone, Debug)]
pub struct SetParser;

impl clap::builder::TypedValueParser for SetParser {
    type Value = (String, f64);

    fn parse_ref(
        &self,
        _cmd: &clap::Command,
        _arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<Self::Value, clap::Error> {
        let refuse = |msg: String| {
            clap::Error::raw(
                clap::error::ErrorKind::ValueValidation,
                format!("--set: {msg}\n"),
            )
        };
        let s = value
            .to_str()
            .ok_or_else(|| refuse("the value is not UTF-8 text".into()))?;
        parse_set(s).map_err(refuse)
    }
}

/// Reads `name=value` (`--set`): a parameter name and a number or an expression of numbers
/// (`E=2.1e11`, `h=1e-4/2`).
pub fn parse_set(arg: &str) -> Result<(String, f64), String> {
    let (name, value) = arg
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found `{}`", deck::short(arg)))?;
    let name = name.trim().trim_start_matches('$');
    let valid = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid {
        return Err(format!("`{}` is not a parameter name", deck::short(name)));
    }
    let v = deck::eval_constant_located(value.trim()).map_err(|(column, why)| {
        format!("the value of `{name}`, at its character {column}: {why}")
    })?;
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

/// Parses a deck and refines its mesh by `refine` ([`Model::refine`]; 0 or 1: as
/// written), printing diagnostics on error.
pub fn load_refined(path: &Path, refine: u32) -> Result<Model, u8> {
    load_variant(path, &[], refine)
}

/// Parses a deck with parameter overrides (`--set`) and refines its mesh by `refine`.
pub fn load_variant(path: &Path, set: &[(String, f64)], refine: u32) -> Result<Model, u8> {
    load_source(path, set, refine).map(|(m, _)| m)
}

/// Reads the deck once ([`deck::read_source`]: a regular file or a pipe, bounded), parses
/// it with the overrides `set`, refines it by `refine`; the model and the very text parsed
/// (what messages locate in, what a checkpoint names). Diagnostics printed on error.
pub fn load_source(path: &Path, set: &[(String, f64)], refine: u32) -> Result<(Model, String), u8> {
    let text = deck::read_source(path).map_err(|errs| {
        eprintln!("{:?}", miette::Report::new(errs));
        EXIT_BAD_INPUT
    })?;
    let name = path.display().to_string();
    let mut model = deck::parse_deck_with(&text, &name, set).map_err(|errs| {
        eprintln!("{:?}", miette::Report::new(errs));
        EXIT_BAD_INPUT
    })?;
    // A SUPERELEMENT's FILES are relative to the deck's directory.
    model.resolve_superelement_dirs(path.parent().unwrap_or(Path::new(".")));
    apply_refine(path, &mut model, refine)?;
    Ok((model, text))
}

/// Refines the model by `refine` (0 or 1: as written), then checks that the whole of it —
/// nodes, elements, the unknowns' system, the output's buffers — fits in the memory the
/// process may take (`--max-memory`, else what is available: [`crate::model::budget`]).
fn apply_refine(path: &Path, model: &mut Model, refine: u32) -> Result<(), u8> {
    if refine > 1 {
        model.refine(refine).map_err(|e| {
            eprintln!("error: {}: --refine {refine}: {e}", path.display());
            EXIT_BAD_INPUT
        })?;
    }
    crate::model::budget::check(model.footprint(), "the model").map_err(|e| {
        eprintln!("error: {}: {e}", path.display());
        EXIT_BAD_INPUT
    })
}

/// Parses a deck read once with the overrides `set`, refines it by `refine`, and names it:
/// its path, the SHA-256 of the very text parsed, the overrides and the refinement (what a checkpoint is checked against).
pub fn load_identified(
    path: &Path,
    set: &[(String, f64)],
    refine: u32,
) -> Result<(Model, DeckIdentity), u8> {
    let (model, text) = load_source(path, set, refine)?;
    let id = deck_identity(path, &text, set, refine);
    Ok((model, id))
}

/// The identity of a run's deck, as a checkpoint records it: the path as given and its
/// absolute form, the SHA-256 of the text parsed, the overrides and the refinement.
pub fn deck_identity(path: &Path, text: &str, set: &[(String, f64)], refine: u32) -> DeckIdentity {
    DeckIdentity {
        path: path.display().to_string(),
        absolute: std::fs::canonicalize(path)
            .ok()
            .map(|p| p.display().to_string()),
        sha256: checkpoint::sha256_hex(text.as_bytes()),
        refine: refine.max(1),
        set: set.to_vec(),
    }
}

/// `mecano-rs --check DECK [--set n=v] [--refine k]`: parse, validate, refine, build the
/// system, print the summary (with the nodes and elements generated) and the parameters
/// with their values (`--set` overrides marked).
pub fn check(path: &Path, set: &[(String, f64)], refine: u32) -> u8 {
    let model = match load_variant(path, set, refine) {
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
        Ok(mut integ) => {
            let _ = writeln!(
                out,
                "equations:   {} ({} nodal, {} multipliers; {} non-zeros in the iteration matrix)",
                integ.sys.n_eq(),
                integ.sys.n_node_eq,
                integ.sys.n_eq() - integ.sys.n_node_eq,
                integ.sys.matrix.nnz()
            );
            // What the solver will change before the first step: held rotations,
            // redundant equations removed, the assembly of the initial positions.
            let started = if integ.sys.n_eq() > integ.sys.n_node_eq {
                integ.start_constraints()
            } else {
                Ok(())
            };
            for n in &integ.notices {
                let _ = writeln!(out, "note:        {n}");
            }
            if let Err(f) = started {
                let _ = writeln!(out, "start:       the run will stop at t = 0: {f}");
            }
            check_output(&mut out, path, &model, &integ.sys);
            // The mesh's highest frequency and what the step resolves (issue 24).
            modes::check_report(&model, &mut out);
            EXIT_OK
        }
        Err(e) => {
            eprintln!("error: {}", located_model_error(path, &model, &e));
            EXIT_BAD_INPUT
        }
    }
}

/// `--check`'s lines on what the OUTPUT selection writes, and a warning when a second of
/// simulated time (or the whole run) would write more than the output disk holds.
fn check_output(out: &mut impl Write, path: &Path, model: &Model, sys: &solver::System) {
    let v = crate::output::volume(model, sys);
    let _ = writeln!(
        out,
        "output:      {} files, {} per written instant, {:.0} instants and {} per second of simulated time, {} for the run",
        v.files,
        bytes(v.bytes_per_row),
        v.rows_per_second,
        bytes(v.bytes_per_row * v.rows_per_second),
        bytes(v.total_bytes)
    );
    let dir = default_out_dir(path, model);
    if let Some(free) = free_bytes(&dir) {
        let per_second = v.bytes_per_row * v.rows_per_second;
        if per_second > free || v.total_bytes > free {
            eprintln!(
                "warning: {}: the OUTPUT selection writes {} per simulated second ({} for the run), more than the {} free on the disk of {}; select fewer nodes and elements, EVERY n, or FORMAT NETCDF",
                path.display(),
                bytes(per_second),
                bytes(v.total_bytes),
                bytes(free),
                dir.display()
            );
        }
    }
}

/// A byte count in B, kB, MB, GB (powers of 1000).
fn bytes(b: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB"];
    let mut x = b;
    let mut u = 0;
    while x >= 1000.0 && u + 1 < units.len() {
        x /= 1000.0;
        u += 1;
    }
    format!("{x:.3} {}", units[u])
}

/// Free bytes on the file system that holds `dir` (or its nearest existing parent).
fn free_bytes(dir: &Path) -> Option<f64> {
    let mut d = dir.to_path_buf();
    while !d.exists() {
        d = d
            .parent()
            .map(Path::to_path_buf)
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or_else(|| PathBuf::from("."));
        if d == Path::new(".") {
            break;
        }
    }
    let c = std::ffi::CString::new(d.as_os_str().as_encoded_bytes()).ok()?;
    let mut s: libc::statvfs = unsafe { std::mem::zeroed() };
    // SAFETY: `c` is a NUL-terminated path and `s` a writable statvfs.
    let ok = unsafe { libc::statvfs(c.as_ptr(), &mut s) } == 0;
    ok.then_some(s.f_bavail as f64 * s.f_frsize as f64)
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

/// Runs a parsed model, writing into `dir` (no checkpoints, no signal handling: the
/// library's entry point). Returns the report (with a failure if the run stopped early)
/// or an exit code and message for errors before the run.
pub fn run_model(
    model: &Model,
    deck_name: &str,
    dir: &Path,
    quiet: bool,
) -> Result<RunReport, (u8, String)> {
    start_session(
        model,
        deck_name,
        dir,
        quiet,
        None,
        Interrupts::none(),
        false,
        false,
    )
}

/// Runs `model`, read from the deck `deck`, into `dir` as `mecano-rs DECK` does —
/// checkpoints every `every` seconds of wall time (0: only at a stop), a clean stop at the
/// end of a step when `interrupts` asks — and returns the report instead of printing it:
/// the library's entry point for a sweep's case, which [`resume_run`] continues after a
/// stop. `every_step`: write every accepted step ([`Writer::every_accepted_step`]).
pub fn run_checkpointed(
    model: &Model,
    deck: DeckIdentity,
    dir: &Path,
    every: f64,
    every_step: bool,
    interrupts: Interrupts,
) -> Result<RunReport, (u8, String)> {
    let name = deck.path.clone();
    let plan = CheckpointPlan::new(every, deck);
    start_session(
        model,
        &name,
        dir,
        true,
        Some(plan),
        interrupts,
        every_step,
        false,
    )
}

/// Prepares the integrator, claims the output directory ([`outdir::OutDir::claim_fresh`]:
/// its lock, the previous run's files removed, foreign files refused unless `force`),
/// creates the writers of a fresh run, and executes it.
#[allow(clippy::too_many_arguments)]
fn start_session(
    model: &Model,
    deck_name: &str,
    dir: &Path,
    quiet: bool,
    plan: Option<CheckpointPlan>,
    interrupts: Interrupts,
    every_step: bool,
    force: bool,
) -> Result<RunReport, (u8, String)> {
    let integ = solver::prepare(model).map_err(|e| {
        // The caller prefixes the deck's name: the place follows as line and column.
        let text = located_model_error(Path::new(deck_name), model, &e);
        let text = text
            .strip_prefix(deck_name)
            .and_then(|t| t.strip_prefix(':'))
            .map_or(text.clone(), |t| format!("line {}", t.trim_start()));
        (EXIT_BAD_INPUT, text)
    })?;
    let files = outdir::run_files(
        crate::output::history_files(model, &integ.sys),
        model.output.vtk,
    );
    let claim = outdir::OutDir::claim_fresh(dir, &files, force)
        .map_err(|e| (EXIT_BAD_INPUT, e.to_string()))?;
    let io_err = |e: std::io::Error| (EXIT_FAILED, format!("{}: {e}", dir.display()));
    // Output that cannot be opened stops the run before its first step, as bad input
    // does (issue 29: exit 2, the cause named; nothing is computed for nowhere).
    let mut writer = Writer::create(dir, deck_name, model, &integ.sys).map_err(|e| {
        (
            EXIT_BAD_INPUT,
            format!("cannot open the output in {}: {e}", dir.display()),
        )
    })?;
    writer.refine = plan.as_ref().map_or(1, |p| p.deck.refine);
    if let Some(v) = crate::modes::run_summary::block(model, integ.sys.n_node_eq) {
        writer
            .notes
            .insert(crate::modes::run_summary::KEY.into(), v);
    }
    if every_step {
        writer.every_accepted_step();
    }
    // A checkpoint of an earlier run in this directory belongs to files just replaced.
    for name in [checkpoint::FILE_NAME, checkpoint::TMP_NAME] {
        crate::safe_file::remove_regular(&dir.join(name)).map_err(io_err)?;
    }
    let vtk = if model.output.vtk {
        Some(VtkWriter::create(dir, model, &integ.sys).map_err(io_err)?)
    } else {
        None
    };
    Session {
        model,
        dir,
        quiet,
        integ,
        writer,
        vtk,
        plan,
        interrupts,
        resume: None,
        claim,
    }
    .execute()
}

/// Prints the outcome of a run (or restart) of `what` and returns its exit code.
fn report_outcome(what: &str, dir: &Path, quiet: bool, report: &RunReport) -> u8 {
    let st = &report.stats;
    let per = if st.steps > 0 {
        st.newton_iterations as f64 / st.steps as f64
    } else {
        0.0
    };
    if let Some(f) = &report.failure {
        eprintln!("error: {what}: the run stopped.\n{f}");
        eprintln!(
            "  histories up to t = {:.6e} s are kept in {} and marked incomplete (summary.json: \"complete\": false)",
            report.time,
            dir.display()
        );
        return EXIT_FAILED;
    }
    if let Some(how) = report.interrupted {
        let from = match how {
            solver::Interruption::AtStep => format!(
                "a checkpoint of this state (t = {:.6e} s, step {}) is in {}",
                report.time,
                st.steps,
                dir.join(checkpoint::FILE_NAME).display()
            ),
            solver::Interruption::WithinStep => format!(
                "stopped within a step; the last checkpoint in {} is where a restart goes on",
                dir.display()
            ),
        };
        eprintln!(
            "{what}: interrupted at t = {:.6e} s after {} steps; histories kept in {} (whole rows, summary.json: \"complete\": false);\n  {from}; go on with: mecano-rs resume {}",
            report.time,
            st.steps,
            dir.display(),
            dir.display()
        );
        return EXIT_INTERRUPTED;
    }
    if !quiet {
        let _ = writeln!(
            std::io::stdout(),
            "{what}: done, t = {:.6} s, {} steps ({} rejected), {:.2} Newton iterations/step, {:.3} s CPU; output in {}",
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

/// Installs the SIGINT/SIGTERM handlers (a failure to do so only costs clean stops).
/// The handlers of SIGINT and SIGTERM, installed (a warning when they cannot be).
pub fn interrupts() -> Interrupts {
    Interrupts::install().unwrap_or_else(|e| {
        eprintln!("warning: cannot handle SIGINT/SIGTERM ({e}): a stop will not be clean");
        Interrupts::none()
    })
}

/// The `--checkpoint SECONDS` value, checked.
fn checkpoint_seconds(s: f64) -> Result<f64, u8> {
    if s.is_finite() && s >= 0.0 {
        Ok(s)
    } else {
        eprintln!(
            "error: --checkpoint takes a number of seconds >= 0 (0: only at an interruption), not {s}"
        );
        Err(EXIT_BAD_INPUT)
    }
}

/// `mecano-rs DECK`: parse, run, write; returns the exit code.
pub fn run(path: &Path, opts: &RunOptions) -> u8 {
    let every = match checkpoint_seconds(opts.checkpoint) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let (model, text) = match load_source(path, &opts.set, opts.refine) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let id = deck_identity(path, &text, &opts.set, opts.refine);
    let dir = opts
        .out_dir
        .clone()
        .unwrap_or_else(|| default_out_dir(path, &model));
    // `ANALYSIS MODES n`: the modal analysis of `mecano-rs modes DECK --count n` about the
    // initial state, written into the run's directory (no time run, no checkpoint).
    if let Some(n) = model.modes {
        let about = crate::modes::about::deck_about(&model);
        return modes::run_loaded(
            path, &text, &model, about, n as usize, &dir, opts.quiet, opts.force,
        );
    }
    let what = path.display().to_string();
    let plan = CheckpointPlan::new(every, id);
    match start_session(
        &model,
        &what,
        &dir,
        opts.quiet,
        Some(plan),
        interrupts(),
        false,
        opts.force,
    ) {
        Ok(report) => report_outcome(&what, &dir, opts.quiet, &report),
        Err((code, msg)) => {
            eprintln!("error: {what}: {msg}");
            code
        }
    }
}
