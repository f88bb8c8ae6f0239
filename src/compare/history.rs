//! A history file (`node_<N>.csv`, `element_<N>.csv`): its columns and rows of numbers.

use super::*;
use crate::output::read::{ReadOptions, read_numeric};

/// A history: column names and rows.
#[derive(Debug, Clone)]
pub struct History {
    /// Column names (the first is `t`).
    pub header: Vec<String>,
    /// Rows of numbers.
    pub rows: Vec<Vec<f64>>,
}

/// Reads a history CSV (header row, then numbers).
pub fn read_history(path: &Path) -> Result<History, CompareError> {
    let err = |why: String| CompareError::File {
        path: path.to_path_buf(),
        why,
    };
    let csv = read_numeric(
        path,
        ReadOptions {
            trim: false,
            first_column: Some("t"),
        },
    )
    .map_err(err)?;
    Ok(History {
        header: csv.header,
        rows: csv.rows,
    })
}
