//! The space–time study's files, printed table and work–precision diagram.

use super::super::report::{csv_number, table_number};
use super::{GridRun, SpaceTimeReport};
use std::io::{self, Write};
use std::path::Path;

fn label(r: &GridRun) -> String {
    format!(
        "{} ({} beams), h = {:.3e}",
        super::mesh_name(r.refine, r.order),
        r.beams,
        r.h
    )
}

/// Writes `spacetime.csv` (one row per run), `spacetime_windows.csv` (per run and window),
/// `spacetime_peaks.csv` (per run, chosen node — by its position in `--nodes` — and window:
/// the largest displacement components) and `spacetime_ladders.csv` (per ladder level and
/// window: error, order, convergence).
pub fn write_space_time(r: &SpaceTimeReport, dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut w = csv::Writer::from_path(dir.join("spacetime.csv"))?;
    w.write_record([
        "refine",
        "order",
        "beam_elements",
        "h",
        "cpu_seconds",
        "steps",
        "newton_iterations",
        "factorizations",
        "complete",
        "error_position",
        "frontier",
    ])?;
    for x in &r.runs {
        w.write_record([
            x.refine.to_string(),
            x.order.to_string(),
            x.beams.to_string(),
            format!("{:e}", x.h),
            format!("{:.4}", x.stats.cpu_seconds),
            x.stats.steps.to_string(),
            x.stats.newton_iterations.to_string(),
            x.stats.factorizations.to_string(),
            x.complete.to_string(),
            csv_number(x.error),
            x.frontier.to_string(),
        ])?;
    }
    w.flush()?;
    let mut w = csv::Writer::from_path(dir.join("spacetime_windows.csv"))?;
    w.write_record([
        "refine",
        "order",
        "h",
        "window_start",
        "error_position",
        "reference_converged_space",
        "reference_converged_time",
        "reference_uncertainty_space",
        "reference_uncertainty_time",
    ])?;
    for x in &r.runs {
        for (k, t) in r.windows.iter().enumerate() {
            w.write_record([
                x.refine.to_string(),
                x.order.to_string(),
                format!("{:e}", x.h),
                format!("{t}"),
                csv_number(x.window_errors[k]),
                r.space.converged[k].to_string(),
                r.time.converged[k].to_string(),
                csv_number(r.space.uncertainty[k]),
                csv_number(r.time.uncertainty[k]),
            ])?;
        }
    }
    w.flush()?;
    let mut w = csv::Writer::from_path(dir.join("spacetime_peaks.csv"))?;
    w.write_record([
        "refine",
        "order",
        "h",
        "node_index",
        "window_start",
        "max_abs_ux",
        "max_abs_uy",
        "max_abs_uz",
    ])?;
    for x in &r.runs {
        for (n, p) in x.peaks.iter().enumerate() {
            for (k, t) in r.windows.iter().enumerate() {
                let Some(v) = p.get(k) else { continue };
                w.write_record([
                    x.refine.to_string(),
                    x.order.to_string(),
                    format!("{:e}", x.h),
                    n.to_string(),
                    format!("{t}"),
                    format!("{:e}", v[0]),
                    format!("{:e}", v[1]),
                    format!("{:e}", v[2]),
                ])?;
            }
        }
    }
    w.flush()?;
    let mut w = csv::Writer::from_path(dir.join("spacetime_ladders.csv"))?;
    w.write_record([
        "ladder",
        "level",
        "window_start",
        "error_position",
        "observed_order",
        "converged",
    ])?;
    for (name, l) in [("space", &r.space), ("time", &r.time)] {
        for (i, lev) in l.levels.iter().enumerate() {
            for (k, t) in r.windows.iter().enumerate() {
                w.write_record([
                    name.to_string(),
                    format!("{lev:e}"),
                    format!("{t}"),
                    csv_number(l.errors[i][k]),
                    csv_number(l.orders[i][k]),
                    l.converged[k].to_string(),
                ])?;
            }
        }
    }
    w.flush()
}

fn order_text(p: f64) -> String {
    if p.is_finite() {
        format!("{p:.2}")
    } else {
        "-".into()
    }
}

/// Prints the space–time table: per window the reference's convergence in space and in
/// time; each ladder's errors and orders per window; every run's CPU and error.
pub fn print_space_time(r: &SpaceTimeReport, out: &mut dyn Write) -> io::Result<()> {
    let rf = &r.runs[r.runs.len() - 1];
    writeln!(
        out,
        "space-time reference: {} ({} beams), h = {:.3e} s",
        super::mesh_name(rf.refine, rf.order),
        rf.beams,
        rf.h
    )?;
    writeln!(
        out,
        "windows (s): reference converged in space? (two finest meshes differ by) in time? (two finest steps differ by) -> scored?"
    )?;
    let flag = |c: bool| if c { "yes" } else { "NO " };
    for (k, t) in r.windows.iter().enumerate() {
        writeln!(
            out,
            "  [{t:6.3}, …)  space {} ({} m)  time {} ({} m)  -> {}",
            flag(r.space.converged[k]),
            table_number(r.space.uncertainty[k]),
            flag(r.time.converged[k]),
            table_number(r.time.uncertainty[k]),
            if r.converged[k] {
                format!(
                    "scored, uncertainty {} m",
                    table_number(r.reference_uncertainty[k])
                )
            } else if r.time.converged[k] {
                "not converged in space: not scored".to_string()
            } else {
                "not scored".to_string()
            }
        )?;
    }
    for (name, l, unit) in [
        ("space: meshes at the finest step", &r.space, "k·p"),
        ("time: steps at the finest mesh", &r.time, "h (s)"),
    ] {
        writeln!(
            out,
            "{name}; error against the finest level per window (m) | observed order per window"
        )?;
        write!(out, "{unit:>10}")?;
        for t in &r.windows {
            write!(out, " {:>9}", format!("{t:.2}-"))?;
        }
        writeln!(out, " | orders")?;
        for (i, lev) in l.levels.iter().enumerate() {
            write!(out, "{:>10}", format!("{lev}"))?;
            for e in &l.errors[i] {
                write!(out, " {:>9}", table_number(*e))?;
            }
            let o: Vec<String> = l.orders[i].iter().map(|p| order_text(*p)).collect();
            writeln!(out, " | {}", o.join(" "))?;
        }
    }
    writeln!(
        out,
        "{:<36} {:>9} {:>8} {:>9} {:>10}  frontier",
        "run", "CPU s", "steps", "Newton", "err x (m)"
    )?;
    for x in &r.runs {
        writeln!(
            out,
            "{:<36} {:>9.3} {:>8} {:>9} {:>10}  {}",
            label(x),
            x.stats.cpu_seconds,
            x.stats.steps,
            x.stats.newton_iterations,
            table_number(x.error),
            if x.frontier { "*" } else { "" }
        )?;
        if let Some(why) = &x.stopped {
            writeln!(out, "  └ {why}")?;
        }
    }
    Ok(())
}

/// Draws the work–precision diagram over both variables: each mesh's runs joined along the
/// steps, the frontier as a black line (error over the windows scored; log–log).
pub fn draw_space_time(r: &SpaceTimeReport, file: &Path) -> Result<(), String> {
    let ok = |x: &&GridRun| x.error > 0.0 && x.error.is_finite() && x.stats.cpu_seconds > 0.0;
    let pts: Vec<(f64, f64)> = r
        .runs
        .iter()
        .filter(ok)
        .map(|x| (x.stats.cpu_seconds, x.error))
        .collect();
    if pts.is_empty() {
        return Err("no run has a scored error (is the reference converged anywhere?)".into());
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &pts {
        (x0, x1, y0, y1) = (x0.min(*x), x1.max(*x), y0.min(*y), y1.max(*y));
    }
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    let format = crate::figure::Format::of(file);
    crate::figure::draw_to!(format, file, (900, 650), |root| draw_st(
        root,
        r,
        (x0, x1, y0, y1)
    ))
}

fn draw_st<DB: plotters::prelude::DrawingBackend>(
    root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    r: &SpaceTimeReport,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> Result<(), String> {
    use plotters::prelude::*;
    let ok = |x: &&GridRun| x.error > 0.0 && x.error.is_finite() && x.stats.cpu_seconds > 0.0;
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Work-precision over mesh and step (windows converged in space and time)",
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            ((x0 / 1.5)..(x1 * 1.5)).log_scale(),
            ((y0 / 2.0)..(y1 * 2.0)).log_scale(),
        )
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("CPU time (s)")
        .y_desc("max position error (m)")
        .x_label_formatter(&|v| super::super::figure::cpu_label(*v))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|e| e.to_string())?;
    let colors = [BLUE, RED, GREEN, MAGENTA, CYAN, RGBColor(255, 140, 0)];
    let mut meshes: Vec<(u32, u32, usize)> = r
        .runs
        .iter()
        .map(|x| (x.refine, x.order, x.beams))
        .collect();
    meshes.dedup();
    for (k, (refine, order, beams)) in meshes.iter().enumerate() {
        let s: Vec<(f64, f64)> = r
            .runs
            .iter()
            .filter(|x| x.refine == *refine && x.order == *order)
            .filter(ok)
            .map(|x| (x.stats.cpu_seconds, x.error))
            .collect();
        let col = colors[k % colors.len()];
        chart
            .draw_series(LineSeries::new(s.clone(), col.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(format!(
                "{} ({beams} beams), steps",
                super::mesh_name(*refine, *order)
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        chart
            .draw_series(s.iter().map(|p| Circle::new(*p, 4, col.filled())))
            .map_err(|e| e.to_string())?;
    }
    let mut front: Vec<(f64, f64)> = r
        .runs
        .iter()
        .filter(|x| x.frontier)
        .map(|x| (x.stats.cpu_seconds, x.error))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(front, BLACK.stroke_width(1)))
        .map_err(|e| e.to_string())?
        .label("frontier")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}
