//! A history file (`node_<N>.csv`, `element_<N>.csv`): its columns and rows of numbers.

use super::*;

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
    let mut r = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_path(path)
        .map_err(|e| err(e.to_string()))?;
    let header: Vec<String> = r
        .headers()
        .map_err(|e| err(e.to_string()))?
        .iter()
        .map(str::to_string)
        .collect();
    if header.first().map(String::as_str) != Some("t") {
        return Err(err("the first column is not `t`".into()));
    }
    let mut rows = Vec::new();
    for (k, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| err(e.to_string()))?;
        let row: Result<Vec<f64>, _> = rec.iter().map(str::parse::<f64>).collect();
        let row = row.map_err(|e| err(format!("row {}: {e}", k + 2)))?;
        if row.len() != header.len() {
            return Err(err(format!(
                "row {}: {} fields, the header has {}",
                k + 2,
                row.len(),
                header.len()
            )));
        }
        rows.push(row);
    }
    Ok(History { header, rows })
}
