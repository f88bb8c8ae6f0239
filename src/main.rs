//! `mecano-rs`: thin command-line front end; everything lives in the `mecano` library.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// mecano-rs — flexible multibody dynamics from a keyword input deck.
///
/// `mecano-rs DECK` runs a deck; `mecano-rs resume OUTDIR` goes on after a stop;
/// `mecano-rs compare RUN REF` compares the histories of two runs; `mecano-rs plot …`
/// draws figures from a run's output; `mecano-rs study DECK` measures what accuracy costs
/// in time; `mecano-rs modes DECK` gives the linearised modes.
///
/// Exit codes: 0 the run completed; 1 the run failed (diagnosis on standard error,
/// histories kept and marked incomplete); 2 bad input (deck errors, nothing written);
/// 130 interrupted by SIGINT (Ctrl-C) or SIGTERM: the run ends at the end of the step
/// under way with whole rows and a checkpoint (a second signal ends it at once), and
/// `mecano-rs resume OUTDIR` goes on.
#[derive(Parser, Debug)]
#[command(
    name = "mecano-rs",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    after_help = "Exit codes: 0 the run completed; 1 the run failed (diagnosis on standard error, \
histories kept, summary.json \"complete\": false); 2 bad input (deck errors, nothing written); \
130 interrupted by Ctrl-C (SIGINT) or SIGTERM: the run ends at the end of the step under way \
with whole rows and a checkpoint (a second signal ends it at once), and \
`mecano-rs resume OUTDIR` goes on."
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
    /// Run into an output directory that holds files no mecano-rs run wrote there (they
    /// are left as they are). Without it such a directory is refused (exit code 2); the
    /// files of the previous run there (listed in its .mecano-manifest) are always replaced.
    #[arg(long)]
    force: bool,
    /// Wall time between two checkpoints of the run's whole state (in the output
    /// directory, checkpoint.bin), seconds; 0: only at an interruption.
    #[arg(long, value_name = "SECONDS", default_value_t = mecano::app::DEFAULT_CHECKPOINT_SECONDS)]
    checkpoint: f64,
    /// Refine the mesh: divide every BEAM of the deck into K times its elements (a BEAM
    /// with `DIVIDE n` into K·n). Generated nodes and elements are numbered beyond the
    /// deck's; the deck's nodes keep their numbers.
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    refine: u32,
    /// Override a deck parameter (PARAMETERS section): `--set E=2.1e10`; repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = mecano::app::SetParser)]
    set: Vec<(String, f64)>,
    /// The memory the run may take (e.g. 512M, 8G; powers of 1024): a model whose
    /// estimated size exceeds it is refused before it is built (exit 2, with the figure).
    /// Default: the memory available (MemAvailable, or a cgroup's limit).
    #[arg(long = "max-memory", value_name = "SIZE", value_parser = mecano::model::budget::parse_size, global = true)]
    max_memory: Option<u64>,
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
    /// Go on from the last checkpoint of a stopped run (Ctrl-C, SIGTERM, SIGKILL, a crash),
    /// appending to its files: they come out as those of a run never stopped.
    #[command(
        after_help = "Exit codes: as a run's (0 done, 1 failed, 130 interrupted again); 2 when the \
restart is refused: no valid checkpoint, a complete run, or a deck whose text differs from the run's."
    )]
    Resume(mecano::app::ResumeArgs),
    /// Compare the histories of two output directories (largest differences per node,
    /// column and time window); with --tol, exit 1 when a difference exceeds it.
    #[command(
        after_help = "Exit codes: 0 every difference judged is within its tolerance (or none is judged); \
1 one exceeds it; 2 bad input (a missing directory, file, node, element or column)."
    )]
    Compare(mecano::compare::CompareArgs),
    /// Linearised modes: the lowest frequencies, damping ratios and shapes about the initial
    /// state, the static equilibrium (--static) or a run's state at --at T; and what the
    /// deck's step resolves of them.
    #[command(
        after_help = "Exit codes: 0 done; 1 the state could not be reached or the eigen-solve failed; \
2 bad input (deck errors, --count above the free unknowns, --at outside the deck's time, nothing to vibrate)."
    )]
    Modes(mecano::app::modes::ModesArgs),
    /// The linear K and M of a deck's structure at its reference state as Matrix Market
    /// files with its nodes and dof map: what a SUPERELEMENT reads (docs/superelements.md).
    #[command(after_help = "Exit codes: 0 done; 1 a file could not be written; 2 bad input.")]
    Export(mecano::app::export::ExportArgs),
    /// Parameter study: run the cases of a plan (TOML) in parallel, or emit a Slurm job
    /// array, and collect sweep.csv, statistics and figures.
    Sweep(mecano::sweep::SweepArgs),
}

fn main() -> ExitCode {
    mecano::interrupt::Interrupts::default_dispositions();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind as E;
            if matches!(
                e.kind(),
                E::DisplayHelp | E::DisplayVersion | E::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                e.exit();
            }
            // clap's message quotes the argument it refuses whole: each line is cut to a
            // bound (a `--set` of 60,000 nested parentheses echoed 120 kB).
            eprint!("{}", mecano::app::cap_lines(&e.render().to_string()));
            return ExitCode::from(mecano::app::EXIT_BAD_INPUT);
        }
    };
    if let Some(bytes) = cli.max_memory {
        mecano::model::budget::set_max_memory(bytes);
    }
    let code = match (&cli.command, &cli.deck) {
        (Some(Command::Plot(args)), _) => mecano::plot::run(args),
        (Some(Command::Study(args)), _) => mecano::study::run(args),
        (Some(Command::Resume(args)), _) => mecano::app::resume(args),
        (Some(Command::Compare(args)), _) => mecano::compare::run(args),
        (Some(Command::Sweep(args)), _) => mecano::sweep::run(args),
        (Some(Command::Modes(args)), _) => mecano::app::modes::run(args),
        (Some(Command::Export(args)), _) => mecano::app::export::run(args),
        (None, Some(deck)) if cli.check => mecano::app::check(deck, &cli.set, cli.refine),
        (None, Some(deck)) => mecano::app::run(
            deck,
            &mecano::app::RunOptions {
                refine: cli.refine,
                set: cli.set.clone(),
                force: cli.force,
                ..mecano::app::RunOptions::new(cli.out, cli.quiet, cli.checkpoint)
            },
        ),
        // clap requires DECK when no subcommand is given.
        (None, None) => mecano::app::EXIT_BAD_INPUT,
    };
    ExitCode::from(code)
}
