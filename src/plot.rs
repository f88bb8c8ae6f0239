//! `mecano-rs plot`: figures from a run's output directory (or several, overlaid).
//!
//! - `trajectory`: paths of chosen nodes in the XY, XZ and YZ planes (the paper's Figs. 4–6);
//! - `history`: chosen columns of chosen nodes against time, several runs overlaid with a
//!   legend (Fig. 7: node 23's `rx`, `vy`, `ay`, rigid vs flexible2);
//! - `modes`: the shapes of a modal analysis in two planes and its frequencies;
//! - `animate`: the whole model (beam, rigid-body and joint connectivity read from the deck)
//!   in elevation (X–Y) and plan (X–Z) as an animated GIF (Fig. 3).
//!
//! The format follows the extension of `-o`: `.svg` (vector) or `.png` (bitmap); `animate`
//! writes `.gif`. Axes are labelled with the quantity and its unit (the node history
//! columns are documented in the README: SI units).
//!
//! Text is drawn with the DejaVu Sans font compiled into the binary
//! (`assets/fonts/DejaVuSans.ttf`, through plotters' `ab_glyph` feature), so the figures
//! need no system font and no fontconfig.
//!
//! Errors (missing directory, file, node or column; a deck that does not parse) are
//! [`PlotError`]s with a message naming what is missing; the binary prints them and exits
//! with code 2 ([`crate::app::EXIT_BAD_INPUT`]); a failure to write the figure exits 1.

use crate::app::{EXIT_BAD_INPUT, EXIT_FAILED};
use crate::model::{ElementKind, Model};
use clap::{Args, Subcommand};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[macro_use]
mod draw;
mod animate;
mod history;
mod modes;
mod table;
mod trajectory;

pub use animate::{animate, connectivity, deck_of, refine_of};
pub use history::history;
pub use modes::{ModesArgs, label as modes_label, modes};
pub use table::{Table, quantity, read_element, read_node};
pub use trajectory::trajectory;

/// `mecano-rs plot …`: the figure to draw.
#[derive(Args, Debug, Clone)]
pub struct PlotArgs {
    /// The kind of figure.
    #[command(subcommand)]
    pub figure: Figure,
}

/// The figures `mecano-rs plot` draws.
#[derive(Subcommand, Debug, Clone)]
pub enum Figure {
    /// Trajectories of nodes in the XY, XZ and YZ planes (paper Figs. 4–6).
    Trajectory(TrajectoryArgs),
    /// Time histories of columns of nodes, several runs overlaid (paper Fig. 7).
    History(HistoryArgs),
    /// Animated GIF of the whole model in elevation (X–Y) and plan (X–Z) (paper Fig. 3).
    Animate(AnimateArgs),
    /// The shapes of a modal analysis (`mecano-rs modes`) in two planes, and its frequencies.
    Modes(ModesArgs),
}

/// Options shared by the figures that overlay runs.
#[derive(Args, Debug, Clone)]
pub struct Common {
    /// Output file: `.svg` or `.png`.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    pub out: PathBuf,
    /// Legend labels of the runs, in order, comma separated (default: the directory names).
    #[arg(long, value_delimiter = ',', value_name = "LABELS")]
    pub labels: Vec<String>,
    /// Only plot from this time on, s.
    #[arg(long, value_name = "T")]
    pub from: Option<f64>,
    /// Only plot up to this time, s.
    #[arg(long, value_name = "T")]
    pub to: Option<f64>,
    /// Figure size in pixels, WIDTHxHEIGHT (default depends on the figure).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Figure title (default: a description of the figure).
    #[arg(long)]
    pub title: Option<String>,
}

/// `mecano-rs plot trajectory OUT_DIR... --nodes 12 23 -o fig.svg`
#[derive(Args, Debug, Clone)]
pub struct TrajectoryArgs {
    /// Output directories of runs (several: overlaid).
    #[arg(required = true, value_name = "OUT_DIR")]
    pub runs: Vec<PathBuf>,
    /// Nodes to trace (the deck's numbers).
    #[arg(long, num_args = 1.., required = true, value_name = "N")]
    pub nodes: Vec<u32>,
    /// Planes to draw, comma separated, from xy, xz, yz (first letter: horizontal axis).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "xy,xz,yz",
        value_name = "PLANES"
    )]
    pub planes: Vec<String>,
    /// Output file, labels, time window, size, title.
    #[command(flatten)]
    pub common: Common,
}

/// `mecano-rs plot history OUT_DIR... --node 23 --columns rx,vy,ay -o fig.svg`, or an
/// element's columns: `--element 23 --element-columns normal_force`.
#[derive(Args, Debug, Clone)]
pub struct HistoryArgs {
    /// Output directories of runs (several: overlaid).
    #[arg(required = true, value_name = "OUT_DIR")]
    pub runs: Vec<PathBuf>,
    /// Nodes (the deck's numbers); one panel per node and column.
    #[arg(long = "node", alias = "nodes", num_args = 1.., required_unless_present = "elements", value_name = "N")]
    pub nodes: Vec<u32>,
    /// Columns of node_<N>.csv, comma separated (x y z ux uy uz rx ry rz vx vy vz wx wy wz ax ay az).
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    pub columns: Vec<String>,
    /// Elements (the deck's numbers) whose element_<N>.csv columns are drawn, one panel per
    /// element and column: a driving torque, a contact force, a spring's tension.
    #[arg(long = "element", alias = "elements", num_args = 1.., value_name = "N")]
    pub elements: Vec<u32>,
    /// Columns of element_<N>.csv, comma separated (the element's header, README: e.g.
    /// normal_force, torque, force); default: --columns.
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    pub element_columns: Vec<String>,
    /// Output file, labels, time window, size, title.
    #[command(flatten)]
    pub common: Common,
}

/// `mecano-rs plot animate OUT_DIR [--deck DECK] -o anim.gif`
#[derive(Args, Debug, Clone)]
pub struct AnimateArgs {
    /// Output directory of the run (its deck should write every node: `OUTPUT NODES ALL`).
    #[arg(value_name = "OUT_DIR")]
    pub run: PathBuf,
    /// The deck (for the connectivity); default: the deck named in OUT_DIR/summary.json.
    #[arg(long)]
    pub deck: Option<PathBuf>,
    /// Output file (`.gif`).
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    pub out: PathBuf,
    /// Number of frames (evenly spread over the run's rows).
    #[arg(long, default_value_t = 100)]
    pub frames: usize,
    /// Delay between frames, ms.
    #[arg(long, default_value_t = 60)]
    pub delay: u32,
    /// Figure size in pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "1000x500")]
    pub size: (u32, u32),
    /// Only animate from this time on, s.
    #[arg(long, value_name = "T")]
    pub from: Option<f64>,
    /// Only animate up to this time, s.
    #[arg(long, value_name = "T")]
    pub to: Option<f64>,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (16..=10000).contains(&n))
            .ok_or_else(|| format!("bad size {s:?}: each side an integer in 16..=10000"))
    };
    Ok((p(w)?, p(h)?))
}

/// What can go wrong when drawing a figure.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The output directory does not exist.
    #[error("{0}: no such output directory")]
    NoDir(PathBuf),
    /// A file is missing from an output directory.
    #[error("{file}: not found ({hint})")]
    NoFile {
        /// The missing file.
        file: PathBuf,
        /// What to do about it.
        hint: String,
    },
    /// A requested column is not in a file.
    #[error("{file}: no column {column:?} (columns: {available})")]
    NoColumn {
        /// The file.
        file: PathBuf,
        /// The requested column.
        column: String,
        /// The file's columns.
        available: String,
    },
    /// A file could not be read or parsed.
    #[error("{file}: {msg}")]
    Read {
        /// The file.
        file: PathBuf,
        /// The problem.
        msg: String,
    },
    /// A bad option value.
    #[error("{0}")]
    Usage(String),
    /// The figure could not be drawn or written.
    #[error("{file}: cannot draw the figure: {msg}")]
    Draw {
        /// The output file.
        file: PathBuf,
        /// The problem.
        msg: String,
    },
}

impl PlotError {
    /// Exit code: 1 when writing the figure failed, 2 for bad input.
    pub fn exit_code(&self) -> u8 {
        match self {
            PlotError::Draw { .. } => EXIT_FAILED,
            _ => EXIT_BAD_INPUT,
        }
    }
}

/// `mecano-rs plot …`: draws the figure, prints errors; returns the exit code.
pub fn run(args: &PlotArgs) -> u8 {
    let res = match &args.figure {
        Figure::Trajectory(a) => trajectory(a),
        Figure::History(a) => history(a),
        Figure::Animate(a) => animate(a),
        Figure::Modes(a) => modes(a),
    };
    match res {
        Ok(path) => {
            println!("wrote {}", path.display());
            crate::app::EXIT_OK
        }
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}

fn labels_for(runs: &[PathBuf], labels: &[String]) -> Result<Vec<String>, PlotError> {
    if !labels.is_empty() && labels.len() != runs.len() {
        return Err(PlotError::Usage(format!(
            "--labels gives {} labels for {} runs",
            labels.len(),
            runs.len()
        )));
    }
    Ok(runs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            labels.get(i).cloned().unwrap_or_else(|| {
                r.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_else(|| r.display().to_string())
            })
        })
        .collect())
}

fn in_window(t: f64, from: Option<f64>, to: Option<f64>) -> bool {
    from.is_none_or(|f| t >= f) && to.is_none_or(|e| t <= e)
}
