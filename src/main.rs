//! `mecano-rs`: thin command-line front end; everything lives in the `mecano` library.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// mecano-rs — flexible multibody dynamics from a keyword input deck.
///
/// `mecano-rs DECK` runs a deck; `mecano-rs plot …` draws figures from a run's output;
/// `mecano-rs study DECK` measures what accuracy costs in time.
///
/// Exit codes: 0 the run completed; 1 the run failed (diagnosis on standard error,
/// histories kept and marked incomplete); 2 bad input (deck errors, nothing written).
#[derive(Parser, Debug)]
#[command(
    name = "mecano-rs",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    /// A subcommand; without one, run the deck.
    #[command(subcommand)]
    command: Option<Command>,
    /// The input deck to run (see grammar.md).
    #[arg(required = true)]
    deck: Option<PathBuf>,
    /// Output directory (default: the deck's OUTPUT DIR, else out/<deck name>/).
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    out: Option<PathBuf>,
    /// Parse and validate the deck, print its summary (nodes, elements, degrees of
    /// freedom, constraints, active effects) and exit without simulating.
    #[arg(long)]
    check: bool,
    /// No progress bar and no closing summary line.
    #[arg(short, long)]
    quiet: bool,
    /// Refine the mesh: divide every BEAM of the deck into K times its elements (a BEAM
    /// with `DIVIDE n` into K·n). Generated nodes and elements are numbered beyond the
    /// deck's; the deck's nodes keep their numbers.
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    refine: u32,
}

/// Subcommands: one variant each, the logic in the library.
#[derive(Subcommand, Debug)]
enum Command {
    /// Draw figures (SVG, PNG, animated GIF) from the output directory of runs.
    Plot(mecano::plot::PlotArgs),
    /// Work-precision study: run a deck at a ladder of time steps (and adaptive tolerances),
    /// report CPU time, steps, Newton iterations and errors per time window, draw error
    /// against CPU time.
    Study(mecano::study::StudyArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let code = match (&cli.command, &cli.deck) {
        (Some(Command::Plot(args)), _) => mecano::plot::run(args),
        (Some(Command::Study(args)), _) => mecano::study::run(args),
        (None, Some(deck)) if cli.check => mecano::app::check(deck, cli.refine),
        (None, Some(deck)) => mecano::app::run(
            deck,
            &mecano::app::RunOptions {
                out_dir: cli.out,
                quiet: cli.quiet,
                refine: cli.refine,
            },
        ),
        // clap requires DECK when no subcommand is given.
        (None, None) => mecano::app::EXIT_BAD_INPUT,
    };
    ExitCode::from(code)
}
