//! Tolerances by column, by group of columns, or one for all (`--tol`).

use super::*;

/// Tolerances by column (`--tol`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tolerances {
    default: Option<f64>,
    by_name: BTreeMap<String, f64>,
}

/// Column groups of `--tol` (node history columns, README).
pub(super) const GROUPS: [(&str, &[&str]); 5] = [
    ("position", &["x", "y", "z", "ux", "uy", "uz"]),
    ("rotation", &["rx", "ry", "rz"]),
    ("velocity", &["vx", "vy", "vz"]),
    ("angular_velocity", &["wx", "wy", "wz"]),
    ("acceleration", &["ax", "ay", "az"]),
];

impl Tolerances {
    /// Parses `--tol` (module docs).
    pub fn parse(s: &str) -> Result<Self, CompareError> {
        let mut t = Tolerances::default();
        let num = |v: &str| -> Result<f64, CompareError> {
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| {
                    CompareError::Option(format!("--tol: `{v}` is not a tolerance (a number >= 0)"))
                })
        };
        for part in s.split(',').filter(|p| !p.trim().is_empty()) {
            match part.split_once('=') {
                None => t.default = Some(num(part)?),
                Some((name, v)) => {
                    t.by_name.insert(name.trim().to_string(), num(v)?);
                }
            }
        }
        Ok(t)
    }

    /// The tolerance of a column: its own, its group's, or the default.
    pub fn of(&self, column: &str) -> Option<f64> {
        if let Some(v) = self.by_name.get(column) {
            return Some(*v);
        }
        GROUPS
            .iter()
            .find(|(_, cols)| cols.contains(&column))
            .and_then(|(g, _)| self.by_name.get(*g).copied())
            .or(self.default)
    }

    /// Names given that are neither a column of `columns` nor a group.
    pub(super) fn unknown<'a>(&'a self, columns: &[&str]) -> Vec<&'a str> {
        self.by_name
            .keys()
            .map(String::as_str)
            .filter(|n| !columns.contains(n) && !GROUPS.iter().any(|(g, _)| g == n))
            .collect()
    }
}
