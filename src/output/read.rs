//! The one reader of the numeric CSV files a run writes (`node_<N>.csv`,
//! `element_<N>.csv`, `energy.csv`): a header row of column names, then rows of numbers.
//! Used by `plot` (and through it `sweep`'s quantities) and by `compare`; each wraps the
//! message of a failure in its own error type. A history asked for by its CSV's name in a
//! run written with `OUTPUT … FORMAT NETCDF` comes from `histories.nc` instead
//! ([`super::columnar`]), so every reader sees the two formats alike.

use std::path::Path;

/// A numeric CSV file: column names and rows of numbers, as many as the columns.
#[derive(Debug, Clone, PartialEq)]
pub struct NumericCsv {
    /// Column names (header row).
    pub header: Vec<String>,
    /// Rows of numbers.
    pub rows: Vec<Vec<f64>>,
}

/// How lenient the reader is.
#[derive(Debug, Clone, Copy, Default)]
pub struct ReadOptions<'a> {
    /// Trim blanks around names and numbers (`plot`); `compare` reads fields as written.
    pub trim: bool,
    /// The name the first column must have (`compare` needs `t`).
    pub first_column: Option<&'a str>,
}

/// Reads `path`: the error is a message (the CSV parser's, or `row R: …` with `R` the
/// line of the file, header = line 1).
pub fn read_numeric(path: &Path, opt: ReadOptions) -> Result<NumericCsv, String> {
    // A run written with OUTPUT FORMAT NETCDF: the same history from histories.nc.
    if !path.is_file()
        && let Some(t) = super::columnar::from_columnar(path)
    {
        let t = t.map_err(|e| e.to_string())?;
        return Ok(NumericCsv {
            header: t.columns,
            rows: t.rows,
        });
    }
    let trim = |s: &str| if opt.trim { s.trim() } else { s }.to_string();
    let mut r = csv::ReaderBuilder::new()
        .has_headers(true)
        // A regular file only (a FIFO under a history's name is not waited on).
        .from_reader(crate::safe_file::open_regular(path).map_err(|e| e.to_string())?);
    let header: Vec<String> = r
        .headers()
        .map_err(|e| e.to_string())?
        .iter()
        .map(trim)
        .collect();
    if let Some(first) = opt.first_column
        && header.first().map(String::as_str) != Some(first)
    {
        return Err(format!("the first column is not `{first}`"));
    }
    let mut rows = Vec::new();
    for (k, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| e.to_string())?;
        let row: Result<Vec<f64>, _> = rec
            .iter()
            .map(|v| if opt.trim { v.trim() } else { v }.parse::<f64>())
            .collect();
        let row = row.map_err(|e| format!("row {}: {e}", k + 2))?;
        if row.len() != header.len() {
            return Err(format!(
                "row {}: {} fields, the header has {}",
                k + 2,
                row.len(),
                header.len()
            ));
        }
        rows.push(row);
    }
    Ok(NumericCsv { header, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_trims_on_request_and_locates_bad_rows() {
        let dir = std::env::temp_dir().join(format!("mecano_read_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.csv");
        std::fs::write(&f, "t, x\n0, 1.5\n1,2\n").unwrap();
        let trimmed = read_numeric(
            &f,
            ReadOptions {
                trim: true,
                first_column: Some("t"),
            },
        );
        assert_eq!(
            trimmed,
            Ok(NumericCsv {
                header: vec!["t".into(), "x".into()],
                rows: vec![vec![0.0, 1.5], vec![1.0, 2.0]],
            })
        );
        // As written, " 1.5" is not a number: the error names the file's line 2.
        let raw = read_numeric(&f, ReadOptions::default()).unwrap_err();
        assert!(raw.starts_with("row 2: "), "{raw}");
        std::fs::write(&f, "x,t\n0,1\n").unwrap();
        let no_t = read_numeric(
            &f,
            ReadOptions {
                trim: false,
                first_column: Some("t"),
            },
        );
        assert_eq!(no_t, Err("the first column is not `t`".to_string()));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
