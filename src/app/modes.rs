//! `mecano-rs modes DECK` (the command; the analysis is the library's `crate::modes`): the lowest modes linearised about the initial state, the static
//! equilibrium under the deck's loads (`--static`) or the state a run reaches at `--at T`.
//!
//! Exit codes: 0 done; 1 the state could not be reached (a failed static solve or run)
//! or the eigen-solve failed; 2 bad input (deck errors, `--count` above the free
//! unknowns, `--at` outside the deck's time, nothing to vibrate). Nothing is written
//! unless the analysis succeeded.

use crate::app::{self, EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK};
use crate::model::Model;
pub use crate::modes::about::{
    About, CHECK_MAX_UNKNOWNS, Failed, analyse_model, analyse_model_using, deck_step,
    lowest_about_initial, reach_state,
};
use crate::modes::output::{self, DeckStep};
use crate::modes::rotating::{Frame, FrameError};
use crate::modes::vtk as modes_vtk;
use crate::modes::{ModalAnalysis, Solver};
use crate::solver;
use clap::Args;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Options of `mecano-rs modes`.
#[derive(Args, Debug, Clone)]
pub struct ModesArgs {
    /// The input deck.
    pub deck: PathBuf,
    /// Number of modes (the lowest; rigid motions first). Default: the deck's
    /// `ANALYSIS MODES n`, else 10.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub count: Option<u32>,
    /// Linearise about the static equilibrium under the deck's loads (an `ANALYSIS STATIC`
    /// solve of one load step) instead of the initial state.
    #[arg(long = "static", conflicts_with = "at")]
    pub statics: bool,
    /// Run the deck to time T (≤ its END) and linearise about the state reached.
    #[arg(long, value_name = "T")]
    pub at: Option<f64>,
    /// A hub driven at constant speed (the deck's one `HINGE … DRIVE f`, grounded, with
    /// `a f̈ = 0` at t = 0): linearise about the relative equilibrium, the modes seen in the
    /// frame turning with the hub (docs/modes.md, "Rotating structures").
    #[arg(long, conflicts_with_all = ["at", "statics"])]
    pub rotating: bool,
    /// Output directory (default: out/<deck name>/modes).
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Divide every BEAM into K times its elements (as for runs).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub refine: u32,
    /// Set every beam to order P (as `mecano-rs study --order`).
    #[arg(long, value_name = "P")]
    pub order: Option<u32>,
    /// Override a deck parameter: `--set E=2.1e10`; repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = app::SetParser)]
    pub set: Vec<(String, f64)>,
    /// No table on standard output.
    #[arg(short, long)]
    pub quiet: bool,
    /// Write into an output directory that holds files no mecano-rs run wrote there (they
    /// are left as they are), as for runs.
    #[arg(long)]
    pub force: bool,
    /// Eigen-solver: `auto` (sparse from 300 unknowns: shift-invert Lanczos for a
    /// conservative model, Arnoldi on the first-order form for a damped or gyroscopic one;
    /// dense otherwise), `dense` or `sparse`.
    #[arg(long, value_enum, default_value_t = SolverArg::Auto)]
    pub solver: SolverArg,
}

/// `--solver`'s values.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverArg {
    /// Sparse for large models, dense otherwise.
    Auto,
    /// Dense (faer/nalgebra): every mode, the highest frequency.
    Dense,
    /// Sparse shift-invert: block Lanczos (conservative) or block Arnoldi on the
    /// first-order form (damped, gyroscopic): the lowest modes.
    Sparse,
}

impl From<SolverArg> for Solver {
    fn from(s: SolverArg) -> Self {
        match s {
            SolverArg::Auto => Solver::Auto,
            SolverArg::Dense => Solver::Dense,
            SolverArg::Sparse => Solver::Sparse,
        }
    }
}

/// Prints the modes and, for a dynamic deck, what its step resolves.
pub fn print_table(out: &mut dyn std::io::Write, a: &ModalAnalysis, step: Option<DeckStep>) {
    let highest = if a.highest_hz.is_finite() {
        format!("{:.6e} Hz", a.highest_hz)
    } else {
        "not computed".to_string()
    };
    let _ = writeln!(
        out,
        "{} free unknowns, {} rigid modes, highest frequency {highest} ({:?} solve)",
        a.free_unknowns, a.rigid_modes, a.method
    );
    let _ = writeln!(out, " mode  kind       frequency Hz     damping ratio");
    for (i, m) in a.modes.iter().enumerate() {
        let _ = writeln!(
            out,
            "{:5}  {:9}  {:15.9e}  {:+.3e}",
            i + 1,
            format!("{:?}", m.kind).to_lowercase(),
            m.natural_hz,
            m.damping_ratio
        );
    }
    if let Some(st) = step {
        let _ = writeln!(
            out,
            "what the step resolves ({}, h = {:e} s): frequency Hz, samples per period, numerical damping ratio, period error",
            st.scheme, st.h
        );
        let rows = output::step_resolution(a, st);
        for (i, r) in rows.iter().enumerate() {
            let label = if i + 1 == rows.len() && highest_computed(a) {
                "highest"
            } else {
                ""
            };
            let (damping, period) = resolution_cells(r);
            let _ = writeln!(
                out,
                "  {:12.6e}  {:10.3e}  {damping:>11}  {period:>10}  {label}",
                r.frequency_hz, r.samples_per_period,
            );
        }
        if a.highest_hz.is_nan() {
            let _ = writeln!(
                out,
                "  highest frequency not computed ({:?} solve: the lowest modes only)",
                a.method
            );
        }
    }
}

/// The step-resolution table's last row is the mesh's highest frequency (the dense solve
/// computed it, and it is not zero); the sparse solve leaves it NaN.
fn highest_computed(a: &ModalAnalysis) -> bool {
    a.highest_hz.is_finite() && a.highest_hz > 0.0
}

/// A row's damping ratio and period error as printed: "annihilated" when the step leaves
/// at most [`crate::modes::hht::ANNIHILATED_RADIUS`] of the mode, "unresolved" for a period
/// the step does not resolve.
fn resolution_cells(r: &crate::modes::hht::Resolution) -> (String, String) {
    if r.annihilated() {
        return ("annihilated".to_string(), "-".to_string());
    }
    (
        format!("{:.3e}", r.hht_damping),
        r.period_error
            .map_or("unresolved".to_string(), |e| format!("{e:.3e}")),
    )
}

/// What each integrator does to each mode at the deck's step (issue 26 §4): the numerical
/// damping ratio and the period error of the deck's scheme and of the others at the same
/// `ρ∞` ([`crate::modes::hht::compared_schemes`]), closed forms, side by side, so that a
/// user sees why one needs fewer steps than another for the same phase.
pub fn print_integrators(out: &mut dyn std::io::Write, a: &ModalAnalysis, st: DeckStep) {
    let schemes = crate::modes::hht::compared_schemes(&st.scheme);
    let tables: Vec<_> = schemes
        .iter()
        .map(|s| {
            output::step_resolution(
                a,
                DeckStep {
                    scheme: *s,
                    h: st.h,
                },
            )
        })
        .collect();
    let _ = writeln!(
        out,
        "what each integrator does to each mode at h = {:e} s (numerical damping ratio, period error; the deck's first):",
        st.h
    );
    let mut head = format!("  {:>12}", "frequency Hz");
    for s in &schemes {
        // `genalpha:0.8181818181818181` → `genalpha:0.8182`: the column's width.
        let label = s.label();
        let short = match label.split_once(':').map(|(n, v)| (n, v.parse::<f64>())) {
            Some((n, Ok(v))) => format!("{n}:{}", (v * 1e4).round() / 1e4),
            _ => label,
        };
        let _ = write!(head, "  {short:>23}");
    }
    let _ = writeln!(out, "{head}");
    for (i, r) in tables[0].iter().enumerate() {
        let mut line = format!("  {:12.6e}", r.frequency_hz);
        for t in &tables {
            let (damping, period) = resolution_cells(&t[i]);
            let _ = write!(line, "  {damping:>11} {period:>11}");
        }
        if i + 1 == tables[0].len() && highest_computed(a) {
            line.push_str("  highest");
        }
        let _ = writeln!(out, "{line}");
    }
    if a.highest_hz.is_nan() {
        let _ = writeln!(
            out,
            "  highest frequency not computed ({:?} solve)",
            a.method
        );
    }
}

/// The modes elements carry as their own coordinates (a superelement's kept
/// fixed-interface modes, [`crate::elements::Element::own_modes_hz`]), element by element,
/// with what the deck's step resolves of each ([`crate::modes::hht::resolution`]: samples
/// per period, the scheme's numerical damping ratio and period error) — the highest kept
/// mode is the one a step must resolve, or the scheme must damp.
pub fn print_own_modes(
    out: &mut dyn std::io::Write,
    elements: &[Box<dyn crate::elements::Element>],
    step: Option<DeckStep>,
) {
    for el in elements {
        let Some(hz) = el.own_modes_hz() else {
            continue;
        };
        let _ = writeln!(
            out,
            "element {}: {} fixed-interface modes of its own (a reduced body's coordinates){}",
            el.id().0,
            hz.len(),
            match step {
                Some(st) => format!(
                    "; at the deck's step ({}, h = {:e} s): samples per period, numerical damping ratio, period error",
                    st.scheme, st.h
                ),
                None => String::new(),
            }
        );
        for (i, f) in hz.iter().enumerate() {
            match step {
                Some(st) => {
                    let r = crate::modes::hht::resolution(&st.scheme, st.h, *f);
                    let (damping, period) = resolution_cells(&r);
                    let _ = writeln!(
                        out,
                        "  {:5}  {:12.6e}  {:10.3e}  {damping:>11}  {period:>10}",
                        i + 1,
                        f,
                        r.samples_per_period
                    );
                }
                None => {
                    let _ = writeln!(out, "  {:5}  {:12.6e}", i + 1, f);
                }
            }
        }
    }
}

/// The lines `--check` adds: each reduced body's own modes ([`print_own_modes`]), the
/// mesh's highest frequency and what the deck's step resolves of the lowest five modes,
/// about the initial state.
pub fn check_report(model: &Model, out: &mut dyn std::io::Write) {
    let Ok(integ) = solver::prepare(model) else {
        return;
    };
    print_own_modes(out, &integ.sys.elements, deck_step(model));
    if integ.sys.n_node_eq > CHECK_MAX_UNKNOWNS {
        let _ = writeln!(
            out,
            "modes:       not computed ({} unknowns > {CHECK_MAX_UNKNOWNS}: use mecano-rs modes)",
            integ.sys.n_node_eq
        );
        return;
    }
    match lowest_about_initial(model, 5, true) {
        Ok(a) => {
            let _ = writeln!(out, "modes about the initial state (mecano-rs modes):");
            if let Some(w) = reach_state(model, About::Initial)
                .ok()
                .and_then(|i| crate::modes::about::equilibrium_warning(&i))
            {
                let _ = writeln!(out, "  warning: {w}");
            }
            print_table(out, &a, deck_step(model));
            if let Some(st) = deck_step(model) {
                print_integrators(out, &a, st);
            }
        }
        Err(f) => {
            let _ = writeln!(out, "modes:       not computed ({})", f.message);
        }
    }
}

/// Where a refusal of the modal analysis points: the deck's text, and whether the count
/// and the rotating state came from its `ANALYSIS MODES n [ROTATING]` card (else from the
/// command line: `--count`, `--rotating`).
struct Source<'a> {
    deck: &'a Path,
    text: &'a str,
    count_from_deck: bool,
    rotating_from_deck: bool,
}

impl Source<'_> {
    /// `deck:line:col` of `span`.
    fn at(&self, span: crate::model::Span) -> String {
        app::locate(self.deck, self.text, span)
    }

    /// The frame error at its element when it has one, else at the deck's `ANALYSIS MODES
    /// … ROTATING` card (or named as `--rotating`'s).
    fn frame_error(&self, model: &Model, e: &FrameError) -> String {
        let span = match e {
            FrameError::OtherDriver { span, .. }
            | FrameError::NotGrounded { span, .. }
            | FrameError::NotConstant { span, .. } => Some(*span),
            _ => None,
        };
        let asked = if self.rotating_from_deck {
            "ANALYSIS MODES … ROTATING"
        } else {
            "--rotating"
        };
        match (span, self.rotating_from_deck) {
            (Some(s), _) => format!("{}: {asked}: {e}", self.at(s)),
            (None, true) => format!("{}: {asked}: {e}", self.at(model.modes_span)),
            (None, false) => format!("{}: {asked}: {e}", self.deck.display()),
        }
    }
}

fn out_dir(args: &ModesArgs, model: &Model) -> PathBuf {
    args.out
        .clone()
        .unwrap_or_else(|| app::default_out_dir(&args.deck, model).join("modes"))
}

fn shape_nodes(model: &Model) -> Vec<usize> {
    model.output_node_indices()
}

/// Loads the deck with its overrides (`--set`, `--refine`, `--order`).
pub fn load(
    path: &Path,
    set: &[(String, f64)],
    refine: u32,
    order: Option<u32>,
) -> Result<Model, u8> {
    load_text(path, set, refine, order).map(|(m, _)| m)
}

/// [`load`], with the deck's text (for located messages).
fn load_text(
    path: &Path,
    set: &[(String, f64)],
    refine: u32,
    order: Option<u32>,
) -> Result<(Model, String), u8> {
    let (mut model, text) = app::load_source(path, set, refine)?;
    if let Some(p) = order {
        model.set_beam_order(p).map_err(|e| {
            eprintln!("error: {}: --order {p}: {e}", path.display());
            EXIT_BAD_INPUT
        })?;
    }
    Ok((model, text))
}

/// `mecano-rs modes`: returns the exit code.
pub fn run(args: &ModesArgs) -> u8 {
    let (model, text) = match load_text(&args.deck, &args.set, args.refine, args.order) {
        Ok(m) => m,
        Err(code) => return code,
    };
    // A deck of `ANALYSIS MODES n ROTATING` is linearised about its rotating state: a
    // request for another state is refused, not ignored (issue 35 §5: `--at 0.1` gave the
    // rotating modes, silently).
    if model.modes_rotating && !args.rotating && (args.at.is_some() || args.statics) {
        let what = if args.statics { "--static" } else { "--at" };
        eprintln!(
            "error: {}: {what}: this deck's ANALYSIS MODES … ROTATING asks for the modes about the hub's rotating state; {what} asks for another state: remove one of them",
            app::locate(&args.deck, &text, model.modes_span)
        );
        return EXIT_BAD_INPUT;
    }
    let about = match (args.statics, args.at) {
        _ if args.rotating || model.modes_rotating => About::Rotating,
        (true, _) => About::Static,
        (false, Some(t)) => About::At(t),
        (false, None) => crate::modes::about::deck_about(&model),
    };
    let count = args.count.or(model.modes).map_or(10, |c| c as usize);
    let dir = out_dir(args, &model);
    let source = Source {
        deck: &args.deck,
        text: &text,
        count_from_deck: args.count.is_none() && model.modes.is_some(),
        rotating_from_deck: !args.rotating && model.modes_rotating,
    };
    analyse_and_write(
        &source,
        &model,
        about,
        count,
        &dir,
        (args.quiet, args.force),
        args.solver.into(),
    )
}

/// The modal analysis of a loaded model (read from `deck`, whose text is `text`) into
/// `dir`: `mecano-rs DECK` on a deck of `ANALYSIS MODES n` (about the initial state, or
/// the rotating state with `ROTATING`, into the run's output directory), a sweep's case of
/// such a deck. Returns the exit code.
#[allow(clippy::too_many_arguments)]
pub fn run_loaded(
    deck: &Path,
    text: &str,
    model: &Model,
    about: About,
    count: usize,
    dir: &Path,
    quiet: bool,
    force: bool,
) -> u8 {
    let source = Source {
        deck,
        text,
        count_from_deck: true,
        rotating_from_deck: model.modes_rotating,
    };
    analyse_and_write(
        &source,
        model,
        about,
        count,
        dir,
        (quiet, force),
        Solver::Auto,
    )
}

fn analyse_and_write(
    source: &Source<'_>,
    model: &Model,
    about: About,
    count: usize,
    dir: &Path,
    (quiet, force): (bool, bool),
    solver: Solver,
) -> u8 {
    let deck = source.deck;
    // The analysis's seconds for summary.json's `cpu_seconds`, measured as a dynamic run's
    // (`solver::Stats::cpu_seconds`: elapsed time on the one thread that computes).
    let start = std::time::Instant::now();
    if about == About::Rotating
        && let Err(e) = Frame::from_model(model, 0.0)
    {
        eprintln!("error: {}", source.frame_error(model, &e));
        return EXIT_BAD_INPUT;
    }
    let (integ, a) = match analyse_model_using(model, about, count, solver) {
        Ok(r) => r,
        Err(f) if f.too_many && source.count_from_deck => {
            eprintln!(
                "error: {}: ANALYSIS MODES {count}: {}",
                source.at(model.modes_span),
                f.message
            );
            return EXIT_BAD_INPUT;
        }
        Err(f) if f.too_many => {
            eprintln!("error: {}: --count {count}: {}", deck.display(), f.message);
            return EXIT_BAD_INPUT;
        }
        Err(f) => {
            eprintln!("error: {}: {}", deck.display(), f.message);
            return if f.bad_input {
                EXIT_BAD_INPUT
            } else {
                EXIT_FAILED
            };
        }
    };
    for n in &integ.notices {
        eprintln!("warning: {}: {n}", deck.display());
    }
    let not_equilibrium = (about != About::Rotating)
        .then(|| crate::modes::about::equilibrium_warning(&integ))
        .flatten();
    if let Some(w) = &not_equilibrium {
        eprintln!("warning: {}: {w}", deck.display());
    }
    let state = match about {
        About::Initial => "initial".to_string(),
        About::Static => "static equilibrium".to_string(),
        About::At(t) => format!("run to t = {t} s"),
        About::Rotating => "relative equilibrium (rotating frame)".to_string(),
    };
    let step = deck_step(model);
    let mut summary = output::summary(&a, &deck.display().to_string(), &state, integ.t, step);
    summary["vtk"] = modes_vtk::summary(&integ.sys, &a);
    summary["cpu_seconds"] = serde_json::json!(start.elapsed().as_secs_f64());
    if let Some(w) = not_equilibrium {
        summary["warnings"] = serde_json::json!([w]);
    }
    if !integ.notices.is_empty() {
        summary["notices"] = serde_json::to_value(&integ.notices).unwrap_or_default();
    }
    if about == About::Rotating
        && let Ok(f) = Frame::from_model(model, integ.t)
    {
        summary["frame"] = serde_json::json!({
            "kind": "rotating",
            "hinge": f.element.to_string(),
            "speed_rad_s": f.speed,
            "axis": [f.axis.x, f.axis.y, f.axis.z],
            "point": [f.point.x, f.point.y, f.point.z],
        });
    }
    // The directory is claimed as a run's is (app::outdir: its lock, the previous
    // analysis's files replaced, foreign ones refused, nothing written through a link).
    let _claim = match app::outdir::OutDir::claim_fresh(dir, &app::outdir::modes_files(), force) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {}: {e}", deck.display());
            return EXIT_BAD_INPUT;
        }
    };
    let written = output::write_all(
        dir,
        &a,
        &integ.sys,
        &shape_nodes(model),
        &integ.nodes,
        &summary,
    )
    .and_then(|()| modes_vtk::write_series(dir, model, &integ.sys, &integ.nodes, &a));
    if let Err(e) = written {
        eprintln!("error: writing {}: {e}", dir.display());
        return EXIT_FAILED;
    }
    if !quiet {
        let mut out = std::io::stdout().lock();
        print_table(&mut out, &a, step);
        print_own_modes(&mut out, &integ.sys.elements, step);
        let _ = writeln!(out, "written: {}", dir.display());
    }
    EXIT_OK
}
