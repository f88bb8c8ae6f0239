//! The names a plan's `[[reference]]` and `[[guide]]` tables give (issue 28 §5): each must
//! be a quantity and a parameter of the plan, refused with its line otherwise (they were
//! ignored: a figure silently lost its reference curve).

use super::Plan;
use crate::sweep::SweepError;
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
        let quantities = plan.quantities.iter().map(|x| x.name.as_str());
        let params = plan.params.iter().map(|x| x.name.as_str());
        let fields: [(&str, &Spanned<String>, Vec<&str>); 2] = [
            ("quantity", &n.quantity, quantities.collect()),
            ("parameter", &n.parameter, params.collect()),
        ];
        for (field, name, known) in fields {
            if !known.contains(&name.get_ref().as_str()) {
                return Err(SweepError::Plan {
                    path: path.to_path_buf(),
                    msg: format!(
                        "line {}: [[{table}]] {field} `{}` is not a {field} of the plan ({})",
                        line(text, name.span().start),
                        crate::deck::short(name.get_ref()),
                        known.join(", ")
                    ),
                });
            }
        }
    }
    Ok(())
}
