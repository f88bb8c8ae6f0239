//! The figures of a sweep (plotters, SVG, in `<out>/figures/`):
//!
//! * a 1-D sweep (one parameter on a grid, nothing random): each quantity against the
//!   parameter (`<quantity>_vs_<parameter>.svg`), with the plan's reference points
//!   (`[[reference]]`: published values) and power-law guides (`[[guide]]`: y ∝ x^exponent
//!   through a point); logarithmic axes for a log range and for positive values spanning
//!   more than two decades;
//! * random parameters: a histogram of each quantity (`<quantity>_hist.svg`, ⌈√n⌉ bins,
//!   5 to 40) and its scatter plot against each random parameter
//!   (`<quantity>_vs_<parameter>.svg`).
//!
//! Each figure is written as `.svg` and `.png`. Only the cases that ended `ok` are drawn. Axes on a log scale are drawn in log10 of the
//! value, their ticks labelled with the value.

use super::SweepError;
use super::collect::values_of;
use super::plan::{Plan, Variation};
use super::runner::{CaseRecord, Status};
use plotters::prelude::*;
use std::path::PathBuf;

struct Axis {
    log: bool,
    lo: f64,
    hi: f64,
}

impl Axis {
    fn of(values: &[f64], log: bool) -> Axis {
        let log = log && values.iter().all(|v| *v > 0.0);
        let t: Vec<f64> = values
            .iter()
            .map(|v| if log { v.log10() } else { *v })
            .collect();
        let (mut lo, mut hi) = t
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        let pad = if hi > lo {
            0.05 * (hi - lo)
        } else {
            0.5 * lo.abs().max(if log { 0.5 } else { 1e-12 })
        };
        Axis {
            log,
            lo: lo - pad,
            hi: hi + pad,
        }
    }

    fn map(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    fn label(&self, v: f64) -> String {
        if self.log {
            let x = 10f64.powf(v);
            return format!("{x:.1e}");
        }
        // Enough digits to tell ticks about (hi − lo)/10 apart.
        let step = ((self.hi - self.lo) / 10.0).abs().max(f64::MIN_POSITIVE);
        let big = self.lo.abs().max(self.hi.abs());
        if !(1e-2..1e4).contains(&big) {
            let digits = ((big / step).log10().ceil() as usize).clamp(1, 10);
            format!("{v:.*e}", digits - 1)
        } else {
            let decimals = (-step.log10().floor()).max(0.0) as usize;
            format!("{v:.*}", decimals.min(12))
        }
    }
}

/// Values spanning more than two decades, all positive: a log axis.
fn wide(values: &[f64]) -> bool {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, 0f64), |(a, b), v| (a.min(*v), b.max(*v)));
    values.iter().all(|v| *v > 0.0) && hi > 100.0 * lo
}

type Series = (String, Vec<(f64, f64)>, RGBColor, bool);

/// Draws into `file` (`.svg`) and its `.png` twin.
fn draw_xy(
    file: &PathBuf,
    title: &str,
    names: (&str, &str),
    axes: (&Axis, &Axis),
    series: &[Series],
) -> Result<(), String> {
    use crate::figure::{Format, draw_to};
    draw_to!(Format::Svg, file, SIZE, |root| xy_on(
        root, title, names, axes, series
    ))?;
    let png = file.with_extension("png");
    draw_to!(Format::Png, &png, SIZE, |root| xy_on(
        root, title, names, axes, series
    ))
}

const SIZE: (u32, u32) = (800, 520);

fn xy_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    (xname, yname): (&str, &str),
    (xa, ya): (&Axis, &Axis),
    series: &[Series],
) -> Result<(), String> {
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(xa.lo..xa.hi, ya.lo..ya.hi)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(xname)
        .y_desc(yname)
        .x_label_formatter(&|v| xa.label(*v))
        .y_label_formatter(&|v| ya.label(*v))
        .draw()
        .map_err(|e| e.to_string())?;
    for (label, pts, color, line) in series {
        let pts: Vec<(f64, f64)> = pts.iter().map(|(x, y)| (xa.map(*x), ya.map(*y))).collect();
        let style = color.stroke_width(2);
        if *line {
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(|e| e.to_string())?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        } else {
            let c = *color;
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))
                .map_err(|e| e.to_string())?
                .label(label.as_str())
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Draws into `file` (`.svg`) and its `.png` twin.
fn draw_hist(file: &PathBuf, title: &str, name: &str, x: &[f64]) -> Result<(), String> {
    use crate::figure::{Format, draw_to};
    draw_to!(Format::Svg, file, SIZE, |root| hist_on(
        root, title, name, x
    ))?;
    let png = file.with_extension("png");
    draw_to!(Format::Png, &png, SIZE, |root| hist_on(
        root, title, name, x
    ))
}

fn hist_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    name: &str,
    x: &[f64],
) -> Result<(), String> {
    let n = x.len();
    let bins = ((n as f64).sqrt().ceil() as usize).clamp(5, 40);
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5, lo + 0.5)
    };
    let w = (hi - lo) / bins as f64;
    let mut counts = vec![0u32; bins];
    for v in x {
        let k = (((v - lo) / w) as usize).min(bins - 1);
        counts[k] += 1;
    }
    let top = f64::from(counts.iter().copied().max().unwrap_or(1)) * 1.1;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(lo..hi, 0.0..top)
        .map_err(|e| e.to_string())?;
    let xa = Axis { log: false, lo, hi };
    chart
        .configure_mesh()
        .x_desc(name)
        .y_desc("cases")
        .x_label_formatter(&|v| xa.label(*v))
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(counts.iter().enumerate().map(|(k, c)| {
            let x0 = lo + k as f64 * w;
            Rectangle::new([(x0, 0.0), (x0 + w, f64::from(*c))], BLUE.mix(0.5).filled())
        }))
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Draws the figures of the plan's kind; returns the files written.
pub fn draw(plan: &Plan, records: &[CaseRecord]) -> Result<Vec<PathBuf>, SweepError> {
    let dir = plan.out.join("figures");
    std::fs::create_dir_all(&dir).map_err(|e| SweepError::Io {
        path: dir.clone(),
        reason: e.to_string(),
    })?;
    let fail = |file: &PathBuf, msg: String| SweepError::Io {
        path: file.clone(),
        reason: msg,
    };
    let ok: Vec<&CaseRecord> = records.iter().filter(|r| r.status == Status::Ok).collect();
    let mut files = Vec::new();
    let pairs = |k: usize, j: usize| -> Vec<(f64, f64)> {
        ok.iter()
            .filter_map(|r| r.quantities[k].map(|y| (r.values[j], y)))
            .collect()
    };
    if let Some(j) = plan.one_dimensional() {
        let p = &plan.params[j];
        let xlog = matches!(p.variation, Variation::Grid { log: true, .. });
        for (k, q) in plan.quantities.iter().enumerate() {
            let pts = pairs(k, j);
            if pts.is_empty() {
                continue;
            }
            let mut series: Vec<Series> = vec![(q.name.clone(), pts.clone(), BLUE, true)];
            series.push(("cases".into(), pts.clone(), BLUE, false));
            let colors = [RED, BLACK, GREEN, MAGENTA, CYAN];
            let mut c = 0;
            for r in plan
                .references
                .iter()
                .filter(|r| r.quantity == q.name && r.parameter == p.name)
            {
                let pts = r.points.iter().map(|a| (a[0], a[1])).collect();
                series.push((r.label.clone(), pts, colors[c % colors.len()], false));
                c += 1;
            }
            let (x0, x1) = pts
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v.0), b.max(v.0))
                });
            for g in plan
                .guides
                .iter()
                .filter(|g| g.quantity == q.name && g.parameter == p.name)
            {
                let f = |x: f64| g.through[1] * (x / g.through[0]).powf(g.exponent);
                let xs: Vec<f64> = (0..=40)
                    .map(|i| {
                        let s = f64::from(i) / 40.0;
                        if xlog && x0 > 0.0 {
                            (x0.ln() + s * (x1.ln() - x0.ln())).exp()
                        } else {
                            x0 + s * (x1 - x0)
                        }
                    })
                    .collect();
                series.push((
                    g.label.clone(),
                    xs.iter().map(|&x| (x, f(x))).collect(),
                    colors[c % colors.len()],
                    true,
                ));
                c += 1;
            }
            let xs: Vec<f64> = series
                .iter()
                .flat_map(|s| s.1.iter().map(|p| p.0))
                .collect();
            let ys: Vec<f64> = pts
                .iter()
                .map(|p| p.1)
                .chain(
                    plan.references
                        .iter()
                        .filter(|r| r.quantity == q.name)
                        .flat_map(|r| r.points.iter().map(|a| a[1])),
                )
                .collect();
            let ya = Axis::of(&ys, wide(&ys));
            // Guides are clipped to the data's y range (they only show slopes).
            for s in series.iter_mut().filter(|s| s.3 && s.0 != q.name) {
                s.1.retain(|(_, y)| {
                    let m = ya.map(*y);
                    m >= ya.lo && m <= ya.hi
                });
            }
            let file = dir.join(format!("{}_vs_{}.svg", q.name, p.name));
            draw_xy(
                &file,
                &format!("{} against {}", q.name, p.name),
                (&p.name, &q.name),
                (&Axis::of(&xs, xlog), &ya),
                &series,
            )
            .map_err(|m| fail(&file, m))?;
            files.push(file);
        }
    }
    let random: Vec<usize> = (0..plan.params.len())
        .filter(|&j| plan.params[j].variation.is_random())
        .collect();
    if !random.is_empty() {
        for (k, q) in plan.quantities.iter().enumerate() {
            let x = values_of(records, k);
            if x.is_empty() {
                continue;
            }
            let file = dir.join(format!("{}_hist.svg", q.name));
            draw_hist(
                &file,
                &format!("{} over {} cases", q.name, x.len()),
                &q.name,
                &x,
            )
            .map_err(|m| fail(&file, m))?;
            files.push(file);
            for &j in &random {
                let p = &plan.params[j];
                let pts = pairs(k, j);
                let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
                let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
                let file = dir.join(format!("{}_vs_{}.svg", q.name, p.name));
                draw_xy(
                    &file,
                    &format!("{} against {}", q.name, p.name),
                    (&p.name, &q.name),
                    (&Axis::of(&xs, false), &Axis::of(&ys, false)),
                    &[(q.name.clone(), pts, BLUE, false)],
                )
                .map_err(|m| fail(&file, m))?;
                files.push(file);
            }
        }
    }
    Ok(files)
}
