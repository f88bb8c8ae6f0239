//! What a plan adds to its 1-D figures: reference points and power-law guides
//! (`[[reference]]`, `[[guide]]`), read with the plan and drawn by `figures`.

use serde::Deserialize;

/// Published or reference points drawn on a 1-D sweep's figure.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// The quantity (y).
    pub quantity: String,
    /// The parameter (x).
    pub parameter: String,
    /// Legend.
    pub label: String,
    /// (x, y) pairs.
    pub points: Vec<[f64; 2]>,
}

/// A power-law guide y = y0 (x / x0)^exponent.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Guide {
    /// The quantity (y).
    pub quantity: String,
    /// The parameter (x).
    pub parameter: String,
    /// Legend.
    pub label: String,
    /// The exponent.
    pub exponent: f64,
    /// The point (x0, y0) it passes through.
    pub through: [f64; 2],
}
