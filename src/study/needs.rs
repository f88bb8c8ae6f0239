//! What each integrator needs for a given accuracy (issue 26 §3): from each scheme's
//! ladder of fixed steps, the step, the steps and the CPU seconds at which its error
//! reaches 1e-2, 1e-3 and 1e-4 (m, or rad when the chosen nodes do not translate).
//!
//! Between the two successive runs of a ladder whose errors bracket the target, the step,
//! the step count and the CPU time are interpolated linearly in the logarithms against
//! `ln error` (the work–precision line is straight there for a method of constant order:
//! error ∝ h^p, cost ∝ 1/h). A target above the coarsest run's error is met by that run
//! (reported as an upper bound on the cost); a target below the finest scored run's error
//! is not reached by the ladder (no extrapolation: the order may change there).

use super::*;
use crate::model::Scheme;
use std::io::Write;

/// The accuracies the table is written for, in the compared quantity's unit.
pub const TARGETS: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// How a [`Need`] was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reached {
    /// Interpolated between two runs of the ladder.
    Interpolated,
    /// Already met by the coarsest run: what it cost, an upper bound.
    ByCoarsest,
    /// The finest scored run of the ladder does not reach it.
    NotReached,
}

/// What one scheme needs for one target error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Need {
    /// The scheme.
    pub scheme: Scheme,
    /// The target error.
    pub target: f64,
    /// Fixed step, s (NaN when not reached).
    pub h: f64,
    /// Accepted steps.
    pub steps: f64,
    /// CPU seconds.
    pub cpu: f64,
    /// How it was found.
    pub how: Reached,
}

/// A ladder point: (h, error, steps, CPU s), coarsest first.
type Point = (f64, f64, f64, f64);

/// [`Need`] of `target` on one scheme's ladder (module docs); points with a zero, NaN or
/// infinite error (the reference, stopped runs) are left out.
pub fn need(scheme: Scheme, ladder: &[Point], target: f64) -> Need {
    let pts: Vec<Point> = ladder
        .iter()
        .copied()
        .filter(|p| p.1 > 0.0 && p.1.is_finite() && p.3 > 0.0)
        .collect();
    let at = |(h, steps, cpu): (f64, f64, f64), how| Need {
        scheme,
        target,
        h,
        steps,
        cpu,
        how,
    };
    let nan = (f64::NAN, f64::NAN, f64::NAN);
    let Some(first) = pts.first() else {
        return at(nan, Reached::NotReached);
    };
    if first.1 <= target {
        return at((first.0, first.2, first.3), Reached::ByCoarsest);
    }
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a.1 >= target && target >= b.1 && a.1 > b.1 {
            let th = (a.1.ln() - target.ln()) / (a.1.ln() - b.1.ln());
            let lerp = |x: f64, y: f64| (x.ln() + th * (y.ln() - x.ln())).exp();
            return at(
                (lerp(a.0, b.0), lerp(a.2, b.2), lerp(a.3, b.3)),
                Reached::Interpolated,
            );
        }
    }
    at(nan, Reached::NotReached)
}

/// The table's rows: every scheme of the study's fixed runs, every [`TARGETS`] entry.
pub fn needs(r: &StudyReport) -> Vec<Need> {
    let c = compared_quantity(&r.runs);
    let mut schemes: Vec<Scheme> = r
        .runs
        .iter()
        .filter(|x| x.tol.is_none())
        .map(|x| x.scheme)
        .collect();
    schemes.dedup();
    let mut out = Vec::new();
    for s in schemes {
        let ladder: Vec<Point> = r
            .runs
            .iter()
            .filter(|x| x.tol.is_none() && x.scheme == s && x.complete)
            .map(|x| (x.h, x.error[c], x.stats.steps as f64, x.stats.cpu_seconds))
            .collect();
        out.extend(TARGETS.iter().map(|&t| need(s, &ladder, t)));
    }
    out
}

/// Prints the table (and returns nothing to write when the study has no fixed runs).
pub fn print_needs(r: &StudyReport, out: &mut dyn Write) -> io::Result<()> {
    let rows = needs(r);
    if rows.is_empty() {
        return Ok(());
    }
    let unit = ["m", "rad"][compared_quantity(&r.runs)];
    writeln!(
        out,
        "what each integrator needs (fixed steps, interpolated on its ladder; ≤ = its coarsest run already meets it):"
    )?;
    writeln!(
        out,
        "  {:<20} {:>8} {:>11} {:>10} {:>9}",
        "integrator",
        format!("error {unit}"),
        "h (s)",
        "steps",
        "CPU s"
    )?;
    for n in rows {
        let (h, steps, cpu) = match n.how {
            Reached::NotReached => ("not reached".into(), "-".into(), "-".into()),
            how => {
                let le = if how == Reached::ByCoarsest {
                    "≤"
                } else {
                    ""
                };
                (
                    format!("{:.3e}", n.h),
                    format!("{le}{:.0}", n.steps),
                    format!("{le}{:.3}", n.cpu),
                )
            }
        };
        writeln!(
            out,
            "  {:<20} {:>8.0e} {:>11} {:>10} {:>9}",
            n.scheme.label(),
            n.target,
            h,
            steps,
            cpu
        )?;
    }
    Ok(())
}

/// Writes `study_needs.csv`: one row per scheme and target (empty fields where the ladder
/// does not reach it).
pub fn write_needs(r: &StudyReport, dir: &std::path::Path) -> io::Result<()> {
    let mut w = csv::Writer::from_path(dir.join("study_needs.csv"))?;
    w.write_record([
        "integrator",
        "target_error",
        "h",
        "steps",
        "cpu_seconds",
        "how",
    ])?;
    for n in needs(r) {
        let f = |x: f64| report::csv_number(x);
        let how = match n.how {
            Reached::Interpolated => "interpolated",
            Reached::ByCoarsest => "coarsest run (upper bound)",
            Reached::NotReached => "not reached",
        };
        w.write_record([
            n.scheme.label(),
            format!("{:e}", n.target),
            f(n.h),
            f(n.steps),
            f(n.cpu),
            how.to_string(),
        ])?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a line error = h², steps = CPU = 1/h (order 2), the interpolation is exact in the
    /// logarithms: 1e-4 needs h = 1e-2, 100 steps; a target the coarsest run meets is its
    /// cost; one below the finest scored run is not reached; the reference (error 0) is
    /// left out.
    #[test]
    fn needs_interpolate_the_ladder_in_logarithms() {
        let s = Scheme::default();
        let ladder: Vec<Point> = [4e-2, 2e-2, 5e-3, 2.5e-3]
            .iter()
            .map(|&h| (h, h * h, 1.0 / h, 1.0 / h))
            .chain([(1e-3, 0.0, 1000.0, 1000.0)])
            .collect();
        let n = need(s, &ladder, 1e-4);
        assert_eq!(n.how, Reached::Interpolated);
        assert!((n.h - 1e-2).abs() < 1e-12 && (n.steps - 100.0).abs() < 1e-9);
        assert!((n.cpu - 100.0).abs() < 1e-9);
        let n = need(s, &ladder, 1e-2);
        assert_eq!((n.how, n.h, n.cpu), (Reached::ByCoarsest, 4e-2, 25.0));
        assert_eq!(need(s, &ladder, 1e-6).how, Reached::NotReached);
    }
}
