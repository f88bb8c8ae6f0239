//! The runs of a time study and their errors per window against the finest run.

use super::*;
use crate::deck::load_deck;
use crate::model::{Adaptive, Analysis, Model, NodeId, Scheme};
use crate::rotation;
use crate::solver::{Observer, Snapshot};
use nalgebra::{Matrix3, Vector3};
use std::path::Path;

#[derive(Clone, Copy)]
pub(super) struct Rec {
    pub(super) t: f64,
    pub(super) x: Vector3<f64>,
    pub(super) v: Vector3<f64>,
    pub(super) r: Matrix3<f64>,
}

pub(super) struct Recorder {
    pub(super) nodes: Vec<usize>,
    pub(super) recs: Vec<Vec<Rec>>,
}

impl Observer for Recorder {
    /// Positions, rotations and velocities only.
    fn reads_reactions(&self, _snap: &Snapshot) -> bool {
        false
    }

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
pub(super) fn sample(recs: &[Rec], t: f64) -> Option<Rec> {
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

pub(super) fn set_run(model: &mut Model, h: f64, sch: Scheme, tol: Option<f64>, t_end: f64) {
    if let Analysis::Dynamic {
        scheme,
        step,
        end,
        min_step,
        max_step,
        adaptive,
        ..
    } = &mut model.analysis
    {
        // The adaptive runs keep the deck's own `CARRY` (`Run` when it declares none).
        let carry_of_deck = adaptive.as_ref().map_or(Default::default(), |a| a.carry);
        *scheme = sch;
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
            carry: carry_of_deck,
        });
    }
}

/// Runs the study of the deck at `path`.
pub fn run_study(
    path: &Path,
    opts: &StudyOptions,
    mut log: impl FnMut(&str),
) -> Result<StudyReport, StudyError> {
    let mut base =
        load_deck(path).map_err(|e| StudyError::Deck(format!("{:?}", miette::Report::new(e))))?;
    if opts.refine > 1 {
        base.refine(opts.refine)
            .map_err(|e| StudyError::Setup(format!("--refine {}: {e}", opts.refine)))?;
    }
    let Analysis::Dynamic { scheme, end, .. } = base.analysis else {
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
    let schemes = if opts.schemes.is_empty() {
        vec![scheme]
    } else {
        opts.schemes.clone()
    };
    let mut configs: Vec<(f64, Scheme, Option<f64>)> = Vec::new();
    for &a in &schemes {
        for &h in &steps {
            configs.push((h, a, None));
        }
    }
    for &tol in &opts.adaptive {
        configs.push((steps[steps.len() / 2], schemes[0], Some(tol)));
    }
    // Runs in interleaved order — every scheme at one step, then the next step — so that
    // a machine whose load drifts charges the schemes alike (their CPU seconds are
    // compared); stored in `configs` order (scheme by scheme).
    let nfix = steps.len();
    let order: Vec<usize> = (0..nfix)
        .flat_map(|j| (0..schemes.len()).map(move |k| k * nfix + j))
        .chain(schemes.len() * nfix..configs.len())
        .collect();
    let mut done: Vec<Option<(StudyRun, Vec<Vec<Rec>>)>> = vec![None; configs.len()];
    for &i in &order {
        let (h, a, tol) = &configs[i];
        let mut m = base.clone();
        set_run(&mut m, *h, *a, *tol, t_end);
        let label = match tol {
            None => format!("h={h:.3e} {}", a.label()),
            Some(t) => format!("adaptive tol={t:.1e} {}", a.label()),
        };
        log(&format!("running {label} …"));
        let mut rec = Recorder {
            nodes: node_idx.clone(),
            recs: vec![Vec::new(); node_idx.len()],
        };
        let report = solver::run(&m, &mut rec).map_err(|e| StudyError::Setup(e.to_string()))?;
        let run = StudyRun {
            label,
            h: *h,
            scheme: *a,
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
        };
        done[i] = Some((run, rec.recs));
    }
    let (mut runs, records): (Vec<StudyRun>, Vec<Vec<Vec<Rec>>>) =
        done.into_iter().flatten().unzip();
    // Sample grid: the coarsest fixed step.
    let dt = steps[0];
    let n_samples = (t_end / dt).round() as usize;
    let nwin = ((t_end / opts.window).ceil() as usize).max(1);
    let windows: Vec<f64> = (0..nwin).map(|k| k as f64 * opts.window).collect();
    // Reference: the finest fixed run of the first scheme.
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
    // Observed order between successive fixed runs of each scheme, over converged windows.
    for i in (0..schemes.len()).flat_map(|k| (0..nfix.saturating_sub(2)).map(move |j| k * nfix + j))
    {
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
            let j = i % nfix;
            runs[i].order = Some((na / nb).log2() / (steps[j] / steps[j + 1]).log2());
        }
    }
    // Adaptive runs against the fixed runs of the first scheme at the same error (position, or
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
    super::needs::write_needs(&report, &opts.out_dir)?;
    Ok(report)
}
