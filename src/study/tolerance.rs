//! Tolerance proportionality (issue 37 §1): how the global error of the adaptive runs
//! follows the tolerance asked, `error ≈ C tol^s`, `s` by least squares in log–log
//! (`s = 1`: the error is proportional to the tolerance — what a user asking for an
//! accuracy needs; Shampine, "Tolerance proportionality in ODE codes", 1989), with the
//! diagram of error against tolerance.

use super::*;
use std::path::Path;

/// The fit of `ln error = ln C + s ln tol` over the adaptive runs with a measurable error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proportionality {
    /// The slope `s`.
    pub slope: f64,
    /// Runs fitted.
    pub runs: usize,
    /// Smallest and largest tolerance fitted, m (or rad).
    pub tol: (f64, f64),
}

/// [`Proportionality`] of the study's adaptive runs (position error, or rotation error when
/// the chosen nodes do not translate); `None` with fewer than two measurable runs.
pub fn proportionality(r: &StudyReport) -> Option<Proportionality> {
    let c = compared_quantity(&r.runs);
    let pts: Vec<(f64, f64)> = r
        .runs
        .iter()
        .filter_map(|x| Some((x.tol?, x.error[c])))
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && e.is_finite())
        .map(|(t, e)| (t.ln(), e.ln()))
        .collect();
    fit(&pts).map(|slope| Proportionality {
        slope,
        runs: pts.len(),
        tol: pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
            (a.min(p.0.exp()), b.max(p.0.exp()))
        }),
    })
}

/// Least-squares slope of `y` on `x`; `None` with fewer than two distinct `x`.
fn fit(p: &[(f64, f64)]) -> Option<f64> {
    let n = p.len() as f64;
    let (mx, my) = p
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (sxy, sxx) = p.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (p.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

/// Prints the fit (nothing without two measurable adaptive runs).
pub fn print(r: &StudyReport, out: &mut dyn io::Write) -> io::Result<()> {
    if let Some(p) = proportionality(r) {
        writeln!(
            out,
            "tolerance proportionality: error ∝ tol^{:.2} over {} adaptive runs, tol {:.1e} … {:.1e} (1 = proportional)",
            p.slope, p.runs, p.tol.0, p.tol.1
        )?;
    }
    Ok(())
}

/// Draws error against tolerance, log–log, with the line `error = tol`.
pub fn draw(r: &StudyReport, file: &Path) -> Result<(), String> {
    let c = compared_quantity(&r.runs);
    let pts: Vec<(f64, f64)> = r
        .runs
        .iter()
        .filter_map(|x| Some((x.tol?, x.error[c])))
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && e.is_finite())
        .collect();
    if pts.len() < 2 {
        return Err("fewer than two adaptive runs with a measurable error".into());
    }
    let lo = pts.iter().fold(f64::INFINITY, |m, p| m.min(p.0).min(p.1)) / 2.0;
    let hi = pts.iter().fold(0.0f64, |m, p| m.max(p.0).max(p.1)) * 2.0;
    let slope = proportionality(r).map_or(f64::NAN, |p| p.slope);
    let format = crate::figure::Format::of(file);
    crate::figure::draw_to!(format, file, (700, 600), |root| {
        use plotters::prelude::*;
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("Global error against tolerance (slope {slope:.2})"),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((lo..hi).log_scale(), (lo..hi).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(if c == 0 {
                "tolerance TOLPOS (m)"
            } else {
                "tolerance TOLROT (rad)"
            })
            .y_desc(if c == 0 {
                "max position error (m)"
            } else {
                "max rotation error (rad)"
            })
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        chart
            .draw_series(LineSeries::new(
                vec![(lo, lo), (hi, hi)],
                BLACK.mix(0.4).stroke_width(1),
            ))
            .map_err(|e| e.to_string())?
            .label("error = tolerance")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.4)));
        chart
            .draw_series(LineSeries::new(pts.clone(), BLUE.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label("adaptive runs")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        chart
            .draw_series(
                pts.iter()
                    .map(|p| TriangleMarker::new(*p, 6, BLUE.filled())),
            )
            .map_err(|e| e.to_string())?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        Ok::<(), String>(())
    })
}

#[cfg(test)]
mod tests {
    use super::fit;

    /// The slope of exact power laws, whatever the constant; undefined on one point.
    #[test]
    fn the_fit_recovers_a_power_law() {
        for s in [0.5, 1.0, 1.7] {
            let p: Vec<(f64, f64)> = [1e-3f64, 1e-4, 1e-5, 1e-6]
                .iter()
                .map(|t| (t.ln(), (3.0 * t.powf(s)).ln()))
                .collect();
            assert!((fit(&p).unwrap() - s).abs() < 1e-12);
        }
        assert_eq!(fit(&[(1.0, 2.0)]), None);
    }
}
