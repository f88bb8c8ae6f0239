//! `mecano-rs plot`: figures from a run's output directory (or several, overlaid).
//!
//! - `trajectory`: paths of chosen nodes in the XY, XZ and YZ planes (the paper's Figs. 4–6);
//! - `history`: chosen columns of chosen nodes against time, several runs overlaid with a
//!   legend (Fig. 7: node 23's `rx`, `vy`, `ay`, rigid vs flexible2);
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
use std::sync::Once;

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

/// `mecano-rs plot history OUT_DIR... --node 23 --columns rx,vy,ay -o fig.svg`
#[derive(Args, Debug, Clone)]
pub struct HistoryArgs {
    /// Output directories of runs (several: overlaid).
    #[arg(required = true, value_name = "OUT_DIR")]
    pub runs: Vec<PathBuf>,
    /// Nodes (the deck's numbers); one panel per node and column.
    #[arg(long = "node", alias = "nodes", num_args = 1.., required = true, value_name = "N")]
    pub nodes: Vec<u32>,
    /// Columns of node_<N>.csv, comma separated (x y z ux uy uz rx ry rz vx vy vz wx wy wz ax ay az).
    #[arg(long, value_delimiter = ',', required = true, value_name = "COLUMNS")]
    pub columns: Vec<String>,
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

/// A CSV table of numbers with named columns.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file it came from.
    pub file: PathBuf,
    /// Column names (header).
    pub columns: Vec<String>,
    /// Rows of values.
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// Reads a CSV file with a header row and numeric values.
    pub fn read(file: &Path) -> Result<Table, PlotError> {
        let err = |msg: String| PlotError::Read {
            file: file.to_path_buf(),
            msg,
        };
        // A run written with OUTPUT FORMAT NETCDF: the same history from histories.nc.
        if !file.is_file()
            && let Some(t) = crate::output::read::from_columnar(file)
        {
            let t = t.map_err(|e| err(e.to_string()))?;
            return Ok(Table {
                file: file.to_path_buf(),
                columns: t.columns,
                rows: t.rows,
            });
        }
        let mut rdr = csv::Reader::from_path(file).map_err(|e| err(e.to_string()))?;
        let columns: Vec<String> = rdr
            .headers()
            .map_err(|e| err(e.to_string()))?
            .iter()
            .map(|s| s.trim().to_string())
            .collect();
        let mut rows = Vec::new();
        for (i, rec) in rdr.records().enumerate() {
            let rec = rec.map_err(|e| err(e.to_string()))?;
            let row: Result<Vec<f64>, _> = rec.iter().map(|v| v.trim().parse::<f64>()).collect();
            rows.push(row.map_err(|e| err(format!("row {}: {e}", i + 2)))?);
        }
        Ok(Table {
            file: file.to_path_buf(),
            columns,
            rows,
        })
    }

    /// Index of a column, or an error naming the available ones.
    pub fn index(&self, name: &str) -> Result<usize, PlotError> {
        self.columns
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| PlotError::NoColumn {
                file: self.file.clone(),
                column: name.to_string(),
                available: self.columns.join(","),
            })
    }

    /// The values of a column.
    pub fn column(&self, name: &str) -> Result<Vec<f64>, PlotError> {
        let i = self.index(name)?;
        Ok(self.rows.iter().map(|r| r[i]).collect())
    }
}

/// Reads `node_<N>.csv` of an output directory.
pub fn read_node(dir: &Path, node: u32) -> Result<Table, PlotError> {
    if !dir.is_dir() {
        return Err(PlotError::NoDir(dir.to_path_buf()));
    }
    let file = dir.join(format!("node_{node}.csv"));
    if !file.is_file() && !crate::output::read::holds(&file) {
        return Err(PlotError::NoFile {
            file,
            hint: format!(
                "node {node} was not written by this run: list it in the deck's OUTPUT NODES"
            ),
        });
    }
    Table::read(&file)
}

/// The quantity and SI unit of a node history column.
pub fn quantity(column: &str) -> Option<(String, &'static str)> {
    let mut ch = column.chars();
    let (a, b) = (ch.next()?, ch.next());
    if ch.next().is_some() {
        return None;
    }
    if column == "t" {
        return Some(("time".into(), "s"));
    }
    let comp = match b {
        None => None,
        Some(c @ ('x' | 'y' | 'z')) => Some(c.to_ascii_uppercase()),
        Some(_) => return None,
    };
    let (what, unit) = match (a, comp) {
        ('x' | 'y' | 'z', None) => {
            return Some((format!("position {}", a.to_ascii_uppercase()), "m"));
        }
        ('u', Some(_)) => ("displacement", "m"),
        ('r', Some(_)) => ("rotation vector", "rad"),
        ('v', Some(_)) => ("velocity", "m/s"),
        ('w', Some(_)) => ("angular velocity", "rad/s"),
        ('a', Some(_)) => ("acceleration", "m/s²"),
        _ => return None,
    };
    Some((format!("{what} {}", comp.unwrap_or(' ')), unit))
}

fn axis_label(column: &str) -> String {
    match quantity(column) {
        Some((q, u)) => format!("{column}: {q} ({u})"),
        None => column.to_string(),
    }
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

static FONT: Once = Once::new();

/// Registers the bundled font as plotters' "sans-serif" (once per process).
pub(crate) fn ensure_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
        // The font is compiled in and known to parse; a failure would only lose the text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, bytes);
    });
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Svg,
    Png,
}

fn format_of(out: &Path, allowed: &[&str]) -> Result<Format, PlotError> {
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !allowed.contains(&ext.as_str()) {
        return Err(PlotError::Usage(format!(
            "{}: the output file must end in {}",
            out.display(),
            allowed
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(" or ")
        )));
    }
    Ok(if ext == "svg" {
        Format::Svg
    } else {
        Format::Png
    })
}

fn prepare_out(out: &Path) -> Result<(), PlotError> {
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| PlotError::Draw {
            file: out.to_path_buf(),
            msg: e.to_string(),
        })?;
    }
    Ok(())
}

/// Draws on an SVG or PNG backend chosen by the file's extension.
macro_rules! with_backend {
    ($fmt:expr, $out:expr, $size:expr, |$root:ident| $body:expr) => {{
        let draw_err = |msg: String| PlotError::Draw {
            file: $out.to_path_buf(),
            msg,
        };
        match $fmt {
            Format::Svg => {
                let $root = SVGBackend::new($out, $size).into_drawing_area();
                $root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
                $body.map_err(draw_err)?;
                $root.present().map_err(|e| draw_err(e.to_string()))?;
            }
            Format::Png => {
                let $root = BitMapBackend::new($out, $size).into_drawing_area();
                $root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
                $body.map_err(draw_err)?;
                $root.present().map_err(|e| draw_err(e.to_string()))?;
            }
        }
    }};
}

/// A series: a label, a colour and points.
struct Series {
    label: String,
    color: RGBColor,
    points: Vec<(f64, f64)>,
}

/// A padded range covering `values` (never empty, never degenerate).
fn range_of(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    let min_span = 1e-12_f64.max(1e-9 * lo.abs().max(hi.abs()));
    if span < min_span {
        let mid = 0.5 * (lo + hi);
        return (mid - min_span, mid + min_span);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// Tick labels: plain for ordinary magnitudes, scientific otherwise.
fn tick(v: &f64, range: (f64, f64)) -> String {
    let m = range.0.abs().max(range.1.abs());
    if *v == 0.0 {
        "0".into()
    } else if !(1e-2..1e4).contains(&m) {
        format!("{v:.2e}")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.into() }
    }
}

/// One panel: a line chart of the series with labelled axes and a legend.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    xdesc: &str,
    ydesc: &str,
    series: &[Series],
    legend: bool,
) -> Result<(), String> {
    let xr = range_of(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let yr = range_of(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(|e| e.to_string())?;
    let fx = move |v: &f64| tick(v, xr);
    let fy = move |v: &f64| tick(v, yr);
    chart
        .configure_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .axis_desc_style(("sans-serif", 15))
        .label_style(("sans-serif", 12))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(|e| e.to_string())?;
    for s in series {
        let color = s.color;
        chart
            .draw_series(LineSeries::new(
                s.points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label(s.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    if legend && !series.is_empty() {
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
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

/// `plot trajectory`: returns the written file.
pub fn trajectory(a: &TrajectoryArgs) -> Result<PathBuf, PlotError> {
    let c = &a.common;
    let fmt = format_of(&c.out, &["svg", "png"])?;
    let labels = labels_for(&a.runs, &c.labels)?;
    let mut planes = Vec::new();
    for p in &a.planes {
        let p = p.trim().to_ascii_lowercase();
        let axes: Vec<char> = p.chars().collect();
        if axes.len() != 2 || axes[0] == axes[1] || !axes.iter().all(|c| "xyz".contains(*c)) {
            return Err(PlotError::Usage(format!(
                "--planes: {p:?} is not a plane (use xy, xz, yz, yx, zx or zy)"
            )));
        }
        planes.push((axes[0].to_string(), axes[1].to_string()));
    }
    // series[plane] = lines over runs × nodes
    let mut series: Vec<Vec<Series>> = planes.iter().map(|_| Vec::new()).collect();
    let mut k = 0;
    for (run, label) in a.runs.iter().zip(&labels) {
        for &n in &a.nodes {
            let table = read_node(run, n)?;
            let t = table.column("t")?;
            for (pi, (h, v)) in planes.iter().enumerate() {
                let xs = table.column(h)?;
                let ys = table.column(v)?;
                let points = (0..t.len())
                    .filter(|&i| in_window(t[i], c.from, c.to))
                    .map(|i| (xs[i], ys[i]))
                    .collect();
                let name = if a.runs.len() > 1 {
                    format!("{label}, node {n}")
                } else {
                    format!("node {n}")
                };
                series[pi].push(Series {
                    label: name,
                    color: COLORS[k % COLORS.len()],
                    points,
                });
            }
            k += 1;
        }
    }
    let title = c.title.clone().unwrap_or_else(|| {
        let nodes: Vec<String> = a.nodes.iter().map(|n| n.to_string()).collect();
        format!(
            "Trajectories of nodes {} — {}",
            nodes.join(", "),
            labels.join(" vs ")
        )
    });
    let size = c.size.unwrap_or((450 * planes.len() as u32, 480));
    prepare_out(&c.out)?;
    ensure_font();
    let out = c.out.as_path();
    with_backend!(fmt, out, size, |root| {
        (|| -> Result<(), String> {
            let area = root
                .titled(&title, ("sans-serif", 20))
                .map_err(|e| e.to_string())?;
            let panels = area.split_evenly((1, planes.len()));
            for (pi, ((h, v), p)) in planes.iter().zip(&panels).enumerate() {
                let cap = format!("{}{} plane", h.to_uppercase(), v.to_uppercase());
                panel(
                    p,
                    &cap,
                    &format!("{} (m)", h.to_uppercase()),
                    &format!("{} (m)", v.to_uppercase()),
                    &series[pi],
                    pi == 0,
                )?;
            }
            Ok(())
        })()
    });
    Ok(c.out.clone())
}

/// `plot history`: returns the written file.
pub fn history(a: &HistoryArgs) -> Result<PathBuf, PlotError> {
    let c = &a.common;
    let fmt = format_of(&c.out, &["svg", "png"])?;
    let labels = labels_for(&a.runs, &c.labels)?;
    let columns: Vec<String> = a
        .columns
        .iter()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    if columns.is_empty() {
        return Err(PlotError::Usage("--columns: no column given".into()));
    }
    // panels[(node, column)] = one series per run
    let mut panels: Vec<(String, String, Vec<Series>)> = Vec::new();
    let mut tables: Vec<BTreeMap<u32, Table>> = Vec::new();
    for run in &a.runs {
        let mut m = BTreeMap::new();
        for &n in &a.nodes {
            m.insert(n, read_node(run, n)?);
        }
        tables.push(m);
    }
    for &n in &a.nodes {
        for col in &columns {
            let mut ss = Vec::new();
            for (ri, label) in labels.iter().enumerate() {
                let table = &tables[ri][&n];
                let t = table.column("t")?;
                let y = table.column(col)?;
                ss.push(Series {
                    label: label.clone(),
                    color: COLORS[ri % COLORS.len()],
                    points: (0..t.len())
                        .filter(|&i| in_window(t[i], c.from, c.to))
                        .map(|i| (t[i], y[i]))
                        .collect(),
                });
            }
            panels.push((format!("node {n}"), axis_label(col), ss));
        }
    }
    let title = c.title.clone().unwrap_or_else(|| {
        format!(
            "Time histories — {}",
            if labels.len() > 1 {
                labels.join(" vs ")
            } else {
                labels[0].clone()
            }
        )
    });
    let size = c.size.unwrap_or((900, 300 * panels.len() as u32 + 40));
    prepare_out(&c.out)?;
    ensure_font();
    let out = c.out.as_path();
    with_backend!(fmt, out, size, |root| {
        (|| -> Result<(), String> {
            let area = root
                .titled(&title, ("sans-serif", 20))
                .map_err(|e| e.to_string())?;
            let areas = area.split_evenly((panels.len(), 1));
            for (i, ((cap, ydesc, ss), p)) in panels.iter().zip(&areas).enumerate() {
                panel(p, cap, "t: time (s)", ydesc, ss, i == 0)?;
            }
            Ok(())
        })()
    });
    Ok(c.out.clone())
}

/// The deck named in `dir/summary.json`.
pub fn deck_of(dir: &Path) -> Result<PathBuf, PlotError> {
    let file = dir.join("summary.json");
    let text = std::fs::read_to_string(&file).map_err(|_| PlotError::NoFile {
        file: file.clone(),
        hint: "not a run's output directory? give the deck with --deck".into(),
    })?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| PlotError::Read {
        file: file.clone(),
        msg: e.to_string(),
    })?;
    v.get("deck")
        .and_then(|d| d.as_str())
        .map(PathBuf::from)
        .ok_or_else(|| PlotError::Read {
            file,
            msg: "no \"deck\" entry: give the deck with --deck".into(),
        })
}

/// The `--refine` factor recorded in `dir/summary.json` (1 when absent).
pub fn refine_of(dir: &Path) -> u32 {
    std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v.get("refine").and_then(|r| r.as_u64()))
        .and_then(|r| u32::try_from(r).ok())
        .unwrap_or(1)
}

/// The segments to draw for a model: pairs of node numbers (beams, rigid bodies as chains,
/// joints), and whether each is a joint.
pub fn connectivity(model: &Model) -> Vec<(u32, u32, bool)> {
    let mut segs = Vec::new();
    for el in model.elements.values() {
        let ids: Vec<u32> = el.nodes.iter().map(|n| n.0).collect();
        match &el.kind {
            ElementKind::Beam { .. } | ElementKind::Rigid => {
                for w in ids.windows(2) {
                    segs.push((w[0], w[1], false));
                }
            }
            ElementKind::Mass { .. } | ElementKind::Came(_) => {}
            _ => {
                if ids.len() == 2 {
                    segs.push((ids[0], ids[1], true));
                }
            }
        }
    }
    segs
}

/// `plot animate`: returns the written file.
pub fn animate(a: &AnimateArgs) -> Result<PathBuf, PlotError> {
    let ext = a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext != "gif" {
        return Err(PlotError::Usage(format!(
            "{}: the animation is written as a GIF: the output file must end in .gif",
            a.out.display()
        )));
    }
    if a.frames == 0 {
        return Err(PlotError::Usage("--frames must be at least 1".into()));
    }
    if !a.run.is_dir() {
        return Err(PlotError::NoDir(a.run.clone()));
    }
    let deck = match &a.deck {
        Some(d) => d.clone(),
        None => deck_of(&a.run)?,
    };
    if !deck.is_file() {
        return Err(PlotError::NoFile {
            file: deck,
            hint: "the deck of the run (from summary.json, relative to the directory the run was started in); give it with --deck".into(),
        });
    }
    // Prints the deck's diagnostics on failure.
    // The run's mesh: a run with --refine k records k in summary.json.
    let refine = refine_of(&a.run);
    let model = crate::app::load_refined(&deck, refine).map_err(|_| PlotError::Read {
        file: deck.clone(),
        msg: "the deck has errors (shown above)".into(),
    })?;
    let segs = connectivity(&model);
    let masses: Vec<u32> = model
        .elements
        .values()
        .filter(|e| matches!(e.kind, ElementKind::Mass { .. }))
        .map(|e| e.nodes[0].0)
        .collect();
    // Node histories: every drawn node needs one, except fully fixed nodes (drawn in place).
    let mut drawn: Vec<u32> = segs
        .iter()
        .flat_map(|s| [s.0, s.1])
        .chain(masses.iter().copied())
        .collect();
    drawn.sort_unstable();
    drawn.dedup();
    let mut tables: BTreeMap<u32, Table> = BTreeMap::new();
    let mut missing = Vec::new();
    for &n in &drawn {
        match read_node(&a.run, n) {
            Ok(t) => {
                tables.insert(n, t);
            }
            Err(PlotError::NoFile { .. }) => {
                let fixed = model
                    .nodes
                    .get(&crate::model::NodeId(n))
                    .is_some_and(|nd| nd.fixed[..3].iter().all(|&f| f));
                if !fixed {
                    missing.push(n);
                }
            }
            Err(e) => return Err(e),
        }
    }
    if !missing.is_empty() {
        return Err(PlotError::NoFile {
            file: a.run.join(format!("node_{}.csv", missing[0])),
            hint: format!(
                "the animation needs the history of every moving node; missing: {}; run the deck with OUTPUT NODES ALL",
                missing
                    .iter()
                    .map(|n| n.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        });
    }
    let Some(first) = tables.values().next() else {
        return Err(PlotError::Usage("no node history to animate".into()));
    };
    let t = first.column("t")?;
    let n_rows = tables.values().map(|t| t.rows.len()).min().unwrap_or(0);
    let rows: Vec<usize> = (0..n_rows)
        .filter(|&i| in_window(t[i], a.from, a.to))
        .collect();
    if rows.is_empty() {
        return Err(PlotError::Usage("no rows in the chosen time window".into()));
    }
    let (ix, iy, iz) = (first.index("x")?, first.index("y")?, first.index("z")?);
    let pos = |n: u32, row: usize| -> (f64, f64, f64) {
        match tables.get(&n) {
            Some(t) => (t.rows[row][ix], t.rows[row][iy], t.rows[row][iz]),
            None => {
                let p = model.nodes[&crate::model::NodeId(n)].position;
                (p.x, p.y, p.z)
            }
        }
    };
    // Fixed axis ranges over all frames, equal scales in both panels.
    let all = || {
        rows.iter()
            .flat_map(|&r| drawn.iter().map(move |&n| (n, r)))
    };
    let xr = range_of(all().map(|(n, r)| pos(n, r).0));
    let yr = range_of(all().map(|(n, r)| pos(n, r).1));
    let zr = range_of(all().map(|(n, r)| pos(n, r).2));
    let (w, h) = a.size;
    let pw = f64::from(w / 2 - 100);
    let ph = f64::from(h - 120);
    let equal = |hr: (f64, f64), vr: (f64, f64)| {
        let sx = (hr.1 - hr.0) / pw;
        let sy = (vr.1 - vr.0) / ph;
        let s = sx.max(sy);
        let grow = |r: (f64, f64), len: f64| {
            let mid = 0.5 * (r.0 + r.1);
            (mid - 0.5 * s * len, mid + 0.5 * s * len)
        };
        (grow(hr, pw), grow(vr, ph))
    };
    let (ex, ey) = equal(xr, yr);
    let (px, pz) = equal(xr, zr);
    let step = (rows.len() as f64 / a.frames as f64).max(1.0);
    let frames: Vec<usize> = (0..a.frames.min(rows.len()))
        .map(|k| rows[((k as f64 * step) as usize).min(rows.len() - 1)])
        .collect();
    prepare_out(&a.out)?;
    ensure_font();
    let draw_err = |msg: String| PlotError::Draw {
        file: a.out.clone(),
        msg,
    };
    let root = BitMapBackend::gif(&a.out, a.size, a.delay)
        .map_err(|e| draw_err(e.to_string()))?
        .into_drawing_area();
    let title = model.title.clone();
    for &row in &frames {
        (|| -> Result<(), String> {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let mut head = String::new();
            let _ = write!(head, "{title} — t = {:.3} s", t[row]);
            let area = root
                .titled(&head, ("sans-serif", 18))
                .map_err(|e| e.to_string())?;
            let halves = area.split_evenly((1, 2));
            for (k, p) in halves.iter().enumerate() {
                let (hr, vr, vdesc, cap) = if k == 0 {
                    (ex, ey, "Y (m)", "elevation (X–Y)")
                } else {
                    (px, pz, "Z (m)", "plan (X–Z)")
                };
                let proj = |n: u32| {
                    let q = pos(n, row);
                    if k == 0 { (q.0, q.1) } else { (q.0, q.2) }
                };
                let mut chart = ChartBuilder::on(p)
                    .caption(cap, ("sans-serif", 15))
                    .margin(10)
                    .x_label_area_size(40)
                    .y_label_area_size(55)
                    .build_cartesian_2d(hr.0..hr.1, vr.0..vr.1)
                    .map_err(|e| e.to_string())?;
                chart
                    .configure_mesh()
                    .x_desc("X (m)")
                    .y_desc(vdesc)
                    .axis_desc_style(("sans-serif", 13))
                    .label_style(("sans-serif", 11))
                    .light_line_style(WHITE.mix(0.0))
                    .draw()
                    .map_err(|e| e.to_string())?;
                chart
                    .draw_series(segs.iter().map(|&(n1, n2, joint)| {
                        let style = if joint {
                            RGBColor(120, 120, 120).stroke_width(1)
                        } else {
                            COLORS[0].stroke_width(3)
                        };
                        PathElement::new(vec![proj(n1), proj(n2)], style)
                    }))
                    .map_err(|e| e.to_string())?;
                chart
                    .draw_series(
                        masses
                            .iter()
                            .map(|&n| Circle::new(proj(n), 5, COLORS[1].filled())),
                    )
                    .map_err(|e| e.to_string())?;
            }
            root.present().map_err(|e| e.to_string())
        })()
        .map_err(draw_err)?;
    }
    Ok(a.out.clone())
}
