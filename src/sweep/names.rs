//! The names a plan's `[[reference]]` and `[[guide]]` tables give (issue 28 §5): each must
//! be a quantity and a parameter of the plan, refused with its line otherwise (they were
//! ignored: a figure silently lost its reference curve).

use super::SweepError;
use super::plan::Plan;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
struct Names {
    quantity: Spanned<String>,
    parameter: Spanned<String>,
}

#[derive(Deserialize)]
struct Figures {
    #[serde(default)]
    reference: Vec<Names>,
    #[serde(default)]
    guide: Vec<Names>,
}

/// 1-based line of byte `at` in `text`.
fn line(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Checks that every reference and guide names a quantity and a parameter of `plan`
/// (`text`: the plan's TOML, already read into `plan`).
pub fn check(text: &str, path: &Path, plan: &Plan) -> Result<(), SweepError> {
    let Ok(f) = toml::from_str::<Figures>(text) else {
        return Ok(()); // the plan's own parse reports malformed tables
    };
    let tables = f
        .reference
        .iter()
        .map(|n| ("reference", n))
        .chain(f.guide.iter().map(|n| ("guide", n)));
    for (table, n) in tables {
        let q = n.quantity.get_ref();
        if !plan.quantities.iter().any(|x| &x.name == q) {
            let known: Vec<&str> = plan.quantities.iter().map(|x| x.name.as_str()).collect();
            return Err(SweepError::Plan {
                path: path.to_path_buf(),
                msg: format!(
                    "line {}: [[{table}]] quantity `{}` is not a quantity of the plan ({})",
                    line(text, n.quantity.span().start),
                    crate::deck::short(q),
                    known.join(", ")
                ),
            });
        }
        let p = n.parameter.get_ref();
        if !plan.params.iter().any(|x| &x.name == p) {
            let known: Vec<&str> = plan.params.iter().map(|x| x.name.as_str()).collect();
            return Err(SweepError::Plan {
                path: path.to_path_buf(),
                msg: format!(
                    "line {}: [[{table}]] parameter `{}` is not a parameter of the plan ({})",
                    line(text, n.parameter.span().start),
                    crate::deck::short(p),
                    known.join(", ")
                ),
            });
        }
    }
    Ok(())
}
