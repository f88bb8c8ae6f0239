//! Reading a run's histories: a numeric CSV table, a node's history, and the quantity and
//! unit of a column.

use super::*;
use crate::output::read::{ReadOptions, read_numeric};

/// A CSV table of numbers with named columns.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file it came from.
    pub file: PathBuf,
    /// Column names (header).
    pub columns: Vec<String>,
    /// Rows of values.
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// Reads a CSV file with a header row and numeric values.
    pub fn read(file: &Path) -> Result<Table, PlotError> {
        let err = |msg: String| PlotError::Read {
            file: file.to_path_buf(),
            msg,
        };
        let csv = read_numeric(
            file,
            ReadOptions {
                trim: true,
                first_column: None,
            },
        )
        .map_err(err)?;
        Ok(Table {
            file: file.to_path_buf(),
            columns: csv.header,
            rows: csv.rows,
        })
    }

    /// Index of a column, or an error naming the available ones.
    pub fn index(&self, name: &str) -> Result<usize, PlotError> {
        self.columns
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| PlotError::NoColumn {
                file: self.file.clone(),
                column: name.to_string(),
                available: self.columns.join(","),
            })
    }

    /// The values of a column.
    pub fn column(&self, name: &str) -> Result<Vec<f64>, PlotError> {
        let i = self.index(name)?;
        Ok(self.rows.iter().map(|r| r[i]).collect())
    }
}

/// Reads `element_<N>.csv` of an output directory.
pub fn read_element(dir: &Path, element: u32) -> Result<Table, PlotError> {
    if !dir.is_dir() {
        return Err(PlotError::NoDir(dir.to_path_buf()));
    }
    let file = dir.join(format!("element_{element}.csv"));
    if !file.is_file() && !crate::output::columnar::holds(&file) {
        return Err(PlotError::NoFile {
            file,
            hint: format!(
                "element {element} was not written by this run: list it in the deck's OUTPUT ELEMENTS"
            ),
        });
    }
    Table::read(&file)
}

/// Reads `node_<N>.csv` of an output directory.
pub fn read_node(dir: &Path, node: u32) -> Result<Table, PlotError> {
    if !dir.is_dir() {
        return Err(PlotError::NoDir(dir.to_path_buf()));
    }
    let file = dir.join(format!("node_{node}.csv"));
    if !file.is_file() && !crate::output::columnar::holds(&file) {
        return Err(PlotError::NoFile {
            file,
            hint: format!(
                "node {node} was not written by this run: list it in the deck's OUTPUT NODES"
            ),
        });
    }
    Table::read(&file)
}

/// The quantity and SI unit of a node history column.
pub fn quantity(column: &str) -> Option<(String, &'static str)> {
    let mut ch = column.chars();
    let (a, b) = (ch.next()?, ch.next());
    if ch.next().is_some() {
        return None;
    }
    if column == "t" {
        return Some(("time".into(), "s"));
    }
    let comp = match b {
        None => None,
        Some(c @ ('x' | 'y' | 'z')) => Some(c.to_ascii_uppercase()),
        Some(_) => return None,
    };
    let (what, unit) = match (a, comp) {
        ('x' | 'y' | 'z', None) => {
            return Some((format!("position {}", a.to_ascii_uppercase()), "m"));
        }
        ('u', Some(_)) => ("displacement", "m"),
        ('r', Some(_)) => ("rotation vector", "rad"),
        ('v', Some(_)) => ("velocity", "m/s"),
        ('w', Some(_)) => ("angular velocity", "rad/s"),
        ('a', Some(_)) => ("acceleration", "m/s²"),
        _ => return None,
    };
    Some((format!("{what} {}", comp.unwrap_or(' ')), unit))
}

pub(super) fn axis_label(column: &str) -> String {
    match quantity(column) {
        Some((q, u)) => format!("{column}: {q} ({u})"),
        None => column.to_string(),
    }
}
