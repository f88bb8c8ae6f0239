//! Quantities of interest: numbers computed from a case's output directory.
//!
//! ```toml
//! [[quantity]]
//! name = "z12"          # the column's name in sweep.csv
//! node = 12             # node_12.csv (or element = 23: element_23.csv)
//! column = "z"          # a column of that file (header names)
//! stat = "max_abs"      # max | min | max_abs | value | last
//!                       # | first_time_above | first_time_below
//! from = 0.0            # window [from, to] in s (default: the whole run)
//! to = 1.0
//! at = 0.5              # stat = "value": the column at t (linear interpolation)
//! threshold = 0.0       # first_time_above / _below: the first time the column crosses
//!                       # the threshold (default 0) upwards / downwards, interpolated
//!                       # linearly between the two rows that bracket the crossing (the
//!                       # first row when it is already past)
//!
//! [[quantity]]
//! name = "impacts"
//! element = 23
//! summary = "impacts"   # element: impacts | max_penetration | dissipated_energy
//!                       # run:     energy_error | steps | cpu
//!
//! [[quantity]]
//! name = "f1"
//! mode = 1              # a deck of ANALYSIS MODES n: its summary.json's mode 1
//! summary = "frequency" # frequency (natural, Hz) | damped_frequency (Hz) | damping (ratio)
//! ```
//!
//! Histories are those the run wrote (`OUTPUT ... EVERY n`): a deck meant for a sweep
//! writes the nodes and elements its quantities need at every step. The `summary`
//! quantities come from `summary.json` and are counted at every step (`impacts`: contact
//! closures; `max_penetration`: the largest penetration, m; `dissipated_energy`: J;
//! `energy_error`: the largest relative energy-balance error; `steps`: accepted steps;
//! `cpu`: the run's seconds — a timing, not reproducible). A quantity that does not exist
//! for a case (an empty window, a threshold never crossed) is absent: an empty cell.

use crate::plot::Table;
use serde::Deserialize;
use std::path::Path;

/// A quantity as written in the plan.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct QuantitySpec {
    name: String,
    node: Option<u32>,
    element: Option<u32>,
    column: Option<String>,
    stat: Option<String>,
    from: Option<f64>,
    to: Option<f64>,
    at: Option<f64>,
    threshold: Option<f64>,
    summary: Option<String>,
    mode: Option<u32>,
}

/// Which history file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `node_<N>.csv`.
    Node(u32),
    /// `element_<N>.csv`.
    Element(u32),
}

/// What to take of a column.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stat {
    /// Largest value in the window.
    Max,
    /// Smallest value in the window.
    Min,
    /// Largest absolute value in the window.
    MaxAbs,
    /// The value at a time (linear interpolation between rows).
    Value(f64),
    /// The last value in the window.
    Last,
    /// The first time in the window where the column rises above the threshold.
    FirstTimeAbove(f64),
    /// The first time in the window where the column falls below the threshold.
    FirstTimeBelow(f64),
}

/// From summary.json.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SummaryKey {
    /// Contact closures of a CAME element.
    Impacts(u32),
    /// Largest penetration of a CAME element, m.
    MaxPenetration(u32),
    /// Energy dissipated by a CAME element, J.
    DissipatedEnergy(u32),
    /// Largest relative energy-balance error of the run.
    EnergyError,
    /// Accepted steps.
    Steps,
    /// CPU seconds of the run (a timing).
    Cpu,
    /// A number of mode `mode` (from 1) of a modal analysis's summary.json (a deck of
    /// `ANALYSIS MODES n`): over a parameter, a Campbell diagram.
    Mode {
        /// Mode number, from 1 (rigid modes first, then by frequency).
        mode: u32,
        /// Which number.
        field: ModeField,
    },
}

/// What a [`SummaryKey::Mode`] quantity takes of its mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeField {
    /// Undamped natural frequency `|s|/2π`, Hz (`natural_hz`).
    Frequency,
    /// Damped frequency `Im s/2π`, Hz (`frequency_hz`).
    DampedFrequency,
    /// Damping ratio `−Re s/|s|` (`damping_ratio`).
    Damping,
}

/// How a quantity is computed.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// A statistic of a history column in a time window.
    Column {
        /// The file.
        source: Source,
        /// The column's header name.
        column: String,
        /// What to take.
        stat: Stat,
        /// Window start, s.
        from: f64,
        /// Window end, s.
        to: f64,
    },
    /// A number of summary.json.
    Summary(SummaryKey),
}

/// A quantity of interest.
#[derive(Debug, Clone, PartialEq)]
pub struct Quantity {
    /// Column name in sweep.csv.
    pub name: String,
    /// How it is computed.
    pub kind: Kind,
}

impl Quantity {
    /// Validates a plan's quantity.
    pub(crate) fn from_spec(q: &QuantitySpec) -> Result<Quantity, String> {
        let ctx = format!("quantity `{}`", q.name);
        if !crate::deck::is_parameter_name(&q.name) {
            return Err(format!(
                "{ctx}: the name must be a letter or `_` followed by letters, digits or `_`"
            ));
        }
        let source = match (q.node, q.element) {
            (Some(n), None) => Some(Source::Node(n)),
            (None, Some(e)) => Some(Source::Element(e)),
            (None, None) => None,
            (Some(_), Some(_)) => return Err(format!("{ctx}: give `node` or `element`, not both")),
        };
        if let Some(s) = &q.summary {
            if q.column.is_some() || q.stat.is_some() || q.from.is_some() || q.to.is_some() {
                return Err(format!(
                    "{ctx}: a `summary` quantity takes no column, stat or window"
                ));
            }
            let el = match source {
                Some(Source::Element(e)) => Some(e),
                _ => None,
            };
            if let Some(mode) = q.mode {
                let field = match s.as_str() {
                    "frequency" => ModeField::Frequency,
                    "damped_frequency" => ModeField::DampedFrequency,
                    "damping" => ModeField::Damping,
                    _ => {
                        return Err(format!(
                            "{ctx}: a `mode` quantity takes summary = \"frequency\", \"damped_frequency\" or \"damping\", not \"{s}\""
                        ));
                    }
                };
                if mode == 0 || source.is_some() {
                    return Err(format!(
                        "{ctx}: `mode` counts from 1 and takes no node or element"
                    ));
                }
                return Ok(Quantity {
                    name: q.name.clone(),
                    kind: Kind::Summary(SummaryKey::Mode { mode, field }),
                });
            }
            let key = match (s.as_str(), el) {
                ("impacts", Some(e)) => SummaryKey::Impacts(e),
                ("max_penetration", Some(e)) => SummaryKey::MaxPenetration(e),
                ("dissipated_energy", Some(e)) => SummaryKey::DissipatedEnergy(e),
                ("impacts" | "max_penetration" | "dissipated_energy", None) => {
                    return Err(format!("{ctx}: summary = \"{s}\" needs `element`"));
                }
                ("energy_error", _) => SummaryKey::EnergyError,
                ("steps", _) => SummaryKey::Steps,
                ("cpu", _) => SummaryKey::Cpu,
                _ => {
                    return Err(format!(
                        "{ctx}: summary = \"{s}\": expected impacts, max_penetration, dissipated_energy, energy_error, steps or cpu"
                    ));
                }
            };
            return Ok(Quantity {
                name: q.name.clone(),
                kind: Kind::Summary(key),
            });
        }
        if q.mode.is_some() {
            return Err(format!(
                "{ctx}: `mode` needs summary = \"frequency\", \"damped_frequency\" or \"damping\""
            ));
        }
        let source = source.ok_or(format!(
            "{ctx}: needs `node` or `element` (and `column`), or `summary`"
        ))?;
        let column = q.column.clone().ok_or(format!("{ctx}: needs `column`"))?;
        let stat = match q.stat.as_deref() {
            Some("max") => Stat::Max,
            Some("min") => Stat::Min,
            Some("max_abs") => Stat::MaxAbs,
            Some("last") => Stat::Last,
            Some("value") => {
                Stat::Value(q.at.ok_or(format!("{ctx}: stat = \"value\" needs `at`"))?)
            }
            Some("first_time_above") => Stat::FirstTimeAbove(q.threshold.unwrap_or(0.0)),
            Some("first_time_below") => Stat::FirstTimeBelow(q.threshold.unwrap_or(0.0)),
            Some(o) => {
                return Err(format!(
                    "{ctx}: stat = \"{o}\": expected max, min, max_abs, value, last, first_time_above or first_time_below"
                ));
            }
            None => return Err(format!("{ctx}: needs `stat`")),
        };
        if q.at.is_some() && !matches!(stat, Stat::Value(_)) {
            return Err(format!("{ctx}: `at` belongs to stat = \"value\""));
        }
        if q.threshold.is_some() && !matches!(stat, Stat::FirstTimeAbove(_)) {
            return Err(format!(
                "{ctx}: `threshold` belongs to stat = \"first_time_above\""
            ));
        }
        let from = q.from.unwrap_or(f64::NEG_INFINITY);
        let to = q.to.unwrap_or(f64::INFINITY);
        if from > to || from.is_nan() || to.is_nan() {
            return Err(format!("{ctx}: the window needs from <= to"));
        }
        Ok(Quantity {
            name: q.name.clone(),
            kind: Kind::Column {
                source,
                column,
                stat,
                from,
                to,
            },
        })
    }

    /// A timing (not reproducible from run to run): excluded from the comparison of sweeps.
    pub fn is_timing(&self) -> bool {
        self.kind == Kind::Summary(SummaryKey::Cpu)
    }

    /// The value for the case whose output is in `dir` (with its parsed summary.json);
    /// `Ok(None)` when it does not exist for this case; `Err` when the file or column
    /// is missing (a plan that does not match its deck's OUTPUT).
    pub fn eval(&self, dir: &Path, summary: &serde_json::Value) -> Result<Option<f64>, String> {
        match &self.kind {
            Kind::Summary(key) => {
                let el = |e: &u32, k: &str| summary["elements"][e.to_string()][k].as_f64();
                let v = match key {
                    SummaryKey::Impacts(e) => el(e, "impacts"),
                    SummaryKey::MaxPenetration(e) => el(e, "max_penetration"),
                    SummaryKey::DissipatedEnergy(e) => el(e, "dissipated_energy"),
                    SummaryKey::EnergyError => summary["energy"]["max_balance_error"].as_f64(),
                    SummaryKey::Steps => summary["stats"]["steps"].as_f64(),
                    SummaryKey::Cpu => summary["stats"]["cpu_seconds"].as_f64(),
                    SummaryKey::Mode { mode, field } => {
                        if summary["modes"].as_array().is_none() {
                            return Err(format!(
                                "{}: summary.json has no modes (the deck needs ANALYSIS MODES n)",
                                self.name
                            ));
                        }
                        let key = match field {
                            ModeField::Frequency => "natural_hz",
                            ModeField::DampedFrequency => "frequency_hz",
                            ModeField::Damping => "damping_ratio",
                        };
                        summary["modes"][*mode as usize - 1][key].as_f64()
                    }
                };
                match (key, v) {
                    (
                        SummaryKey::Impacts(e)
                        | SummaryKey::MaxPenetration(e)
                        | SummaryKey::DissipatedEnergy(e),
                        None,
                    ) => Err(format!(
                        "{}: summary.json has no contact element {e}",
                        self.name
                    )),
                    (_, v) => Ok(v.filter(|x| x.is_finite())),
                }
            }
            Kind::Column {
                source,
                column,
                stat,
                from,
                to,
            } => {
                let file = match source {
                    Source::Node(n) => dir.join(format!("node_{n}.csv")),
                    Source::Element(e) => dir.join(format!("element_{e}.csv")),
                };
                let table = Table::read(&file).map_err(|e| format!("{}: {e}", self.name))?;
                let t = table
                    .column("t")
                    .map_err(|e| format!("{}: {e}", self.name))?;
                let y = table
                    .column(column)
                    .map_err(|e| format!("{}: {e}", self.name))?;
                Ok(column_stat(&t, &y, *stat, *from, *to))
            }
        }
    }
}

/// A statistic of the samples (t, y) in the window [from, to].
pub fn column_stat(t: &[f64], y: &[f64], stat: Stat, from: f64, to: f64) -> Option<f64> {
    let inside = || t.iter().zip(y).filter(|(t, _)| **t >= from && **t <= to);
    match stat {
        Stat::Max => inside().map(|p| *p.1).reduce(f64::max),
        Stat::Min => inside().map(|p| *p.1).reduce(f64::min),
        Stat::MaxAbs => inside().map(|p| p.1.abs()).reduce(f64::max),
        Stat::Last => inside().next_back().map(|p| *p.1),
        Stat::FirstTimeAbove(th) => crossing(inside(), |y| y > th, th),
        Stat::FirstTimeBelow(th) => crossing(inside(), |y| y < th, th),
        Stat::Value(at) => {
            if at < from || at > to {
                return None;
            }
            let k = t.iter().position(|&x| x >= at)?;
            if t[k] == at || k == 0 {
                return (t[k] == at).then_some(y[k]);
            }
            let s = (at - t[k - 1]) / (t[k] - t[k - 1]);
            Some(y[k - 1] + s * (y[k] - y[k - 1]))
        }
    }
}

/// The first time `past(y)` holds, interpolated linearly from the row before.
fn crossing<'a>(
    mut rows: impl Iterator<Item = (&'a f64, &'a f64)>,
    past: impl Fn(f64) -> bool,
    th: f64,
) -> Option<f64> {
    let mut prev: Option<(f64, f64)> = None;
    rows.find_map(|(&t, &y)| {
        let hit = past(y).then(|| match prev {
            Some((t0, y0)) if y != y0 => t0 + (th - y0) / (y - y0) * (t - t0),
            _ => t,
        });
        prev = Some((t, y));
        hit
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_a_column() {
        let t = [0.0, 0.1, 0.2, 0.3, 0.4];
        let y = [0.0, -3.0, 2.0, 1.0, 5.0];
        let inf = f64::INFINITY;
        assert_eq!(column_stat(&t, &y, Stat::Max, -inf, inf), Some(5.0));
        assert_eq!(column_stat(&t, &y, Stat::Max, 0.0, 0.3), Some(2.0));
        assert_eq!(column_stat(&t, &y, Stat::Min, 0.0, 0.3), Some(-3.0));
        assert_eq!(column_stat(&t, &y, Stat::MaxAbs, 0.0, 0.3), Some(3.0));
        assert_eq!(column_stat(&t, &y, Stat::Last, 0.0, 0.35), Some(1.0));
        // 1.5 is crossed between (0.1, −3) and (0.2, 2): at 0.1 + 4.5/5 · 0.1 = 0.19.
        let up = column_stat(&t, &y, Stat::FirstTimeAbove(1.5), -inf, inf).expect("crossed");
        assert!((up - 0.19).abs() < 1e-12, "{up}");
        let down = column_stat(&t, &y, Stat::FirstTimeBelow(-1.0), -inf, inf).expect("crossed");
        assert!((down - 0.1 / 3.0).abs() < 1e-12, "{down}");
        assert_eq!(
            column_stat(&t, &y, Stat::FirstTimeBelow(1.0), 0.0, inf),
            Some(0.0)
        );
        assert_eq!(
            column_stat(&t, &y, Stat::FirstTimeAbove(9.0), -inf, inf),
            None
        );
        let v = column_stat(&t, &y, Stat::Value(0.25), -inf, inf).expect("inside");
        assert!((v - 1.5).abs() < 1e-12);
        assert_eq!(column_stat(&t, &y, Stat::Value(0.2), -inf, inf), Some(2.0));
        assert_eq!(column_stat(&t, &y, Stat::Value(0.5), -inf, inf), None);
        assert_eq!(column_stat(&t, &y, Stat::Max, 0.5, 0.6), None);
    }
}
