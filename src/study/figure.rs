//! The work–precision diagram (error against CPU time, log–log).

use super::*;
use std::path::Path;

/// Draws the work–precision diagram: position error over the converged windows against CPU
/// seconds, log–log; fixed-step runs joined by a line per α, adaptive runs as another series.
pub fn draw_work_precision(r: &StudyReport, file: &Path) -> Result<(), String> {
    // Position error, or the rotation error when the chosen nodes do not translate.
    let c = compared_quantity(&r.runs);
    let pts: Vec<(f64, f64)> = r
        .runs
        .iter()
        .filter(|x| x.error[c] > 0.0 && x.error[c].is_finite() && x.stats.cpu_seconds > 0.0)
        .map(|x| (x.stats.cpu_seconds, x.error[c]))
        .collect();
    if pts.is_empty() {
        return Err(
            "no run has a measurable error (need at least two fixed steps besides the reference)"
                .into(),
        );
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    let ranges = (x0 / 1.5, x1 * 1.5, y0 / 2.0, y1 * 2.0);
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    let format = crate::figure::Format::of(file);
    crate::figure::draw_to!(format, file, (800, 600), |root| draw_wp(root, r, ranges, c))
}

fn draw_wp<DB: plotters::prelude::DrawingBackend>(
    root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    r: &StudyReport,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    c: usize,
) -> Result<(), String> {
    use plotters::prelude::*;
    {
        let mut chart = ChartBuilder::on(root)
            .caption("Work-precision (converged windows)", ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("CPU time (s)")
            .y_desc(if c == 0 {
                "max position error (m)"
            } else {
                "max rotation error (rad)"
            })
            .x_label_formatter(&|v| cpu_label(*v))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        let mut schemes: Vec<crate::model::Scheme> = r
            .runs
            .iter()
            .filter(|x| x.tol.is_none())
            .map(|x| x.scheme)
            .collect();
        schemes.dedup();
        let colors = [BLUE, RED, GREEN, MAGENTA, CYAN];
        for (k, a) in schemes.iter().enumerate() {
            let s: Vec<(f64, f64)> = r
                .runs
                .iter()
                .filter(|x| {
                    x.tol.is_none() && x.scheme == *a && x.error[c] > 0.0 && x.error[c].is_finite()
                })
                .map(|x| (x.stats.cpu_seconds, x.error[c]))
                .collect();
            let col = colors[k % colors.len()];
            chart
                .draw_series(LineSeries::new(s.clone(), col.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(format!("fixed steps, {a}"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                });
            chart
                .draw_series(s.iter().map(|p| Circle::new(*p, 4, col.filled())))
                .map_err(|e| e.to_string())?;
        }
        let ad: Vec<(f64, f64)> = r
            .runs
            .iter()
            .filter(|x| x.tol.is_some() && x.error[c] > 0.0 && x.error[c].is_finite())
            .map(|x| (x.stats.cpu_seconds, x.error[c]))
            .collect();
        if !ad.is_empty() {
            chart
                .draw_series(LineSeries::new(ad.clone(), BLACK.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label("adaptive")
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2))
                });
            chart
                .draw_series(
                    ad.iter()
                        .map(|p| TriangleMarker::new(*p, 6, BLACK.filled())),
                )
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        Ok(())
    }
}

/// A label for the log CPU-time axis: only at 1, 2 and 5 × 10^k (plotters puts a mesh line
/// at each of 1…9 × 10^k, whose labels would run into each other), in plain decimals.
pub(super) fn cpu_label(v: f64) -> String {
    if v.is_nan() || v <= 0.0 {
        return String::new();
    }
    let m = v / 10f64.powf(v.log10().floor());
    if ![1.0, 2.0, 5.0, 10.0]
        .iter()
        .any(|k| (m - k).abs() < 1e-3 * k)
    {
        return String::new();
    }
    let s = format!("{v:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
