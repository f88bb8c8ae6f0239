//! The study's files (`study.csv`, `study_windows.csv`) and printed table.

use super::*;
use std::io::Write;
use std::path::Path;

/// An error for the CSV files: empty where it is not a number (no converged window, or a
/// run that stopped early), so that no NaN or infinity is written.
pub(super) fn csv_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        String::new()
    }
}

/// An error for the printed table: `-` where no window is converged, `stopped` where the
/// run stopped before the window's end.
pub(super) fn table_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2e}")
    } else if x.is_nan() {
        "-".into()
    } else {
        "stopped".into()
    }
}

/// Writes `study.csv` (one row per run) and `study_windows.csv` (one row per run and window).
pub fn write_results(r: &StudyReport, dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = csv::Writer::from_path(dir.join("study.csv"))?;
    w.write_record([
        "run",
        "h",
        "integrator",
        "adaptive_tol",
        "cpu_seconds",
        "steps",
        "newton_iterations",
        "factorizations",
        "rejected_steps",
        "complete",
        "error_position",
        "error_rotation",
        "error_velocity",
        "observed_order",
        "fixed_cpu_same_error",
        "cheapest_fixed_cpu_within_error",
        "cheapest_fixed_h_within_error",
    ])?;
    for run in &r.runs {
        let fe = run.fixed_equivalent;
        let interpolated = fe.and_then(|f| f.interpolated);
        let cheapest = fe.and_then(|f| f.cheapest);
        w.write_record([
            run.label.clone(),
            format!("{:e}", run.h),
            run.scheme.label(),
            run.tol.map_or(String::new(), |t| format!("{t:e}")),
            format!("{:.4}", run.stats.cpu_seconds),
            run.stats.steps.to_string(),
            run.stats.newton_iterations.to_string(),
            run.stats.factorizations.to_string(),
            run.stats.rejected_steps.to_string(),
            run.complete.to_string(),
            csv_number(run.error[0]),
            csv_number(run.error[1]),
            csv_number(run.error[2]),
            run.order.map_or(String::new(), |o| format!("{o:.3}")),
            interpolated.map_or(String::new(), |c| format!("{c:.4}")),
            cheapest.map_or(String::new(), |c| format!("{:.4}", c.0)),
            cheapest.map_or(String::new(), |c| format!("{:e}", c.1)),
        ])?;
    }
    w.flush()?;
    let mut w = csv::Writer::from_path(dir.join("study_windows.csv"))?;
    w.write_record([
        "run",
        "window_start",
        "position_converged",
        "rotation_converged",
        "velocity_converged",
        "reference_uncertainty_position",
        "reference_uncertainty_rotation",
        "reference_uncertainty_velocity",
        "error_position",
        "error_rotation",
        "error_velocity",
    ])?;
    for run in &r.runs {
        for (k, t) in r.windows.iter().enumerate() {
            let e = run.window_errors[k];
            w.write_record([
                run.label.clone(),
                format!("{t}"),
                r.converged[k][0].to_string(),
                r.converged[k][1].to_string(),
                r.converged[k][2].to_string(),
                csv_number(r.reference_uncertainty[k][0]),
                csv_number(r.reference_uncertainty[k][1]),
                csv_number(r.reference_uncertainty[k][2]),
                csv_number(e[0]),
                csv_number(e[1]),
                csv_number(e[2]),
            ])?;
        }
    }
    w.flush()
}

/// Prints the study table.
pub fn print_table(r: &StudyReport, out: &mut dyn Write) -> io::Result<()> {
    writeln!(
        out,
        "windows (s): reference converged? (finest two runs differ by) in position, rotation, velocity"
    )?;
    let flag = |c: bool| if c { "yes" } else { "NO " };
    for (k, t) in r.windows.iter().enumerate() {
        let (c, d) = (r.converged[k], r.reference_uncertainty[k]);
        writeln!(
            out,
            "  [{t:6.3}, …)  x {} ({} m)  R {} ({} rad)  v {} ({} m/s)",
            flag(c[0]),
            table_number(d[0]),
            flag(c[1]),
            table_number(d[1]),
            flag(c[2]),
            table_number(d[2])
        )?;
    }
    writeln!(
        out,
        "{:<32} {:>9} {:>8} {:>8} {:>8} {:>10} {:>10} {:>10} {:>6}",
        "run", "CPU s", "steps", "Newton", "factor.", "err x (m)", "err R", "err v", "order"
    )?;
    for run in &r.runs {
        writeln!(
            out,
            "{:<32} {:>9.3} {:>8} {:>8} {:>8} {:>10} {:>10} {:>10} {:>6}",
            run.label,
            run.stats.cpu_seconds,
            run.stats.steps,
            run.stats.newton_iterations,
            run.stats.factorizations,
            table_number(run.error[0]),
            table_number(run.error[1]),
            table_number(run.error[2]),
            run.order.map_or("-".into(), |o| format!("{o:.2}")),
        )?;
        if let Some(why) = &run.stopped {
            writeln!(out, "  └ {why}")?;
        }
    }
    let adaptive: Vec<(&StudyRun, FixedEquivalent)> = r
        .runs
        .iter()
        .filter_map(|x| Some((x, x.fixed_equivalent?)))
        .collect();
    let (c, unit) = match compared_quantity(&r.runs) {
        0 => (0, "m"),
        _ => (1, "rad"),
    };
    if !adaptive.is_empty() {
        writeln!(
            out,
            "adaptive against fixed steps at the same {} error (ratio = adaptive CPU / fixed CPU):",
            ["position", "rotation"][c]
        )?;
    }
    for (run, fe) in adaptive {
        let cpu = run.stats.cpu_seconds;
        let interp = fe
            .interpolated
            .map_or("no fixed pair brackets its error".to_string(), |f| {
                format!("fixed steps {f:.3} s (interpolated), ratio {:.2}", cpu / f)
            });
        let cheapest = fe
            .cheapest
            .map_or("no fixed run is as accurate".to_string(), |(f, h)| {
                format!(
                    "cheapest fixed run as accurate h = {h:.3e}: {f:.3} s, ratio {:.2}",
                    cpu / f
                )
            });
        writeln!(
            out,
            "  {:<30} {:.2e} {unit} in {cpu:.3} s: {interp}; {cheapest}",
            run.label, run.error[c]
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::fixed_equivalent;
    use super::{csv_number, table_number};

    /// A quantity without a converged window (NaN) or a run that stopped (infinite error)
    /// is an empty CSV field and a word in the table, never a NaN or `inf` in a file.
    /// On a work–precision line error = h², CPU = 1/h (order 2, cost ∝ steps) the
    /// interpolation is exact in (ln error, ln CPU): an error h*² costs 1/h*. The cheapest
    /// run within an error is the coarsest that reaches it; the reference (error 0) and a
    /// stopped run (infinite error) are ignored; an error below every run's has no
    /// bracketing pair.
    #[test]
    fn fixed_equivalent_interpolates_the_work_precision_line() {
        let ladder: Vec<(f64, f64, f64)> = [8e-3, 4e-3, 2e-3, 1e-3]
            .iter()
            .map(|&h| (h, h * h, 1.0 / h))
            .chain([(5e-4, 0.0, 2000.0), (1e-2, f64::INFINITY, 1.0)])
            .collect();
        let h_star: f64 = 3e-3;
        let f = fixed_equivalent(&ladder, h_star * h_star);
        let c = f.interpolated.expect("bracketed");
        assert!((c - 1.0 / h_star).abs() < 1e-9 * c, "{c}");
        assert_eq!(f.cheapest, Some((500.0, 2e-3)));
        let f = fixed_equivalent(&ladder, 1e-7);
        assert_eq!(f.interpolated, None);
        assert_eq!(f.cheapest, None);
    }

    #[test]
    fn errors_that_are_not_numbers_are_not_written_as_numbers() {
        assert_eq!(csv_number(f64::NAN), "");
        assert_eq!(csv_number(f64::INFINITY), "");
        assert_eq!(csv_number(2.5e-4), "2.5e-4");
        assert_eq!(table_number(f64::NAN), "-");
        assert_eq!(table_number(f64::INFINITY), "stopped");
        assert_eq!(table_number(2.5e-4), "2.50e-4");
    }
}
