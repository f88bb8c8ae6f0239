//! The readable report of `mecano-rs compare`: one line per file and column, with the
//! largest difference, where it is, its tolerance and verdict, and the largest per window.

use super::Report;
use std::fmt::Write as _;

fn num(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_string(), |v| format!("{v:.3e}"))
}

/// Renders a report as a text table.
pub fn render(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "compare {} against {}", r.run, r.reference);
    let n_win = r
        .files
        .iter()
        .flat_map(|f| f.columns.iter().map(|c| c.windows.len()))
        .max()
        .unwrap_or(0);
    let mut head = format!(
        "{:<16} {:<14} {:>10} {:>10} {:>11} {:>11} {:>9} {:<4}",
        "file", "column", "max |diff|", "at t (s)", "run", "ref", "tol", "ok"
    );
    for w in 0..n_win {
        let _ = write!(
            head,
            " {:>10}",
            format!("<{:.3}", (w + 1) as f64 * r.window)
        );
    }
    let _ = writeln!(s, "{head}");
    for f in &r.files {
        for c in &f.columns {
            let (d, t, a, b) = match c.max {
                Some(m) => (
                    num(Some(m.max_abs_diff)),
                    format!("{:.4}", m.at_time),
                    num(Some(m.run_value)),
                    num(Some(m.ref_value)),
                ),
                None => ("-".into(), "-".into(), "-".into(), "-".into()),
            };
            let ok = match c.pass {
                Some(true) => "ok",
                Some(false) => "FAIL",
                None => "",
            };
            let mut line = format!(
                "{:<16} {:<14} {:>10} {:>10} {:>11} {:>11} {:>9} {:<4}",
                f.file,
                c.column,
                d,
                t,
                a,
                b,
                num(c.tolerance),
                ok
            );
            for w in &c.windows {
                let _ = write!(line, " {:>10}", num(w.max_abs_diff));
            }
            let _ = writeln!(s, "{}", line.trim_end());
        }
        if f.interpolated || f.rows_outside > 0 {
            let _ = writeln!(
                s,
                "{:<16} ({} rows compared{}{})",
                "",
                f.rows_compared,
                if f.interpolated {
                    ", the reference interpolated linearly in time"
                } else {
                    ""
                },
                if f.rows_outside > 0 {
                    format!(
                        ", {} rows outside the reference's time range",
                        f.rows_outside
                    )
                } else {
                    String::new()
                }
            );
        }
    }
    let _ = write!(
        s,
        "{} columns judged, {} over tolerance: {}",
        r.judged,
        r.exceeded,
        if r.pass { "PASS" } else { "FAIL" }
    );
    s
}
