//! Reading a run's histories from `histories.nc` as if they were its CSVs: the reader
//! `compare`, `plot` and `sweep` share (issue 29). A history is asked for by the name of
//! its CSV (`node_12.csv`, `element_3.csv`, `energy.csv`); when the directory has no such
//! file but a `histories.nc` that holds the entity, the same table (header `t,…`, one row
//! per instant) comes from there.
//!
//! The parser reads the NetCDF classic and 64-bit-offset formats (Unidata, "File Format
//! Specifications") for the types this project writes: char, int, double.

use super::netcdf::{
    FILE_NAME, NC_ATTRIBUTE, NC_CHAR, NC_DIMENSION, NC_DOUBLE, NC_INT, NC_VARIABLE,
};
use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::Path;

/// A history: column names (the first is `t`) and rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Column names.
    pub columns: Vec<String>,
    /// One row per written instant.
    pub rows: Vec<Vec<f64>>,
}

/// Why `histories.nc` could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a NetCDF file of the kind this project writes.
    #[error("{file}: not a readable NetCDF classic file: {why}")]
    Format {
        /// The file.
        file: String,
        /// What is wrong.
        why: String,
    },
}

struct Var {
    name: String,
    dims: Vec<usize>,
    columns: Option<String>,
    kind: u32,
    begin: u64,
}

/// The parsed header of a NetCDF classic file.
struct Header {
    dims: Vec<(String, u64)>,
    vars: Vec<Var>,
    numrecs: u64,
    rec_size: u64,
}

struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|e| *e <= self.b.len());
        let end = end.ok_or("the header ends early")?;
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, String> {
        let s = self.take(4)?;
        Ok(u32::from_be_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        let s = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(u64::from_be_bytes(a))
    }
    fn name(&mut self) -> Result<String, String> {
        let n = self.u32()? as usize;
        let s = String::from_utf8_lossy(self.take(n)?).into_owned();
        self.take((4 - n % 4) % 4)?;
        Ok(s)
    }
    /// An attribute list; returns the text of the attribute `want`, if there.
    fn atts(&mut self, want: &str) -> Result<Option<String>, String> {
        let tag = self.u32()?;
        let n = self.u32()?;
        if tag != NC_ATTRIBUTE && !(tag == 0 && n == 0) {
            return Err("bad attribute list".into());
        }
        let mut found = None;
        for _ in 0..n {
            let name = self.name()?;
            let kind = self.u32()?;
            let len = self.u32()? as usize;
            let size = match kind {
                1 | 2 => 1,
                3 => 2,
                4 | 5 => 4,
                6 => 8,
                _ => return Err(format!("attribute type {kind}")),
            };
            let bytes = len * size;
            let v = self.take(bytes)?;
            if kind == NC_CHAR && name == want {
                found = Some(String::from_utf8_lossy(v).into_owned());
            }
            self.take((4 - bytes % 4) % 4)?;
        }
        Ok(found)
    }
}

fn header(b: &[u8]) -> Result<Header, String> {
    let mut c = Cursor { b, at: 0 };
    let magic = c.take(4)?;
    let wide = match magic {
        b"CDF\x01" => false,
        b"CDF\x02" => true,
        _ => return Err("no CDF magic number".into()),
    };
    let numrecs = c.u32()?;
    let tag = c.u32()?;
    let n = c.u32()?;
    if tag != NC_DIMENSION && !(tag == 0 && n == 0) {
        return Err("bad dimension list".into());
    }
    let mut dims = Vec::new();
    for _ in 0..n {
        let name = c.name()?;
        dims.push((name, u64::from(c.u32()?)));
    }
    c.atts("")?;
    let tag = c.u32()?;
    let n = c.u32()?;
    if tag != NC_VARIABLE && !(tag == 0 && n == 0) {
        return Err("bad variable list".into());
    }
    let mut vars = Vec::new();
    let mut rec_size = 0u64;
    for _ in 0..n {
        let name = c.name()?;
        let nd = c.u32()? as usize;
        let mut vd = Vec::new();
        for _ in 0..nd {
            let d = c.u32()? as usize;
            if d >= dims.len() {
                return Err(format!("variable {name}: dimension {d}"));
            }
            vd.push(d);
        }
        let columns = c.atts("columns")?;
        let kind = c.u32()?;
        let vsize = u64::from(c.u32()?);
        let begin = if wide { c.u64()? } else { u64::from(c.u32()?) };
        if vd.first().is_some_and(|d| dims[*d].1 == 0) {
            rec_size += vsize;
        }
        vars.push(Var {
            name,
            dims: vd,
            columns,
            kind,
            begin,
        });
    }
    Ok(Header {
        dims,
        vars,
        numrecs: u64::from(numrecs),
        rec_size,
    })
}

fn open(dir: &Path) -> Option<Result<(File, Header), ReadError>> {
    let path = dir.join(FILE_NAME);
    let file_s = path.display().to_string();
    // A FIFO or a device under the name is not waited on (crate::safe_file).
    let f = match crate::safe_file::open_regular(&path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => {
            return Some(Err(ReadError::Io {
                file: file_s,
                source: e,
            }));
        }
    };
    let io = |source| ReadError::Io {
        file: file_s.clone(),
        source,
    };
    let run = || -> Result<(File, Header), ReadError> {
        // Headers of this project's files are a few kB per group; 1 MB covers them.
        let len = f.metadata().map_err(io)?.len().min(1 << 20) as usize;
        let mut b = vec![0u8; len];
        f.read_exact_at(&mut b, 0).map_err(io)?;
        let h = header(&b).map_err(|why| ReadError::Format {
            file: file_s.clone(),
            why,
        })?;
        Ok((f, h))
    };
    Some(run())
}

fn ints(f: &File, v: &Var, n: u64) -> std::io::Result<Vec<u32>> {
    let mut b = vec![0u8; 4 * n as usize];
    f.read_exact_at(&mut b, v.begin)?;
    Ok(b.chunks_exact(4)
        .map(|c| u32::from_be_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// The nodes and elements `histories.nc` of `dir` holds: (`node` or `element`, number).
/// Empty when there is no such file (or it cannot be read).
pub fn entities(dir: &Path) -> Vec<(String, u32)> {
    let Some(Ok((f, h))) = open(dir) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for v in &h.vars {
        let Some(group) = v.name.strip_suffix("_id") else {
            continue;
        };
        let kind = if group == "node" { "node" } else { "element" };
        if v.kind != NC_INT || v.dims.len() != 1 {
            continue;
        }
        if let Ok(ids) = ints(&f, v, h.dims[v.dims[0]].1) {
            out.extend(ids.into_iter().map(|i| (kind.to_string(), i)));
        }
    }
    out
}

/// The history of a CSV the run did not write as a file (`dir/node_12.csv`,
/// `dir/element_3.csv`, `dir/energy.csv`) from the directory's `histories.nc`; `None`
/// when there is no such file or it does not hold that entity.
pub fn from_columnar(csv: &Path) -> Option<Result<Table, ReadError>> {
    let dir = csv.parent()?;
    let name = csv.file_name()?.to_str()?.strip_suffix(".csv")?;
    let (f, h) = match open(dir)? {
        Ok(x) => x,
        Err(e) => return Some(Err(e)),
    };
    let file_s = dir.join(FILE_NAME).display().to_string();
    let io = |source| ReadError::Io {
        file: file_s.clone(),
        source,
    };
    // The variable and the entity's index in it.
    let (var, index) = if name == "energy" {
        (h.vars.iter().find(|v| v.name == "energy")?, 0)
    } else {
        let (kind, num) = name.split_once('_')?;
        let num: u32 = num.parse().ok()?;
        let mut found = None;
        for v in &h.vars {
            let Some(group) = v.name.strip_suffix("_id") else {
                continue;
            };
            let ok = if kind == "node" {
                group == "node"
            } else {
                kind == "element" && group.starts_with("element_")
            };
            if !ok || v.kind != NC_INT || v.dims.len() != 1 {
                continue;
            }
            let ids = match ints(&f, v, h.dims[v.dims[0]].1) {
                Ok(i) => i,
                Err(e) => return Some(Err(io(e))),
            };
            if let Some(i) = ids.iter().position(|i| *i == num) {
                found = Some((h.vars.iter().find(|d| d.name == group)?, i));
                break;
            }
        }
        found?
    };
    let t = h.vars.iter().find(|v| v.name == "t")?;
    let bad = |why: &str| {
        Some(Err(ReadError::Format {
            file: file_s.clone(),
            why: why.to_string(),
        }))
    };
    if var.kind != NC_DOUBLE || t.kind != NC_DOUBLE {
        return bad("histories are not doubles");
    }
    let ncols = h.dims[*var.dims.last()?].1 as usize;
    let mut columns = vec!["t".to_string()];
    columns.extend(
        var.columns
            .as_deref()
            .unwrap_or_default()
            .split(',')
            .map(str::to_string),
    );
    if columns.len() != ncols + 1 {
        return bad("the `columns` attribute does not match the variable");
    }
    // Records in the file: the header's count, or (a stream of unknown length) what the
    // file's length holds.
    let mut numrecs = h.numrecs;
    if numrecs == u64::from(u32::MAX) && h.rec_size > 0 {
        let len = match f.metadata() {
            Ok(m) => m.len(),
            Err(e) => return Some(Err(io(e))),
        };
        numrecs = len.saturating_sub(t.begin) / h.rec_size;
    }
    let mut rows = Vec::with_capacity(numrecs as usize);
    let mut buf = vec![0u8; 8 * ncols];
    let mut tb = [0u8; 8];
    for r in 0..numrecs {
        let at = r * h.rec_size;
        let slab = var.begin + at + (index * ncols * 8) as u64;
        if let Err(e) = f
            .read_exact_at(&mut tb, t.begin + at)
            .and_then(|_| f.read_exact_at(&mut buf, slab))
        {
            return Some(Err(io(e)));
        }
        let mut row = Vec::with_capacity(ncols + 1);
        row.push(f64::from_be_bytes(tb));
        row.extend(buf.chunks_exact(8).map(|c| {
            let mut a = [0u8; 8];
            a.copy_from_slice(c);
            f64::from_be_bytes(a)
        }));
        rows.push(row);
    }
    Some(Ok(Table { columns, rows }))
}

/// Whether the `histories.nc` beside `csv` holds that history (`csv` itself absent).
pub fn holds(csv: &Path) -> bool {
    let Some(dir) = csv.parent() else {
        return false;
    };
    let Some(name) = csv.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    (name == "energy.csv" && dir.join(FILE_NAME).is_file())
        || entities(dir)
            .iter()
            .any(|(k, n)| name == format!("{k}_{n}.csv"))
}
