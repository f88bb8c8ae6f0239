//! `mecano-rs study DECK`: the command line.

use super::*;
use crate::deck::load_deck;
use crate::model::{Analysis, Scheme};
use std::io::Write;

/// `mecano-rs study DECK`: arguments.
#[derive(Debug, Clone, clap::Args)]
pub struct StudyArgs {
    /// The deck to study (a dynamic analysis).
    pub deck: PathBuf,
    /// Fixed time steps, s, comma-separated (default: the deck's step ×8, ×4, ×2, ×1, ÷2).
    #[arg(long, value_delimiter = ',')]
    pub steps: Vec<f64>,
    /// Adaptive runs: position tolerances, m, comma-separated (rotation tolerance: the same
    /// number in rad).
    #[arg(long, value_delimiter = ',')]
    pub adaptive: Vec<f64>,
    /// HHT α values of the fixed-step runs, comma-separated (default: the deck's); the
    /// same as `--integrator hht:α,…`, before the `--integrator` ones.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub alpha: Vec<f64>,
    /// Time integrators of the fixed-step runs, comma-separated, one ladder of steps and one
    /// line of the diagram each: `hht[:α]`, `genalpha[:ρ∞]`, `esdirk3`, `esdirk5` (default: the deck's).
    /// A bare `hht` is α = −0.1 and a bare `genalpha` ρ∞ = 0.8; give another value after a
    /// colon, e.g. `hht:-0.3,genalpha:0.5`. The first one's finest run is the reference and
    /// its scheme the adaptive runs'. A space–time study (several `--refine`, or `--order`)
    /// takes one.
    #[arg(long, value_delimiter = ',', value_parser = parse_scheme)]
    pub integrator: Vec<Scheme>,
    /// Nodes whose histories are compared (default: the deck's OUTPUT nodes).
    #[arg(long, value_delimiter = ',')]
    pub nodes: Vec<u32>,
    /// Window length for the errors, s.
    #[arg(long, default_value_t = 0.25)]
    pub window: f64,
    /// A window whose two finest runs differ by at most this (m, and rad for rotations)
    /// counts as converged.
    #[arg(long, default_value_t = 1e-6)]
    pub floor: f64,
    /// Study only up to this time, s (default: the deck's end time).
    #[arg(long)]
    pub until: Option<f64>,
    /// Output directory (default: out/<deck name>/study).
    #[arg(short = 'o', long = "out")]
    pub out: Option<PathBuf>,
    /// Mesh refinement factors, comma-separated (every beam divided into k times its
    /// elements). One factor: the time study on that mesh. Three or more (e.g. 1,2,4): the
    /// space–time study, every (mesh, step) pair run, the finest of both the reference.
    #[arg(long, value_delimiter = ',')]
    pub refine: Vec<u32>,
    /// Beam orders, comma-separated (e.g. 1,2,4,8): the space–time study with every beam of
    /// the deck set to each order p (p + 1 nodes, `ORDER p` in grammar.md), at each
    /// `--refine` factor; the mesh levels are ordered by k·p.
    #[arg(long, value_delimiter = ',')]
    pub order: Vec<u32>,
}

/// `--integrator`'s values ([`Scheme::parse`]).
fn parse_scheme(s: &str) -> Result<Scheme, String> {
    Scheme::parse(s).map_err(|e| e.to_string())
}

impl StudyArgs {
    /// The schemes asked for: `--alpha`'s as HHT, then `--integrator`'s (empty: the deck's),
    /// each once (a scheme named twice would run its ladder twice and write its rows twice).
    pub fn schemes(&self) -> Vec<Scheme> {
        let mut v: Vec<Scheme> = Vec::new();
        let asked = self.alpha.iter().map(|&alpha| Scheme::Hht { alpha });
        for s in asked.chain(self.integrator.iter().copied()) {
            if !v.contains(&s) {
                v.push(s);
            }
        }
        v
    }
}

/// Runs `mecano-rs study` and returns the exit code (0, or 2 for bad input).
pub fn run(args: &StudyArgs) -> u8 {
    let model = match load_deck(&args.deck) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{:?}", miette::Report::new(e));
            return crate::app::EXIT_BAD_INPUT;
        }
    };
    let Analysis::Dynamic { step, .. } = model.analysis else {
        eprintln!(
            "error: {}: a study needs ANALYSIS DYNAMIC",
            args.deck.display()
        );
        return crate::app::EXIT_BAD_INPUT;
    };
    let steps = if args.steps.is_empty() {
        [8.0, 4.0, 2.0, 1.0, 0.5].iter().map(|k| step * k).collect()
    } else {
        args.steps.clone()
    };
    let nodes = if !args.nodes.is_empty() {
        args.nodes.clone()
    } else {
        match &model.output.nodes {
            crate::model::Selection::List(l) => l.iter().map(|n| n.0).collect(),
            _ => model.nodes.keys().map(|n| n.0).collect(),
        }
    };
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| crate::app::default_out_dir(&args.deck, &model).join("study"));
    if args.refine.len() > 1 || !args.order.is_empty() {
        return run_space(args, steps, nodes, out_dir);
    }
    let opts = StudyOptions {
        steps,
        adaptive: args.adaptive.clone(),
        schemes: args.schemes(),
        nodes,
        window: args.window,
        floor: args.floor,
        t_max: args.until,
        out_dir: out_dir.clone(),
        refine: args.refine.first().copied().unwrap_or(1),
    };
    let report = match run_study(&args.deck, &opts, |s| eprintln!("{s}")) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {}: {e}", args.deck.display());
            return crate::app::EXIT_BAD_INPUT;
        }
    };
    let _ = print_table(&report, &mut io::stdout().lock());
    let _ = tolerance::print(&report, &mut io::stdout().lock());
    let _ = needs::print_needs(&report, &mut io::stdout().lock());
    if let Ok(m) = crate::app::modes::load(&args.deck, &[], opts.refine, None) {
        crate::modes::run_summary::study_lines(&m, &opts.steps, &mut io::stdout().lock());
    }
    for ext in ["svg", "png"] {
        let file = out_dir.join(format!("work_precision.{ext}"));
        if let Err(e) = draw_work_precision(&report, &file) {
            eprintln!("error: {}: {e}", file.display());
            return crate::app::EXIT_FAILED;
        }
    }
    let mut written = "work_precision.svg/.png";
    if tolerance::proportionality(&report).is_some() {
        for ext in ["svg", "png"] {
            let file = out_dir.join(format!("tolerance.{ext}"));
            if let Err(e) = tolerance::draw(&report, &file) {
                eprintln!("error: {}: {e}", file.display());
                return crate::app::EXIT_FAILED;
            }
        }
        written = "work_precision.svg/.png, tolerance.svg/.png";
    }
    println!(
        "written: {}/study.csv, study_windows.csv, study_needs.csv, {written}",
        out_dir.display()
    );
    crate::app::EXIT_OK
}

/// The space–time study (`--refine` with several factors, or `--order`).
fn run_space(args: &StudyArgs, steps: Vec<f64>, nodes: Vec<u32>, out_dir: PathBuf) -> u8 {
    let schemes = args.schemes();
    // One integrator per space–time study: its reference is the finest (mesh, step) pair of
    // that integrator, and its table separates space from time errors for it alone; a
    // comparison of integrators is the time study's (one ladder each, on one mesh).
    if !args.adaptive.is_empty() {
        eprintln!(
            "error: {}: a space-time study (several --refine factors, or --order) runs fixed steps only: drop --adaptive",
            args.deck.display()
        );
        return crate::app::EXIT_BAD_INPUT;
    }
    if schemes.len() > 1 {
        let names: Vec<String> = schemes.iter().map(|s| s.label()).collect();
        eprintln!(
            "error: {}: a space-time study (several --refine factors, or --order) runs one integrator, got {} ({}): run it once per integrator (with its own -o DIR), or compare the integrators with a time study (one --refine factor)",
            args.deck.display(),
            schemes.len(),
            names.join(", ")
        );
        return crate::app::EXIT_BAD_INPUT;
    }
    let opts = space::SpaceTimeOptions {
        refine: args.refine.clone(),
        orders: args.order.clone(),
        steps,
        nodes,
        window: args.window,
        floor: args.floor,
        t_max: args.until,
        out_dir: out_dir.clone(),
        scheme: schemes.first().copied(),
    };
    let report = match space::run_space_time(&args.deck, &opts, |s| eprintln!("{s}")) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {}: {e}", args.deck.display());
            return crate::app::EXIT_BAD_INPUT;
        }
    };
    let mut table = Vec::new();
    let _ = space::print_space_time(&report, &mut table);
    let _ = io::stdout().write_all(&table);
    if let Err(e) = std::fs::write(out_dir.join("table.txt"), &table) {
        eprintln!("error: {}: {e}", out_dir.join("table.txt").display());
        return crate::app::EXIT_FAILED;
    }
    for ext in ["svg", "png"] {
        let file = out_dir.join(format!("work_precision.{ext}"));
        if let Err(e) = space::draw_space_time(&report, &file) {
            eprintln!("error: {}: {e}", file.display());
            return crate::app::EXIT_FAILED;
        }
    }
    println!(
        "written: {}/spacetime.csv, spacetime_windows.csv, spacetime_ladders.csv, table.txt, work_precision.svg/.png",
        out_dir.display()
    );
    crate::app::EXIT_OK
}
