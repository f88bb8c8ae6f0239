//! The space–time study (`mecano-rs study DECK --refine 1,2,4 --steps …`): a ladder of
//! meshes as well as of time steps.
//!
//! Every (mesh, step) pair of the two ladders is run (mesh `k`: every beam of the deck divided
//! into `k` times its elements, [`crate::model::Model::refine`]; with `--order p1,p2,…` each
//! refinement also at every order `p`, [`crate::model::Model::set_beam_order`], the levels
//! ordered by `k·p`, the number of nodes per beam card less one, which is also the measure of
//! the ratio `r` below: for p-refinement the observed algebraic order is only indicative, the
//! convergence of smooth fields being exponential in `p`, while the convergence check stays
//! valid). The finest mesh at the finest
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

mod report;

pub use report::{draw_space_time, print_space_time, write_space_time};

use super::StudyError;
use super::run::{Rec, sample, set_run};
use crate::deck::load_deck;
use crate::model::{Analysis, ElementKind, NodeId};
use crate::solver::{self, Observer, Snapshot};
use std::io;
use std::path::{Path, PathBuf};

/// What a space–time study runs.
#[derive(Debug, Clone)]
pub struct SpaceTimeOptions {
    /// Refinement factors of the mesh (the largest is the reference mesh).
    pub refine: Vec<u32>,
    /// Beam orders (`--order`): every beam set to order p at each refinement; empty: the
    /// deck's orders. The mesh levels are the (refine k, order p) pairs, ordered by `k·p`
    /// (nodes per beam card, less one), at least 3 of them.
    pub orders: Vec<u32>,
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
    /// The time integration scheme of every run (`None`: the deck's).
    pub scheme: Option<crate::model::Scheme>,
}

/// One (mesh, step) run.
#[derive(Debug, Clone)]
pub struct GridRun {
    /// Refinement factor of the mesh.
    pub refine: u32,
    /// Order every beam was set to (`--order`); 0: the deck's orders.
    pub order: u32,
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
    /// Positions, rotations and velocities only.
    fn reads_reactions(&self, _snap: &Snapshot) -> bool {
        false
    }

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

/// The name of a mesh level: `refine k`, and `order p` when the study set the orders.
pub fn mesh_name(k: u32, p: u32) -> String {
    if p > 0 {
        format!("refine {k} order {p}")
    } else {
        format!("refine {k}")
    }
}

/// The mesh levels (refine k, order p; p = 0: the deck's orders) of `--refine` × `--order`,
/// coarsest first by `k·p`. Two levels of the same `k·p` (e.g. refine 2 order 4 and refine
/// 1 order 8) have no ratio between them and are refused.
fn mesh_levels(refine: &[u32], orders: &[u32]) -> Result<Vec<(u32, u32)>, StudyError> {
    let ks: Vec<u32> = if refine.is_empty() {
        vec![1]
    } else {
        refine.to_vec()
    };
    let ps: Vec<u32> = if orders.is_empty() {
        vec![0]
    } else {
        orders.to_vec()
    };
    let mut levels: Vec<(u32, u32)> = ks
        .iter()
        .flat_map(|k| ps.iter().map(move |p| (*k, *p)))
        .collect();
    levels.sort_by_key(|(k, p)| (k * p.max(&1), *k));
    levels.dedup();
    if let Some(w) = levels
        .windows(2)
        .find(|w| w[0].0 * w[0].1.max(1) == w[1].0 * w[1].1.max(1))
    {
        return Err(StudyError::Setup(format!(
            "{} and {} have the same number of nodes per beam: a mesh ladder needs one level per size",
            mesh_name(w[0].0, w[0].1),
            mesh_name(w[1].0, w[1].1)
        )));
    }
    Ok(levels)
}

/// Runs the space–time study of the deck at `path`.
pub fn run_space_time(
    path: &Path,
    opts: &SpaceTimeOptions,
    mut log: impl FnMut(&str),
) -> Result<SpaceTimeReport, StudyError> {
    let base =
        load_deck(path).map_err(|e| StudyError::Deck(format!("{:?}", miette::Report::new(e))))?;
    let Analysis::Dynamic { scheme, end, .. } = base.analysis else {
        return Err(StudyError::Setup("a study needs a dynamic analysis".into()));
    };
    let mut steps = opts.steps.clone();
    steps.sort_by(|a, b| b.total_cmp(a));
    steps.dedup();
    if opts.refine.contains(&0) {
        return Err(StudyError::Setup(
            "--refine factors must be at least 1".into(),
        ));
    }
    if let Some(p) = opts
        .orders
        .iter()
        .find(|p| **p == 0 || **p > crate::model::order::MAX_ORDER)
    {
        return Err(StudyError::Setup(format!(
            "--order {p}: beam orders are 1 to {}",
            crate::model::order::MAX_ORDER
        )));
    }
    let meshes = mesh_levels(&opts.refine, &opts.orders)?;
    if meshes.len() < 3 || steps.len() < 3 {
        return Err(StudyError::Setup(
            "a space-time study needs at least three meshes (--refine, --order) and three time \
             steps (--steps): each variable's convergence is judged on two successive differences"
                .into(),
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
    for &(k, p) in &meshes {
        let mut m = base.clone();
        m.refine(k)
            .map_err(|e| StudyError::Setup(format!("--refine {k}: {e}")))?;
        if p > 0 {
            m.set_beam_order(p)
                .map_err(|e| StudyError::Setup(format!("--order {p}: {e}")))?;
        }
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
            set_run(&mut m, h, opts.scheme.unwrap_or(scheme), None, t_end);
            log(&format!(
                "running {} ({beams} beams), h = {h:.3e} s …",
                mesh_name(k, p)
            ));
            let mut rec = GridRecorder {
                nodes: idx.clone(),
                dt,
                recs: vec![Vec::new(); idx.len()],
            };
            let report = solver::run(&m, &mut rec).map_err(|e| StudyError::Setup(e.to_string()))?;
            runs.push(GridRun {
                refine: k,
                order: p,
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
    let nm = meshes.len();
    let space_idx: Vec<usize> = (0..nm).map(|m| at(m, ns - 1)).collect();
    let measure = |i: usize| f64::from(meshes[i].0 * meshes[i].1.max(1));
    let space = ladder((0..nm).map(measure).collect(), space_idx, &|i| {
        measure(i) / measure(i - 1)
    });
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

#[cfg(test)]
mod tests {
    use super::*;

    fn run(cpu: f64, error: f64) -> GridRun {
        GridRun {
            refine: 1,
            order: 0,
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
