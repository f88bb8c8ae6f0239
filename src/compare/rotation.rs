//! Rotations compared as rotations (issue 27 §3): the columns `rx, ry, rz` of a node history
//! are a rotation vector Φ (`R = exp(Φ̃)`, [`crate::rotation::exp`]), defined up to 2π along
//! its axis, so the same attitude may be written `Φ` by one run and `Φ − 2π Φ/|Φ|` by the
//! other (a rotation crossing ±π). Taking `rx_run − rx_ref` then shows a "difference" near 2π
//! where there is none. Instead the three columns are compared as one, `rotation`: the angle
//! of the relative rotation `R_runᵀ R_ref`, `|log(R_runᵀ R_ref)|` ∈ [0, π] rad
//! ([`crate::rotation::log`]), which is zero exactly when the attitudes agree and does not
//! depend on how either run wrote its vector.
//!
//! Where the reference's times differ from the run's, its attitude at `t` between rows `a`
//! and `b` is the geodesic interpolant `R_a exp(s log(R_aᵀ R_b))`, `s = (t − t_a)/(t_b − t_a)`
//! (the rotation analogue of the linear interpolant of the other columns, of the same order
//! in the reference's step).

use super::{ColumnReport, Extreme, History};
use crate::rotation::{exp, log};
use nalgebra::{Matrix3, Vector3};

/// The rotation-vector columns, and the name of the column that replaces them in reports
/// (and the `--tol` group that judges it).
pub const COLUMNS: [&str; 3] = ["rx", "ry", "rz"];
/// See [`COLUMNS`].
pub const NAME: &str = "rotation";

/// The angle of `R(a)ᵀ R(b)`, rad, in [0, π] (for the tests; [`compare`] works on matrices).
#[cfg(test)]
fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    log(&(exp(a).transpose() * exp(b))).norm()
}

/// Positions of `rx, ry, rz` in `h`'s header, if it has all three.
fn positions(h: &History) -> Option<[usize; 3]> {
    let p = |c: &str| h.header.iter().position(|x| x == c);
    Some([p(COLUMNS[0])?, p(COLUMNS[1])?, p(COLUMNS[2])?])
}

/// Splits the chosen `columns` into the plain ones and whether the rotation is compared as a
/// rotation: when both histories have the three columns `rx, ry, rz` and any of them is
/// chosen, they leave the plain list and [`compare`] reports them as one column.
pub fn split(columns: &[String], run: &History, reference: &History) -> (Vec<String>, bool) {
    let rotation = positions(run).is_some()
        && positions(reference).is_some()
        && columns.iter().any(|c| COLUMNS.contains(&c.as_str()));
    let plain = columns
        .iter()
        .filter(|c| !(rotation && COLUMNS.contains(&c.as_str())))
        .cloned()
        .collect();
    (plain, rotation)
}

fn vector(row: &[f64], p: [usize; 3]) -> Vector3<f64> {
    Vector3::new(row[p[0]], row[p[1]], row[p[2]])
}

/// The reference's attitude at `t` (module docs), `k` a cursor advanced monotonically; `None`
/// outside its time range.
fn attitude(rows: &[Vec<f64>], p: [usize; 3], k: &mut usize, t: f64) -> Option<Matrix3<f64>> {
    let (first, last) = (rows.first()?[0], rows.last()?[0]);
    if t < first || t > last {
        return None;
    }
    while *k + 1 < rows.len() && rows[*k + 1][0] < t {
        *k += 1;
    }
    let ra = exp(&vector(&rows[*k], p));
    if rows[*k][0] == t || *k + 1 == rows.len() {
        return Some(ra);
    }
    let b = &rows[*k + 1];
    let s = (t - rows[*k][0]) / (b[0] - rows[*k][0]);
    let rel = log(&(ra.transpose() * exp(&vector(b, p))));
    Some(ra * exp(&(rel * s)))
}

/// The `rotation` column of a file's report: the angle of `R_runᵀ R_ref` at each time of the
/// run, its largest value (with the rotation angles `|Φ|` of both runs there as the values),
/// per window of width `window` (`n_win` of them), judged against `tolerance`. Also returns
/// the rows compared and those outside the reference's time range. `same_times`: the rows
/// pair up one to one.
pub fn compare(
    run: &History,
    reference: &History,
    same_times: bool,
    window: f64,
    n_win: usize,
    tolerance: Option<f64>,
) -> (ColumnReport, usize, usize) {
    let (Some(pr), Some(pf)) = (positions(run), positions(reference)) else {
        unreachable!("split() checked both histories have rx, ry, rz")
    };
    let mut max: Option<Extreme> = None;
    let mut wins: Vec<Option<f64>> = vec![None; n_win];
    let (mut k, mut compared, mut outside) = (0, 0, 0);
    for (i, row) in run.rows.iter().enumerate() {
        let t = row[0];
        let r_ref = if same_times {
            Some(exp(&vector(&reference.rows[i], pf)))
        } else {
            attitude(&reference.rows, pf, &mut k, t)
        };
        let Some(r_ref) = r_ref else {
            outside += 1;
            continue;
        };
        compared += 1;
        let r_run = exp(&vector(row, pr));
        let d = log(&(r_run.transpose() * r_ref)).norm();
        if max.is_none_or(|m| d > m.max_abs_diff) {
            max = Some(Extreme {
                max_abs_diff: d,
                at_time: t,
                run_value: log(&r_run).norm(),
                ref_value: log(&r_ref).norm(),
            });
        }
        let w = ((t / window).floor().max(0.0) as usize).min(n_win - 1);
        wins[w] = Some(wins[w].map_or(d, |m: f64| m.max(d)));
    }
    let report = ColumnReport::new(NAME.to_string(), max, &wins, window, tolerance);
    (report, compared, outside)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn hist(rows: &[[f64; 4]]) -> History {
        History {
            header: ["t", "rx", "ry", "rz"].map(String::from).to_vec(),
            rows: rows.iter().map(|r| r.to_vec()).collect(),
        }
    }

    /// Rotations about z by π − ε and by π + ε (written `(0, 0, −(π − ε))`, |Φ| ≤ π): 2π − 2ε
    /// apart as numbers, 2ε apart as rotations.
    #[test]
    fn a_rotation_vector_crossing_pi_is_no_difference() {
        let eps = 1e-3;
        let a = Vector3::new(0.0, 0.0, PI - eps);
        let b = Vector3::new(0.0, 0.0, -(PI - eps)); // the rotation by π + eps
        assert!((a - b).norm() > 6.0);
        assert!((angle_between(&a, &b) - 2.0 * eps).abs() < 1e-12);
        // Same attitude written with the vector Φ − 2π Φ/|Φ|: no difference at all (to the
        // rounding of exp and log of angles near π: a few ulps of π).
        let c = a - a.normalize() * (2.0 * PI);
        assert!(angle_between(&a, &c) < 1e-12);
    }

    #[test]
    fn the_rotation_column_is_the_relative_angle_and_interpolates_on_the_geodesic() {
        // The reference turns about z at 1 rad/s through ±π: rows at t = 3.0 and 3.2 written
        // with |Φ| ≤ π (3.0 rad, then 3.2 − 2π). The run samples t = 3.1 at 3.1 rad exactly
        // (the geodesic midpoint) and t = 3.2 with a planted 1e-3 rad about x.
        let reference = hist(&[[3.0, 0.0, 0.0, 3.0], [3.2, 0.0, 0.0, 3.2 - 2.0 * PI]]);
        let planted =
            log(&(exp(&Vector3::new(0.0, 0.0, 3.2)) * exp(&Vector3::new(1e-3, 0.0, 0.0))));
        let run = hist(&[[3.1, 0.0, 0.0, 3.1], [3.2, planted.x, planted.y, planted.z]]);
        let cols = ["rx", "ry", "rz"].map(String::from).to_vec();
        let (plain, rot) = split(&cols, &run, &reference);
        assert!(plain.is_empty() && rot);
        let (c, compared, outside) = compare(&run, &reference, false, 1.0, 4, Some(2e-3));
        assert_eq!((compared, outside), (2, 0));
        let m = c.max.unwrap();
        assert_eq!(m.at_time, 3.2);
        // exp and log round to ~1e-15 rad; the geodesic midpoint is exact to that.
        assert!((m.max_abs_diff - 1e-3).abs() < 1e-12, "{}", m.max_abs_diff);
        assert_eq!(c.pass, Some(true));
        assert!(c.windows[3].max_abs_diff.unwrap() < 1.1e-3);
    }
}
