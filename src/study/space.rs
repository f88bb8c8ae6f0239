//! The space–time study (`mecano-rs study DECK --refine 1,2,4 --steps …`): a ladder of
//! meshes as well as of time steps.
//!
//! Every (mesh, step) pair of the two ladders is run (mesh `k`: every beam of the deck divided
//! into `k` times its elements, [`crate::model::Model::refine`]). The finest mesh at the finest
//! step is the **space–time reference**. The two errors are separated, each against a
//! reference converged in its own variable:
//! - **in space**, at the finest step: mesh `k`'s error is its distance to the finest mesh;
//!   a window's finest mesh counts as converged in space when the two finest meshes differ
//!   there by at most `1/r` of what the previous pair differs by (`r` the refinement ratio:
//!   the sequence contracts at least like a first-order method), or by less than the floor;
//! - **in time**, at the finest mesh, the same with the steps (ratio `h_i/h_{i+1}`).
//!
//! The observed order of each variable per window is `p = ln(d_i/d_{i+1}) / ln r` from the
//! differences `d_i` between successive levels (the ladders should have a constant ratio,
//! e.g. 1, 2, 4, 8 and h, h/2, h/4). A window's reference uncertainty is the sum of the two
//! finest differences, space and time (each bounds the finest level's own error by
//! `d/(r^p − 1) ≤ d` for `p ≥ 1` and `r = 2`). Each run is scored against the space–time
//! reference over the windows where that reference is converged in **both** variables; a
//! window converged in time but not in space is reported as such and never scored. The
//! work–precision frontier is the set of runs that no cheaper run beats in error.
//!
//! Only positions are compared (the largest distance of the chosen nodes over the samples
//! of a window; samples at the coarsest step's grid, which every fixed-step run hits, also
//! through contact events).

use super::StudyError;
use super::report::{csv_number, table_number};
use super::run::{Rec, sample, set_run};
use crate::deck::load_deck;
use crate::model::{Analysis, ElementKind, NodeId};
use crate::solver::{self, Observer, Snapshot};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// What a space–time study runs.
#[derive(Debug, Clone)]
pub struct SpaceTimeOptions {
    /// Refinement factors of the mesh (at least 3; the largest is the reference mesh).
    pub refine: Vec<u32>,
    /// Fixed time steps, s (at least 3; the smallest is the reference step).
    pub steps: Vec<f64>,
    /// User node numbers whose positions are compared.
    pub nodes: Vec<u32>,
    /// Window length, s.
    pub window: f64,
    /// Difference (m) below which the two finest levels count as converged.
    pub floor: f64,
    /// Only study up to this time (default: the deck's end).
    pub t_max: Option<f64>,
    /// Where to write the files and the diagram.
    pub out_dir: PathBuf,
}

/// One (mesh, step) run.
#[derive(Debug, Clone)]
pub struct GridRun {
    /// Refinement factor of the mesh.
    pub refine: u32,
    /// Beam elements of the refined model.
    pub beams: usize,
    /// Time step, s.
    pub h: f64,
    /// Counters (CPU seconds, steps, Newton iterations, factorisations).
    pub stats: solver::Stats,
    /// The run reached its end.
    pub complete: bool,
    /// Where and why it stopped, if it did.
    pub stopped: Option<String>,
    /// Position error against the space–time reference, per window, m.
    pub window_errors: Vec<f64>,
    /// Largest position error over the windows where the reference is converged in space
    /// and in time (NaN where there is none), m.
    pub error: f64,
    /// On the work–precision frontier: no cheaper run has a smaller error.
    pub frontier: bool,
    /// Per chosen node and window: the largest |u_x|, |u_y|, |u_z| of its displacement
    /// `x(t) − x(0)` over the window's samples, m (e.g. the paper's out-of-plane |z| of
    /// node 12); it differs from the reference's by at most the run's position error.
    pub peaks: Vec<Vec<[f64; 3]>>,
}

/// A ladder in one variable (meshes at the finest step, or steps at the finest mesh).
#[derive(Debug, Clone)]
pub struct Ladder {
    /// The levels, coarsest first: refinement factors, or steps (s).
    pub levels: Vec<f64>,
    /// Index of each level's run in [`SpaceTimeReport::runs`].
    pub runs: Vec<usize>,
    /// Each level's distance to the finest level, per window, m.
    pub errors: Vec<Vec<f64>>,
    /// Observed order per level and window, from the differences of levels (i, i+1) and
    /// (i+1, i+2); NaN where not measurable.
    pub orders: Vec<Vec<f64>>,
    /// Difference of the two finest levels per window, m.
    pub uncertainty: Vec<f64>,
    /// Whether the finest level is converged in this variable, per window.
    pub converged: Vec<bool>,
}

/// The result of a space–time study.
#[derive(Debug, Clone)]
pub struct SpaceTimeReport {
    /// Window start times, s.
    pub windows: Vec<f64>,
    /// Every (mesh, step) run, meshes coarsest first, steps coarsest first within a mesh.
    pub runs: Vec<GridRun>,
    /// The meshes at the finest step.
    pub space: Ladder,
    /// The steps at the finest mesh.
    pub time: Ladder,
    /// Uncertainty of the space–time reference per window: space plus time, m.
    pub reference_uncertainty: Vec<f64>,
    /// The reference is converged in space and in time, per window.
    pub converged: Vec<bool>,
}

/// Records the chosen nodes at the instants of a grid `k·dt` only (the study samples
/// nothing else; at 1e-5 s a 1.5 s run would otherwise keep 150,000 states per node).
struct GridRecorder {
    nodes: Vec<usize>,
    dt: f64,
    recs: Vec<Vec<Rec>>,
}

impl Observer for GridRecorder {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        let integ = snap.integ;
        let k = integ.t / self.dt;
        if (k - k.round()).abs() > 1e-6 {
            return Ok(());
        }
        for (j, &i) in self.nodes.iter().enumerate() {
            let s = &integ.nodes[i];
            self.recs[j].push(Rec {
                t: integ.t,
                x: s.x,
                v: s.v,
                r: s.r,
            });
        }
        Ok(())
    }
}

/// Largest |displacement component| per node and window (see [`GridRun::peaks`]).
fn peaks(recs: &[Vec<Rec>], window: f64, t_end: f64) -> Vec<Vec<[f64; 3]>> {
    let nwin = ((t_end / window).ceil() as usize).max(1);
    recs.iter()
        .map(|r| {
            let mut p = vec![[0.0f64; 3]; nwin];
            if let Some(first) = r.first() {
                for s in r {
                    let w = ((s.t / window) as usize).min(nwin - 1);
                    let u = s.x - first.x;
                    for c in 0..3 {
                        p[w][c] = p[w][c].max(u[c].abs());
                    }
                }
            }
            p
        })
        .collect()
}

/// The order `ln(d0/d1)/ln r` of two successive differences; NaN when not measurable.
fn order(d0: f64, d1: f64, r: f64) -> f64 {
    if d0 > 0.0 && d1 > 0.0 && d0.is_finite() && d1.is_finite() && r > 1.0 {
        (d0 / d1).ln() / r.ln()
    } else {
        f64::NAN
    }
}

/// Runs the space–time study of the deck at `path`.
pub fn run_space_time(
    path: &Path,
    opts: &SpaceTimeOptions,
    mut log: impl FnMut(&str),
) -> Result<SpaceTimeReport, StudyError> {
    let base =
        load_deck(path).map_err(|e| StudyError::Deck(format!("{:?}", miette::Report::new(e))))?;
    let Analysis::Dynamic { alpha, end, .. } = base.analysis else {
        return Err(StudyError::Setup("a study needs a dynamic analysis".into()));
    };
    let mut refine = opts.refine.clone();
    refine.sort_unstable();
    refine.dedup();
    let mut steps = opts.steps.clone();
    steps.sort_by(|a, b| b.total_cmp(a));
    steps.dedup();
    if refine.len() < 3 || steps.len() < 3 {
        return Err(StudyError::Setup(
            "a space-time study needs at least three meshes (--refine) and three time steps \
             (--steps): each variable's convergence is judged on two successive differences"
                .into(),
        ));
    }
    if refine[0] == 0 {
        return Err(StudyError::Setup(
            "--refine factors must be at least 1".into(),
        ));
    }
    for n in &opts.nodes {
        if !base.nodes.contains_key(&NodeId(*n)) {
            return Err(StudyError::Setup(format!("node {n} is not in the deck")));
        }
    }
    if opts.nodes.is_empty() {
        return Err(StudyError::Setup("no nodes to compare".into()));
    }
    let t_end = opts.t_max.unwrap_or(end).min(end);
    let dt = steps[0];
    let mut runs = Vec::new();
    let mut records = Vec::new();
    for &k in &refine {
        let mut m = base.clone();
        m.refine(k)
            .map_err(|e| StudyError::Setup(format!("--refine {k}: {e}")))?;
        let beams = m
            .elements
            .values()
            .filter(|e| matches!(e.kind, ElementKind::Beam { .. }))
            .count();
        let idx: Vec<usize> = opts
            .nodes
            .iter()
            .filter_map(|n| m.nodes.get_index_of(&NodeId(*n)))
            .collect();
        for &h in &steps {
            set_run(&mut m, h, alpha, None, t_end);
            log(&format!(
                "running refine {k} ({beams} beams), h = {h:.3e} s …"
            ));
            let mut rec = GridRecorder {
                nodes: idx.clone(),
                dt,
                recs: vec![Vec::new(); idx.len()],
            };
            let report = solver::run(&m, &mut rec).map_err(|e| StudyError::Setup(e.to_string()))?;
            runs.push(GridRun {
                refine: k,
                beams,
                h,
                stats: report.stats,
                complete: report.failure.is_none(),
                stopped: report.failure.as_ref().map(|f| {
                    let why = f.to_string();
                    format!("stopped: {}", why.lines().next().unwrap_or_default())
                }),
                window_errors: Vec::new(),
                error: f64::NAN,
                frontier: false,
                peaks: peaks(&rec.recs, opts.window, t_end),
            });
            records.push(rec.recs);
        }
    }
    let ns = steps.len();
    let at = |mesh: usize, step: usize| mesh * ns + step;
    let n_samples = (t_end / dt).round() as usize;
    let nwin = ((t_end / opts.window).ceil() as usize).max(1);
    let windows: Vec<f64> = (0..nwin).map(|k| k as f64 * opts.window).collect();
    let between = |a: usize, b: usize| -> Vec<f64> {
        let mut w = vec![0.0f64; nwin];
        for s in 0..=n_samples {
            let t = s as f64 * dt;
            let wi = ((t / opts.window) as usize).min(nwin - 1);
            for n in 0..opts.nodes.len() {
                match (sample(&records[a][n], t), sample(&records[b][n], t)) {
                    (Some(p), Some(q)) => w[wi] = w[wi].max((p.x - q.x).norm()),
                    // A run that stopped early: its missing samples are an infinite error.
                    _ => w[wi] = f64::INFINITY,
                }
            }
        }
        w
    };
    let ladder = |levels: Vec<f64>, idx: Vec<usize>, ratio: &dyn Fn(usize) -> f64| -> Ladder {
        let last = idx.len() - 1;
        let errors: Vec<Vec<f64>> = idx.iter().map(|&i| between(i, idx[last])).collect();
        let diffs: Vec<Vec<f64>> = (0..last).map(|i| between(idx[i], idx[i + 1])).collect();
        let orders: Vec<Vec<f64>> = (0..last)
            .map(|i| {
                (0..nwin)
                    .map(|w| match diffs.get(i + 1) {
                        Some(d1) => order(diffs[i][w], d1[w], ratio(i + 1)),
                        None => f64::NAN,
                    })
                    .collect()
            })
            .chain(std::iter::once(vec![f64::NAN; nwin]))
            .collect();
        let (d0, d1) = (&diffs[last - 1], &diffs[last - 2]);
        let r = ratio(last);
        let converged = (0..nwin)
            .map(|w| d0[w].is_finite() && (d0[w] <= d1[w] / r || d0[w] <= opts.floor))
            .collect();
        Ladder {
            levels,
            runs: idx,
            errors,
            orders,
            uncertainty: d0.clone(),
            converged,
        }
    };
    let nm = refine.len();
    let space_idx: Vec<usize> = (0..nm).map(|m| at(m, ns - 1)).collect();
    let space = ladder(
        refine.iter().map(|k| f64::from(*k)).collect(),
        space_idx,
        &|i| f64::from(refine[i]) / f64::from(refine[i - 1]),
    );
    let time_idx: Vec<usize> = (0..ns).map(|s| at(nm - 1, s)).collect();
    let time = ladder(steps.clone(), time_idx, &|i| steps[i - 1] / steps[i]);
    let reference = at(nm - 1, ns - 1);
    let converged: Vec<bool> = (0..nwin)
        .map(|w| space.converged[w] && time.converged[w])
        .collect();
    let reference_uncertainty: Vec<f64> = (0..nwin)
        .map(|w| space.uncertainty[w] + time.uncertainty[w])
        .collect();
    for i in 0..runs.len() {
        let e = if i == reference {
            vec![0.0; nwin]
        } else {
            between(i, reference)
        };
        runs[i].error = (0..nwin)
            .filter(|w| converged[*w])
            .fold(f64::NAN, |a, w| a.max(e[w]));
        runs[i].window_errors = e;
    }
    mark_frontier(&mut runs);
    let report = SpaceTimeReport {
        windows,
        runs,
        space,
        time,
        reference_uncertainty,
        converged,
    };
    write_space_time(&report, &opts.out_dir)?;
    Ok(report)
}

/// Marks the runs no cheaper run beats: sorted by CPU time, each run whose error is below
/// every cheaper run's (complete runs with a measured, non-zero error).
fn mark_frontier(runs: &mut [GridRun]) {
    let mut order: Vec<usize> = (0..runs.len())
        .filter(|&i| runs[i].complete && runs[i].error.is_finite() && runs[i].error > 0.0)
        .collect();
    order.sort_by(|&a, &b| {
        runs[a]
            .stats
            .cpu_seconds
            .total_cmp(&runs[b].stats.cpu_seconds)
    });
    let mut best = f64::INFINITY;
    for i in order {
        if runs[i].error < best {
            best = runs[i].error;
            runs[i].frontier = true;
        }
    }
}

fn label(r: &GridRun) -> String {
    format!("refine {} ({} beams), h = {:.3e}", r.refine, r.beams, r.h)
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
        "space-time reference: refine {} ({} beams), h = {:.3e} s",
        rf.refine, rf.beams, rf.h
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
        ("space: meshes at the finest step", &r.space, "refine"),
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
    use plotters::prelude::*;
    crate::plot::ensure_font();
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
    match file.extension().and_then(|e| e.to_str()) {
        Some("svg") => draw_st(
            SVGBackend::new(file, (900, 650)).into_drawing_area(),
            r,
            (x0, x1, y0, y1),
        ),
        _ => draw_st(
            BitMapBackend::new(file, (900, 650)).into_drawing_area(),
            r,
            (x0, x1, y0, y1),
        ),
    }
}

fn draw_st<DB: plotters::prelude::DrawingBackend>(
    root: plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    r: &SpaceTimeReport,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> Result<(), String> {
    use plotters::prelude::*;
    let ok = |x: &&GridRun| x.error > 0.0 && x.error.is_finite() && x.stats.cpu_seconds > 0.0;
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
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
        .x_label_formatter(&|v| super::figure::cpu_label(*v))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|e| e.to_string())?;
    let colors = [BLUE, RED, GREEN, MAGENTA, CYAN, RGBColor(255, 140, 0)];
    let mut meshes: Vec<(u32, usize)> = r.runs.iter().map(|x| (x.refine, x.beams)).collect();
    meshes.dedup();
    for (k, (refine, beams)) in meshes.iter().enumerate() {
        let s: Vec<(f64, f64)> = r
            .runs
            .iter()
            .filter(|x| x.refine == *refine)
            .filter(ok)
            .map(|x| (x.stats.cpu_seconds, x.error))
            .collect();
        let col = colors[k % colors.len()];
        chart
            .draw_series(LineSeries::new(s.clone(), col.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(format!("refine {refine} ({beams} beams), steps"))
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
    root.present().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(cpu: f64, error: f64) -> GridRun {
        GridRun {
            refine: 1,
            beams: 1,
            h: 1.0,
            stats: solver::Stats {
                cpu_seconds: cpu,
                ..Default::default()
            },
            complete: true,
            stopped: None,
            window_errors: vec![],
            error,
            frontier: false,
            peaks: vec![],
        }
    }

    /// The frontier keeps the runs that no cheaper run beats; the reference (error 0) and
    /// unscored runs (NaN) are not on it. Orders: differences falling by 4 per halving are
    /// order 2; by 8 with ratio 2, order 3.
    #[test]
    fn frontier_and_orders() {
        let mut runs = vec![
            run(1.0, 1e-2),
            run(2.0, 2e-2),
            run(3.0, 5e-3),
            run(4.0, f64::NAN),
            run(5.0, 0.0),
            run(2.5, 4e-3),
        ];
        mark_frontier(&mut runs);
        let f: Vec<bool> = runs.iter().map(|x| x.frontier).collect();
        assert_eq!(f, vec![true, false, false, false, false, true]);
        assert!((order(4e-3, 1e-3, 2.0) - 2.0).abs() < 1e-12);
        assert!((order(8e-3, 1e-3, 2.0) - 3.0).abs() < 1e-12);
        assert!(order(0.0, 1e-3, 2.0).is_nan());
        assert!(order(1e-3, f64::INFINITY, 2.0).is_nan());
    }
}
