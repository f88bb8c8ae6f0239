//! `mecano-rs`: thin command-line front end; everything lives in the `mecano` library.

use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;

/// mecano-rs — flexible multibody dynamics from a keyword input deck.
///
/// Exit codes: 0 the run completed; 1 the run failed (diagnosis on standard error,
/// histories kept and marked incomplete); 2 bad input (deck errors, nothing written).
#[derive(Parser, Debug)]
#[command(name = "mecano-rs", version, about, long_about = None)]
struct Cli {
    /// The input deck to run (see grammar.md).
    deck: PathBuf,
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let code = if cli.check {
        mecano::app::check(&cli.deck)
    } else {
        mecano::app::run(
            &cli.deck,
            &mecano::app::RunOptions {
                out_dir: cli.out,
                quiet: cli.quiet,
            },
        )
    };
    ExitCode::from(code)
}
