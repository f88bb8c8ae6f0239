//! Work–precision study: what accuracy costs in time (`mecano-rs study DECK`).
//!
//! Runs a deck at a ladder of fixed time steps (and optionally with adaptive tolerances and
//! other HHT α), takes the finest fixed-step run as the reference, and reports for each run
//! the CPU seconds, steps, Newton iterations, factorisations and the error of chosen node
//! histories, **per time window**: positions (m), rotations (rad, `|log(R_refᵀR)|`) and
//! velocities (m/s), max over the window's sample instants and the chosen nodes. A window
//! counts as converged when the reference itself is: the difference between the two finest
//! runs there is at most half the difference between the second and third finest (the
//! sequence contracts at least like a first-order method) or below a floor (`--floor`,
//! default 1e-6 m: where the finest runs agree to a micrometre their difference is the
//! noise of the Newton tolerance, and its ratio to the next pair says nothing). This is
//! judged for each quantity on its own — positions, rotations (the same floor in rad),
//! velocities (in m/s) — because they converge differently: on the pendulum the tip
//! rotations, driven by the bars' torsion, converge at order 1.1–1.5 before the impact
//! where the positions converge at 1.5–1.9 (`docs/accuracy.md`). Each quantity's error is
//! the largest over the windows where its reference is converged. The observed order is
//! measured on positions (on rotations if the chosen nodes do not move). The
//! work–precision figure (position error against CPU time) uses the position-converged
//! windows only, as the IFToMM benchmark protocol compares codes at given precision bands.
//!
//! Samples are taken on the grid of the coarsest fixed step (which every fixed run hits);
//! adaptive runs are interpolated there with cubic Hermite polynomials in position and
//! velocity (error O(h⁴)) and geodesically in rotation.

use crate::deck::load_deck;
use crate::model::{Adaptive, Analysis, Model, NodeId};
use crate::rotation;
use crate::solver::{self, Observer, Snapshot};
use nalgebra::{Matrix3, Vector3};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// What to study.
#[derive(Debug, Clone)]
pub struct StudyOptions {
    /// Fixed time steps, s (at least 3; the smallest is the reference).
    pub steps: Vec<f64>,
    /// Adaptive position tolerances, m (rotation tolerance = position tolerance / m).
    pub adaptive: Vec<f64>,
    /// HHT α values of the fixed-step runs (default: the deck's).
    pub alphas: Vec<f64>,
    /// User node numbers whose histories are compared (default: the deck's output nodes).
    pub nodes: Vec<u32>,
    /// Window length, s.
    pub window: f64,
    /// Difference (m for positions, rad for rotations) below which the two finest runs
    /// count as converged whatever their ratio to the next pair (there they differ by
    /// solver-tolerance noise).
    pub floor: f64,
    /// Only study up to this time (default: the deck's end).
    pub t_max: Option<f64>,
    /// Where to write study.csv, study_windows.csv and the diagram.
    pub out_dir: PathBuf,
}

/// One run of the study.
#[derive(Debug, Clone)]
pub struct StudyRun {
    /// Label, e.g. `h=1.0e-4 a=-0.1` or `adaptive tol=1e-5`.
    pub label: String,
    /// Fixed step (or the initial step of an adaptive run), s.
    pub h: f64,
    /// HHT α.
    pub alpha: f64,
    /// Adaptive position tolerance, m.
    pub tol: Option<f64>,
    /// Counters.
    pub stats: solver::Stats,
    /// The run reached its end.
    pub complete: bool,
    /// Where and why the run stopped, if it did not reach its end.
    pub stopped: Option<String>,
    /// Errors per window: (position, rotation, velocity).
    pub window_errors: Vec<[f64; 3]>,
    /// Errors over the converged windows of each quantity: (position, rotation, velocity).
    pub error: [f64; 3],
    /// Observed order against the next finer fixed run (fixed runs only).
    pub order: Option<f64>,
    /// Adaptive runs: what fixed steps (of the first α) cost for the same position error.
    pub fixed_equivalent: Option<FixedEquivalent>,
}

/// The CPU time fixed steps take to reach an adaptive run's position error (the measure of
/// issue 7's target: adaptive CPU over "the best fixed step that reaches the same
/// accuracy").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedEquivalent {
    /// CPU seconds interpolated on the fixed runs' work–precision line, linear in
    /// `(ln error, ln CPU)` between the two successive ladder runs whose errors bracket the
    /// adaptive run's; `None` when no pair brackets it.
    pub interpolated: Option<f64>,
    /// The cheapest fixed run whose error is at most the adaptive run's: (CPU s, h).
    pub cheapest: Option<(f64, f64)>,
}

/// The error the diagram and the adaptive comparison use: 0 (positions), or 1 (rotations)
/// when no run has a position error (the chosen nodes do not translate).
fn compared_quantity(runs: &[StudyRun]) -> usize {
    usize::from(
        runs.iter()
            .all(|x| x.error[0] == 0.0 || !x.error[0].is_finite()),
    )
}

/// [`FixedEquivalent`] of an error `e` among fixed runs `(h, error, CPU s)`, coarsest first
/// (runs with a zero, NaN or infinite error — the reference, stopped runs — are ignored).
pub fn fixed_equivalent(fixed: &[(f64, f64, f64)], e: f64) -> FixedEquivalent {
    let runs: Vec<(f64, f64, f64)> = fixed
        .iter()
        .copied()
        .filter(|r| r.1 > 0.0 && r.1.is_finite() && r.2 > 0.0)
        .collect();
    let interpolated = runs.windows(2).find_map(|w| {
        let ((_, e0, c0), (_, e1, c1)) = (w[0], w[1]);
        (e0 >= e && e >= e1 && e0 > e1).then(|| {
            let theta = (e0.ln() - e.ln()) / (e0.ln() - e1.ln());
            (c0.ln() + theta * (c1.ln() - c0.ln())).exp()
        })
    });
    let cheapest = runs
        .iter()
        .filter(|r| r.1 <= e)
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|r| (r.2, r.0));
    FixedEquivalent {
        interpolated,
        cheapest,
    }
}

/// The study's result.
#[derive(Debug, Clone)]
pub struct StudyReport {
    /// Runs, coarsest fixed first, then adaptive.
    pub runs: Vec<StudyRun>,
    /// Window start times, s.
    pub windows: Vec<f64>,
    /// Whether each window's reference is converged: (position, rotation, velocity).
    pub converged: Vec<[bool; 3]>,
    /// Difference between the two finest runs per window: (position m, rotation rad,
    /// velocity m/s).
    pub reference_uncertainty: Vec<[f64; 3]>,
}

#[derive(Clone, Copy)]
struct Rec {
    t: f64,
    x: Vector3<f64>,
    v: Vector3<f64>,
    r: Matrix3<f64>,
}

struct Recorder {
    nodes: Vec<usize>,
    recs: Vec<Vec<Rec>>,
}

impl Observer for Recorder {
    fn state(&mut self, snap: &Snapshot) -> io::Result<()> {
        let integ = snap.integ;
        for (k, &i) in self.nodes.iter().enumerate() {
            let s = &integ.nodes[i];
            self.recs[k].push(Rec {
                t: integ.t,
                x: s.x,
                v: s.v,
                r: s.r,
            });
        }
        Ok(())
    }
}

/// State of a recorded node at time `t` (Hermite in position, geodesic in rotation).
fn sample(recs: &[Rec], t: f64) -> Option<Rec> {
    let k = recs.partition_point(|r| r.t < t - 1e-12);
    let b = recs.get(k)?;
    if (b.t - t).abs() <= 1e-12 * t.abs().max(1.0) || k == 0 {
        return Some(*b);
    }
    let a = recs[k - 1];
    let h = b.t - a.t;
    let s = (t - a.t) / h;
    let (h00, h10, h01, h11) = (
        2.0 * s * s * s - 3.0 * s * s + 1.0,
        s * s * s - 2.0 * s * s + s,
        -2.0 * s * s * s + 3.0 * s * s,
        s * s * s - s * s,
    );
    let x = a.x * h00 + a.v * (h10 * h) + b.x * h01 + b.v * (h11 * h);
    let v = a.v + (b.v - a.v) * s;
    let r = a.r * rotation::exp(&(rotation::log(&(a.r.transpose() * b.r)) * s));
    Some(Rec { t, x, v, r })
}

fn set_run(model: &mut Model, h: f64, alpha: f64, tol: Option<f64>, t_end: f64) {
    if let Analysis::Dynamic {
        alpha: a,
        step,
        end,
        min_step,
        max_step,
        adaptive,
        ..
    } = &mut model.analysis
    {
        *a = alpha;
        *step = h;
        *end = t_end;
        *min_step = (h / 1024.0).min(*min_step);
        *max_step = if tol.is_some() {
            (*max_step).max(h * 100.0)
        } else {
            h
        };
        *adaptive = tol.map(|tp| Adaptive {
            tol_position: tp,
            tol_rotation: tp,
            max_growth: 2.0,
        });
    }
}

/// Errors of study runs.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The deck could not be read.
    #[error("{0}")]
    Deck(String),
    /// The study cannot be set up as asked.
    #[error("{0}")]
    Setup(String),
    /// Writing results failed.
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// Runs the study of the deck at `path`.
pub fn run_study(
    path: &Path,
    opts: &StudyOptions,
    mut log: impl FnMut(&str),
) -> Result<StudyReport, StudyError> {
    let base =
        load_deck(path).map_err(|e| StudyError::Deck(format!("{:?}", miette::Report::new(e))))?;
    let Analysis::Dynamic { alpha, end, .. } = base.analysis else {
        return Err(StudyError::Setup("a study needs a dynamic analysis".into()));
    };
    let mut steps = opts.steps.clone();
    steps.sort_by(|a, b| b.total_cmp(a));
    if steps.len() < 3 {
        return Err(StudyError::Setup("give at least three time steps".into()));
    }
    let t_end = opts.t_max.unwrap_or(end).min(end);
    let node_idx: Vec<usize> = opts
        .nodes
        .iter()
        .map(|n| {
            base.nodes
                .get_index_of(&NodeId(*n))
                .ok_or_else(|| StudyError::Setup(format!("node {n} is not in the deck")))
        })
        .collect::<Result<_, _>>()?;
    if node_idx.is_empty() {
        return Err(StudyError::Setup("no nodes to compare".into()));
    }
    let alphas = if opts.alphas.is_empty() {
        vec![alpha]
    } else {
        opts.alphas.clone()
    };
    let mut configs: Vec<(f64, f64, Option<f64>)> = Vec::new();
    for &a in &alphas {
        for &h in &steps {
            configs.push((h, a, None));
        }
    }
    for &tol in &opts.adaptive {
        configs.push((steps[steps.len() / 2], alphas[0], Some(tol)));
    }
    let mut records = Vec::new();
    let mut runs = Vec::new();
    for (h, a, tol) in &configs {
        let mut m = base.clone();
        set_run(&mut m, *h, *a, *tol, t_end);
        let label = match tol {
            None => format!("h={h:.3e} alpha={a}"),
            Some(t) => format!("adaptive tol={t:.1e} alpha={a}"),
        };
        log(&format!("running {label} …"));
        let mut rec = Recorder {
            nodes: node_idx.clone(),
            recs: vec![Vec::new(); node_idx.len()],
        };
        let report = solver::run(&m, &mut rec).map_err(|e| StudyError::Setup(e.to_string()))?;
        runs.push(StudyRun {
            label,
            h: *h,
            alpha: *a,
            tol: *tol,
            stats: report.stats,
            complete: report.failure.is_none(),
            stopped: report.failure.as_ref().map(|f| {
                // The diagnosis' first line: what failed, at which time and step.
                let why = f.to_string();
                format!("stopped: {}", why.lines().next().unwrap_or_default())
            }),
            window_errors: Vec::new(),
            error: [f64::NAN; 3],
            order: None,
            fixed_equivalent: None,
        });
        records.push(rec.recs);
    }
    // Sample grid: the coarsest fixed step.
    let dt = steps[0];
    let n_samples = (t_end / dt).round() as usize;
    let nwin = ((t_end / opts.window).ceil() as usize).max(1);
    let windows: Vec<f64> = (0..nwin).map(|k| k as f64 * opts.window).collect();
    // Reference: the finest fixed run of the first α.
    let nfix = steps.len();
    let ref_i = nfix - 1;
    let errors_between = |a: usize, b: usize| -> Vec<[f64; 3]> {
        let mut w = vec![[0.0f64; 3]; nwin];
        for k in 0..=n_samples {
            let t = k as f64 * dt;
            let wi = ((t / opts.window) as usize).min(nwin - 1);
            for n in 0..node_idx.len() {
                let (Some(p), Some(q)) = (sample(&records[a][n], t), sample(&records[b][n], t))
                else {
                    // A run that stopped early: its missing samples count as infinite error.
                    w[wi] = [f64::INFINITY; 3];
                    continue;
                };
                w[wi][0] = w[wi][0].max((p.x - q.x).norm());
                w[wi][1] = w[wi][1].max(rotation::log(&(q.r.transpose() * p.r)).norm());
                w[wi][2] = w[wi][2].max((p.v - q.v).norm());
            }
        }
        w
    };
    let d01 = errors_between(ref_i, ref_i - 1);
    let d12 = errors_between(ref_i - 1, ref_i - 2);
    let reference_uncertainty = d01.clone();
    let converged: Vec<[bool; 3]> = (0..nwin)
        .map(|w| {
            std::array::from_fn(|c| {
                d01[w][c].is_finite() && (d01[w][c] <= 0.5 * d12[w][c] || d01[w][c] <= opts.floor)
            })
        })
        .collect();
    for (i, run) in runs.iter_mut().enumerate() {
        run.window_errors = if i == ref_i {
            vec![[0.0; 3]; nwin]
        } else {
            errors_between(i, ref_i)
        };
        // NaN (reported as "-", never written as a number) where no window of the
        // quantity is converged; `NaN.max(x)` is x.
        let mut e = [f64::NAN; 3];
        for w in 0..nwin {
            for c in 0..3 {
                if converged[w][c] {
                    e[c] = e[c].max(run.window_errors[w][c]);
                }
            }
        }
        run.error = e;
    }
    // Observed order between successive fixed runs of the first α, over converged windows.
    for i in 0..nfix.saturating_sub(2) {
        let a = errors_between(i, i + 1);
        let b = errors_between(i + 1, i + 2);
        // Positions, or rotations where no chosen node moves (a spinning body).
        let (mut na, mut nb) = (0.0f64, 0.0f64);
        for c in 0..2 {
            if na > 0.0 && nb > 0.0 {
                break;
            }
            (na, nb) = (0.0, 0.0);
            for w in (0..nwin).filter(|&w| converged[w][c]) {
                na = na.max(a[w][c]);
                nb = nb.max(b[w][c]);
            }
        }
        if na > 0.0 && nb > 0.0 {
            runs[i].order = Some((na / nb).log2() / (steps[i] / steps[i + 1]).log2());
        }
    }
    // Adaptive runs against the fixed runs of the first α at the same error (position, or
    // rotation where the chosen nodes do not translate, as in the diagram).
    let c = compared_quantity(&runs);
    let fixed: Vec<(f64, f64, f64)> = runs[..nfix]
        .iter()
        .filter(|r| r.complete)
        .map(|r| (r.h, r.error[c], r.stats.cpu_seconds))
        .collect();
    for run in runs.iter_mut().filter(|r| r.tol.is_some() && r.complete) {
        if run.error[c].is_finite() {
            run.fixed_equivalent = Some(fixed_equivalent(&fixed, run.error[c]));
        }
    }
    let report = StudyReport {
        runs,
        windows,
        converged,
        reference_uncertainty,
    };
    write_results(&report, &opts.out_dir)?;
    Ok(report)
}

/// An error for the CSV files: empty where it is not a number (no converged window, or a
/// run that stopped early), so that no NaN or infinity is written.
fn csv_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        String::new()
    }
}

/// An error for the printed table: `-` where no window is converged, `stopped` where the
/// run stopped before the window's end.
fn table_number(x: f64) -> String {
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
        "alpha",
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
            run.alpha.to_string(),
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

/// `mecano-rs study DECK`: arguments.
#[derive(Debug, Clone, clap::Args)]
pub struct StudyArgs {
    /// The deck to study (a dynamic analysis).
    pub deck: PathBuf,
    /// Fixed time steps, s, comma-separated (default: the deck's step ×8, ×4, ×2, ×1, ÷2).
    #[arg(long, value_delimiter = ',')]
    pub steps: Vec<f64>,
    /// Adaptive runs: position tolerances, m, comma-separated (rotation tolerance: the same
    /// number in rad).
    #[arg(long, value_delimiter = ',')]
    pub adaptive: Vec<f64>,
    /// HHT α values of the fixed-step runs, comma-separated (default: the deck's).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub alpha: Vec<f64>,
    /// Nodes whose histories are compared (default: the deck's OUTPUT nodes).
    #[arg(long, value_delimiter = ',')]
    pub nodes: Vec<u32>,
    /// Window length for the errors, s.
    #[arg(long, default_value_t = 0.25)]
    pub window: f64,
    /// A window whose two finest runs differ by at most this (m, and rad for rotations)
    /// counts as converged.
    #[arg(long, default_value_t = 1e-6)]
    pub floor: f64,
    /// Study only up to this time, s (default: the deck's end time).
    #[arg(long)]
    pub until: Option<f64>,
    /// Output directory (default: out/<deck name>/study).
    #[arg(short = 'o', long = "out")]
    pub out: Option<PathBuf>,
}

/// Runs `mecano-rs study` and returns the exit code (0, or 2 for bad input).
pub fn run(args: &StudyArgs) -> u8 {
    let model = match load_deck(&args.deck) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{:?}", miette::Report::new(e));
            return crate::app::EXIT_BAD_INPUT;
        }
    };
    let Analysis::Dynamic { step, .. } = model.analysis else {
        eprintln!(
            "error: {}: a study needs ANALYSIS DYNAMIC",
            args.deck.display()
        );
        return crate::app::EXIT_BAD_INPUT;
    };
    let steps = if args.steps.is_empty() {
        [8.0, 4.0, 2.0, 1.0, 0.5].iter().map(|k| step * k).collect()
    } else {
        args.steps.clone()
    };
    let nodes = if !args.nodes.is_empty() {
        args.nodes.clone()
    } else {
        match &model.output.nodes {
            crate::model::Selection::List(l) => l.iter().map(|n| n.0).collect(),
            _ => model.nodes.keys().map(|n| n.0).collect(),
        }
    };
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| crate::app::default_out_dir(&args.deck, &model).join("study"));
    let opts = StudyOptions {
        steps,
        adaptive: args.adaptive.clone(),
        alphas: args.alpha.clone(),
        nodes,
        window: args.window,
        floor: args.floor,
        t_max: args.until,
        out_dir: out_dir.clone(),
    };
    let report = match run_study(&args.deck, &opts, |s| eprintln!("{s}")) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {}: {e}", args.deck.display());
            return crate::app::EXIT_BAD_INPUT;
        }
    };
    let _ = print_table(&report, &mut io::stdout().lock());
    for ext in ["svg", "png"] {
        let file = out_dir.join(format!("work_precision.{ext}"));
        if let Err(e) = draw_work_precision(&report, &file) {
            eprintln!("error: {}: {e}", file.display());
            return crate::app::EXIT_FAILED;
        }
    }
    println!(
        "written: {}/study.csv, study_windows.csv, work_precision.svg/.png",
        out_dir.display()
    );
    crate::app::EXIT_OK
}

/// Draws the work–precision diagram: position error over the converged windows against CPU
/// seconds, log–log; fixed-step runs joined by a line per α, adaptive runs as another series.
pub fn draw_work_precision(r: &StudyReport, file: &Path) -> Result<(), String> {
    use plotters::prelude::*;
    crate::plot::ensure_font();
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
    match file.extension().and_then(|e| e.to_str()) {
        Some("svg") => draw_wp(
            SVGBackend::new(file, (800, 600)).into_drawing_area(),
            r,
            ranges,
            c,
        ),
        _ => draw_wp(
            BitMapBackend::new(file, (800, 600)).into_drawing_area(),
            r,
            ranges,
            c,
        ),
    }
}

fn draw_wp<DB: plotters::prelude::DrawingBackend>(
    root: plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    r: &StudyReport,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    c: usize,
) -> Result<(), String> {
    use plotters::prelude::*;
    {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
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
        let mut alphas: Vec<f64> = r
            .runs
            .iter()
            .filter(|x| x.tol.is_none())
            .map(|x| x.alpha)
            .collect();
        alphas.dedup();
        let colors = [BLUE, RED, GREEN, MAGENTA];
        for (k, a) in alphas.iter().enumerate() {
            let s: Vec<(f64, f64)> = r
                .runs
                .iter()
                .filter(|x| {
                    x.tol.is_none() && x.alpha == *a && x.error[c] > 0.0 && x.error[c].is_finite()
                })
                .map(|x| (x.stats.cpu_seconds, x.error[c]))
                .collect();
            let col = colors[k % colors.len()];
            chart
                .draw_series(LineSeries::new(s.clone(), col.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(format!("fixed steps, alpha = {a}"))
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
        root.present().map_err(|e| e.to_string())
    }
}

/// A label for the log CPU-time axis: only at 1, 2 and 5 × 10^k (plotters puts a mesh line
/// at each of 1…9 × 10^k, whose labels would run into each other), in plain decimals.
fn cpu_label(v: f64) -> String {
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

#[cfg(test)]
mod tests {
    use super::{csv_number, fixed_equivalent, table_number};

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
