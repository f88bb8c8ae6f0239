//! Which accepted states a run writes (`OUTPUT … EVERY n`, `SUBSTEPS`): with fixed steps one
//! row per instant `k n STEP`, exactly once, whatever the events (issue 34 §7).

use crate::solver::Snapshot;

/// Which accepted states `OUTPUT … EVERY n` writes: with fixed steps, the states at the
/// instants `k n h` (steps land back on that grid after contact events, which add steps of
/// their own, so a history keeps regular instants); with adaptive steps, every n-th state.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sampling {
    every: u64,
    /// `n h` for fixed steps.
    period: Option<f64>,
    /// `OUTPUT … SUBSTEPS`: also the states of steps shorter than `step` (fixed steps), or
    /// every accepted state (adaptive).
    #[serde(default)]
    substeps: bool,
    /// The deck's STEP, s (fixed steps; 0 otherwise).
    #[serde(default)]
    step: f64,
    /// The end time, s: an instant less than r before it, or after it, is the end's row.
    /// Not in checkpoints (their postcard layout is positional: a field added here would
    /// misread every earlier checkpoint's next fields); a resumed Writer takes it from the
    /// model ([`Sampling::resumed`]).
    #[serde(skip, default = "no_end")]
    end: f64,
}

/// No end time (a sampling read from a checkpoint, before [`Sampling::resumed`]).
fn no_end() -> f64 {
    f64::INFINITY
}

impl Sampling {
    /// The sampling a model asks for.
    pub fn of(model: &crate::model::Model) -> Self {
        let every = u64::from(model.output.every.max(1));
        let (period, step, end) = match &model.analysis {
            crate::model::Analysis::Dynamic {
                step,
                adaptive,
                end,
                ..
            } if adaptive.is_none() => (Some(*step * every as f64), *step, *end),
            _ => (None, 0.0, f64::INFINITY),
        };
        Sampling {
            every,
            period,
            substeps: model.output.substeps,
            step,
            end,
        }
    }

    /// A checkpoint's sampling with the end time of the model it resumes (`fresh`, as
    /// [`Sampling::of`] makes it).
    pub fn resumed(self, fresh: &Sampling) -> Self {
        Sampling {
            end: fresh.end,
            ..self
        }
    }

    /// Every accepted state.
    pub fn every_step() -> Self {
        Sampling {
            every: 1,
            period: None,
            substeps: false,
            step: 0.0,
            end: f64::INFINITY,
        }
    }

    /// Whether the state at `t`, reached by a step `h`, is the first to reach an instant
    /// `k p` (k ≥ 1) of the output grid: the step `(t − h, t]` crosses `k p − r`, r the
    /// stepper's reach [`crate::solver::GRID_REACH`]·STEP. The stepper lands on every
    /// instant or, when an event landed it less than r before one, steps over it (no
    /// sliver step is taken): that state is then the instant's row. The steps' intervals
    /// are disjoint, so each instant has exactly one row (issue 34 §7: a touch landed
    /// 1e-4 STEP before an instant, with MINSTEP 3e-4 STEP, lost that instant's row when a
    /// row had to be within 1e-6 of it).
    fn first_at_instant(&self, t: f64, h: f64, p: f64) -> bool {
        // STEP = p / every (a checkpoint of an older version has no `step`).
        let r = crate::solver::GRID_REACH * p / self.every as f64;
        let k = ((t + r) / p).floor();
        // An instant less than r before the end (or after it) has the end's state, which
        // is always written.
        let at_end = t >= self.end - 1e-9 * p / self.every as f64;
        k >= 1.0 && t - h < k * p - r && (k * p <= self.end - r || at_end)
    }

    /// Whether the state of a snapshot is written.
    pub fn takes(&self, snap: &Snapshot) -> bool {
        match self.period {
            Some(p) => {
                snap.step == 0
                    || self.first_at_instant(snap.integ.t, snap.h, p)
                    || (self.substeps && snap.h < self.step * (1.0 - 1e-9))
            }
            None => self.substeps || snap.step.is_multiple_of(self.every),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Sampling;

    fn fixed(every: u64, step: f64, end: f64) -> Sampling {
        Sampling {
            every,
            period: Some(every as f64 * step),
            substeps: false,
            step,
            end,
        }
    }

    /// Which of the states `(t, h)` (in order) are rows.
    fn rows(s: &Sampling, states: &[(f64, f64)]) -> Vec<f64> {
        let p = s.period.unwrap();
        states
            .iter()
            .filter(|(t, h)| s.first_at_instant(*t, *h, p))
            .map(|x| x.0)
            .collect()
    }

    /// On the grid (sums of steps, round-off in t): every instant, EVERY 1 and 3. An event
    /// landing 1e-4 STEP before instant 10 and a step over it: that state is the row, once.
    /// A landing 1/1024 STEP before it and then one exactly on it: the first, not both. An
    /// instant within reach after END has the end's row only.
    #[test]
    fn one_row_per_instant() {
        let h = 1e-4;
        let mut t = 0.0;
        let mut grid = Vec::new();
        for _ in 0..30 {
            t += h;
            grid.push((t, h));
        }
        assert_eq!(rows(&fixed(1, h, 1.0), &grid).len(), 30);
        let r3 = rows(&fixed(3, h, 1.0), &grid);
        assert_eq!(r3.len(), 10);
        assert!((r3[0] - 3e-4).abs() < 1e-15);
        let land = 10.0 * h - 1e-4 * h;
        let over = [
            (9.0 * h, h),
            (land, land - 9.0 * h),
            (11.0 * h, 11.0 * h - land),
        ];
        assert_eq!(
            rows(&fixed(1, h, 1.0), &over),
            vec![9.0 * h, land, 11.0 * h]
        );
        let near = 10.0 * h - h / 1024.0;
        let both = [(9.0 * h, h), (near, near - 9.0 * h), (10.0 * h, h / 1024.0)];
        assert_eq!(rows(&fixed(1, h, 1.0), &both), vec![9.0 * h, near]);
        // END 4e-4 STEP before instant 40 (within reach): the state before END is no row,
        // and END's own (it crosses nothing) is the one `finish` writes, as every run's last.
        let end = 40.0 * h - 4e-4 * h;
        let last = [(39.0 * h, h), (end - 5e-4 * h, 1e-3 * h), (end, 5e-4 * h)];
        assert_eq!(rows(&fixed(1, h, end), &last), vec![39.0 * h]);
        // END on the grid: its state is the last instant's row.
        let on = [(39.0 * h, h), (40.0 * h, h)];
        assert_eq!(rows(&fixed(1, h, 40.0 * h), &on), vec![39.0 * h, 40.0 * h]);
    }
}
