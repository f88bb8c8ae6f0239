//! `mecano-rs compare RUN REF`: how far the histories of a run are from a reference's.
//!
//! For every history file the two output directories share (`node_<N>.csv`,
//! `element_<N>.csv`; or the chosen `--nodes`, `--elements`) and every column they share
//! but `t` (or the chosen `--columns`), the difference `d(t) = run(t) − ref(t)` is taken at
//! the run's times; where the reference's times differ from the run's, `ref(t)` is its
//! piecewise-linear interpolant (second-order accurate in the reference's step, so a
//! reference sampled as finely as the run adds an error of the order of its own
//! truncation error). Times of the run outside the reference's time range are not
//! compared, and counted. Reported per file and column: `max |d|`, where it occurs (time,
//! both values), and `max |d|` per time window (`--window`, default 0.25 s).
//!
//! `--tol` judges: one number (absolute, every column, in the column's SI unit), and/or
//! `NAME=VALUE` pairs by column or by group (`position` x,y,z,ux,uy,uz; `rotation`
//! rx,ry,rz; `velocity` vx,vy,vz; `angular_velocity` wx,wy,wz; `acceleration` ax,ay,az);
//! a column's own entry wins over its group's, which wins over the number. Columns with no
//! tolerance are reported, not judged. Exit codes: 0 every judged difference within its
//! tolerance (or none judged), 1 one exceeds it, 2 bad input (a missing directory, file,
//! node, element or column, named with what is available).
//!
//! Rotations are compared as rotations ([`rotation`]): a node's `rx, ry, rz` are reported as
//! one column `rotation`, the angle of `R_runᵀ R_ref` (rad), judged by the `rotation`
//! tolerance. `energy.csv` is compared too, as a history file like the others.

mod diff;
mod history;
mod rotation;
mod table;
mod tolerances;

use crate::app::{EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use diff::{ColumnReport, Extreme, FileReport, Report, Window, compare_histories};
pub use history::{History, read_history};
use tolerances::GROUPS;
pub use tolerances::Tolerances;

/// Exit code: a difference exceeds its tolerance.
pub const EXIT_EXCEEDED: u8 = 1;

/// `mecano-rs compare …`
#[derive(clap::Args, Debug, Clone)]
pub struct CompareArgs {
    /// Output directory of the run to check.
    pub run: PathBuf,
    /// Output directory of the reference.
    pub reference: PathBuf,
    /// Only these nodes (node_<N>.csv), e.g. 12,23.
    #[arg(long, value_delimiter = ',', value_name = "N")]
    pub nodes: Vec<u32>,
    /// Only these elements (element_<N>.csv).
    #[arg(long, value_delimiter = ',', value_name = "N")]
    pub elements: Vec<u32>,
    /// Only these columns, e.g. x,y,rx.
    #[arg(long, value_delimiter = ',', value_name = "COLUMNS")]
    pub columns: Vec<String>,
    /// Tolerances: `1e-6` (every column), `x=1e-3,rx=1e-2`, by group `position=1e-4`, or
    /// both (`1e-6,rotation=1e-4`). Absolute, in the columns' SI units.
    #[arg(long, value_name = "TOL")]
    pub tol: Option<String>,
    /// Width of the time windows of the report, s.
    #[arg(long, default_value_t = 0.25, value_name = "SECONDS")]
    pub window: f64,
    /// The report as JSON (for scripts) instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Bad input of `compare` (exit code 2).
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A directory is missing.
    #[error("{0}: no such directory")]
    NoDir(PathBuf),
    /// A history file is missing or unreadable.
    #[error("{path}: {why}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
    /// A requested node or element has no history in a directory.
    #[error("{what} has no history in {dir} (available: {available})")]
    Missing {
        /// e.g. `node 7`.
        what: String,
        /// The directory.
        dir: PathBuf,
        /// What it has.
        available: String,
    },
    /// A requested column is in none of the compared files.
    #[error("no compared file has a column `{column}` (columns: {available})")]
    Column {
        /// The column.
        column: String,
        /// Columns of the compared files.
        available: String,
    },
    /// Nothing in common.
    #[error("{0} and {1} have no history file in common")]
    Nothing(PathBuf, PathBuf),
    /// A bad `--tol` or `--window`.
    #[error("{0}")]
    Option(String),
}

/// History files of a directory: (kind `node`/`element`, number) → file name.
fn histories(dir: &Path) -> Result<BTreeMap<(String, u32), String>, CompareError> {
    if !dir.is_dir() {
        return Err(CompareError::NoDir(dir.to_path_buf()));
    }
    let rd = std::fs::read_dir(dir).map_err(|e| CompareError::File {
        path: dir.to_path_buf(),
        why: e.to_string(),
    })?;
    let mut out = BTreeMap::new();
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name == "energy.csv" {
            out.insert(("energy".to_string(), 0), name.clone());
        }
        for kind in ["node", "element"] {
            if let Some(n) = name
                .strip_prefix(kind)
                .and_then(|r| r.strip_prefix('_'))
                .and_then(|r| r.strip_suffix(".csv"))
                .and_then(|n| n.parse::<u32>().ok())
            {
                out.insert((kind.to_string(), n), name.clone());
            }
        }
    }
    for (kind, n) in crate::output::columnar::entities(dir) {
        out.entry((kind.clone(), n))
            .or_insert_with(|| format!("{kind}_{n}.csv"));
    }
    Ok(out)
}

fn available(h: &BTreeMap<(String, u32), String>, kind: &str) -> String {
    let v: Vec<String> = h
        .keys()
        .filter(|(k, _)| k == kind)
        .map(|(_, n)| n.to_string())
        .collect();
    if v.is_empty() {
        format!("no {kind}")
    } else {
        format!("{kind}s {}", v.join(", "))
    }
}

/// Compares the histories of two output directories (module docs).
pub fn compare(args: &CompareArgs) -> Result<Report, CompareError> {
    if !(args.window.is_finite() && args.window > 0.0) {
        return Err(CompareError::Option(format!(
            "--window: {} is not a duration > 0",
            args.window
        )));
    }
    let tol = match &args.tol {
        Some(s) => Tolerances::parse(s)?,
        None => Tolerances::default(),
    };
    let (hr, hf) = (histories(&args.run)?, histories(&args.reference)?);
    let mut keys: Vec<(String, u32)> = Vec::new();
    if args.nodes.is_empty() && args.elements.is_empty() {
        keys.extend(hr.keys().filter(|k| hf.contains_key(*k)).cloned());
    } else {
        let wanted = args
            .nodes
            .iter()
            .map(|n| ("node", *n))
            .chain(args.elements.iter().map(|n| ("element", *n)));
        for (kind, n) in wanted {
            let key = (kind.to_string(), n);
            for (h, dir) in [(&hr, &args.run), (&hf, &args.reference)] {
                if !h.contains_key(&key) {
                    return Err(CompareError::Missing {
                        what: format!("{kind} {n}"),
                        dir: dir.clone(),
                        available: available(h, kind),
                    });
                }
            }
            keys.push(key);
        }
    }
    if keys.is_empty() {
        return Err(CompareError::Nothing(
            args.run.clone(),
            args.reference.clone(),
        ));
    }
    let mut loaded = Vec::new();
    for k in &keys {
        let name = &hr[k];
        let a = read_history(&args.run.join(name))?;
        let b = read_history(&args.reference.join(name))?;
        loaded.push((name.clone(), a, b));
    }
    // Columns: the chosen ones (each must be in some compared file), or every shared one.
    let mut all_cols: Vec<&str> = Vec::new();
    for (_, a, b) in &loaded {
        for h in a.header.iter().skip(1).filter(|h| b.header.contains(h)) {
            if !all_cols.contains(&h.as_str()) {
                all_cols.push(h);
            }
        }
    }
    for c in &args.columns {
        if !all_cols.contains(&c.as_str()) {
            return Err(CompareError::Column {
                column: c.clone(),
                available: all_cols.join(","),
            });
        }
    }
    let unknown = tol.unknown(&all_cols);
    if !unknown.is_empty() {
        return Err(CompareError::Option(format!(
            "--tol names {}: neither a compared column ({}) nor a group ({})",
            unknown.join(", "),
            all_cols.join(","),
            GROUPS.map(|g| g.0).join(", ")
        )));
    }
    let mut files = Vec::new();
    for (name, a, b) in &loaded {
        let cols: Vec<String> = if args.columns.is_empty() {
            a.header
                .iter()
                .skip(1)
                .filter(|h| b.header.contains(h))
                .cloned()
                .collect()
        } else {
            args.columns.clone()
        };
        files.push(compare_histories(name, a, b, &cols, args.window, &tol));
    }
    let judged: Vec<bool> = files
        .iter()
        .flat_map(|f| f.columns.iter().filter_map(|c| c.pass))
        .collect();
    let exceeded = judged.iter().filter(|p| !**p).count();
    Ok(Report {
        run: args.run.display().to_string(),
        reference: args.reference.display().to_string(),
        window: args.window,
        files,
        pass: exceeded == 0,
        judged: judged.len(),
        exceeded,
    })
}

/// `mecano-rs compare`: prints the report; returns the exit code (module docs).
pub fn run(args: &CompareArgs) -> u8 {
    let report = match compare(args) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: compare: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let text = if args.json {
        match serde_json::to_string_pretty(&report) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("error: compare: {e}");
                return EXIT_FAILED;
            }
        }
    } else {
        table::render(&report)
    };
    use std::io::Write;
    let _ = writeln!(std::io::stdout(), "{text}");
    if report.pass { EXIT_OK } else { EXIT_EXCEEDED }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hist(header: &str, rows: &[&[f64]]) -> History {
        History {
            header: header.split(',').map(str::to_string).collect(),
            rows: rows.iter().map(|r| r.to_vec()).collect(),
        }
    }

    #[test]
    fn interpolation_of_a_linear_history_is_exact_and_differences_are_located() {
        // ref(t) = 2t + 1 sampled at 0, 0.5, 1; the run at 0.25 and 0.75 reads 1.5 + d
        // and 2.5: the interpolant of a linear function is the function, so |d| only.
        let r = hist("t,x", &[&[0.0, 1.0], &[0.5, 2.0], &[1.0, 3.0]]);
        let a = hist("t,x", &[&[0.25, 1.5 + 1e-3], &[0.75, 2.5], &[1.5, 9.0]]);
        let tol = Tolerances::parse("1e-4").unwrap();
        let f = compare_histories("node_1.csv", &a, &r, &["x".into()], 0.5, &tol);
        assert!(f.interpolated);
        assert_eq!((f.rows_compared, f.rows_outside), (2, 1));
        let c = &f.columns[0];
        let m = c.max.unwrap();
        assert_eq!(m.at_time, 0.25);
        assert!((m.max_abs_diff - 1e-3).abs() < 1e-15);
        assert_eq!(c.pass, Some(false));
        assert_eq!(c.windows[0].max_abs_diff, Some(m.max_abs_diff));
        assert_eq!(c.windows[1].max_abs_diff, Some(0.0));
        assert_eq!(c.windows[2].max_abs_diff, None);
    }

    #[test]
    fn tolerances_by_column_group_and_default() {
        let t = Tolerances::parse("1e-6, rotation=1e-3,rx=1e-2").unwrap();
        assert_eq!(t.of("rx"), Some(1e-2));
        assert_eq!(t.of("ry"), Some(1e-3));
        assert_eq!(t.of("x"), Some(1e-6));
        let t = Tolerances::parse("position=1e-4").unwrap();
        assert_eq!(t.of("gap"), None);
        assert!(Tolerances::parse("x=-1").is_err());
        assert!(Tolerances::parse("x=abc").is_err());
    }
}
