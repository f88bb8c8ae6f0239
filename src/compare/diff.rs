//! The differences of two histories: the reference interpolated at the run's times, the
//! largest difference per column and per time window.

use super::*;

/// The largest difference over a set of rows.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Extreme {
    /// `max |run − ref|`.
    pub max_abs_diff: f64,
    /// Time of it, s.
    pub at_time: f64,
    /// The run's value there.
    pub run_value: f64,
    /// The reference's (interpolated) value there.
    pub ref_value: f64,
}

/// One time window of a column.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Window {
    /// Start, s.
    pub from: f64,
    /// End, s.
    pub to: f64,
    /// Largest difference in it (`None`: no compared row in it).
    pub max_abs_diff: Option<f64>,
}

/// The comparison of one column of one file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ColumnReport {
    /// Column name.
    pub column: String,
    /// Largest difference (`None`: no row compared).
    pub max: Option<Extreme>,
    /// Per time window.
    pub windows: Vec<Window>,
    /// Its tolerance, if judged.
    pub tolerance: Option<f64>,
    /// Within it (`None`: not judged).
    pub pass: Option<bool>,
}

/// The comparison of one file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FileReport {
    /// File name, e.g. `node_23.csv`.
    pub file: String,
    /// Rows of the run compared.
    pub rows_compared: usize,
    /// Rows of the run outside the reference's time range (not compared).
    pub rows_outside: usize,
    /// The reference was interpolated (its times differ from the run's).
    pub interpolated: bool,
    /// Per column.
    pub columns: Vec<ColumnReport>,
}

/// The whole comparison.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Report {
    /// The run's directory.
    pub run: String,
    /// The reference's directory.
    pub reference: String,
    /// Window width, s.
    pub window: f64,
    /// Per file.
    pub files: Vec<FileReport>,
    /// Every judged column within its tolerance.
    pub pass: bool,
    /// Columns judged, and how many exceed their tolerance.
    pub judged: usize,
    /// Columns over their tolerance.
    pub exceeded: usize,
}

/// The reference's value of column `c` at time `t`: linear interpolation between the
/// rows around `t` (`k` is a cursor into `rows`, advanced monotonically). `None` outside
/// the reference's time range.
fn interpolate(rows: &[Vec<f64>], k: &mut usize, t: f64, c: usize) -> Option<f64> {
    let (first, last) = (rows.first()?[0], rows.last()?[0]);
    if t < first || t > last {
        return None;
    }
    while *k + 1 < rows.len() && rows[*k + 1][0] < t {
        *k += 1;
    }
    // rows[k].t < t <= rows[k+1].t, or t == first.
    let a = &rows[*k];
    if a[0] == t || *k + 1 == rows.len() {
        return Some(a[c]);
    }
    let b = &rows[*k + 1];
    if b[0] == t {
        return Some(b[c]);
    }
    let s = (t - a[0]) / (b[0] - a[0]);
    Some(a[c] + s * (b[c] - a[c]))
}

impl ColumnReport {
    /// The report of a column: its largest difference, the largest per time window
    /// (`wins[w]` over `[w·window, (w+1)·window)`), and its judgement against `tolerance`.
    pub(super) fn new(
        column: String,
        max: Option<Extreme>,
        wins: &[Option<f64>],
        window: f64,
        tolerance: Option<f64>,
    ) -> Self {
        ColumnReport {
            column,
            max,
            windows: wins
                .iter()
                .enumerate()
                .map(|(w, m)| Window {
                    from: w as f64 * window,
                    to: (w + 1) as f64 * window,
                    max_abs_diff: *m,
                })
                .collect(),
            tolerance,
            pass: tolerance.map(|tv| max.is_none_or(|m| m.max_abs_diff <= tv)),
        }
    }
}

/// Compares two histories on the chosen columns (names present in both).
pub fn compare_histories(
    file: &str,
    run: &History,
    reference: &History,
    columns: &[String],
    window: f64,
    tol: &Tolerances,
) -> FileReport {
    let same_times = run.rows.len() == reference.rows.len()
        && run
            .rows
            .iter()
            .zip(&reference.rows)
            .all(|(a, b)| a[0] == b[0]);
    let t_end = run.rows.last().map_or(0.0, |r| r[0]);
    let n_win = ((t_end / window).floor() as usize + 1).max(1);
    let mut out = Vec::new();
    let mut compared = 0;
    let mut outside = 0;
    let (columns, by_rotation) = super::rotation::split(columns, run, reference);
    for (ci, name) in columns.iter().enumerate() {
        let (Some(cr), Some(cf)) = (
            run.header.iter().position(|h| h == name),
            reference.header.iter().position(|h| h == name),
        ) else {
            continue;
        };
        let mut max: Option<Extreme> = None;
        let mut wins: Vec<Option<f64>> = vec![None; n_win];
        let mut k = 0;
        let (mut cmp_rows, mut out_rows) = (0, 0);
        for (i, row) in run.rows.iter().enumerate() {
            let t = row[0];
            let r = if same_times {
                Some(reference.rows[i][cf])
            } else {
                interpolate(&reference.rows, &mut k, t, cf)
            };
            let Some(r) = r else {
                out_rows += 1;
                continue;
            };
            cmp_rows += 1;
            let d = (row[cr] - r).abs();
            if max.is_none_or(|m| d > m.max_abs_diff) {
                max = Some(Extreme {
                    max_abs_diff: d,
                    at_time: t,
                    run_value: row[cr],
                    ref_value: r,
                });
            }
            let w = ((t / window).floor().max(0.0) as usize).min(n_win - 1);
            wins[w] = Some(wins[w].map_or(d, |m: f64| m.max(d)));
        }
        if ci == 0 || cmp_rows > compared {
            compared = cmp_rows;
            outside = out_rows;
        }
        out.push(ColumnReport::new(
            name.clone(),
            max,
            &wins,
            window,
            tol.of(name),
        ));
    }
    if by_rotation {
        let tv = tol.of(super::rotation::NAME);
        let (c, cmp_rows, out_rows) =
            super::rotation::compare(run, reference, same_times, window, n_win, tv);
        if out.is_empty() || cmp_rows > compared {
            (compared, outside) = (cmp_rows, out_rows);
        }
        out.push(c);
    }
    FileReport {
        file: file.to_string(),
        rows_compared: compared,
        rows_outside: outside,
        interpolated: !same_times,
        columns: out,
    }
}
