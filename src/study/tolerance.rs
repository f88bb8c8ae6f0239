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

/// The reference's own resolution where a run's error is measured: the largest
/// difference of the two finest fixed runs over the windows counted (converged) for the
/// quantity `c`. An error below about ten times it is not measured (issue 37).
pub fn resolution(r: &StudyReport, c: usize) -> f64 {
    r.converged
        .iter()
        .zip(&r.reference_uncertainty)
        .filter(|(k, _)| k[c])
        .fold(0.0f64, |m, (_, u)| m.max(u[c]))
}

/// One adaptive run against the next looser one: the local slope `Δ ln error / Δ ln tol`
/// and what the tighter tolerance costs, as ratios of steps, Newton iterations and CPU
/// (wall) seconds per decade of tolerance (`ratio^(1/decades)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decade {
    /// Looser and tighter tolerance.
    pub tol: (f64, f64),
    /// Local slope between the two runs.
    pub slope: f64,
    /// Steps, Newton iterations, CPU s: factor per decade of tolerance.
    pub cost: [f64; 3],
}

/// [`Decade`]s between successive adaptive runs (sorted by tolerance, loosest first)
/// whose errors are measurable.
pub fn decades(r: &StudyReport) -> Vec<Decade> {
    let c = compared_quantity(&r.runs);
    let mut runs: Vec<&StudyRun> = r
        .runs
        .iter()
        .filter(|x| x.tol.is_some_and(|t| t > 0.0) && x.error[c] > 0.0 && x.error[c].is_finite())
        .collect();
    runs.sort_by(|a, b| b.tol.unwrap_or(0.0).total_cmp(&a.tol.unwrap_or(0.0)));
    runs.windows(2)
        .filter_map(|w| {
            let (a, b) = (w[0], w[1]);
            let (ta, tb) = (a.tol?, b.tol?);
            let dec = (ta / tb).log10();
            (dec > 0.0).then(|| {
                let per = |x: f64, y: f64| (y / x).powf(1.0 / dec);
                Decade {
                    tol: (ta, tb),
                    slope: (a.error[c] / b.error[c]).ln() / (ta / tb).ln(),
                    cost: [
                        per(a.stats.steps as f64, b.stats.steps as f64),
                        per(
                            a.stats.newton_iterations as f64,
                            b.stats.newton_iterations as f64,
                        ),
                        per(a.stats.cpu_seconds, b.stats.cpu_seconds),
                    ],
                }
            })
        })
        .collect()
}

/// Prints the fit (nothing without two measurable adaptive runs), each run's error
/// against the tolerance and the reference's resolution, and the cost of each decade.
pub fn print(r: &StudyReport, out: &mut dyn io::Write) -> io::Result<()> {
    let Some(p) = proportionality(r) else {
        return Ok(());
    };
    writeln!(
        out,
        "tolerance proportionality: error ∝ tol^{:.2} over {} adaptive runs, tol {:.1e} … {:.1e} (1 = proportional)",
        p.slope, p.runs, p.tol.0, p.tol.1
    )?;
    let c = compared_quantity(&r.runs);
    let res = resolution(r, c);
    let below = r
        .runs
        .iter()
        .filter(|x| x.tol.is_some() && x.error[c] < 10.0 * res)
        .count();
    writeln!(
        out,
        "  the reference's resolution (its two finest runs' difference over the windows counted): {res:.2e}{}",
        if below > 0 {
            format!(
                "; {below} adaptive run(s) err less than 10 times it: not measured, the fit leans on them"
            )
        } else {
            String::new()
        }
    )?;
    for d in decades(r) {
        writeln!(
            out,
            "  tol {:.1e} → {:.1e}: local slope {:.2}; per decade of tolerance ×{:.2} steps, ×{:.2} Newton iterations, ×{:.2} CPU s",
            d.tol.0, d.tol.1, d.slope, d.cost[0], d.cost[1], d.cost[2]
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
    use super::*;

    fn run(tol: Option<f64>, error: f64, steps: u64) -> StudyRun {
        StudyRun {
            label: String::new(),
            h: 1e-3,
            scheme: crate::model::Scheme::Esdirk5,
            tol,
            stats: solver::Stats {
                steps,
                newton_iterations: 3 * steps,
                cpu_seconds: 1e-3 * steps as f64,
                ..Default::default()
            },
            complete: true,
            stopped: None,
            window_errors: Vec::new(),
            error: [error, f64::NAN, f64::NAN],
            order: None,
            fixed_equivalent: None,
        }
    }

    /// Local slopes and costs per decade between successive tolerances, loosest first,
    /// whatever the order the runs come in; a half-decade's cost ratio scaled to a decade;
    /// the resolution the largest difference over the converged windows only.
    #[test]
    fn decades_give_local_slopes_and_costs_per_decade() {
        let r = StudyReport {
            runs: vec![
                run(None, 1e-6, 1000),
                run(None, 0.0, 2000),
                run(Some(1e-4), 2e-7, 800),
                run(Some(1e-2), 1e-5, 100),
                run(Some(1e-3), 1e-6, 200),
                run(Some(1e-3 / 10f64.sqrt()), 1e-6 / 10f64.sqrt(), 400),
            ],
            windows: vec![0.0, 1.0],
            converged: vec![[true; 3], [false; 3]],
            reference_uncertainty: vec![[2e-8; 3], [1.0; 3]],
        };
        let d = decades(&r);
        assert_eq!(d.len(), 3);
        assert!((d[0].tol.0 - 1e-2).abs() < 1e-15 && (d[0].tol.1 - 1e-3).abs() < 1e-15);
        assert!((d[0].slope - 1.0).abs() < 1e-12 && (d[0].cost[0] - 2.0).abs() < 1e-12);
        // Half a decade that doubled the steps: ×4 per decade.
        assert!((d[1].slope - 1.0).abs() < 1e-12 && (d[1].cost[0] - 4.0).abs() < 1e-12);
        assert!((d[1].cost[1] - 4.0).abs() < 1e-12 && (d[1].cost[2] - 4.0).abs() < 1e-9);
        // 1e-6/√10 → 2e-7 over half a decade: slope ln(1.58)/ln(3.16).
        let s = (1e-6 / 10f64.sqrt() / 2e-7f64).ln() / 10f64.sqrt().ln();
        assert!((d[2].slope - s).abs() < 1e-12);
        assert_eq!(resolution(&r, 0), 2e-8);
    }

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
