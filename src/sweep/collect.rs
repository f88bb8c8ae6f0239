//! Assembling a sweep from its case directories: `sweep.csv`, `statistics.csv` and the
//! figures — the same files whether the cases ran locally or as Slurm array tasks.
//!
//! `sweep.csv`: one row per case, in case order: `case`, the parameters, `status`, `steps`,
//! the quantities, `cpu_s`, `diagnosis`. Numbers in the shortest form that reads back to
//! the same double; an absent quantity is an empty cell. **Timing columns** — `cpu_s` and
//! the quantities with `summary = "cpu"` — change from run to run; every other column is
//! reproducible to the bit (same binary, same plan), which is what comparing two sweeps
//! means ([`timing_columns`]).
//!
//! `statistics.csv`: per quantity, over the cases that ended `ok` and have it: n, mean,
//! standard deviation (n − 1), the standard error of the mean sd/√n (the Monte Carlo
//! error; for a Latin hypercube it is an upper bound), min, the 5/25/50/75/95 % quantiles
//! (linear interpolation between order statistics, Hyndman & Fan type 7) and max.

use super::SweepError;
use super::plan::Plan;
use super::runner::{CaseRecord, Status, finished};
use std::fmt::Write as _;
use std::path::PathBuf;

/// What `collect` found.
#[derive(Debug, Clone)]
pub struct Collected {
    /// One record per case (status `missing` for cases not run).
    pub records: Vec<CaseRecord>,
    /// Files written.
    pub files: Vec<PathBuf>,
}

fn num(v: f64) -> String {
    let mut b = ryu::Buffer::new();
    b.format(v).to_string()
}

/// The names of the timing columns of `sweep.csv` for this plan.
pub fn timing_columns(plan: &Plan) -> Vec<String> {
    let mut v = vec!["cpu_s".to_string()];
    v.extend(
        plan.quantities
            .iter()
            .filter(|q| q.is_timing())
            .map(|q| q.name.clone()),
    );
    v
}

/// The records of every case (a `missing` record for a case not finished).
pub fn records(plan: &Plan) -> Vec<CaseRecord> {
    (0..plan.cases.len())
        .map(|i| {
            finished(plan, i).unwrap_or_else(|| CaseRecord {
                case: i,
                values: plan.cases[i].clone(),
                status: Status::Missing,
                diagnosis: String::new(),
                steps: 0,
                time: 0.0,
                cpu_s: 0.0,
                quantities: vec![None; plan.quantities.len()],
                quantity_names: Vec::new(),
                deck_hash: String::new(),
            })
        })
        .collect()
}

/// The text of sweep.csv.
pub fn sweep_csv(plan: &Plan, records: &[CaseRecord]) -> String {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    let mut header = vec!["case".to_string()];
    header.extend(plan.params.iter().map(|p| p.name.clone()));
    header.extend(["status".to_string(), "steps".to_string()]);
    header.extend(plan.quantities.iter().map(|q| q.name.clone()));
    header.extend(["cpu_s".to_string(), "diagnosis".to_string()]);
    let _ = w.write_record(&header);
    for r in records {
        let mut row = vec![r.case.to_string()];
        row.extend(r.values.iter().map(|v| num(*v)));
        row.push(r.status.as_str().to_string());
        row.push(r.steps.to_string());
        row.extend(r.quantities.iter().map(|q| q.map(num).unwrap_or_default()));
        row.push(num(r.cpu_s));
        row.push(r.diagnosis.clone());
        let _ = w.write_record(&row);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// Statistics of one sample (values of a quantity over the ok cases).
#[derive(Debug, Clone, PartialEq)]
pub struct Stats {
    /// Number of values.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Standard deviation (n − 1 in the denominator; 0 for one value).
    pub sd: f64,
    /// Standard error of the mean, sd/√n.
    pub stderr: f64,
    /// Smallest, 5 %, 25 %, 50 %, 75 %, 95 % quantiles, largest.
    pub quantiles: [f64; 7],
}

/// The statistics of `x` (None when empty).
pub fn stats(x: &[f64]) -> Option<Stats> {
    if x.is_empty() {
        return None;
    }
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let sd = if n > 1 {
        (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    } else {
        0.0
    };
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let h = (n - 1) as f64 * p;
        let lo = h.floor() as usize;
        let hi = (lo + 1).min(n - 1);
        s[lo] + (h - lo as f64) * (s[hi] - s[lo])
    };
    Some(Stats {
        n,
        mean,
        sd,
        stderr: sd / (n as f64).sqrt(),
        quantiles: [s[0], q(0.05), q(0.25), q(0.5), q(0.75), q(0.95), s[n - 1]],
    })
}

/// The values of quantity `k` over the ok cases.
pub fn values_of(records: &[CaseRecord], k: usize) -> Vec<f64> {
    records
        .iter()
        .filter(|r| r.status == Status::Ok)
        .filter_map(|r| r.quantities[k])
        .collect()
}

/// The text of statistics.csv.
pub fn statistics_csv(plan: &Plan, records: &[CaseRecord]) -> String {
    let mut s =
        String::from("quantity,n,not_ok,mean,sd,stderr_mean,min,q05,q25,median,q75,q95,max\n");
    let not_ok = records.iter().filter(|r| r.status != Status::Ok).count();
    for (k, q) in plan.quantities.iter().enumerate() {
        let x = values_of(records, k);
        let _ = write!(s, "{},{},{not_ok}", q.name, x.len());
        match stats(&x) {
            Some(st) => {
                for v in [st.mean, st.sd, st.stderr].iter().chain(&st.quantiles) {
                    let _ = write!(s, ",{}", num(*v));
                }
            }
            None => s.push_str(&",".repeat(10)),
        }
        s.push('\n');
    }
    s
}

/// Reads every case directory and writes sweep.csv and statistics.csv (the figures are
/// drawn from its records by `figures::draw`; `collect_and_draw` in the sweep module does both).
pub fn collect(plan: &Plan) -> Result<Collected, SweepError> {
    let records = records(plan);
    let io = |p: &PathBuf, e: std::io::Error| SweepError::Io {
        path: p.clone(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(&plan.out).map_err(|e| io(&plan.out, e))?;
    let mut files = Vec::new();
    for (name, text) in [
        ("sweep.csv", sweep_csv(plan, &records)),
        ("statistics.csv", statistics_csv(plan, &records)),
    ] {
        let p = plan.out.join(name);
        std::fs::write(&p, text).map_err(|e| io(&p, e))?;
        files.push(p);
    }
    Ok(Collected { records, files })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_a_known_sample() {
        let st = stats(&[1.0, 2.0, 3.0, 4.0, 5.0]).expect("non-empty");
        assert_eq!(st.n, 5);
        assert_eq!(st.mean, 3.0);
        assert!((st.sd - 2.5f64.sqrt()).abs() < 1e-15);
        assert!((st.stderr - (2.5f64 / 5.0).sqrt()).abs() < 1e-15);
        // type 7: q(p) at h = 4p: 0.05 -> 1.2, 0.25 -> 2, 0.5 -> 3, 0.95 -> 4.8
        let q = st.quantiles;
        assert!(
            (q[1] - 1.2).abs() < 1e-12 && q[2] == 2.0 && q[3] == 3.0 && (q[5] - 4.8).abs() < 1e-12
        );
        assert_eq!((q[0], q[6]), (1.0, 5.0));
        assert_eq!(stats(&[]), None);
        assert_eq!(stats(&[2.0]).map(|s| s.sd), Some(0.0));
    }
}
